"""The palpation campaign: grid, parameters, simulated palpations and their fits."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign_params import CampaignParams
from vic_drake.experiments.palpation_campaign import grid_points, run_campaign
from vic_drake.experiments.palpation_fit import fit_point
from vic_drake.experiments.palpation_sim import simulate_palpations
from vic_drake.systems.indenter import PalpationParams, SensorParams
from vic_drake.tissue import SyntheticChestPhantom

BETA = 1.35


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
        _palpate(x=[0.0, 0.01])
    with pytest.raises(VicDrakeError, match="finite"):
        _palpate(surface_z=[np.nan])
    for ids in ([1, 2], [-1], [0.5]):
        with pytest.raises(
            VicDrakeError, match=r"ids must be one integer >= 0 per point \(1 points\)"
        ):
            _palpate(ids=ids)


def _palpate(**overrides):
    """simulate_palpations of one point, with arguments replaced."""
    args = dict(x=[0.0], y=[0.0], surface_z=[0.1], kappa=[1.0], lam=[1.0])
    args.update(beta=BETA, params=CampaignParams())
    args.update(overrides)
    x, y = args.pop("x"), args.pop("y")
    return simulate_palpations(x, y, **args)


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


def test_a_campaign_on_a_local_cluster_equals_the_one_in_this_process():
    """Two batches either way (batch_size 3 of 6 points): the same jobs, so
    the same fits to the bit, whether on Dask or here."""
    phantom = SyntheticChestPhantom()
    region = (-0.08, -0.06, -0.37, -0.36)
    here = run_campaign(phantom, CampaignParams(region_m=region, seed=2, batch_size=3))
    lines = []
    there = run_campaign(
        phantom,
        CampaignParams(region_m=region, seed=2, batch_size=3, workers=2),
        progress=lines.append,
    )
    assert there.points.equals(here.points)
    assert there.lag_s == here.lag_s
    assert "palpating 6 points on 2 local Dask worker(s)" in lines
    assert sorted(line for line in lines if line.startswith("batch")) == [
        "batch 1 of 2 done (3 points)",
        "batch 2 of 2 done (3 points)",
    ]


def test_a_points_fit_does_not_depend_on_how_the_points_are_batched():
    """Each point's sensor noise is its own (seed, grid index): one batch of
    6 and three batches of 2 give the same fits (to rounding: the batch's
    vector arithmetic may differ in the last bit)."""
    phantom = SyntheticChestPhantom()
    region = (-0.08, -0.06, -0.37, -0.36)
    one = run_campaign(phantom, CampaignParams(region_m=region, seed=2, batch_size=6))
    three = run_campaign(phantom, CampaignParams(region_m=region, seed=2, batch_size=2))
    assert one.lag_s == three.lag_s
    numeric = one.points.select_dtypes("number").columns
    np.testing.assert_allclose(
        three.points[numeric].to_numpy(float),
        one.points[numeric].to_numpy(float),
        rtol=1e-9,
        atol=1e-12,
    )
    other_seed = run_campaign(
        phantom, CampaignParams(region_m=region, seed=3, batch_size=6)
    )
    assert not np.allclose(
        other_seed.points["kappa_N_per_m_beta"], one.points["kappa_N_per_m_beta"]
    )


def test_an_unreachable_scheduler_is_named():
    phantom = SyntheticChestPhantom()
    params = CampaignParams(region_m=(-0.08, -0.06, -0.37, -0.36))
    with pytest.raises(VicDrakeError, match="cannot reach the Dask scheduler"):
        run_campaign(phantom, params, scheduler="tcp://127.0.0.1:9")
