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


def _tick(system, context, t, z, v, f, s):
    context.SetTime(t)
    system.GetInputPort("probe.position").FixValue(context, [0.0, 0.0, z])
    system.GetInputPort("probe.velocity").FixValue(context, [0.0, 0.0, v])
    system.GetInputPort("ft_sensor.force_W").FixValue(context, [0.0, 0.0, -f])
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
    assert system.num_input_ports() == 3
    context = system.CreateDefaultContext()
    est = system.get_estimate_output_port().Eval(context)
    assert est[0] == p.kappa_prior and est[1] == p.lam_prior
    assert math.isnan(system.get_surface_output_port().Eval(context)[0])


def test_bad_arguments():
    with pytest.raises(VicDrakeError, match="OnlineEstimatorParams"):
        OnlineEstimatorSystem({"method": "rls"}, period_s=0.002)
    with pytest.raises(VicDrakeError, match="period_s"):
        OnlineEstimatorSystem(OnlineEstimatorParams(), period_s=0.0)
