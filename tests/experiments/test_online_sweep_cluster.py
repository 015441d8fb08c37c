"""The comparison sweep on a Dask cluster: the same scores as in this
process, in the sweep's order; a failed scan named."""

import math

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.online_sweep import online_comparison_sweep
from vic_drake.experiments.online_sweep_scans import ComparisonScan, run_on_cluster
from vic_drake.experiments.scan_diagram import load_scenario_phantom
from vic_drake.paths import scenario_path
from vic_drake.scenario import load_scenario


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(
        a[k] == b[k] or (math.isnan(a[k]) and math.isnan(b[k])) for k in a
    )


def test_a_sweep_on_a_local_cluster_equals_the_one_in_this_process():
    base = load_scenario(scenario_path("nominal_vs_vf_synthetic"))
    phantom = load_scenario_phantom(base)
    kwargs = dict(
        phantom=phantom,
        runs=("online_dither_tracker", "true_map"),
        dither_hzs=(2.9, 3.1),
        duration_s=4.5,
    )
    seen = []
    here = online_comparison_sweep(base, **kwargs)
    there = online_comparison_sweep(
        base, **kwargs, workers=2, on_scan=lambda run, hz: seen.append((run, hz))
    )
    assert sorted(seen, key=str) == sorted(
        [
            ("online_dither_tracker", 2.9),
            ("online_dither_tracker", 3.1),
            ("true_map", None),
        ],
        key=str,
    )
    assert here.keys() == there.keys() and len(there["true_map"]) == 2
    for run in here:
        assert all(_same(a, b) for a, b in zip(here[run], there[run], strict=True))
    # Not all nan: the 4.5 s hold a scan window.
    finite = [
        k for k, v in there["online_dither_tracker"][0].items() if math.isfinite(v)
    ]
    assert "dither_rms_N" in finite


def test_a_failed_scan_is_named_with_its_reason():
    job = ComparisonScan("not: a scenario", None, "true_map", 3.0, 1.0)
    with pytest.raises(VicDrakeError, match=r"the scan true_map at 3 Hz failed: "):
        run_on_cluster([job], 1, None)
