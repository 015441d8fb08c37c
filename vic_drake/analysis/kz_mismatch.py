"""Where a simulated scan's K_z departs from a real VS log's, and why.

Three diagnostics of compare-real's ``kz_corr`` (Pearson's r of K_z over the
real scan window, :func:`vic_drake.analysis.real_comparison.compare_with_real`),
each on the simulated record shifted by the comparison's time offset and
resampled at the real log's times:

- :func:`kz_deficit_by_bin`: with both K_z standardised (mean 0, std 1),
  the squared differences sum to ``2 n (1 - r)``; their share per time bin
  says where the correlation is lost, next to the QP's inputs there.
- :func:`kz_input_swap`: the real log replayed through the QP
  (:func:`vic_drake.control.replay.replay_controller_log`, which reproduces
  the logged K_z) with some inputs taken from the simulation; r of that K_z
  against the logged one says which input carries the mismatch.
- :func:`tip_height_components`: the tip-height difference (sim - real)
  split into the map under the two tips, the surface each force says the
  tissue has against the map, and the penetration (force inversion at the
  map's kappa, :func:`vic_drake.analysis.phantom_motion.penetration_m`). It
  reads the scored force: a diagnostic, never an input of the simulation.
"""

import numpy as np
import pandas as pd

from vic_drake.analysis.columns import real_to_canonical, require_columns
from vic_drake.analysis.contact import scan_window
from vic_drake.analysis.phantom_motion import penetration_m
from vic_drake.analysis.real_comparison import resample, shift_time
from vic_drake.control.params import ControllerParams
from vic_drake.control.replay import REPLAY_COLUMNS, replay_controller_log
from vic_drake.errors import VicDrakeError

#: The QP inputs :func:`kz_input_swap` can take from the simulation, and the
#: 31-column log's columns each replaces.
SWAP_INPUTS = {
    "z": ("z_m",),
    "vz": ("vz_m_per_s",),
    "xy": ("x_m", "y_m"),
    "force_ref": ("force_ref_z_N",),
    "force_min": ("force_min_z_N",),
}

#: Fewest window samples a diagnostic works on.
MIN_SAMPLES = 10


def _on_real_times(sim, real, time_offset_s, columns):
    """Sim columns at the real times (shifted by time_offset_s), and the mask
    of real scan-window samples where all of them are finite."""
    require_columns(sim, "t_s", *columns)
    t = real["t_s"].to_numpy(float)
    s = resample(shift_time(sim, time_offset_s), t, columns)
    ok = scan_window(real).copy()
    for c in columns:
        ok &= np.isfinite(s[c])
    return s, ok


def _standardised(v):
    return (v - v.mean()) / v.std()


def kz_deficit_by_bin(
    sim: pd.DataFrame,
    real: pd.DataFrame,
    *,
    time_offset_s: float = 0.0,
    bin_s: float = 1.0,
    params: ControllerParams | None = None,
) -> pd.DataFrame:
    """Where Pearson's r of K_z is lost, per time bin of the real scan window.

    Args:
        sim: simulated scan (canonical columns).
        real: the real log, canonical (``real_to_canonical``), with K_z.
        time_offset_s: the comparison's shift of the simulated time.
        bin_s: bin length, s (> 0); bins start at multiples of it.
        params: for the K_z bounds (default: the real controller's).

    Returns:
        One row per bin: ``t0_s``, ``samples``, ``time_share``,
        ``deficit_share`` (its part of sum (z_real - z_sim)^2 = 2 n (1 - r);
        0 everywhere when r = 1),
        means of ``k_real``/``k_sim`` (N/m), ``e_z_real_mm``/``e_z_sim_mm``
        (z_d - z), and the fractions of ticks whose force reference lies
        below F_min (``f_min_binds_real``/``_sim``: the QP's F_min row then
        sets K_z) or whose K_z sits on a bound (``k_at_bound_real``/``_sim``).
        ``attrs["kz_corr"]`` is r over all bins.

    Raises:
        VicDrakeError: bad bin_s, a real log without K_z, or fewer than
            MIN_SAMPLES comparable samples, or a constant K_z.
    """
    if not (np.isfinite(bin_s) and bin_s > 0):
        raise VicDrakeError(f"bin_s must be a number of s > 0; got {bin_s!r}")
    cols = ["z_m", "z_d_m", "force_ref_z_N", "force_min_z_N", "stiffness_z_N_per_m"]
    require_columns(real, "t_s", *cols)
    s, ok = _on_real_times(sim, real, time_offset_s, cols)
    r = {c: real[c].to_numpy(float) for c in cols}
    for c in cols:
        ok &= np.isfinite(r[c])
    kr, ks = r["stiffness_z_N_per_m"][ok], s["stiffness_z_N_per_m"][ok]
    if ok.sum() < MIN_SAMPLES or kr.std() == 0 or ks.std() == 0:
        raise VicDrakeError(
            f"K_z comparison needs >= {MIN_SAMPLES} window samples with a varying K_z "
            f"in both records; got {int(ok.sum())} samples (is the real log a 31-column one?)"
        )
    params = ControllerParams() if params is None else params
    k_lo = params.qp.stiffness_min_N_per_m[2]
    k_hi = params.qp.stiffness_max_N_per_m[2]
    deficit = (_standardised(kr) - _standardised(ks)) ** 2
    t = real["t_s"].to_numpy(float)[ok]
    frame = pd.DataFrame(
        {
            "t0_s": np.floor(t / bin_s) * bin_s,
            "deficit": deficit,
            "k_real": kr,
            "k_sim": ks,
            "e_z_real_mm": 1e3 * (r["z_d_m"] - r["z_m"])[ok],
            "e_z_sim_mm": 1e3 * (s["z_d_m"] - s["z_m"])[ok],
            "f_min_binds_real": (r["force_ref_z_N"] < r["force_min_z_N"])[ok],
            "f_min_binds_sim": (s["force_ref_z_N"] < s["force_min_z_N"])[ok],
            "k_at_bound_real": (kr <= k_lo * (1 + 1e-9)) | (kr >= k_hi * (1 - 1e-9)),
            "k_at_bound_sim": (ks <= k_lo * (1 + 1e-9)) | (ks >= k_hi * (1 - 1e-9)),
        }
    )
    out = frame.groupby("t0_s", as_index=False).mean()
    counts = frame.groupby("t0_s")["deficit"].agg(["size", "sum"]).to_numpy()
    out.insert(1, "samples", counts[:, 0].astype(int))
    out.insert(2, "time_share", counts[:, 0] / len(frame))
    total = deficit.sum()
    out.insert(3, "deficit_share", counts[:, 1] / total if total > 0 else 0.0)
    out = out.drop(columns="deficit")
    out.attrs["kz_corr"] = float(np.corrcoef(kr, ks)[0, 1])
    return out


def kz_input_swap(
    raw: pd.DataFrame,
    sim: pd.DataFrame,
    inputs,
    *,
    r_weight: float,
    time_offset_s: float = 0.0,
    params: ControllerParams | None = None,
) -> float:
    """r of K_z replayed from the real log with some inputs taken from the sim.

    The named inputs (keys of :data:`SWAP_INPUTS`; "vz" is the slope of the
    simulated tip height) replace the log's over the real scan window where
    the simulation covers it; the QP is replayed
    (:func:`~vic_drake.control.replay.replay_controller_log`: D, T and the
    other inputs from the log) and its K_z correlated with the logged K_z
    over the same samples. With no input swapped it is 1 up to the replay's
    error.

    Args:
        raw: the 31-column log (``read_bag(path, expect="controller")``).
        sim: simulated scan (canonical columns).
        inputs: iterable of input names.
        r_weight: the log's R (``identify_r_weight``).
        time_offset_s: the comparison's shift of the simulated time.
        params: controller parameters of the replay.

    Raises:
        VicDrakeError: an unknown input name, a log that is not a 31-column
            one, or fewer than MIN_SAMPLES window samples.
    """
    inputs = list(inputs)
    unknown = [name for name in inputs if name not in SWAP_INPUTS]
    if unknown:
        raise VicDrakeError(
            f"kz_input_swap inputs must be among {list(SWAP_INPUTS)}; got {unknown}"
        )
    missing = [c for c in REPLAY_COLUMNS if c not in raw.columns]
    if raw.attrs.get("layout") != "controller" or missing:
        raise VicDrakeError(
            "kz_input_swap needs a 31-column controller log "
            f"(read_bag(path, expect='controller')); this frame lacks {missing}"
        )
    real = real_to_canonical(raw)
    cols = ["z_m", "x_m", "y_m", "force_ref_z_N", "force_min_z_N"]
    s, ok = _on_real_times(sim, real, time_offset_s, cols)
    if ok.sum() < MIN_SAMPLES:
        raise VicDrakeError(
            f"kz_input_swap needs >= {MIN_SAMPLES} window samples the simulation "
            f"covers; got {int(ok.sum())}"
        )
    ts = sim["t_s"].to_numpy(float) + time_offset_s
    z_sim = sim["z_m"].to_numpy(float)
    s["vz_m_per_s"] = np.interp(real["t_s"].to_numpy(float), ts, np.gradient(z_sim, ts))
    swapped = raw.copy()
    for name in inputs:
        for column in SWAP_INPUTS[name]:
            values = swapped[column].to_numpy(float).copy()
            values[ok] = s[column][ok]
            swapped[column] = values
    result = replay_controller_log(swapped, params, r_weight=r_weight)
    keep = ok[1:]  # The replay's ticks are rows 1..n-1.
    k_replay = result.stiffness_N_per_m[keep, 2]
    k_logged = result.stiffness_logged_N_per_m[keep, 2]
    return float(np.corrcoef(k_replay, k_logged)[0, 1])


def tip_height_components(
    sim: pd.DataFrame,
    real: pd.DataFrame,
    phantom,
    *,
    time_offset_s: float = 0.0,
) -> pd.DataFrame:
    """The tip-height difference sim - real split by where it comes from, m.

    With ``a = z + penetration_m - map surface at the tip`` the apparent
    surface against the map (the force inverted at the map's kappa),
    ``dz = lateral + surface - penetration`` exactly, where ``lateral`` is the
    map's surface under the simulated tip minus under the real one,
    ``surface`` is a_sim - a_real and ``penetration`` the inverted
    penetrations' difference (sim - real).

    Args:
        sim: simulated scan; real: the real log, both canonical.
        phantom: the map both are read against (e.g. the published map).
        time_offset_s: the comparison's shift of the simulated time.

    Returns:
        Per real scan-window sample in contact in both: ``t_s``,
        ``x_real_m``, ``dz_m``, ``lateral_m``, ``surface_m``,
        ``penetration_m``, ``apparent_real_m``, ``apparent_sim_m``.
    """
    cols = ["x_m", "y_m", "z_m", "force_sensor_z_N"]
    require_columns(real, "t_s", *cols)
    shifted = shift_time(sim, time_offset_s)
    shifted = shifted.assign(inverted_penetration_m=penetration_m(shifted, phantom))
    s, ok = _on_real_times(shifted, real, 0.0, [*cols, "inverted_penetration_m"])
    pen_real = penetration_m(real, phantom)
    ok &= np.isfinite(pen_real)
    xr, yr, zr = (real[c].to_numpy(float)[ok] for c in ("x_m", "y_m", "z_m"))
    xs, ys, zs = (s[c][ok] for c in ("x_m", "y_m", "z_m"))
    map_r = np.asarray(phantom.surface_z(xr, yr), float)
    map_s = np.asarray(phantom.surface_z(xs, ys), float)
    pen_s = s["inverted_penetration_m"][ok]
    app_r = zr + pen_real[ok] - map_r
    app_s = zs + pen_s - map_s
    return pd.DataFrame(
        {
            "t_s": real["t_s"].to_numpy(float)[ok],
            "x_real_m": xr,
            "dz_m": zs - zr,
            "lateral_m": map_s - map_r,
            "surface_m": app_s - app_r,
            "penetration_m": pen_s - pen_real[ok],
            "apparent_real_m": app_r,
            "apparent_sim_m": app_s,
        }
    )


__all__ = [
    "MIN_SAMPLES",
    "SWAP_INPUTS",
    "kz_deficit_by_bin",
    "kz_input_swap",
    "tip_height_components",
]
