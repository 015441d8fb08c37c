"""compare-real on a simulated log of a phantom placed with a known tilt.

:func:`placed_roundtrip` checks the placement plane
(:mod:`vic_drake.analysis.surface_placement`) where its truth is known: the
scenario compare-real builds for a shared log (controller and settings
identified from the log, relaxing tissue), simulated on the published map
raised by a known plane (``offset_m`` at the track's middle, rising
``slope_m_per_m`` along +x), the controller reading the published map as on
the rig; the scan written as the rig's ROS 2 bag and fed back to
:func:`~vic_drake.experiments.compare_real.compare_real` under each surface
mode asked for. A perfect registration reads the plane back; the scores say
what the surface mode does to compare-real where the surface is the only
thing that differs (``benchmarks/placement_roundtrip.py`` prints them).
"""

from pathlib import Path

import numpy as np

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.analysis.contact import scan_window
from vic_drake.analysis.surface_offset import first_contact_offset
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.compare_real import compare_real
from vic_drake.experiments.real_logs import scenario_from_real_log
from vic_drake.experiments.rig_log import write_scan_bag
from vic_drake.experiments.scan_run import run_scan
from vic_drake.experiments.surface_calibration import parse_surface_offset
from vic_drake.realdata import read_bag
from vic_drake.tissue.phantom import load_phantom
from vic_drake.tissue.phantom.distorted import with_map_errors, with_surface_plane

#: The mode that gives compare-real the bag's own first contact as a number.
FIRST_CONTACT = "first contact"


def track_middle(real) -> tuple[float, float, float, float]:
    """The middle (x, y) of a log's scan-window track and its x extent, m."""
    window = scan_window(real)
    if not window.any():
        raise VicDrakeError("the log has no scan window; cannot place a plane on it")
    x = real["x_m"].to_numpy(float)[window]
    y = real["y_m"].to_numpy(float)[window]
    return (
        float(0.5 * (x.min() + x.max())),
        float(np.median(y)),
        float(x.min()),
        float(x.max()),
    )


def placed_roundtrip(
    data_dir: Path,
    log: str,
    out_dir: Path,
    *,
    offset_m: float,
    slope_m_per_m: float,
    kappa_scale: float = 1.0,
    modes=("first contact", "anchors", "placement"),
) -> list[dict]:
    """One simulated log of ``log``'s scan on the map placed by a known plane,
    compared under each surface mode in ``modes``.

    ``kappa_scale`` scales the simulated tissue's kappa against the map's (a
    map whose stiffness is off, as the real one may be). A mode is one of
    compare-real's surface offsets or "first contact": the bag's own first
    contact (:func:`~vic_drake.analysis.surface_offset.first_contact_offset`)
    given as a number, the constant offset "anchors" takes on a real log
    whose lift-off is rejected.

    Returns:
        one dict per mode: mode, the truth (truth_offset_mm at the track's
        middle, truth_slope_mm_per_m), the plane read back
        (placement_offset_mm at its own origin, placement_slope_mm_per_m and
        their sigmas) and its error (placement_offset_err_mm: read minus
        true at the read origin; placement_max_err_mm over the track's x),
        compare-real's surface_offset_source / surface_offset_mm and its
        scores (force_rmse_N, z_rmse_mm, kz_corr, force_peak_err_N, peaks,
        contact loss sim / real / overlap).

    Raises:
        VicDrakeError: no such log, or a mode compare-real does not take.
    """
    for mode in modes:
        if mode != FIRST_CONTACT:
            parse_surface_offset(mode)
    bag_in = Path(data_dir) / "experiments" / log
    if not bag_in.is_dir():
        raise VicDrakeError(f"no log {log!r} in {str(bag_in.parent)!r}")
    raw = read_bag(bag_in)
    x0, y0, x_lo, x_hi = track_middle(real_to_canonical(raw))
    scenario = scenario_from_real_log(raw, name=f"placed_{log}")
    published = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    gradient = (float(slope_m_per_m), 0.0)
    tissue = with_map_errors(
        with_surface_plane(published, offset_m, gradient, (x0, y0)),
        kappa_scale=kappa_scale,
    )
    truth = run_scan(scenario, phantom=tissue, controller_phantom=published)
    tag = f"{slope_m_per_m * 1e3:+.0f}_k{kappa_scale:g}".replace("+", "p")
    bag = write_scan_bag(truth, Path(out_dir) / f"placed_{log}_{tag.replace('-', 'm')}")
    first = first_contact_offset(real_to_canonical(read_bag(bag)), published)

    def true_offset(x):
        return offset_m + slope_m_per_m * (np.asarray(x, float) - x0)

    rows = []
    for mode in modes:
        if mode == FIRST_CONTACT and first is None:
            continue
        given = first.offset_m if mode == FIRST_CONTACT else mode
        out = compare_real(bag, data_dir=data_dir, surface_offset=given)
        row = {
            "log": log,
            "mode": mode,
            "kappa_scale": kappa_scale,
            "truth_offset_mm": 1e3 * offset_m,
            "truth_slope_mm_per_m": 1e3 * slope_m_per_m,
        }
        fitted = out["surface_placement_offset_mm"]
        if fitted is not None:
            ox, oy = out["surface_placement_origin_m"]
            dx, dy = out["surface_placement_direction"]
            slope = out["surface_placement_slope_mm_per_m"]
            xs = np.linspace(x_lo, x_hi, 50)
            read = fitted + slope * dx * (xs - ox) + slope * dy * (y0 - oy)
            row.update(
                placement_offset_mm=fitted,
                placement_offset_sigma_mm=out["surface_placement_offset_sigma_mm"],
                placement_slope_mm_per_m=slope * dx,
                placement_slope_sigma_mm_per_m=out[
                    "surface_placement_slope_sigma_mm_per_m"
                ],
                placement_offset_err_mm=fitted - 1e3 * float(true_offset(ox)),
                placement_max_err_mm=float(
                    np.max(np.abs(read - 1e3 * true_offset(xs)))
                ),
            )
        for key in (
            "surface_offset_source",
            "surface_offset_mm",
            "force_rmse_N",
            "z_rmse_mm",
            "kz_corr",
            "force_peak_err_N",
            "force_peak_sim_N",
            "force_peak_real_N",
            "contact_loss_total_sim_s",
            "contact_loss_total_real_s",
            "contact_loss_overlap_s",
        ):
            row[key] = out[key]
        rows.append(row)
    return rows


__all__ = ["FIRST_CONTACT", "placed_roundtrip", "track_middle"]
