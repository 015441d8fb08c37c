"""Every scenario in diagrams/ loads, builds and simulates briefly."""

from pathlib import Path

import numpy as np
import pytest

from vic_drake.experiments import run_scan
from vic_drake.paths import has_data
from vic_drake.scenario import load_scenario

DIAGRAMS = sorted((Path(__file__).resolve().parents[1] / "diagrams").glob("*.yaml"))
SMOKE_S = 0.1  # Simulated seconds per scenario: the default suite stays fast.


def test_diagrams_folder_has_the_paper_scenarios():
    names = {p.stem for p in DIAGRAMS}
    for c in ("cs", "cf", "vs_cf", "vs_vf"):
        assert f"nominal_{c}_synthetic" in names
    for c in ("vs_vf", "cs", "cf"):
        assert f"disturbance_{c}_synthetic" in names
    for log in (
        "test_compliance_control400",
        "test_compliance_control400_dist",
        "test_force_control",
        "test_force_control_dist",
        "test_tracking5",
        "test_nardi_matForce_lowR",
    ):
        assert f"real_{log}" in names


@pytest.mark.parametrize("path", DIAGRAMS, ids=[p.stem for p in DIAGRAMS])
def test_scenario_loads_builds_and_simulates(path):
    scenario = load_scenario(path)
    assert scenario.name == path.stem
    if scenario.phantom.kind == "measured" and not has_data():
        pytest.skip("measured phantom map not available")
    result = run_scan(scenario, duration_s=SMOKE_S)
    assert len(result.df) >= int(SMOKE_S / scenario.logging.period_s)
    assert np.all(np.isfinite(result.df[["x_m", "y_m", "z_m", "force_sensor_z_N"]]))
