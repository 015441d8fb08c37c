"""Hunt-Crossley tissue with stress relaxation (a quasi-linear viscoelastic law).

The elastic Hunt-Crossley term relaxes after a Prony series (Fung's
quasi-linear viscoelasticity with the instantaneous elastic response
``kappa u``, ``u = max(eps, 0)^beta``):

    F = kappa (u - sum_i g_i s_i) + lam u eps_dot,
    ds_i/dt = (u - s_i) / tau_i,

with relaxation fractions g_i >= 0 (sum < 1) and time constants tau_i > 0.
Each branch state s_i (m^beta) is u seen through a first-order lag, so a
step of penetration first meets the instantaneous modulus ``kappa``, then
the force decays as ``kappa u (g_inf + sum_i g_i exp(-t / tau_i))`` towards
the long-term (relaxed) modulus ``kappa g_inf``, ``g_inf = 1 - sum_i g_i``.
At the equilibrium of a slow press (s_i = u, eps_dot = 0) the law is plain
Hunt-Crossley with kappa scaled by g_inf. Out of contact u = 0 and the
states decay: the tissue recovers. Under a held force the compliant probe
sinks as the force relaxes (creep).

Which kappa: the ``kappa`` argument (and a phantom map's kappa) is the
INSTANTANEOUS modulus; the relaxed one is ``g_inf kappa``
(:attr:`RelaxationParams.long_term_fraction`). A map fitted with plain
Hunt-Crossley on palpations of a few seconds, short against the relaxation
time, holds about the instantaneous kappa. With every g_i = 0 the law is
:func:`vic_drake.tissue.models.hunt_crossley_force`.

States are in units of u (not force), so one state serves a probe that
slides over tissue whose kappa varies (the scan's force element).

Discrete update (:func:`relaxation_step`): exact for an input u held
constant over the step, ``s <- u + (s - u) exp(-h / tau)``; it is what a
tissue element runs each tick, and :func:`relaxation_history` runs the same
recurrence along a logged trajectory for the fits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from vic_drake.errors import VicDrakeError

#: The tissue laws a simulation can use: ``"relaxing"`` (this module, with
#: :data:`DEFAULT_RELAXATION`) or ``"hc"`` (plain Hunt-Crossley).
TISSUE_LAWS = ("relaxing", "hc")


@dataclass(frozen=True)
class RelaxationParams:
    """A Prony series of the Hunt-Crossley elastic term (see module doc).

    Attributes:
        fractions: g_i, the parts of the instantaneous modulus that relax
            (each >= 0, sum < 1).
        time_constants_s: tau_i, s (each > 0), one per fraction.
    """

    fractions: tuple[float, ...]
    time_constants_s: tuple[float, ...]

    def __post_init__(self):
        g = tuple(float(v) for v in np.atleast_1d(self.fractions))
        tau = tuple(float(v) for v in np.atleast_1d(self.time_constants_s))
        if len(g) != len(tau):
            raise VicDrakeError(
                "RelaxationParams.fractions and time_constants_s must have the same "
                f"length, got {len(g)} and {len(tau)}"
            )
        if not all(math.isfinite(v) and v >= 0.0 for v in g) or not sum(g) < 1.0:
            raise VicDrakeError(
                "RelaxationParams.fractions must be finite, >= 0 and sum to < 1, "
                f"got {g!r}"
            )
        if not all(math.isfinite(v) and v > 0.0 for v in tau):
            raise VicDrakeError(
                f"RelaxationParams.time_constants_s must be finite and > 0, got {tau!r}"
            )
        object.__setattr__(self, "fractions", g)
        object.__setattr__(self, "time_constants_s", tau)

    @property
    def n_branches(self) -> int:
        return len(self.fractions)

    @property
    def long_term_fraction(self) -> float:
        """g_inf = 1 - sum g_i: relaxed kappa / instantaneous kappa."""
        return 1.0 - float(sum(self.fractions))

    def as_dict(self) -> dict:
        """{"fractions": [...], "time_constants_s": [...]} (JSON-ready)."""
        return {
            "fractions": list(self.fractions),
            "time_constants_s": list(self.time_constants_s),
        }

    def relaxation_function(self, t_s) -> np.ndarray:
        """G(t) = g_inf + sum_i g_i exp(-t / tau_i): the force after a unit step."""
        t = np.asarray(t_s, float)[..., None]
        g = np.asarray(self.fractions)
        tau = np.asarray(self.time_constants_s)
        return self.long_term_fraction + np.sum(g * np.exp(-t / tau), axis=-1)


#: The relaxation identified on the paper's palpation and load-test logs
#: (:func:`vic_drake.estimation.relaxation_fit.fit_relaxation`, fitted on
#: the three palpations; see docs/decisions.md, "Tissue relaxation").
DEFAULT_RELAXATION = RelaxationParams(fractions=(0.080,), time_constants_s=(22.9,))

#: Period of a tissue element's state update, s: the rig's 500 Hz tick. The
#: update is exact for an input held over the step, and tau >> 2 ms.
DEFAULT_UPDATE_PERIOD_S = 0.002


def tissue_relaxation(law: str) -> RelaxationParams | None:
    """The relaxation of a named tissue law (None: plain Hunt-Crossley).

    Raises:
        VicDrakeError: ``law`` is not one of :data:`TISSUE_LAWS`.
    """
    if law == "relaxing":
        return DEFAULT_RELAXATION
    if law == "hc":
        return None
    raise VicDrakeError(f"tissue law must be one of {TISSUE_LAWS}, got {law!r}")


def relaxation_input(eps, beta: float) -> np.ndarray:
    """u = max(eps, 0)^beta, the quantity every branch relaxes towards, m^beta."""
    eps = np.asarray(eps, float)
    return np.where(eps > 0.0, eps, 0.0) ** beta


def relaxation_step(state, u, dt_s: float, time_constants_s) -> np.ndarray:
    """Branch states after dt_s with u held constant (exact), m^beta.

    Args:
        state: (..., K) states now.
        u: input, broadcast against ``state[..., 0]`` (e.g. (n,) for n probes).
        dt_s: step, s (>= 0).
        time_constants_s: (K,) tau_i, s.

    Returns:
        (..., K): ``u + (state - u) exp(-dt / tau)``.
    """
    decay = np.exp(-float(dt_s) / np.asarray(time_constants_s, float))
    u = np.asarray(u, float)[..., None]
    return u + (np.asarray(state, float) - u) * decay


def relaxing_hunt_crossley_force(
    eps,
    eps_dot,
    kappa,
    lam,
    beta: float,
    state,
    fractions,
    *,
    clip_tension: bool = False,
) -> np.ndarray:
    """F = kappa (u - sum_i g_i s_i) + lam u eps_dot, 0 out of contact (N).

    Args:
        eps, eps_dot: penetration, m, and its rate, m/s (as in
            :func:`~vic_drake.tissue.models.hunt_crossley_force`).
        kappa: INSTANTANEOUS elasticity, N/m^beta. lam: viscosity,
            N s/m^(beta+1). beta: exponent.
        state: (..., K) branch states s_i, m^beta (K may be 0).
        fractions: (K,) g_i.
        clip_tension: never return a negative (pulling) force.
    """
    eps = np.asarray(eps, float)
    u = relaxation_input(eps, beta)
    relaxed = np.asarray(state, float) @ np.asarray(fractions, float)
    force = np.asarray(kappa, float) * (u - relaxed) + np.asarray(
        lam, float
    ) * u * np.asarray(eps_dot, float)
    force = np.where(eps > 0.0, force, 0.0)
    if clip_tension:
        force = np.maximum(force, 0.0)
    return force


def relaxation_history(t_s, u, time_constants_s, initial=None) -> np.ndarray:
    """Branch states at every sample of a trajectory, (n, K), m^beta.

    Runs :func:`relaxation_step` along the samples: the state of sample k is
    the state of sample k-1 advanced by t_k - t_{k-1} with u held at its
    value of sample k-1, as a tissue element ticking at those times does.

    Args:
        t_s: (n,) increasing times, s. u: (n,) inputs, m^beta (e.g.
            :func:`relaxation_input`). time_constants_s: (K,) tau_i, s.
        initial: (K,) states at t_s[0]; default zero (relaxed, unloaded).
    """
    t = np.asarray(t_s, float)
    u = np.asarray(u, float)
    taus = [float(v) for v in np.atleast_1d(time_constants_s)]
    if t.ndim != 1 or u.shape != t.shape:
        raise VicDrakeError(
            f"relaxation_history: t_s and u must be 1-D of one length, got shapes "
            f"{t.shape} and {u.shape}"
        )
    dt = np.diff(t)
    if np.any(dt < 0):
        raise VicDrakeError("relaxation_history: t_s must not decrease")
    out = np.zeros((t.size, len(taus)))
    start = np.zeros(len(taus)) if initial is None else np.asarray(initial, float)
    u_prev = u[:-1].tolist()
    for j, tau in enumerate(taus):
        # A scalar Python loop: a few times faster than per-sample numpy ops.
        decay = np.exp(-dt / tau).tolist()
        s = float(start[j])
        column = [s]
        for a, v in zip(decay, u_prev):
            s = v + (s - v) * a
            column.append(s)
        out[:, j] = column
    return out


__all__ = [
    "DEFAULT_RELAXATION",
    "DEFAULT_UPDATE_PERIOD_S",
    "TISSUE_LAWS",
    "RelaxationParams",
    "relaxation_history",
    "relaxation_input",
    "relaxation_step",
    "relaxing_hunt_crossley_force",
    "tissue_relaxation",
]
