"""Writing logs as the real rig's ROS 2 bags (the inverse of :mod:`vic_drake.realdata`).

:func:`write_bag` stores rows of one of the rig's layouts
(:data:`vic_drake.realdata.LAYOUTS`) as ``std_msgs/msg/Float64MultiArray``
messages on the rig's topic (:data:`LAYOUT_TOPICS`), in a ROS 2 bag folder
(``metadata.yaml`` + sqlite3 ``.db3``) written with ``rosbags``: the topics,
message type and row layouts of the real logs, so the tools that read those
(the project's :func:`vic_drake.realdata.read_bag`, ROS 2 tools, bag
viewers) read it the same way. Each message's timestamp is its row's ``t_s``
in nanoseconds.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.realdata import LAYOUTS

#: The topic each layout was logged on by the real rig.
LAYOUT_TOPICS = {
    "controller": "/adaptive_stiffness_data",
    "scan": "/data_control",
    "palpation": "/data_control",
}

_MSGTYPE = "std_msgs/msg/Float64MultiArray"
#: rosbags writes bag format 8 or 9; 8 is the oldest it offers (the real logs
#: are format 5). Which ROS 2 releases open format 8 was not checked here.
_BAG_VERSION = 8


#: The ``custom_data`` entry of the metadata of every bag :func:`write_bag`
#: writes: only such a bag is replaced by another write (a real log never).
WRITTEN_BY = ("written_by", "vic_drake")


def _is_bag_folder(path: Path) -> bool:
    files = list(path.iterdir())
    return bool(files) and all(
        f.is_file() and (f.name == "metadata.yaml" or f.suffix == ".db3") for f in files
    )


def _written_here(path: Path) -> bool:
    """The bag folder's metadata carries :data:`WRITTEN_BY`."""
    import yaml

    try:
        meta = yaml.safe_load((path / "metadata.yaml").read_text())
        custom = meta["rosbag2_bagfile_information"].get("custom_data") or {}
    except (OSError, yaml.YAMLError, KeyError, TypeError, AttributeError):
        return False
    key, value = WRITTEN_BY
    return custom.get(key) == value


def check_bag_target(path: str | os.PathLike, *, option: str = "--bag") -> Path:
    """Checks, before any work, that a bag can be written at ``path``.

    Allowed: a path that does not exist yet (its first existing parent must
    be a writable folder), an empty folder, or a bag folder that
    :func:`write_bag` wrote before (metadata.yaml and .db3 files only, with
    :data:`WRITTEN_BY` in its metadata), which it replaces. Any other bag,
    such as a real log, is never replaced.

    Raises:
        VicDrakeError: naming the option, the path and what is wrong.
    """
    path = Path(path).expanduser()
    what = f"{option} {str(path)!r}"
    if path.exists():
        if not path.is_dir():
            raise VicDrakeError(f"{what} is a file; expected a new or bag folder")
        if any(path.iterdir()) and not _is_bag_folder(path):
            raise VicDrakeError(
                f"{what} is a folder holding other files; expected a new folder or a "
                "bag folder (metadata.yaml + .db3) to replace"
            )
        if any(path.iterdir()) and not _written_here(path):
            raise VicDrakeError(
                f"{what} holds a ROS 2 bag that vic-drake did not write (a real "
                "log?); it is never replaced: choose a new folder"
            )
        if not os.access(path, os.W_OK):
            raise VicDrakeError(f"{what} is not writable")
        return path
    parent = path.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise VicDrakeError(
            f"{what} cannot be created: {str(parent)!r} is not writable"
        )
    return path


def _layout_of(rows: pd.DataFrame) -> str:
    for name, columns in LAYOUTS.values():
        if tuple(rows.columns) == tuple(columns):
            return name
    raise VicDrakeError(
        "write_bag takes a DataFrame with the columns of one of the rig's layouts "
        f"{[name for name, _ in LAYOUTS.values()]} (vic_drake.realdata); got "
        f"{len(rows.columns)} columns starting {list(rows.columns)[:3]}"
    )


def write_bag(
    rows: pd.DataFrame, path: str | os.PathLike, *, topic: str | None = None
) -> Path:
    """Writes rows of a rig layout as a ROS 2 bag folder.

    Args:
        rows: DataFrame with exactly the columns of a layout of
            :data:`vic_drake.realdata.LAYOUTS` (e.g. from
            :func:`vic_drake.analysis.rig_layout.controller_log_rows`);
            ``t_s`` >= 0 and non-decreasing, in seconds.
        path: the bag folder to create (an existing bag folder is replaced;
            see :func:`check_bag_target`).
        topic: topic name (default: the rig's, :data:`LAYOUT_TOPICS`).

    Returns:
        The bag folder.

    Raises:
        VicDrakeError: not a layout, no rows, bad times, or a path that cannot
            be written.
    """
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    layout = _layout_of(rows)
    topic = LAYOUT_TOPICS[layout] if topic is None else str(topic)
    if not topic.startswith("/"):
        raise VicDrakeError(f"topic must start with '/'; got {topic!r}")
    data = np.ascontiguousarray(rows.to_numpy(dtype=float))
    if data.shape[0] == 0:
        raise VicDrakeError("write_bag needs at least one row")
    t = data[:, 0]
    if not (np.all(np.isfinite(t)) and t[0] >= 0 and np.all(np.diff(t) >= 0)):
        raise VicDrakeError(
            "rows' t_s must be finite, >= 0 and non-decreasing (seconds); got "
            f"{t[:3].tolist()}..."
        )
    path = check_bag_target(path, option="bag path")
    if path.exists():
        shutil.rmtree(path)
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    msg_cls = typestore.types[_MSGTYPE]
    layout_cls = typestore.types["std_msgs/msg/MultiArrayLayout"]
    empty_layout = layout_cls(dim=[], data_offset=0)
    stamps = np.round(t * 1e9).astype(np.int64)
    try:
        with Writer(path, version=_BAG_VERSION) as writer:
            writer.set_custom_data(*WRITTEN_BY)
            conn = writer.add_connection(topic, _MSGTYPE, typestore=typestore)
            for stamp, row in zip(stamps.tolist(), data, strict=True):
                msg = msg_cls(layout=empty_layout, data=row)
                writer.write(conn, stamp, typestore.serialize_cdr(msg, _MSGTYPE))
    except OSError as exc:
        raise VicDrakeError(f"cannot write bag {str(path)!r}: {exc}") from exc
    return path


__all__ = ["LAYOUT_TOPICS", "WRITTEN_BY", "check_bag_target", "write_bag"]
