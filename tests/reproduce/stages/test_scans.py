"""The ``scans`` stage: the scenarios of the paper's runs and their limits."""

import pytest

from vic_drake.errors import VicDrakeError


def test_scan_scenarios_cover_the_paper_runs():
    from vic_drake.reproduce import CONTROLLERS, scan_limits, scan_scenario

    for quick in (True, False):
        for c in CONTROLLERS:
            s = scan_scenario(c, disturbed=False, phantom_kind="synthetic", quick=quick)
            assert s.controller.reference.controller == c
            assert s.disturbance.is_nominal
        d = scan_scenario(
            "vs-vf", disturbed=True, phantom_kind="synthetic", quick=quick
        )
        lifts = d.disturbance.lifts
        assert len(lifts) == (2 if quick else 4)
        # Every event ends (phantom back at rest) before the target lifts off.
        traj = d.trajectory
        scan_end = traj.end_time_s - traj.liftoff_s
        for lift in lifts:
            assert lift.start_s + lift.rise_s + lift.hold_s + lift.fall_s < scan_end
        # Dropped below rest: contact loss must be possible.
        assert min(lift.height_m for lift in lifts) < 0
    lim = scan_limits(
        scan_scenario("vs-vf", disturbed=False, phantom_kind="synthetic", quick=True)
    )
    assert lim.k_min_z_N_per_m == 100.0 and lim.tank_min_J == 0.4
    assert lim.power_max_W == pytest.approx(0.1) and lim.eps_d_m == 0.008


def test_scan_scenarios_take_a_relaxation():
    from vic_drake.reproduce import scan_scenario
    from vic_drake.tissue import DEFAULT_RELAXATION, RelaxationParams

    rel = RelaxationParams((0.03, 0.09), (1.7, 65.0))
    given = scan_scenario(
        "cs", disturbed=True, phantom_kind="synthetic", quick=True, relaxation=rel
    )
    assert given.station.relaxation == rel
    plain = scan_scenario("cs", disturbed=True, phantom_kind="synthetic", quick=True)
    assert plain.station.relaxation is DEFAULT_RELAXATION
    assert plain.station.tissue_relaxation_fractions == []


def test_the_paper_scans_are_built_from_the_diagram_files(monkeypatch, tmp_path):
    """reproduce reads diagrams/*.yaml: a changed file changes the scan."""
    import importlib

    from vic_drake.paths import DIAGRAMS_DIR
    from vic_drake.reproduce import scan_scenario

    text = (DIAGRAMS_DIR / "nominal_cf_synthetic.yaml").read_text()
    assert "    controller: cf\n" in text
    (tmp_path / "nominal_cf_synthetic.yaml").write_text(
        text.replace(
            "    controller: cf\n", "    controller: cf\n    force_ref_N: 5.5\n"
        )
    )
    # The module, not the function of the same name that the package exports.
    module = importlib.import_module("vic_drake.experiments.paper_scenarios")
    monkeypatch.setattr(module, "DIAGRAMS_DIR", tmp_path)
    s = scan_scenario("cf", disturbed=False, phantom_kind="synthetic", quick=True)
    assert s.controller.reference.force_ref_N == 5.5
    with pytest.raises(VicDrakeError, match="controller must be one of"):
        scan_scenario("pid", disturbed=False, phantom_kind="synthetic", quick=True)
