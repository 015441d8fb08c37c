"""What the stages share: the run's options, results so far, figures, tables.

A stage is a function ``stage(ctx: RunContext) -> value``; it reads earlier
stages' results from ``ctx.results``, adds figures and tables to the report,
writes logs with :func:`_write_log`, and raises :class:`StageSkipped` when it
cannot run here. :class:`StageRecord` is how a stage went.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import yaml

from vic_drake.errors import VicDrakeError
from vic_drake.paths import find_data_dir
from vic_drake.reproduce.options import ReproduceOptions
from vic_drake.reproduce.report import ReportFigure


class StageSkipped(VicDrakeError):
    """A stage cannot run here (missing data or a missing part of vic_drake)."""


@dataclass
class StageRecord:
    """How a stage went."""

    name: str
    ok: bool
    wall_s: float
    error: str | None = None
    skipped: bool = False  # Not run here by design (no data, quick mode).

    @property
    def status(self) -> str:
        return "ok" if self.ok else ("skipped" if self.skipped else "failed")

    def as_dict(self) -> dict:
        return {
            "name": self.name,
            "ok": self.ok,
            "status": self.status,
            "wall_s": round(self.wall_s, 2),
            "error": self.error,
        }


@dataclass
class RunContext:
    """The options, the stage results so far and the run's bookkeeping."""

    options: ReproduceOptions
    results: dict[str, Any] = field(default_factory=dict)
    records: list[StageRecord] = field(default_factory=list)
    figures: list = field(default_factory=list)  # list[report.ReportFigure]
    tables: list = field(default_factory=list)  # list[report.ReportTable]
    #: Where the stages write (the run's work folder; None: options.out_dir).
    work_dir: Path | None = None

    @property
    def out_dir(self) -> Path:
        """Where the stages write; renamed to ``options.out_dir`` at the end."""
        return self.work_dir if self.work_dir is not None else self.options.out_dir

    @property
    def data_dir(self) -> Path | None:
        return find_data_dir(self.options.data_dir)

    @property
    def phantom_kind(self) -> str:
        if self.options.phantom != "auto":
            return self.options.phantom
        return "measured" if self.data_dir is not None else "synthetic"

    def progress(self, message: str) -> None:
        self.options.progress(message)

    def stage_error(self, name: str) -> str | None:
        for r in self.records:
            if r.name == name and not r.ok:
                return r.error
        if name not in self.results:
            selected = self.options.stages
            if selected is not None and name not in selected:
                return (
                    f"the {name} stage was not run (not in --stages "
                    f"{','.join(selected)})"
                )
            return f"the {name} stage did not run"
        return None

    def add_figure(self, title: str, caption: str, fig, filename: str) -> Path:
        """Saves a matplotlib figure under figures/ and adds it to the report."""
        path = self.out_dir / "figures" / filename
        path.parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(path, dpi=110, bbox_inches="tight")
        # Function-local: matplotlib is heavy, and only figure-making runs need it.
        import matplotlib.pyplot as plt

        plt.close(fig)
        self.figures.append(ReportFigure(title, caption, path))
        return path


def _write_log(ctx: RunContext, name: str, df: pd.DataFrame, config: dict) -> None:
    """logs/<name>.parquet and, beside it, logs/<name>.yaml with its configuration."""

    def plain(v):
        if dataclasses.is_dataclass(v):
            return plain(dataclasses.asdict(v))
        if isinstance(v, dict):
            return {str(k): plain(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        if isinstance(v, (np.floating, np.integer)):
            return v.item()
        return v

    logs = ctx.out_dir / "logs"
    logs.mkdir(parents=True, exist_ok=True)
    df.to_parquet(logs / f"{name}.parquet", index=False)
    (logs / f"{name}.yaml").write_text(
        yaml.safe_dump(plain(config), sort_keys=False), encoding="utf-8"
    )
