"""The ltc kind's tile engine (lutbake.kinds.ltc): one bake's fits, shared by its tiles. The coarse pass and the
magnitudes are built once; each texel range is fitted once (lutbake.ltc.fit, refined by lutbake.ltc.shaded for
``fit = "shaded"``) and serves both texture slices: slice 0 the packed inverse matrix, slice 1 (magnitude, fresnel,
fit_error, sphere)."""

from __future__ import annotations

import os
import threading

import numpy as np

from ..axes import Axis
from .magnitude import lobe_magnitude, magnitude_alpha, magnitude_fresnel, texel_params


def uses_shaded_fit(o: dict) -> bool:
    """Whether the table's texels are the shaded fit's (lutbake.ltc.shaded) or the L3 fit's."""
    return o["fit"] == "shaded" and o["lobe"] != "lambert"  # lambert: the L3 fit is exact


class LtcBake:
    """The state one bake shares between its tiles: the problem (magnitudes, frames) and the coarse pass,
    built once under a lock; fits are memoised per texel range (both slices' tiles of one range use one fit) and
    per texel across tables (lutbake.ltc.fit.MEMO: a texel with the same inputs and seeds as one another table
    of the process fitted, e.g. ltc-hdrp's beside ltc-ggx's, is that fit)."""

    def __init__(self, o: dict, axes: list[Axis], lobe, tolerance=None):
        self.o = o
        self.lobe = lobe  # the Lobe fitted (the spec's record's object)
        self.tolerance = tolerance  # a plugin lobe's magnitude target (lobe_magnitude; a lutbake.tolerance.Tolerance)
        self.magnitude_estimate, self.magnitude_met = None, True
        self.axes = axes
        self.nov, self.alpha = texel_params(axes, o["alpha_min"])
        self.n_view, self.n_rough = axes[1].count, axes[2].count
        from . import sphere

        self._lock = threading.Lock()
        self._fits: dict[tuple[int, int], tuple[threading.Lock, list]] = {}
        self.problem = None
        self.coarse = None
        self.shaded = uses_shaded_fit(o)
        self.device = "cpu"
        self.sphere = sphere.sphere_table(self.n_rough) if self.n_view == self.n_rough else None

    def prepare(self, device: str) -> None:
        from . import fit

        with self._lock:
            if self.problem is None:
                o = self.o
                alpha = magnitude_alpha(self.axes, o["alpha_min"])
                if self.lobe.magnitude == "lobe_adaptive":  # a plugin's lobe: to the table's tolerance, estimated
                    mag, self.magnitude_estimate, self.magnitude_met = lobe_magnitude(
                        self.lobe, self.nov, alpha, device, self.tolerance
                    )
                    fres = mag.copy()
                else:
                    mag, fres = magnitude_fresnel(
                        self.lobe, self.nov, alpha, o["samples"], device, o["estimator"], o["seed"]
                    )
                self.fresnel = fres
                self.device = device
                self.has_fresnel = not np.array_equal(mag, fres)  # lobes without Fresnel store fresnel = magnitude
                # a tabulated lobe's table is built here on every available core (the executor's default; values do
                # not depend on the thread count)
                threads = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
                p = fit.Problem(self.lobe, self.nov, self.alpha, mag, self.o["fit_samples"], device, threads)
                nodes = self.unclamped_nodes(device, threads)
                self.coarse = fit.coarse_pass(p, self.n_view, self.n_rough, fit.MEMO, nodes)
                self.problem = p

    def magnitude_attributes(self) -> dict[str, str]:
        """A plugin lobe's magnitude error estimate (lutbake:ltc_magnitude_error_estimate), and the over_tolerance
        record (lutbake.pipeline.OVER_TOLERANCE) where it missed the table's tolerance; {} for lutbake's lobes."""
        if self.magnitude_estimate is None:
            return {}
        est = self.magnitude_estimate
        out = {"ltc_magnitude_error_estimate": f"{est:.3e}"}
        if not self.magnitude_met:
            out["over_tolerance"] = (
                f"the magnitude (slice 1, R) of lobe {self.lobe.name!r}: the diffuse rule's orders disagree by up to "
                f"{est:.3e}, over the tolerance (a lobe sharper than that rule resolves)"
            )
        return out

    def unclamped_nodes(self, device: str, threads: int):
        """The coarse pass's own problem where ``alpha_min`` clamps a coarse texel's alpha: the coarse texels at the
        lobe's alpha (>= lutbake's ALPHA_MIN) and magnitude, as a table without the clamp fits them; None where no
        coarse texel is clamped. The coarse fits only seed the texels, so the table's seeds are then the unclamped
        table's, and through the fit memo so is every texel the clamp leaves alone (ltc-hdrp, alpha_min 1e-3, fits
        its two clamped columns of 64 beside ltc-ggx instead of the nine of the first coarse cell)."""
        from . import fit

        idx = fit.coarse_texels(self.n_view, self.n_rough)
        nov, alpha = texel_params(self.axes)
        if np.array_equal(alpha[idx], self.alpha[idx]):
            return None
        o = self.o
        mag, _ = magnitude_fresnel(
            self.lobe, nov[idx], magnitude_alpha(self.axes)[idx], o["samples"], device, o["estimator"], o["seed"]
        )
        return fit.Problem(self.lobe, nov[idx], alpha[idx], mag, o["fit_samples"], device, threads)

    def fitted(self, start: int, stop: int) -> list:
        """[packed ltc_1 (k, 4), relative error (k,)] of texels [start, stop) of a slice (fitted once)."""
        from . import fit

        with self._lock:
            lock, box = self._fits.setdefault((start, stop), (threading.Lock(), []))
        with lock:
            if not box:
                texel = np.arange(start, stop)
                p = self.problem
                m, err = fit.fit_texels(p, texel, self.n_rough, self.coarse, fit.MEMO)
                packed, mag, fres = fit.pack_inverse(m), p.magnitude[texel], self.fresnel[texel]
                if self.shaded:
                    from . import shaded

                    # texels the L3 fit represents exactly (EON at r = 0: Lambert) keep it: the training lights'
                    # sampled targets would only add their noise
                    sel = np.flatnonzero(p.relative(texel, err) >= shaded.EXACT_L3)
                    free = self.o["magnitude"] == "fitted"
                    exact_fres = fres[sel] if self.has_fresnel else None
                    w = self.o["fit_f0_weight"]
                    packed, mag, fres, err = packed.copy(), mag.copy(), fres.copy(), err.copy()
                    packed[sel], mag[sel], fres[sel] = shaded.refine(
                        p, texel[sel], packed[sel], exact_fres, free, self.device, f0_weight=w
                    )
                    err[sel] = p.error(texel[sel], np.linalg.inv(fit.unpack_inverse(packed[sel])))
                box += [packed, p.relative(texel, err), mag, fres]
        return box

    def run_tile(self, start: int, stop: int, device: str) -> np.ndarray:
        self.prepare(device)
        n = self.n_view * self.n_rough
        out = np.empty((stop - start, 4))
        pos = start
        while pos < stop:  # a tile may straddle the two slices
            z, s = divmod(pos, n)
            e = min(stop - z * n, n)
            packed, rel, mag, fres = self.fitted(s, e)
            rows = slice(pos - start, pos - start + e - s)
            if z == 0:
                out[rows] = packed
            else:
                sph = self.sphere.ravel()[s:e] if self.sphere is not None else np.zeros(e - s)
                out[rows] = np.stack([mag, fres, rel, sph], axis=1)
            pos += e - s
        return out
