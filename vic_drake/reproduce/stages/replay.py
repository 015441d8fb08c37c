"""Stage ``replay``: a logged scan as a standalone Meshcat animation (replay.html)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.reproduce.context import RunContext, StageSkipped
from vic_drake.tissue import load_phantom

#: Frames per second of the Meshcat replay.
REPLAY_FPS = 25.0


def replay_scan(df: pd.DataFrame, scenario, *, phantom, fps: float = REPLAY_FPS) -> str:
    """A standalone Meshcat HTML animation of a logged scan.

    The station (arm, tool, phantom) is posed at every frame from the log: the
    joint angles commanded by FDCC (``q_cmd_*_rad``; the arm's servo follows
    them closely, see docs/decisions.md, "Replay from commanded joints") and
    the phantom's lift (``phantom_lift_m``), and published into a Meshcat
    recording; no simulation runs.

    Returns:
        The HTML text (``Meshcat.StaticHtml()``).
    """
    # Function-local: pydrake (heavy).
    from pydrake.geometry import Meshcat
    from pydrake.systems.framework import DiagramBuilder

    from vic_drake.station import MakeStation, set_station_state

    q_cols = [f"q_cmd_{i}_rad" for i in range(6)]
    missing = [c for c in [*q_cols, "t_s", "phantom_lift_m"] if c not in df.columns]
    if missing:
        raise VicDrakeError(f"replay_scan: the log lacks columns {missing}")
    meshcat = Meshcat()
    builder = DiagramBuilder()
    station = builder.AddNamedSystem(
        "station", MakeStation(scenario.station, phantom=phantom, meshcat=meshcat)
    )
    diagram = builder.Build()
    context = diagram.CreateDefaultContext()
    station_context = station.GetMyMutableContextFromRoot(context)
    t = df["t_s"].to_numpy()
    frames = np.arange(t[0], t[-1], 1.0 / fps)
    idx = np.searchsorted(t, frames).clip(0, len(t) - 1)
    q = df[q_cols].to_numpy()
    lift = df["phantom_lift_m"].to_numpy()
    meshcat.StartRecording(
        frames_per_second=fps, set_visualizations_while_recording=False
    )
    for i, tf in zip(idx, frames):
        context.SetTime(float(tf))
        set_station_state(station, station_context, q[i], phantom_lift_m=float(lift[i]))
        diagram.ForcedPublish(context)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return meshcat.StaticHtml()


def stage_replay(ctx: RunContext) -> dict:
    """The nominal VS-VF scan as a standalone Meshcat animation (replay.html)."""
    scans = ctx.results.get("scans")
    if not scans:
        raise StageSkipped("no simulated scan to replay (the scans stage did not run)")
    key = ("nominal", "vs-vf")
    df = scans["frames"][key[0]][key[1]]
    scenario = scans["scenarios"][key]
    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    html = replay_scan(df, scenario, phantom=phantom)
    path = ctx.out_dir / "replay.html"
    path.write_text(html, encoding="utf-8")
    return {"path": path, "bytes": path.stat().st_size, "scenario": scenario.name}
