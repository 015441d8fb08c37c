"""Headless Chromium for the tests that open our HTML pages in a real browser.

The tests skip, with the reason, where Chromium is absent, except under
CI=true, where they fail: .ci/run installs Debian's ``chromium`` package.
"""

import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

#: Flags of every launch: headless, no sandbox (CI runs as root), software
#: rendering, and nothing that reaches the network.
CHROMIUM_FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
)


def chromium() -> str:
    """The Chromium executable; skips the test where there is none (fails in CI)."""
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    if os.environ.get("CI") == "true":
        pytest.fail("CI needs Chromium (.ci/run installs Debian's chromium package)")
    pytest.skip("Chromium is not installed (apt-get install chromium)")


def _run(args: list[str], timeout_s: float) -> subprocess.CompletedProcess:
    exe = chromium()
    with tempfile.TemporaryDirectory(prefix="vic-drake-chromium-") as profile:
        return subprocess.run(
            [exe, *CHROMIUM_FLAGS, f"--user-data-dir={profile}", *args],
            capture_output=True,
            text=True,
            timeout=timeout_s,
            check=False,
        )


def screenshot(
    page: Path,
    png: Path,
    *,
    width: int = 1400,
    height: int = 900,
    wait_ms: int = 8000,
    timeout_s: float = 300.0,
) -> np.ndarray:
    """Opens ``page`` at width x height, waits ``wait_ms`` (real time) and
    saves a screenshot; returns it as an (height, width, 3) uint8 array."""
    from PIL import Image

    proc = _run(
        [
            f"--window-size={width},{height}",
            # Real time, not --virtual-time-budget: the Meshcat page's render
            # loop keeps virtual time from advancing (a 5-minute hang).
            f"--timeout={wait_ms}",
            f"--screenshot={png}",
            Path(page).resolve().as_uri(),
        ],
        timeout_s,
    )
    assert png.is_file(), f"Chromium wrote no screenshot: {proc.stderr[-2000:]}"
    return np.asarray(Image.open(png).convert("RGB"))


def dump_dom(
    page: Path, *, width: int = 1400, height: int = 900, timeout_s: float = 300.0
) -> str:
    """The page's DOM after its scripts ran, at width x height."""
    proc = _run(
        [
            f"--window-size={width},{height}",
            "--virtual-time-budget=2000",
            "--dump-dom",
            Path(page).resolve().as_uri(),
        ],
        timeout_s,
    )
    assert proc.stdout.strip(), f"Chromium dumped no DOM: {proc.stderr[-2000:]}"
    return proc.stdout
