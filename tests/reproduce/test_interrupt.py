"""A Ctrl-C stops the run as interrupted even when a library hands it back
as another error, or swallows it."""

import os
import signal

import pytest

from vic_drake.reproduce import ReproduceOptions, pipeline, reproduce


def _sigint_then(error):
    def stage(ctx):
        try:
            os.kill(os.getpid(), signal.SIGINT)
        except KeyboardInterrupt:
            if error is not None:
                raise error from None  # Wrapped, as a worker pool would.
            return {}  # Swallowed, as a C++ destructor would.
        raise AssertionError("no KeyboardInterrupt")

    return stage


@pytest.mark.parametrize("error", [RuntimeError("worker died"), None])
def test_a_wrapped_or_swallowed_ctrl_c_stops_the_run(tmp_path, monkeypatch, error):
    before = signal.getsignal(signal.SIGINT)  # SIG_IGN under a background shell
    ran = []
    stages = (
        ("offline_real", _sigint_then(error)),
        ("offline_sim", lambda ctx: ran.append("offline_sim")),
    )
    monkeypatch.setattr(pipeline, "STAGES", stages)
    out = tmp_path / "run"
    with pytest.raises(KeyboardInterrupt):
        reproduce(
            ReproduceOptions(
                out_dir=out, quick=True, stages=("offline_real", "offline_sim")
            )
        )
    assert ran == []
    assert not out.exists()
    assert signal.getsignal(signal.SIGINT) is before


def test_a_failing_stage_without_ctrl_c_is_reported_not_raised(tmp_path, monkeypatch):
    def fails(ctx):
        raise RuntimeError("boom")

    monkeypatch.setattr(pipeline, "STAGES", (("offline_real", fails),))
    result = reproduce(
        ReproduceOptions(out_dir=tmp_path / "run", stages=("offline_real",))
    )
    assert [r.ok for r in result.records] == [False]
    assert "boom" in result.records[0].error
