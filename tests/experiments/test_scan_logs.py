"""The scan's logged groups: named port elements onto the canonical columns."""

import pytest

from vic_drake.analysis.columns import CANONICAL_COLUMNS
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.scan_logs import LOG_GROUPS, XYZ, LogGroup


def test_log_groups_fill_every_canonical_column_once():
    columns = [column for group in LOG_GROUPS for _, column in group.kept()]
    assert sorted(columns) == sorted(c for c in CANONICAL_COLUMNS if c != "t_s")
    assert len({group.name for group in LOG_GROUPS}) == len(LOG_GROUPS)


def test_kept_elements_follow_the_port_layout():
    group = LogGroup("f", "station", "tissue.force_W", XYZ, {"z": "force_tissue_z_N"})
    assert group.kept() == [(2, "force_tissue_z_N")]
    with pytest.raises(VicDrakeError, match="not elements"):
        LogGroup("f", "station", "tissue.force_W", XYZ, {"w": "w_N"}).kept()
