"""OnlineEstimatorSystem: one tick through the ports equals the pure step;
ticks over simulated HC data recover the parameters; NaN inputs hold."""

import math

import numpy as np
import pytest

from tests.estimation.online.hc_data import hc_palpation
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import (
    OUTPUT_FIELDS,
    OnlineEstimatorParams,
    rls_initial_state,
    rls_step,
)
from vic_drake.systems.online_estimator import (
    EkfEstimatorSystem,
    OnlineEstimatorSystem,
    RlsEstimatorSystem,
)
from vic_drake.systems.signals import (
    MEASURED_FORCE,
    MEASURED_POSITION,
    MEASURED_VELOCITY,
    MEASUREMENT_SIZE,
)


def _measurement(z, v, f, xy=(0.0, 0.0)):
    m = np.zeros(MEASUREMENT_SIZE)
    m[MEASURED_POSITION] = [*xy, z]
    m[MEASURED_VELOCITY] = [0.0, 0.0, v]
    m[MEASURED_FORCE] = [0.0, 0.0, -f]
    return m


def _tick(system, context, t, z, v, f, s):
    context.SetTime(t)
    system.get_measurement_input_port().FixValue(context, _measurement(z, v, f))
    system.GetInputPort("surface_z").FixValue(context, [s])
    state = system.EvalUniquePeriodicDiscreteUpdate(context)
    context.SetDiscreteState(state)


def test_one_tick_equals_the_pure_step():
    p = OnlineEstimatorParams()
    system = RlsEstimatorSystem(p, period_s=0.002)
    context = system.CreateDefaultContext()
    _tick(system, context, 0.0, 0.095, -0.01, 5.0, 0.1)
    _, est = rls_step(rls_initial_state(p), 0.0, 0.095, -0.01, 5.0, 0.1, p)
    np.testing.assert_allclose(system.get_estimate_output_port().Eval(context), est)
    assert system.get_kappa_output_port().Eval(context)[0] == est.kappa_hat
    assert system.get_valid_output_port().Eval(context)[0] == est.valid
    assert len(OUTPUT_FIELDS) == system.get_estimate_output_port().size()


@pytest.mark.parametrize("kind", [RlsEstimatorSystem, EkfEstimatorSystem])
def test_recovers_parameters_and_survives_nan(kind):
    kappa, lam = 6000.0, 50000.0
    t, z, v, f, s = hc_palpation(kappa, lam, seed=2, duration_s=4.0)
    f = f.copy()
    f[::97] = np.nan
    system = kind(OnlineEstimatorParams(), period_s=0.002)
    context = system.CreateDefaultContext()
    for k in range(t.size):
        _tick(system, context, t[k], z[k], v[k], f[k], s)
        if k % 97 == 0:
            assert system.get_valid_output_port().Eval(context)[0] == 0.0
    est = system.get_estimate_output_port().Eval(context)
    assert np.all(np.isfinite(est[:5]))
    assert system.get_kappa_output_port().Eval(context)[0] == pytest.approx(
        kappa, rel=0.02
    )
    assert system.get_lambda_output_port().Eval(context)[0] == pytest.approx(
        lam, rel=0.1
    )


def test_without_surface_input_the_prior_is_published_before_contact():
    p = OnlineEstimatorParams(method="ekf")
    system = OnlineEstimatorSystem(p, period_s=0.002, surface_input=False)
    assert system.num_input_ports() == 1
    assert system.get_measurement_input_port().size() == MEASUREMENT_SIZE
    context = system.CreateDefaultContext()
    est = system.get_estimate_output_port().Eval(context)
    assert est[0] == p.kappa_prior and est[1] == p.lam_prior
    assert math.isnan(system.get_surface_output_port().Eval(context)[0])


def test_bad_arguments():
    with pytest.raises(VicDrakeError, match="OnlineEstimatorParams"):
        OnlineEstimatorSystem({"method": "rls"}, period_s=0.002)
    with pytest.raises(VicDrakeError, match="period_s"):
        OnlineEstimatorSystem(OnlineEstimatorParams(), period_s=0.0)


def test_map_surface_is_read_at_the_measured_x_y():
    """With a surface map, the tick's surface is the map's under the probe's
    (x, y) from the measurement vector, not under any other point."""
    from vic_drake.tissue.phantom import GridPhantom

    xs, ys = np.array([0.0, 0.01]), np.array([0.0, 0.02])
    heights = np.array([[0.10, 0.11], [0.12, 0.14]])  # Rows: x; columns: y.
    grid = np.full((2, 2), 5000.0)
    tissue = GridPhantom(x_m=xs, y_m=ys, z_m=heights, kappa=grid, lam=grid)
    system = RlsEstimatorSystem(
        OnlineEstimatorParams(), period_s=0.002, surface_input=False, surface_map=tissue
    )
    context = system.CreateDefaultContext()
    x, y = 0.004, 0.015
    system.get_measurement_input_port().FixValue(
        context, _measurement(0.105, -0.01, 5.0, xy=(x, y))
    )
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    got = system.get_surface_output_port().Eval(context)[0]
    lookup = tissue.point_lookup()
    assert got == lookup(x, y)[0]
    assert got not in (lookup(y, x)[0], lookup(0.0, 0.0)[0], lookup(x, 0.0)[0])


def test_the_dither_frequency_reaches_the_slope_fit():
    """Ticks through the ports with ``dither_hz`` equal the pure step told the
    same frequency (the fit's instrument), and differ from it untold."""
    from vic_drake.estimation.online.ekf import (
        ekf_slope_initial_state,
        ekf_slope_step,
    )

    p = OnlineEstimatorParams(
        method="ekf", surface_from_slope=True, surface_walk_m_per_sqrt_s=0.0
    )
    system = OnlineEstimatorSystem(p, period_s=0.002, dither_hz=3.0)
    context = system.CreateDefaultContext()
    told = untold = ekf_slope_initial_state(p)
    rng = np.random.default_rng(0)
    for k in range(600):
        t = 0.002 * k
        eps = 0.006 + 3e-4 * math.sin(2 * math.pi * 3.0 * t)
        v = -3e-4 * 2 * math.pi * 3.0 * math.cos(2 * math.pi * 3.0 * t)
        z, f = 0.1 - eps, 6000.0 * eps**1.35 + rng.normal(0.0, 0.05)
        _tick(system, context, t, z, v, f, math.nan)
        told, est = ekf_slope_step(told, t, z, v, f, math.nan, p, dither_hz=3.0)
        untold, est_untold = ekf_slope_step(untold, t, z, v, f, math.nan, p)
    out = system.get_estimate_output_port().Eval(context)
    np.testing.assert_array_equal(out, np.asarray(est, float))
    assert not np.array_equal(out, np.asarray(est_untold, float))


@pytest.mark.parametrize("bad", [0.0, -3.0, math.nan, math.inf])
def test_dither_frequency_must_be_positive_and_needs_the_slope_fit(bad):
    with pytest.raises(VicDrakeError, match="dither_hz is for"):
        OnlineEstimatorSystem(
            OnlineEstimatorParams(method="ekf"), period_s=0.002, dither_hz=3.0
        )
    with pytest.raises(VicDrakeError, match=r"dither_hz must be > 0; got"):
        OnlineEstimatorSystem(
            OnlineEstimatorParams(method="ekf", surface_from_slope=True),
            period_s=0.002,
            dither_hz=bad,
        )
