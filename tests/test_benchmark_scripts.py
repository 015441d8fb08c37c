"""The benchmark scripts that run in seconds still run (they are not timed
here: they print figures; a changed signature must not leave them broken)."""

import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"


@pytest.mark.parametrize(
    "script, args, prints",
    [
        ("bench_fdcc.py", ["--calls", "60"], "per call, us"),
        ("bench_station.py", ["--duration", "0.05"], "RTF"),
    ],
)
def test_a_quick_benchmark_runs_and_prints_its_figures(script, args, prints):
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), *args],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    assert prints in done.stdout
