"""diagrams/*.yaml, the source of truth: every file loads, simulates briefly,
round-trips through the dumper, and agrees with the scenario it names as the
code builds it (``vic_drake.experiments.paper_scenarios``)."""

import functools
from pathlib import Path

import numpy as np
import pytest

from vic_drake.experiments import REAL_EXPERIMENTS, run_scan
from vic_drake.experiments.paper_scenarios import paper_scenarios
from vic_drake.paths import has_data
from vic_drake.scenario import (
    differences,
    dumps_scenario,
    load_scenario,
    loads_scenario,
)

DIAGRAMS_DIR = Path(__file__).resolve().parents[2] / "diagrams"
DIAGRAMS = sorted(DIAGRAMS_DIR.glob("*.yaml"))
SMOKE_S = 0.1  # Simulated seconds per scenario: the default suite stays fast.

#: How the files are made from the code.
REGENERATE = (
    'python -c "from vic_drake.experiments import write_paper_scenarios; '
    "write_paper_scenarios('diagrams')\""
)

#: Numbers in a file and in the code agree within this relative tolerance
#: (the real scenarios hold fits to the logs, whose last digits may depend on
#: the linear algebra library).
RTOL = 1e-9


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


def test_every_scenario_of_the_code_has_its_file():
    names = {p.stem for p in DIAGRAMS}
    expected = set(_code_scenarios(None)) | {f"real_{n}" for n in REAL_EXPERIMENTS}
    assert expected <= names, f"missing in diagrams/: {sorted(expected - names)}"
    assert names <= expected, f"no scenario in the code for: {sorted(names - expected)}"


@pytest.mark.parametrize("path", DIAGRAMS, ids=[p.stem for p in DIAGRAMS])
def test_scenario_loads_builds_and_simulates(path):
    scenario = load_scenario(path)
    assert scenario.name == path.stem
    if scenario.phantom.kind == "measured" and not has_data():
        pytest.skip("measured phantom map not available")
    result = run_scan(scenario, duration_s=SMOKE_S)
    assert len(result.df) >= int(SMOKE_S / scenario.logging.period_s)
    assert np.all(np.isfinite(result.df[["x_m", "y_m", "z_m", "force_sensor_z_N"]]))


@pytest.mark.parametrize("path", DIAGRAMS, ids=[p.stem for p in DIAGRAMS])
def test_file_is_what_the_dumper_writes(path):
    scenario = load_scenario(path)
    assert loads_scenario(dumps_scenario(scenario)) == scenario
    assert dumps_scenario(scenario, only_changes=True) == path.read_text(), (
        f"{path.name} is not in the dumper's form; regenerate it: {REGENERATE}"
    )


@functools.cache
def _code_scenarios(data_dir):
    """paper_scenarios() once per session (the real ones only with data)."""
    return paper_scenarios(data_dir=data_dir, include_real=data_dir is not None)


@pytest.mark.parametrize("path", DIAGRAMS, ids=[p.stem for p in DIAGRAMS])
def test_file_agrees_with_the_scenario_it_names(path, request):
    from_file = load_scenario(path)
    name = from_file.name
    data_dir = request.getfixturevalue("data_dir") if name.startswith("real_") else None
    built = _code_scenarios(data_dir)
    assert name in built, f"{path.name} names {name!r}, which the code does not build"
    diff = differences(from_file, built[name], rtol=RTOL)
    assert not diff, (
        f"{path.name} disagrees with paper_scenarios()[{name!r}] "
        "(first: the file, second: the code):\n  "
        + "\n  ".join(diff)
        + f"\nIf the code is right, regenerate the files: {REGENERATE}"
    )
