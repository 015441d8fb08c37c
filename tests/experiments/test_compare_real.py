"""compare-real on short stretches of real logs: its keys and the motion replay."""

import math

import pytest

from vic_drake.analysis.real_comparison import COMPARE_REAL_KEYS
from vic_drake.experiments.compare_real import compare_real
from vic_drake.realdata import RIG_SURFACE_OFFSET_M

#: Keys every compare-real result holds besides the contract keys.
MOTION_KEYS = (
    "phantom_motion_max_mm",
    "phantom_motion_sigma_median_mm",
    "phantom_motion_significance",
    "phantom_motion_replayed",
    "phantom_motion_reference",
    "contact_loss_total_sim_s",
    "contact_loss_total_real_s",
    "contact_loss_overlap_s",
    "surface_offset_mm",
    "surface_offset_source",
    "surface_first_contact_mm",
    "controller_map_offset_mm",
)


@pytest.mark.realdata
@pytest.mark.parametrize(
    ("log", "duration_s", "replayed", "reference"),
    [
        # The phantom is first lifted 4.5 s into the log (about 40 s of wall
        # time on two loaded cores).
        pytest.param(
            "test_compliance_control400_dist",
            6.0,
            True,
            "nominal log",
            marks=pytest.mark.slow,
        ),
        ("test_compliance_control400", 2.5, False, "phantom map"),
    ],
)
def test_compare_real_reports_the_motion_and_contact_loss(
    data_dir, log, duration_s, replayed, reference
):
    out, sim, _ = compare_real(
        data_dir / "experiments" / log,
        data_dir=data_dir,
        duration_s=duration_s,
        return_frames=True,
    )
    assert list(out)[: len(COMPARE_REAL_KEYS)] == list(COMPARE_REAL_KEYS)
    for key in MOTION_KEYS:
        assert key in out, key
    assert out["phantom_motion_replayed"] is replayed
    # "auto": one lateral pass when the motion is replayed, none otherwise.
    assert out["lateral_passes"] == (1 if replayed else 0)
    assert out["phantom_motion_reference"] == reference
    assert out["phantom_motion_max_mm"] >= 0 and math.isfinite(
        out["phantom_motion_max_mm"]
    )
    for key in ("contact_loss_total_sim_s", "contact_loss_total_real_s"):
        assert out[key] >= 0.0
    assert 0.0 <= out["contact_loss_overlap_s"] <= out["contact_loss_total_real_s"]
    # The replayed motion moves the simulated phantom; a nominal log's does not.
    moved = sim["phantom_lift_m"].abs().max()
    assert bool(moved > 1e-4) is replayed
    assert ("lift_max_mm" in out) is replayed
    # A 9-column log holds no anchor of its own: a moving phantom gets the
    # rig default, a resting one the plane of its in-contact surface.
    if replayed:
        assert out["surface_offset_mm"] == pytest.approx(1e3 * RIG_SURFACE_OFFSET_M)
        assert out["surface_offset_source"] == "rig default"
    else:
        assert out["surface_offset_source"] == "placement"
        assert out["surface_offset_mm"] == out["surface_placement_offset_mm"]
    assert out["surface_placement_slope_mm_per_m"] is not None
    assert out["surface_first_contact_mm"] is None
    assert out["controller_map_offset_mm"] is None


@pytest.mark.realdata
def test_compare_real_reports_what_it_identified_and_the_tissue_law(data_dir):
    out = compare_real(
        data_dir / "experiments" / "test_force_control",
        data_dir=data_dir,
        duration_s=2.5,
        tissue_law="hc",
    )
    ident = out["controller_identified"]
    assert ident["controller"] == "cf" and ident["given"] is False
    assert ident["settings"]["force_ref_N"] == pytest.approx(7.0, abs=0.2)
    assert out["tissue_law"] == "hc"


@pytest.mark.realdata
def test_compare_real_rejects_an_unknown_tissue_law_before_simulating(data_dir):
    from vic_drake.errors import VicDrakeError

    with pytest.raises(VicDrakeError, match="tissue_law must be one of"):
        compare_real(data_dir / "experiments" / "test_force_control", tissue_law="kv")


@pytest.mark.realdata
def test_compare_real_rejects_a_relaxation_on_plain_hc_before_simulating(data_dir):
    from vic_drake.errors import VicDrakeError
    from vic_drake.tissue import RelaxationParams

    rel = RelaxationParams((0.03,), (1.7,))
    with pytest.raises(VicDrakeError, match="needs the 'relaxing' tissue law"):
        compare_real(
            data_dir / "experiments" / "test_force_control",
            tissue_law="hc",
            relaxation=rel,
        )
    with pytest.raises(VicDrakeError, match="RelaxationParams or None"):
        compare_real(
            data_dir / "experiments" / "test_force_control", relaxation=[(0.03, 1.7)]
        )


@pytest.mark.realdata
def test_compare_real_simulates_the_given_relaxation(data_dir):
    """A short run on a given relaxation: echoed, and the simulated force
    differs from the default law's (the same run otherwise)."""
    from vic_drake.tissue import RelaxationParams

    bag = data_dir / "experiments" / "test_force_control"
    rel = RelaxationParams((0.3,), (0.5,))
    # One surface for both ("auto" would read each run's plane with its own
    # law, placing the tissue where the log's tip height says).
    kw = dict(data_dir=data_dir, duration_s=2.5, surface_offset="anchors")
    out, sim, _ = compare_real(bag, relaxation=rel, return_frames=True, **kw)
    base, sim0, _ = compare_real(bag, return_frames=True, **kw)
    assert out["tissue_relaxation"] == {"fractions": [0.3], "time_constants_s": [0.5]}
    assert "tissue_relaxation" not in base
    assert out["tissue_law"] == base["tissue_law"] == "relaxing"
    # Under force control the tip sinks further into the more relaxing tissue.
    assert sim["z_m"].iloc[-1] < sim0["z_m"].iloc[-1] - 1e-4
