"""The scenario's variations in the scan diagram: patient, motion, faults, map.

Each function returns the part of :func:`MakeScanDiagram` that a
:class:`~vic_drake.scenario.variation.VariationConfig` changes, or the
unchanged part when that variation is off (so a scenario without
variations builds the same diagram as before).
"""

from __future__ import annotations

import math

from vic_drake.scenario import Scenario
from vic_drake.systems.patient_motion import PatientMotionSource
from vic_drake.systems.sensor_faults import FaultySensor
from vic_drake.tissue.motion import breath_cycles, load_motion_trace
from vic_drake.tissue.phantom.distorted import with_map_errors
from vic_drake.tissue.phantom.population import patient_phantom


def patient_phantom_of(scenario: Scenario):
    """The patient's chest, or None when the scenario has no patient."""
    patient = scenario.variations.patient
    return patient_phantom(patient.factors()) if patient.enabled else None


def controller_map(scenario: Scenario, phantom):
    """The map the controller reads: the phantom with the scenario's map errors."""
    e = scenario.variations.map_errors
    return with_map_errors(
        phantom,
        kappa_scale=e.kappa_scale,
        lam_scale=e.lam_scale,
        surface_offset_m=e.surface_offset_m,
        shift_x_m=e.shift_x_m,
        shift_y_m=e.shift_y_m,
    )


def patient_motion_source(scenario: Scenario):
    """A PatientMotionSource (lifts + breathing + trace), or None without motion.

    With a lateral breathing part it has the ``phantom_lateral`` output too.
    """
    motion = scenario.variations.motion
    if not motion.active:
        return None
    b = motion.breathing
    breaths = (
        breath_cycles(
            frequency_hz=b.frequency_hz,
            amplitude_m=b.amplitude_m,
            irregularity=b.irregularity,
            duration_s=scenario.total_duration_s,
            seed=b.seed,
        )
        if b.active
        else None
    )
    trace = load_motion_trace(motion.trace_csv) if motion.trace_csv else None
    return PatientMotionSource(
        scenario.disturbance,
        breaths=breaths,
        trace=trace,
        trace_scale=motion.trace_scale,
        lateral_amplitude_m=b.lateral_amplitude_m if b.lateral_active else None,
    )


def add_sensor_faults(builder, scenario: Scenario, force_port):
    """The force port the controllers read: ``force_port`` through a FaultySensor.

    Returns ``force_port`` itself when the scenario has no sensor faults.
    """
    f = scenario.variations.sensor_faults
    if not f.active:
        return force_port
    sensor = builder.AddNamedSystem(
        "faulty_sensor",
        FaultySensor(
            period_s=scenario.controller.period_s,
            duration_s=scenario.total_duration_s,
            seed=f.seed,
            bias_N=f.bias_N,
            noise_std_N=f.noise_std_N,
            dropout_rate_per_s=f.dropout_rate_per_s,
            dropout_duration_s=f.dropout_duration_s,
            dropout_mode=f.dropout_mode,
            spike_rate_per_s=f.spike_rate_per_s,
            spike_magnitude_N=f.spike_magnitude_N,
            extra_latency_s=f.extra_latency_s,
            stuck_channel=f.stuck_channel,
            stuck_start_s=f.stuck_start_s,
            dead_start_s=f.dead_start_s if f.dead else math.inf,
        ),
    )
    builder.Connect(force_port, sensor.get_input_port_force())
    return sensor.get_output_port_force()


__all__ = [
    "add_sensor_faults",
    "controller_map",
    "patient_motion_source",
    "patient_phantom_of",
]
