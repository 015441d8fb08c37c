"""Identification of the relaxing Hunt-Crossley law."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    estimate_lag,
    fit_hunt_crossley,
    shift,
)
from vic_drake.estimation.relaxation_fit import (
    fit_relaxation,
    held_out_errors,
    predict_force,
)
from vic_drake.realdata import read_bag
from vic_drake.tissue import (
    RelaxationParams,
    relaxation_history,
    relaxation_input,
    relaxing_hunt_crossley_force,
)

BETA = 1.35
TRUTH = RelaxationParams(fractions=(0.1,), time_constants_s=(8.0,))
NOISE_N = 0.02
SURFACE_M = 0.1


def _palpation(freq_hz, kappa, lam, seed, duration_s=40.0) -> PalpationData:
    """A sinusoidal palpation of relaxing tissue, starting 0.5 s above it."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, duration_s, 0.002)
    w = 2 * np.pi * freq_hz
    tc = t - 0.5
    eps = np.where(
        tc < 0, 0.004 * tc, 0.012 * (1 - np.exp(-tc / 0.2)) + 0.005 * np.sin(w * tc)
    )
    eps_dot = np.gradient(eps, t)
    state = relaxation_history(t, relaxation_input(eps, BETA), TRUTH.time_constants_s)
    force = relaxing_hunt_crossley_force(
        eps, eps_dot, kappa, lam, BETA, state, TRUTH.fractions, clip_tension=True
    )
    return PalpationData(
        t_s=t,
        z_m=SURFACE_M - eps,
        force_N=force + NOISE_N * rng.standard_normal(t.size),
        surface_z_m=SURFACE_M,
    )


@pytest.fixture(scope="module")
def synthetic():
    return {
        "a": _palpation(1.0, 3000.0, 2e4, 0),
        "b": _palpation(2.5, 4500.0, 3e4, 1),
        "c": _palpation(2.0, 3800.0, 2.5e4, 2),
    }


def test_fit_recovers_the_relaxation_and_the_parameters(synthetic):
    train = {k: synthetic[k] for k in ("a", "b")}
    fit = fit_relaxation(
        train, beta=BETA, initial_time_constants_s=(3.0,), indenter_mass_kg=0.0
    )
    assert fit.relaxation.fractions[0] == pytest.approx(0.1, rel=0.1)
    assert fit.relaxation.time_constants_s[0] == pytest.approx(8.0, rel=0.2)
    assert fit.kappa["a"] == pytest.approx(3000.0, rel=0.02)
    assert fit.kappa["b"] == pytest.approx(4500.0, rel=0.02)
    for name in train:
        assert fit.rms_N[name] < 1.3 * NOISE_N
        assert fit.hc_rms_N[name] > 2 * fit.rms_N[name]


def test_held_out_log_is_predicted_better_than_by_plain_hc(synthetic):
    errors = held_out_errors(
        TRUTH, {"c": synthetic["c"]}, beta=BETA, indenter_mass_kg=0.0
    )
    e = errors["c"]
    assert e.relaxing_rms_N < 1.3 * NOISE_N
    assert e.hc_rms_N > 2 * e.relaxing_rms_N
    assert e.kappa == pytest.approx(3800.0, rel=0.02)
    # The plain fit on a relaxing log lands between the relaxed and the
    # instantaneous kappa.
    assert TRUTH.long_term_fraction * 3800.0 < e.hc_kappa < 3800.0


def test_prediction_without_relaxation_is_hunt_crossley(synthetic):
    data = synthetic["c"]
    hc = fit_hunt_crossley(data, BETA, indenter_mass_kg=0.0)
    predicted = predict_force(
        None, hc.kappa, hc.lam, data, beta=BETA, indenter_mass_kg=0.0
    )
    relaxing = predict_force(
        TRUTH, 3800.0, 2.5e4, data, beta=BETA, indenter_mass_kg=0.0
    )
    late = data.t_s > 20.0
    err_hc = np.sqrt(np.mean((predicted - data.force_N)[late] ** 2))
    err_relaxing = np.sqrt(np.mean((relaxing - data.force_N)[late] ** 2))
    assert err_relaxing < 1.3 * NOISE_N < err_hc


def test_bad_arguments_are_named(synthetic):
    with pytest.raises(VicDrakeError, match="at least one log"):
        fit_relaxation({})
    with pytest.raises(VicDrakeError, match="initial_time_constants_s"):
        fit_relaxation({"a": synthetic["a"]}, initial_time_constants_s=(-1.0,))
    with pytest.raises(VicDrakeError, match="max_time_constant_s"):
        fit_relaxation(
            {"a": synthetic["a"]},
            initial_time_constants_s=(5.0,),
            max_time_constant_s=2.0,
        )


@pytest.mark.realdata
def test_real_held_out_palpation_is_predicted_better_than_by_plain_hc(data_dir):
    """Shape fitted on 1 Hz and 2.5 Hz; 2 Hz held out (kappa, lam refitted)."""
    logs = {}
    for name in ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz"):
        raw = PalpationData.from_frame(read_bag(data_dir / "palpation" / name))
        logs[name] = shift(raw, estimate_lag(raw, 0.2))
    held = logs.pop("test_soft_2hz")
    fit = fit_relaxation(logs, initial_time_constants_s=(5.0,))
    assert 0.0 < fit.relaxation.fractions[0] < 0.5
    e = held_out_errors(fit.relaxation, {"held": held})["held"]
    assert e.relaxing_rms_N < 0.8 * e.hc_rms_N
