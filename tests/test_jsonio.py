"""JSON text of result dicts: numpy values as plain numbers, non-finite as null."""

import json
from pathlib import Path

import numpy as np

from vic_drake.jsonio import to_json


def test_to_json_converts_numpy_paths_and_non_finite():
    text = to_json(
        {
            "a": np.float64(1.5),
            "b": np.int64(2),
            "c": np.bool_(True),
            "d": np.array([1.0, np.nan]),
            "e": Path("x/y"),
            3: float("inf"),
            "f": (1, 2),
        }
    )
    assert json.loads(text) == {
        "a": 1.5,
        "b": 2,
        "c": True,
        "d": [1.0, None],
        "e": "x/y",
        "3": None,
        "f": [1, 2],
    }
