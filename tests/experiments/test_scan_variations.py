"""The variations in the scan diagram: what each changes, in a short closed loop."""

from pathlib import Path

import numpy as np
import pytest

from vic_drake.control.watchdog import DEAD_SENSOR
from vic_drake.experiments import MakeScanDiagram, run_scan
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.scan_logs import LATERAL_COLUMNS
from vic_drake.experiments.scan_variations import controller_map
from vic_drake.scenario import load_scenario
from vic_drake.station import station_plant
from vic_drake.tissue.motion import (
    breath_cycles,
    breathing_lateral_m,
    breathing_offset_m,
)
from vic_drake.tissue.phantom import SyntheticChestPhantom
from vic_drake.tissue.phantom.distorted import DistortedPhantom


def _short():
    s = synthetic_scenario("vs-vf")
    s.trajectory.approach_z_m = 0.11
    s.trajectory.approach_speed_m_per_s = 0.015
    return s


def test_no_variation_builds_the_same_diagram():
    names = {sys.get_name() for sys in MakeScanDiagram(_short())[0].GetSystems()}
    assert "faulty_sensor" not in names
    s = _short()
    s.variations.sensor_faults.noise_std_N = 0.5
    s.variations.motion.breathing.amplitude_m = 0.01
    diagram, _ = MakeScanDiagram(s)
    systems = {sys.get_name(): sys for sys in diagram.GetSystems()}
    assert "faulty_sensor" in systems
    assert type(systems["phantom_lift"]).__name__ == "PatientMotionSource"
    s.variations.map_errors.kappa_scale = 1.3
    chest = SyntheticChestPhantom()
    assert controller_map(_short(), chest) is chest
    assert isinstance(controller_map(s, chest), DistortedPhantom)


def test_lateral_joints_and_logs_only_with_lateral_breathing():
    def built(s):
        diagram, logs = MakeScanDiagram(s)
        plant = station_plant(diagram.GetSubsystemByName("station"))
        return plant.num_positions(), "phantom_lateral" in logs

    s = _short()
    s.variations.motion.breathing.amplitude_m = 0.01
    assert built(s) == (7, False)  # Vertical breathing: the same plant.
    s.variations.motion.breathing.lateral_amplitude_m = [0.0, 0.002]
    assert built(s) == (9, True)


def test_lateral_breathing_moves_the_phantom_as_commanded():
    s = _short()
    b = s.variations.motion.breathing
    b.amplitude_m, b.frequency_hz, b.irregularity, b.seed = 0.01, 0.33, 0.2, 3
    b.lateral_amplitude_m = [0.004, -0.003]
    df = run_scan(s, duration_s=1.5).df
    assert tuple(df.columns[-2:]) == LATERAL_COLUMNS
    cycles = breath_cycles(
        frequency_hz=0.33,
        amplitude_m=0.01,
        irregularity=0.2,
        duration_s=s.total_duration_s,
        seed=3,
    )
    t = df["t_s"].to_numpy()
    commanded = np.array([breathing_lateral_m(x, cycles, [0.004, -0.003]) for x in t])
    assert np.max(np.abs(commanded[:, 0])) > 0.003  # The run sees a breath.
    # The servo follows one command period late (up to 4 mm/s here): the
    # joints track the commanded offset within 10 um (measured 7.5 um over 4 s).
    np.testing.assert_allclose(df["phantom_x_m"], commanded[:, 0], atol=1e-5)
    np.testing.assert_allclose(df["phantom_y_m"], commanded[:, 1], atol=1e-5)
    z = np.array([breathing_offset_m(x, cycles) for x in t])
    np.testing.assert_allclose(df["phantom_lift_m"], z, atol=5e-5)


def test_example_lateral_breathing_scenario_moves_the_phantom_sideways():
    example = (
        Path(__file__).resolve().parents[2]
        / "campaigns/base/breathing_lateral_synthetic.yaml"
    )
    s = load_scenario(example)
    assert s.variations.motion.breathing.lateral_amplitude_m == [0.003, -0.0015]
    df = run_scan(s, duration_s=1.0).df
    # At 0.25 Hz the breath is at 1 - cos(pi/2) = half way up at 1 s.
    row = df.iloc[-1]
    assert row["phantom_x_m"] == pytest.approx(0.0015, abs=2e-5)
    assert row["phantom_y_m"] == pytest.approx(-0.00075, abs=2e-5)
    assert row["phantom_lift_m"] == pytest.approx(0.005, abs=5e-5)


def test_breathing_moves_the_phantom_and_a_stuck_sensor_shows_in_the_force():
    s = _short()
    s.variations.motion.breathing.amplitude_m = 0.01
    s.variations.motion.breathing.frequency_hz = 0.33
    df = run_scan(s, duration_s=1.5).df
    t = df["t_s"].to_numpy()
    expected = 0.01 * 0.5 * (1 - np.cos(2 * np.pi * 0.33 * t))
    np.testing.assert_allclose(df["phantom_lift_m"], expected, atol=5e-4)
    # CF with its z reading stuck at ~0 from the start sees no force and,
    # without the sensor watchdog, pushes on: the true force on the patient
    # (the metric) rises well above the fault-free run's; the run does not
    # raise. With the watchdog (the default) the stuck channel stops the
    # scan before the probe reaches the chest.
    stuck = synthetic_scenario("cf")
    stuck.trajectory = _short().trajectory
    ok = synthetic_scenario("cf")
    ok.trajectory = _short().trajectory
    stuck.variations.sensor_faults.stuck_channel = 2
    watched = run_scan(stuck, duration_s=1.5)
    stuck.watchdog.enabled = False
    unwatched = run_scan(stuck, duration_s=1.5)
    f_ok = run_scan(ok, duration_s=1.5).df["force_tissue_z_N"].max()
    assert unwatched.df["force_tissue_z_N"].max() > 1.5 * f_ok
    assert np.isnan(unwatched.watchdog_trip_s) and unwatched.watchdog_channel == -1
    assert watched.watchdog_channel == 2
    assert 0.05 <= watched.watchdog_trip_s <= 0.1
    assert watched.df["force_tissue_z_N"].max() < 0.1
    z = watched.df["z_m"].to_numpy()
    assert z[-1] > z[0] + 0.02  # Lifted away.


@pytest.mark.parametrize("mode", ["hold", "nan"])
def test_a_sensor_that_dies_in_contact_stops_the_scan(mode):
    # CF pressing at its target when the sensor dies (its last reading held,
    # or NaN) and the chest breathes. Without the watchdog the held reading
    # hides the chest pushing into the probe (the force climbs), and NaN
    # freezes the arm where it is (every FDCC tick faults). With it (the
    # default) the probe lifts away 0.1 s after the last reading.
    s = synthetic_scenario("cf")
    s.trajectory = _short().trajectory
    s.variations.motion.breathing.amplitude_m = 0.01
    s.variations.motion.breathing.frequency_hz = 0.33
    f = s.variations.sensor_faults
    f.dead, f.dead_start_s, f.dropout_mode = True, 1.0, mode
    watched = run_scan(s, duration_s=4.0)
    assert watched.watchdog_channel == DEAD_SENSOR
    assert watched.watchdog_trip_s == pytest.approx(1.1, abs=0.005)
    t = watched.df["t_s"].to_numpy()
    z = watched.df["z_m"].to_numpy()
    assert z[-1] > z[t <= 1.0][-1] + 0.02  # Lifted away.
    assert watched.df["force_tissue_z_N"].to_numpy()[-1] == 0.0
    s.watchdog.enabled = False
    unwatched = run_scan(s, duration_s=4.0)
    assert unwatched.watchdog_channel == -1
    force = unwatched.df["force_tissue_z_N"].to_numpy()
    z = unwatched.df["z_m"].to_numpy()
    if mode == "hold":
        assert force[t > 1.0].max() > 2.0 * force[t <= 1.0][-1]
    else:
        assert abs(z[-1] - z[t <= 1.0][-1]) < 1e-4  # The arm froze in place.
        assert force[-1] > 1.0


def test_under_breathing_the_maps_eps_dot_misses_the_chests_velocity():
    """The map is static, so under breathing the controller's penetration
    rate (eq. 10 on the map: its surface velocity minus the tip's) is the
    true rate minus the chest's velocity, as on the paper's rig. With 1 cm
    at 0.33 Hz the probe rides the chest (true rate ~1 mm/s RMS), the
    controller reads ~7.5 mm/s against the chest's motion, and the damping
    term lambda eps_dot is ~11 % of kappa at its p95 (measured)."""
    s = _short()
    b = s.variations.motion.breathing
    b.amplitude_m, b.frequency_hz, b.irregularity = 0.01, 0.33, 0.0
    result = run_scan(s, duration_s=7.0)
    df, rig = result.df, result.rig
    t = df["t_s"].to_numpy()
    held = (t > 3.0) & (df["in_contact"].to_numpy() > 0.5)  # After the approach.
    assert held.sum() > 1000
    controller = (
        rig["surface_velocity_m_per_s"] - rig["controller_vz_m_per_s"]
    ).to_numpy()
    chest = np.gradient(df["phantom_lift_m"].to_numpy(), t)
    true = np.gradient(df["penetration_m"].to_numpy(), t)
    c, v, e = controller[held], chest[held], true[held]
    # The kinematic identity: the controller's rate lacks the chest's velocity.
    assert np.max(np.abs(c - (e - v))) < 5e-4
    assert np.corrcoef(c, -v)[0, 1] > 0.95
    rms = lambda x: float(np.sqrt(np.mean(x**2)))  # noqa: E731
    assert rms(e) < 0.3 * rms(c)  # The probe follows: the true rate is small.
    # How much of the reference that is: lambda |eps_dot| / kappa.
    share = (rig["lambda_N_s_per_m_beta1"] / rig["kappa_N_per_m_beta"]).to_numpy()
    share = share[held] * np.abs(c)
    assert 0.05 < np.percentile(share, 95) < 0.2
