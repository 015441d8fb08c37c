"""The paper's claims, each a metric computed from logs, with a pass/fail.

Every claim of the paper that vic_drake reproduces is a pure function here.
It takes the results of the pipeline's stages (fit residuals, a kappa map,
per-scan metrics reduced from logged signals) for the simulation and, where
the paper's measurements exist, for the real rig, and returns a
:class:`Claim`: the statement, the paper's value, the simulated value, the
real value and whether the claim holds. A side that could not be evaluated
(no data, a stage that failed) is ``None`` with the reason in ``detail``; it
never counts as a pass, and a claim with no evaluated side fails.

``pass`` is True when the simulated side was evaluated and passes and the
real side, where evaluated, passes too (the reproduction must show the
claim; the real logs must not contradict it). ``pass_sim`` and ``pass_real`` give each side's verdict (None when
not evaluated).

Thresholds are module constants; each comment says why that number.

Scan DataFrames use the canonical columns of :mod:`vic_drake.experiments`
(``t_s``, ``z_d_m``, ``force_sensor_z_N`` with the sensor's sign, negative =
pressing, ``force_ref_z_N``, ``force_min_z_N``, ``penetration_m``,
``stiffness_z_N_per_m``, ``tank_energy_J``, ``tank_power_W``);
:func:`scan_metrics` reduces one to the numbers the claims need.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError

# --- Thresholds (each with why) --------------------------------------------

#: The exponent the paper found best (Table I).
BEST_BETA = 1.35
#: C2: Spearman rank correlation of residual vs palpation time must be at most
#: this: "falls" means a clear monotone trend, not noise around a constant.
C2_MAX_SPEARMAN = -0.8
#: C2: the exponential model r(T) = c + a exp(-T/tau) must explain at least
#: this fraction of the variance ("about exponentially", Fig. 3).
C2_MIN_R2 = 0.9
#: C2: the residual at the longest palpation must be at most this fraction of
#: the shortest one's: a fall, not a flat curve with a monotone wiggle (the
#: paper's Fig. 3 falls several-fold).
C2_MAX_RATIO = 0.8
#: C3: a kappa peak counts as a rib when its prominence (above the higher of
#: its two neighbouring troughs) is at least this fraction of the map's median
#: kappa; the measured map's weakest rib (under the muscle) has ~9 %, texture
#: bumps of the soft tissue less than 3 %.
C3_MIN_RIB_PROMINENCE = 0.05
#: C3: a rib "stands out" when its prominence is at least this fraction of the
#: map's median kappa (a clearly visible line in a colour map of kappa).
C3_STRONG_RELATIVE = 0.15
#: C3: a rib is "less" evident when its prominence is at most this fraction of
#: the median prominence of the standing-out ribs; the paper sees three evident
#: lines and one less.
C3_WEAK_FRACTION = 0.5
#: C3: the paper's counts: three evident ribs and at least one weaker one.
C3_MIN_STRONG_RIBS = 3
#: C3: neighbouring ribs are at least this far apart (m); closer peaks are
#: texture or an over-fitted map, not ribs (the chest's ribs are ~4 cm apart,
#: intercostal spaces >= 2 cm).
C3_MIN_RIB_SPACING_M = 0.02
#: C4: VS-CF's force RMSE may exceed CF's by at most 20 % (the issue's
#: "about as well as CF").
C4_MAX_RMSE_RATIO = 1.2
#: C5: the CS force range over the scan must be at least twice VS-CF's.
C5_MIN_RANGE_RATIO = 2.0
#: C6: median |penetration - eps_d| off the ribs at most 3 mm: the real
#: controller's penetration is measured against the map surface, whose offset
#: (2.5 mm) and GRIDFIT error are of that order.
C6_MAX_PEN_ERROR_M = 0.003
#: C6: over the ribs the 99th percentile of the pressing force may exceed
#: |F_min| by at most 10 % (FDCC tracks the QP's force bound with a lag).
C6_FORCE_CAP_TOL = 0.10
#: C7: during contact loss the stiffness must be within this of K_min (N/m);
#: 5 % of the paper's 100 N/m.
C7_K_MIN_TOL_N_PER_M = 5.0
#: C7: fraction of the contact-loss time (after the first C7_LOSS_SETTLE_S of
#: each interval) that K must spend at K_min.
C7_MIN_FRACTION_AT_K_MIN = 0.9
#: C7: seconds K may take to fall to K_min after contact is lost (the QP
#: lowers it within a tick; FDCC and sensor lags add a little).
C7_LOSS_SETTLE_S = 0.2
#: C7: the tank's power may exceed the valve's limit by this fraction: the
#: real controller takes dt from timestamps, which jitter by a few percent.
C7_POWER_TOL = 0.10
#: C7: the tank energy may dip below T_min by this much (J), numerical slack.
C7_TANK_TOL_J = 1e-6
#: Contact: pressing force above this (N), as the real controller decided.
CONTACT_THRESHOLD_N = 0.5
#: A contact-loss interval shorter than this (s) is chatter, not a loss.
MIN_LOSS_S = 0.1

# The paper's values (Table I and the text of Sec. III).
PAPER_TABLE_I = {"kelvin_voigt": 0.066, "hc_1.5": 0.029, "hc_1.35": 0.014, "hc_1.1": 0.045}

STATEMENTS = {
    "C1": "Hunt-Crossley fits the palpation forces better than Kelvin-Voigt; "
    "beta = 1.35 is the best of the three exponents (Table I).",
    "C2": "The fit residual falls about exponentially with palpation time (Fig. 3).",
    "C3": "The ribs stand out in the kappa map; the rib under the pectoral "
    "muscle less than the others (Fig. 4).",
    "C4": "VS-CF tracks its force reference about as well as CF (force RMSE "
    "within 20 % of CF's) while keeping position control: it lifts off at the "
    "end; CF cannot (Fig. 6).",
    "C5": "The CS force follows the body's shape: its force range over the scan "
    "is at least twice VS-CF's.",
    "C6": "VS-VF holds the penetration near eps_d off the ribs and caps the force "
    "at F_min over them (Fig. 6).",
    "C7": "Under the disturbance K falls to K_min while contact is lost, its rise "
    "at re-contact is limited by the power valve, T >= T_min throughout, and the "
    "peak force of VS-VF is lower than CS's and CF's (Fig. 7).",
}


@dataclass(frozen=True)
class Claim:
    """One claim's verdict.

    Attributes:
        id: "C1" ... "C7".
        statement: what the paper claims, as checked here.
        paper: the paper's value (number, dict or text).
        sim: the simulated value (dict of metrics) or None if not evaluated.
        real: the value in the real logs or None where no log exists.
        pass_sim: the simulated side's verdict, None if not evaluated.
        pass_real: the real side's verdict, None if not evaluated.
        detail: thresholds used and reasons for any side not evaluated.
    """

    id: str
    statement: str
    paper: Any
    sim: Any
    real: Any
    pass_sim: bool | None
    pass_real: bool | None
    detail: str = ""

    @property
    def passed(self) -> bool:
        return bool(self.pass_sim) and self.pass_real is not False

    def to_dict(self) -> dict:
        return {
            "statement": self.statement,
            "paper": self.paper,
            "sim": self.sim,
            "real": self.real,
            "pass": self.passed,
            "pass_sim": self.pass_sim,
            "pass_real": self.pass_real,
            "detail": self.detail,
        }


def claims_to_json_dict(claims: Sequence[Claim]) -> dict:
    """{"C1": {...}, ...} as written to claims.json."""
    return {c.id: c.to_dict() for c in claims}


def _clean(value):
    """Plain Python numbers (floats rounded to 6 significant digits)."""
    if isinstance(value, Mapping):
        return {str(k): _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return float(f"{v:.6g}") if np.isfinite(v) else None
    return value


def _not_evaluated(reason_sim: str | None, reason_real: str | None) -> str:
    parts = []
    if reason_sim:
        parts.append(f"sim not evaluated: {reason_sim}")
    if reason_real:
        parts.append(f"real not evaluated: {reason_real}")
    return "; ".join(parts)


# --- C1: model comparison ---------------------------------------------------


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
            raise VicDrakeError(f"ModelResiduals: residuals must be finite and >= 0, got {values}")

    def as_dict(self) -> dict:
        out = {"kelvin_voigt": self.kelvin_voigt}
        for beta in sorted(self.hunt_crossley):
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


def claim_c1(sim: ModelResiduals | None, real: ModelResiduals | None, *,
             reason_sim: str | None = None, reason_real: str | None = None) -> Claim:
    """C1: HC beats KV and beta = 1.35 is the best of the betas tried.

    Passes on a side when the best HC residual is below KV's and the best
    beta is 1.35.
    """
    sv, sp = _c1_side(sim) if sim is not None else (None, None)
    rv, rp = _c1_side(real) if real is not None else (None, None)
    detail = "relative RMS residuals; pass: min over beta of HC < KV and argmin beta = 1.35"
    extra = _not_evaluated(reason_sim if sim is None else None,
                           reason_real if real is None else None)
    return Claim("C1", STATEMENTS["C1"], PAPER_TABLE_I, _clean(sv), _clean(rv), sp, rp,
                 "; ".join(p for p in (detail, extra) if p))


# --- C2: residual vs palpation time ----------------------------------------


def residual_decay(duration_s, residual) -> dict:
    """Fits r(T) = c + a exp(-T / tau) to residual vs palpation time.

    Args:
        duration_s: (n,) palpation lengths, s (n >= 4).
        residual: (n,) residual at each length.

    Returns:
        dict: tau_s, a, c, r2 (of the exponential model), spearman (rank
        correlation of residual with time), ratio_last_first.
    """
    from scipy.optimize import curve_fit
    from scipy.stats import spearmanr

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
    span = max(float(np.ptp(t)), 1e-9)

    def model(tt, a, tau, c):
        return c + a * np.exp(-tt / tau)

    p0 = (max(r[0] - r[-1], 1e-9), span / 3, r[-1])
    try:
        (a, tau, c), _ = curve_fit(model, t, r, p0=p0, bounds=([0, 1e-6, -np.inf], [np.inf, 1e3 * span, np.inf]), maxfev=20000)
        pred = model(t, a, tau, c)
        ss_res = float(np.sum((r - pred) ** 2))
        ss_tot = float(np.sum((r - r.mean()) ** 2))
        r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else 0.0
    except (RuntimeError, ValueError):
        a, tau, c, r2 = np.nan, np.nan, np.nan, np.nan
    return {
        "tau_s": float(tau),
        "a": float(a),
        "c": float(c),
        "r2": float(r2),
        "spearman": rho,
        "ratio_last_first": float(r[-1] / r[0]) if r[0] != 0 else np.nan,
        "n_points": int(t.size),
    }


def _c2_pass(d: dict) -> bool:
    return bool(
        d["spearman"] <= C2_MAX_SPEARMAN
        and np.isfinite(d["r2"])
        and d["r2"] >= C2_MIN_R2
        and d["a"] > 0
        and d["ratio_last_first"] <= C2_MAX_RATIO
    )


def claim_c2(sim: tuple | None, real: tuple | None, *, reason_sim: str | None = None,
             reason_real: str | None = None) -> Claim:
    """C2: residual vs palpation time falls about exponentially.

    Args:
        sim, real: (duration_s, residual) arrays, or {log name: (duration_s,
            residual)} (each log must pass), or None.

    Passes on a side when Spearman rho <= -0.8 and the exponential model has
    R^2 >= 0.9 with a positive amplitude.
    """
    def side(curves):
        if curves is None:
            return None, None
        if not isinstance(curves, Mapping):
            d = residual_decay(*curves)
            return d, _c2_pass(d)
        per_log = {name: residual_decay(*c) for name, c in curves.items()}
        for d in per_log.values():
            d["pass"] = _c2_pass(d)
        return per_log, all(d["pass"] for d in per_log.values())

    sv, sp = side(sim)
    rv, rp = side(real)
    detail = (f"fit r(T)=c+a exp(-T/tau); pass: spearman <= {C2_MAX_SPEARMAN}, "
              f"R^2 >= {C2_MIN_R2}, a > 0, r(T_max)/r(T_min) <= {C2_MAX_RATIO} (every log)")
    extra = _not_evaluated(reason_sim if sim is None else None,
                           reason_real if real is None else None)
    return Claim("C2", STATEMENTS["C2"],
                 "residual decreases exponentially with palpation time; 5 s chosen",
                 _clean(sv), _clean(rv), sp, rp,
                 "; ".join(p for p in (detail, extra) if p))


# --- C3: ribs in the kappa map ----------------------------------------------


def rib_prominences(x_m, y_m, kappa, *, across: str = "x") -> dict:
    """Finds the ribs as peaks of the kappa profile across them.

    The ribs run along y on the phantom (a scan along x crosses them), so the
    profile is the median of kappa over y at each x.

    Args:
        x_m: (nx,) grid axis, m.
        y_m: (ny,) grid axis, m.
        kappa: (nx, ny) Hunt-Crossley elasticity.
        across: axis the ribs are crossed along ("x" or "y").

    Returns:
        dict: rib_x_m (peak positions), prominence (absolute), relative
        (prominence / median kappa), n_ribs, n_strong, n_weak,
        weakest_to_median_strong, median_kappa.
    """
    from scipy.signal import find_peaks

    x = np.asarray(x_m, float)
    y = np.asarray(y_m, float)
    k = np.asarray(kappa, float)
    if k.shape != (x.size, y.size):
        raise VicDrakeError(
            f"rib_prominences: kappa has shape {k.shape}; expected (len(x), len(y)) = "
            f"({x.size}, {y.size})"
        )
    if across not in ("x", "y"):
        raise VicDrakeError(f"rib_prominences: across must be 'x' or 'y', got {across!r}")
    axis, prof = (x, np.median(k, axis=1)) if across == "x" else (y, np.median(k, axis=0))
    median = float(np.median(k))
    peaks, props = find_peaks(prof, prominence=C3_MIN_RIB_PROMINENCE * median)
    prom = props["prominences"]
    rel = prom / median
    strong = rel >= C3_STRONG_RELATIVE
    ref = np.median(prom[strong]) if strong.any() else np.nan
    weak = prom <= C3_WEAK_FRACTION * ref if strong.any() else np.zeros(prom.size, bool)
    return {
        "rib_position_m": axis[peaks].tolist(),
        "prominence": prom.tolist(),
        "relative": rel.tolist(),
        "n_ribs": int(peaks.size),
        "n_strong": int((strong & ~weak).sum()),
        "n_weak": int(weak.sum()),
        "weakest_to_median_strong": float(prom.min() / ref) if strong.any() else None,
        "min_spacing_m": float(np.min(np.diff(np.sort(axis[peaks])))) if peaks.size > 1
        else None,
        "median_kappa": median,
    }


def _c3_pass(d: dict) -> bool:
    spacing_ok = d.get("min_spacing_m") is None or d["min_spacing_m"] >= C3_MIN_RIB_SPACING_M
    return bool(d["n_strong"] >= C3_MIN_STRONG_RIBS and d["n_weak"] >= 1 and spacing_ok)


def claim_c3(sim: dict | None, real: dict | None, *, reason_sim: str | None = None,
             reason_real: str | None = None) -> Claim:
    """C3: >= 3 ribs stand out in the kappa map and at least one is weaker.

    Args:
        sim, real: outputs of :func:`rib_prominences` (estimated map in
            simulation; the paper's measured map), or None.
    """
    detail = (f"ribs = peaks of the median-over-y kappa profile with prominence >= "
              f"{C3_MIN_RIB_PROMINENCE:.0%} of median kappa; strong = prominence >= "
              f"{C3_STRONG_RELATIVE:.0%} of median kappa; weak = prominence <= "
              f"{C3_WEAK_FRACTION:.0%} of the strong ribs' median; pass: >= "
              f"{C3_MIN_STRONG_RIBS} strong ribs, >= 1 weak rib, ribs >= "
              f"{C3_MIN_RIB_SPACING_M * 100:g} cm apart")
    extra = _not_evaluated(reason_sim if sim is None else None,
                           reason_real if real is None else None)
    return Claim("C3", STATEMENTS["C3"],
                 {"n_ribs": 4, "n_strong": 3, "n_weak": 1, "text": "4 stiff lines, 3 evident, 1 less "
                  "(the rib covered by the pectoral muscle)"},
                 _clean(sim), _clean(real),
                 _c3_pass(sim) if sim else None, _c3_pass(real) if real else None,
                 "; ".join(p for p in (detail, extra) if p))


# --- Scan metrics -----------------------------------------------------------


@dataclass(frozen=True)
class ScanLimits:
    """Controller settings the scan claims compare against.

    Attributes:
        k_min_z_N_per_m: minimum z stiffness K_min.
        tank_min_J: T_min.
        power_max_W: the power valve's limit P_max (> 0).
        eps_d_m: VS-VF's desired penetration.
    """

    k_min_z_N_per_m: float = 100.0
    tank_min_J: float = 0.4
    power_max_W: float = 0.1
    eps_d_m: float = 0.008


REQUIRED_SCAN_COLUMNS = ("t_s", "z_d_m", "force_sensor_z_N")


def _intervals(mask: np.ndarray, t: np.ndarray) -> list[tuple[int, int]]:
    """[start, stop) index ranges where mask is True."""
    m = np.concatenate([[False], mask, [False]]).astype(int)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1)))


def scan_window(df: pd.DataFrame, *, settle_s: float = 1.0) -> np.ndarray:
    """Boolean mask of the scan phase: after first contact + settle_s, with the
    target at its scanning height (within 1 mm of the median target height of
    the in-contact samples), before the final lift of the target."""
    t = df["t_s"].to_numpy()
    f = -df["force_sensor_z_N"].to_numpy()
    zd = df["z_d_m"].to_numpy()
    contact = f > CONTACT_THRESHOLD_N
    if not contact.any():
        return np.zeros(len(df), bool)
    t_contact = t[np.argmax(contact)]
    z_scan = np.median(zd[contact])
    at_height = np.abs(zd - z_scan) < 1e-3
    # The scan ends where the target last leaves its scanning height.
    last = np.flatnonzero(at_height)[-1]
    window = at_height & (t >= t_contact + settle_s)
    window[last + 1:] = False
    return window


def scan_metrics(df: pd.DataFrame, *, limits: ScanLimits = ScanLimits(),
                 settle_s: float = 1.0, end_s: float = 0.5) -> dict:
    """Reduces one scan log to the numbers the claims C4-C7 need.

    Args:
        df: canonical scan DataFrame (see module docstring); optional columns
            are used where present.
        limits: controller settings (K_min, T_min, P_max, eps_d).
        settle_s: seconds after first contact excluded from the scan window.
        end_s: length of the final segment checked for lift-off, s.

    Returns:
        dict with force_rmse_N (pressing force vs reference over the scan
        window; only when the reference is nonzero there), force_range_N (98th - 2nd percentile of the pressing force in
        the window), peak_force_N (whole run), lifted_off (mean pressing force
        of the last end_s below the contact threshold), and where the columns
        exist: penetration / force-cap metrics (C6), contact-loss, stiffness
        and tank metrics (C7).
    """
    missing = [c for c in REQUIRED_SCAN_COLUMNS if c not in df.columns]
    if missing:
        raise VicDrakeError(f"scan_metrics: DataFrame lacks columns {missing}; "
                            f"needs {list(REQUIRED_SCAN_COLUMNS)}")
    if len(df) < 10:
        raise VicDrakeError(f"scan_metrics: the log has {len(df)} rows; needs >= 10")
    t = df["t_s"].to_numpy(float)
    f = -df["force_sensor_z_N"].to_numpy(float)
    w = scan_window(df, settle_s=settle_s)
    out: dict[str, Any] = {"duration_s": float(t[-1] - t[0]), "n_window": int(w.sum())}
    out["peak_force_N"] = float(np.max(f))
    end = t >= t[-1] - end_s
    out["final_force_N"] = float(np.mean(f[end]))
    out["lifted_off"] = bool(out["final_force_N"] < CONTACT_THRESHOLD_N)
    if w.sum() >= 10:
        fw = f[w]
        lo, hi = np.percentile(fw, [2, 98])
        out["force_range_N"] = float(hi - lo)
        out["force_mean_N"] = float(np.mean(fw))
        if "force_ref_z_N" in df.columns:
            ref = -df["force_ref_z_N"].to_numpy(float)[w]
            # Only a controller with a force reference (CF, VS-CF, VS-VF) has a
            # tracking error; CS's reference column is zero.
            if np.any(np.abs(ref) > 0):
                out["force_rmse_N"] = float(np.sqrt(np.mean((fw - ref) ** 2)))
    # C6: penetration off the ribs, force over the ribs (where the cap binds).
    if {"force_ref_z_N", "force_min_z_N", "penetration_m"} <= set(df.columns) and w.sum():
        ref = -df["force_ref_z_N"].to_numpy(float)
        cap = -df["force_min_z_N"].to_numpy(float)
        pen = df["penetration_m"].to_numpy(float)
        off = w & (ref < 0.9 * cap)
        on = w & (ref > cap)
        out["n_off_ribs"] = int(off.sum())
        out["n_on_ribs"] = int(on.sum())
        if off.sum() >= 10:
            err = np.abs(pen[off] - limits.eps_d_m)
            out["penetration_off_ribs_median_m"] = float(np.median(pen[off]))
            out["penetration_error_off_ribs_median_m"] = float(np.median(err))
        if on.sum() >= 10:
            out["force_on_ribs_p99_N"] = float(np.percentile(f[on], 99))
            out["force_cap_N"] = float(np.median(cap[on]))
    # C7: contact loss, stiffness, tank.
    if w.any():
        i0 = np.argmax(w)
        i1 = len(w) - np.argmax(w[::-1])
        seg = np.zeros(len(t), bool)
        seg[i0:i1] = True
        lost = seg & (f <= CONTACT_THRESHOLD_N)
        losses = [(a, b) for a, b in _intervals(lost, t) if t[b - 1] - t[a] >= MIN_LOSS_S]
        out["n_contact_losses"] = len(losses)
        out["contact_loss_s"] = float(sum(t[b - 1] - t[a] for a, b in losses))
        if losses and "stiffness_z_N_per_m" in df.columns:
            k = df["stiffness_z_N_per_m"].to_numpy(float)
            sel = np.zeros(len(t), bool)
            for a, b in losses:
                sel[a:b] = t[a:b] >= t[a] + C7_LOSS_SETTLE_S
            if sel.any():
                at_min = k[sel] <= limits.k_min_z_N_per_m + C7_K_MIN_TOL_N_PER_M
                out["fraction_at_k_min_during_loss"] = float(at_min.mean())
                out["k_max_during_loss_N_per_m"] = float(k[sel].max())
    if "tank_energy_J" in df.columns:
        out["tank_min_J"] = float(df["tank_energy_J"].min())
    if "tank_power_W" in df.columns:
        out["tank_power_min_W"] = float(df["tank_power_W"].min())
    if "stiffness_z_N_per_m" in df.columns:
        out["stiffness_z_max_N_per_m"] = float(df["stiffness_z_N_per_m"].max())
    return out


def _need(d: Mapping | None, *keys) -> bool:
    return d is not None and all(d.get(k) is not None for k in keys)


# --- C4 -----------------------------------------------------------------------


def _c4_side(vscf: Mapping | None, cf: Mapping | None):
    if not (_need(vscf, "force_rmse_N", "lifted_off") and _need(cf, "force_rmse_N", "lifted_off")):
        return None, None
    ratio = vscf["force_rmse_N"] / cf["force_rmse_N"] if cf["force_rmse_N"] > 0 else np.inf
    value = {
        "force_rmse_vs_cf_N": vscf["force_rmse_N"],
        "force_rmse_cf_N": cf["force_rmse_N"],
        "rmse_ratio": ratio,
        "vs_cf_lifted_off": vscf["lifted_off"],
        "cf_lifted_off": cf["lifted_off"],
    }
    ok = ratio <= C4_MAX_RMSE_RATIO and vscf["lifted_off"] and not cf["lifted_off"]
    return value, bool(ok)


def claim_c4(sim: Mapping[str, Mapping] | None, real: Mapping[str, Mapping] | None, *,
             reason_sim: str | None = None, reason_real: str | None = None) -> Claim:
    """C4: VS-CF's force RMSE <= 1.2 x CF's; VS-CF lifts off at the end, CF not.

    Args:
        sim, real: {"vs-cf": scan_metrics(...), "cf": scan_metrics(...)}.
    """
    sv, sp = _c4_side(*(sim.get(k) for k in ("vs-cf", "cf"))) if sim else (None, None)
    rv, rp = _c4_side(*(real.get(k) for k in ("vs-cf", "cf"))) if real else (None, None)
    detail = (f"RMSE of pressing force vs reference over the scan window; pass: ratio <= "
              f"{C4_MAX_RMSE_RATIO}, VS-CF final force < {CONTACT_THRESHOLD_N} N, CF's not")
    extra = _not_evaluated(reason_sim if sv is None else None,
                           reason_real if rv is None else None)
    return Claim("C4", STATEMENTS["C4"],
                 "VS-CF tracks the reference force as well as force control; only "
                 "VS-CF can lift off the surface", _clean(sv), _clean(rv), sp, rp,
                 "; ".join(p for p in (detail, extra) if p))


# --- C5 -----------------------------------------------------------------------


def _c5_side(cs: Mapping | None, vscf: Mapping | None):
    if not (_need(cs, "force_range_N") and _need(vscf, "force_range_N")):
        return None, None
    ratio = cs["force_range_N"] / vscf["force_range_N"] if vscf["force_range_N"] > 0 else np.inf
    value = {"force_range_cs_N": cs["force_range_N"],
             "force_range_vs_cf_N": vscf["force_range_N"], "range_ratio": ratio}
    return value, bool(ratio >= C5_MIN_RANGE_RATIO)


def claim_c5(sim: Mapping[str, Mapping] | None, real: Mapping[str, Mapping] | None, *,
             reason_sim: str | None = None, reason_real: str | None = None) -> Claim:
    """C5: CS's force range over the scan >= 2 x VS-CF's.

    Args:
        sim, real: {"cs": scan_metrics(...), "vs-cf": scan_metrics(...)}.
    """
    sv, sp = _c5_side(*(sim.get(k) for k in ("cs", "vs-cf"))) if sim else (None, None)
    rv, rp = _c5_side(*(real.get(k) for k in ("cs", "vs-cf"))) if real else (None, None)
    detail = ("force range = 98th - 2nd percentile of the pressing force over the scan "
              f"window; pass: ratio >= {C5_MIN_RANGE_RATIO}")
    extra = _not_evaluated(reason_sim if sv is None else None,
                           reason_real if rv is None else None)
    return Claim("C5", STATEMENTS["C5"],
                 "CS force strongly depends on the body's shape", _clean(sv), _clean(rv),
                 sp, rp, "; ".join(p for p in (detail, extra) if p))


# --- C6 -----------------------------------------------------------------------


def _c6_side(vsvf: Mapping | None):
    if not _need(vsvf, "penetration_error_off_ribs_median_m", "force_on_ribs_p99_N",
                 "force_cap_N"):
        return None, None
    value = {
        "penetration_off_ribs_median_m": vsvf.get("penetration_off_ribs_median_m"),
        "penetration_error_off_ribs_median_m": vsvf["penetration_error_off_ribs_median_m"],
        "force_on_ribs_p99_N": vsvf["force_on_ribs_p99_N"],
        "force_cap_N": vsvf["force_cap_N"],
        "n_on_ribs": vsvf.get("n_on_ribs"),
        "n_off_ribs": vsvf.get("n_off_ribs"),
    }
    ok = (vsvf["penetration_error_off_ribs_median_m"] <= C6_MAX_PEN_ERROR_M
          and vsvf["force_on_ribs_p99_N"] <= (1 + C6_FORCE_CAP_TOL) * vsvf["force_cap_N"])
    return value, bool(ok)


def claim_c6(sim: Mapping | None, real: Mapping | None, *, eps_d_m: float = 0.008,
             reason_sim: str | None = None, reason_real: str | None = None) -> Claim:
    """C6: VS-VF: median |eps - eps_d| off ribs <= 3 mm; force over ribs capped.

    Args:
        sim, real: scan_metrics(...) of the VS-VF scan (computed with
            limits.eps_d_m = eps_d_m).

    "Over the ribs" is where the force reference F_body(eps_d) exceeds
    |F_min| (the cap binds); "off the ribs" where it is below 0.9 |F_min|.
    """
    sv, sp = _c6_side(sim)
    rv, rp = _c6_side(real)
    detail = (f"eps_d = {eps_d_m * 1e3:g} mm; pass: median |eps - eps_d| off ribs <= "
              f"{C6_MAX_PEN_ERROR_M * 1e3:g} mm and p99 force on ribs <= "
              f"{1 + C6_FORCE_CAP_TOL:g} x |F_min|")
    extra = _not_evaluated(reason_sim if sv is None else None,
                           reason_real if rv is None else None)
    return Claim("C6", STATEMENTS["C6"],
                 {"eps_d_m": 0.008, "F_min_N": -9.0,
                  "text": "constant penetration tracked; the minimum force avoids pushing "
                  "too hard on the ribs"},
                 _clean(sv), _clean(rv), sp, rp, "; ".join(p for p in (detail, extra) if p))


# --- C7 -----------------------------------------------------------------------


def _c7_side(runs: Mapping[str, Mapping], limits: ScanLimits):
    vsvf, cs, cf = (runs.get(k) for k in ("vs-vf", "cs", "cf"))
    if not _need(vsvf, "peak_force_N", "tank_min_J", "tank_power_min_W"):
        return None, None
    value: dict[str, Any] = {
        "n_contact_losses": vsvf.get("n_contact_losses"),
        "contact_loss_s": vsvf.get("contact_loss_s"),
        "fraction_at_k_min_during_loss": vsvf.get("fraction_at_k_min_during_loss"),
        "tank_min_J": vsvf["tank_min_J"],
        "tank_power_min_W": vsvf["tank_power_min_W"],
        "peak_force_vs_vf_N": vsvf["peak_force_N"],
        "peak_force_cs_N": cs.get("peak_force_N") if cs else None,
        "peak_force_cf_N": cf.get("peak_force_N") if cf else None,
    }
    checks = {
        "contact_lost": (vsvf.get("n_contact_losses") or 0) >= 1,
        "k_at_min_when_lost": (vsvf.get("fraction_at_k_min_during_loss") or 0.0)
        >= C7_MIN_FRACTION_AT_K_MIN,
        "tank_above_min": vsvf["tank_min_J"] >= limits.tank_min_J - C7_TANK_TOL_J,
        "power_valve": vsvf["tank_power_min_W"]
        >= -(1 + C7_POWER_TOL) * limits.power_max_W,
        "peak_below_cs": value["peak_force_cs_N"] is not None
        and vsvf["peak_force_N"] < value["peak_force_cs_N"],
        "peak_below_cf": value["peak_force_cf_N"] is not None
        and vsvf["peak_force_N"] < value["peak_force_cf_N"],
    }
    value["checks"] = checks
    return value, bool(all(checks.values()))


def claim_c7(sim: Mapping[str, Mapping] | None, real: Mapping[str, Mapping] | None, *,
             limits: ScanLimits = ScanLimits(), reason_sim: str | None = None,
             reason_real: str | None = None) -> Claim:
    """C7: disturbance runs: K -> K_min when contact is lost, power valve holds,
    T >= T_min, and VS-VF's peak force is below CS's and CF's.

    Args:
        sim, real: {"vs-vf": ..., "cs": ..., "cf": ...} scan_metrics of the
            disturbance runs. The real side needs a VS-VF disturbance log,
            which the published data lacks; the CS and CF peaks are then
            reported in ``detail`` only.
    """
    sv, sp = _c7_side(sim, limits) if sim else (None, None)
    rv, rp = _c7_side(real, limits) if real else (None, None)
    detail = (f"K at min: K_z <= K_min + {C7_K_MIN_TOL_N_PER_M:g} N/m for >= "
              f"{C7_MIN_FRACTION_AT_K_MIN:.0%} of the loss time after {C7_LOSS_SETTLE_S:g} s; "
              f"valve: tank power >= -{1 + C7_POWER_TOL:g} P_max (P_max = "
              f"{limits.power_max_W:g} W); T >= T_min = {limits.tank_min_J:g} J")
    if rv is None and real:
        peaks = {k: v.get("peak_force_N") for k, v in real.items() if v}
        detail += f"; real peak forces without a VS-VF disturbance log: {_clean(peaks)}"
    extra = _not_evaluated(reason_sim if sv is None else None,
                           reason_real if rv is None else None)
    return Claim("C7", STATEMENTS["C7"],
                 "stiffness decreases to its minimum until re-contact; at re-contact the "
                 "valves limit its growth; the tank is not emptied",
                 _clean(sv), _clean(rv), sp, rp, "; ".join(p for p in (detail, extra) if p))


@dataclass
class ClaimInputs:
    """Everything the claims need, gathered by the pipeline (None = absent).

    The ``reasons`` dict maps "C1.sim", "C4.real", ... to why a side is absent.
    """

    residuals_sim: ModelResiduals | None = None
    residuals_real: ModelResiduals | None = None
    decay_sim: tuple | None = None
    decay_real: tuple | None = None
    ribs_sim: dict | None = None
    ribs_real: dict | None = None
    nominal_sim: dict | None = None  # {"cs": metrics, "cf": ..., "vs-cf": ..., "vs-vf": ...}
    nominal_real: dict | None = None
    disturbance_sim: dict | None = None  # {"vs-vf": ..., "cs": ..., "cf": ...}
    disturbance_real: dict | None = None
    limits: ScanLimits = field(default_factory=ScanLimits)
    reasons: dict = field(default_factory=dict)


def evaluate_claims(inp: ClaimInputs) -> list[Claim]:
    """All claims C1-C7 from the gathered inputs."""
    r = inp.reasons

    def why(cid, side):
        return r.get(f"{cid}.{side}") or r.get(side) or "stage result missing"

    return [
        claim_c1(inp.residuals_sim, inp.residuals_real,
                 reason_sim=why("C1", "sim"), reason_real=why("C1", "real")),
        claim_c2(inp.decay_sim, inp.decay_real,
                 reason_sim=why("C2", "sim"), reason_real=why("C2", "real")),
        claim_c3(inp.ribs_sim, inp.ribs_real,
                 reason_sim=why("C3", "sim"), reason_real=why("C3", "real")),
        claim_c4(inp.nominal_sim, inp.nominal_real,
                 reason_sim=why("C4", "sim"), reason_real=why("C4", "real")),
        claim_c5(inp.nominal_sim, inp.nominal_real,
                 reason_sim=why("C5", "sim"), reason_real=why("C5", "real")),
        claim_c6((inp.nominal_sim or {}).get("vs-vf"), (inp.nominal_real or {}).get("vs-vf"),
                 eps_d_m=inp.limits.eps_d_m,
                 reason_sim=why("C6", "sim"), reason_real=why("C6", "real")),
        claim_c7(inp.disturbance_sim, inp.disturbance_real, limits=inp.limits,
                 reason_sim=why("C7", "sim"), reason_real=why("C7", "real")),
    ]


__all__ = [
    "Claim",
    "ClaimInputs",
    "ModelResiduals",
    "ScanLimits",
    "claim_c1",
    "claim_c2",
    "claim_c3",
    "claim_c4",
    "claim_c5",
    "claim_c6",
    "claim_c7",
    "claims_to_json_dict",
    "evaluate_claims",
    "residual_decay",
    "rib_prominences",
    "scan_metrics",
    "scan_window",
]
