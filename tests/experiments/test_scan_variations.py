"""The variations in the scan diagram: what each changes, in a short closed loop."""

import numpy as np

from vic_drake.experiments import MakeScanDiagram, run_scan
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.scan_variations import controller_map
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


def test_breathing_moves_the_phantom_and_a_stuck_sensor_shows_in_the_force():
    s = _short()
    s.variations.motion.breathing.amplitude_m = 0.01
    s.variations.motion.breathing.frequency_hz = 0.33
    df = run_scan(s, duration_s=1.5).df
    t = df["t_s"].to_numpy()
    expected = 0.01 * 0.5 * (1 - np.cos(2 * np.pi * 0.33 * t))
    np.testing.assert_allclose(df["phantom_lift_m"], expected, atol=5e-4)
    # CF with its z reading stuck at ~0 from the start sees no force and
    # pushes on: the true force on the patient (the metric) rises well
    # above the fault-free run's; the run does not raise.
    stuck = synthetic_scenario("cf")
    stuck.trajectory = _short().trajectory
    ok = synthetic_scenario("cf")
    ok.trajectory = _short().trajectory
    stuck.variations.sensor_faults.stuck_channel = 2
    f_stuck = run_scan(stuck, duration_s=1.5).df["force_tissue_z_N"].max()
    f_ok = run_scan(ok, duration_s=1.5).df["force_tissue_z_N"].max()
    assert f_stuck > 1.5 * f_ok
