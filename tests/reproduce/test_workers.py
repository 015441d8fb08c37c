"""Ctrl-C stops a reproduce run and its Dask workers within 2 s, and the
interrupted run is marked incomplete."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

#: The issue's limit: from SIGINT to the whole process tree gone, s.
STOP_LIMIT_S = 2.0


def _children(pid: int) -> list[int]:
    kids = []
    try:
        for task in Path(f"/proc/{pid}/task").iterdir():
            text = (task / "children").read_text().split()
            kids.extend(int(k) for k in text)
    except FileNotFoundError:  # It has just ended.
        pass
    return kids


def _descendants(pid: int) -> list[int]:
    """Every process below pid: the cluster's nannies and their workers."""
    found, todo = [], [pid]
    while todo:
        kids = _children(todo.pop())
        found += kids
        todo += kids
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0]
    except FileNotFoundError:
        return False
    return state != "Z"


def test_sigint_stops_the_scan_workers_within_2_s(tmp_path):
    out = tmp_path / "run"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "vic_drake.cli",
            "reproduce",
            "--quick",
            "--phantom",
            "synthetic",
            "--stages",
            "scans",
            "--out",
            str(out),
        ],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    )
    try:
        for line in proc.stderr:
            if "local Dask worker" in line:
                break
        else:
            raise AssertionError("the scans stage never started")
        # Let the workers spawn and start their scans.
        deadline = time.monotonic() + 60
        while len(_descendants(proc.pid)) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
        time.sleep(4.0)
        workers = _descendants(proc.pid)
        assert len(workers) >= 2, f"no worker process started: {workers}"
        t0 = time.monotonic()
        proc.send_signal(signal.SIGINT)
        rest = proc.communicate(timeout=30)[1]
        rc = proc.returncode
        stopped = time.monotonic() - t0
        while any(_alive(w) for w in workers) and time.monotonic() - t0 < 30:
            time.sleep(0.05)
        all_gone = time.monotonic() - t0
    finally:
        if proc.poll() is None:
            proc.kill()
    assert rc == 130, f"exit {rc}; the run's last words:\n{rest[-3000:]}"
    assert stopped <= STOP_LIMIT_S, f"main process took {stopped:.2f} s"
    assert all_gone <= STOP_LIMIT_S, f"workers took {all_gone:.2f} s"
    # Nothing at --out; the partial run is marked incomplete beside it.
    assert not out.exists()
    marker = json.loads((tmp_path / ".run.partial" / "run.json").read_text())
    assert marker["complete"] is False
