"""The parameters of a palpation campaign (:class:`CampaignParams`).

What defines a simulated campaign of the paper's offline phase: the grid,
the palpation procedure, the indenter and its servo, the F/T sensor model,
how each point is reduced, and how the simulation is batched.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vic_drake.errors import VicDrakeError
from vic_drake.systems.indenter import IndenterParams, PalpationParams, SensorParams


@dataclass(frozen=True)
class CampaignParams:
    """Everything that defines a palpation campaign (SI units).

    Attributes:
        spacing_m: grid spacing of the palpation points (paper: 1 cm).
        region_m: (x_min, x_max, y_min, y_max) to palpate; None = the
            phantom's bounds. Points start at (x_min, y_min).
        palpation, indenter, sensor: the procedure, the indenter and its
            servo, the F/T sensor model.
        lag_s: sensor lag used to align force and position, s; None uses the
            rig's calibration, ``sensor.lag_samples / sensor.rate_hz`` (the
            real controller's 28 samples).
        estimate_lag: estimate the lag from the logs instead (median of
            :func:`~vic_drake.estimation.palpation.estimate_lag` over
            ``lag_calibration_points`` points). At a single palpation
            frequency a lag and a viscous term look alike, hence off by
            default (see docs/decisions.md, "Campaign sensor lag").
        lag_calibration_points: points used to estimate the lag (median).
        free_air_s: initial span used for the tare and the noise std.
        rise_sigmas, rise_min_N, rise_hold_samples: force-rise detection.
        surface_iterations: fixed-point iterations of the surface correction
            (each one refits; see docs/decisions.md, "Campaign surface
            iterations").
        batch_size: indenters per simulated diagram. The cost of a step is
            mostly per-step overhead, so bigger banks are cheaper per point
            (see docs/decisions.md, "Campaign batch size").
        workers: worker processes for the simulation (1: in-process). With
            more, the batches run on a local Dask cluster of that many
            worker processes, so a calling script needs the ``if __name__ ==
            "__main__":`` guard. On 2 cores the gain is small (see
            docs/decisions.md, "Campaign workers"), hence 1 by default.
        seed: seed of the sensor noise (point i of the grid: (seed, i)).
    """

    spacing_m: float = 0.01
    region_m: tuple[float, float, float, float] | None = None
    palpation: PalpationParams = field(default_factory=PalpationParams)
    indenter: IndenterParams = field(default_factory=IndenterParams)
    sensor: SensorParams = field(default_factory=SensorParams)
    lag_s: float | None = None
    estimate_lag: bool = False
    lag_calibration_points: int = 5
    free_air_s: float = 0.08
    rise_sigmas: float = 4.0
    rise_min_N: float = 0.05
    rise_hold_samples: int = 5
    surface_iterations: int = 1
    batch_size: int = 256
    workers: int = 1
    seed: int = 0

    def __post_init__(self):
        if not (np.isfinite(self.spacing_m) and self.spacing_m > 0):
            raise VicDrakeError(
                f"CampaignParams.spacing_m must be > 0, got {self.spacing_m!r}"
            )
        if self.region_m is not None:
            r = tuple(float(v) for v in self.region_m)
            if len(r) != 4 or not all(np.isfinite(r)) or r[1] < r[0] or r[3] < r[2]:
                raise VicDrakeError(
                    "CampaignParams.region_m must be (x_min, x_max, y_min, y_max) with "
                    f"x_min <= x_max and y_min <= y_max, got {self.region_m!r}"
                )
            object.__setattr__(self, "region_m", r)
        if self.lag_s is not None and not (np.isfinite(self.lag_s) and self.lag_s >= 0):
            raise VicDrakeError(
                f"CampaignParams.lag_s must be >= 0 or None, got {self.lag_s!r}"
            )
        for name in (
            "lag_calibration_points",
            "batch_size",
            "rise_hold_samples",
            "surface_iterations",
        ):
            value = getattr(self, name)
            if int(value) != value or value < 1:
                raise VicDrakeError(
                    f"CampaignParams.{name} must be an integer >= 1, got {value!r}"
                )
        if int(self.workers) != self.workers or self.workers < 1:
            raise VicDrakeError(
                f"CampaignParams.workers must be an integer >= 1, got {self.workers!r}"
            )
        for name in ("free_air_s", "rise_sigmas"):
            value = getattr(self, name)
            if not (np.isfinite(value) and value > 0):
                raise VicDrakeError(f"CampaignParams.{name} must be > 0, got {value!r}")
        if not (np.isfinite(self.rise_min_N) and self.rise_min_N >= 0):
            raise VicDrakeError(
                f"CampaignParams.rise_min_N must be >= 0, got {self.rise_min_N!r}"
            )


__all__ = ["CampaignParams"]
