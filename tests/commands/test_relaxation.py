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
