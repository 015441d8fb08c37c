"""The options of a reproduction run, checked when they are made."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from vic_drake.errors import VicDrakeError
from vic_drake.paths import check_data_dir, has_data, resolve_data_dir
from vic_drake.reproduce.stage_names import STAGE_NAMES
from vic_drake.tissue.relaxation import RelaxationParams


@dataclass
class ReproduceOptions:
    """Options of a reproduction run.

    Attributes:
        out_dir: folder for every output (created).
        data_dir: the paper's measurements (None: the default lookup).
        quick: shorter scans and a coarser map (see docs/decisions.md,
            "Quick mode").
        phantom: "auto" (measured map when the data is there, else synthetic),
            "measured" or "synthetic".
        stages: names of the stages to run (None: all).
        meshcat: keep the replay's Meshcat server for a live view (the result's
            ``results["replay"]["meshcat"]``).
        progress: called with one line of progress text.
        relaxation: the relaxing tissue's branches in every simulation of the
            run (palpations, scans, compare-real); None (the default):
            :data:`vic_drake.tissue.DEFAULT_RELAXATION`.
        workers: local Dask worker processes for the scans and the
            compare-real re-runs (None: one per core; for compare-real, not
            more than there are logs).
        scheduler: the address of an existing Dask scheduler to run them
            on instead (not with ``workers``).
        overwrite: replace a previous complete run in ``out_dir`` even when
            this run does not cover it (fewer stages, or no data where it had
            the data); without it such a run is refused before any work
            (:func:`vic_drake.reproduce.run_dir.check_replace`).
    """

    out_dir: Path
    data_dir: Path | None = None
    quick: bool = False
    phantom: str = "auto"
    stages: tuple[str, ...] | None = None
    meshcat: bool = False
    progress: Callable[[str], None] = lambda message: None
    relaxation: RelaxationParams | None = None
    overwrite: bool = False
    workers: int | None = None
    scheduler: str | None = None

    def __post_init__(self):
        self.out_dir = Path(self.out_dir)
        if self.workers is not None and (
            isinstance(self.workers, bool)
            or not isinstance(self.workers, int)
            or self.workers < 1
        ):
            raise VicDrakeError(
                f"workers must be an integer >= 1 or None; got {self.workers!r}"
            )
        if self.scheduler is not None and (
            not isinstance(self.scheduler, str) or not self.scheduler.strip()
        ):
            raise VicDrakeError(
                "scheduler must be an address such as tcp://host:8786 or None; "
                f"got {self.scheduler!r}"
            )
        if self.workers is not None and self.scheduler is not None:
            raise VicDrakeError(
                "give workers (a local cluster) or scheduler (an existing one), "
                "not both"
            )
        if self.relaxation is not None and not isinstance(
            self.relaxation, RelaxationParams
        ):
            raise VicDrakeError(
                "relaxation must be a vic_drake.tissue.RelaxationParams or None, got "
                f"{type(self.relaxation).__name__}"
            )
        if self.phantom not in ("auto", "measured", "synthetic"):
            raise VicDrakeError(
                f"phantom must be 'auto', 'measured' or 'synthetic', got {self.phantom!r}"
            )
        check_data_dir(self.data_dir)
        if self.phantom == "measured" and not has_data(self.data_dir):
            raise VicDrakeError(
                f"--phantom measured needs the paper's phantom map; none found at "
                f"{str(resolve_data_dir(self.data_dir))!r} (pass --data-dir DIR or set "
                "VIC_DRAKE_DATA)"
            )
        if self.stages is not None:
            self.stages = tuple(self.stages)
            if not self.stages:
                raise VicDrakeError(
                    "no stage given (--stages is empty); give one or more of "
                    f"{', '.join(STAGE_NAMES)}, or omit it to run them all"
                )
            unknown = [s for s in self.stages if s not in STAGE_NAMES]
            if unknown:
                raise VicDrakeError(
                    f"unknown stage(s) {unknown}; allowed: {', '.join(STAGE_NAMES)}"
                )
