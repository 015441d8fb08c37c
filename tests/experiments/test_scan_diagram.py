"""The closed-loop scan diagram: wiring, logged groups, the controller's map."""

import numpy as np
import pytest

from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.rig_log import RIG_GROUPS
from vic_drake.experiments.scan_diagram import MakeScanDiagram
from vic_drake.experiments.scan_logs import LOG_GROUPS
from vic_drake.experiments.scan_run import run_scan


def test_scan_diagram_is_wired_and_logs_every_group():
    diagram, loggers = MakeScanDiagram(synthetic_scenario("vs-vf"))
    assert diagram.get_name() == "scan"
    assert set(loggers) == {name for name, *_ in LOG_GROUPS} | {
        name for name, _ in RIG_GROUPS
    }
    # Closed loop: no input port is left open.
    assert diagram.num_input_ports() == 0
    for name in (
        "station",
        "variable_impedance_controller",
        "fdcc",
        "target",
        "phantom_lift",
    ):
        diagram.GetSubsystemByName(name)


def test_command_feedback_reads_the_tip_from_the_joint_command():
    from dataclasses import replace

    scenario = replace(synthetic_scenario("vs-vf"), controller_feedback="command")
    diagram, _ = MakeScanDiagram(scenario)
    diagram.GetSubsystemByName("commanded_tip")
    df = run_scan(scenario, duration_s=0.05).df
    # At rest at the start the commanded tip is where the arm is.
    np.testing.assert_allclose(
        df[["x_m", "y_m", "z_m"]].iloc[0], [0.036, -0.36, 0.12], atol=1e-3
    )


def test_controller_reads_the_map_with_its_own_lookup():
    from dataclasses import replace

    from vic_drake.experiments.scan_diagram import _controller_phantom
    from vic_drake.scenario import PhantomConfig
    from vic_drake.tissue.phantom import GridPhantom

    xs, ys = np.array([0.0, 0.01]), np.array([0.0, 0.01])
    grid = np.array([[1000.0, 2000.0], [3000.0, 4000.0]])
    tissue = GridPhantom(x_m=xs, y_m=ys, z_m=np.zeros((2, 2)), kappa=grid, lam=grid)
    tissue.point_lookup()  # The tissue's (bilinear) fast lookup is cached first.
    scenario = replace(
        synthetic_scenario("vs-vf"), phantom=PhantomConfig(kind="measured")
    )
    ctrl = _controller_phantom(scenario, tissue)
    assert ctrl.point_lookup()(0.004, 0.001)[3] == pytest.approx(1000.0)  # Nearest.
    assert tissue.point_lookup()(0.004, 0.001)[3] == pytest.approx(1900.0)  # Bilinear.
