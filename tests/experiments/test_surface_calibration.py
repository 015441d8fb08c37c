"""The surface offset compare-real applies: the rule, the rig default, the replay."""

import importlib

import numpy as np
import pytest

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.surface_offset import first_contact_offset
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.compare_real import compare_real
from vic_drake.experiments.scan_variations import controller_map
from vic_drake.experiments.surface_calibration import (
    DEFAULT_SURFACE_OFFSET,
    parse_surface_offset,
    rig_surface_offset,
    surface_calibration,
)
from vic_drake.realdata import RIG_SURFACE_OFFSET_M, read_bag
from vic_drake.tissue.phantom import load_phantom

VS_LOGS = ("test_tracking5", "test_nardi_matForce_lowR")
SCAN_LOGS = ("test_compliance_control400", "test_force_control")


def test_parse_surface_offset():
    assert parse_surface_offset(None) == DEFAULT_SURFACE_OFFSET == "auto"
    assert parse_surface_offset("auto") == "auto"
    assert parse_surface_offset(-0.002) == -0.002
    for bad in ("rig", 0.05, float("nan"), "3"):
        with pytest.raises(VicDrakeError, match="surface offset"):
            parse_surface_offset(bad)


@pytest.mark.realdata
def test_rig_default_is_what_the_calibration_logs_give(data_dir):
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    bags = [data_dir / "experiments" / n for n in (*VS_LOGS, *SCAN_LOGS)]
    rig = rig_surface_offset(bags, phantom)
    assert rig["offset_m"] == pytest.approx(RIG_SURFACE_OFFSET_M, abs=5e-6)
    assert sorted(rig["per_log"]) == sorted(VS_LOGS)
    assert rig["unused"] == list(SCAN_LOGS)
    with pytest.raises(VicDrakeError, match="free space"):
        rig_surface_offset(bags[2:], phantom)


@pytest.mark.realdata
@pytest.mark.parametrize(
    ("log", "offset", "source", "expected_mm"),
    [
        ("test_compliance_control400", "none", "none", 0.0),
        ("test_compliance_control400", None, "rig default", 1e3 * RIG_SURFACE_OFFSET_M),
        (
            "test_compliance_control400",
            "auto",
            "rig default",
            1e3 * RIG_SURFACE_OFFSET_M,
        ),
        ("test_tracking5", "auto", "first contact", 2.89),
        ("test_tracking5", -0.001, "given", -1.0),
    ],
)
def test_the_rule_picks_the_offset(data_dir, log, offset, source, expected_mm):
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    real = real_to_canonical(read_bag(data_dir / "experiments" / log))
    surface = surface_calibration(real, phantom, offset)
    assert surface["source"] == source
    assert 1e3 * surface["offset_m"] == pytest.approx(expected_mm, abs=0.01)


class _Built(Exception):
    """Raised by the stand-in for run_scan: what compare-real built is checked."""


@pytest.mark.realdata
@pytest.mark.parametrize("offset_m", [0.003, -0.002])
def test_compare_real_raises_the_tissue_and_keeps_the_controllers_map(
    data_dir, monkeypatch, offset_m
):
    module = importlib.import_module("vic_drake.experiments.compare_real")
    built = {}

    def build_only(scenario, *, phantom, **_):
        built.update(scenario=scenario, phantom=phantom)
        raise _Built

    monkeypatch.setattr(module, "run_scan", build_only)
    with pytest.raises(_Built):
        compare_real(
            data_dir / "experiments" / "test_force_control",
            data_dir=data_dir,
            surface_offset=offset_m,
        )
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    x, y = np.linspace(-0.15, 0.04, 50), np.full(50, -0.356)
    tissue = built["phantom"].surface_z(x, y)
    np.testing.assert_allclose(tissue - published.surface_z(x, y), offset_m, atol=1e-12)
    # The controller's map (the scan diagram's map errors on the tissue).
    seen = controller_map(built["scenario"], built["phantom"])
    np.testing.assert_allclose(
        seen.surface_z(x, y), published.surface_z(x, y), atol=1e-12
    )


@pytest.mark.realdata
def test_a_simulated_scan_shows_the_offset_compare_real_applied(data_dir):
    """tracking5's approach from free space, simulated on tissue 3 mm above the
    map: the first contact in the simulated log finds the 3 mm again."""
    out, sim, _ = compare_real(
        data_dir / "experiments" / "test_tracking5",
        data_dir=data_dir,
        duration_s=2.5,
        surface_offset=0.003,
        return_frames=True,
    )
    assert out["surface_offset_mm"] == pytest.approx(3.0)
    assert out["surface_offset_source"] == "given"
    assert out["surface_first_contact_mm"] == pytest.approx(2.89, abs=0.05)
    assert out["controller_map_offset_mm"] == pytest.approx(1.5, abs=0.05)
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    first = first_contact_offset(sim, published)
    assert first is not None
    assert 1e3 * first.offset_m == pytest.approx(3.0, abs=0.15)


@pytest.mark.realdata
def test_auto_falls_back_on_the_rig_default_for_a_loose_first_contact(
    data_dir, monkeypatch
):
    import vic_drake.experiments.surface_calibration as calibration

    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    real = real_to_canonical(read_bag(data_dir / "experiments" / "test_tracking5"))
    first = calibration.first_contact_offset(real, phantom)
    loose = first._replace(sigma_m=2 * calibration.MAX_FIRST_CONTACT_SIGMA_M)
    far = first._replace(offset_m=2 * calibration.MAX_SURFACE_OFFSET_M)
    for bad in (loose, far):
        monkeypatch.setattr(calibration, "first_contact_offset", lambda *a, b=bad: b)
        surface = calibration.surface_calibration(real, phantom, "auto")
        assert surface["source"] == "rig default"
        assert surface["offset_m"] == RIG_SURFACE_OFFSET_M
        assert surface["first_contact"] is bad  # still reported
