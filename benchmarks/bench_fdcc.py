"""Per-tick cost of the FDCC layer (FdccController and its pure functions).

Prints the median and 90th percentile wall time per call, in microseconds,
of

- ``FdccController._update`` on a fixed context (inputs fixed, the discrete
  state copied in as Drake does before calling the handler), without and
  with the force sensor's watchdog (two contexts whose force readings
  differ, called in turn, so that the watchdog compares changing readings
  as on a live sensor), and the watchdog's ``watch_reading`` alone;
- ``EvalUniquePeriodicDiscreteUpdate`` (the same plus Drake's event
  dispatch and a fresh DiscreteValues; the context time is nudged before
  each call so that the cached result is not reused);
- the pure functions ``fdcc_tick`` and ``fdcc_step`` (the latter checks
  its arguments and reads FdccParams on every call);
- the internal model's Drake calls of one tick: SetPositions, then
  CalcMassMatrix, CalcJacobianSpatialVelocity and CalcPoseInWorld.

Calls are timed one by one and the kinds interleaved (A, B, C, ... A, B,
C, ...) so that a load change on a shared machine hits every figure alike.
No asserts: this prints figures.

Usage:
    python benchmarks/bench_fdcc.py [--calls N]
"""

from __future__ import annotations

import argparse
import importlib.metadata
import platform
import statistics
import time

import numpy as np
from pydrake.multibody.tree import JacobianWrtVariable

from vic_drake.control.fdcc import FdccConstants, FdccParams, fdcc_step, fdcc_tick
from vic_drake.control.watchdog import (
    SensorWatchdogParams,
    initial_watchdog_state,
    watch_reading,
)
from vic_drake.station import StationParams, initial_q_for_tip
from vic_drake.systems.fdcc import FdccController
from vic_drake.systems.signals import FDCC_IN_FORCE, FDCC_INPUT_PARTS, FDCC_INPUTS_SIZE

START = np.array([-0.06, -0.36, 0.13])


def _controller(watchdog=None):
    q0 = initial_q_for_tip(START)
    system = FdccController(
        FdccParams(), station_params=StationParams(), initial_q=q0, watchdog=watchdog
    )
    context = system.CreateDefaultContext()
    inputs = {
        "joint_positions": q0 + 0.001,
        "target_position": START + [0.0, 0.0, 0.01],
        "stiffness": np.array([300.0, 300.0, 300.0]),
        "ft_sensor.force_W": np.array([0.0, 0.0, -1.0]),
        "target_force": np.array([0.0, 0.0, -2.0]),
    }
    u = np.zeros(FDCC_INPUTS_SIZE)
    for name, part in FDCC_INPUT_PARTS:
        u[part] = inputs[name]
    system.get_inputs_input_port().FixValue(context, u)
    return system, context, q0, list(inputs.values())


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=20000, help="calls per kind")
    args = parser.parse_args(argv)
    print(
        f"Python {platform.python_version()}, Drake {importlib.metadata.version('drake')}, "
        f"numpy {np.__version__}, {platform.machine()}"
    )
    system, context, q0, (q_m, x_d, K, f_m, f_t) = _controller()
    model, params = system.model, system.params
    discrete_state = system.AllocateDiscreteVariables()
    discrete_state.SetFrom(context.get_discrete_state())
    constants = FdccConstants.from_params(params)
    zeros = np.zeros(6)
    step_kw = dict(
        q_measured=q_m,
        q_command_prev=q0,
        qdot=zeros,
        last_error=zeros,
        p_WP_target=x_d,
        stiffness=K,
        measured_force=f_m,
        target_force=f_t,
        R_WP_target=constants.R_WP_target,
    )
    plant, scratch = model.plant, model._context
    world, origin = plant.world_frame(), np.zeros(3)
    q_alt = (q_m, q_m + 1e-6)
    # One alternation per kind: a counter shared by several kinds would
    # flip an even number of times between two calls of one of them.
    state = {"positions": 0, "update": 0, "watch": 0}

    def set_positions():
        state["positions"] ^= 1
        plant.SetPositions(scratch, q_alt[state["positions"]])

    # The watchdog's controller on two contexts whose readings differ, one
    # state between them: each call compares a reading that changed.
    w_system, w_context, _, _ = _controller(SensorWatchdogParams())
    w_contexts = (w_context, w_system.CreateDefaultContext())
    u = w_system.get_inputs_input_port().Eval(w_context).copy()
    u[FDCC_IN_FORCE] = [0.001, 0.002, -1.001]  # Every channel differs.
    w_system.get_inputs_input_port().FixValue(w_contexts[1], u)
    w_state = w_system.AllocateDiscreteVariables()
    w_state.SetFrom(w_context.get_discrete_state())
    readings = (np.array([0.01, 0.02, -1.0]), np.array([0.02, 0.01, -1.001]))
    watch_state = initial_watchdog_state()
    defaults = SensorWatchdogParams()
    window = defaults.window_ticks(FdccParams().period_s)
    dead = defaults.dead_ticks(FdccParams().period_s)

    def watched_update():
        state["update"] ^= 1
        w_system._update(w_contexts[state["update"]], w_state)

    def watch():
        state["watch"] ^= 1
        watch_reading(watch_state, readings[state["watch"]], window, dead)

    def eval_update():
        context.SetTime(context.get_time() + 1e-9)
        system.EvalUniquePeriodicDiscreteUpdate(context)

    kinds = {
        "FdccController._update": lambda: system._update(context, discrete_state),
        "  with the watchdog": watched_update,
        "watch_reading": watch,
        "EvalUniquePeriodicDiscreteUpdate": eval_update,
        "fdcc_tick": lambda: fdcc_tick(
            model, constants, q_m, q0, zeros, zeros, x_d, K, f_m, f_t
        ),
        "fdcc_step": lambda: fdcc_step(model, params, **step_kw),
        "SetPositions (model)": set_positions,
        "  + CalcMassMatrix": lambda: (set_positions(), plant.CalcMassMatrix(scratch)),
        "  + CalcJacobianSpatialVelocity": lambda: (
            set_positions(),
            plant.CalcJacobianSpatialVelocity(
                scratch, JacobianWrtVariable.kV, model.frame, origin, world, world
            ),
        ),
        "  + CalcPoseInWorld": lambda: (
            set_positions(),
            model.frame.CalcPoseInWorld(scratch),
        ),
    }
    times = {name: [] for name in kinds}
    for f in kinds.values():  # warm-up
        for _ in range(200):
            f()
    clock = time.perf_counter
    for _ in range(args.calls):
        for name, f in kinds.items():
            t0 = clock()
            f()
            times[name].append(clock() - t0)
    if w_state.get_vector(3).GetAtIndex(6) != 0.0:
        raise SystemExit(
            "the benchmark's watchdog tripped: its figure is not a live tick's"
        )
    print(f"{'per call, us':36s} {'median':>8s} {'p90':>8s}   ({args.calls} calls)")
    for name, ts in times.items():
        ts.sort()
        med, p90 = statistics.median(ts), ts[int(0.9 * len(ts))]
        print(f"{name:36s} {1e6 * med:8.1f} {1e6 * p90:8.1f}")


if __name__ == "__main__":
    main()
