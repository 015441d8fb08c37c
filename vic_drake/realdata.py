"""Readers for the paper's real measurements (ROS 2 bags and the phantom map).

Every log of the real rig is a ROS 2 bag (``metadata.yaml`` + sqlite3
``.db3``) holding ``std_msgs/msg/Float64MultiArray`` messages on one topic (a
bag may carry other topics too, e.g. the raw wrench; they are ignored). Three
row layouts exist, told apart by their width:

- 6 columns: palpation and load-cycle logs (:data:`PALPATION_COLUMNS`),
- 9 columns: the CS/CF scan logs (:data:`SCAN_COLUMNS`),
- 31 columns: the variable-impedance controller's log
  (:data:`CONTROLLER_COLUMNS`).

:func:`read_bag` returns a pandas DataFrame with named, unit-suffixed columns;
``t_s`` is time since the first row and ``df.attrs`` holds ``layout``,
``topic``, ``path`` and ``t0_epoch_s``.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from vic_drake.errors import DataNotFoundError, VicDrakeError

PALPATION_COLUMNS = (
    "t_s",
    "surface_z_m",
    "z_target_m",
    "z_m",
    "vz_m_per_s",
    "force_z_N",  # As the sensor reads it: negative = pressing into the body.
)

SCAN_COLUMNS = (
    "t_s",
    "surface_z_start_m",
    "z_m",
    "z_target_m",
    "vz_m_per_s",
    "force_pressing_z_N",  # Minus the sensor's z force: positive = pressing.
    "palpation_no",
    "x_m",
    "y_m",
)

CONTROLLER_COLUMNS = (
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "x_d_m",
    "y_d_m",
    "z_d_m",
    "force_model_z_N",  # K_z e_z + 2 0.707 sqrt(K_z) de_z.
    "sensor_force_x_N",
    "sensor_force_y_N",
    "sensor_force_z_N",
    "force_ref_z_N",
    "tank_energy_J",  # After this tick's update.
    "tank_delta_J",
    "stiffness_x_N_per_m",
    "stiffness_y_N_per_m",
    "stiffness_z_N_per_m",
    "stiffness_z_max_N_per_m",
    "stiffness_z_min_N_per_m",
    "penetration_m",  # map z + 0.0025 - z.
    "kappa_N_per_m_beta",
    "lambda_N_s_per_m_beta1",
    "force_min_z_N",
    "force_hc_N",
    "eps_max_m",
    "tank_min_J",
    "power_limit_W",
    "vx_m_per_s",
    "vy_m_per_s",
    "vz_m_per_s",
    "surface_velocity_m_per_s",
)

LAYOUTS = {
    len(PALPATION_COLUMNS): ("palpation", PALPATION_COLUMNS),
    len(SCAN_COLUMNS): ("scan", SCAN_COLUMNS),
    len(CONTROLLER_COLUMNS): ("controller", CONTROLLER_COLUMNS),
}

_MSGTYPE = "std_msgs/msg/Float64MultiArray"


def _bag_error(path: Path, what: str) -> VicDrakeError:
    return VicDrakeError(
        f"bag {str(path)!r}: {what}; expected a ROS 2 bag folder (metadata.yaml + "
        f".db3) with {_MSGTYPE} rows of {sorted(LAYOUTS)} columns"
    )


def read_bag_array(path: str | os.PathLike) -> tuple[np.ndarray, str]:
    """Reads a bag's Float64MultiArray rows.

    Returns:
        (rows, topic): an (n, m) float array and the topic it came from.

    Raises:
        DataNotFoundError: the folder does not exist.
        VicDrakeError: not a readable bag, no Float64MultiArray topic, no
            messages, or rows of unequal width.
    """
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    path = Path(path)
    if not path.exists():
        raise DataNotFoundError(
            f"bag {str(path)!r} does not exist; expected a ROS 2 bag folder "
            "(metadata.yaml + .db3)"
        )
    given = path
    if path.is_file():
        path = path.parent
    if not (path / "metadata.yaml").is_file():
        where = "in the folder" if given == path else f"beside the file {given.name!r}"
        raise _bag_error(path, f"no metadata.yaml {where}")
    typestore = get_typestore(Stores.ROS2_HUMBLE)
    try:
        with AnyReader([path], default_typestore=typestore) as reader:
            connections = [c for c in reader.connections if c.msgtype == _MSGTYPE]
            if not connections:
                found = sorted({c.msgtype for c in reader.connections})
                raise _bag_error(path, f"no {_MSGTYPE} topic (found {found})")
            topics = sorted({c.topic for c in connections})
            if len(topics) > 1:
                raise _bag_error(path, f"several {_MSGTYPE} topics {topics}")
            rows = []
            for connection, _, raw in reader.messages(connections=connections):
                msg = reader.deserialize(raw, connection.msgtype)
                rows.append(np.asarray(msg.data, dtype=float))
    except VicDrakeError:
        raise
    except Exception as exc:  # rosbags raises many types for corrupt files.
        raise _bag_error(path, f"cannot be read ({type(exc).__name__}: {exc})") from exc
    if not rows:
        raise _bag_error(path, "no messages")
    widths = {len(r) for r in rows}
    if len(widths) != 1:
        raise _bag_error(path, f"rows of unequal widths {sorted(widths)}")
    return np.vstack(rows), topics[0]


def read_bag(path: str | os.PathLike, *, expect: str | None = None) -> pd.DataFrame:
    """Reads a real-rig bag into a DataFrame with named, unit-suffixed columns.

    Args:
        path: the bag folder (or its .db3 file).
        expect: optional layout the caller needs ("palpation", "scan" or
            "controller"); another layout raises VicDrakeError.

    Returns:
        DataFrame; ``t_s`` starts at 0. ``attrs``: layout, topic, path,
        t0_epoch_s.
    """
    rows, topic = read_bag_array(path)
    width = rows.shape[1]
    if width not in LAYOUTS:
        raise _bag_error(Path(path), f"unknown layout of {width} columns")
    layout, columns = LAYOUTS[width]
    if expect is not None and layout != expect:
        allowed = {name: len(cols) for name, cols in LAYOUTS.values()}
        raise VicDrakeError(
            f"bag {str(path)!r} holds the {layout!r} layout ({width} columns); this "
            f"needs the {expect!r} layout ({allowed[expect]} columns)"
        )
    df = pd.DataFrame(rows, columns=list(columns))
    t0 = float(df["t_s"].iloc[0])
    df["t_s"] = df["t_s"] - t0
    df.attrs.update(layout=layout, topic=topic, path=str(path), t0_epoch_s=t0)
    return df


#: How far the real phantom's surface lay above the published map's tissue
#: surface (z + PhantomMapData.surface_offset_m) in the scans, m: the rig's
#: default for a log that holds no evidence of its own. The mean first-contact
#: offset of the two 31-column logs
#: (vic_drake.experiments.surface_calibration.rig_surface_offset).
RIG_SURFACE_OFFSET_M = 0.00375


@dataclass(frozen=True)
class PhantomMapData:
    """The measured GP map as the real controller loaded it.

    Attributes:
        x_m: (nx,) grid axis, increasing.
        y_m: (ny,) grid axis, increasing.
        z_m: (nx, ny) surface height from GRIDFIT (the real controller took
            the tissue surface as z + 0.0025 m; see surface_offset_m).
        kappa: (nx, ny) Hunt-Crossley elasticity, N/m^beta.
        lam: (nx, ny) Hunt-Crossley viscosity, N s/m^(beta+1).
        beta: the exponent the map was fitted with.
    """

    x_m: np.ndarray
    y_m: np.ndarray
    z_m: np.ndarray
    kappa: np.ndarray
    lam: np.ndarray
    beta: float = 1.35
    surface_offset_m: float = 0.0025


def read_phantom_map(map_dir: str | os.PathLike) -> PhantomMapData:
    """Reads ``phantom_map/`` (x.txt, y.txt, z.txt, stiffness.txt, damping.txt).

    Values are row-major ``[ix][iy]``. Raises VicDrakeError naming the file
    on a missing file, a wrong count or non-finite values.
    """
    map_dir = Path(map_dir)
    if not map_dir.is_dir():
        raise DataNotFoundError(
            f"phantom map folder {str(map_dir)!r} does not exist; expected "
            "x.txt, y.txt, z.txt, stiffness.txt, damping.txt"
        )

    def load(name: str) -> np.ndarray:
        file = map_dir / name
        if not file.is_file():
            raise DataNotFoundError(f"phantom map file {str(file)!r} is missing")
        try:
            values = np.loadtxt(file, dtype=float, ndmin=1)
        except ValueError as exc:
            raise VicDrakeError(f"phantom map file {str(file)!r}: {exc}") from exc
        if not np.all(np.isfinite(values)):
            raise VicDrakeError(f"phantom map file {str(file)!r} has non-finite values")
        return values

    x, y = load("x.txt"), load("y.txt")
    if np.any(np.diff(x) <= 0) or np.any(np.diff(y) <= 0):
        raise VicDrakeError(
            f"phantom map {str(map_dir)!r}: x.txt and y.txt must increase"
        )
    fields = {}
    for key, name in (
        ("z_m", "z.txt"),
        ("kappa", "stiffness.txt"),
        ("lam", "damping.txt"),
    ):
        values = load(name)
        if values.size != x.size * y.size:
            raise VicDrakeError(
                f"phantom map file {str(map_dir / name)!r} has {values.size} values; "
                f"expected len(x) * len(y) = {x.size} * {y.size} = {x.size * y.size}"
            )
        fields[key] = values.reshape(x.size, y.size)
    return PhantomMapData(x_m=x, y_m=y, **fields)
