"""Stage ``report``: report.html with the claims, tables, figures, files,
stage times and versions (rendered by :mod:`vic_drake.reproduce.report`)."""

from __future__ import annotations

import os
import platform
import time

import numpy as np
import pandas as pd

from vic_drake.reproduce.context import RunContext
from vic_drake.reproduce.report import ReportContent, write_report

REPORT_NOTES = (
    "paper: the paper's number or statement; simulation: the same metric computed from "
    "the logs of the Drake simulation; real measurement: the same metric on the paper's "
    "own logs (../shared/data), where such a log exists.",
    "C1 and C2 in simulation fit palpations simulated on a Hunt-Crossley tissue with "
    "beta = 1.35: they test the estimation pipeline (sensor lag and noise, indenter mass, "
    "contact selection), not whether tissue is Hunt-Crossley; the real logs test that.",
    "C2 in simulation: the simulated tissue IS the fitted model, so a short palpation "
    "already fits it and the residual barely falls; the several-fold fall of the real "
    "logs comes from what the model lacks (drift, non-stationarity, model mismatch).",
    "C3 in simulation re-estimates the scan phantom's map from simulated palpations on "
    "a 1 cm grid (with the paper's data, the phantom is the paper's measured map); the "
    "real value is the paper's own GP map.",
    "C4-C7 in simulation come from the scans of this run; the real values from the "
    "paper's scan logs. The published data has no VS-VF disturbance log, so C7 has no "
    "real value. The real CF reference (7 N) is not logged; it is taken from the "
    "data's README.",
    "The disturbance here is a scripted lift, drop below rest and return of the phantom "
    "(vic_drake.experiments.disturbance_lifts); the paper's was by hand, so peak forces "
    "compare in order, not in value.",
    "Quick mode scans 5 cm instead of 20 cm with one disturbance event; force ranges "
    "(C5) and peak forces (C7) see less of the body than the full run.",
)


_PAPER_ORDER = (
    ("Fig. 2", 2.0),
    ("Table I", 2.5),
    ("Beta sweep", 2.6),
    ("Fig. 3", 3.0),
    ("Fig. 4", 4.0),
    ("Fig. 5", 5.0),
    ("Fig. 6", 6.0),
    ("CS and CF", 6.5),
    ("Fig. 7", 7.0),
    ("Real scan logs", 8.0),
    ("Simulated scans: metrics", 8.1),
    ("Real experiments", 8.5),
    ("Real vs simulated", 8.6),
)


def _paper_order(title: str) -> float:
    """Rank of a figure or table: the paper's order, then the rest."""
    return next(
        (rank for prefix, rank in _PAPER_ORDER if title.startswith(prefix)), 9.0
    )


def _versions() -> dict:
    # Function-local: heavy packages, imported only to read their versions.
    import matplotlib
    import scipy
    import sklearn

    import vic_drake

    try:
        import pydrake

        drake_version = getattr(pydrake, "__version__", "unknown")
    except ImportError:  # pragma: no cover - drake is a dependency
        drake_version = "not installed"
    return {
        "vic_drake": vic_drake.__version__,
        "drake": drake_version,
        "python": platform.python_version(),
        "numpy": np.__version__,
        "scipy": scipy.__version__,
        "pandas": pd.__version__,
        "scikit-learn": sklearn.__version__,
        "matplotlib": matplotlib.__version__,
    }


def stage_report(ctx: RunContext) -> dict:
    """report.html: claims, tables, figures, files, stage times, versions."""
    claims = (ctx.results.get("claims") or {}).get("claims", {})
    links = []
    replay = ctx.results.get("replay")
    if replay and replay.get("path"):
        links.append(
            (
                "Meshcat replay of one scan (open in a browser)",
                os.path.relpath(replay["path"], ctx.out_dir),
            )
        )
    links.append(("claims.json", "claims.json"))
    logs_dir = ctx.out_dir / "logs"
    if logs_dir.is_dir():
        for p in sorted(logs_dir.iterdir()):
            links.append((f"logs/{p.name}", f"logs/{p.name}"))
    mode = "quick" if ctx.options.quick else "full"
    content = ReportContent(
        title="vic_drake: reproduction of Beber et al., passive variable impedance "
        "control for safe ultrasonography",
        summary=(
            f"Mode: {mode}. Phantom for the simulated scans: {ctx.phantom_kind}. "
            f"Real data: {ctx.data_dir if ctx.data_dir else 'not found'}. Each claim is a "
            "metric computed from logged signals, in simulation and in the paper's real "
            "logs where they exist."
        ),
        claims=claims,
        figures=sorted(ctx.figures, key=lambda f: _paper_order(f.title)),
        tables=sorted(ctx.tables, key=lambda t: _paper_order(t.title)),
        metadata={
            **{f"version {k}": v for k, v in _versions().items()},
            "data folder": str(ctx.data_dir) if ctx.data_dir else "not found",
            "mode": mode,
            "phantom": ctx.phantom_kind,
            "machine": f"{platform.machine()}, {os.cpu_count()} CPUs",
            "total wall time [s]": round(sum(r.wall_s for r in ctx.records), 1),
            "date (UTC)": time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime()),
        },
        stages=[r.as_dict() for r in ctx.records],
        links=links,
        notes=REPORT_NOTES,
    )
    path = write_report(content, ctx.out_dir / "report.html")
    return {"path": path}
