"""Writing the rig's ROS 2 bags: what is written reads back as it was, bad input."""

import numpy as np
import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.realdata import CONTROLLER_COLUMNS, SCAN_COLUMNS, read_bag
from vic_drake.realdata_write import LAYOUT_TOPICS, check_bag_target, write_bag


def _rows(columns, n=50, seed=0):
    rng = np.random.default_rng(seed)
    data = rng.normal(size=(n, len(columns)))
    data[:, 0] = 3.0 + 0.002 * np.arange(n)
    return pd.DataFrame(data, columns=list(columns))


@pytest.mark.parametrize(
    "columns, layout", [(CONTROLLER_COLUMNS, "controller"), (SCAN_COLUMNS, "scan")]
)
def test_rows_read_back_bit_for_bit_on_the_rigs_topic(tmp_path, columns, layout):
    rows = _rows(columns)
    rows.iloc[4, 5] = np.nan  # The rig logs NaN (e.g. HC force out of the tissue).
    path = write_bag(rows, tmp_path / "bag")
    back = read_bag(path, expect=layout)
    assert back.attrs["topic"] == LAYOUT_TOPICS[layout]
    assert back.attrs["t0_epoch_s"] == rows["t_s"].iloc[0]
    expected = rows.copy()
    expected["t_s"] -= rows["t_s"].iloc[0]
    np.testing.assert_array_equal(back.to_numpy(), expected.to_numpy())


def test_an_existing_bag_is_replaced(tmp_path):
    write_bag(_rows(SCAN_COLUMNS, n=20), tmp_path / "bag")
    write_bag(_rows(SCAN_COLUMNS, n=7, seed=1), tmp_path / "bag")
    assert len(read_bag(tmp_path / "bag")) == 7


def test_a_bag_it_did_not_write_is_never_replaced(tmp_path, data_dir):
    """A real log (its metadata without vic_drake's mark) is refused, before
    anything is deleted, by the writer and by the commands' early check."""
    import shutil

    real = tmp_path / "real"
    shutil.copytree(data_dir / "experiments" / "test_tracking5", real)
    before = sorted((p.name, p.stat().st_size) for p in real.iterdir())
    for attempt in (
        lambda: write_bag(_rows(CONTROLLER_COLUMNS), real),
        lambda: check_bag_target(real),
    ):
        with pytest.raises(VicDrakeError, match="vic-drake did not write"):
            attempt()
    assert sorted((p.name, p.stat().st_size) for p in real.iterdir()) == before


def test_a_bag_without_the_mark_is_never_replaced(tmp_path):
    # The real data's logs are checked above where they are present; here a
    # bag written by another tool: the same bag without vic_drake's mark.
    bag = write_bag(_rows(SCAN_COLUMNS, n=20), tmp_path / "bag")
    meta = bag / "metadata.yaml"
    text = meta.read_text()
    assert "written_by: vic_drake" in text
    meta.write_text(text.replace("written_by: vic_drake", "written_by: ros2"))
    with pytest.raises(VicDrakeError, match="vic-drake did not write"):
        write_bag(_rows(SCAN_COLUMNS, n=7), bag)
    assert len(read_bag(bag)) == 20


def test_bad_rows_and_paths_are_clear_errors(tmp_path):
    with pytest.raises(VicDrakeError, match="layouts"):
        write_bag(pd.DataFrame({"t_s": [0.0], "a": [1.0]}), tmp_path / "x")
    rows = _rows(SCAN_COLUMNS, n=3)
    rows.loc[2, "t_s"] = 0.0
    with pytest.raises(VicDrakeError, match="non-decreasing"):
        write_bag(rows, tmp_path / "x")
    with pytest.raises(VicDrakeError, match="at least one row"):
        write_bag(_rows(SCAN_COLUMNS).iloc[:0], tmp_path / "x")
    (tmp_path / "file").write_text("x")
    with pytest.raises(VicDrakeError, match="--bag .* is a file"):
        check_bag_target(tmp_path / "file")
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("x")
    with pytest.raises(VicDrakeError, match="other files"):
        write_bag(_rows(SCAN_COLUMNS), tmp_path / "other")
    assert (tmp_path / "other" / "notes.txt").is_file()  # Never deleted.
    with pytest.raises(VicDrakeError, match="cannot be created"):
        check_bag_target(tmp_path / "file" / "sub")
