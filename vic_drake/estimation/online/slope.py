"""The tissue's penetration from its local slope under a moving probe.

At a steady depth the force ``F = kappa eps^beta`` fits a whole curve of
(kappa, surface) pairs: the two are not separately observable. When the
tip moves (a dither of the penetration keeps it moving), the tissue answers
with its local slope ``k = dF/d eps = beta kappa eps^(beta - 1)``, and with
the force level F

    eps = beta F / k,        surface = z + eps,

whatever kappa is. :func:`slope_step` fits, by least squares with
exponential forgetting (time constant ``slope_memory_s``),

    F(t) = a0 + a1 tau + a2 tau^2 + a3 tau^3 - k (z - z0) - c z_dot

(tau = time since now): the cubic takes the slow change of the force as
the probe travels over the body, so that k and c (the local damping) come
from the part of the tip's motion that the cubic does not explain: the
dither and whatever else the loop does. The loop's own motion answers the
force that the fit does not model, which biases k low; given the dither's
frequency (``dither_hz``) and ``slope_instrument`` "dither" (the default),
the fit takes the dither as its instrument, which that motion does not
bias (:mod:`vic_drake.estimation.online.slope_instrument`; least squares
otherwise). The fit takes z as the penetration's motion: it does not model
the surface under the tip moving with the tip's sideways sway (friction
follows the force, so that sway cannot be a regressor).

The sums are accumulated every sample; every :data:`SOLVE_EVERY` samples
they are re-centred (time and height on the newest data; on the sample
before the solve, which halves the work of the costliest tick) and the 6 x 6
normal equations solved by Cholesky
(:mod:`vic_drake.estimation.online.slope_gram`, pure Python floats; the
instrumented fit reuses the cubic's factor); a system that is not
numerically solvable gives no solve. A
solve is valid once the contact has lasted ``2 slope_memory_s``, the tip's
motion beyond the trend has an RMS of at least ``slope_min_motion_m``, k's
relative standard error (from the fit's residuals) is at most
``slope_max_rel_std``, k > 0 and 0 < eps < :data:`MAX_PENETRATION_M`. A
solve that is not valid says nothing about how a change of the force
splits between kappa and the depth; it keeps kappa = F / eps^beta of the
last valid solve and reads the depth from its own mean force,
eps = (F / kappa)^(1 / beta) (where the stiffness saturates or the force
sits at its bound the tip stops moving, while the force still follows the
depth). Its surface ``mean z + eps`` holds at the weighted mean time of
the data; the output surface tracks it (brought to now with the tracked
rate) through a second-order filter (see :func:`slope_step`). Everything
restarts at each loss of contact (the force at or below the contact
threshold, or fallen back to the level it rose from:
:mod:`~vic_drake.estimation.online.contact`).

That is the "tracker" mode (``slope_kappa_mode``): the surface is smooth
and kappa follows the force. Two flags from the controller's side change
the fit at the controller's bounds (docs/decisions.md, "The tracker at
the controller's bounds"):

- in the "tracker" mode, a sample taken while the controller holds the
  force at a bound that does not follow the dither (``at_force_bound``:
  VS-VF's F_min,z in the dither's upper half-cycle) is not fitted. Its
  force is the controller's choice, not the tissue's answer to the tip's
  motion, and such samples read the slope low on the ribs;
- in both modes, while the stiffness is at its bound (``saturated``), a
  solve that is not valid moves the held kappa down towards ``F / (s_hold
  - z)^beta`` where that reading is the softer one (F and z the solve's
  mean force and tip height: read from each sample, the force's noise
  would ratchet kappa down). s_hold is the last valid solve's own surface
  (mean z + eps at its mean time: its mean force, free of the dither's
  damping force). A kappa held too high asks more force than the saturated
  stiffness gives, the tip stops, and no solve is valid again: the held
  surface is then the only reading of a tissue that softens. A saturated
  stiffness never stiffens the held kappa: a tip that rides up a rib under
  it reads as a stiffer tissue at the held surface, and a higher kappa
  keeps the stiffness saturated, a loop with no bound where F_min,z does
  not cap the reference (docs/decisions.md, "One saturation rule for both
  modes").

The "direct" mode holds kappa instead (and fits every sample): its
output ln kappa follows the last valid solve's kappa (F / eps^beta, or
that kappa softened under a saturated stiffness as above), moving at most
``slope_kappa_max_rate_per_s`` (a single biased solve, and the fit reads
the loop's own large motions worst, moves the estimate by a bounded
step); the output surface is ``z + (F / kappa)^(1 / beta)`` (the EKF
downstream then reads that kappa back).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from vic_drake.estimation.online.contact import (
    FALLEN,
    GATE_SIZE,
    advance_gate,
    gate_initial_state,
)
from vic_drake.estimation.online.contact import TARE as _GATE_TARE
from vic_drake.estimation.online.params import OnlineEstimatorParams
from vic_drake.estimation.online.slope_gram import (
    GRAM_SIZE,
    SUMS_SIZE,
    add_sample,
    shift_basis,
    solve_sums,
)
from vic_drake.estimation.online.slope_instrument import (
    INSTRUMENT_SIZE,
    add_instrument_sample,
    shift_instruments,
    solve_instrumented,
)

#: Samples between two solves of the fit.
SOLVE_EVERY = 10
#: Largest penetration the slope estimate accepts, m (beyond: not valid).
MAX_PENETRATION_M = 0.05
#: The surface filter's error is clipped at this, m: a bad solve moves the
#: surface at a bounded rate.
MAX_SURFACE_ERROR_M = 1e-3
_Z = 4  # the column of z0 - z in the fit's functions (slope_gram)

# State layout.
_T_REF = 0  # time the basis is centred on (NaN: no sample since the reset)
_Z_REF = 1
_T_START = 2  # first contact sample since the reset
_T_LAST = 3  # last good sample
_COUNT = 4  # samples since the last solve
_G = 5  # the sums of slope_gram: the upper triangle of the Gram matrix,
_B = _G + GRAM_SIZE  # its right-hand side (the force),
_FF = _G + SUMS_SIZE - 1  # the weighted sum of the squared forces
_SLOPE = _FF + 1  # k of the last solve, N/m (NaN: none)
_REL_STD = _SLOPE + 1  # its relative standard error
_MOTION = _REL_STD + 1  # RMS of the tip's motion beyond the trend, m
_VALID = _MOTION + 1  # 1 if the last solve was valid
_EPS = _VALID + 1  # penetration of the last valid solve, m (NaN: none)
_Z_MEAN = _EPS + 1  # mean tip height of the last solve's data, m
_T_MEAN = _Z_MEAN + 1  # its weighted mean time, s
_S_OUT = _T_MEAN + 1  # the tracked surface, m (NaN: none)
_V_OUT = _S_OUT + 1  # its rate, m/s
_KAPPA = _V_OUT + 1  # F / eps^beta of the last valid solve (NaN: none)
_LN_KAPPA = _KAPPA + 1  # "direct": the output ln kappa (NaN: none)
_S_HOLD = _LN_KAPPA + 1  # the last valid solve's surface, m
_D_SOLVE = _S_HOLD + 1  # the time covered by the last re-centring, s
_I = _D_SOLVE + 1  # the instrument's sums (slope_instrument; zero without)
_GATE = _I + INSTRUMENT_SIZE  # the contact gate (kept through restarts)
SLOPE_SIZE = _GATE + GATE_SIZE
#: Index of the tracked surface in the state (:func:`advance`).
SURFACE = _S_OUT
#: Index of the contact gate's tare in the state, N (:func:`advance`
#: subtracts it from the force).
TARE = _GATE + _GATE_TARE


class SlopeEstimate(NamedTuple):
    """One sample's output of :func:`slope_step`.

    Attributes:
        surface_z_m: the tracked surface height (NaN before the first
            valid solve since contact), m.
        penetration_m: eps of the last valid solve, or from its kappa and
            the force after it (NaN before the first since contact), m.
        slope_N_per_m: k of the last solve (NaN before one).
        slope_rel_std: its relative standard error (NaN before one).
        motion_m: RMS of the tip's motion beyond the trend in the last
            solve's data (0 before one), m.
        valid: 1.0 if the last solve was valid, else 0.0.
    """

    surface_z_m: float
    penetration_m: float
    slope_N_per_m: float
    slope_rel_std: float
    motion_m: float
    valid: float


def slope_initial_state() -> list[float]:
    """A fresh fit: no sample, no estimate."""
    state = [0.0] * SLOPE_SIZE
    for i in (
        _T_REF, _T_START, _T_LAST, _SLOPE, _REL_STD, _EPS, _Z_MEAN, _T_MEAN, _S_OUT,
        _KAPPA, _LN_KAPPA, _S_HOLD,
    ):  # fmt: skip
        state[i] = math.nan
    state[_GATE:] = gate_initial_state()
    return state


def _soften_held_kappa(
    s: list[float], force: float, dt: float, p: OnlineEstimatorParams
) -> None:
    """An invalid solve under a saturated stiffness (in place), in both
    modes: the held kappa moves down towards ``F / (s_hold - z)^beta`` (the
    solve's mean force and tip height) where that reading is the softer
    one, at most at the rate bound over ``dt`` (since the last solve)."""
    eps = s[_S_HOLD] - s[_Z_MEAN]
    if not eps > 0.0:
        return
    held = math.log(s[_KAPPA])
    target = math.log(force) - p.beta * math.log(eps)
    if target < held:
        s[_KAPPA] = math.exp(max(target, held - p.slope_kappa_max_rate_per_s * dt))


def _recentre(s: list[float], t: float, p: OnlineEstimatorParams, instrumented: bool):
    """Moves the sums' basis to t and the data's mean height (in place), the
    tick before a solve (the two halves of a solve's work on two ticks: the
    fit does not depend on the basis)."""
    if not s[_G] > 0.0:  # Every sample since the reset was at the force bound.
        s[_D_SOLVE] = t - s[_T_REF]
        s[_T_REF] = t
        return
    d = t - s[_T_REF]
    dz = -s[_G + _Z] / s[_G]  # mean z - z0 (G04 / G00 = mean of z0 - z)
    scale = math.exp(-d / p.slope_memory_s)
    s[_G : _FF + 1] = shift_basis(s[_G : _FF + 1], d, dz, scale)
    if instrumented:
        s[_I:_GATE] = shift_instruments(s[_I:_GATE], d, dz, scale)
    s[_D_SOLVE] = d
    s[_T_REF] = t
    s[_Z_REF] += dz


def _solve(
    s: list[float],
    t: float,
    p: OnlineEstimatorParams,
    saturated: bool,
    instrumented: bool,
) -> None:
    """Solves the fit (in place), with the dither as the instrument if
    ``instrumented``."""
    s[_COUNT] = 0.0
    if not s[_G] > 0.0:  # Every sample since the reset was at the force bound.
        return
    d = s[_D_SOLVE]  # the time since the last solve (between re-centrings)
    sums = s[_G : _FF + 1]
    w0 = sums[0]
    s[_Z_MEAN] = s[_Z_REF] - sums[_Z] / w0
    s[_T_MEAN] = s[_T_REF] + sums[1] / w0
    s[_VALID] = 0.0
    fit = solve_instrumented(sums, s[_I:_GATE]) if instrumented else solve_sums(sums)
    if fit is None:  # G not positive definite: no solve, as a singular one.
        return
    schur_z, slope, residual, var_factor = fit
    # Weighted mean squared residual, and the variance of k: sigma^2 times
    # G^-1's entry (or the instrumented fit's factor), scaled by
    # sum w^2 / sum w, which is 1/2 for exponential weights whose newest is
    # 1 (it is exp((t - t_ref) / memory) here: the basis is a sample old).
    newest = math.exp((t - s[_T_REF]) / p.slope_memory_s)
    var_k = max(residual, 0.0) / w0 * var_factor * 0.5 * newest
    s[_SLOPE] = slope
    s[_REL_STD] = math.sqrt(var_k) / abs(slope) if slope != 0.0 else math.inf
    s[_MOTION] = math.sqrt(schur_z / w0)
    force = sums[_B - _G] / w0  # the data's weighted mean force
    eps = p.beta * force / slope if slope > 0.0 else math.nan
    ok = (
        t - s[_T_START] >= 2.0 * p.slope_memory_s
        and s[_MOTION] >= p.slope_min_motion_m
        and s[_REL_STD] <= p.slope_max_rel_std
        and 0.0 < eps < MAX_PENETRATION_M
    )
    if ok:
        s[_VALID] = 1.0
        s[_EPS] = eps
        s[_KAPPA] = force / eps**p.beta
        # The solve's own surface (its mean force: no dither damping).
        s[_S_HOLD] = s[_Z_MEAN] + eps
    elif force > 0.0 and math.isfinite(s[_KAPPA]):  # Not valid: kappa held,
        if saturated:
            _soften_held_kappa(s, force, d, p)
        s[_EPS] = (force / s[_KAPPA]) ** (1.0 / p.beta)


def _direct(
    s: list[float], z: float, force: float, dt: float, p: OnlineEstimatorParams
) -> None:
    """The "direct" mode's kappa and surface of one sample (in place)."""
    # (advance has returned already unless force > contact_threshold_N >= 0.)
    if not math.isfinite(s[_KAPPA]):
        return
    held = s[_LN_KAPPA]
    target = math.log(s[_KAPPA])
    if math.isnan(held):
        ln_kappa = target
    else:
        bound = p.slope_kappa_max_rate_per_s * dt
        ln_kappa = min(max(target, held - bound), held + bound)
    s[_LN_KAPPA] = ln_kappa
    s[_S_OUT] = z + (force / math.exp(ln_kappa)) ** (1.0 / p.beta)
    s[_V_OUT] = 0.0


def slope_step(
    state,
    t: float,
    z: float,
    z_dot: float,
    force: float,
    params: OnlineEstimatorParams,
    surface_start: float = math.nan,
    saturated: bool = False,
    at_force_bound: bool = False,
    dither_hz: float = 0.0,
) -> tuple[list[float], SlopeEstimate]:
    """One sample of the fit and of the surface it measures.

    The output surface tracks ``m = mean z + eps + v (t - mean time)`` (the
    last solve's mean tip height; eps of the last valid solve, or, while
    the solves are not valid, the depth at which the last solve's mean
    force meets the last valid solve's kappa; v the tracked rate) through
    a filter of natural frequency w = 1 / ``slope_surface_time_s`` that
    follows a ramp without lag (``s' = v + 2 w e``, ``v' = w^2 e``,
    e = m - s clipped at :data:`MAX_SURFACE_ERROR_M`). It is slower than the probe's own motion
    on purpose: within that time the surface stays put under a probe that
    presses deeper (a surface that followed the tip at once would read
    every change of force as a change of kappa). It starts at
    ``surface_start`` when that is finite (the surface the caller used
    until now: no jump), else at the first valid solve's.

    Args:
        state: from :func:`slope_initial_state` (not modified).
        t: time, s (a sample not after the last good one is ignored).
        z, z_dot: tip height, m, and its rate, m/s.
        force: tissue force on the probe, N (positive = pushing it up);
            the contact gate's tare
            (:mod:`~vic_drake.estimation.online.contact`) is subtracted
            from it. At or below ``params.contact_threshold_N``, or fallen
            back to the level it rose from, everything restarts.
        params: ``slope_memory_s``, ``slope_min_motion_m``,
            ``slope_surface_time_s``, ``beta``, ``contact_threshold_N``.
        surface_start: see above, m ("tracker" mode).
        saturated: the controller's stiffness is at its bound (see the
            module docstring).
        at_force_bound: the controller holds the force at a bound that
            does not follow the dither ("tracker" mode: the sample is not
            fitted; see the module docstring).
        dither_hz: the frequency of the controller's penetration dither,
            Hz (its phase is 2 pi dither_hz t): with
            ``params.slope_instrument`` "dither" the fit takes it as its
            instrument (:mod:`~vic_drake.estimation.online.slope_instrument`);
            0 (not known): least squares.

    Returns:
        (new state, :class:`SlopeEstimate`).
    """
    s = list(state)
    advance(
        s, t, z, z_dot, force, params, surface_start, saturated, at_force_bound,
        dither_hz,
    )  # fmt: skip
    return s, _estimate(s)


def advance(
    s: list[float],
    t: float,
    z: float,
    z_dot: float,
    force: float,
    params: OnlineEstimatorParams,
    surface_start: float = math.nan,
    saturated: bool = False,
    at_force_bound: bool = False,
    dither_hz: float = 0.0,
) -> float | None:
    """:func:`slope_step` on the state ``s`` in place, without the estimate
    (its surface is ``s[SURFACE]``).

    Returns:
        The contact gate's phase after the sample
        (:mod:`~vic_drake.estimation.online.contact`), None for a sample
        that is not finite or not after the last good one (ignored).
    """
    p = params
    if not math.isfinite(t + z + z_dot + force) or not (
        math.isnan(s[_T_LAST]) or t > s[_T_LAST]
    ):
        return None
    dt = 0.0 if math.isnan(s[_T_LAST]) else t - s[_T_LAST]
    phase = advance_gate(s, _GATE, dt, z, force, p)
    force -= s[TARE]
    if phase == FALLEN or force <= p.contact_threshold_N:
        gate = s[_GATE:]
        s[:] = slope_initial_state()
        s[_GATE:] = gate
        s[_T_LAST] = t
        return phase
    s[_T_LAST] = t
    if math.isnan(s[_T_REF]):
        s[_T_REF] = s[_T_START] = t
        s[_Z_REF] = z
    direct = p.slope_kappa_mode == "direct"
    instrumented = dither_hz > 0.0 and p.slope_instrument == "dither"
    if direct or not at_force_bound:
        tau = t - s[_T_REF]
        w = math.exp(tau / p.slope_memory_s)
        e = s[_Z_REF] - z
        s[_G : _FF + 1] = add_sample(s[_G : _FF + 1], w, tau, e, -z_dot, force)
        if instrumented:
            phase = 2.0 * math.pi * dither_hz * t
            s[_I:_GATE] = add_instrument_sample(
                s[_I:_GATE], w, tau, e, -z_dot, force, math.sin(phase), math.cos(phase)
            )
    s[_COUNT] += 1.0
    if s[_COUNT] >= SOLVE_EVERY:
        _solve(s, t, p, saturated, instrumented)
    elif s[_COUNT] == SOLVE_EVERY - 1:
        _recentre(s, t, p, instrumented)
    if direct:
        _direct(s, z, force, dt, p)
    elif math.isfinite(s[_EPS]):
        v = s[_V_OUT]
        measured = s[_Z_MEAN] + s[_EPS] + v * (t - s[_T_MEAN])
        if math.isnan(s[_S_OUT]):
            start = surface_start if math.isfinite(surface_start) else measured
            s[_S_OUT], s[_V_OUT] = start, 0.0
        else:
            wn = 1.0 / p.slope_surface_time_s
            e = min(
                max(measured - s[_S_OUT], -MAX_SURFACE_ERROR_M), MAX_SURFACE_ERROR_M
            )
            s[_S_OUT] += dt * (v + 2.0 * wn * e)
            s[_V_OUT] += dt * wn * wn * e
    return phase


def _estimate(s: list[float]) -> SlopeEstimate:
    return SlopeEstimate(
        s[_S_OUT], s[_EPS], s[_SLOPE], s[_REL_STD], s[_MOTION], s[_VALID]
    )


__all__ = [
    "MAX_PENETRATION_M",
    "MAX_SURFACE_ERROR_M",
    "SLOPE_SIZE",
    "SOLVE_EVERY",
    "SURFACE",
    "SlopeEstimate",
    "TARE",
    "advance",
    "slope_initial_state",
    "slope_step",
]
