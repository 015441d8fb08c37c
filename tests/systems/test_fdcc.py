"""FdccController: ports, one tick equals fdcc_step, NaN fault, closed loop with the station."""

import numpy as np
import pytest
from pydrake.systems.analysis import Simulator
from pydrake.systems.framework import DiagramBuilder
from pydrake.systems.primitives import ConstantVectorSource, Demultiplexer

from vic_drake.control.fdcc import FdccParams, fdcc_step
from vic_drake.station import MakeStation, StationParams, initial_q_for_tip
from vic_drake.systems.fdcc import AddFdccInputs, FdccController
from vic_drake.systems.signals import (
    FDCC_IN_FORCE,
    FDCC_IN_JOINT_POSITIONS,
    FDCC_IN_STIFFNESS,
    FDCC_IN_TARGET_FORCE,
    FDCC_IN_TARGET_POSITION,
    FDCC_INPUT_PARTS,
    FDCC_INPUTS_SIZE,
)
from vic_drake.tissue import SyntheticChestPhantom

#: Above a nearly level point of the synthetic chest (surface slope < 0.04).
START = np.array([-0.045, -0.40, 0.13])


@pytest.fixture(scope="module")
def q_start():
    return initial_q_for_tip(START)


def _fix_inputs(
    system, context, q, *, stiffness=(300.0, 300.0, 300.0), force=(0.0, 0.0, -1.0)
):
    u = np.zeros(FDCC_INPUTS_SIZE)
    u[FDCC_IN_JOINT_POSITIONS] = q
    u[FDCC_IN_TARGET_POSITION] = START + [0, 0, 0.01]
    u[FDCC_IN_STIFFNESS] = stiffness
    u[FDCC_IN_FORCE] = force
    u[FDCC_IN_TARGET_FORCE] = [0.0, 0.0, -2.0]
    system.get_inputs_input_port().FixValue(context, u)


def test_input_parts_tile_the_inputs_vector():
    parts = [part for _, part in FDCC_INPUT_PARTS]
    assert [p.start for p in parts] == [0, *(p.stop for p in parts[:-1])]
    assert [p.stop - p.start for p in parts] == [6, 3, 3, 3, 3]
    assert parts[-1].stop == FDCC_INPUTS_SIZE == 18


def test_ports_and_one_tick_equals_the_pure_step(q_start):
    system = FdccController(
        FdccParams(), station_params=StationParams(), initial_q=q_start
    )
    assert system.num_input_ports() == 1
    assert system.GetInputPort("inputs").size() == FDCC_INPUTS_SIZE
    assert system.GetOutputPort("position_command").size() == 6
    context = system.CreateDefaultContext()
    np.testing.assert_array_equal(
        system.get_position_command_output_port().Eval(context), q_start
    )
    _fix_inputs(system, context, q_start)
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    # Second tick: the internal velocity from tick one moves the command.
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    q_cmd = system.get_position_command_output_port().Eval(context)
    kw = dict(
        p_WP_target=START + [0, 0, 0.01],
        stiffness=[300.0] * 3,
        measured_force=[0, 0, -1.0],
        target_force=[0, 0, -2.0],
    )
    one = fdcc_step(
        system.model,
        system.params,
        q_measured=q_start,
        q_command_prev=q_start,
        qdot=np.zeros(6),
        last_error=np.zeros(6),
        **kw,
    )
    two = fdcc_step(
        system.model,
        system.params,
        q_measured=q_start,
        q_command_prev=one.q_command,
        qdot=one.qdot,
        last_error=one.last_error,
        **kw,
    )
    np.testing.assert_allclose(q_cmd, two.q_command, atol=1e-15)
    assert not np.allclose(q_cmd, q_start)
    np.testing.assert_array_equal(
        system.get_status_output_port().Eval(context), [0.0, 0.0]
    )


def test_nan_input_holds_the_command_and_flags(q_start):
    system = FdccController(
        FdccParams(), station_params=StationParams(), initial_q=q_start
    )
    context = system.CreateDefaultContext()
    _fix_inputs(system, context, q_start)
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    held = system.get_position_command_output_port().Eval(context).copy()
    _fix_inputs(system, context, q_start, force=(0.0, np.nan, 0.0))
    for _ in range(3):
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    np.testing.assert_array_equal(
        system.get_position_command_output_port().Eval(context), held
    )
    np.testing.assert_array_equal(
        system.get_status_output_port().Eval(context), [1.0, 3.0]
    )
    # Recovery: a finite input clears the flag, the count stays.
    _fix_inputs(system, context, q_start)
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    np.testing.assert_array_equal(
        system.get_status_output_port().Eval(context), [0.0, 3.0]
    )


def test_non_finite_command_is_refused_or_a_fault(q_start):
    """A NaN command never reaches Drake's kinematics (which abort on it)."""
    from dataclasses import replace

    from vic_drake.errors import VicDrakeError

    params = replace(FdccParams(), pose_feedback="command")
    system = FdccController(params, station_params=StationParams(), initial_q=q_start)
    context = system.CreateDefaultContext()
    with pytest.raises(VicDrakeError, match="6 finite joint angles"):
        system.set_initial_command(context, [np.nan] * 6)
    _fix_inputs(system, context, q_start)
    # A state set around the check: the tick is a fault, not an abort.
    context.SetDiscreteState(0, np.full(6, np.nan))
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    assert system.get_status_output_port().Eval(context)[0] == 1.0


def _closed_loop(q0, station_params, *, target, stiffness, target_force):
    phantom = SyntheticChestPhantom()
    builder = DiagramBuilder()
    station = builder.AddNamedSystem(
        "station", MakeStation(station_params, phantom=phantom, initial_q=q0)
    )
    fdcc = builder.AddNamedSystem(
        "fdcc",
        FdccController(FdccParams(), station_params=station_params, initial_q=q0),
    )
    demux = builder.AddSystem(Demultiplexer([6, 6]))
    builder.Connect(station.GetOutputPort("ur3e.state"), demux.get_input_port())
    inputs = AddFdccInputs(builder, fdcc)
    builder.Connect(demux.get_output_port(0), inputs["joint_positions"])
    builder.Connect(
        station.GetOutputPort("ft_sensor.force_W"), inputs["ft_sensor.force_W"]
    )
    builder.Connect(
        fdcc.get_position_command_output_port(),
        station.GetInputPort("ur3e.position_command"),
    )
    for port, value in (
        (inputs["target_position"], target),
        (inputs["stiffness"], stiffness),
        (inputs["target_force"], target_force),
        (station.GetInputPort("phantom.lift"), [0.0]),
    ):
        source = builder.AddSystem(ConstantVectorSource(np.asarray(value, float)))
        builder.Connect(source.get_output_port(), port)
    diagram = builder.Build()
    return diagram, station


def test_closed_loop_force_target_on_the_phantom():
    """CF-like use: K_z = 0, 7 N target; the true tissue force settles at 7 N."""
    phantom = SyntheticChestPhantom()
    xy = START[:2]
    s = float(phantom.surface_z(*xy))
    q0 = initial_q_for_tip([*xy, s + 0.005])
    diagram, station = _closed_loop(
        q0,
        StationParams(),
        target=[*xy, s + 0.005],
        stiffness=[300, 300, 0],
        target_force=[0, 0, -7.0],
    )
    simulator = Simulator(diagram)
    simulator.AdvanceTo(3.0)
    context = station.GetMyContextFromRoot(simulator.get_context())
    f_tissue = station.GetOutputPort("tissue.force_W").Eval(context)[2]
    assert f_tissue == pytest.approx(7.0, abs=0.4)
    p = station.GetOutputPort("probe.position").Eval(context)
    np.testing.assert_allclose(p[:2], xy, atol=1e-3)


def test_a_stuck_force_channel_trips_the_watchdog_and_the_tick_retracts(q_start):
    from vic_drake.control.watchdog import (
        TRIP_POSITION,
        TRIP_TIME,
        TRIPPED,
        WATCHDOG_SIZE,
        SensorWatchdogParams,
    )

    watchdog = SensorWatchdogParams()
    system = FdccController(
        FdccParams(),
        station_params=StationParams(),
        initial_q=q_start,
        watchdog=watchdog,
    )
    assert system.GetOutputPort("watchdog").size() == WATCHDOG_SIZE
    context = system.CreateDefaultContext()
    rng = np.random.default_rng(0)
    window = watchdog.window_ticks(FdccParams().period_s)
    for k in range(window + 1):  # z keeps -1 N while x, y change.
        context.SetTime(0.002 * k)
        force = (0.05 * rng.standard_normal(), 0.05 * rng.standard_normal(), -1.0)
        _fix_inputs(system, context, q_start, force=force)
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
        tripped = system.get_watchdog_output_port().Eval(context)[TRIPPED]
        assert tripped == (1.0 if k == window else 0.0)
    state = system.get_watchdog_output_port().Eval(context)
    assert state[TRIP_TIME] == pytest.approx(0.002 * window)
    np.testing.assert_allclose(
        state[TRIP_POSITION], system.model.pose(q_start).translation()
    )
    # The next tick reads neither the sensor nor the stiffness and targets
    # of its inputs: it is the pure step towards the retract target.
    q_prev = system.get_position_command_output_port().Eval(context).copy()
    internal = context.get_discrete_state(1).get_value().copy()
    context.SetTime(0.002 * (window + 1))
    _fix_inputs(system, context, q_start, force=(9.0, 9.0, 9.0))
    context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    expected = fdcc_step(
        system.model,
        system.params,
        q_measured=q_start,
        q_command_prev=q_prev,
        qdot=internal[:6],
        last_error=internal[6:],
        p_WP_target=state[TRIP_POSITION] + [0, 0, 0.03 * 0.002],
        stiffness=[1000.0] * 3,
        measured_force=[0.0] * 3,
        target_force=[0.0] * 3,
    )
    np.testing.assert_allclose(
        system.get_position_command_output_port().Eval(context),
        expected.q_command,
        atol=1e-15,
    )


def _run_fdcc(q_start, watchdog, forces):
    """An FdccController fed ``forces`` one tick each (the other inputs
    fixed at ``q_start``); returns it and its context after the last tick."""
    system = FdccController(
        FdccParams(),
        station_params=StationParams(),
        initial_q=q_start,
        watchdog=watchdog,
    )
    context = system.CreateDefaultContext()
    for k, force in enumerate(forces):
        context.SetTime(0.002 * k)
        _fix_inputs(system, context, q_start, force=force)
        context.SetDiscreteState(system.EvalUniquePeriodicDiscreteUpdate(context))
    return system, context


def test_a_dead_sensor_trips_the_watchdog_and_the_probe_lifts_instead_of_holding(
    q_start,
):
    from vic_drake.control.watchdog import (
        DEAD_SENSOR,
        STUCK_CHANNEL,
        TRIPPED,
        SensorWatchdogParams,
    )

    def run(watchdog, ticks):
        rng = np.random.default_rng(1)
        forces = [
            0.05 * rng.standard_normal(3) + [0, 0, -5.0] if k < 10 else [np.nan] * 3
            for k in range(ticks)
        ]
        return _run_fdcc(q_start, watchdog, forces)

    watchdog = SensorWatchdogParams()
    dead = watchdog.dead_ticks(FdccParams().period_s)
    # No reading from tick 10 on: dead at tick 10 + dead - 1.
    system, context = run(watchdog, 10 + dead - 1)
    assert system.get_watchdog_output_port().Eval(context)[TRIPPED] == 0.0
    system, context = run(watchdog, 10 + dead + 50)
    state = system.get_watchdog_output_port().Eval(context)
    assert state[TRIPPED] == 1.0 and state[STUCK_CHANNEL] == DEAD_SENSOR
    # Tripped, the ticks run without the sensor: the tip rises.
    tip = system.model.pose(system.get_position_command_output_port().Eval(context))
    assert tip.translation()[2] > system.model.pose(q_start).translation()[2] + 1e-4
    assert system.get_status_output_port().Eval(context)[0] == 0.0
    # Without the watchdog every NaN tick faults and holds the command.
    system, context = run(None, 10 + dead + 50)
    assert system.get_status_output_port().Eval(context)[1] == dead + 50


def test_without_a_watchdog_a_stuck_channel_is_followed(q_start):
    from vic_drake.control.watchdog import SensorWatchdogParams

    for watchdog in (None, SensorWatchdogParams(enabled=False)):
        rng = np.random.default_rng(0)
        forces = [
            (0.05 * rng.standard_normal(), 0.05 * rng.standard_normal(), -1.0)
            for _ in range(60)
        ]
        system, context = _run_fdcc(q_start, watchdog, forces)
        assert system.get_watchdog_output_port().Eval(context)[6] == 0.0
