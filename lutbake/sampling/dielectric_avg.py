"""Kind dielectric_avg's quadrature: E_avg(r, eta) = 2 ∫_0^1 E(mu) mu dmu per texel, by adaptive Gauss-Kronrod
panels in mu (lutbake.sampling.mu_average) over the dielectric integrand's E(mu) (lutbake.integrands.dielectric), its
inner rule (the E(mu) estimator) chosen once per plan from a probe; docs/transmission.md has the derivation and the
measured accuracy. lutbake.kinds.dielectric declares the kind; the layout record (lutbake.layouts) maps the averages
to its channels.
"""

from __future__ import annotations

import threading

import numpy as np

from ..edge import ALPHA_MIN, alpha_policy
from ..runtime.memo import RowMemo
from ..runtime.plan import TexelPlan
from . import points
from .mu_average import mu_averages, mu_target
from .plan import Grid, probe_indices

# kind dielectric_avg: while a texel's mu estimate (its panels' differences between the Kronrod and the Gauss rule of
# the mu_order pair) exceeds a quarter of its target, its worst panel is bisected, up to MU_MAX_PANELS panels. Inside
# the glass at small roughness E(mu) crosses the total-internal-reflection transition, ~alpha wide at cos theta_c, and
# E_T is not analytic at further points inside the glass (mu = eta among them: mu_starts): the fixed 16 nodes per panel
# of before were off by up to 2.0e-4 on OpenPBR's eta < 1 rows (alpha = 0.004)
MU_MAX_PANELS = 40
# inside the glass the first mu panels are also graded towards cos theta_c (mu_starts): Turquin's average 0.84x the mu
# evaluations, OpenPBR's 0.88x (docs/decisions.md)
MU_GRADE_MAX, MU_GRADE_RATIO = 0.25, 4.0
# kind dielectric_avg's inner rule (fixed-order Gauss-Legendre at the mu nodes, its error the probe's): without
# ``samples``, its order climbs from the default 12 by 4 (each order's refined rule, order + 4, is the next order) up
# to INNER_ORDER_MAX until the probe's share is within INNER_SHARE of the target at every probe texel (the mu rule's is
# within the other half: a quarter per kernel channel, at most two of them summed). Order 12 was the fixed default:
# Turquin's float32 average needs it (order 10: 1.53e-6 against 5e-7), OpenPBR's UNORM16 one would take 10 (1.47e-6
# against 1.9e-6) but the try costs as much as it saves, so the climb starts at 12 and tolerances tighter than order
# 12 reaches now climb instead of recording an estimate above them (tolerance 1e-7: 2.99e-7 at order 12 before)
INNER_ORDER_MAX = 32
INNER_SHARE = 0.5


def mu_starts(eta: float, alpha: float = 0.0) -> np.ndarray:
    """The first mu panel ends of kind dielectric_avg: 0, 0.2, 1 and, for eta < 1, cos theta_c = sqrt(1 - eta^2)
    (where E(mu) has its total-internal-reflection kink in the smooth limit) and mu = eta = sin theta_c, where
    theta_v + theta_c = pi/2: the outer cut theta_h = theta_v + theta_c of the dielectric estimator (phi_c,
    lutbake.sampling.dielectric) enters the hemisphere there and E(mu) is not analytic (rough texels bisected
    around it: 11 % of turquin_dielectric_e_avg's mu nodes). For eta < 1 off the mirror limit (alpha >= ALPHA_MIN,
    lutbake.edge: the mirror's kink is the cos theta_c end itself) the panels are also graded towards cos theta_c,
    ends at cos theta_c +- alpha MU_GRADE_RATIO^k below MU_GRADE_MAX: the transition there is ~alpha wide, which
    bisection from the first panels reached only after up to 16 halvings of 30 evaluations each."""
    cuts = [0.0, 0.2, 1.0]
    if eta < 1.0:
        c = float(np.sqrt(1.0 - eta * eta))
        cuts += [c, float(eta)]
        w = float(alpha)
        while ALPHA_MIN <= w < MU_GRADE_MAX:
            cuts += [c - w, c + w]
            w *= MU_GRADE_RATIO
    return np.unique(np.clip(cuts, 0.0, 1.0))


def average_plan(integrand, estimator, axes, alpha, eta, layout, order: int, tol, climb: bool, terms: dict):
    """E_avg per (eta, roughness) texel of ``layout`` (a lutbake.layouts Layout record of kind dielectric_avg): the
    kernel at the nodes of its mu panels, reduced 2 sum w mu E per texel (the node set depends on eta, so the
    reduction is here rather than in lutbake.sampling.plan.Grid). ``estimator``: the inner rule, its panels merged
    as the adaptive kernel's (its error is the probe's: inner_rule); ``climb``: its order climbs (INNER_ORDER_MAX)
    until the probe fits the tolerance ``tol``; ``order``: the mu rule's Gauss order. The layout maps the averages
    (E_R, E_T, E(F = 1)) to its channels (``stored``) and, with ``mirror_ratio``, adds a channel from each texel's
    mirror row (OpenPBR's reflection ratio)."""
    x_mu, w_kronrod, _ = points.gauss_kronrod(order)
    ratio = layout.mirror_ratio
    starts = [mu_starts(float(e), float(a)) for e, a in zip(eta, alpha)]
    grid = Grid(axes, {"alpha": alpha}, alpha=np.asarray(alpha, np.float64))
    n_channels = len(layout.channels)

    def e_at(t, mu, est, device):
        """E(mu) (len(mu), 3) of texels t (one per mu), one launch."""
        inputs = {
            "nov": mu.astype(np.float32),
            "alpha": integrand.alpha_input(alpha[t]),
            "param": eta[t].astype(np.float32),
        }
        return est.evaluate(integrand, inputs, device)

    def first_panels(t):
        """(owner, lo, hi): the mu_starts panels of texels t, owner = the texel's position in t."""
        ends = [starts[i] for i in t]
        owner = np.concatenate([[j] * (len(e) - 1) for j, e in enumerate(ends)]).astype(int)
        return owner, np.concatenate([e[:-1] for e in ends]), np.concatenate([e[1:] for e in ends])

    # the inner rule (chosen once per plan, by one thread: inner_rule) and E at the probe texels' first-panel nodes at
    # its order, which the table's first pass takes instead of computing them again (the same inputs, the same bits)
    chosen: dict = {}
    known: dict[tuple[int, float], np.ndarray] = {}
    lock = threading.Lock()

    def inner_rule(device):
        """(estimator, inner estimate, text): the inner rule's share, 2 Σ W mu |E - E_refined| over the Kronrod nodes
        of the first panels (mu_starts) of the probe texels, per texel through the layout's channels (energy_errors).
        It bounds |2 ∫ mu (E - E_refined) dmu| whatever nodes the mu rule ends on (2 ∫ mu dmu = 1: an error of E at
        every mu moves the average by at most its mu-weighted mean), so it needs neither the bisection nor the
        refined rule's own panels. With ``climb``, the first order of 12, 16, ... INNER_ORDER_MAX (each order's
        refined rule the next) whose share is within INNER_SHARE of every probe texel's target (max(tolerance,
        relative_tolerance |v|), v its first-pass average, the worst channel, as the mu rule's)."""
        with lock:
            if chosen:
                return chosen["est"], chosen["inner"], chosen["how"]
            idx = probe_indices(grid)
            owner, lo, hi = first_panels(idx)
            mu = (lo[:, None] + (hi - lo)[:, None] * x_mu).ravel()
            tt = np.repeat(idx[owner], len(x_mu))
            w = (2.0 * np.repeat(hi - lo, len(x_mu)) * mu * np.tile(w_kronrod, len(lo)))[:, None]
            rows = np.repeat(owner, len(x_mu))
            est = estimator
            e = e_at(tt, mu, est, device)
            total = np.zeros((len(idx), e.shape[1]))
            np.add.at(total, rows, e * w)
            target = INNER_SHARE * np.maximum(tol.absolute, tol.relative * np.min(np.abs(total), axis=1))
            while True:
                refined, how = est.refined()
                e_ref = e_at(tt, mu, refined, device)
                per_texel = np.zeros((len(idx), e.shape[1]))
                np.add.at(per_texel, rows, np.abs(e - e_ref) * w)
                err = energy_errors(per_texel)
                if not climb or np.all(err <= target[:, None]) or est.order >= INNER_ORDER_MAX:
                    break
                est, e = refined, e_ref
            known.update({(int(k), float(m)): v for k, m, v in zip(tt, mu, e)})
            chosen.update(est=est, inner=float(np.max(err)), how=how)
            return est, chosen["inner"], how

    def e_known(t, mu, est, device):
        """e_at, the rows the probe computed (the table's order) taken from it."""
        out = np.empty((len(t), 3))
        got = np.array([(int(k), float(m)) in known for k, m in zip(t, mu)], bool)
        if np.any(got):
            out[got] = [known[(int(k), float(m))] for k, m in zip(t[got], mu[got])]
        if not np.all(got):
            out[~got] = e_at(t[~got], mu[~got], est, device)
        return out

    def averages(t, device):
        """(values, mu-rule estimates), (len(t), 3) float64 each: 2 ∫ E mu dmu of (E_R, E_T, E(F = 1)) at texels t by
        lutbake.sampling.mu_average from the panels of mu_starts, the mu rule to a quarter of the target
        (max(tolerance, relative_tolerance |v|) at the first pass's v, the worst channel: a layout's sum of two
        channels gets half); the inner rule's share is the probe's (inner_rule)."""
        est = inner_rule(device)[0]
        r = mu_averages(
            lambda tt, mu: (e_known(tt, mu, est, device), None),
            t,
            [starts[i] for i in t],
            order,
            mu_target(tol, 0.25),
            MU_MAX_PANELS,
        )
        return r.values, r.mu_error

    memo = RowMemo(capacity=len(alpha))

    def averages_once(t, device):
        """averages(t), each texel computed once per plan, by one thread (a texel another thread is computing is
        waited for): OpenPBR's tiles also need their mirror rows, another tile's texels (a texel's values do not
        depend on who computes them)."""
        return memo.run([int(k).to_bytes(8, "little") for k in t], lambda i: averages(t[i], device))

    def run(idx, device):
        """The channels of texels idx, then their mu-rule estimates (aux columns; OpenPBR's ratio: the bound of
        ratio_error)."""
        t = np.arange(len(alpha))[idx]
        if ratio is not None:
            mirror = ratio.mirror(t)
            avg, err = averages_once(t, device)  # its own texels first: another tile may need them
            avg_m, err_m = averages_once(mirror, device)
            ch, ch_m = layout.stored(avg), layout.stored(avg_m)
            ce, ce_m = energy_errors(err), energy_errors(err_m)
            x = ratio.ratio(ch[:, 0], ch_m[:, 0], eta[t])
            r_err = ratio.ratio_error(ch[:, 0], ch_m[:, 0], ce[:, 0], ce_m[:, 0], eta[t])
            return np.concatenate([ch, x[:, None], ce, r_err[:, None]], axis=1)
        avg, err = averages(t, device)
        return np.concatenate([layout.stored(avg), energy_errors(err)], axis=1)

    def energy_errors(err):
        """Bounds on the layout's energy channels from those on (E_R, E_T, E(F = 1)) (the triangle inequality)."""
        return layout.stored_error(err)

    def error_estimate(data: np.ndarray, device: str) -> tuple[float, str]:
        """The inner rule's share at the probe texels (inner_rule) plus the largest per-texel mu-rule estimate (the
        aux columns); OpenPBR's ratio (channel A) is reported apart (0/0-like where E_c,avg -> 0)."""
        full = data.reshape(len(alpha), -1)
        energy = 3
        idx = probe_indices(grid)
        _, inner, how = inner_rule(device)
        mu = float(np.max(full[:, n_channels : n_channels + energy]))
        text = (
            f"2 sum W mu |{how}| at the Kronrod nodes of the first mu panels of {len(idx)} strided probe texels "
            f"({inner:.3g}) + the largest per-texel mu-rule estimate, sum over bisected panels of "
            f"|Q(Kronrod {2 * order + 1}) - Q(Gauss {order})| ({mu:.3g})"
        )
        if ratio is not None:
            used = alpha >= ratio.alpha_min
            text += (
                f"; reflection ratio (A): mu-rule bound {float(np.max(full[used, n_channels + energy])):.3g} where "
                f"alpha >= {ratio.alpha_min:g} (OpenPBR's multiple-scattering lobe)"
            )
        return inner + mu, text

    per = int(estimator.samples({"nov": [0.0]})[0]) * 5 * (2 * order + 1)  # nominal: 5 panels
    return TexelPlan(
        axes=axes,
        channels=layout.channels,
        reconstruction=layout.reconstruction(),
        n_texels=len(alpha),
        n_channels=n_channels,
        run_tile=lambda s, e, d: run(slice(s, e), d),
        prepare=lambda d: (estimator.prepare(integrand, d), inner_rule(d)),
        samples=per,
        aux_channels=n_channels,
        estimator=estimator.name,
        terms=terms,
        cost=float(len(alpha)) * per,
        extra={
            "mu_quadrature": f"Gauss-Kronrod ({order}, {2 * order + 1}) per panel from mu = 0, 0.2, 1 and, for "
            f"eta < 1, eta and cos theta_c; the worst panel bisected until the sum of |Kronrod - Gauss| is within "
            f"tol / 4 (at most {MU_MAX_PANELS} panels)",
            "tolerance": tol.text(),
            "alpha_policy": alpha_policy(True),
            **layout.extra,
        },
        error_estimate=error_estimate,
    )
