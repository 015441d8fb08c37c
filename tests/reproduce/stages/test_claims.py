"""The claims stage's scan-metrics tables."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from vic_drake.analysis import claims as C
from vic_drake.control.params import real_controller_params
from vic_drake.reproduce.report import table_html
from vic_drake.reproduce.stages.claims import _TABLE_COLUMNS, _metrics_table

_KEYS = [key for key, _, _ in _TABLE_COLUMNS]


def test_the_tank_of_cs_and_cf_shows_as_a_dash_not_as_a_figure():
    """CS and CF log their tank's initial energy (0.5 J, 0 W) though they
    have none: the table shows a dash there, and VS-VF's figures."""
    t = np.arange(0, 10, 0.01)
    df = pd.DataFrame(
        {
            "t_s": t,
            "z_d_m": 0.085,
            "force_sensor_z_N": -7.0,
            "tank_energy_J": 0.5,
            "tank_power_W": 0.0,
        }
    )
    metrics = {
        "disturbance": {
            c: C.scan_metrics(
                df, limits=C.ScanLimits.from_controller(real_controller_params(c))
            )
            for c in ("cs", "cf", "vs-vf")
        }
    }
    ctx = SimpleNamespace(tables=[])
    _metrics_table(ctx, "Simulated scans: metrics", metrics)
    (table,) = ctx.tables
    tank = [2 + _KEYS.index(k) for k in ("tank_min_J", "tank_power_min_W")]
    by_ctrl = {row[1]: [row[i] for i in tank] for row in table.rows}
    assert by_ctrl == {"cs": [None, None], "cf": [None, None], "vs-vf": [0.5, 0.0]}
    assert "n/a" not in table_html(table)  # How a NaN figure shows.


def test_the_penetration_error_reads_in_mm():
    """The table gives the penetration error in mm (its metric is in m: a
    0.69 mm error showed as 6.9e-4)."""
    metrics = {"nominal": {"vs-vf": {"penetration_error_off_ribs_median_m": 6.9e-4}}}
    ctx = SimpleNamespace(tables=[])
    _metrics_table(ctx, "Simulated scans: metrics", metrics)
    (table,) = ctx.tables
    i = table.columns.index("penetration_error_off_ribs_median_mm")
    assert table.rows[0][i] == pytest.approx(0.69)
    assert "penetration_error_off_ribs_median_m" not in table.columns
