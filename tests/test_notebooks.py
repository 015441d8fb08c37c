"""The worked-example notebooks run top to bottom in their short mode.

Marked ``notebook``; each runs in a fresh kernel with VIC_DRAKE_SHORT=1
(a few seconds of simulated time per scan). Also checks that the committed
notebooks are what notebooks/make_notebooks.py generates.
"""

import sys
from pathlib import Path

import pytest

NOTEBOOK_DIR = Path(__file__).resolve().parents[1] / "notebooks"
NAMES = sorted(p.name for p in NOTEBOOK_DIR.glob("*.ipynb"))


def test_notebooks_are_generated(tmp_path):
    import subprocess

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
        # Byte for byte: the generator is deterministic (cell ids included).
        fresh = (tmp_path / name).read_text()
        assert (NOTEBOOK_DIR / name).read_text() == fresh, (
            f"{name} differs from what notebooks/make_notebooks.py writes; rerun it"
        )


#: Figures each notebook shows in its short mode (the real-vs-sim notebook
#: draws its figure only with the paper's data).
MIN_IMAGES = {
    "01_tissue_estimation.ipynb": 2,
    "02_scan_controllers.ipynb": 1,
    "03_disturbance.ipynb": 2,
    "04_real_vs_sim.ipynb": 1,
    "05_online_estimation.ipynb": 2,
}


@pytest.mark.notebook
@pytest.mark.parametrize("name", NAMES)
def test_notebook_runs_short_and_shows_its_figures(name, monkeypatch):
    import nbformat
    from nbclient import NotebookClient

    from vic_drake.paths import has_data

    monkeypatch.setenv("VIC_DRAKE_SHORT", "1")
    # The kernel's own backend, as in Jupyter (the suite's Agg would hide
    # figures that only the inline backend shows).
    monkeypatch.delenv("MPLBACKEND", raising=False)
    nb = nbformat.read(NOTEBOOK_DIR / name, as_version=4)
    client = NotebookClient(
        nb,
        timeout=300,
        kernel_name="python3",
        resources={"metadata": {"path": str(NOTEBOOK_DIR)}},
    )
    client.execute()
    outputs = [
        o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
    ]
    errors = [o for o in outputs if o.get("output_type") == "error"]
    assert not errors
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    # No figure shown as its text repr ("<Figure size ... with N Axes>") alone.
    text_only = [
        o
        for o in outputs
        if "<Figure size" in str(o.get("data", {}).get("text/plain", ""))
        and "image/png" not in o.get("data", {})
    ]
    assert not text_only, text_only
    if name == "04_real_vs_sim.ipynb" and not has_data():
        printed = "".join(o.get("text", "") for o in outputs)
        assert "no real data" in printed
        return
    assert len(images) >= MIN_IMAGES[name], f"{name}: {len(images)} image outputs"
