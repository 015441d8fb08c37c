"""The report stage: notes that match the run, versions from the metadata."""

from vic_drake.reproduce import ReproduceOptions, RunContext, StageRecord
from vic_drake.reproduce.stages.report import package_versions, report_notes


def _ctx(tmp_path, monkeypatch, stages):
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    monkeypatch.setattr("vic_drake.paths.DEFAULT_DATA_DIR", tmp_path / "no_data")
    ctx = RunContext(ReproduceOptions(out_dir=tmp_path / "out", quick=False))
    ctx.records = [StageRecord(s, True, 1.0) for s in stages]
    return ctx


def test_notes_of_a_run_without_real_data(tmp_path, monkeypatch):
    ctx = _ctx(tmp_path, monkeypatch, ["offline_sim", "map", "scans"])
    claims = {
        "C2": {
            "sim": {"sim_2.5hz": {"ratio_last_first": 0.97}},
            "pass_sim": False,
        }
    }
    text = " ".join(report_notes(ctx, claims))
    assert "This run has no real data" in text
    for stale in (
        "real logs test that",
        "paper's scan logs",
        "5 cm",
    ):
        assert stale not in text, stale
    assert "fails on this run's relaxing tissue: ratio 0.97" in text
    # The plain-HC control run is reported when the stage made one.
    assert "Control run" not in text
    ctx.results["offline_sim"] = {
        "truth": {"relaxation": {"fractions": [0.08], "time_constants_s": [22.9]}},
        "control_hc": {
            "c2": {"sim_2.5hz": {"ratio_last_first": 0.97}},
            "c2_pass": False,
        },
    }
    text = " ".join(report_notes(ctx, claims))
    assert "g = 0.080, tau = 22.9 s" in text
    assert "Control run" in text and "C2 fails" in text and "0.97" in text


def test_notes_name_the_real_log_that_misses_c2(tmp_path, monkeypatch):
    ctx = _ctx(tmp_path, monkeypatch, ["offline_sim", "offline_real"])
    good = {"r2": 0.97, "spearman": -1.0, "a": 0.1, "ratio_last_first": 0.13}
    bad = {"r2": 0.26, "spearman": -0.81, "a": 0.02, "ratio_last_first": 0.26}
    claims = {
        "C2": {
            "real": {
                "test_soft_1hz": {**good, "pass": True},
                "test_soft_25hz": {**bad, "pass": False},
            },
            "pass_real": False,
        }
    }
    text = " ".join(report_notes(ctx, claims))
    assert "test_soft_25hz misses R^2 0.26 (needs >= 0.9)" in text
    assert "test_soft_1hz misses" not in text and "Spearman" not in text


def test_notes_with_real_logs_and_a_passing_c2(tmp_path, monkeypatch):
    ctx = _ctx(tmp_path, monkeypatch, ["offline_sim", "offline_real", "real_scans"])
    claims = {"C2": {"sim": {"ratio_last_first": 0.3}, "pass_sim": True}}
    text = " ".join(report_notes(ctx, claims))
    assert "the real logs test it" in text
    assert "fails on this run's" not in text and "C4-C7" not in text


def test_versions_from_installed_metadata():
    v = package_versions()
    assert v["drake"][0].isdigit() and v["numpy"][0].isdigit()
    assert "unknown" not in v.values()
