import shutil

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.realdata import read_bag


@pytest.mark.parametrize(
    "bag, layout, width",
    [
        ("palpation/test_soft_1hz", "palpation", 6),
        ("palpation/test_soft_25hz", "palpation", 6),  # also carries a wrench topic
        ("experiments/test_force_control", "scan", 9),
        ("experiments/test_tracking5", "controller", 31),
    ],
)
def test_layouts(data_dir, bag, layout, width):
    df = read_bag(data_dir / bag)
    assert df.attrs["layout"] == layout
    assert df.shape[1] == width
    assert df["t_s"].iloc[0] == 0.0
    assert 0.0019 < df["t_s"].diff().median() < 0.0021  # 500 Hz


def test_missing_bag(tmp_path):
    with pytest.raises(VicDrakeError, match="does not exist"):
        read_bag(tmp_path / "nope")


def test_folder_without_metadata(tmp_path):
    with pytest.raises(VicDrakeError, match="no metadata.yaml"):
        read_bag(tmp_path)


def test_file_outside_a_bag_is_named(tmp_path):
    stray = tmp_path / "notes.txt"
    stray.write_text("not a bag")
    with pytest.raises(
        VicDrakeError, match="no metadata.yaml beside the file 'notes.txt'"
    ):
        read_bag(stray)


def test_corrupt_bag(tmp_path, data_dir):
    bag = tmp_path / "bad"
    shutil.copytree(data_dir / "palpation" / "test_soft_2hz", bag)
    db = next(bag.glob("*.db3"))
    db.write_bytes(b"not a sqlite database" * 10)
    with pytest.raises(VicDrakeError, match="cannot be read"):
        read_bag(bag)


def test_expected_layout(data_dir):
    with pytest.raises(VicDrakeError, match="needs the 'palpation' layout"):
        read_bag(data_dir / "experiments" / "test_tracking5", expect="palpation")
