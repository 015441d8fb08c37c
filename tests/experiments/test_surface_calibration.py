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
    for mode in ("auto", "anchors", "placement", "none"):
        assert parse_surface_offset(mode) == mode
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
        surface = calibration.surface_calibration(real, phantom, "anchors")
        assert surface["source"] == "rig default"
        assert surface["offset_m"] == RIG_SURFACE_OFFSET_M
        assert surface["first_contact"] is bad  # still reported


def _anchors(real, phantom):
    """A plausible first contact at the track's start and a plausible
    lift-off at its end (the real first contact, a lift-off put beside it)."""
    import vic_drake.experiments.surface_calibration as calibration
    from vic_drake.analysis.lift_off import LiftOff

    first = calibration.first_contact_offset(real, phantom)
    lift = LiftOff(
        offset_m=-0.001, sigma_m=5e-5, surface_z_m=0.1, x_m=-0.147, y_m=-0.354,
        t_s=21.0, samples=40, bias_N=0.0, speed_m_per_s=0.04, raw_offset_m=-0.001,
        kappa_scale=1.0,
    )  # fmt: skip
    return first, lift


@pytest.mark.realdata
def test_auto_profile_between_two_plausible_anchors_and_its_fallbacks(
    data_dir, monkeypatch
):
    import vic_drake.experiments.surface_calibration as calibration

    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    real = real_to_canonical(read_bag(data_dir / "experiments" / "test_tracking5"))
    first, lift = _anchors(real, phantom)

    def use(lift_off):
        monkeypatch.setattr(calibration, "lift_off_offset", lambda *a, **k: lift_off)
        return calibration.surface_calibration(real, phantom, "anchors")

    surface = use(lift)
    assert surface["source"] == "first contact + lift-off"
    assert surface["profile"]["x_m"] == [lift.x_m, first.x_m]  # increasing x
    assert surface["profile"]["offset_m"] == [lift.offset_m, first.offset_m]
    assert surface["offset_m"] == pytest.approx((lift.offset_m + first.offset_m) / 2)
    # A lift that does not follow the model (the real ones: 1.9, 2.1), a
    # loose one, or one beside the first contact: the first contact alone.
    for bad in (
        lift._replace(kappa_scale=1.6),
        lift._replace(kappa_scale=0.6),
        lift._replace(sigma_m=2 * calibration.MAX_FIRST_CONTACT_SIGMA_M),
        lift._replace(x_m=first.x_m - 0.5 * calibration.MIN_PROFILE_SPAN_M),
    ):
        surface = use(bad)
        assert surface["source"] == "first contact" and surface["profile"] is None
        assert surface["offset_m"] == first.offset_m
        assert surface["lift_off"] is bad  # still reported
    # The lift-off alone, when the first contact is not plausible.
    monkeypatch.setattr(
        calibration,
        "first_contact_offset",
        lambda *a: first._replace(offset_m=2 * calibration.MAX_SURFACE_OFFSET_M),
    )
    surface = use(lift)
    assert surface["source"] == "lift-off" and surface["offset_m"] == lift.offset_m
    # A number or "none" never applies the anchors.
    given = calibration.surface_calibration(real, phantom, 0.001)
    assert given["source"] == "given" and given["profile"] is None
    assert given["offset_m"] == 0.001
    assert calibration.surface_calibration(real, phantom, "none")["offset_m"] == 0.0


@pytest.mark.realdata
def test_the_real_lift_offs_are_not_used(data_dir):
    """Both VS logs lift off, but their lifts do not follow the map's
    viscosity (fit modulus ~2x the map's kappa): auto keeps the first contact."""
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    for name in VS_LOGS:
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        surface = surface_calibration(real, phantom, "anchors")
        assert surface["lift_off"] is not None
        assert surface["lift_off"].kappa_scale > 1.8
        assert surface["source"] == "first contact" and surface["profile"] is None
    for name in SCAN_LOGS:
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        assert surface_calibration(real, phantom, "anchors")["lift_off"] is None


@pytest.mark.realdata
def test_compare_real_with_a_profile_raises_the_tissue_not_the_controllers_map(
    data_dir, monkeypatch
):
    import vic_drake.experiments.surface_calibration as calibration

    module = importlib.import_module("vic_drake.experiments.compare_real")
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    bag = data_dir / "experiments" / "test_tracking5"
    first, lift = _anchors(real_to_canonical(read_bag(bag)), published)
    monkeypatch.setattr(calibration, "lift_off_offset", lambda *a, **k: lift)
    built = {}

    def build_only(scenario, *, phantom, controller_phantom=None, **_):
        built.update(scenario=scenario, phantom=phantom, ctrl=controller_phantom)
        raise _Built

    monkeypatch.setattr(module, "run_scan", build_only)
    with pytest.raises(_Built):
        compare_real(bag, data_dir=data_dir, surface_offset="anchors")
    x, y = np.array([-0.155, lift.x_m, -0.05, first.x_m, 0.04]), np.full(5, -0.356)
    raised = built["phantom"].surface_z(x, y) - published.surface_z(x, y)
    expected = [lift.offset_m, lift.offset_m, None, first.offset_m, first.offset_m]
    expected[2] = np.interp(
        -0.05, [lift.x_m, first.x_m], [lift.offset_m, first.offset_m]
    )
    np.testing.assert_allclose(raised, expected, atol=2e-5)  # bilinear between nodes
    assert built["scenario"].variations.map_errors.surface_offset_m == 0.0
    seen = controller_map(built["scenario"], built["ctrl"])
    np.testing.assert_allclose(
        seen.surface_z(x, y), published.surface_z(x, y), atol=1e-12
    )


def test_surface_profile_raises_a_grid_along_x():
    from vic_drake.tissue.phantom import GridPhantom
    from vic_drake.tissue.phantom.distorted import with_surface_profile

    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.4, -0.3, 11)
    flat = GridPhantom(
        x_m=xs, y_m=ys, z_m=np.full((31, 11), 0.1), kappa=np.full((31, 11), 3e3),
        lam=np.full((31, 11), 3e4), surface_offset_m=0.0025,
    )  # fmt: skip
    raised = with_surface_profile(flat, [-0.1, 0.0], [0.002, -0.001])
    x = np.array([-0.15, -0.1, -0.05, 0.0, 0.05])
    np.testing.assert_allclose(
        raised.surface_z(x, -0.35) - flat.surface_z(x, -0.35),
        [0.002, 0.002, 0.0005, -0.001, -0.001],
        atol=1e-12,
    )
    np.testing.assert_allclose(raised.surface_gradient(-0.05, -0.35)[0], -0.03)
    np.testing.assert_allclose(raised.kappa(x, -0.35), flat.kappa(x, -0.35))
    for bad in (([0.0, -0.1], [0.0, 0.0]), ([0.0], [0.0]), ([0.0, 0.1], [0.0, np.nan])):
        with pytest.raises(VicDrakeError, match="surface profile"):
            with_surface_profile(flat, *bad)
    with pytest.raises(VicDrakeError, match="grid phantom"):
        with_surface_profile(object(), [0.0, 0.1], [0.0, 0.0])


@pytest.mark.slow
@pytest.mark.realdata
def test_a_simulated_lift_off_reads_the_known_surface(data_dir):
    """tracking5 simulated whole on relaxing tissue 3 mm above the map: the
    lift-off read from the simulated log finds the 3 mm (measured 3.14)."""
    from vic_drake.analysis.lift_off import lift_off_offset

    _, sim, _ = compare_real(
        data_dir / "experiments" / "test_tracking5",
        data_dir=data_dir,
        surface_offset=0.003,
        return_frames=True,
    )
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    found = lift_off_offset(sim, published)
    assert 1e3 * found.offset_m == pytest.approx(3.0, abs=0.2)
    assert found.kappa_scale == pytest.approx(1.0, abs=0.1)
    plain = lift_off_offset(sim, published, viscous=False)
    assert abs(1e3 * plain.offset_m - 3.0) > 0.3


def _flat_grid():
    from vic_drake.tissue.phantom import GridPhantom

    xs, ys = np.linspace(-0.2, 0.1, 31), np.linspace(-0.4, -0.3, 11)
    return GridPhantom(
        x_m=xs, y_m=ys, z_m=np.full((31, 11), 0.1), kappa=np.full((31, 11), 3e3),
        lam=np.full((31, 11), 3e4), surface_offset_m=0.0025,
    )  # fmt: skip


def test_surface_plane_raises_a_grid_by_a_plane():
    from vic_drake.tissue.phantom.distorted import with_surface_plane

    flat = _flat_grid()
    placed = with_surface_plane(flat, 0.002, (-0.02, 0.01), (-0.05, -0.35))
    x = np.array([-0.2, -0.15, -0.05, 0.0, 0.1])
    for y in (-0.38, -0.35):
        np.testing.assert_allclose(
            placed.surface_z(x, y) - flat.surface_z(x, y),
            0.002 - 0.02 * (x + 0.05) + 0.01 * (y + 0.35),
            atol=1e-12,
        )
    np.testing.assert_allclose(placed.surface_gradient(-0.07, -0.36), (-0.02, 0.01))
    np.testing.assert_allclose(placed.kappa(x, -0.35), flat.kappa(x, -0.35))
    assert placed.lookup == flat.lookup
    for bad in (
        (np.nan, (0.0, 0.0), (0.0, 0.0)),
        (0.0, (0.0,), (0.0, 0.0)),
        (0.0, (0.0, 0.0), (0.0, np.inf)),
    ):
        with pytest.raises(VicDrakeError, match="surface plane"):
            with_surface_plane(flat, *bad)
    with pytest.raises(VicDrakeError, match="grid phantom"):
        with_surface_plane(object(), 0.0, (0.0, 0.0), (0.0, 0.0))


def _placement(offset_m=0.002, slope=0.015, span_m=0.18, start_m=None):
    from vic_drake.analysis.surface_placement import SurfacePlacement

    start_m = -0.5 * span_m if start_m is None else start_m
    return SurfacePlacement(
        offset_m=offset_m, slope_m_per_m=slope, offset_sigma_m=1e-4,
        slope_sigma_m=2e-3, x0_m=-0.05, y0_m=-0.355, direction=(0.8, -0.6),
        span_m=span_m, start_m=start_m, bins=19, samples=9000,
        residual_rms_m=5e-4,
    )  # fmt: skip


def test_placed_surface_applies_the_plane_only_to_a_resting_phantom():
    from vic_drake.experiments.surface_calibration import placed_surface

    anchors = {
        "offset_m": 0.004, "source": "first contact", "profile": None,
        "plane": None, "placement": _placement(), "placement_wanted": True,
    }  # fmt: skip
    placed = placed_surface(anchors, resting=True)
    assert placed["source"] == "placement" and placed["offset_m"] == 0.002
    assert placed["plane"]["origin_m"] == (-0.05, -0.355)
    np.testing.assert_allclose(placed["plane"]["gradient"], (0.012, -0.009))
    assert anchors["source"] == "first contact"  # not changed in place
    # A moving phantom, a mode that does not ask for it, no plane, or a plane
    # that leaves the map's +-20 mm at an end of its span: the anchors.
    too_steep = _placement(slope=2 * calibration_max() / 0.18 + 0.01)
    # The origin is the mean of the bin centres: with uneven bins the far
    # end is 0.15 m from it, not 0.09 m (at 0.13 m/m: +21.5 mm there).
    uneven = _placement(slope=0.13, start_m=-0.03)
    assert (
        placed_surface({**anchors, "placement": _placement(slope=0.13)}, resting=True)[
            "source"
        ]
        == "placement"
    )
    for surface, resting in (
        (anchors, False),
        ({**anchors, "placement_wanted": False}, True),
        ({**anchors, "placement": None}, True),
        ({**anchors, "placement": too_steep}, True),
        ({**anchors, "placement": _placement(offset_m=0.025)}, True),
        ({**anchors, "placement": uneven}, True),
    ):
        assert placed_surface(surface, resting=resting) is surface


def calibration_max():
    from vic_drake.experiments.surface_calibration import MAX_SURFACE_OFFSET_M

    return MAX_SURFACE_OFFSET_M


def test_surface_calibration_reads_the_plane_and_leaves_it_to_placed_surface():
    """On a synthetic log: the plane is reported under every mode, and
    wanted only under "auto" and "placement"."""
    from tests.analysis.test_surface_placement import _map, _scan

    phantom = _map()
    scan = _scan(phantom, 0.003, 0.01)
    for mode, wanted in (
        ("auto", True), ("placement", True), ("anchors", False), ("none", False),
        (0.001, False),
    ):  # fmt: skip
        surface = surface_calibration(scan, phantom, mode)
        assert surface["placement_wanted"] is wanted
        assert surface["plane"] is None
        assert 1e3 * surface["placement"].slope_m_per_m == pytest.approx(10.0, abs=0.3)


@pytest.mark.realdata
def test_compare_real_places_a_resting_phantom_and_keeps_the_controllers_map(
    data_dir, monkeypatch
):
    module = importlib.import_module("vic_drake.experiments.compare_real")
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    built = {}

    def build_only(scenario, *, phantom, controller_phantom=None, **_):
        built.update(scenario=scenario, phantom=phantom, ctrl=controller_phantom)
        raise _Built

    monkeypatch.setattr(module, "run_scan", build_only)
    bag = data_dir / "experiments" / "test_nardi_matForce_lowR"
    with pytest.raises(_Built):
        compare_real(bag, data_dir=data_dir)
    real = real_to_canonical(read_bag(bag))
    plane = surface_calibration(real, published)["placement"]
    x, y = np.linspace(-0.15, 0.04, 20), np.full(20, -0.356)
    raised = built["phantom"].surface_z(x, y) - published.surface_z(x, y)
    np.testing.assert_allclose(raised, plane.offset_at(x, y), atol=2e-5)
    assert built["scenario"].variations.map_errors.surface_offset_m == 0.0
    seen = controller_map(built["scenario"], built["ctrl"])
    np.testing.assert_allclose(
        seen.surface_z(x, y), published.surface_z(x, y), atol=1e-12
    )
    # A log whose phantom moves keeps the anchors' constant (the rig default).
    built.clear()
    with pytest.raises(_Built):
        compare_real(data_dir / "experiments" / "test_force_control_dist")
    raised = built["phantom"].surface_z(x, y) - published.surface_z(x, y)
    np.testing.assert_allclose(raised, RIG_SURFACE_OFFSET_M, atol=1e-12)
    assert built["ctrl"] is None


@pytest.mark.realdata
def test_the_real_placements(data_dir):
    """nardi's phantom is tilted along the track by more than 5 sigma of its
    plane; tracking5's is not; the two 9-column logs of one session, six
    minutes apart under different controllers, read one plane."""
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")

    def plane(name):
        real = real_to_canonical(read_bag(data_dir / "experiments" / name))
        return surface_calibration(real, phantom)["placement"]

    nardi, tracking = plane("test_nardi_matForce_lowR"), plane("test_tracking5")
    assert nardi.slope_m_per_m > 5 * nardi.slope_sigma_m
    assert 1e3 * nardi.slope_m_per_m == pytest.approx(16.6, abs=0.2)
    assert abs(tracking.slope_m_per_m) < 2 * tracking.slope_sigma_m
    cs, cf = plane(SCAN_LOGS[0]), plane(SCAN_LOGS[1])
    at = (-0.055, -0.355)
    assert cs.offset_at(*at) == pytest.approx(cf.offset_at(*at), abs=1e-4)
    assert abs(cs.slope_m_per_m - cf.slope_m_per_m) < np.hypot(
        cs.slope_sigma_m, cf.slope_sigma_m
    )
