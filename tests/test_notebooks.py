"""The worked-example notebooks run top to bottom in their short mode.

Marked ``notebook``; each runs in a fresh kernel with VIC_DRAKE_SHORT=1
(a few seconds of simulated time per scan). Also checks that the committed
notebooks are what notebooks/make_notebooks.py generates.
"""

import os
import sys
from pathlib import Path

import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NAMES = sorted(p.name for p in NOTEBOOK_DIR.glob("*.ipynb"))


def test_notebooks_are_generated(tmp_path):
    import subprocess

    import nbformat

    subprocess.run(
        [
            sys.executable,
            str(NOTEBOOK_DIR / "make_notebooks.py"),
            "--out",
            str(tmp_path),
        ],
        check=True,
        capture_output=True,
    )
    assert sorted(p.name for p in tmp_path.glob("*.ipynb")) == NAMES
    for name in NAMES:
        fresh = nbformat.read(tmp_path / name, as_version=4)
        stored = nbformat.read(NOTEBOOK_DIR / name, as_version=4)
        assert [c.source for c in stored.cells] == [c.source for c in fresh.cells], (
            f"{name} differs from what notebooks/make_notebooks.py writes; rerun it"
        )


@pytest.mark.notebook
@pytest.mark.parametrize("name", NAMES)
def test_notebook_runs_short(name, monkeypatch):
    import nbformat
    from nbclient import NotebookClient

    monkeypatch.setenv("VIC_DRAKE_SHORT", "1")
    monkeypatch.setenv("MPLBACKEND", "Agg")
    nb = nbformat.read(NOTEBOOK_DIR / name, as_version=4)
    client = NotebookClient(
        nb,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    client.execute()
    errors = [
        o
        for c in nb.cells
        if c.cell_type == "code"
        for o in c.get("outputs", [])
        if o.get("output_type") == "error"
    ]
    assert not errors
    assert os.environ["VIC_DRAKE_SHORT"] == "1"
