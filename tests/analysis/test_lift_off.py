"""The surface at the final lift-off: viscous and relaxation corrections, the fit's consistency."""

import numpy as np
import pytest

from tests.analysis.scans import make_scan
from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.lift_off import lift_off_offset, tip_velocity
from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag
from vic_drake.tissue.phantom import GridPhantom, load_phantom
from vic_drake.tissue.relaxation import (
    DEFAULT_RELAXATION,
    relaxation_history,
    relaxation_input,
    relaxing_hunt_crossley_force,
)

KAPPA, LAM, BETA, MAP_Z = 3300.0, 32000.0, 1.35, 0.1
DT = 0.002


def _flat_map() -> GridPhantom:
    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.45, -0.28, 18)
    full = np.ones((31, 18))
    return GridPhantom(
        x_m=xs, y_m=ys, z_m=MAP_Z * full, kappa=KAPPA * full, lam=LAM * full, beta=BETA
    )


def _lift(offset_m, *, peak_mm_s=50.0, relax=True, bias_N=-0.15, noise_N=0.03, seed=1):
    """A tip pressed 8 mm into tissue whose surface is the map's plus
    ``offset_m`` for 15 s, then lifted as the real logs lift: the speed
    rises to ``peak_mm_s`` in 30 ms and falls to 60 % of it over 0.2 s
    (relaxing Hunt-Crossley with its viscous term, clipped at zero; sensor
    bias and noise); 1 s of free space follows."""
    surface = MAP_Z + offset_m
    t = np.arange(0.0, 17.0, DT)
    t_up = 15.0
    s = np.clip((t - t_up) / 0.03, 0.0, 1.0)
    decay = 1.0 - 0.4 * np.clip((t - t_up - 0.03) / 0.2, 0.0, 1.0)
    v = 1e-3 * peak_mm_s * s * decay
    z = surface - 0.008 + np.concatenate([[0.0], np.cumsum(v[:-1]) * DT])
    eps = surface - z
    eps_dot = -v
    u = relaxation_input(eps, BETA)
    if relax:
        g, taus = DEFAULT_RELAXATION.fractions, DEFAULT_RELAXATION.time_constants_s
        states = relaxation_history(t, u, taus)
    else:
        g, states = (), np.zeros((t.size, 0))
    f = relaxing_hunt_crossley_force(
        eps, eps_dot, KAPPA, LAM, BETA, states, g, clip_tension=True
    )
    f = f + bias_N + np.random.default_rng(seed).normal(0.0, noise_N, t.size)
    return make_scan(t, f, x_m=-0.147, y_m=-0.36, z_m=z)


@pytest.mark.parametrize("offset_mm", [-1.5, 0.0, 3.0])
@pytest.mark.parametrize("peak_mm_s", [35.0, 55.0])
def test_lift_off_recovers_a_known_surface(offset_mm, peak_mm_s):
    phantom = _flat_map()
    found = lift_off_offset(_lift(offset_mm * 1e-3, peak_mm_s=peak_mm_s), phantom)
    assert found is not None
    # 0.04 mm up to 45 mm/s; at 55 mm/s the fit starts on the speed ramp: 0.11.
    assert 1e3 * found.offset_m == pytest.approx(offset_mm, abs=0.15)
    assert found.kappa_scale == pytest.approx(1.0, abs=0.1)
    assert found.bias_N == pytest.approx(-0.15, abs=0.01)
    assert 0 < found.sigma_m < 1e-4 and found.samples >= 10
    assert 1e3 * found.speed_m_per_s == pytest.approx(0.8 * peak_mm_s, rel=0.25)


def test_lift_off_corrections_are_needed():
    """Without the viscous (or the relaxation) correction the same lift reads
    the surface low and the fit's modulus is off the map's."""
    phantom = _flat_map()
    lift = _lift(0.003)
    plain = lift_off_offset(lift, phantom, viscous=False)
    assert abs(1e3 * plain.offset_m - 3.0) > 0.3
    assert abs(plain.kappa_scale - 1.0) > 0.3
    unrelaxed = lift_off_offset(lift, phantom, relaxation=None)
    assert 1e3 * unrelaxed.offset_m < 3.0 - 0.3
    # On plain Hunt-Crossley tissue the relaxation is left out.
    hc = lift_off_offset(_lift(0.003, relax=False), phantom, relaxation=None)
    assert 1e3 * hc.offset_m == pytest.approx(3.0, abs=0.1)
    # The history of the penetration given instead of iterated: the same.
    given = lift_off_offset(lift, phantom, history_offset_m=0.003)
    assert given.offset_m == pytest.approx(
        lift_off_offset(lift, phantom).offset_m, abs=2e-5
    )


def test_lift_off_needs_free_space_after_the_last_contact():
    phantom = _flat_map()
    lift = _lift(0.0)
    # Still pressing at the end (the 9-column logs).
    assert lift_off_offset(lift[lift["t_s"] < 14.0], phantom) is None
    # Lifts, but the record ends 0.1 s later.
    assert lift_off_offset(lift[lift["t_s"] < 15.35], phantom) is None
    with pytest.raises(VicDrakeError, match="high_N"):
        lift_off_offset(lift, phantom, high_N=0.1)
    with pytest.raises(VicDrakeError, match="history_offset_m"):
        lift_off_offset(lift, phantom, history_offset_m=np.nan)


def test_tip_velocity_is_the_local_slope():
    t = np.arange(0.0, 1.0, DT)
    z = 0.05 * t + 1e-5 * np.round(np.sin(40 * t))  # 0.01 mm steps
    v = tip_velocity(t, z, np.arange(20, 480))
    assert np.all(np.abs(v - 0.05) < 3e-3)


VS_LOGS = ("test_tracking5", "test_nardi_matForce_lowR")


@pytest.mark.realdata
def test_real_lift_offs_do_not_follow_the_maps_viscosity(data_dir):
    """The real lifts read with the map's lambda give a line twice as steep
    as the map's kappa; read as elastic only they give the map's kappa. The
    first contacts of the same logs give the map's kappa (0.93, 1.03)."""
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    for name in VS_LOGS:
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        found = lift_off_offset(real, phantom)
        assert found is not None and found.sigma_m < 1e-4
        assert found.kappa_scale > 1.8
        elastic = lift_off_offset(real, phantom, viscous=False, relaxation=None)
        assert elastic.kappa_scale == pytest.approx(0.94, abs=0.08)
        assert 0.030 < found.speed_m_per_s < 0.050
    for name in ("test_compliance_control400", "test_force_control"):
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        assert lift_off_offset(real, phantom) is None  # the logs end pressing
