"""The reproduce scans on Dask: on an existing cluster whose workers have no
data folder, the logs equal a scan in this process; a scheduler that does
not answer is named before any work."""

import logging

import pandas as pd
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.reproduce import ReproduceOptions, reproduce


@pytest.fixture
def scheduler(tmp_path):
    """The address of a local cluster of 2 workers that see no paper data
    (VIC_DRAKE_DATA names an empty folder)."""
    from distributed import LocalCluster

    empty = tmp_path / "no_data"
    empty.mkdir()
    cluster = LocalCluster(
        n_workers=2,
        threads_per_worker=1,
        processes=True,
        dashboard_address=":0",
        silence_logs=logging.CRITICAL,
        env={"VIC_DRAKE_DATA": str(empty)},
    )
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()


def _scans_on(scheduler, out, phantom, data_dir=None):
    return reproduce(
        ReproduceOptions(
            out_dir=out,
            quick=True,
            phantom=phantom,
            stages=("scans",),
            scheduler=scheduler,
            data_dir=data_dir,
        )
    )


def _check_against_this_process(result, name, data_dir=None):
    from vic_drake.experiments import run_scan

    scenario = result.results["scans"]["scenarios"][("disturbance", "vs-vf")]
    assert scenario.name == name
    here = run_scan(scenario, data_dir=data_dir).df
    logged = pd.read_parquet(result.out_dir / "logs" / f"{name}.parquet")
    pd.testing.assert_frame_equal(logged, here)


def test_scans_on_an_existing_cluster_equal_this_process(tmp_path, scheduler):
    result = _scans_on(scheduler, tmp_path / "out", "synthetic")
    assert [r.ok for r in result.records] == [True]
    logs = sorted((tmp_path / "out" / "logs").glob("*.parquet"))
    assert len(logs) == 7
    _check_against_this_process(result, "disturbance_vs_vf_synthetic")


@pytest.mark.realdata
def test_measured_scans_need_no_data_on_the_workers(tmp_path, scheduler, data_dir):
    result = _scans_on(scheduler, tmp_path / "out", "measured", data_dir)
    assert [r.ok for r in result.records] == [True]
    _check_against_this_process(result, "disturbance_vs_vf_measured", data_dir)


def test_an_unreachable_scheduler_is_named_before_any_work(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(VicDrakeError, match="cannot reach the Dask scheduler"):
        _scans_on("tcp://127.0.0.1:9", out, "synthetic")
    assert list(tmp_path.iterdir()) == []  # No run folder, not even a partial one.
