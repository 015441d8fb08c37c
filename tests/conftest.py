"""Shared fixtures. Matplotlib draws off-screen in every test."""

import os

os.environ.setdefault("MPLBACKEND", "Agg")

import pytest  # noqa: E402

from vic_drake.paths import has_data, resolve_data_dir  # noqa: E402


@pytest.fixture(scope="session")
def data_dir():
    """The paper's measurements. Skipped where absent, except in CI, where it fails."""
    path = resolve_data_dir()
    if not has_data(path):
        if os.environ.get("CI"):
            pytest.fail(f"CI must have the real data at {path} (or $VIC_DRAKE_DATA)")
        pytest.skip(f"real data not found at {path}")
    return path
