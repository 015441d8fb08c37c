"""JSON text of result dicts: numpy scalars and arrays as plain numbers, NaN as null.

Shared by the command line (``--json``) and the reproduction (claims.json).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, Path):
        return str(value)
    return value


def to_json(result: dict, *, indent: int | None = 2) -> str:
    """JSON text of a result dict (numpy scalars converted, NaN/inf -> null;
    ``indent`` None: one line)."""
    return json.dumps(_jsonable(result), indent=indent, allow_nan=False)


__all__ = ["to_json"]
