"""Settings of the online tissue estimators (RLS and EKF on Hunt-Crossley).

One dataclass for both estimators, so a scenario can switch ``method``
without rewriting the rest. Mutable with a :meth:`validate`, as every config
that ``yaml_load_typed`` fills (no ``from __future__ import annotations``:
the loader reads the field types at run time).
"""

from dataclasses import dataclass

from vic_drake.errors import VicDrakeError, check_number
from vic_drake.paper import BEST_BETA, CONTACT_THRESHOLD_N

#: The online estimators, by name.
ONLINE_METHODS = ("rls", "ekf")
#: How the slope fit's surface is formed
#: (:mod:`~vic_drake.estimation.online.slope`).
SLOPE_KAPPA_MODES = ("tracker", "direct")
#: What the slope fit takes as its instrument
#: (:mod:`~vic_drake.estimation.online.slope_instrument`).
SLOPE_INSTRUMENTS = ("dither", "none")


def _number(name: str, value, *, low=None, low_open=False, high=None) -> float:
    if isinstance(value, bool):
        raise VicDrakeError(
            f"OnlineEstimatorParams.{name} must be a number; got {value!r}"
        )
    return check_number(
        "OnlineEstimatorParams", name, value, low=low, low_open=low_open, high=high
    )


@dataclass
class OnlineEstimatorParams:
    """How the online estimator weighs the prior, the data and the faults.

    Measurement model (the tissue force on the probe, positive = the body
    pushes the probe up; paper eq. 2):
    ``F = (kappa + lam eps_dot) eps^beta``, ``eps = s - z``,
    ``eps_dot = s_dot - z_dot``.

    Attributes:
        method: "rls" (recursive least squares with exponential forgetting
            on kappa, lam at fixed beta) or "ekf" (extended Kalman filter
            with kappa, lam, a surface offset and optionally beta as a
            random walk).
        beta: Hunt-Crossley exponent (fixed; the EKF's initial value when
            ``estimate_beta``).
        kappa_prior: nominal kappa the estimate starts from, N/m^beta.
        lam_prior: nominal lam, N s/m^(beta+1).
        prior_rel_std: prior standard deviation of kappa and lam as a
            fraction of the prior (the RLS's initial covariance too); the
            RLS never lets a variance exceed it (no covariance wind-up when
            lam is not excited).
        noise_std_N: standard deviation of the force residual (sensor noise
            and model error), N.
        memory_s: RLS forgetting time constant, s (forgetting factor
            exp(-dt / memory_s) per sample in contact).
        kappa_walk_rel_per_sqrt_s: EKF random walk of kappa, fraction of
            the prior per sqrt(s).
        lam_walk_rel_per_sqrt_s: EKF random walk of lam, likewise.
        surface_prior_std_m: EKF prior std of the surface offset, m.
        surface_walk_m_per_sqrt_s: EKF random walk of the surface offset,
            m per sqrt(s); 0 keeps the surface of the input (or of first
            contact).
        estimate_beta: EKF only: beta joins the state.
        beta_prior_std: EKF prior std of beta.
        beta_walk_per_sqrt_s: EKF random walk of beta per sqrt(s).
        contact_threshold_N: contact when the force exceeds this, N.
        min_penetration_m: and the penetration exceeds this, m.
        latch_rise_filter_s: without a surface (input or slope fit's), a
            surface latched at first contact stands once the force,
            low-passed with this time constant, s, has risen by
            ``contact_threshold_N`` above its lowest value since the latch;
            until then the samples do not update the estimate (a sensor's
            bias on the pressing side reads as contact in free air); 0: the
            latch stands at once (and ``contact_fall_margin_N`` is not
            used).
        contact_fall_margin_N: a contact whose force (low-passed as above)
            has risen by ``contact_threshold_N`` ends when it falls back to
            within this of the level it rose from, N, even above the
            threshold (a probe that the tissue has left reads the sensor's
            bias, not zero); the next contact needs the force to rise
            again (:mod:`~vic_drake.estimation.online.contact`).
        contact_fall_air_travel_m: ... but only once the tip has gone down
            by at least this, m, at that level before the rise (the level
            is then free air's, not a force of a contact the data start
            in). Such a level above ``contact_threshold_N`` is also the
            sensor's tare: it is subtracted from the force until the
            reading drops to the threshold.
        gate_sigma: innovations are clipped at this many predicted
            standard deviations (a spike moves the estimate by a bounded
            step, a real change still gets through).
        clip_reset_s: when every update has been clipped for this long, s,
            the covariance returns to the prior (the tissue changed faster
            than the covariance allowed, or the prior was far off); 0:
            never. Clipped updates where the estimate predicts a pulling
            force (kappa + lam eps_dot <= 0) do not count.
        reset_confirm_s: a covariance reset stands once the contact has
            gone on for this long after it, s; a contact that ends sooner
            puts back the estimate and covariance of before the reset (the
            clipped run was the contact's ending); 0: resets always stand.
        valid_rel_std: the estimate is flagged valid in contact once the
            std of kappa is below this fraction of kappa_hat.
        max_gap_s: a sample more than this after the previous one restarts
            the surface-rate filter (a dropout), s.
        surface_rate_time_constant_s: low-pass time constant of the surface
            rate s_dot (finite differences of the surface input), s.
        max_rel_change: kappa and lam stay within [prior / max_rel_change,
            prior * max_rel_change].
        surface_from_slope: EKF only: the surface comes from the tissue's
            local slope under the moving tip
            (:mod:`vic_drake.estimation.online.slope`) instead of being
            latched at first contact, once that fit is valid. It needs the
            tip to keep moving (a dither of the penetration,
            ``ReferenceParams.penetration_dither_m``).
        slope_memory_s: forgetting time constant of the slope fit, s.
        slope_min_motion_m: a solve of the fit counts only when the tip's
            motion beyond the slow trend has at least this RMS, m.
        slope_max_rel_std: ... and the relative standard error of the
            slope is at most this.
        slope_surface_time_s: time scale of the filter that tracks the
            fit's surface (1 / its natural frequency), s ("tracker" mode).
        slope_kappa_mode: "tracker" (the fit's surface through a slow
            filter; kappa follows the force) or "direct" (kappa from the
            fit's valid solves, held between them; the surface z + (F /
            kappa)^(1 / beta)); in both, a saturated stiffness softens a
            held kappa towards the force at the held surface; see
            :mod:`~vic_drake.estimation.online.slope` and, for where each
            wins, docs/decisions.md ("The tracker at the controller's
            bounds").
        slope_kappa_max_rate_per_s: ln kappa moves at most this fast under
            a saturated stiffness (both modes) and, in "direct" mode, from
            the valid solves too, 1/s (the tissue under the probe at scan
            speed changes its ln kappa by at most ~0.5/s on both phantoms).
        slope_instrument: "dither" (the fit takes the controller's dither
            as its instrument, which the loop's own motion does not bias;
            :mod:`~vic_drake.estimation.online.slope_instrument`) or "none"
            (least squares). Where the dither's frequency is not known (a
            replay of a log), the fit is least squares either way.
    """

    method: str = "rls"
    beta: float = BEST_BETA
    kappa_prior: float = 4000.0
    lam_prior: float = 32000.0
    prior_rel_std: float = 0.5
    noise_std_N: float = 0.2
    memory_s: float = 2.0
    kappa_walk_rel_per_sqrt_s: float = 0.1
    lam_walk_rel_per_sqrt_s: float = 0.1
    surface_prior_std_m: float = 0.002
    surface_walk_m_per_sqrt_s: float = 0.0
    estimate_beta: bool = False
    beta_prior_std: float = 0.1
    beta_walk_per_sqrt_s: float = 0.0
    contact_threshold_N: float = CONTACT_THRESHOLD_N
    min_penetration_m: float = 0.5e-3
    latch_rise_filter_s: float = 0.05
    contact_fall_margin_N: float = 0.2
    contact_fall_air_travel_m: float = 0.002
    gate_sigma: float = 4.0
    clip_reset_s: float = 0.05
    reset_confirm_s: float = 0.1
    valid_rel_std: float = 0.1
    max_gap_s: float = 0.02
    surface_rate_time_constant_s: float = 0.02
    max_rel_change: float = 20.0
    surface_from_slope: bool = False
    slope_memory_s: float = 0.2
    slope_min_motion_m: float = 5e-5
    slope_max_rel_std: float = 0.05
    slope_surface_time_s: float = 0.5
    slope_kappa_mode: str = "tracker"
    slope_kappa_max_rate_per_s: float = 1.0
    slope_instrument: str = "dither"

    def __post_init__(self):
        self.validate()

    @property
    def reads_controller_bounds(self) -> bool:
        """Whether the estimator reads whether the controller's stiffness
        and force are at their bounds: the slope fit does
        (:mod:`~vic_drake.estimation.online.slope`)."""
        return self.surface_from_slope

    def validate(self) -> "OnlineEstimatorParams":
        """Checks every field; returns self (raises VicDrakeError naming it)."""
        if self.method not in ONLINE_METHODS:
            raise VicDrakeError(
                f"OnlineEstimatorParams.method must be one of {list(ONLINE_METHODS)}; "
                f"got {self.method!r}"
            )
        _number("beta", self.beta, low=0.0, low_open=True, high=3.0)
        for name in ("kappa_prior", "lam_prior", "noise_std_N", "memory_s"):
            _number(name, getattr(self, name), low=0.0, low_open=True)
        _number("prior_rel_std", self.prior_rel_std, low=0.0, low_open=True)
        _number("surface_prior_std_m", self.surface_prior_std_m, low=0.0, low_open=True)
        _number("beta_prior_std", self.beta_prior_std, low=0.0, low_open=True)
        for name in (
            "kappa_walk_rel_per_sqrt_s",
            "lam_walk_rel_per_sqrt_s",
            "surface_walk_m_per_sqrt_s",
            "beta_walk_per_sqrt_s",
            "contact_threshold_N",
            "min_penetration_m",
            "latch_rise_filter_s",
            "contact_fall_margin_N",
            "contact_fall_air_travel_m",
            "surface_rate_time_constant_s",
            "clip_reset_s",
            "reset_confirm_s",
        ):
            _number(name, getattr(self, name), low=0.0)
        _number("gate_sigma", self.gate_sigma, low=0.0, low_open=True)
        _number("valid_rel_std", self.valid_rel_std, low=0.0, low_open=True)
        _number("max_gap_s", self.max_gap_s, low=0.0, low_open=True)
        _number("max_rel_change", self.max_rel_change, low=1.0, low_open=True)
        if not isinstance(self.estimate_beta, bool):
            raise VicDrakeError(
                "OnlineEstimatorParams.estimate_beta must be true or false; "
                f"got {self.estimate_beta!r}"
            )
        _number("slope_memory_s", self.slope_memory_s, low=0.0, low_open=True)
        _number("slope_min_motion_m", self.slope_min_motion_m, low=0.0)
        _number("slope_max_rel_std", self.slope_max_rel_std, low=0.0, low_open=True)
        _number(
            "slope_surface_time_s", self.slope_surface_time_s, low=0.0, low_open=True
        )
        if self.slope_kappa_mode not in SLOPE_KAPPA_MODES:
            raise VicDrakeError(
                "OnlineEstimatorParams.slope_kappa_mode must be one of "
                f"{list(SLOPE_KAPPA_MODES)}; got {self.slope_kappa_mode!r}"
            )
        if self.slope_instrument not in SLOPE_INSTRUMENTS:
            raise VicDrakeError(
                "OnlineEstimatorParams.slope_instrument must be one of "
                f"{list(SLOPE_INSTRUMENTS)}; got {self.slope_instrument!r}"
            )
        _number(
            "slope_kappa_max_rate_per_s",
            self.slope_kappa_max_rate_per_s,
            low=0.0,
            low_open=True,
        )
        if not isinstance(self.surface_from_slope, bool):
            raise VicDrakeError(
                "OnlineEstimatorParams.surface_from_slope must be true or false; "
                f"got {self.surface_from_slope!r}"
            )
        if self.surface_from_slope and self.method != "ekf":
            raise VicDrakeError(
                "OnlineEstimatorParams.surface_from_slope needs method 'ekf'; got "
                f"method {self.method!r}"
            )
        if self.estimate_beta and self.method != "ekf":
            raise VicDrakeError(
                "OnlineEstimatorParams.estimate_beta needs method 'ekf' (the RLS "
                f"holds beta fixed); got method {self.method!r}"
            )
        return self


__all__ = [
    "ONLINE_METHODS",
    "SLOPE_INSTRUMENTS",
    "SLOPE_KAPPA_MODES",
    "OnlineEstimatorParams",
]
