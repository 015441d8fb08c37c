"""PatientMotionSource: the phantom's lift with breathing and a motion trace.

The sum of the scenario's lifts
(:func:`vic_drake.systems.trajectory.phantom_lift_m`), a breathing motion
and a replayed trace (:mod:`vic_drake.tissue.motion`), as the station's
``phantom.lift`` command.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.systems.trajectory import phantom_lift_m
from vic_drake.tissue.motion import (
    BreathCycles,
    breathing_offset_m,
    trace_offset_m,
)


class PatientMotionSource(LeafSystem):
    """The phantom's vertical offset: lifts + breathing + trace.

    Args:
        disturbance: the scenario's lifts (a DisturbanceConfig).
        breaths: the run's breaths (None: no breathing).
        trace: (n, 2) [t_s, z_m] rows (None: no trace).
        trace_scale: the trace's z x this.

    Output ports:
        phantom_lift: (1,) z offset of the phantom, m.
    """

    def __init__(
        self,
        disturbance,
        *,
        breaths: BreathCycles | None = None,
        trace: np.ndarray | None = None,
        trace_scale: float = 1.0,
    ):
        super().__init__()
        self._disturbance = disturbance
        self._breaths = breaths
        self._trace = None if trace is None else np.asarray(trace, float)
        self._trace_scale = float(trace_scale)
        self._port = self.DeclareVectorOutputPort(
            "phantom_lift",
            BasicVector(1),
            self._calc,
            prerequisites_of_calc={self.time_ticket()},
        )

    def get_phantom_lift_output_port(self):
        return self._port

    def offset_m(self, t: float) -> float:
        """The offset at time t, m."""
        z = (
            0.0
            if self._disturbance.is_nominal
            else float(phantom_lift_m(t, self._disturbance))
        )
        if self._breaths is not None:
            z += breathing_offset_m(t, self._breaths)
        if self._trace is not None:
            z += trace_offset_m(t, self._trace, self._trace_scale)
        return z

    def _calc(self, context, output):
        output.SetAtIndex(0, self.offset_m(context.get_time()))


__all__ = ["PatientMotionSource"]
