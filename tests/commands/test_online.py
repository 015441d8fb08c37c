"""``vic-drake estimate-online``: the JSON contract on the real logs, and bad input."""

import json

import pytest

from vic_drake.cli import main

KEYS = {
    "method",
    "samples",
    "kappa_rel_err_median",
    "kappa_corr",
    "lambda_rel_err_median",
    "convergence_s",
    "tick_us_p99",
}


def run(capsys, argv):
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize("method", ["rls", "ekf"])
def test_palpation_json_contract(capsys, data_dir, method):
    bag = data_dir / "palpation" / "test_soft_25hz"
    status, out, err = run(
        capsys, ["estimate-online", bag, "--method", method, "--json"]
    )
    assert status == 0, err
    result = json.loads(out)
    assert set(result) == KEYS and result["method"] == method
    assert result["kappa_corr"] is None  # one reference value: no correlation
    # The issue's targets on a palpation: within 10 % in <= 2 s, and close.
    assert result["kappa_rel_err_median"] < 0.05
    assert result["convergence_s"] is not None and result["convergence_s"] <= 2.0


def test_scan_log_is_compared_with_the_map(capsys, data_dir):
    bag = data_dir / "experiments" / "test_nardi_matForce_lowR"
    status, out, err = run(
        capsys, ["estimate-online", bag, "--method", "ekf", "--json"]
    )
    assert status == 0, err
    result = json.loads(out)
    assert set(result) == KEYS and result["samples"] > 10000
    assert result["kappa_corr"] is not None


def test_scan_log_kappa_within_the_issue_target(capsys, data_dir):
    # The issue's median-error target on a VS scan, with the surface the
    # controller acted on (the map's 1.5 mm offset to the logged z would
    # make it ~57 %).
    bag = data_dir / "experiments" / "test_tracking5"
    status, out, err = run(
        capsys, ["estimate-online", bag, "--method", "ekf", "--json"]
    )
    assert status == 0, err
    result = json.loads(out)
    assert result["kappa_rel_err_median"] <= 0.20
    assert result["kappa_corr"] > 0.5


def test_default_method_on_a_vs_vf_scan_within_the_issue_target(capsys, data_dir):
    # The default (RLS) on the VS-VF scan: its covariance shrinks to what a
    # static tissue allows, so along the path every innovation was clipped
    # for seconds at a time and the median error was 29 %; the covariance
    # reset after 50 ms of clipped updates brings it to 14 %.
    bag = data_dir / "experiments" / "test_nardi_matForce_lowR"
    status, out, err = run(capsys, ["estimate-online", bag, "--json"])
    assert status == 0, err
    result = json.loads(out)
    assert result["method"] == "rls"
    assert result["kappa_rel_err_median"] <= 0.20


def test_wrong_layout_and_missing_bag(capsys, data_dir, tmp_path):
    status, out, err = run(
        capsys, ["estimate-online", data_dir / "experiments" / "test_force_control"]
    )
    assert status == 2 and out == ""
    assert "'scan' layout (9 columns)" in err and "31 columns" in err
    status, _, err = run(capsys, ["estimate-online", tmp_path / "nope"])
    assert status == 2 and "does not exist" in err and "Traceback" not in err


@pytest.mark.parametrize(
    "argv", [["--lag", "-1"], ["--beta", "0"], ["--method", "ukf"]]
)
def test_bad_options(capsys, data_dir, argv):
    bag = data_dir / "palpation" / "test_soft_25hz"
    with pytest.raises(SystemExit) if argv[0] == "--method" else _no_raise():
        status, _, err = run(capsys, ["estimate-online", bag, *argv])
        assert status == 2 and argv[0] in err


class _no_raise:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def test_an_unreached_convergence_is_said_in_words():
    from vic_drake.commands.online import _convergence_line

    for value in (float("nan"), None):
        line = _convergence_line(value)
        assert "n/a" not in line and "not reached" in line
    assert _convergence_line(1.234).endswith("1.23 s after first contact")


@pytest.fixture(scope="module")
def simulated_vs_bags(tmp_path_factory):
    """The quick reproduce's nominal VS-VF and VS-CF scans on the synthetic
    chest (8.5 s, 5 cm over the ribs), written as the rig's bags."""
    from vic_drake.experiments import run_scan
    from vic_drake.experiments.rig_log import write_scan_bag
    from vic_drake.reproduce.stages.scans import scan_scenario

    folder = tmp_path_factory.mktemp("bags")
    bags = {}
    for controller in ("vs-vf", "vs-cf"):
        scenario = scan_scenario(
            controller, disturbed=False, phantom_kind="synthetic", quick=True
        )
        bags[controller] = write_scan_bag(run_scan(scenario), folder / controller)
    return bags


@pytest.mark.parametrize("controller", ["vs-vf", "vs-cf"])
@pytest.mark.parametrize("method", ["rls", "ekf"])
def test_a_simulated_scan_on_its_own_map_meets_the_scan_targets(
    capsys, simulated_vs_bags, controller, method
):
    """Where the tissue is the map the controller read, the replay meets the
    issue's scan targets (median error <= 20 %, correlation >= 0.8): what
    the real logs miss is in their data (docs/decisions.md, "Online replay
    on scan logs: the controller's own surface"). No real data needed."""
    bag = simulated_vs_bags[controller]
    status, out, err = run(
        capsys, ["estimate-online", bag, "--method", method, "--json"]
    )
    assert status == 0, err
    result = json.loads(out)
    assert set(result) == KEYS and result["method"] == method
    assert result["samples"] > 4000
    assert result["kappa_rel_err_median"] <= 0.20
    assert result["kappa_corr"] >= 0.8


@pytest.fixture(scope="module")
def simulated_palpation_bags(tmp_path_factory):
    """10 s palpations at 1 and 2.5 Hz of one point of the synthetic chest
    (relaxing tissue, sensor noise and lag), written as the rig's bags."""
    import numpy as np

    from vic_drake.experiments import CampaignParams, simulate_palpations
    from vic_drake.experiments.rig_log import write_palpation_bag
    from vic_drake.systems.indenter import PalpationParams
    from vic_drake.tissue import load_phantom

    phantom = load_phantom("synthetic")
    x, y = np.array([-0.05]), np.array([-0.36])
    truth = phantom.sample(x, y)
    folder = tmp_path_factory.mktemp("palpations")
    bags = {}
    for f in (1.0, 2.5):
        palpation = PalpationParams(frequency_hz=f, duration_s=10.0)
        (record,) = simulate_palpations(
            x,
            y,
            surface_z=truth.surface_z_m,
            kappa=truth.kappa,
            lam=truth.lam,
            beta=phantom.beta,
            params=CampaignParams(palpation=palpation),
            seed=1,
        )
        bags[f] = write_palpation_bag(
            record, folder / f"{f:g}hz", surface_z_m=float(truth.surface_z_m[0])
        )
    return bags


@pytest.mark.parametrize("frequency_hz", [1.0, 2.5])
@pytest.mark.parametrize("method", ["rls", "ekf"])
def test_a_simulated_palpation_meets_the_palpation_targets(
    capsys, simulated_palpation_bags, frequency_hz, method
):
    """Within 10 % of the whole log's fit in <= 2 s and close to it, on a
    palpation of the project's relaxing tissue. The real 1 Hz log takes
    3.45 s: its tissue softens more than this one in its first seconds
    (docs/decisions.md, "The 1 Hz palpation's 2 s target is out of reach
    for an estimator of the current tissue"). No real data needed."""
    bag = simulated_palpation_bags[frequency_hz]
    status, out, err = run(
        capsys, ["estimate-online", bag, "--method", method, "--json"]
    )
    assert status == 0, err
    result = json.loads(out)
    assert set(result) == KEYS and result["kappa_corr"] is None
    assert result["convergence_s"] is not None and result["convergence_s"] <= 2.0
    assert result["kappa_rel_err_median"] <= 0.05
