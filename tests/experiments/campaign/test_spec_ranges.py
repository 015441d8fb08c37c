"""Every value a factor can draw is checked when the spec loads.

A bad end of a range or a bad label fails ``load_campaign_spec``, naming
the spec, the factor and the scenario's own message, whatever ``runs`` and
``seed`` are: not only when some run happens to draw it.
"""

import json
import re
from pathlib import Path

import pytest

from vic_drake.cli import main
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign import load_campaign_spec
from vic_drake.experiments.campaign.plan import run_scenario
from vic_drake.experiments.campaign.spec import CampaignSpec, Factor
from vic_drake.scenario import load_scenario

CAMPAIGNS = Path(__file__).resolve().parents[3] / "campaigns"
BASE = CAMPAIGNS / "base" / "short_scan_synthetic.yaml"
FAULTS = "variations.sensor_faults"


def _spec(tmp_path, factors: list[dict], runs: int = 1, seed: int = 1) -> Path:
    """A spec file with these factors (JSON is YAML)."""
    path = tmp_path / "spec.yaml"
    lines = [f"  - {json.dumps(f)}" for f in factors]
    path.write_text(
        f"name: t\nbase_scenario: {BASE}\nruns: {runs}\nseed: {seed}\n"
        "duration_s: 4.0\nfactors:\n" + "\n".join(lines) + "\n"
    )
    return path


#: (factor, its bad end, the scenario's message about it).
BAD = {
    "low": (
        {
            "field": f"{FAULTS}.dead_start_s",
            "dist": "uniform",
            "low": -1.0,
            "high": 4.0,
        },
        "low -1.0",
        "SensorFaultConfig.dead_start_s must be >= 0.0; got -1.0",
    ),
    "high": (
        {"field": f"{FAULTS}.noise_std_N", "dist": "uniform", "low": 0.0, "high": 25.0},
        "high 25.0",
        "SensorFaultConfig.noise_std_N must be <= 20.0; got 25.0",
    ),
    "label": (
        {
            "field": f"{FAULTS}.dropout_mode",
            "dist": "choice",
            "labels": ["hold", "zero"],
        },
        "label 'zero'",
        "SensorFaultConfig.dropout_mode must be one of ['hold', 'nan']; got 'zero'",
    ),
}

#: A factor every run of the specs below can take (it comes first).
GOOD = {
    "field": "variations.map_errors.kappa_scale",
    "dist": "uniform",
    "low": 0.8,
    "high": 1.2,
}


@pytest.mark.parametrize("case", BAD)
def test_the_single_run_of_the_spec_would_draw_a_valid_value(case):
    # The point of the next test: with runs 1 and seed 1, the one run draws
    # a value its own check takes (dead_start_s 1.56, noise_std_N 12.8,
    # "hold"), so only a check of the whole range can refuse these specs.
    factor = Factor(**BAD[case][0])
    spec = CampaignSpec(name="t", runs=1, seed=1, duration_s=4.0, factors=[factor])
    run_scenario(spec, load_scenario(BASE), 0)


@pytest.mark.parametrize("runs, seed", [(1, 1), (8, 0), (200, 7)])
@pytest.mark.parametrize("case", BAD)
def test_a_bad_end_or_label_fails_at_load_whatever_runs_and_seed(
    tmp_path, case, runs, seed
):
    factor, which, message = BAD[case]
    path = _spec(tmp_path, [GOOD, factor], runs=runs, seed=seed)
    with pytest.raises(VicDrakeError) as err:
        load_campaign_spec(path)
    text = str(err.value)
    assert text.startswith(
        f"campaign spec {str(path)!r}: factors[1] ({factor['field']}): its {which}"
    )
    assert message in text
    assert "\n" not in text  # One paragraph.


def test_an_unclipped_normal_is_checked_at_six_std_and_a_clipped_one_at_its_clip(
    tmp_path,
):
    normal = {"field": f"{FAULTS}.noise_std_N", "dist": "normal", "mean": 0.5}
    # Unbounded: mean - 6 std is -0.1 N, below the field's 0.
    with pytest.raises(
        VicDrakeError,
        match=re.escape("its mean - 6 std -0.1")
        + r".*give it low and high to clip it.*noise_std_N must be >= 0.0",
    ):
        load_campaign_spec(_spec(tmp_path, [{**normal, "std": 0.1}]))
    load_campaign_spec(_spec(tmp_path, [{**normal, "std": 0.08}]))
    # Clipped: its bounds are drawn (every draw beyond them), so they are checked.
    clipped = {**normal, "std": 0.1, "low": 0.0, "high": 1.0}
    load_campaign_spec(_spec(tmp_path, [clipped]))
    with pytest.raises(VicDrakeError, match="its low -0.5 is refused"):
        load_campaign_spec(_spec(tmp_path, [{**clipped, "low": -0.5}]))


def test_a_grid_value_and_a_controller_label_are_checked_each(tmp_path):
    stuck = {"field": f"{FAULTS}.stuck_channel", "dist": "grid", "values": [-1, 2, 3]}
    with pytest.raises(VicDrakeError, match=r"factors\[0\].*its value 3.0 is refused"):
        load_campaign_spec(_spec(tmp_path, [stuck], runs=3))
    arms = {"field": "controller", "dist": "grid", "labels": ["cs", "pid"]}
    with pytest.raises(
        VicDrakeError, match=r"factors\[0\] \(controller\): its label 'pid'"
    ):
        load_campaign_spec(_spec(tmp_path, [arms], runs=2))


def test_a_start_pose_out_of_reach_fails_at_load_not_as_error_rows(tmp_path):
    # The scenario's checks take any y; the run's IK does not, on the worker.
    y = {"field": "trajectory.y_m", "dist": "uniform", "low": -0.9, "high": -0.36}
    with pytest.raises(
        VicDrakeError,
        match=r"factors\[0\] \(trajectory.y_m\): its low -0.9 is refused: a run "
        r"with it cannot start: no joint configuration puts the probe tip",
    ):
        load_campaign_spec(_spec(tmp_path, [y]))


@pytest.mark.parametrize("name", sorted(p.stem for p in CAMPAIGNS.glob("*.yaml")))
def test_every_shipped_spec_loads(name):
    spec, base = load_campaign_spec(CAMPAIGNS / f"{name}.yaml")
    assert spec.factors and base.is_file()


def test_the_command_says_it_in_one_line_and_writes_nothing(tmp_path, capsys):
    factor, which, message = BAD["label"]
    out = tmp_path / "out"
    code = main(["campaign", str(_spec(tmp_path, [factor])), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.startswith("vic-drake: error: campaign spec") and err.count("\n") == 1
    assert which in err and message in err and "Traceback" not in err
    assert not out.exists()


@pytest.mark.parametrize(
    "factor, message",
    [
        # A misspelt field: the fields there and the close name, not "narrow
        # the range".
        (
            {
                "field": "variations.motion.breathing.amplitud_m",
                "dist": "uniform",
                "low": 0.005,
                "high": 0.01,
            },
            r"factors\[0\]: factor 'variations\.motion\.breathing\.amplitud_m': "
            r"variations\.motion\.breathing has no field 'amplitud_m'; did you mean "
            r"amplitude_m",
        ),
        # An integer field drawn from a range: rounded in the run, unrounded in
        # the row, its levels drawn unevenly.
        (
            {
                "field": f"{FAULTS}.stuck_channel",
                "dist": "uniform",
                "low": -1,
                "high": 2,
            },
            r"factors\[0\] \(variations\.sensor_faults\.stuck_channel\) is an "
            r"integer field: draw it with dist grid or choice",
        ),
        (
            {"field": "seed", "dist": "normal", "mean": 5, "std": 1},
            r"factors\[0\] \(seed\) is an integer field",
        ),
        # The same cell twice in a grid.
        (
            {"field": "controller", "dist": "grid", "labels": ["cs", "cs"]},
            r"the grid lists 'cs' more than once",
        ),
    ],
)
def test_a_factor_that_cannot_be_what_it_says_is_refused(tmp_path, factor, message):
    with pytest.raises(VicDrakeError, match=message):
        load_campaign_spec(_spec(tmp_path, [factor]))


def test_an_integer_field_from_levels_and_a_weighted_choice_are_fine(tmp_path):
    factors = [
        {"field": f"{FAULTS}.stuck_channel", "dist": "choice", "values": [-1, 2]},
        {"field": "controller", "dist": "choice", "labels": ["cs", "cs", "vs-vf"]},
    ]
    load_campaign_spec(_spec(tmp_path, factors))


def test_a_duration_far_past_the_base_scenario_is_refused(tmp_path):
    path = _spec(tmp_path, [{"field": "controller", "dist": "grid", "labels": ["cs"]}])
    path.write_text(path.read_text().replace("duration_s: 4.0", "duration_s: 100000"))
    with pytest.raises(
        VicDrakeError, match=r"duration_s 100000 s is far beyond the base scenario"
    ):
        load_campaign_spec(path)
