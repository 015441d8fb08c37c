"""The closed-loop scan diagram: wiring, logged groups, the controller's map."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.paper_scenarios import synthetic_scenario
from vic_drake.experiments.rig_log import RIG_GROUPS
from vic_drake.experiments.scan_diagram import (
    MakeScanDiagram,
    initial_joint_positions,
    set_initial_state,
)
from vic_drake.experiments.scan_logs import LOG_GROUPS
from vic_drake.experiments.scan_run import run_scan


def test_scan_diagram_is_wired_and_logs_every_group():
    diagram, logs = MakeScanDiagram(synthetic_scenario("vs-vf"))
    assert diagram.get_name() == "scan"
    assert logs.names == tuple(g.name for g in LOG_GROUPS) + tuple(
        g.name for g in RIG_GROUPS
    )
    # One sink logs every group.
    sinks = [s for s in diagram.GetSystems() if type(s).__name__ == "VectorLogSink"]
    assert sinks == [logs.sink]
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


def test_each_group_reads_its_port_from_the_one_log():
    from dataclasses import replace

    from pydrake.systems.analysis import Simulator

    scenario = synthetic_scenario("vs-vf")
    scenario = replace(scenario, logging=replace(scenario.logging, period_s=0.01))
    diagram, logs = MakeScanDiagram(scenario)
    simulator = Simulator(diagram)
    root = simulator.get_mutable_context()
    set_initial_state(diagram, root, initial_joint_positions(scenario))
    simulator.Initialize()
    simulator.AdvanceTo(0.1)
    # The logging period sets the samples: 0, 0.01, ..., 0.1 s.
    np.testing.assert_allclose(logs.times(root), np.arange(11) * 0.01, atol=1e-12)
    mux = diagram.GetSubsystemByName("scan_log_inputs")
    mux_context = mux.GetMyContextFromRoot(root)
    for i, name in enumerate(logs.names):
        rows = logs.rows(name, root)
        assert rows.shape == (mux.get_input_port(i).size(), 11)
        # The last sample is the group's port now (the sink's last publish).
        np.testing.assert_array_equal(
            rows[:, -1], mux.get_input_port(i).Eval(mux_context)
        )
    with pytest.raises(VicDrakeError, match="no log group 'nope'"):
        logs.rows("nope", root)


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
        synthetic_scenario("vs-vf"),
        phantom=PhantomConfig(kind="measured", controller_lookup="nearest"),
    )
    ctrl = _controller_phantom(scenario, tissue)
    assert ctrl.point_lookup()(0.004, 0.001)[3] == pytest.approx(1000.0)  # Nearest.
    assert tissue.point_lookup()(0.004, 0.001)[3] == pytest.approx(1900.0)  # Bilinear.
    # The default: bilinear, as the real controller's logs show.
    assert PhantomConfig(kind="measured").controller_lookup == "bilinear"
