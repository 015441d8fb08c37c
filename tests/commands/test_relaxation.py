"""``vic-drake fit-relaxation``: the fit on the paper's palpations, held-out
scores, and bad input."""

import json

import pytest

from vic_drake.cli import main


def run(capsys, argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.realdata
def test_held_out_palpation_is_predicted_better_than_by_plain_hc(capsys, data_dir):
    status, out, err = run(
        capsys,
        [
            "fit-relaxation",
            data_dir / "palpation" / "test_soft_2hz",
            data_dir / "palpation" / "test_soft_25hz",
            "--held-out",
            data_dir / "palpation" / "test_soft_1hz",
            data_dir / "loadcycle" / "test_soft_1",
            "--json",
        ],
    )
    assert status == 0, err
    result = json.loads(out)
    rel = result["relaxation"]
    assert len(rel["fractions"]) == 1
    assert 0.02 < rel["fractions"][0] < 0.3 and 5.0 < rel["time_constants_s"][0] < 60.0
    for scores in (*result["fitted"].values(), *result["held_out"].values()):
        assert scores["rms_N"] < scores["hc_rms_N"]
    held = result["held_out"]
    assert set(held) == {
        str(data_dir / "palpation" / "test_soft_1hz"),
        str(data_dir / "loadcycle" / "test_soft_1"),
    }
    # The load test's lag is not identified: it takes the fitted logs' median.
    fitted_lags = sorted(v["lag_s"] for v in result["fitted"].values())
    assert held[str(data_dir / "loadcycle" / "test_soft_1")]["lag_s"] == pytest.approx(
        sum(fitted_lags) / 2
    )


@pytest.mark.parametrize(
    "argv, words",
    [
        (["--tau0", "0"], "--tau0 values must be > 0"),
        (["--tau0", "5", "--max-tau", "2"], "--max-tau must exceed"),
        (["--lag", "-1"], "--lag must be"),
    ],
)
def test_bad_options(capsys, data_dir, argv, words):
    bag = data_dir / "palpation" / "test_soft_25hz"
    status, out, err = run(capsys, ["fit-relaxation", bag, *argv])
    assert status == 2 and out == "" and words in err and "Traceback" not in err


def test_missing_bag(capsys, tmp_path):
    status, _, err = run(capsys, ["fit-relaxation", tmp_path / "nope"])
    assert status == 2 and "does not exist" in err


def test_every_path_is_checked_before_any_log_is_read(capsys, tmp_path, monkeypatch):
    """A bad --held-out path fails before the fitted logs are read (README:
    paths are checked before any work)."""
    import vic_drake.realdata as realdata

    def no_read(*args, **kwargs):
        raise AssertionError("read a log before checking every path")

    monkeypatch.setattr(realdata, "read_bag", no_read)
    (tmp_path / "bag").mkdir()
    argv = ["fit-relaxation", tmp_path / "bag", "--held-out", tmp_path / "nope"]
    status, _, err = run(capsys, argv)
    assert status == 2
    assert f"held-out bag {str(tmp_path / 'nope')!r} does not exist" in err


@pytest.mark.realdata
def test_load_tests_held_out_by_phase(capsys, data_dir):
    """The palpation fit's law on the load tests, phase by phase (measured):
    the real force during the unloading and the release sits ABOVE the law
    (it falls more slowly than the relaxing law says), plain HC's release
    below; the relaxing law beats plain HC in the hold, unload and release."""
    loads = [data_dir / "loadcycle" / f"test_soft_{k}" for k in (1, 2, 3)]
    status, out, err = run(
        capsys,
        [
            "fit-relaxation",
            *(data_dir / "palpation" / n for n in ("test_soft_1hz", "test_soft_2hz")),
            data_dir / "palpation" / "test_soft_25hz",
            "--held-out",
            *loads,
            "--json",
        ],
    )
    assert status == 0, err
    held = json.loads(out)["held_out"]
    for bag in loads:
        phases = held[str(bag)]["phases"]
        assert list(phases) == ["load", "hold", "unload", "release"]
        for name in ("unload", "release"):
            assert 0.05 < phases[name]["mean_N"] < 0.15
        assert phases["release"]["hc_mean_N"] < -0.1
        for name in ("hold", "unload", "release"):
            assert phases[name]["rms_N"] < phases[name]["hc_rms_N"]


@pytest.mark.realdata
def test_a_fitted_load_test_takes_the_palpations_median_lag(capsys, data_dir):
    """A fitted log whose lag is not identified (estimated at 0) is aligned
    by the median of the identified ones, as a held-out log is."""
    status, out, err = run(
        capsys,
        [
            "fit-relaxation",
            data_dir / "palpation" / "test_soft_1hz",
            data_dir / "palpation" / "test_soft_25hz",
            data_dir / "loadcycle" / "test_soft_1",
            "--json",
        ],
    )
    assert status == 0, err
    fitted = json.loads(out)["fitted"]
    lags = [
        fitted[str(data_dir / "palpation" / n)]["lag_s"]
        for n in ("test_soft_1hz", "test_soft_25hz")
    ]
    assert min(lags) > 0.0
    load_lag = fitted[str(data_dir / "loadcycle" / "test_soft_1")]["lag_s"]
    assert load_lag == pytest.approx(sum(lags) / 2)
