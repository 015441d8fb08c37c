"""PatientMotionSource: the phantom's lift with breathing and a motion trace.

The sum of the scenario's lifts
(:func:`vic_drake.systems.trajectory.phantom_lift_m`), a breathing motion
and a replayed trace (:mod:`vic_drake.tissue.motion`), as the station's
``phantom.lift`` command; with a lateral breathing part, also the
breathing's (x, y) offset as the station's ``phantom.lateral`` command.
"""

from __future__ import annotations

import numpy as np
from pydrake.systems.framework import BasicVector, LeafSystem

from vic_drake.errors import VicDrakeError
from vic_drake.systems.trajectory import phantom_lift_m
from vic_drake.tissue.motion import (
    BreathCycles,
    breathing_lateral_m,
    breathing_offset_m,
    trace_offset_m,
)


class PatientMotionSource(LeafSystem):
    """The phantom's vertical offset (lifts + breathing + trace) and lateral one.

    Args:
        disturbance: the scenario's lifts (a DisturbanceConfig).
        breaths: the run's breaths (None: no breathing).
        trace: (n, 2) [t_s, z_m] rows (None: no trace).
        trace_scale: the trace's z x this.
        lateral_amplitude_m: (x, y) peak-to-peak lateral excursion of a
            mean breath, m (:func:`vic_drake.tissue.motion.breathing_lateral_m`);
            None: no lateral motion and no ``phantom_lateral`` port.

    Output ports:
        phantom_lift: (1,) z offset of the phantom, m.
        phantom_lateral: (2,) x, y offset of the phantom, m (only with
            ``lateral_amplitude_m``).
    """

    def __init__(
        self,
        disturbance,
        *,
        breaths: BreathCycles | None = None,
        trace: np.ndarray | None = None,
        trace_scale: float = 1.0,
        lateral_amplitude_m=None,
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
        self._lateral = None
        self._lateral_port = None
        if lateral_amplitude_m is not None:
            if breaths is None:
                raise VicDrakeError(
                    "PatientMotionSource: a lateral breathing part needs the breaths"
                )
            self._lateral = [float(v) for v in np.asarray(lateral_amplitude_m, float)]
            if len(self._lateral) != 2:
                raise VicDrakeError(
                    "PatientMotionSource: lateral_amplitude_m must be (x, y); got "
                    f"{lateral_amplitude_m!r}"
                )
            self._lateral_port = self.DeclareVectorOutputPort(
                "phantom_lateral",
                BasicVector(2),
                self._calc_lateral,
                prerequisites_of_calc={self.time_ticket()},
            )

    def get_phantom_lift_output_port(self):
        return self._port

    def get_phantom_lateral_output_port(self):
        """The (x, y) offset port; None without a lateral breathing part."""
        return self._lateral_port

    def lateral_m(self, t: float) -> tuple[float, float]:
        """The lateral (x, y) offset at time t, m ((0, 0) without one)."""
        if self._lateral is None:
            return 0.0, 0.0
        return breathing_lateral_m(t, self._breaths, self._lateral)

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

    def _calc_lateral(self, context, output):
        output.SetFromVector(self.lateral_m(context.get_time()))


__all__ = ["PatientMotionSource"]
