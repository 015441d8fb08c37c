"""The indenter-bank diagram and the palpation campaign."""

import numpy as np
import pytest
from scipy.optimize import brentq

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.campaign import (
    CampaignParams,
    fit_point,
    grid_points,
    run_campaign,
    simulate_palpations,
)
from vic_drake.systems.indenter import (
    HuntCrossleyIndentation,
    IndenterParams,
    LaggedForceSensor,
    MakeIndenterDiagram,
    PalpationParams,
    SensorParams,
    palpation_target,
)
from vic_drake.tissue import SyntheticChestPhantom, hunt_crossley_force

BETA = 1.35


def test_hunt_crossley_system_calls_the_force_law():
    system = HuntCrossleyIndentation(3, BETA)
    context = system.CreateDefaultContext()
    s = np.array([0.10, 0.10, 0.10])
    kappa, lam = np.array([2000.0, 5000.0, 9000.0]), np.array([2e4, 6e4, 2e5])
    system.set_tissue(context, surface_z=s, kappa=kappa, lam=lam)
    q = np.array([0.095, 0.101, 0.09])  # in contact, out of contact, pulling away fast
    v = np.array([-0.01, 0.0, 0.5])
    system.get_indenter_state_input_port().FixValue(context, np.concatenate([q, v]))
    force = system.get_generalized_force_output_port().Eval(context)
    expected = hunt_crossley_force(s - q, -v, kappa, lam, BETA, clip_tension=True)
    np.testing.assert_allclose(force, expected, rtol=1e-12)
    assert force[1] == 0.0 and force[2] == 0.0  # no contact; no tension
    assert force[0] > 0.0


def test_lagged_sensor_delays_by_lag_samples():
    params = SensorParams(lag_samples=3, noise_std_N=0.0)
    sensor = LaggedForceSensor(2, params, indenter_mass_kg=0.1)
    context = sensor.CreateDefaultContext()
    sensor.GetInputPort("tissue_force").FixValue(context, [5.0, 1.0])
    sensor.GetInputPort("acceleration").FixValue(context, [2.0, 0.0])
    sensor.GetInputPort("noise").FixValue(context, [0.0, 0.0])
    outputs = []
    for _ in range(5):
        outputs.append(sensor.get_measured_force_output_port().Eval(context).copy())
        update = sensor.EvalUniquePeriodicDiscreteUpdate(context)
        context.SetDiscreteState(update.get_vector().get_value())
    # Reading F - m_I a = 5 - 0.2 = 4.8 appears after lag + 1 updates.
    np.testing.assert_allclose(outputs[3], [0.0, 0.0])
    np.testing.assert_allclose(outputs[4], [4.8, 1.0])


def test_palpation_target_switches_to_the_sinusoid():
    p = PalpationParams(velocity_feedforward=True)
    mode = np.array([0.0, 1.0])
    z_d, v_d = palpation_target(
        1.0, mode, np.array([0.2, 0.2]), np.array([0.1, 0.1]), np.array([0.0, 0.9]), p
    )
    assert z_d[0] == pytest.approx(0.2 - p.approach_speed_m_per_s)
    w = 2 * np.pi * p.frequency_hz
    assert z_d[1] == pytest.approx(0.1 - p.depth_m - p.amplitude_m * np.sin(w * 0.1))
    assert v_d[1] == pytest.approx(-p.amplitude_m * w * np.cos(w * 0.1))
    z_d, v_d = palpation_target(
        1.0,
        mode,
        np.array([0.2, 0.2]),
        np.array([0.1, 0.1]),
        np.array([0.0, 0.9]),
        PalpationParams(),
    )
    np.testing.assert_array_equal(v_d, 0.0)  # no feed-forward by default


def test_indenter_diagram_static_equilibrium_matches_hunt_crossley():
    """Constant target: the tip settles where servo and HC forces balance."""
    from pydrake.systems.analysis import Simulator

    indenter = IndenterParams()
    palpation = PalpationParams(amplitude_m=0.0, duration_s=2.5)
    sensor = SensorParams(noise_std_N=0.0)
    n = 2
    s = np.array([0.10, 0.12])
    kappa, lam = np.array([2500.0, 9000.0]), np.array([2e4, 2e5])
    bank = MakeIndenterDiagram(
        n, beta=BETA, indenter=indenter, sensor=sensor, palpation=palpation
    )
    context = bank.diagram.CreateDefaultContext()
    bank.set_points(
        context, surface_z=s, kappa=kappa, lam=lam, start_z=s + 0.002, seed=1
    )
    Simulator(bank.diagram, context).AdvanceTo(4.0)
    q = bank.plant.GetPositions(bank.plant.GetMyContextFromRoot(context))
    contact = (
        bank.target.get_contact_output_port()
        .Eval(bank.target.GetMyContextFromRoot(context))
        .reshape(3, n)
    )
    assert np.all(contact[0] == 1.0)
    z_d = contact[1] - palpation.depth_m
    measured = bank.sensor.get_measured_force_output_port().Eval(
        bank.sensor.GetMyContextFromRoot(context)
    )
    k_p = indenter.servo_stiffness_N_per_m
    for i in range(n):
        # Independent oracle: kappa eps^beta = K_p (s - eps - z_d).
        eps = brentq(
            lambda e, i=i: kappa[i] * e**BETA - k_p * (s[i] - e - z_d[i]), 0.0, 0.05
        )
        assert s[i] - q[i] == pytest.approx(eps, abs=2e-6)
        assert measured[i] == pytest.approx(kappa[i] * eps**BETA, rel=1e-3)


def test_grid_points_of_the_measured_region():
    x, y = grid_points((-0.1587, 0.0423, -0.4145, -0.3125), 0.01)
    assert x.size == 21 * 11
    assert x.min() == pytest.approx(-0.1587) and x.max() == pytest.approx(0.0413)


def test_campaign_params_reject_bad_values():
    with pytest.raises(VicDrakeError, match="spacing_m"):
        CampaignParams(spacing_m=0.0)
    with pytest.raises(VicDrakeError, match="region_m"):
        CampaignParams(region_m=(0.1, 0.0, 0.0, 0.1))
    with pytest.raises(VicDrakeError, match="amplitude_m"):
        PalpationParams(amplitude_m=0.02)
    with pytest.raises(VicDrakeError, match="lag_samples"):
        SensorParams(lag_samples=-1)
    with pytest.raises(VicDrakeError, match="common"):
        simulate_palpations(
            [0.0, 0.01],
            [0.0],
            surface_z=[0.1],
            kappa=[1.0],
            lam=[1.0],
            beta=BETA,
            params=CampaignParams(),
        )
    with pytest.raises(VicDrakeError, match="finite"):
        simulate_palpations(
            [0.0],
            [0.0],
            surface_z=[np.nan],
            kappa=[1.0],
            lam=[1.0],
            beta=BETA,
            params=CampaignParams(),
        )


@pytest.mark.parametrize("x", [-0.09, -0.115])  # soft tissue; on a rib
def test_simulated_palpation_fit_recovers_kappa_lambda_and_surface(x):
    phantom = SyntheticChestPhantom()
    params = CampaignParams()
    xs, ys = np.array([x]), np.array([-0.36])
    truth = phantom.sample(xs, ys)
    (record,) = simulate_palpations(
        xs,
        ys,
        surface_z=truth.surface_z_m,
        kappa=truth.kappa,
        lam=truth.lam,
        beta=BETA,
        params=params,
        seed=3,
    )
    lag = params.sensor.lag_samples * params.sensor.period_s
    fit = fit_point(record, beta=BETA, lag_s=lag, params=params)
    assert fit.ok, fit.message
    assert fit.kappa == pytest.approx(truth.kappa[0], rel=0.04)
    assert fit.lam == pytest.approx(truth.lam[0], rel=0.08)
    assert fit.surface_z_m == pytest.approx(truth.surface_z_m[0], abs=3e-4)
    assert fit.noise_N == pytest.approx(params.sensor.noise_std_N, rel=0.4)
    assert record.t_s[-1] - record.t_contact_s == pytest.approx(5.0, abs=0.01)


def test_run_campaign_on_a_small_region():
    phantom = SyntheticChestPhantom()
    region = (-0.08, -0.06, -0.37, -0.36)
    result = run_campaign(phantom, CampaignParams(region_m=region, seed=2))
    points = result.points
    assert len(points) == 6 and points["ok"].all()
    err = points["kappa_N_per_m_beta"] / points["kappa_true_N_per_m_beta"] - 1
    assert np.sqrt(np.mean(err**2)) < 0.04
    assert result.lag_s == pytest.approx(0.056)
    assert result.region_m == region
