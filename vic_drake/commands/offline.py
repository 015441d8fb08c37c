"""Offline fits of the paper's Sec. III-A: ``fit-palpation`` and ``load-test``.

``vic-drake fit-palpation BAG_DIR`` reads a 6-column palpation bag, estimates
the force sensor's lag, aligns force and position, fits Kelvin-Voigt and
Hunt-Crossley (at each ``--betas``) by least squares with the indenter-mass
term, and sweeps beta over [1.0, 2.0] (Table I of the paper).

``vic-drake load-test BAG_DIR --fit-from PALPATION_BAG_DIR`` fits both models
on the palpation and predicts the load/unload test's force from its measured
trajectory (Fig. 2), reporting each model's RMS error.

Relative residual: RMS least-squares residual / RMS of the fitted force
(F_sensor + m_I z_ddot) over the in-contact samples. The paper's Table I
("relative residual value") does not define its number; compare the
ordering of the models rather than the digits.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from vic_drake.commands.common import (
    Progress,
    add_bag_data_dir_option,
    add_json_option,
    bag_path,
    emit,
    help_text,
    parse_float_list,
)
from vic_drake.errors import VicDrakeError
from vic_drake.paper import TABLE_I_BETAS
from vic_drake.paths import PLOT_SUFFIXES, check_output_file

_RELATIVE_HELP = (
    "Relative residual = RMS residual / RMS fitted force over the in-contact "
    "samples (the paper's Table I does not define its 'relative residual value'; "
    "compare orderings, not digits)."
)


def _beta_key(beta: float) -> str:
    """JSON key of a beta: the shortest repr of the float ("1.35", "1.0")."""
    return repr(float(beta))


def _parse_betas(text: str) -> list[float]:
    betas = parse_float_list(text, "--betas")
    for b in betas:
        if not (math.isfinite(b) and 0.0 < b <= 3.0):
            raise VicDrakeError(
                f"--betas values must be in (0, 3]; got {b!r} in {text!r}"
            )
    # Keep order, drop repeats (they would collide as JSON keys).
    return list(dict.fromkeys(betas))


def _check_beta_option(beta: float, option: str) -> float:
    if not (math.isfinite(beta) and 0.0 < beta <= 3.0):
        raise VicDrakeError(f"{option} must be in (0, 3]; got {beta!r}")
    return beta


def _check_nonneg(value: float, option: str) -> float:
    if not (math.isfinite(value) and value >= 0.0):
        raise VicDrakeError(f"{option} must be a finite number >= 0; got {value!r}")
    return value


#: What the offline commands read: the rig's 6-column palpation/loadcycle logs.
PALPATION_EXPECTED = (
    "a ROS 2 bag folder (metadata.yaml + .db3) of the 6-column palpation/loadcycle "
    "layout"
)


def _find_palpation(args: argparse.Namespace, text: str, role: str) -> Path:
    """The bag folder ``text`` names (as given, else in the data folder)."""
    return bag_path(args, text, role, PALPATION_EXPECTED)


def _read_palpation(path: Path):
    """A found bag (:func:`_find_palpation`) as PalpationData."""
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.realdata import read_bag

    df = read_bag(path, expect="palpation")
    return PalpationData.from_frame(df)


def _add_fit_options(parser: argparse.ArgumentParser) -> None:
    from vic_drake.estimation.palpation import (
        DEFAULT_INDENTER_MASS_KG,
        DEFAULT_MAX_LAG_S,
    )

    parser.add_argument(
        "--max-lag",
        type=float,
        default=DEFAULT_MAX_LAG_S,
        metavar="S",
        help="sensor-lag search range [0, S] seconds (default %(default)s)",
    )
    parser.add_argument(
        "--lag",
        type=float,
        default=None,
        metavar="S",
        help="use this sensor lag (s) instead of estimating it",
    )
    parser.add_argument(
        "--indenter-mass",
        type=float,
        default=DEFAULT_INDENTER_MASS_KG,
        metavar="KG",
        help="indenter mass m_I below the sensing element, kg (default %(default)s: "
        "the BOTA SensONE wrench-side mass)",
    )


def _fit_palpation(args: argparse.Namespace) -> int:
    from vic_drake.estimation.palpation import compare_models

    betas = _parse_betas(args.betas)
    max_lag = _check_nonneg(args.max_lag, "--max-lag")
    lag = None if args.lag is None else _check_nonneg(args.lag, "--lag")
    mass = _check_nonneg(args.indenter_mass, "--indenter-mass")
    if args.plot:  # Checked before the fits: a bad path fails now.
        check_output_file(args.plot, "--plot", PLOT_SUFFIXES)
    path = _find_palpation(args, args.bag_dir, "palpation bag")
    say = Progress()
    say(f"reading {path}")
    data = _read_palpation(path)
    result = compare_models(
        data,
        betas,
        lag_s=lag,
        max_lag_s=max_lag,
        indenter_mass_kg=mass,
        progress=say,
    )
    kv = result.kelvin_voigt
    out = {
        "lag_s": result.lag_s,
        "kelvin_voigt": {
            "rms_N": kv.rms_N,
            "relative": kv.relative,
            "k": kv.k,
            "d": kv.d,
        },
        "hunt_crossley": {
            _beta_key(b): {
                "rms_N": f.rms_N,
                "relative": f.relative,
                "kappa": f.kappa,
                "lambda": f.lam,
            }
            for b, f in result.hunt_crossley.items()
        },
        "best_beta": result.best_beta,
    }
    if args.plot:
        from vic_drake.reproduce.plots.offline import plot_palpation_summary

        plot_palpation_summary(result, title=str(args.bag_dir), save_path=args.plot)
        say(f"wrote {args.plot}")
    lag_note = ""
    if result.lag_profile is not None:
        lo, hi = result.lag_profile.flat_range(0.01)
        lag_note = f"; residual within 1 % of its minimum for lags {lo * 1e3:.0f}-{hi * 1e3:.0f} ms"
    lines = [
        f"palpation {args.bag_dir}: {kv.n_samples} in-contact samples",
        f"sensor lag {result.lag_s * 1e3:.1f} ms (force behind position){lag_note}",
        f"{'model':<22}{'rms [N]':>10}{'relative':>10}   parameters",
        f"{'Kelvin-Voigt':<22}{kv.rms_N:>10.4f}{kv.relative:>10.4f}   "
        f"k = {kv.k:.1f} N/m, d = {kv.d:.2f} N s/m",
    ]
    for b, f in result.hunt_crossley.items():
        lines.append(
            f"{'Hunt-Crossley b=' + _beta_key(b):<22}{f.rms_N:>10.4f}{f.relative:>10.4f}   "
            f"kappa = {f.kappa:.1f}, lambda = {f.lam:.1f}"
        )
    lines.append(f"best beta in [1.0, 2.0]: {result.best_beta:.3f}")
    if not args.json:
        from vic_drake.estimation.palpation import residual_vs_palpation_time, shift

        curve = residual_vs_palpation_time(
            shift(data, result.lag_s), indenter_mass_kg=mass
        )
        f = curve.exp_fit
        if f is not None:
            skipped = curve.approach.cycles_skipped if curve.approach else 0
            lines.append(
                "residual vs palpation time (Fig. 3, beta = 1.35, fit on the first T s "
                f"after the approach ({skipped} cycles), scored on the whole palpation): "
                f"{f.a:.3g} exp(-T / {f.tau_s:.3g} s) + {f.c:.3g}"
            )
    lines.append(_RELATIVE_HELP)
    emit(out, args.json, "\n".join(lines))
    return 0


def _load_test(args: argparse.Namespace) -> int:
    from vic_drake.estimation.loadtest import load_test

    beta = _check_beta_option(args.beta, "--beta")
    max_lag = _check_nonneg(args.max_lag, "--max-lag")
    lag = None if args.lag is None else _check_nonneg(args.lag, "--lag")
    mass = _check_nonneg(args.indenter_mass, "--indenter-mass")
    if args.plot:  # Checked before the fits: a bad path fails now.
        check_output_file(args.plot, "--plot", PLOT_SUFFIXES)
    # Both paths are found before either log is read.
    load_path = _find_palpation(args, args.bag_dir, "load-test bag")
    fit_path = _find_palpation(args, args.fit_from, "--fit-from palpation bag")
    say = Progress()
    say(f"reading {load_path} and {fit_path}")
    load = _read_palpation(load_path)
    palpation = _read_palpation(fit_path)
    result = load_test(
        load,
        palpation,
        beta=beta,
        lag_s=lag,
        max_lag_s=max_lag,
        indenter_mass_kg=mass,
        progress=say,
        load_name=f"load-test bag {args.bag_dir!r}",
        palpation_name=f"--fit-from {args.fit_from!r}",
    )
    out = {
        "kelvin_voigt_rms_N": result.kelvin_voigt_rms_N,
        "hunt_crossley_rms_N": result.hunt_crossley_rms_N,
        "beta": result.beta,
    }
    if args.plot:
        from vic_drake.reproduce.plots.offline import plot_load_test

        plot_load_test(result, title=str(args.bag_dir), save_path=args.plot)
        say(f"wrote {args.plot}")
    kv, hc = result.kelvin_voigt, result.hunt_crossley
    human = "\n".join(
        [
            f"load test {args.bag_dir}, models fitted on {args.fit_from}",
            f"sensor lag {result.lag_s * 1e3:.1f} ms; {int(result.mask.sum())} samples "
            "in contact",
            f"Kelvin-Voigt (k = {kv.k:.1f} N/m, d = {kv.d:.2f} N s/m): "
            f"RMS error {result.kelvin_voigt_rms_N:.3f} N",
            f"Hunt-Crossley beta = {result.beta:g} (kappa = {hc.kappa:.1f}, "
            f"lambda = {hc.lam:.1f}): RMS error {result.hunt_crossley_rms_N:.3f} N",
        ]
    )
    emit(out, args.json, human)
    return 0


def register(subparsers) -> None:
    """Adds ``fit-palpation`` and ``load-test``."""
    p = subparsers.add_parser(
        "fit-palpation",
        help="fit Kelvin-Voigt and Hunt-Crossley to a palpation bag (Table I)",
        description=help_text(__doc__, 1) + " " + _RELATIVE_HELP,
    )
    p.add_argument(
        "bag_dir",
        metavar="BAG_DIR",
        help="6-column palpation bag folder (absolute, relative, or relative to the "
        "data folder, e.g. palpation/test_soft_1hz)",
    )
    p.add_argument(
        "--betas",
        default=",".join(f"{b:g}" for b in TABLE_I_BETAS),
        metavar="B1,B2,...",
        help="Hunt-Crossley exponents to report, each in (0, 3] (default %(default)s)",
    )
    _add_fit_options(p)
    p.add_argument("--plot", default=None, metavar="FILE", help="save a summary figure")
    add_bag_data_dir_option(p)
    add_json_option(p)
    p.set_defaults(handler=_fit_palpation)

    q = subparsers.add_parser(
        "load-test",
        help="predict a load/unload test with models fitted on a palpation (Fig. 2)",
        description=help_text(__doc__, 2),
    )
    q.add_argument(
        "bag_dir",
        metavar="BAG_DIR",
        help="6-column load-test bag folder (absolute, relative, or relative to the "
        "data folder, e.g. loadcycle/test_soft_1)",
    )
    q.add_argument(
        "--fit-from",
        required=True,
        metavar="PALPATION_BAG_DIR",
        help="palpation bag the model parameters are fitted on (found as BAG_DIR, "
        "e.g. palpation/test_soft_1hz)",
    )
    q.add_argument(
        "--beta",
        type=float,
        default=1.35,
        help="Hunt-Crossley exponent, in (0, 3] (default %(default)s)",
    )
    _add_fit_options(q)
    q.add_argument("--plot", default=None, metavar="FILE", help="save the Fig. 2 plot")
    add_bag_data_dir_option(q)
    add_json_option(q)
    q.set_defaults(handler=_load_test)
