"""Which tissue a scan runs on: the synthetic chest or the measured map."""

from dataclasses import dataclass

from vic_drake.errors import VicDrakeError
from vic_drake.tissue.phantom import PHANTOM_KINDS

#: How a measured map is read between its grid points.
LOOKUPS = ("bilinear", "nearest")


@dataclass
class PhantomConfig:
    """Which tissue the probe scans.

    Attributes:
        kind: "synthetic" (the analytic chest, always available) or
            "measured" (the paper's GP map from ``<data>/phantom_map``).
        lookup: how the *tissue* (the station's force element) reads the
            measured map: "bilinear" (a smooth body) or "nearest".
        controller_lookup: how the *controller* reads the map (surface,
            kappa, lambda for its references): "bilinear", what the real
            controller's logs show (docs/decisions.md, "The controller reads
            the map bilinearly"), or "nearest" (the grid point, as the data
            README describes the published source).
    """

    kind: str = "synthetic"  # "synthetic" | "measured".
    lookup: str = "bilinear"  # Tissue lookup on the measured map.
    controller_lookup: str = "bilinear"  # The controller's lookup on the measured map.

    def __post_init__(self):
        self.validate()

    def validate(self) -> "PhantomConfig":
        """Checks every field; returns self.

        Raises:
            VicDrakeError: naming the field and the bad value.
        """
        if self.kind not in PHANTOM_KINDS:
            raise VicDrakeError(
                f"PhantomConfig.kind must be one of {list(PHANTOM_KINDS)}; got {self.kind!r}"
            )
        for name in ("lookup", "controller_lookup"):
            value = getattr(self, name)
            if value not in LOOKUPS:
                raise VicDrakeError(
                    f"PhantomConfig.{name} must be 'bilinear' or 'nearest'; got {value!r}"
                )
        return self
