"""The phantom's vertical motion estimated from a scan log, with its uncertainty.

:func:`estimate_phantom_motion` works on any canonical scan frame (a real
9- or 31-column log through :func:`~vic_drake.analysis.columns.real_to_canonical`,
or a simulated scan). In contact it inverts the Hunt-Crossley law at the
map's kappa, lambda, beta for the penetration, so the tissue surface under
the tip is the tip height plus that penetration; its difference from the
undisturbed surface (a nominal log of the same scan when there is one,
else the map) is the motion. Out of contact the surface lies below the tip:
the motion is bounded above by the tip height minus the undisturbed
surface. :func:`motion_is_significant` decides whether the motion stands
out of its uncertainty (compare-real replays it only then): enough of the
record beyond the band, one excursion beyond it longer than the averaging
can make of one odd sample, or a contact loss the resting phantom cannot
explain; :func:`lift_table` turns it into a scenario table.

Why each constant is what it is: docs/decisions.md, "Phantom motion from a
scan log".
"""

import numpy as np
import pandas as pd
from scipy.signal import savgol_filter

from vic_drake.analysis.columns import require_columns
from vic_drake.analysis.contact import MIN_CONTACT_LOSS_S, pressing_force_N
from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N

#: 1-sigma error of the motion estimated against the map, m: the RMS of the
#: map-referenced estimate over the contact samples of the four nominal
#: logs (1.0-3.6 mm, pooled 2.8 mm), where the phantom did not move.
MAP_SURFACE_SIGMA_M = 2.8e-3
#: Least 1-sigma error of the motion estimated against a nominal log of the
#: same scan, m: the RMS of the estimate of one nominal 9-column log against
#: the other (CS 400 vs CF, both ways: 0.55-0.56 mm).
SIBLING_SIGMA_M = 0.56e-3
#: 1-sigma relative error of the map's kappa: the slopes of the surface
#: disagreement between two nominal logs against their penetration
#: difference give 0.14-0.36.
MAP_KAPPA_REL_SIGMA = 0.2
#: A motion sample stands out when |motion| exceeds this many sigmas.
SIGNIFICANCE_Z = 3.0
#: The motion is significant (and replayed) when at least this fraction of
#: the samples from the first to the last contact stand out: a Gaussian
#: error leaves 0.3 % beyond 3 sigma, and no single sample can flip it
#: (10 % is 2 s of a 20 s scan).
SIGNIFICANT_FRACTION = 0.10
#: The motion is also significant when one contiguous run of samples beyond
#: SIGNIFICANCE_Z lasts at least this many averaging windows: one odd raw
#: sample moves the averaged estimate over one window only, and a run of
#: two independent windows beyond 3 sigma has odds of about 7e-6.
EXCURSION_WINDOWS = 2.0
#: 1-sigma change of the surface estimate between two samples of a log where
#: nothing moved, m, and its growth with their distance in x, m/m: above the
#: nominal logs' RMS at every distance (0.09-0.38 mm under 2 mm apart).
LOCAL_SURFACE_SIGMA_M = 0.4e-3
MAP_SLOPE_SIGMA = 0.09
#: Smallest kappa_eff / kappa the viscous inversion uses: below it (a fast
#: release) the force says little about the penetration and the static
#: law's answer is kept within a factor 2 in stiffness.
MIN_VISCOUS_STIFFNESS_RATIO = 0.5
#: Fixed-point passes of the viscous inversion. Each shrinks a slow error by
#: about lambda |eps_dot| / (beta kappa) but amplifies what the rate's
#: smoothing lets through (a kink in the motion); with RATE_SMOOTH_S the
#: largest error is 0.51 mm on a 1 Hz, 4 mm indentation and 0.40 mm on a
#: 15 mm trapezoid lift (static law: 1.17 and 0.70 mm).
VISCOUS_PASSES = 2
#: Time over which the penetration rate of the viscous term is smoothed, s.
RATE_SMOOTH_S = 0.2


def _moving_average(v: np.ndarray, w: np.ndarray, n: int) -> np.ndarray:
    """Centred weighted moving average over n samples (NaN where no weight)."""
    kernel = np.ones(n)
    pad = (n // 2, n - 1 - n // 2)
    num = np.convolve(np.pad(np.where(w > 0, v * w, 0.0), pad), kernel, "valid")
    den = np.convolve(np.pad(w, pad), kernel, "valid")
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(den > 0, num / den, np.nan)


def _rate(t: np.ndarray, v: np.ndarray, smooth_s: float) -> np.ndarray:
    dt = float(np.median(np.diff(t)))
    window = max(5, int(round(smooth_s / dt)) | 1)
    if window >= len(v):
        return np.gradient(v, t)
    return np.gradient(savgol_filter(v, window, 2), t)


def force_noise_N(df: pd.DataFrame) -> float:
    """The z force's white-noise 1-sigma, N: std of its sample differences / sqrt 2."""
    f = pressing_force_N(df)
    d = np.diff(f[np.isfinite(f)])
    return float(np.std(d) / np.sqrt(2.0)) if d.size > 1 else 0.0


def penetration_m(
    df: pd.DataFrame,
    phantom,
    *,
    viscous: bool = True,
) -> np.ndarray:
    """Penetration that makes the Hunt-Crossley law give the measured force, m.

    Static law: ``eps = (F / kappa)^(1 / beta)`` at the map's kappa under the
    tip. With ``viscous``, ``F = eps^beta (kappa + lambda eps_dot)`` is
    solved by :data:`VISCOUS_PASSES` fixed-point passes, eps_dot the
    smoothed rate of the previous pass's penetration; ``kappa + lambda eps_dot`` is kept at least
    :data:`MIN_VISCOUS_STIFFNESS_RATIO` kappa. NaN where the force is at or
    below the contact threshold (no information on the surface there).

    Args:
        df: canonical scan frame (t_s, x_m, y_m, force_sensor_z_N).
        phantom: the tissue map (kappa, lam, beta).
        viscous: include the viscous term.
    """
    f = pressing_force_N(df)
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    kappa = np.asarray(phantom.kappa(x, y), float)
    contact = f > CONTACT_THRESHOLD_N
    eps = np.where(contact, np.maximum(f, 0.0) / kappa, np.nan) ** (1.0 / phantom.beta)
    if not viscous or contact.sum() < 10:
        return eps
    t = df["t_s"].to_numpy(float)
    lam = np.asarray(phantom.lam(x, y), float)
    for _ in range(VISCOUS_PASSES):
        filled = np.interp(t, t[contact], eps[contact])
        stiff = kappa + lam * _rate(t, filled, RATE_SMOOTH_S)
        stiff = np.maximum(stiff, MIN_VISCOUS_STIFFNESS_RATIO * kappa)
        eps = np.where(contact, np.maximum(f, 0.0) / stiff, np.nan) ** (
            1.0 / phantom.beta
        )
    return eps


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) index of each run of True."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    starts = idx[np.r_[True, np.diff(idx) > 1]]
    ends = idx[np.r_[np.diff(idx) > 1, True]]
    return list(zip(starts.tolist(), ends.tolist()))


def _sustained(t: np.ndarray, contact: np.ndarray) -> np.ndarray:
    """``contact`` less its runs under MIN_CONTACT_LOSS_S (noise in the air)."""
    out = np.asarray(contact, bool).copy()
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    for a, b in _runs(out):
        if t[b] - t[a] + dt < MIN_CONTACT_LOSS_S:
            out[a : b + 1] = False
    return out


def _gap_depth(t, keep, eps, smooth_s) -> np.ndarray:
    """How far under the tip the surface may lie in each gap without contact, m.

    The surface leaves the tip at the penetration rate of the last
    ``smooth_s`` of contact before the gap and comes back at the rate of the
    first ``smooth_s`` after it; the depth at time t is the smaller of the
    two separations, ``min(-eps_dot_0 (t - t_0), eps_dot_1 (t_1 - t))``
    (0 in contact and at the record's ends, where one side is missing).
    """
    depth = np.zeros(len(t))
    for i0, i1 in _runs(~keep):
        if i0 == 0 or i1 == len(t) - 1:
            continue
        before = keep & (t >= t[i0] - smooth_s) & (t < t[i0])
        after = keep & (t > t[i1]) & (t <= t[i1] + smooth_s)
        if before.sum() < 2 or after.sum() < 2:
            continue
        rate0 = np.polyfit(t[before], eps[before], 1)[0]
        rate1 = np.polyfit(t[after], eps[after], 1)[0]
        span = t[i0 : i1 + 1]
        d = np.minimum(
            max(-rate0, 0.0) * (span - t[i0 - 1]), max(rate1, 0.0) * (t[i1 + 1] - span)
        )
        depth[i0 : i1 + 1] = d
    return depth


def _reference(df, phantom, nominal, viscous):
    """Undisturbed surface and penetration at the frame's samples."""
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    if nominal is None:
        return np.asarray(phantom.surface_z(x, y), float), None
    require_columns(nominal, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    eps_n = penetration_m(nominal, phantom, viscous=viscous)
    ok = np.isfinite(eps_n)
    if ok.sum() < 2:
        raise VicDrakeError(
            "the nominal log has no contact; cannot use it as reference"
        )
    xn = nominal["x_m"].to_numpy(float)[ok]
    order = np.argsort(xn)
    s_n = (nominal["z_m"].to_numpy(float) + eps_n)[ok][order]
    return np.interp(x, xn[order], s_n), np.interp(x, xn[order], eps_n[ok][order])


def estimate_phantom_motion(
    df: pd.DataFrame,
    phantom,
    *,
    nominal: pd.DataFrame | None = None,
    viscous: bool = True,
    smooth_s: float = 0.2,
    baseline_s: float = 1.0,
    map_surface_sigma_m: float = MAP_SURFACE_SIGMA_M,
    kappa_rel_sigma: float = MAP_KAPPA_REL_SIGMA,
) -> pd.DataFrame:
    """Estimates the phantom's vertical motion over a scan, with a 1-sigma band.

    In contact (pressing force above the contact threshold) the surface under
    the tip is the tip height plus :func:`penetration_m`; minus the
    undisturbed surface at the same x (``nominal``'s apparent surface, which
    cancels the map's errors, else the map's surface) it is the raw motion,
    averaged over the contact samples within ``smooth_s``. Its median over
    the first ``baseline_s`` of contact is
    removed (the phantom rests at the start; this also removes the map's
    constant offset). Out of contact the surface lies below the tip plus the
    penetration the noise-level force allows: that is an upper bound on the
    motion. How far under it the surface went is not seen; the surface left
    the tip and came back at the penetration rates measured at the gap's
    ends, which bound the separation by a triangle (:func:`_gap_depth`). The
    estimate in the gap is the linear bridge between its contact ends, held
    at most at the tip's own height (no penetration) minus half that depth
    (the middle of the triangle); the bound is the band's edge.

    1-sigma band: in contact, the reference's error (``map_surface_sigma_m``
    for the map; for a nominal log, the RMS of the raw motion over the
    baseline window, how well the two logs agree where nothing moves, at
    least :data:`SIBLING_SIGMA_M`), the
    kappa error on the penetration beyond the reference's
    (``kappa_rel_sigma |eps - eps_ref| / beta``), the force noise through
    the law and the RMS of the raw motion about its average within the
    window, in quadrature. Out of contact, the bridged band, the penetration
    at the contact threshold and half the triangle's depth, in quadrature.

    Args:
        df: canonical scan frame (t_s, x_m, y_m, z_m, force_sensor_z_N).
        phantom: the tissue map (surface_z, kappa, lam, beta).
        nominal: canonical frame of the same scan without motion, or None.
        viscous: invert the law with its viscous term.
        smooth_s: averaging window of the raw motion, s.
        baseline_s: length of the rest window whose median is removed, s.
        map_surface_sigma_m, kappa_rel_sigma: the map's error model.

    Returns:
        DataFrame with t_s, phantom_lift_m (the motion, m, > 0 up),
        phantom_lift_sigma_m (1-sigma), upper_bound_m (out of contact, the
        bound from the tip: the motion is at most this; NaN in contact) and
        measured (bool: from contact), loss_descent_m / _sigma_m (see
        :func:`_loss_descent`); ``attrs``: "reference" ("nominal log" or
        "phantom map") and "smooth_s".

    Raises:
        VicDrakeError: missing columns, fewer than two contact samples,
            or bad parameters.
    """
    require_columns(df, "t_s", "x_m", "y_m", "z_m", "force_sensor_z_N")
    for name, value in (("smooth_s", smooth_s), ("baseline_s", baseline_s)):
        if not (np.isfinite(value) and value > 0):
            raise VicDrakeError(f"{name} must be a positive number of s; got {value!r}")
    for name, value in (
        ("map_surface_sigma_m", map_surface_sigma_m),
        ("kappa_rel_sigma", kappa_rel_sigma),
    ):
        if not (np.isfinite(value) and value >= 0):
            raise VicDrakeError(f"{name} must be a number >= 0; got {value!r}")
    t = df["t_s"].to_numpy(float)
    z = df["z_m"].to_numpy(float)
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    f = pressing_force_N(df)
    eps = penetration_m(df, phantom, viscous=viscous)
    measured = np.isfinite(eps)
    if measured.sum() < 2:
        raise VicDrakeError(
            "the scan has fewer than two samples in contact; cannot estimate the "
            "phantom's motion"
        )
    ref, eps_ref = _reference(df, phantom, nominal, viscous)
    dt = float(np.median(np.diff(t)))
    n = max(1, int(round(smooth_s / dt)))
    raw = z + eps - ref
    smooth = _moving_average(raw, measured.astype(float), n)
    t_first = t[np.argmax(measured)]
    base_sel = measured & (t <= t_first + baseline_s)
    base = float(np.median(smooth[base_sel]))
    motion_c = smooth - base
    # Error model in contact.
    kappa = np.asarray(phantom.kappa(x, y), float)
    beta = phantom.beta
    noise = force_noise_N(df)
    with np.errstate(invalid="ignore", divide="ignore"):
        s_force = eps / (beta * np.maximum(f, CONTACT_THRESHOLD_N)) * noise / np.sqrt(n)
    if nominal is None:
        s_ref = map_surface_sigma_m
        eps_base = float(np.median(eps[base_sel]))
        d_eps = eps - eps_base
    else:
        s_ref = max(
            SIBLING_SIGMA_M, float(np.sqrt(np.mean((smooth[base_sel] - base) ** 2)))
        )
        d_eps = eps - eps_ref
    s_kappa = kappa_rel_sigma * np.abs(d_eps) / beta
    # How far the raw motion strays from its average within the window: the
    # noise left after it and the average's lag at a fast change.
    s_fit = np.sqrt(_moving_average((raw - smooth) ** 2, measured.astype(float), n))
    sigma_c = np.sqrt(s_ref**2 + s_kappa**2 + s_force**2 + s_fit**2)
    # Out of contact: the bound from the tip, the bridge under it.
    # The force is at most its window average plus twice its noise; the
    # tissue is at least MIN_VISCOUS_STIFFNESS_RATIO kappa stiff.
    f_high = np.maximum(_moving_average(f, np.ones(len(f)), n), 0.0) + 2.0 * noise
    eps_high = (f_high / (MIN_VISCOUS_STIFFNESS_RATIO * kappa)) ** (1.0 / beta)
    upper = z + eps_high - ref - base
    keep = measured & np.isfinite(motion_c)
    bridge = np.interp(t, t[keep], motion_c[keep])
    sigma_bridge = np.interp(t, t[keep], sigma_c[keep])
    depth = _gap_depth(t, keep, eps, smooth_s)
    # Capped at the tip's height, not at the bound (see the docstring).
    tip_level = z - ref - base
    motion = np.where(keep, motion_c, np.minimum(bridge, tip_level - depth / 2))
    eps_thr = (CONTACT_THRESHOLD_N / kappa) ** (1.0 / beta)
    sigma_gap = np.sqrt(sigma_bridge**2 + eps_thr**2 + (depth / 2) ** 2)
    sigma = np.where(keep, sigma_c, sigma_gap)
    descent, descent_sigma = _loss_descent(t, x, keep, tip_level, upper)
    out = pd.DataFrame(
        {
            "t_s": t,
            "phantom_lift_m": motion,
            "phantom_lift_sigma_m": sigma,
            "upper_bound_m": np.where(keep, np.nan, upper),
            "measured": keep,
            "loss_descent_m": descent,
            "loss_descent_sigma_m": descent_sigma,
        }
    )
    out.attrs["reference"] = "phantom map" if nominal is None else "nominal log"
    out.attrs["smooth_s"] = smooth_s
    return out


def _loss_descent(t, x, keep, tip_level, upper):
    """How far, in each gap between two contacts of at least
    MIN_CONTACT_LOSS_S, the surface must have fallen since the gap's last
    contact sample, m, and its 1-sigma (NaN elsewhere).

    When contact is lost the surface touches the tip (``tip_level``, its
    height above the reference); a resting surface stays there or, relaxing,
    rises, and the tip must stay above it less the penetration an under-
    threshold force allows (``upper``, that bound on the motion). Descent:
    the tip's level at the last contact minus the bound; 1-sigma: the
    estimate's change between two samples of a resting log that far apart.
    """
    descent = np.full(len(t), np.nan)
    sig = np.full(len(t), np.nan)
    for i0, i1 in _runs(~_sustained(t, keep)):
        if i0 == 0 or i1 == len(t) - 1:
            continue
        span = slice(i0, i1 + 1)
        descent[span] = tip_level[i0 - 1] - upper[span]
        dx = np.abs(x[span] - x[i0 - 1])
        sig[span] = np.hypot(LOCAL_SURFACE_SIGMA_M, MAP_SLOPE_SIGMA * dx)
    return descent, sig


def motion_significance(motion: pd.DataFrame) -> float:
    """Fraction of the samples from the first to the last contact whose motion
    exceeds :data:`SIGNIFICANCE_Z` of its 1-sigma band."""
    require_columns(motion, "phantom_lift_m", "phantom_lift_sigma_m", "measured")
    m = motion["measured"].to_numpy(bool)
    if not m.any():
        return 0.0
    i0, i1 = int(np.argmax(m)), len(m) - 1 - int(np.argmax(m[::-1]))
    v = motion["phantom_lift_m"].to_numpy(float)[i0 : i1 + 1]
    s = motion["phantom_lift_sigma_m"].to_numpy(float)[i0 : i1 + 1]
    return float(np.mean(np.abs(v) > SIGNIFICANCE_Z * s))


def longest_excursion_s(motion: pd.DataFrame) -> float:
    """Longest contiguous run, from the first to the last contact (runs of
    contact of at least MIN_CONTACT_LOSS_S), of samples whose motion exceeds
    :data:`SIGNIFICANCE_Z` of its band, s."""
    require_columns(motion, "t_s", "phantom_lift_m", "phantom_lift_sigma_m", "measured")
    t = motion["t_s"].to_numpy(float)
    m = _sustained(t, motion["measured"].to_numpy(bool))
    if not m.any():
        return 0.0
    i0, i1 = int(np.argmax(m)), len(m) - 1 - int(np.argmax(m[::-1]))
    v = motion["phantom_lift_m"].to_numpy(float)
    s = motion["phantom_lift_sigma_m"].to_numpy(float)
    beyond = np.zeros(len(m), bool)
    beyond[i0 : i1 + 1] = np.abs(v[i0 : i1 + 1]) > SIGNIFICANCE_Z * s[i0 : i1 + 1]
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 0.0
    return float(max((t[b] - t[a] + dt for a, b in _runs(beyond)), default=0.0))


def unexplained_loss_z(motion: pd.DataFrame) -> float:
    """Largest descent, in sigmas, that a contact loss of at least
    :data:`~vic_drake.analysis.contact.MIN_CONTACT_LOSS_S` demands of the
    surface (``loss_descent_m`` / ``loss_descent_sigma_m``), 0.0 without such
    a loss or those columns. Beyond :data:`SIGNIFICANCE_Z` the resting
    phantom cannot explain the loss: the tip went that far below its height
    when contact was lost (less the penetration the force allows), and the
    force stayed under the contact threshold."""
    cols = ("t_s", "loss_descent_m", "loss_descent_sigma_m")
    if not all(c in motion.columns for c in cols):
        return 0.0
    t = motion["t_s"].to_numpy(float)
    d = motion["loss_descent_m"].to_numpy(float)
    s = motion["loss_descent_sigma_m"].to_numpy(float)
    best = 0.0
    for a, b in _runs(np.isfinite(d)):
        if b + 1 < len(t) and t[b + 1] - t[a] >= MIN_CONTACT_LOSS_S:
            best = max(best, float(np.max(d[a : b + 1] / s[a : b + 1])))
    return best


def motion_is_significant(motion: pd.DataFrame) -> bool:
    """True when the motion stands out of its band: :func:`motion_significance`
    reaches :data:`SIGNIFICANT_FRACTION`, or :func:`longest_excursion_s` lasts
    :data:`EXCURSION_WINDOWS` averaging windows (``attrs["smooth_s"]``, else
    0.2 s), or :func:`unexplained_loss_z` reaches :data:`SIGNIFICANCE_Z`."""
    smooth_s = float(motion.attrs.get("smooth_s", 0.2))
    return bool(
        motion_significance(motion) >= SIGNIFICANT_FRACTION
        or longest_excursion_s(motion) >= EXCURSION_WINDOWS * smooth_s
        or unexplained_loss_z(motion) >= SIGNIFICANCE_Z
    )


def map_surface_error_m(df: pd.DataFrame, phantom, nominal: pd.DataFrame) -> np.ndarray:
    """The map's surface error under a scan's track, m (> 0: the map is low).

    The apparent surface of ``nominal`` (a log of the same scan without
    motion; tip height + :func:`penetration_m`) minus the map's surface, at
    the x of each sample of ``df``.
    """
    require_columns(df, "t_s", "x_m", "y_m")
    ref, _ = _reference(df, phantom, nominal, True)
    x, y = df["x_m"].to_numpy(float), df["y_m"].to_numpy(float)
    return ref - np.asarray(phantom.surface_z(x, y), float)


def replay_table(
    motion: pd.DataFrame, *, surface_error_m: np.ndarray | None = None
) -> list[list[float]]:
    """The disturbance table that replays a scan's motion in simulation.

    ``[]`` (the phantom rests) unless :func:`motion_is_significant`; else
    the :func:`lift_table` of the motion plus ``surface_error_m`` (the map's
    error under the track, :func:`map_surface_error_m`, measured on another
    log: the simulated surface under the tip is then the real one). The one
    rule compare-real and the real scenarios use.
    """
    if not motion_is_significant(motion):
        return []
    if surface_error_m is None:
        return lift_table(motion)
    moved = motion.copy()
    moved["phantom_lift_m"] = moved["phantom_lift_m"].to_numpy() + surface_error_m
    return lift_table(moved)


def lift_table(lift: pd.DataFrame, *, dt_s: float = 0.05) -> list[list[float]]:
    """Resamples an estimated motion (t_s, phantom_lift_m) to the
    scenario's [t_s, z_offset_m] table, every dt_s, clipped to +-0.1 m."""
    require_columns(lift, "t_s", "phantom_lift_m")
    if not dt_s > 0:
        raise VicDrakeError(f"dt_s must be > 0; got {dt_s!r}")
    t = lift["t_s"].to_numpy(float)
    grid = np.arange(t[0], t[-1] + 1e-9, dt_s)
    z = np.interp(grid, t, lift["phantom_lift_m"].to_numpy(float))
    z = np.clip(z, -0.1, 0.1)
    return [[float(a), float(b)] for a, b in zip(grid, z)]


__all__ = [
    "EXCURSION_WINDOWS",
    "LOCAL_SURFACE_SIGMA_M",
    "MAP_KAPPA_REL_SIGMA",
    "MAP_SLOPE_SIGMA",
    "MAP_SURFACE_SIGMA_M",
    "SIGNIFICANCE_Z",
    "SIBLING_SIGMA_M",
    "SIGNIFICANT_FRACTION",
    "estimate_phantom_motion",
    "force_noise_N",
    "lift_table",
    "longest_excursion_s",
    "map_surface_error_m",
    "motion_is_significant",
    "motion_significance",
    "penetration_m",
    "replay_table",
    "unexplained_loss_z",
]
