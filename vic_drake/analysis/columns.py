"""The canonical scan table: its columns, and the real logs converted to it.

Every analysis function takes a DataFrame in this layout (what
:func:`vic_drake.experiments.run_scan` returns). A real bag is converted with
:func:`real_to_canonical`; signals it does not hold become NaN, so real and
simulated scans go through the same functions.

Frames, units and signs (W: the robot base frame, z up; SI units):

- ``x_m``, ``y_m``, ``z_m``: the probe tip (the indenter's lowest point) in
  W; ``x_d_m`` ... ``z_d_m``: the compliance stage's target for it.
- ``force_sensor_{x,y,z}_N``: the sensor's reading in W, minus the external
  force on the probe (the force the probe exerts), so ``force_sensor_z_N``
  is negative when pressing into the body. ``force_ref_z_N`` and
  ``force_min_z_N`` (the reference and its cap F_min) follow the same
  convention: negative = pressing.
- ``force_tissue_z_N``: the simulated tissue's force on the tip along +z,
  >= 0: the force on the patient (NaN in a rig log).
- ``penetration_m``: eps = surface height - tip height, positive in the
  tissue and negative above it; ``surface_z_m``: the surface under the tip.
  In a simulated log both are the phantom's true ones; in a rig log they
  are the controller's (its map's).
- ``stiffness_*``: the compliance stage's stiffness, N/m; ``tank_*``: the
  energy tank (J, W; CS and CF log its initial state).
"""

import numpy as np
import pandas as pd

from vic_drake.errors import VicDrakeError
from vic_drake.paper import CONTACT_THRESHOLD_N

#: The columns of a scan DataFrame. ``qp_ok`` is 0 on a tick whose stiffness
#: QP failed or was skipped; ``qp_fault`` is 1 on a tick the controller
#: skipped because an input (the sensor's reading, mostly) was not finite:
#: a failed solve is ``qp_ok`` 0 with ``qp_fault`` 0.
CANONICAL_COLUMNS = (
    "t_s",
    "x_m",
    "y_m",
    "z_m",
    "x_d_m",
    "y_d_m",
    "z_d_m",
    "force_sensor_x_N",
    "force_sensor_y_N",
    "force_sensor_z_N",
    "force_tissue_z_N",
    "penetration_m",
    "surface_z_m",
    "phantom_lift_m",
    "force_ref_z_N",
    "force_min_z_N",
    "stiffness_x_N_per_m",
    "stiffness_y_N_per_m",
    "stiffness_z_N_per_m",
    "tank_energy_J",
    "tank_power_W",
    "tank_sigma",
    "tank_enabled",
    "qp_ok",
    "qp_fault",
    "in_contact",
    *(f"q_cmd_{i}_rad" for i in range(6)),
)


def check_frame(df, what: str = "a scan log") -> None:
    """Raises VicDrakeError unless ``df`` is a DataFrame, naming what came."""
    if not isinstance(df, pd.DataFrame):
        hint = " (its log is result.df)" if hasattr(df, "df") else ""
        raise VicDrakeError(
            f"expected {what} as a pandas DataFrame; got a {type(df).__name__}{hint}"
        )


def require_columns(df: pd.DataFrame, *columns: str) -> None:
    """Raises VicDrakeError naming the canonical columns df lacks (or that
    ``df`` is no DataFrame: e.g. a ScanResult given for its ``.df``)."""
    check_frame(df)
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise VicDrakeError(
            f"scan DataFrame lacks columns {missing}; expected the canonical layout "
            "(vic_drake.analysis.columns.CANONICAL_COLUMNS)"
        )


def real_to_canonical(df: pd.DataFrame) -> pd.DataFrame:
    """Converts a real bag (``realdata.read_bag``) to the canonical scan layout.

    - 31-column controller logs: every canonical signal the controller logged
      (the sensor's x force negated: see the code);
      ``surface_z_m`` = penetration + z (the map surface under the probe),
      ``tank_power_W`` = dT / dt; ``force_tissue_z_N`` is NaN (not measured).
    - 9-column CS/CF logs: pose, target z (x_d, y_d NaN) and the sensor's z
      force (= minus the logged pressing force).

    Raises:
        VicDrakeError: a layout other than "controller" or "scan".
    """
    layout = df.attrs.get("layout")
    n = len(df)
    out = pd.DataFrame({c: np.full(n, np.nan) for c in CANONICAL_COLUMNS})
    out["t_s"] = df["t_s"].to_numpy()
    if layout == "controller":
        same = {
            "x_m": "x_m", "y_m": "y_m", "z_m": "z_m",
            "x_d_m": "x_d_m", "y_d_m": "y_d_m", "z_d_m": "z_d_m",
            "force_sensor_x_N": "sensor_force_x_N",
            "force_sensor_y_N": "sensor_force_y_N",
            "force_sensor_z_N": "sensor_force_z_N",
            "penetration_m": "penetration_m",
            "force_ref_z_N": "force_ref_z_N",
            "force_min_z_N": "force_min_z_N",
            "stiffness_x_N_per_m": "stiffness_x_N_per_m",
            "stiffness_y_N_per_m": "stiffness_y_N_per_m",
            "stiffness_z_N_per_m": "stiffness_z_N_per_m",
            "tank_energy_J": "tank_energy_J",
        }  # fmt: skip
        for dst, src in same.items():
            out[dst] = df[src].to_numpy()
        # The logged x, y forces are the external force on the probe in the
        # sensor frame S (x_S = x_W, y_S = -y_W with the tool pointing down;
        # estimate_tissue_friction finds the normal tilt and friction
        # consistent in both axes only so); the canonical reading is minus
        # the external force in W, as the simulated sensor's: x flips.
        out["force_sensor_x_N"] = -df["sensor_force_x_N"].to_numpy()
        out["surface_z_m"] = df["penetration_m"].to_numpy() + df["z_m"].to_numpy()
        dt = np.gradient(df["t_s"].to_numpy())
        out["tank_power_W"] = df["tank_delta_J"].to_numpy() / np.where(
            dt > 0, dt, np.nan
        )
        out["in_contact"] = (
            df["sensor_force_z_N"].to_numpy() < -CONTACT_THRESHOLD_N
        ).astype(float)
        out["phantom_lift_m"] = 0.0
    elif layout == "scan":
        for c in ("x_m", "y_m", "z_m"):
            out[c] = df[c].to_numpy()
        out["z_d_m"] = df["z_target_m"].to_numpy()
        out["force_sensor_z_N"] = -df["force_pressing_z_N"].to_numpy()
        out["in_contact"] = (
            df["force_pressing_z_N"].to_numpy() > CONTACT_THRESHOLD_N
        ).astype(float)
    else:
        raise VicDrakeError(
            f"real_to_canonical takes a scan log ('controller' 31-column or 'scan' 9-column "
            f"layout); got layout {layout!r}"
        )
    out.attrs.update(df.attrs)
    out.attrs["source"] = "real"
    return out
