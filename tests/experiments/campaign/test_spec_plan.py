"""Campaign specs and run plans: checks before any run, deterministic draws."""

from pathlib import Path

import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.experiments.campaign import load_campaign_spec, plan_campaign
from vic_drake.experiments.campaign.plan import plan_run
from vic_drake.scenario import dumps_scenario, load_scenario, loads_scenario

CAMPAIGNS = Path(__file__).resolve().parents[3] / "campaigns"
BASE = CAMPAIGNS / "base" / "short_scan_synthetic.yaml"


def _spec(tmp_path, body: str) -> Path:
    path = tmp_path / "spec.yaml"
    path.write_text(f"name: t\nbase_scenario: {BASE}\nruns: 8\nseed: 3\n{body}")
    return path


def _plans(path):
    spec, base = load_campaign_spec(path)
    return spec, plan_campaign(spec, load_scenario(base))


@pytest.mark.parametrize("name", sorted(p.stem for p in CAMPAIGNS.glob("*.yaml")))
def test_shipped_campaigns_plan_every_run(name):
    spec, plans = _plans(CAMPAIGNS / f"{name}.yaml")
    assert len(plans) == spec.runs
    assert len({p.run_id for p in plans}) == spec.runs
    loads_scenario(dumps_scenario(plans[-1].scenario()))  # What scan replays.


def test_grid_cycles_and_draws_depend_only_on_seed_and_index(tmp_path):
    path = _spec(
        tmp_path,
        "factors:\n"
        "  - {field: controller, dist: grid, labels: [cs, vs-vf]}\n"
        "  - {field: variations.map_errors.kappa_scale, dist: uniform, low: 0.7, high: 1.3}\n"
        "  - {field: 'variations.sensor_faults.bias_N[2]', dist: normal, mean: 0, std: 1,"
        " low: -2, high: 2}\n"
        "  - {field: variations.sensor_faults.stuck_channel, dist: choice, values: [-1, 2]}\n",
    )
    spec, plans = _plans(path)
    assert [p.factors["controller"] for p in plans] == ["cs", "vs-vf"] * 4
    again = plan_run(spec, load_scenario(BASE), 5)
    assert again == plans[5]
    s = plans[5].scenario()
    assert s.controller.reference.controller == "vs-vf"
    assert s.variations.map_errors.kappa_scale == pytest.approx(
        plans[5].factors["variations.map_errors.kappa_scale"]
    )
    assert s.variations.sensor_faults.stuck_channel in (-1, 2)
    assert s.duration_s == spec.duration_s
    assert len({p.factors["variations.map_errors.kappa_scale"] for p in plans}) == 8


def test_a_factor_sets_one_axis_of_the_lateral_breathing(tmp_path):
    path = _spec(
        tmp_path,
        "factors:\n"
        "  - {field: variations.motion.breathing.amplitude_m, dist: grid,"
        " values: [0.005, 0.01]}\n"
        "  - {field: 'variations.motion.breathing.lateral_amplitude_m[0]',"
        " dist: uniform, low: -0.004, high: 0.004}\n",
    )
    _, plans = _plans(path)
    lateral = [
        p.scenario().variations.motion.breathing.lateral_amplitude_m for p in plans
    ]
    drawn = [
        p.factors["variations.motion.breathing.lateral_amplitude_m[0]"] for p in plans
    ]
    assert [x for x, _ in lateral] == pytest.approx(drawn)
    assert all(y == 0.0 for _, y in lateral)  # The other axis stays the base's.
    assert len(set(drawn)) == len(plans) and all(abs(x) <= 0.004 for x in drawn)
    assert all(p.scenario().variations.motion.lateral_active for p in plans)
    # Beyond the allowed range: the run's check names the item.
    bad = _spec(
        tmp_path,
        "factors:\n  - {field: 'variations.motion.breathing.lateral_amplitude_m[1]',"
        " dist: uniform, low: 0.02, high: 0.03}\n",
    )
    with pytest.raises(VicDrakeError, match=r"lateral_amplitude_m\[1\] must be within"):
        _plans(bad)
    with pytest.raises(VicDrakeError, match="has no item 2"):
        _plans(
            _spec(
                tmp_path,
                "factors:\n  - {field: 'variations.motion.breathing.lateral_amplitude_m[2]',"
                " dist: uniform, low: 0, high: 0.001}\n",
            )
        )


def test_population_draws_a_patient_per_run(tmp_path):
    _, plans = _plans(_spec(tmp_path, "population: true\n"))
    s = plans[0].scenario()
    assert s.variations.patient.enabled
    assert plans[0].factors["patient.kappa_scale"] == s.variations.patient.kappa_scale
    assert (
        plans[0].factors["patient.kappa_scale"]
        != plans[1].factors["patient.kappa_scale"]
    )


def test_the_online_source_is_an_arm_of_its_own_on_the_same_patients():
    spec, plans = _plans(CAMPAIGNS / "population_online.yaml")
    arms = [p.factors["controller"] for p in plans[:4]]
    assert arms == ["vs-vf", "vs-vf online", "vs-vf", "vs-vf online"]
    online = plans[1].scenario()
    assert online.stiffness_source == "online"
    assert online.controller.reference.penetration_dither_m == 3e-4
    assert online.online_estimator.surface_from_slope
    # Each patient is scanned by both arms; the next pair has another one.
    kappa = [p.factors["patient.kappa_scale"] for p in plans[:4]]
    assert kappa[0] == kappa[1] != kappa[2] == kappa[3]


@pytest.mark.parametrize(
    "body, message",
    [
        (
            "factors:\n  - {field: variations.nope, dist: uniform, low: 0, high: 1}\n",
            "no field 'nope'",
        ),
        ("factors:\n  - {field: controller, dist: choice, labels: [cs, pid]}\n", "pid"),
        ("factors:\n  - {field: seed, dist: cauchy}\n", "dist must be one of"),
        ("factors:\n  - {field: seed, dist: uniform, low: 2, high: 1}\n", "low < high"),
        (
            "factors:\n  - {field: variations.motion.breathing.amplitude_m, dist: uniform, low: 0, high: 0.5}\n",
            "amplitude_m",
        ),
        (
            "factors:\n  - {field: controller, dist: grid, labels: [cs, cf, vs-vf]}\n",
            "multiple of the grid",
        ),
        (
            "factors:\n  - {field: name, dist: uniform, low: 0, high: 1}\n",
            "takes labels",
        ),
        ("runs_: 3\n", "runs_"),
    ],
)
def test_bad_specs_fail_before_any_run(tmp_path, body, message):
    with pytest.raises(VicDrakeError, match=message):
        _plans(_spec(tmp_path, body))


@pytest.mark.parametrize(
    "body, message",
    [
        # As for a scenario YAML: the field named, the allowed ones listed.
        ("seed_: 1\n", r"field seed_ is unknown; allowed: \[.*'seed'"),
        ("duraton_s: 2.5\n", r"field duraton_s is unknown; allowed: \[.*'duration_s'"),
        ("force_limit_N: high\n", "field force_limit_N must be a float; got 'high'"),
        (
            "factors:\n  - {field: controller, dist: grid, lables: [cs]}\n",
            r"field factors\[0\]\.lables is unknown; allowed: \[.*'labels'",
        ),
        (
            "factors:\n  - {field: seed, dist: uniform, low: a, high: 1}\n",
            r"field factors\[0\]\.low must be a float; got 'a'",
        ),
    ],
)
def test_spec_errors_name_the_field_like_scenario_errors(tmp_path, body, message):
    with pytest.raises(VicDrakeError, match=message) as err:
        load_campaign_spec(_spec(tmp_path, body))
    assert str(err.value).startswith(f"campaign spec {str(tmp_path / 'spec.yaml')!r}:")
    assert "CampaignSpec" in str(err.value)


def test_a_wrong_scalar_is_named_with_its_field(tmp_path):
    # _spec writes seed: 3; a spec of its own with a word for the seed.
    path = tmp_path / "spec.yaml"
    path.write_text(f"name: t\nbase_scenario: {BASE}\nseed: one\n")
    with pytest.raises(VicDrakeError, match="field seed must be an int; got 'one'"):
        load_campaign_spec(path)


def test_missing_files_are_named(tmp_path):
    with pytest.raises(VicDrakeError, match="does not exist"):
        load_campaign_spec(tmp_path / "none.yaml")
    path = tmp_path / "s.yaml"
    path.write_text("name: t\nbase_scenario: nowhere.yaml\n")
    with pytest.raises(VicDrakeError, match="nowhere.yaml"):
        load_campaign_spec(path)


_PAIRED_FACTORS = (
    "factors:\n"
    "  - {field: controller, dist: grid, labels: [cf, vs-vf]}\n"
    "  - {field: 'variations.sensor_faults.bias_N[2]', dist: normal, mean: 0, std: 1,"
    " low: -3, high: 3}\n"
    "  - {field: variations.motion.breathing.amplitude_m, dist: uniform, low: 0,"
    " high: 0.01}\n"
)


@pytest.mark.parametrize("paired", [True, False])
def test_paired_arms_share_every_draw_and_the_run_seed(tmp_path, paired):
    body = ("paired: true\n" if paired else "") + _PAIRED_FACTORS
    _, plans = _plans(_spec(tmp_path, body))
    shared = (
        "variations.sensor_faults.bias_N[2]",
        "variations.motion.breathing.amplitude_m",
    )
    for k in range(0, 8, 2):
        a, b = plans[k], plans[k + 1]
        assert (a.factors["controller"], b.factors["controller"]) == ("cf", "vs-vf")
        sa, sb = a.scenario(), b.scenario()
        same = [a.factors[f] == b.factors[f] for f in shared]
        same.append(
            sa.variations.sensor_faults.seed == sb.variations.sensor_faults.seed
        )
        same.append(
            sa.variations.motion.breathing.seed == sb.variations.motion.breathing.seed
        )
        assert all(same) if paired else not any(same)
    # The next round draws anew.
    assert plans[0].factors[shared[0]] != plans[2].factors[shared[0]]


def test_paired_needs_a_grid(tmp_path):
    path = _spec(
        tmp_path,
        "paired: true\nfactors:\n  - {field: seed, dist: uniform, low: 1, high: 9}\n",
    )
    with pytest.raises(VicDrakeError, match="paired needs a grid factor"):
        load_campaign_spec(path)


def test_a_true_false_field_is_a_grid_of_two_labels_and_its_own_arm(tmp_path):
    path = _spec(
        tmp_path,
        "paired: true\n"
        "factors:\n"
        "  - {field: watchdog.enabled, dist: grid, labels: ['true', 'false']}\n"
        "  - {field: variations.sensor_faults.stuck_channel, dist: choice,"
        " values: [2]}\n",
    )
    spec, plans = _plans(path)
    arms = [p.factors["controller"] for p in plans]
    assert arms == ["vs-vf", "vs-vf no watchdog"] * 4
    on, off = plans[0].scenario(), plans[1].scenario()
    assert on.watchdog.enabled and not off.watchdog.enabled
    assert on.seed == off.seed  # Paired: the same draws.


@pytest.mark.parametrize("levels", ["values: [0, 1]", "labels: ['yes', 'no']"])
def test_a_true_false_field_refuses_other_levels_before_any_run(tmp_path, levels):
    path = _spec(
        tmp_path, f"factors:\n  - {{field: watchdog.enabled, dist: grid, {levels}}}\n"
    )
    with pytest.raises(VicDrakeError, match=r"'watchdog.enabled' is true/false"):
        _plans(path)
