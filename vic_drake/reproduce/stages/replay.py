"""Stage ``replay``: a logged scan as a standalone Meshcat animation (replay.html).

The page opens framed on the probe and the phantom along the scan line, with
a title and a caption naming the scan. The Meshcat server that records the
animation is quiet: its URL is printed only when the user asked for a live
view (``vic-drake reproduce --meshcat``), which keeps it open until Ctrl-C.
"""

from __future__ import annotations

import contextlib
import html as html_mod
import logging

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.reproduce.context import RunContext, StageSkipped
from vic_drake.tissue import load_phantom

#: Frames per second of the Meshcat replay.
REPLAY_FPS = 25.0
#: Camera offset from the middle of the scan line, m (world frame): beside the
#: scan line, away from the arm's base, and above it, so the probe, the
#: phantom under it and the arm's forearm fill the view.
CAMERA_OFFSET_M = (0.12, -0.50, 0.26)


@contextlib.contextmanager
def _quiet_drake_log():
    """Silences Drake's INFO lines (Meshcat's "listening at http://...")."""
    logger = logging.getLogger("drake")
    level = logger.level
    logger.setLevel(logging.WARNING)
    try:
        yield
    finally:
        logger.setLevel(level)


def new_meshcat():
    """A Meshcat server whose URL is not logged (the caller prints it if asked)."""
    # Function-local: pydrake (heavy).
    from pydrake.geometry import Meshcat

    with _quiet_drake_log():
        return Meshcat()


def scan_frame_target(df: pd.DataFrame, scenario) -> np.ndarray:
    """The point the camera looks at: the middle of the scanned stretch, p_WT (m).

    From the logged tip position where the log has it (``x_m``, ``y_m``,
    ``z_m``), else from the scenario's scan line at its target height.
    """
    cols = ("x_m", "y_m", "z_m")
    if all(c in df.columns for c in cols):
        p = df[list(cols)].to_numpy(float)
        p = p[np.all(np.isfinite(p), axis=1)]
        if len(p):
            lo, hi = p.min(axis=0), p.max(axis=0)
            return 0.5 * (lo + hi)
    traj = scenario.trajectory
    return np.array([0.5 * (traj.start_x_m + traj.end_x_m), traj.y_m, traj.target_z_m])


def _page(static_html: str, title: str, caption: str) -> str:
    """Meshcat's static page with our title, and a title/caption box over the view."""
    t, c = html_mod.escape(title), html_mod.escape(caption)
    out = static_html.replace("<title>Drake MeshCat</title>", f"<title>{t}</title>", 1)
    box = (
        '<div id="vic-drake-caption" style="position:fixed;left:12px;top:10px;'
        "z-index:10;max-width:60%;background:rgba(255,255,255,0.88);padding:8px 12px;"
        'border-radius:4px;font:14px/1.35 system-ui,sans-serif;color:#222">'
        f'<div style="font-weight:600;font-size:16px">{t}</div><div>{c}</div></div>'
    )
    if "<body>" not in out:
        raise VicDrakeError("replay_scan: Meshcat's static page has no <body>")
    return out.replace("<body>", "<body>\n" + box, 1)


def replay_scan(
    df: pd.DataFrame,
    scenario,
    *,
    phantom,
    fps: float = REPLAY_FPS,
    meshcat=None,
    title: str | None = None,
    caption: str | None = None,
) -> str:
    """A standalone Meshcat HTML animation of a logged scan.

    The station (arm, tool, phantom) is posed at every frame from the log: the
    joint angles commanded by FDCC (``q_cmd_*_rad``; see docs/decisions.md,
    "Replay from commanded joints") and the phantom's lift
    (``phantom_lift_m``), and published into a Meshcat recording; no
    simulation runs. The camera looks at the middle of the scan
    (:func:`scan_frame_target`) from ``CAMERA_OFFSET_M``.

    Args:
        df: the scan log (canonical columns).
        scenario: the scan's Scenario.
        phantom: the phantom the scan ran on.
        fps: frames per second of the animation.
        meshcat: a Meshcat to record into (kept for a live view); None: a
            new, quiet one.
        title, caption: shown over the view (default: the scenario's name
            and description).

    Returns:
        The HTML text (``Meshcat.StaticHtml()`` with the title and caption).
    """
    # Function-local: pydrake (heavy).
    from pydrake.systems.framework import DiagramBuilder

    from vic_drake.station import MakeStation, set_station_state

    q_cols = [f"q_cmd_{i}_rad" for i in range(6)]
    missing = [c for c in [*q_cols, "t_s", "phantom_lift_m"] if c not in df.columns]
    if missing:
        raise VicDrakeError(f"replay_scan: the log lacks columns {missing}")
    if len(df) < 2:
        raise VicDrakeError(f"replay_scan: the log has {len(df)} rows; needs >= 2")
    meshcat = new_meshcat() if meshcat is None else meshcat
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
    target = scan_frame_target(df, scenario)
    meshcat.SetCameraPose(target + np.asarray(CAMERA_OFFSET_M), target)
    meshcat.StartRecording(
        frames_per_second=fps, set_visualizations_while_recording=False
    )
    for i, tf in zip(idx, frames):
        context.SetTime(float(tf))
        set_station_state(
            station, station_context, q[i], phantom_command=[float(lift[i])]
        )
        diagram.ForcedPublish(context)
    meshcat.StopRecording()
    meshcat.PublishRecording()
    return _page(
        meshcat.StaticHtml(),
        title or f"vic_drake replay: {scenario.name}",
        caption or scenario.description,
    )


def stage_replay(ctx: RunContext) -> dict:
    """The nominal VS-VF scan as a standalone Meshcat animation (replay.html).

    With ``options.meshcat`` the Meshcat server is kept in the result
    (``"meshcat"``) for a live view.
    """
    scans = ctx.results.get("scans")
    if not scans:
        raise StageSkipped("no simulated scan to replay (the scans stage did not run)")
    key = ("nominal", "vs-vf")
    df = scans["frames"][key[0]][key[1]]
    scenario = scans["scenarios"][key]
    phantom = load_phantom(ctx.phantom_kind, data_dir=ctx.data_dir)
    meshcat = new_meshcat()
    duration = float(df["t_s"].iloc[-1] - df["t_s"].iloc[0])
    caption = (
        f"{scenario.description}: scenario {scenario.name}, {duration:.1f} s "
        "simulated, the arm posed from the joint angles FDCC commanded. Press play "
        "under Open Controls > Animations."
    )
    html = replay_scan(
        df,
        scenario,
        phantom=phantom,
        meshcat=meshcat,
        title=f"Replay of the simulated {key[1].upper()} {key[0]} scan",
        caption=caption,
    )
    path = ctx.out_dir / "replay.html"
    path.write_text(html, encoding="utf-8")
    out = {"path": path, "bytes": path.stat().st_size, "scenario": scenario.name}
    if ctx.options.meshcat:
        out["meshcat"] = meshcat
    return out
