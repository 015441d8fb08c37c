"""FaultySensor: the force reading the controllers see, with sensor faults.

A thin wrapper of :func:`vic_drake.control.sensor_faults.faulty_reading`,
inserted by the scan diagram between the station's ``ft_sensor.force_W``
and the controllers when a scenario has sensor faults.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.control.sensor_faults import (
    DROPOUT_MODES,
    fault_schedule,
    faulty_reading,
)
from vic_drake.errors import VicDrakeError


class FaultySensor(LeafSystem):
    """The force reading with bias, noise, spikes, latency, a stuck axis,
    dropouts and a sensor that dies.

    Input ports:
        force_W: (3,) true sensor force in W, N.
    Output ports:
        force_W: (3,) the faulty reading, N (direct feedthrough of the input
            plus the state; no delay beyond ``extra_latency_s``).

    State (discrete, updated every ``period_s``): the last delivered reading
    (3), the stuck channel's value (1, NaN until it sticks) and the latency
    buffer of the last L true readings (3 L).
    """

    def __init__(
        self,
        *,
        period_s: float,
        duration_s: float,
        seed: int,
        bias_N=(0.0, 0.0, 0.0),
        noise_std_N: float = 0.0,
        dropout_rate_per_s: float = 0.0,
        dropout_duration_s: float = 0.0,
        dropout_mode: str = "hold",
        spike_rate_per_s: float = 0.0,
        spike_magnitude_N: float = 0.0,
        extra_latency_s: float = 0.0,
        stuck_channel: int = -1,
        stuck_start_s: float = 0.0,
        dead_start_s: float = math.inf,
    ):
        super().__init__()
        if dropout_mode not in DROPOUT_MODES:
            raise VicDrakeError(
                f"FaultySensor dropout_mode must be one of {list(DROPOUT_MODES)}; "
                f"got {dropout_mode!r}"
            )
        if stuck_channel not in (-1, 0, 1, 2):
            raise VicDrakeError(
                f"FaultySensor stuck_channel must be -1, 0, 1 or 2; got {stuck_channel!r}"
            )
        self._period_s = float(period_s)
        self._schedule = fault_schedule(
            ticks=int(math.ceil(duration_s / self._period_s)) + 2,
            period_s=self._period_s,
            seed=seed,
            noise_std_N=noise_std_N,
            spike_rate_per_s=spike_rate_per_s,
            spike_magnitude_N=spike_magnitude_N,
            dropout_rate_per_s=dropout_rate_per_s,
            dropout_duration_s=dropout_duration_s,
        )
        self._bias = np.asarray(bias_N, float).reshape(3)
        self._latency = int(round(extra_latency_s / self._period_s))
        self._stuck_channel = int(stuck_channel)
        self._stuck_start_s = float(stuck_start_s)
        self._dead_start_s = float(dead_start_s)
        self._mode = dropout_mode
        self._input = self.DeclareVectorInputPort("force_W", 3)
        self._state = self.DeclareDiscreteState(
            np.concatenate([np.zeros(3), [np.nan], np.zeros(3 * self._latency)])
        )
        self.DeclarePeriodicDiscreteUpdateEvent(self._period_s, 0.0, self._update)
        self._output = self.DeclareVectorOutputPort(
            "force_W",
            BasicVector(3),
            self._calc,
            prerequisites_of_calc={
                self.time_ticket(),
                self.all_input_ports_ticket(),
                self.xd_ticket(),
            },
        )

    def get_input_port_force(self):
        return self._input

    def get_output_port_force(self):
        return self._output

    def _reading(self, context) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(delivered reading, this tick's true input, state vector)."""
        x = context.get_discrete_state(self._state).get_value()
        u = self._input.Eval(context)
        raw = x[4:7] if self._latency > 0 else u
        t = context.get_time()
        y = faulty_reading(
            raw,
            tick=int(round(t / self._period_s)),
            t_s=t,
            schedule=self._schedule,
            bias_N=self._bias,
            stuck_channel=self._stuck_channel,
            stuck_start_s=self._stuck_start_s,
            stuck_value_N=float(x[3]),
            previous_N=x[0:3],
            dropout_mode=self._mode,
            dead_start_s=self._dead_start_s,
        )
        return y, u, x

    def _calc(self, context, output):
        output.SetFromVector(self._reading(context)[0])

    def _update(self, context, discrete_state):
        y, u, x = self._reading(context)
        new = x.copy()
        new[0:3] = y
        ch = self._stuck_channel
        if ch >= 0 and context.get_time() >= self._stuck_start_s and math.isnan(x[3]):
            new[3] = y[ch]
        if self._latency > 0:
            new[4:] = np.concatenate([x[7:], u])
        discrete_state.set_value(self._state, new)


__all__ = ["FaultySensor"]
