"""Claims C1-C3 of the offline phase: the tissue model (Table I), the residual
against palpation time (Fig. 3) and the ribs in the kappa map (Fig. 4).
"""

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy.stats import spearmanr

from vic_drake.analysis.claims.claim import Claim, two_sided
from vic_drake.analysis.claims.thresholds import (
    C2_MAX_RATIO,
    C2_MAX_SPEARMAN,
    C2_MIN_R2,
    C3_MIN_RIB_SPACING_M,
    C3_MIN_STRONG_RIBS,
)
from vic_drake.analysis.ribs import (
    RIB_MIN_PROMINENCE,
    RIB_STRONG_PROMINENCE,
    RIB_WEAK_FRACTION,
)
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation.residual import fit_exponential
from vic_drake.paper import BEST_BETA, paper_table_i


@dataclass(frozen=True)
class ModelResiduals:
    """Relative fit residuals of the tissue models on the same palpations.

    Attributes:
        kelvin_voigt: relative RMS residual of the Kelvin-Voigt fit.
        hunt_crossley: {beta: relative RMS residual of the HC fit at beta}.
    """

    kelvin_voigt: float
    hunt_crossley: Mapping[float, float]

    def __post_init__(self):
        if not self.hunt_crossley:
            raise VicDrakeError("ModelResiduals.hunt_crossley needs at least one beta")
        values = [self.kelvin_voigt, *self.hunt_crossley.values()]
        if not all(np.isfinite(v) and v >= 0 for v in values):
            raise VicDrakeError(
                f"ModelResiduals: residuals must be finite and >= 0, got {values}"
            )

    def as_dict(self) -> dict:
        out = {"kelvin_voigt": self.kelvin_voigt}
        for beta in sorted(self.hunt_crossley, reverse=True):  # Table I order
            out[f"hc_{beta:g}"] = self.hunt_crossley[beta]
        return out


def _c1_side(res: ModelResiduals) -> tuple[dict, bool]:
    betas = sorted(res.hunt_crossley)
    best = min(betas, key=lambda b: res.hunt_crossley[b])
    hc_best = res.hunt_crossley[best]
    value = {
        **res.as_dict(),
        "best_beta": best,
        "hc_all_below_kv": all(res.hunt_crossley[b] < res.kelvin_voigt for b in betas),
    }
    ok = hc_best < res.kelvin_voigt and abs(best - BEST_BETA) < 1e-9
    return value, bool(ok)


def claim_c1(
    sim: ModelResiduals | None,
    real: ModelResiduals | None,
    *,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C1: HC beats KV and beta = 1.35 is the best of the betas tried.

    Passes on a side when the best HC residual is below KV's and the best
    beta is 1.35.
    """
    sv, sp = _c1_side(sim) if sim is not None else (None, None)
    rv, rp = _c1_side(real) if real is not None else (None, None)
    detail = (
        "relative RMS residuals; pass: min over beta of HC < KV and argmin beta = 1.35"
    )
    return two_sided(
        "C1",
        paper_table_i(),
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )


def residual_decay(duration_s, residual) -> dict:
    """Fits r(T) = c + a exp(-T / tau) to residual vs palpation time.

    The fit is :func:`vic_drake.estimation.palpation.fit_exponential`, the
    one that Fig. 3 draws, so the figure and claims.json give one number
    per fitted quantity.

    Args:
        duration_s: (n,) palpation lengths, s (n >= 4).
        residual: (n,) residual at each length.

    Returns:
        dict: tau_s, a, c, r2 (of the exponential model), spearman (rank
        correlation of residual with time), ratio_last_first.
    """
    t = np.asarray(duration_s, float)
    r = np.asarray(residual, float)
    if t.shape != r.shape or t.ndim != 1 or t.size < 4:
        raise VicDrakeError(
            f"residual_decay needs two 1-D arrays of the same length >= 4; got shapes "
            f"{t.shape} and {r.shape}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(r))):
        raise VicDrakeError("residual_decay: duration_s and residual must be finite")
    order = np.argsort(t)
    t, r = t[order], r[order]
    rho = float(spearmanr(t, r)[0]) if np.ptp(r) > 0 else 0.0
    # The one exponential fit of Fig. 3 (the figure's legend shows the same).
    fit = fit_exponential(t, r)
    if fit is None:
        a, tau, c, r2 = np.nan, np.nan, np.nan, np.nan
    else:
        a, tau, c = fit.a, fit.tau_s, fit.c
        ss_res = float(np.sum((r - fit(t)) ** 2))
        ss_tot = float(np.sum((r - r.mean()) ** 2))
        r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else 0.0
    return {
        "tau_s": float(tau),
        "a": float(a),
        "c": float(c),
        "r2": float(r2),
        "spearman": rho,
        "ratio_last_first": float(r[-1] / r[0]) if r[0] != 0 else np.nan,
        "n_points": int(t.size),
    }


def _num(value) -> str:
    return "n/a" if value is None else f"{value:.2f}"


def c2_missed(d: Mapping) -> list[str]:
    """C2's criteria that one residual curve's metrics miss, in words (a value
    that is None, as in claims.json, or NaN misses its criterion)."""
    r2, rho, ratio, a = (d.get(k) for k in ("r2", "spearman", "ratio_last_first", "a"))
    missed = []
    if r2 is None or not r2 >= C2_MIN_R2:
        missed.append(f"R^2 {_num(r2)} (needs >= {C2_MIN_R2:g})")
    if rho is None or not rho <= C2_MAX_SPEARMAN:
        missed.append(f"Spearman {_num(rho)} (needs <= {C2_MAX_SPEARMAN:g})")
    if ratio is None or not ratio <= C2_MAX_RATIO:
        missed.append(f"last/first {_num(ratio)} (needs <= {C2_MAX_RATIO:g})")
    if a is None or not a > 0:
        missed.append("no falling amplitude")
    return missed


def _c2_pass(d: dict) -> bool:
    return not c2_missed(d)


def c2_decay(curves) -> tuple:
    """C2's metric and verdict on one side's residual curves.

    Args:
        curves: (duration_s, residual) arrays, or {log name: (duration_s,
            residual)} (each log must pass), or None.

    Returns:
        (value, passed): :func:`residual_decay`'s dict (per log, each with
        its own ``pass``, for a mapping) and whether C2 holds; (None, None)
        for None.
    """
    if curves is None:
        return None, None
    if not isinstance(curves, Mapping):
        d = residual_decay(*curves)
        return d, _c2_pass(d)
    per_log = {name: residual_decay(*c) for name, c in curves.items()}
    for d in per_log.values():
        d["pass"] = _c2_pass(d)
    return per_log, all(d["pass"] for d in per_log.values())


def claim_c2(
    sim: tuple | None,
    real: tuple | None,
    *,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C2: residual vs palpation time falls about exponentially.

    Args:
        sim, real: (duration_s, residual) arrays, or {log name: (duration_s,
            residual)} (each log must pass), or None.

    Passes on a side when Spearman rho <= -0.8 and the exponential model has
    R^2 >= 0.9 with a positive amplitude.
    """

    sv, sp = c2_decay(sim)
    rv, rp = c2_decay(real)
    detail = (
        f"fit r(T)=c+a exp(-T/tau); pass: spearman <= {C2_MAX_SPEARMAN}, "
        f"R^2 >= {C2_MIN_R2}, a > 0, r(T_max)/r(T_min) <= {C2_MAX_RATIO} (every log)"
    )
    return two_sided(
        "C2",
        "residual decreases exponentially with palpation time; 5 s chosen",
        (sv, sp),
        (rv, rp),
        detail,
        reason_sim,
        reason_real,
    )


def _c3_pass(d: dict) -> bool:
    spacing_ok = (
        d.get("min_spacing_m") is None or d["min_spacing_m"] >= C3_MIN_RIB_SPACING_M
    )
    return bool(d["n_strong"] >= C3_MIN_STRONG_RIBS and d["n_weak"] >= 1 and spacing_ok)


def claim_c3(
    sim: dict | None,
    real: dict | None,
    *,
    reason_sim: str | None = None,
    reason_real: str | None = None,
) -> Claim:
    """C3: >= 3 ribs stand out in the kappa map and at least one is weaker.

    Args:
        sim, real: outputs of :func:`rib_prominences` (estimated map in
            simulation; the paper's measured map), or None.
    """
    detail = (
        f"ribs = peaks of the median-over-y kappa profile with prominence >= "
        f"{RIB_MIN_PROMINENCE:.0%} of median kappa; strong = prominence >= "
        f"{RIB_STRONG_PROMINENCE:.0%} of median kappa; weak = prominence <= "
        f"{RIB_WEAK_FRACTION:.0%} of the strong ribs' median; pass: >= "
        f"{C3_MIN_STRONG_RIBS} strong ribs, >= 1 weak rib, ribs >= "
        f"{C3_MIN_RIB_SPACING_M * 100:g} cm apart"
    )
    return two_sided(
        "C3",
        {
            "n_ribs": 4,
            "n_strong": 3,
            "n_weak": 1,
            "text": "4 stiff lines, 3 evident, 1 less "
            "(the rib covered by the pectoral muscle)",
        },
        (sim, _c3_pass(sim) if sim else None),
        (real, _c3_pass(real) if real else None),
        detail,
        reason_sim,
        reason_real,
    )
