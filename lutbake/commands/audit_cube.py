"""``lutbake audit CUBE``: check a shipped prefiltered environment cube against lutbake's exact prefilter of its own
mip 0, and name what is off. Nothing is assumed about how the file was made but the face table (lutbake.io.cube_read
reads it) and, for the curve check, the engine's roughness -> mip curve (``--preset bevy-ibl``, ``--curve linear``).

**Specular cube** (more than one mip). Mip 0 is taken as the source, texel-constant on the cube (it is the engines'
r = 0 level: the environment itself); its a_lm come from lutbake.environment.harmonic.analyse_cube. For each mip m >= 1
the GGX alpha that best explains it is the minimiser of the relative RMS

    rms(alpha) = sqrt(Σ ω (P_alpha - T)^2) / sqrt(Σ ω T^2)      (ω: texel solid angles; channels summed)

of T (the mip, on up to MAX_PROBES strided texels) against P_alpha = Σ (g_l(alpha) / g_0) a_lm Y_lm (harmonic.
kernel_coefficients, harmonic.synthesise: every trial is one synthesis, no sampling), a bounded 1-D minimisation in
log alpha over [1 / (4 n_m), 1] (n_m the mip's face size: a lobe a quarter of a texel wide is below what the mip
resolves), in two passes: at lmax COARSE_LMAX, then over [alpha_c / 4, 2 alpha_c] around its result alpha_c at the
lmax that bracket's narrowest lobe needs, TAIL_L / (alpha_c / 4) (the GGX kernel's g_l / g_0 fall below 1e-6 there,
measured: l alpha = 7.6 .. 7.7 for alpha 0.008 .. 0.2), at most MAX_LMAX and 4 n_0. Both lobes are fitted (``ggx_nl``,
``ggx``), the one with the smaller RMS over the mips is reported. Then:

- **curve**: the fitted alpha per mip against the hypotheses, each a prediction of every mip's alpha: the declared
  curve (alpha = r_m^2), alpha = r_m (perceptual roughness used as alpha), alpha = r_m^4, every other curve of
  lutbake.environment.curves, and the declared curve one level off (r_{m-1}, r_{m+1}). The score of a hypothesis is
  the RMS over mips of ln(alpha_fit / alpha_hyp); the declared curve matches when its score is below MATCH_LOG, and
  another hypothesis is named when its score is below MISMATCH_RATIO x the declared one's.
- **gamma**: the fit repeated on the file's values passed through the sRGB EOTF and through its inverse (both mip 0
  and the mip); a transfer whose best RMS is below MISMATCH_RATIO x the file's as read names a gamma mistake. 8-bit
  sRGB formats are reported as such (the reader applied the EOTF, as a GPU sampler does).
- **faces**: each face of mip m against every face of the prediction under the eight flips, rotations and transposes
  of the square; a face whose best match is another (face, transform) with an RMS below FACE_RATIO x its own is named;
  a face named in the finest mip and left out of the alpha fit in every checked mip (its RMS above OUTLIER_RATIO x the
  median face's) is mip 0's (the source) face out of place. The alpha is refitted without such outlier faces; a
  misplaced face that dominates the cube's light spoils every face's fit, and the audit then names no curve.
- **noise**: the relative RMS of the residual T - P at the best alpha, and of its high-frequency part (the residual
  minus its 3 x 3 box average on each face): sampled prefilters leave high-frequency noise, a wrong lobe or curve a
  smooth residual.

**Irradiance cube** (one mip). A Lambertian convolution E / pi holds no odd band l >= 3 and its even bands fall like
the cosine kernel's (g_4 / g_0 = -1/24, g_6 / g_0 = 1/64): the cube is fitted, in the least-squares sense over its
texels (solid-angle weighted), by real SH of bands 0, 1, 2, 4, 6, 8 and by every band up to 8; the report gives both
residuals and the odd bands' part (sqrt of their share of the fitted power: a relative RMS), named above ODD_TOL (what
no Lambertian irradiance holds: a sampled filter's bias or noise, or another lobe). Faces: each face against the fit
of the other five, under the eight transforms. Gamma: as above, on the residual.

What the audit cannot see: the orientation of the whole cube in the world (every mip is compared with the file's own
mip 0), an intensity scale common to every mip (reported as ``scale``: the least-squares factor on P at the best
alpha), and the difference between mip 0 and the engine's true source (mip 0 is a texel box average of it, which
widens the fitted alpha of the finest mips a little).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..environment import cube, curves, harmonic
from ..io.cube_read import CubeFile, read_cube
from ..io.encodings import srgb_eotf, srgb_oetf

MAX_PROBES = 6 * 24 * 24  # texels per mip in the alpha fit (strided rows and columns of every face)
TAIL_L = 7.7  # l alpha where the GGX kernel's |g_l / g_0| falls below 1e-6 (module docstring)
MAX_LMAX = 1023
OUTLIER_RATIO = 4.0  # a face whose RMS at the best alpha is above this x the median face's is refitted without
COARSE_LMAX = 256  # the first fit's lmax (and the gamma check's): the fine fit takes each mip's lmax from its result
MATCH_LOG = math.log(1.25)  # a curve matches when alpha_fit / alpha_curve is within 25% on average (RMS of logs)
MISMATCH_RATIO = 0.5  # another hypothesis is named when its score (or RMS) is below this x the declared one's
FACE_RATIO = 0.5  # a face is named when another (face, transform) fits it with below this x its own RMS
FACE_MIN = 4  # faces of at least this many texels a side are checked (a 2 x 2 face is near-symmetric)
LOBES = ("ggx_nl", "ggx")
TRANSFERS = {"as read": lambda v: v, "sRGB EOTF": srgb_eotf, "sRGB OETF": srgb_oetf}
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])  # BT.709: the gamma and face checks fit one channel
IRRADIANCE_BANDS = (0, 1, 2, 4, 6, 8)  # the bands a Lambertian convolution keeps (odd l >= 3 vanish)
SH_BANDS = 8
ODD_TOL = 2e-3  # odd bands >= 3 of an irradiance cube, relative RMS: above this it is named (lutbake's exact cube: 0)


def transforms(face: np.ndarray) -> dict[str, np.ndarray]:
    """The eight symmetries of a square face image (rows t, columns s)."""
    t = face.swapaxes(0, 1)
    return {
        "identity": face,
        "s flipped": face[:, ::-1],
        "t flipped": face[::-1],
        "rotated 180": face[::-1, ::-1],
        "transposed": t,
        "rotated 90 (t flipped, transposed)": t[:, ::-1],
        "rotated 270 (s flipped, transposed)": t[::-1],
        "anti-transposed": t[::-1, ::-1],
    }


def relative_rms(p: np.ndarray, t: np.ndarray, w: np.ndarray) -> float:
    """sqrt(Σ w (p - t)^2) / sqrt(Σ w t^2), w broadcast over the texels (channels summed)."""
    return float(np.sqrt(np.sum(w * (p - t) ** 2) / max(np.sum(w * t * t), 1e-300)))


def high_frequency(r: np.ndarray) -> np.ndarray:
    """r (6, n, n, C) minus its 3 x 3 box average on each face (edges replicated)."""
    n = r.shape[1]
    pad = np.pad(r, ((0, 0), (1, 1), (1, 1), (0, 0)), mode="edge")
    box = sum(pad[:, i : i + n, j : j + n] for i in range(3) for j in range(3)) / 9.0
    return r - box


def probe_grid(n: int) -> np.ndarray:
    """Rows (and columns) of an n x n face sampled in the fit: all, or MAX_PROBES / 6 strided ones per face."""
    side = int(math.isqrt(MAX_PROBES // 6))
    return np.arange(n) if n <= side else np.unique(np.linspace(0, n - 1, side).round().astype(int))


@dataclass
class MipFit:
    mip: int
    size: int
    alpha: float
    rms: float
    scale: float
    residual_hf: float
    lmax: int
    at_bound: bool
    faces: list[str] = field(default_factory=list)


@dataclass
class CubeAudit:
    path: str
    container: str
    pixel_format: str
    transfer: str
    sizes: list[int]
    kind: str  # "specular" or "irradiance"
    curve: str | None = None
    curve_source: str = ""
    lobe: str | None = None
    lobe_rms: dict = field(default_factory=dict)
    fits: list[MipFit] = field(default_factory=list)
    declared_alpha: list[float] = field(default_factory=list)
    hypotheses: dict = field(default_factory=dict)  # name -> (score, alphas)
    gamma: dict = field(default_factory=dict)  # transfer -> best RMS
    irradiance: dict = field(default_factory=dict)
    findings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        return not self.findings

    def as_dict(self) -> dict:
        out = {k: v for k, v in self.__dict__.items() if k != "fits"}
        out["fits"] = [f.__dict__ for f in self.fits]
        out["passed"] = self.passed
        return out

    def text(self) -> str:
        lines = [
            f"audit {self.path}",
            f"  {self.container} cube, {self.pixel_format}"
            + (" (decoded by the sRGB EOTF)" if self.transfer == "srgb" else "")
            + f", mips {' '.join(map(str, self.sizes))}",
        ]
        if self.kind == "specular":
            lines.append(
                f"  curve: {self.curve} ({self.curve_source}); lobe fitted best: {self.lobe} "
                f"({', '.join(f'{k} RMS {v:.3g}' for k, v in self.lobe_rms.items())})"
            )
            lines.append("  mip  size  alpha fit    alpha curve  rel. RMS   high-freq  scale   lmax")
            for f in self.fits:
                want = self.declared_alpha[f.mip] if f.mip < len(self.declared_alpha) else float("nan")
                lines.append(
                    f"  {f.mip:<4} {f.size:<5} {f.alpha:<12.4g} {want:<12.4g} {f.rms:<10.3g} {f.residual_hf:<10.3g} "
                    f"{f.scale:<7.4f} {f.lmax}" + ("  (at the search's bound)" if f.at_bound else "")
                )
            lines.append("  hypotheses (RMS over mips of ln(alpha_fit / alpha_hypothesis)):")
            for name, (score, _) in sorted(self.hypotheses.items(), key=lambda kv: kv[1][0])[:6]:
                lines.append(f"    {score:8.3f}  {name}")
        else:
            irr = self.irradiance
            lines.append(
                f"  irradiance: Lambertian bands {IRRADIANCE_BANDS} leave rel. RMS {irr['rms_lambertian']:.3g}, "
                f"bands <= {SH_BANDS} leave {irr['rms_all']:.3g} (high-freq {irr['residual_hf']:.3g}); odd bands >= 3: "
                f"rel. RMS {irr['odd_rms']:.3g} (a cosine convolution holds none)"
            )
        if self.gamma:
            lines.append(
                "  transfer hypotheses (best rel. RMS): " + ", ".join(f"{k} {v:.3g}" for k, v in self.gamma.items())
            )
        lines += [f"  note: {n}" for n in self.notes]
        lines += [f"  finding: {f}" for f in self.findings] or ["  finding: none"]
        lines.append("PASS" if self.passed else "FAIL")
        return "\n".join(lines) + "\n"


# ------------------------------------------------------------------------------------------------ specular


@dataclass
class Target:
    """One mip's probe texels: directions, solid angles, values and faces (6 faces x rows x columns, flattened)."""

    dirs: np.ndarray
    weights: np.ndarray
    values: np.ndarray
    face: np.ndarray

    def without(self, faces: list[int]) -> Target:
        """The same probes with the texels of ``faces`` weighted 0."""
        keep = ~np.isin(self.face, faces)[:, None]
        return Target(self.dirs, self.weights * keep, self.values, self.face)

    def face_rms(self, pred: np.ndarray) -> np.ndarray:
        """(6,) relative_rms of each face's probes."""
        return np.array(
            [
                relative_rms(pred[self.face == f], self.values[self.face == f], self.weights[self.face == f])
                for f in range(6)
            ]
        )


def target(mip: np.ndarray) -> Target:
    n = mip.shape[1]
    rows = probe_grid(n)
    dirs = cube.texel_centres(n)[:, rows][:, :, rows].reshape(-1, 3)
    w = np.broadcast_to(cube.texel_solid_angles(n)[rows][:, rows], (6, len(rows), len(rows))).reshape(-1, 1)
    face = np.repeat(np.arange(6), len(rows) ** 2)
    return Target(dirs, w, mip[:, rows][:, :, rows].reshape(-1, mip.shape[-1]), face)


def predict(h: harmonic.Harmonics, lobe: str, alpha: float, dirs: np.ndarray, lmax: int) -> np.ndarray:
    return harmonic.synthesise(h, harmonic.kernel_coefficients(lobe, alpha, lmax), dirs)


def fit_alpha(h, lobe: str, t: Target, lmax: int, lo: float, hi: float = 1.0) -> tuple[float, float]:
    """(alpha, rms) minimising relative_rms over log alpha in [lo, hi] (bounded Brent)."""
    from scipy.optimize import minimize_scalar

    def rms(log_alpha: float) -> float:
        return relative_rms(predict(h, lobe, math.exp(log_alpha), t.dirs, lmax), t.values, t.weights)

    res = minimize_scalar(rms, bounds=(math.log(lo), math.log(hi)), method="bounded", options={"xatol": 2e-3})
    return math.exp(res.x), float(res.fun)


def analysed(mip0: np.ndarray, lmax: int, channels: np.ndarray | None = None, threads: int = 1):
    """a_lm of mip 0 (its three channels, or their combination ``channels`` as one), lmax, at an order that leaves
    about 1e-6 (module docstring: harmonic.cube_order's measurements)."""
    n = mip0.shape[1]
    order = 2 + math.ceil(1.5 * lmax * (2.0 / n) / math.pi)
    h = harmonic.analyse_cube(mip0, lmax, order=order, threads=threads)
    if channels is not None:
        h = harmonic.Harmonics((channels[:, None] * h.alm).sum(axis=0, keepdims=True), lmax)
    return h


def lobe_lmax(alpha: float, cap: int) -> int:
    """The lmax a GGX lobe of ``alpha`` needs (TAIL_L / alpha), at most ``cap``."""
    return int(min(cap, math.ceil(TAIL_L / alpha)))


def curve_hypotheses(curve: str, mips: int) -> dict[str, list[float]]:
    """name -> alpha per mip (index 0 included) of every hypothesis (module docstring)."""
    declared = curves.CURVES[curve]
    r = [declared.roughness(m, mips) for m in range(mips)]
    out = {
        f"the declared curve '{curve}' (alpha = r^2)": [x * x for x in r],
        f"'{curve}' with alpha = r (perceptual roughness used as alpha)": r,
        f"'{curve}' with alpha = r^4 (roughness squared twice)": [x**4 for x in r],
        f"'{curve}' one level later (mip m holds r of mip m - 1)": [r[max(m - 1, 0)] ** 2 for m in range(mips)],
        f"'{curve}' one level earlier (mip m holds r of mip m + 1)": [
            r[min(m + 1, mips - 1)] ** 2 for m in range(mips)
        ],
    }
    for name, c in curves.CURVES.items():
        if name != curve:
            out[f"curve '{name}' ({c.lod})"] = [c.roughness(m, mips) ** 2 for m in range(mips)]
    return out


def score(fit: list[float], alphas: list[float], mips: list[int]) -> float:
    """RMS over ``mips`` of ln(fit / hypothesis); a hypothesis of alpha 0 at a fitted mip is infinitely off."""
    logs = [math.log(fit[k] / alphas[m]) if alphas[m] > 0 else math.inf for k, m in enumerate(mips)]
    return math.sqrt(sum(x * x for x in logs) / len(logs))


def face_findings(mip: np.ndarray, pred: np.ndarray, w: np.ndarray, faces=range(6)) -> list[str]:
    """Faces (of ``faces``) of ``mip`` that another face of ``pred`` under a transform fits much better (module
    docstring)."""
    found = []
    for f in faces:
        own = relative_rms(pred[f], mip[f], w)
        best = min(
            ((relative_rms(pred[g], tf, w), g, name) for name, tf in transforms(mip[f]).items() for g in range(6)),
            key=lambda x: x[0],
        )
        if (best[1], best[2]) != (f, "identity") and best[0] < FACE_RATIO * own:
            found.append(
                f"face {cube.FACE_NAMES[f]} is the prediction's {cube.FACE_NAMES[best[1]]} {best[2]} "
                f"(RMS {best[0]:.3g} vs {own:.3g} as stored)"
            )
    return found


def audit_specular(cube_file: CubeFile, curve: str, curve_source: str, max_lmax: int, threads: int) -> CubeAudit:
    mips = cube_file.mips
    n0, count = mips[0].shape[1], len(mips)
    report = CubeAudit(
        str(cube_file.path),
        cube_file.container,
        cube_file.pixel_format,
        cube_file.transfer,
        [m.shape[1] for m in mips],
        "specular",
        curve,
        curve_source,
    )
    fitted = [m for m in range(1, count) if mips[m].shape[1] >= 2]  # a 1 x 1 mip fits any wide lobe
    cap = int(min(max_lmax, 4 * n0))
    coarse = min(cap, COARSE_LMAX)
    h_coarse = analysed(mips[0], coarse, threads=threads)
    targets = {m: target(mips[m]) for m in fitted}
    lo = {m: min(0.25 / mips[m].shape[1], 0.5) for m in fitted}
    rough = {
        lobe: {m: fit_alpha(h_coarse, lobe, targets[m], lobe_lmax(lo[m], coarse), lo[m])[0] for m in fitted}
        for lobe in LOBES
    }
    # the fine fit: each mip's lmax from its coarse alpha (a quarter of it), the analysis redone where that is more
    bounds = {
        lobe: {m: (max(lo[m], a / 4), min(1.0, 2 * a), lobe_lmax(max(lo[m], a / 4), cap)) for m, a in r.items()}
        for lobe, r in rough.items()
    }
    lmax = max((b[2] for r in bounds.values() for b in r.values()), default=coarse)
    h = h_coarse if lmax <= coarse else analysed(mips[0], lmax, threads=threads)
    per_lobe = {
        lobe: [fit_alpha(h, lobe, targets[m], b[m][2], b[m][0], b[m][1]) for m in fitted] for lobe, b in bounds.items()
    }
    lobe_rms = {lobe: float(np.sqrt(np.mean([r * r for _, r in fits]))) for lobe, fits in per_lobe.items()}
    lobe = min(lobe_rms, key=lobe_rms.get)
    report.lobe, report.lobe_rms = lobe, lobe_rms
    faces_by_mip, left_out = [], []
    for k, m in enumerate(fitted):
        alpha, rms = per_lobe[lobe][k]
        n, (low, high, mip_l) = mips[m].shape[1], bounds[lobe][m]
        per_face = targets[m].face_rms(predict(h, lobe, alpha, targets[m].dirs, mip_l))
        outliers = [f for f in range(6) if per_face[f] > OUTLIER_RATIO * np.median(per_face)]
        if n >= FACE_MIN:
            left_out.append({cube.FACE_NAMES[f] for f in outliers})
        if outliers:  # a face far off every other (misplaced, or its source face is): the fit without it
            alpha, rms = fit_alpha(h, lobe, targets[m].without(outliers), mip_l, lo[m], 1.0)
            report.notes.append(
                f"mip {m}: faces {' '.join(cube.FACE_NAMES[f] for f in outliers)} left out of the alpha fit (their RMS "
                f"{', '.join(f'{per_face[f]:.3g}' for f in outliers)} > {OUTLIER_RATIO:g} x the median face's)"
            )
        pred = predict(h, lobe, alpha, cube.texel_centres(n).reshape(-1, 3), mip_l).reshape(mips[m].shape)
        scale = float(np.sum(pred * mips[m]) / max(np.sum(pred * pred), 1e-300))
        w = cube.texel_solid_angles(n)[..., None]
        wall = np.broadcast_to(w, mips[m].shape[1:3] + (1,))
        resid = mips[m] - pred
        hf = float(np.sqrt(np.sum(w * high_frequency(resid) ** 2) / max(np.sum(w * mips[m] ** 2), 1e-300)))
        faces = face_findings(mips[m], pred, wall) if n >= FACE_MIN else []
        if n >= FACE_MIN:
            faces_by_mip.append((m, faces))
        at_bound = alpha <= low * 1.01 or (alpha >= high * 0.99 and high < 1.0) or alpha <= lo[m] * 1.01
        report.fits.append(MipFit(m, n, alpha, rms, scale, hf, mip_l, at_bound, faces))
    _curve_findings(report, curve, count, fitted)
    _face_summary(report, faces_by_mip, set.intersection(*left_out) if len(left_out) > 1 else set())
    report.gamma = gamma_check(cube_file, lobe, fitted, lo, coarse, threads)
    _gamma_findings(report, cube_file)
    return report


def _curve_findings(report: CubeAudit, curve: str, count: int, fitted: list[int]) -> None:
    hyps = curve_hypotheses(curve, count)
    fit = [f.alpha for f in report.fits]
    report.hypotheses = {name: (score(fit, alphas, fitted), alphas) for name, alphas in hyps.items()}
    declared_name = next(iter(hyps))
    report.declared_alpha = hyps[declared_name]
    declared = report.hypotheses[declared_name][0]
    best_name, (best, _) = min(report.hypotheses.items(), key=lambda kv: kv[1][0])
    if declared > MATCH_LOG:
        if best_name != declared_name and best < MISMATCH_RATIO * declared:
            report.findings.append(
                f"the mips do not hold the declared curve's alpha (score {declared:.3f}); they fit {best_name} "
                f"(score {best:.3f})"
            )
        else:
            report.findings.append(
                f"the mips do not hold the declared curve's alpha (score {declared:.3f}, above {MATCH_LOG:.3f}) and "
                f"no hypothesis explains them (best: {best_name}, {best:.3f})"
            )


def _face_summary(report: CubeAudit, faces_by_mip: list[tuple[int, list[str]]], off_everywhere: set[str]) -> None:
    """Name each misplaced face. One named in the finest checked mip whose face is an outlier of the alpha fit in
    every mip whose faces are checked (``off_everywhere``: every mip disagrees with the prediction there) is mip 0's."""
    finest = {_face_key(f) for f in faces_by_mip[0][1]} if faces_by_mip else set()
    source = {key for key in finest if key[0] in off_everywhere}
    for key in sorted(source):
        report.findings.append(
            f"face {key[0]} is the prediction's {key[1]} in mip {faces_by_mip[0][0]} and off in every mip: mip 0 "
            "(the source) has that face out of place"
        )
    for m, faces in faces_by_mip:
        report.findings += [f"mip {m}: {f}" for f in faces if _face_key(f) not in source]


def _face_key(finding: str) -> tuple[str, str]:
    """(face, what it matches) of a face_findings line, without its RMS numbers."""
    head = finding.split(" (RMS")[0]
    face, _, match = head.removeprefix("face ").partition(" is the prediction's ")
    return face, match


def gamma_check(cube_file: CubeFile, lobe: str, fitted: list[int], lo: dict, lmax: int, threads: int) -> dict:
    """transfer -> the RMS (over up to two mips: the first and the middle fitted) of the luminance fit at the coarse
    lmax after passing mip 0 and the mip through the transfer."""
    if not fitted:
        return {}
    chosen = sorted({fitted[0], fitted[len(fitted) // 2]})
    out = {}
    for name, transfer in TRANSFERS.items():
        h = analysed(transfer(cube_file.mips[0]), lmax, LUMINANCE, threads)
        rms = [
            fit_alpha(h, lobe, target(transfer(cube_file.mips[m]) @ LUMINANCE[:, None]), lobe_lmax(lo[m], lmax), lo[m])[
                1
            ]
            for m in chosen
        ]
        out[name] = float(np.sqrt(np.mean(np.square(rms))))
    return out


def _gamma_findings(report: CubeAudit, cube_file: CubeFile) -> None:
    if cube_file.transfer == "srgb":
        report.notes.append("stored as 8-bit sRGB codes (read through the sRGB EOTF): an HDR environment clips at 1")
    elif cube_file.stored_8bit:
        report.notes.append("stored as 8-bit UNORM codes: an HDR environment clips at 1")
    if not report.gamma:
        return
    base = report.gamma["as read"]
    best = min(report.gamma, key=report.gamma.get)
    if best != "as read" and report.gamma[best] < MISMATCH_RATIO * base:
        report.findings.append(
            f"the mips fit much better after the {best} ({report.gamma[best]:.3g} vs {base:.3g} as read): a gamma "
            "mistake (a cube stored with the wrong transfer, or filtered in the wrong space)"
        )


# ---------------------------------------------------------------------------------------------- irradiance


def real_sh(lmax: int, dirs: np.ndarray, bands=None) -> tuple[np.ndarray, list[int]]:
    """(N, K) real orthonormal SH of the given bands (default 0..lmax) at unit ``dirs`` (theta from +Y), and each
    column's band: sqrt(2) Re / Im of scipy's complex Y_lm for m != 0."""
    from scipy.special import sph_harm_y

    theta = np.arccos(np.clip(dirs[:, 1], -1, 1))
    phi = np.arctan2(dirs[:, 2], dirs[:, 0])
    cols, band = [], []
    for ell in bands if bands is not None else range(lmax + 1):
        for m in range(0, ell + 1):
            y = sph_harm_y(ell, m, theta, phi)
            if m == 0:
                cols.append(y.real)
                band.append(ell)
            else:
                cols += [math.sqrt(2) * y.real, math.sqrt(2) * y.imag]
                band += [ell, ell]
    return np.stack(cols, 1), band


def weighted_fit(basis: np.ndarray, values: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(coefficients, prediction) of the least-squares fit of ``values`` (N, C) by ``basis`` (N, K), weights w (N,)."""
    sw = np.sqrt(w)[:, None]
    coef, *_ = np.linalg.lstsq(basis * sw, values * sw, rcond=None)
    return coef, basis @ coef


def audit_irradiance(cube_file: CubeFile) -> CubeAudit:
    mip = cube_file.mips[0]
    n = mip.shape[1]
    report = CubeAudit(
        str(cube_file.path), cube_file.container, cube_file.pixel_format, cube_file.transfer, [n], "irradiance"
    )
    dirs = cube.texel_centres(n).reshape(-1, 3)
    w = np.tile(cube.texel_solid_angles(n).ravel(), 6)
    values = mip.reshape(-1, 3)
    lam, _ = real_sh(SH_BANDS, dirs, IRRADIANCE_BANDS)
    full, band = real_sh(SH_BANDS, dirs)
    _, p_lam = weighted_fit(lam, values, w)
    coef, p_all = weighted_fit(full, values, w)
    odd = np.array([b >= 3 and b % 2 == 1 for b in band])
    resid = (values - p_all).reshape(mip.shape)
    wf = cube.texel_solid_angles(n)[..., None]
    report.irradiance = {
        "rms_lambertian": relative_rms(p_lam, values, w[:, None]),
        "rms_all": relative_rms(p_all, values, w[:, None]),
        "odd_rms": float(np.sqrt(np.sum(coef[odd] ** 2) / np.sum(coef**2))),
        "residual_hf": float(np.sqrt(np.sum(wf * high_frequency(resid) ** 2) / np.sum(wf * mip**2))),
    }
    if report.irradiance["odd_rms"] > ODD_TOL:
        report.findings.append(
            f"odd bands l >= 3 hold a relative RMS of {report.irradiance['odd_rms']:.3g} (above {ODD_TOL:g}): not a "
            "Lambertian convolution E / pi to that level (a sampled filter's bias or noise, or another lobe)"
        )
    for f in range(6):  # each face against the Lambertian fit of the other five
        others = np.repeat(np.arange(6) != f, n * n)
        coef_f, _ = weighted_fit(lam[others], values[others], w[others])
        pred = (lam @ coef_f).reshape(mip.shape)
        report.findings += face_findings(mip, pred, wf, [f])
    gamma = {}
    for name, transfer in TRANSFERS.items():
        v = transfer(values)
        _, p = weighted_fit(lam, v, w)
        gamma[name] = relative_rms(p, v, w[:, None])
    report.gamma = gamma
    _gamma_findings(report, cube_file)
    return report


# ----------------------------------------------------------------------------------------------------- entry


def resolve_curve(cube_file: CubeFile, preset: str | None, curve: str | None, overrides) -> tuple[str, str]:
    """(curve name, where it came from): --curve, --set curve=, the preset's environment_specular table, the file's
    lutbake record, else linear (said so)."""
    sets = dict(o.split("=", 1) for o in overrides or () if "=" in o)
    if curve or "curve" in sets:
        name, where = curve or sets["curve"], "--curve" if curve else "--set curve"
    elif preset:
        from .environment import engine_keys

        engine = preset.removesuffix("-ibl")
        keys = engine_keys(engine).get("environment_specular", {})
        name, where = keys.get("curve", "linear"), f"preset {engine}-ibl"
    elif cube_file.record and isinstance(cube_file.record.get("mip_curve"), str):
        name, where = cube_file.record["mip_curve"].split(":")[0], "the file's lutbake record"
    else:
        name, where = "linear", "no curve named: linear assumed (--curve NAME)"
    if name not in curves.CURVES:
        raise ValueError(f"curve must be one of {', '.join(curves.CURVES)}, got {name!r}")
    return name, where


def audit_cube(
    path, preset: str | None = None, curve: str | None = None, overrides=None, max_lmax: int = MAX_LMAX, threads=None
) -> CubeAudit:
    """The audit of the cube map at ``path`` (module docstring); ValueError for a file or option it cannot take."""
    import os

    cube_file = read_cube(path)
    threads = threads or os.cpu_count() or 1
    if len(cube_file.mips) == 1:
        return audit_irradiance(cube_file)
    name, where = resolve_curve(cube_file, preset, curve, overrides)
    return audit_specular(cube_file, name, where, max_lmax, threads)
