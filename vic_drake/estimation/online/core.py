"""What the RLS and the EKF share: the state layout, the contact and surface
bookkeeping of one sample, and the scalar Kalman update.

The estimator state is one flat list of floats (it lives in a LeafSystem's
discrete state as is): :data:`AUX_SIZE` bookkeeping entries, then the
parameter vector x (n, normalised: kappa / kappa_prior, lam / lam_prior,
the surface offset in mm, beta), then its covariance P (n * n, row-major),
then a saved copy of x and P (n + n * n: what they were before a covariance
reset that contact has not yet confirmed, :func:`confirm_reset`).

Per sample (:func:`prepare`):

- a non-finite time, position, velocity or force, or a time that does not
  increase, is a fault: nothing changes but the fault count;
- the contact gate (:mod:`~vic_drake.estimation.online.contact`) ends a
  contact whose force falls back to the free-air level it rose from, even
  above the threshold (a bias on the pressing side, read by a probe that
  the tissue has left): until the force rises again, the samples are out
  of contact, and a latched surface is released. Its tare (that free-air
  level once confirmed, 0 until then) is subtracted from the force before
  the rest reads it;
- the surface is the input's when finite; otherwise it is latched at first
  contact at the height where the current estimate gives the measured force
  (``z + (F / kappa_hat)^(1 / beta)``) and released when the force drops
  below the contact threshold (the next contact latches anew). The latch
  stands once the force has risen from its lowest value (:func:`_latch`),
  where the surface is latched; until then the sample is out of contact;
- the surface rate s_dot is a first-order low-pass of its finite
  differences, restarted after a gap longer than ``max_gap_s``;
- contact: force above ``contact_threshold_N``, not fallen back (the
  gate), and penetration above ``min_penetration_m``; only samples in
  contact update x;
- innovations are clipped at ``gate_sigma`` (spikes); when every update
  has been clipped for ``clip_reset_s``, P returns to the prior
  (:func:`record_clip`; updates whose estimate predicts a pulling force
  do not count). Contact must then go on for ``reset_confirm_s``: a contact
  that ends sooner was the run of clipped updates (a lift-off, a surface
  that moved away), and x and P return to what they were before the reset
  (:func:`confirm_reset`).

All arithmetic is on Python floats: the filters are 2 to 4 states, where
numpy's per-call overhead would dominate a tick (the update itself:
:mod:`vic_drake.estimation.online.kalman`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

from vic_drake.estimation.online.contact import (
    FALLEN,
    GATE_SIZE,
    SETTLE_TIME_CONSTANTS,
    TARE,
    advance_gate,
    gate_initial_state,
)
from vic_drake.estimation.online.kalman import scalar_update
from vic_drake.estimation.online.params import OnlineEstimatorParams

# Bookkeeping entries at the head of the state.
T_PREV = 0  # time of the last good sample, s (NaN before the first)
S_LATCH = 1  # latched surface height, m (NaN: none)
S_PREV = 2  # surface used at the last good sample, m (NaN: none)
S_DOT = 3  # filtered surface rate, m/s
IN_CONTACT = 4  # 1 if the last good sample was in contact
N_UPDATES = 5  # samples that updated x
N_FAULTS = 6  # non-finite or out-of-order samples
N_CLIPPED = 7  # updates whose innovation was clipped (spikes, big changes)
T_UPDATE = 8  # time of the last update, s (NaN before the first)
CLIP_START = 9  # time of the first of the clipped updates in a row, s (NaN: none)
RESET_T = 10  # time of the last covariance reset not yet confirmed, s (NaN: none)
N_RESTORED = 11  # unconfirmed resets undone at the end of their contact
F_FILT = 12  # the force through the latch's low-pass, N (NaN before the first)
LATCH_F_MIN = 13  # lowest filtered force since the latch, N (NaN: no latch)
LATCH_OK = 14  # 1 once the latched contact is confirmed by a rise of the force
LATCH_AGE = 15  # time since the latch's low-pass (re)started from a raw sample, s
GATE = 16  # the contact gate's state (contact.GATE_SIZE entries)
AUX_SIZE = GATE + GATE_SIZE

#: Fields of the estimator's outputs, in order (:class:`Estimate`).
OUTPUT_FIELDS = (
    "kappa_hat",
    "lambda_hat",
    "kappa_var",
    "lambda_var",
    "valid",
    "surface_z_m",
    "in_contact",
)


class Estimate(NamedTuple):
    """One sample's outputs.

    Attributes:
        kappa_hat: N/m^beta. lambda_hat: N s/m^(beta+1).
        kappa_var, lambda_var: their variances (same units squared).
        valid: 1.0 when in contact and kappa's std is below
            ``valid_rel_std`` of kappa_hat, else 0.0.
        surface_z_m: the surface height the sample used (NaN if none).
        in_contact: 1.0 when the sample was in contact (it updated the
            estimate), else 0.0.
    """

    kappa_hat: float
    lambda_hat: float
    kappa_var: float
    lambda_var: float
    valid: float
    surface_z_m: float
    in_contact: float


def initial_state(x0: list[float], p0_diag: list[float]) -> list[float]:
    """A fresh state: no sample seen, x = x0, P = diag(p0_diag)."""
    n = len(x0)
    aux = [math.nan, math.nan, math.nan, 0.0, 0.0, 0.0, 0.0, 0.0, math.nan]
    aux += [math.nan, math.nan, 0.0]  # CLIP_START, RESET_T, N_RESTORED
    aux += [math.nan, math.nan, 0.0, 0.0]  # F_FILT, LATCH_F_MIN, LATCH_OK, LATCH_AGE
    aux += gate_initial_state()
    P = [0.0] * (n * n)
    for i in range(n):
        P[i * n + i] = float(p0_diag[i])
    x = [float(v) for v in x0]
    return aux + x + P + x + P


def state_size(n: int) -> int:
    """Length of the state of an n-parameter filter."""
    return AUX_SIZE + 2 * (n + n * n)


def unpack(state, n: int) -> tuple[list[float], list[float], list[float], list[float]]:
    """(aux, x, P, saved x and P) as new lists."""
    if type(state) is not list:  # A list's slices are new lists already.
        state = list(state)
    a, b = AUX_SIZE + n, AUX_SIZE + n + n * n
    return state[:AUX_SIZE], state[AUX_SIZE:a], state[a:b], state[b:]


def prepare(
    aux: list[float],
    t: float,
    z: float,
    z_dot: float,
    force: float,
    surface_z: float,
    kappa_hat: float,
    beta: float,
    p: OnlineEstimatorParams,
    gate_phase: float | None = None,
) -> tuple[float, float, bool, float] | None:
    """Bookkeeping of one sample (updates ``aux`` in place).

    ``gate_phase``: the contact gate's phase for this sample from a gate
    that the caller ran on the same samples (the slope fit's, in
    :func:`~vic_drake.estimation.online.ekf.ekf_slope_step`), with
    ``force`` tared by that gate; None: the gate in ``aux`` runs and tares
    the force.

    Returns:
        None on a fault, else (the surface height, m, NaN if unknown; the
        surface rate, m/s; whether the tared force is above the contact
        threshold and the contact gate has not seen it fall back: the
        penetration test is the filter's; the tared force, N). A plain
        tuple: a NamedTuple would cost a tenth of the RLS's tick.
    """
    if not math.isfinite(t + z + z_dot + force) or not (
        math.isnan(aux[T_PREV]) or t > aux[T_PREV]
    ):
        aux[N_FAULTS] += 1.0
        return None
    dt = 0.0 if math.isnan(aux[T_PREV]) else t - aux[T_PREV]
    aux[T_PREV] = t
    # Out of contact at or below the threshold, or once the force has
    # fallen back to the free-air level it rose from.
    if gate_phase is None:
        gate_phase = advance_gate(aux, GATE, dt, z, force, p)
        force -= aux[GATE + TARE]
    contact = gate_phase != FALLEN and force > p.contact_threshold_N
    if math.isfinite(surface_z):
        s = surface_z
    else:
        contact = _latch(aux, dt, z, force, contact, kappa_hat, beta, p)
        s = aux[S_LATCH]
    s_prev = aux[S_PREV]
    if math.isfinite(s) and math.isfinite(s_prev) and 0.0 < dt <= p.max_gap_s:
        alpha = dt / (p.surface_rate_time_constant_s + dt)
        aux[S_DOT] += alpha * ((s - s_prev) / dt - aux[S_DOT])
    else:
        aux[S_DOT] = 0.0
    aux[S_PREV] = s
    return s, aux[S_DOT], contact, force


def _latch(
    aux: list[float],
    dt: float,
    z: float,
    force: float,
    touching: bool,
    kappa_hat: float,
    beta: float,
    p: OnlineEstimatorParams,
) -> bool:
    """The surface latched at first contact (in ``aux``); returns whether the
    sample counts as contact.

    The surface is latched where the force, low-passed with
    ``latch_rise_filter_s``, is lowest since the force crossed the contact
    threshold (where it started to rise; at that sample's force). The latch
    stands once that force has risen by ``contact_threshold_N`` above its
    lowest value. Until then the sample is not in contact: a force that
    does not rise as the probe goes on is not the tissue's (a sensor's bias
    reads as contact in free air, and the estimate would read the depth
    that the probe travels as a softer tissue). ``latch_rise_filter_s`` 0:
    the latch stands at once, at the first sample.

    The low-pass starts from a raw sample (the first, or the first after a
    gap longer than ``max_gap_s``), which holds that sample's noise. Until
    it has settled (``contact.SETTLE_TIME_CONSTANTS`` time constants) no
    rise confirms the latch, and where it settles the lowest value is
    raised to the settled force: a first sample a few tenths of a newton
    below a biased reading would otherwise be a low that the filter's
    settling "rises" from. The latched height stays where the lowest value
    was (a log that starts pressed in keeps the height of its first
    sample).
    """
    tau = p.latch_rise_filter_s
    settle = SETTLE_TIME_CONSTANTS * tau
    f = aux[F_FILT]
    if math.isnan(f) or not 0.0 < dt <= p.max_gap_s:
        f = force
        aux[LATCH_AGE] = age = 0.0
    else:
        f += dt / (tau + dt) * (force - f)
        aux[LATCH_AGE] = age = aux[LATCH_AGE] + dt
    aux[F_FILT] = f
    if not touching:
        aux[S_LATCH] = aux[LATCH_F_MIN] = math.nan
        aux[LATCH_OK] = 0.0
        return False
    if aux[LATCH_OK] == 1.0:
        return True
    if not f >= aux[LATCH_F_MIN]:  # A new low (NaN: the latch's first sample).
        aux[LATCH_F_MIN] = f
        aux[S_LATCH] = z + (force / kappa_hat) ** (1.0 / beta)
    if age < settle:
        return False  # The filter still holds its first sample's noise.
    if age - dt < settle and f > aux[LATCH_F_MIN]:  # Settled at this sample.
        aux[LATCH_F_MIN] = f
    if tau == 0.0 or f - aux[LATCH_F_MIN] >= p.contact_threshold_N:
        aux[LATCH_OK] = 1.0
        return True
    return False


def record_clip(
    aux: list[float],
    clipped: bool,
    t: float,
    reset_s: float,
    max_gap_s: float,
    evidence: bool = True,
) -> bool:
    """Counts a clipped update (in ``aux``); True when P must return to the prior.

    Call before ``aux[T_UPDATE]`` takes ``t``. A spike is one sample or a
    few. When every update has been clipped for ``reset_s`` seconds (a run
    that a gap longer than ``max_gap_s`` between updates, such as a contact
    loss, restarts), the data disagree with the estimate and its
    covariance, not with a spike: the caller then resets the covariance to
    the prior (:func:`reset_covariance`; the estimate is kept), so that the
    data move the estimate again. ``reset_s`` 0: never.

    ``evidence`` False: the clipped update is counted but ends the run and
    cannot start one. The callers pass False when the estimate predicts a
    pulling force at the sample's penetration rate (kappa + lam eps_dot
    <= 0): the model holds only where it pushes, so the residual says that
    the estimate (lam at that rate) is outside it, not that the tissue
    changed, and a reset would hand the residual to kappa.
    """
    if not clipped:
        aux[CLIP_START] = math.nan
        return False
    aux[N_CLIPPED] += 1.0
    if not evidence:
        aux[CLIP_START] = math.nan
        return False
    if math.isnan(aux[CLIP_START]) or not t - aux[T_UPDATE] <= max_gap_s:
        aux[CLIP_START] = t
    if reset_s > 0.0 and t - aux[CLIP_START] >= reset_s:
        aux[CLIP_START] = math.nan
        return True
    return False


def confirm_reset(
    aux: list[float],
    x: list[float],
    P: list[float],
    saved: list[float],
    t: float,
    update: list[float] | None,
    reset: bool,
    confirm_s: float,
) -> None:
    """Keeps or undoes a covariance reset; x, P, saved and aux in place.

    Call on every good sample: after the update and :func:`record_clip`
    with ``update`` the x + P of before the update (``reset``: record_clip
    asked for a reset; P is reset after this call), or with ``update`` None
    on a sample out of contact. ``saved`` keeps x + P of before the first
    update of the current run of clipped updates. A reset is confirmed once
    the updates have gone on for ``confirm_s`` after it. Before that, the
    first sample out of contact puts back the saved x and P, of before the
    run that led to the first of the unconfirmed resets: that run was the
    contact's ending (a lift-off, a surface that moved with the probe),
    which says nothing of the tissue, and the estimate is held out of
    contact for the next one. ``confirm_s`` 0: resets are never undone.
    """
    n = len(x)
    pending = not math.isnan(aux[RESET_T])
    if update is None:
        if pending:
            x[:] = saved[:n]
            P[:] = saved[n:]
            aux[RESET_T] = math.nan
            aux[N_RESTORED] += 1.0
        return
    if pending and t - aux[RESET_T] >= confirm_s:
        aux[RESET_T] = math.nan
        pending = False
        if not math.isnan(aux[CLIP_START]):  # in a run: its evidence from here
            saved[:] = update
    elif not pending and aux[CLIP_START] == t:  # a run starts
        saved[:] = update
    if reset and confirm_s > 0.0:
        aux[RESET_T] = t


def gated_update(
    aux: list[float],
    x: list[float],
    P: list[float],
    saved: list[float],
    t: float,
    h: list[float],
    innovation: float,
    stiffness: float,
    prior_var: list[float],
    p: OnlineEstimatorParams,
) -> None:
    """One update in contact, in place: :func:`scalar_update` with the gate,
    :func:`record_clip` (``stiffness`` = kappa + lam eps_dot of the estimate
    before the update; <= 0 is no evidence), :func:`bound_parameters`,
    :func:`confirm_reset`, and P back to ``prior_var`` when record_clip asks
    for it (:func:`reset_covariance`)."""
    before = x + P
    clipped = scalar_update(x, P, h, innovation, p.noise_std_N**2, p.gate_sigma)
    reset = record_clip(aux, clipped, t, p.clip_reset_s, p.max_gap_s, stiffness > 0.0)
    bound_parameters(x, p.max_rel_change)
    confirm_reset(aux, x, P, saved, t, before, reset, p.reset_confirm_s)
    if reset:
        reset_covariance(P, prior_var)


def reset_covariance(P: list[float], prior_var: list[float]) -> None:
    """P = diag(prior_var), in place."""
    n = len(prior_var)
    P[:] = [0.0] * (n * n)
    for i in range(n):
        P[i * n + i] = prior_var[i]


def cap_variances(P: list[float], caps: list[float]) -> None:
    """Scales row and column i so that P_ii <= caps[i] (keeps P PSD), in place."""
    n = len(caps)
    for i in range(n):
        pii = P[i * n + i]
        if pii > caps[i]:
            f = math.sqrt(caps[i] / pii)
            for j in range(n):
                P[i * n + j] *= f
                P[j * n + i] *= f


def bound_parameters(x: list[float], max_rel_change: float) -> None:
    """Keeps the normalised kappa and lam (x[0], x[1]) in [1/m, m], in place."""
    lo = 1.0 / max_rel_change
    for i in (0, 1):
        v = x[i]  # NaN stays NaN, as with min(max(v, lo), max_rel_change)
        x[i] = lo if v < lo else max_rel_change if v > max_rel_change else v


def make_estimate(
    aux: list[float],
    x: list[float],
    P: list[float],
    p: OnlineEstimatorParams,
    surface: float,
    in_contact: bool,
) -> Estimate:
    """The outputs of a state (kappa and lam de-normalised)."""
    n = len(x)
    kappa = x[0] * p.kappa_prior
    kappa_var = P[0] * p.kappa_prior**2
    lam_var = P[n + 1] * p.lam_prior**2
    valid = in_contact and math.sqrt(max(kappa_var, 0.0)) < p.valid_rel_std * kappa
    return Estimate(
        kappa,
        x[1] * p.lam_prior,
        kappa_var,
        lam_var,
        1.0 if valid else 0.0,
        surface,
        1.0 if in_contact else 0.0,
    )


__all__ = [
    "AUX_SIZE",
    "OUTPUT_FIELDS",
    "Estimate",
    "bound_parameters",
    "cap_variances",
    "confirm_reset",
    "gated_update",
    "initial_state",
    "make_estimate",
    "prepare",
    "record_clip",
    "reset_covariance",
    "scalar_update",
    "state_size",
    "unpack",
]
