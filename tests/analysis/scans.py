"""Synthetic scans in the canonical layout, shared by the analysis tests."""

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import CANONICAL_COLUMNS

#: Target height of the synthetic scans, m (the real scans': 0.085 m).
Z_SCAN_M = 0.085


def make_scan(t, force_pressing, **columns) -> pd.DataFrame:
    """A canonical scan with the target held at Z_SCAN_M throughout."""
    df = pd.DataFrame({c: np.full(len(t), np.nan) for c in CANONICAL_COLUMNS})
    df["t_s"] = t
    df["z_d_m"] = Z_SCAN_M
    df["force_sensor_z_N"] = -np.asarray(force_pressing, float)
    for key, value in columns.items():
        df[key] = value
    return df
