"""``vic-drake fit-palpation`` and ``vic-drake load-test``: JSON contracts and
bad input (exit status 2 with a clear message, never a traceback)."""

import json

import numpy as np
import pytest

from vic_drake.cli import main


def write_bag(path, rows, topic="/data_control"):
    """A ROS 2 bag of Float64MultiArray rows, like the rig's logs."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE)
    msg_t = store.types["std_msgs/msg/Float64MultiArray"]
    layout_t = store.types["std_msgs/msg/MultiArrayLayout"]
    with Writer(path, version=8) as writer:
        conn = writer.add_connection(topic, msg_t.__msgtype__, typestore=store)
        for i, row in enumerate(np.asarray(rows, float)):
            msg = msg_t(layout=layout_t(dim=[], data_offset=0), data=row)
            writer.write(
                conn, 1_000 + i * 2_000_000, store.serialize_cdr(msg, msg_t.__msgtype__)
            )
    return path


def run(capsys, argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


# --- bad input --------------------------------------------------------------------


@pytest.mark.parametrize(
    "argv",
    [
        ["fit-palpation", "{missing}"],
        ["load-test", "{missing}", "--fit-from", "{missing}"],
    ],
)
def test_missing_bag(capsys, tmp_path, argv):
    argv = [a.format(missing=tmp_path / "nope") for a in argv]
    status, out, err = run(capsys, argv)
    assert status == 2
    assert "does not exist" in err and "Traceback" not in err
    assert out == ""


def test_wrong_layout(capsys, data_dir):
    controller_log = data_dir / "experiments" / "test_tracking5"
    status, _, err = run(capsys, ["fit-palpation", controller_log])
    assert status == 2
    assert "31 columns" in err and "'palpation' layout (6 columns)" in err
    status, _, err = run(
        capsys,
        [
            "load-test",
            controller_log,
            "--fit-from",
            data_dir / "palpation" / "test_soft_1hz",
        ],
    )
    assert status == 2 and "31 columns" in err
    status, _, err = run(
        capsys,
        [
            "load-test",
            data_dir / "loadcycle" / "test_soft_1",
            "--fit-from",
            controller_log,
        ],
    )
    assert status == 2 and "31 columns" in err


def test_too_few_in_contact_samples(capsys, tmp_path, data_dir):
    t = 0.002 * np.arange(1000)
    # Probe hovering 1 cm above the surface, sensor reading nothing.
    rows = np.column_stack(
        [
            1.7e9 + t,
            np.full_like(t, -0.05),
            np.full_like(t, -0.04),
            np.full_like(t, -0.04),
            np.zeros_like(t),
            np.zeros_like(t),
        ]
    )
    bag = write_bag(tmp_path / "hover", rows)
    status, _, err = run(capsys, ["fit-palpation", bag])
    assert status == 2 and "in-contact samples" in err
    status, _, err = run(
        capsys,
        ["load-test", bag, "--fit-from", data_dir / "palpation" / "test_soft_1hz"],
    )
    # A constant target is no load cycle: refused before the fit.
    assert status == 2 and "is not a load/unload test" in err
    status, _, err = run(
        capsys, ["load-test", data_dir / "loadcycle" / "test_soft_1", "--fit-from", bag]
    )
    assert status == 2 and "in-contact samples" in err


@pytest.mark.parametrize(
    "betas, message",
    [
        ("abc", "comma-separated numbers"),
        ("1.35,4", "(0, 3]"),
        ("0", "(0, 3]"),
        ("-1", "(0, 3]"),
        ("nan", "(0, 3]"),
        (",", "at least one"),
    ],
)
def test_bad_betas(capsys, tmp_path, betas, message):
    # Options are checked before the bag is read.
    status, out, err = run(
        capsys, ["fit-palpation", tmp_path / "nope", "--betas", betas]
    )
    assert status == 2
    assert message in err
    assert out == ""


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("--beta", "0", "--beta must be in (0, 3]"),
        ("--beta", "3.5", "--beta must be in (0, 3]"),
        ("--max-lag", "-1", "--max-lag"),
        ("--indenter-mass", "-0.1", "--indenter-mass"),
    ],
)
def test_bad_load_test_options(capsys, tmp_path, option, value, message):
    argv = ["load-test", tmp_path / "a", "--fit-from", tmp_path / "b", option, value]
    status, _, err = run(capsys, argv)
    assert status == 2 and message in err


def test_load_test_needs_fit_from(capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        main(["load-test", str(tmp_path)])
    assert exc.value.code == 2
    assert "--fit-from" in capsys.readouterr().err


# --- JSON contracts on the real logs ------------------------------------------


@pytest.mark.realdata
def test_fit_palpation_json(capsys, data_dir):
    bag = data_dir / "palpation" / "test_soft_25hz"
    status, out, err = run(
        capsys, ["fit-palpation", bag, "--betas", "1.1,1.35,1.5,1", "--json"]
    )
    assert status == 0
    result = json.loads(out)  # stdout is the JSON alone; progress went to stderr.
    assert "[vic-drake]" in err
    assert set(result) == {"lag_s", "kelvin_voigt", "hunt_crossley", "best_beta"}
    assert set(result["kelvin_voigt"]) == {"rms_N", "relative", "k", "d"}
    assert list(result["hunt_crossley"]) == ["1.1", "1.35", "1.5", "1.0"]
    for fit in result["hunt_crossley"].values():
        assert set(fit) == {"rms_N", "relative", "kappa", "lambda"}
    assert 0.0 <= result["lag_s"] <= 0.2
    assert 1.0 <= result["best_beta"] <= 2.0
    hc = result["hunt_crossley"]["1.35"]
    assert hc["rms_N"] < result["kelvin_voigt"]["rms_N"]
    assert hc["relative"] == pytest.approx(
        hc["rms_N"] / 5.04, rel=0.1
    )  # RMS force ~5 N.


@pytest.mark.realdata
def test_fit_palpation_human_summary(capsys, data_dir):
    status, out, _ = run(
        capsys,
        ["fit-palpation", data_dir / "palpation" / "test_soft_25hz", "--lag", "0.05"],
    )
    assert status == 0
    assert (
        "Kelvin-Voigt" in out
        and "Hunt-Crossley b=1.35" in out
        and "sensor lag 50.0 ms" in out
    )
    assert "residual vs palpation time" in out and "exp(-T /" in out
    assert "after the approach (3 cycles)" in out


@pytest.mark.realdata
def test_load_test_json(capsys, data_dir, tmp_path):
    plot = tmp_path / "load.png"
    argv = [
        "load-test",
        data_dir / "loadcycle" / "test_soft_2",
        "--fit-from",
        data_dir / "palpation" / "test_soft_1hz",
        "--json",
        "--plot",
        plot,
    ]
    status, out, _ = run(capsys, argv)
    assert status == 0
    result = json.loads(out)
    assert set(result) == {"kelvin_voigt_rms_N", "hunt_crossley_rms_N", "beta"}
    assert result["beta"] == 1.35
    assert result["hunt_crossley_rms_N"] < result["kelvin_voigt_rms_N"]
    assert plot.stat().st_size > 10_000


@pytest.mark.realdata
def test_bag_relative_to_the_data_folder(capsys, data_dir, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("VIC_DRAKE_DATA", str(data_dir))
    argv = ["fit-palpation", "palpation/test_soft_25hz", "--lag", "0.05", "--json"]
    status, out, _ = run(capsys, argv)
    assert status == 0
    assert json.loads(out)["lag_s"] == 0.05


@pytest.mark.realdata
def test_bag_relative_to_the_data_dir_option(capsys, data_dir, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("VIC_DRAKE_DATA", raising=False)
    argv = [
        "load-test",
        "loadcycle/test_soft_2",
        "--fit-from",
        "palpation/test_soft_1hz",
        "--data-dir",
        data_dir,
        "--json",
    ]
    status, out, err = run(capsys, argv)
    assert status == 0, err
    assert json.loads(out)["beta"] == 1.35


@pytest.mark.realdata
def test_load_test_refuses_swapped_logs(capsys, data_dir):
    """A palpation given as the load test (and a load test as --fit-from) is
    told by the logs' targets, before any fit."""
    palpation = data_dir / "palpation" / "test_soft_1hz"
    load = data_dir / "loadcycle" / "test_soft_1"
    status, out, err = run(capsys, ["load-test", palpation, "--fit-from", load])
    assert status == 2 and out == ""
    assert f"load-test bag {str(palpation)!r} is not a load/unload test" in err
    assert "the two look swapped" in err
    status, _, err = run(capsys, ["load-test", load, "--fit-from", load])
    assert status == 2
    assert f"--fit-from {str(load)!r} is a load/unload test, not a palpation" in err


def test_table_i_columns_come_in_the_papers_order():
    """Kelvin-Voigt, then beta 1.5, 1.35, 1.1, as the paper's Table I: in
    fit-palpation's default, the report's table and figure, and the claims."""
    from vic_drake.analysis.claims import ModelResiduals
    from vic_drake.cli import build_parser
    from vic_drake.paper import paper_table_i

    args = build_parser().parse_args(["fit-palpation", "bag"])
    assert args.betas == "1.5,1.35,1.1"
    order = ["kelvin_voigt", "hc_1.5", "hc_1.35", "hc_1.1"]
    assert list(paper_table_i()) == order
    residuals = ModelResiduals(0.066, {1.1: 0.045, 1.35: 0.014, 1.5: 0.029})
    assert list(residuals.as_dict()) == order
