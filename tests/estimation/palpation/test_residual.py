"""Fig. 3: residual against palpation time and its exponential fit."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.palpation import (
    PalpationData,
    fit_exponential,
    residual_vs_palpation_time,
)
from vic_drake.estimation.palpation.residual import DEFAULT_START_STEP_S

from .synthetic import synthetic_palpation


def test_exponential_fit_recovers_parameters():
    t = np.linspace(0.5, 30.0, 40)
    fit = fit_exponential(t, 0.1 * np.exp(-t / 4.0) + 0.02)
    assert fit.a == pytest.approx(0.1, rel=1e-4)
    assert fit.tau_s == pytest.approx(4.0, rel=1e-4)
    assert fit.c == pytest.approx(0.02, rel=1e-4)


def test_exponential_fit_is_robust_to_one_outlier():
    t = np.linspace(0.5, 30.0, 40)
    r = 0.1 * np.exp(-t / 4.0) + 0.02
    r[1] = 0.0  # One window that happened to generalise unusually well.
    fit = fit_exponential(t, r)
    assert fit.tau_s == pytest.approx(4.0, rel=0.1)
    assert fit.c == pytest.approx(0.02, rel=0.05)


def test_residual_decreases_with_palpation_time():
    data = synthetic_palpation(noise_N=0.2, duration_s=20.0, seed=5)
    curve = residual_vs_palpation_time(data)
    assert curve.window_s[0] == 0.5
    assert curve.window_s[-1] == pytest.approx(data.duration_s, abs=0.01)
    # The whole-log fit minimises the whole-log residual.
    assert curve.relative[-1] == pytest.approx(curve.relative.min(), rel=1e-9)
    assert curve.relative[0] > curve.relative[-1]
    assert curve.kappa[-1] == pytest.approx(4000.0, rel=0.05)


def _brute_force_curve(data, T, starts):
    """Relative whole-log residual of lstsq fits on [s, s + T], one per start,
    and the in-contact span of the log, s."""
    from vic_drake.estimation.palpation.data import (
        DEFAULT_INDENTER_MASS_KG,
        DEFAULT_MIN_FORCE_N,
        DEFAULT_MIN_PENETRATION_M,
        DEFAULT_SPIKE_SIGMA,
    )
    from vic_drake.estimation.palpation.fits import _hc_columns, _lstsq, _problem
    from vic_drake.estimation.signals import DEFAULT_DERIVATIVE_WINDOW_S
    from vic_drake.paper import BEST_BETA

    p = _problem(
        data,
        derivative_window_s=DEFAULT_DERIVATIVE_WINDOW_S,
        min_penetration_m=DEFAULT_MIN_PENETRATION_M,
        min_force_N=DEFAULT_MIN_FORCE_N,
        spike_sigma=DEFAULT_SPIKE_SIGMA,
    )
    t = (data.t_s - data.t_s[np.argmax(p.mask)])[p.mask]
    A, y = _hc_columns(p, BEST_BETA), p.target(DEFAULT_INDENTER_MASS_KG)
    rms_y = np.sqrt(np.mean(y**2))
    out = []
    for s in starts:
        sel = (t >= s) & (t <= s + T)
        coef, _, _ = _lstsq(A[sel], y[sel])
        out.append(np.sqrt(np.mean((y - A @ coef) ** 2)) / rms_y)
    return np.array(out), float(t[-1])


def test_each_length_is_the_mean_over_its_placements():
    data = synthetic_palpation(noise_N=0.2, duration_s=6.0, seed=3)
    curve = residual_vs_palpation_time(data, [1.0, 2.5], start_step_s=0.5)
    _, span = _brute_force_curve(data, 1.0, [0.0])
    assert 5.5 < span < 6.0
    # Starts 0, 0.5, ... while the window ends inside the in-contact span.
    assert list(curve.n_windows) == [10, 7]
    for T, n, r in zip(curve.window_s, curve.n_windows, curve.relative):
        brute, _ = _brute_force_curve(data, T, 0.5 * np.arange(n))
        assert r == pytest.approx(brute.mean(), rel=1e-9)
    rms = residual_vs_palpation_time(data, [1.0], start_step_s=0.5, average="rms")
    med = residual_vs_palpation_time(data, [1.0], start_step_s=0.5, average="median")
    brute, _ = _brute_force_curve(data, 1.0, 0.5 * np.arange(10))
    assert rms.relative[0] == pytest.approx(np.sqrt(np.mean(brute**2)), rel=1e-9)
    assert med.relative[0] == pytest.approx(np.median(brute), rel=1e-9)


def test_one_placement_per_length_is_the_first_window():
    data = synthetic_palpation(noise_N=0.2, duration_s=6.0, seed=3)
    curve = residual_vs_palpation_time(data, [0.5, 2.0, 4.0])
    assert list(curve.n_windows) == [1, 1, 1] and curve.start_step_s is None
    for T, r in zip(curve.window_s, curve.relative):
        assert r == pytest.approx(_brute_force_curve(data, T, [0.0])[0][0], rel=1e-9)


def test_an_odd_start_does_not_set_the_curve():
    """Tissue 30 % stiffer in the first second (say, not yet relaxed): a
    short window at the first in-contact sample holds only that second and
    its parameters miss the rest of the log; averaged over placements, the
    short windows' excess over the whole-log fit stays small."""
    plain = synthetic_palpation(noise_N=0.05, duration_s=12.0, seed=4)
    force = plain.force_N.copy()
    force[plain.t_s < 1.0] *= 1.3
    odd = PalpationData(
        t_s=plain.t_s, z_m=plain.z_m, force_N=force, surface_z_m=plain.surface_z_m
    )
    windows = [0.5, 1.0, 12.0]
    first = residual_vs_palpation_time(odd, windows, start_step_s=None)
    spread = residual_vs_palpation_time(odd, windows, start_step_s=DEFAULT_START_STEP_S)
    whole = first.relative[-1]
    assert spread.relative[-1] == pytest.approx(whole, rel=1e-12)
    excess_first = first.relative[:2] - whole
    excess_spread = spread.relative[:2] - whole
    assert np.all(excess_spread > 0)
    assert np.all(excess_spread < 0.2 * excess_first)
    # Without the odd second, both placements give about the same curve.
    clean_first = residual_vs_palpation_time(plain, windows, start_step_s=None)
    clean_spread = residual_vs_palpation_time(
        plain, windows, start_step_s=DEFAULT_START_STEP_S
    )
    np.testing.assert_allclose(clean_spread.relative, clean_first.relative, rtol=0.02)


@pytest.mark.parametrize("step", [0.0, -0.5, float("nan"), float("inf"), "fast"])
def test_bad_start_step_is_refused(step):
    data = synthetic_palpation(duration_s=4.0)
    with pytest.raises(VicDrakeError, match="start_step_s"):
        residual_vs_palpation_time(data, start_step_s=step)


def test_bad_average_is_refused():
    data = synthetic_palpation(duration_s=4.0)
    with pytest.raises(VicDrakeError, match="average must be one of"):
        residual_vs_palpation_time(data, average="max")
