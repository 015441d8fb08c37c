"""``vic-drake fit-relaxation``: the relaxing Hunt-Crossley law from palpation logs.

Fits one shared relaxation (g_i, tau_i) and per-log kappa, lambda to the
given 6-column palpation or load-test bags (each aligned by its own sensor
lag), beside plain Hunt-Crossley on the same samples; then scores the fitted
relaxation on the ``--held-out`` bags, where both laws refit only kappa and
lambda. The simulated tissue's default (``vic_drake.tissue.DEFAULT_RELAXATION``)
is this fit on the paper's three palpations.
"""

from __future__ import annotations

import math

from vic_drake.commands.common import (
    Progress,
    add_bag_data_dir_option,
    add_json_option,
    emit,
    help_text,
    parse_float_list,
)
from vic_drake.commands.offline import (
    _add_fit_options,
    _find_palpation,
    _read_palpation,
)
from vic_drake.errors import VicDrakeError


def _initial_time_constants(text: str | None) -> tuple[float, ...]:
    from vic_drake.estimation.relaxation_fit import DEFAULT_INITIAL_TIME_CONSTANTS_S

    if text is None:
        return DEFAULT_INITIAL_TIME_CONSTANTS_S
    taus = parse_float_list(text, "--tau0")
    for t in taus:
        if not (math.isfinite(t) and t > 0.0):
            raise VicDrakeError(f"--tau0 values must be > 0 s; got {t!r} in {text!r}")
    return tuple(taus)


def _aligned(bags: dict, args, say) -> tuple[dict, dict]:
    """{name: aligned PalpationData}, {name: lag_s} of found bags ({name: path}).

    Each log is aligned by its own estimated lag (or ``--lag``); a lag
    estimated at 0 (not identified: a load test has no sinusoid) takes the
    median of the other logs' identified lags, when there are any.
    """
    import numpy as np

    from vic_drake.estimation.palpation import estimate_lag, shift

    raw, lags = {}, {}
    for name, path in bags.items():
        data = _read_palpation(path)
        raw[name] = data
        lags[name] = (
            args.lag if args.lag is not None else estimate_lag(data, args.max_lag)
        )
    identified = [v for v in lags.values() if v > 0.0]
    if args.lag is None and identified:
        median = float(np.median(identified))
        lags = {n: v if v > 0.0 else median for n, v in lags.items()}
    for name, lag in lags.items():
        say(f"  {name}: sensor lag {lag * 1e3:.1f} ms")
    return {n: shift(d, lags[n]) for n, d in raw.items()}, lags


def _found(args, texts, role: str) -> dict:
    """{name as given: found bag path} (:func:`_find_palpation`), in order."""
    found = {}
    for text in texts:
        name = text.rstrip("/")
        if name in found:
            raise VicDrakeError(f"{role} {text!r} is given twice")
        found[name] = _find_palpation(args, text, role)
    return found


def _fit_relaxation(args) -> int:
    import numpy as np

    from vic_drake.estimation.palpation import estimate_lag, shift
    from vic_drake.estimation.relaxation_fit import fit_relaxation, held_out_errors

    say = Progress(enabled=not args.json)
    taus = _initial_time_constants(args.tau0)
    if args.lag is not None and not (math.isfinite(args.lag) and args.lag >= 0.0):
        raise VicDrakeError(f"--lag must be a finite number >= 0; got {args.lag!r}")
    if args.max_tau is not None and not (
        math.isfinite(args.max_tau) and args.max_tau > max(taus)
    ):
        raise VicDrakeError(
            f"--max-tau must exceed every --tau0 ({max(taus):g} s); got {args.max_tau!r}"
        )
    # Every path, fitted and held out, is found before any log is read, so a
    # bad one fails at once.
    bags = _found(args, args.bags, "bag")
    held_paths = _found(args, args.held_out, "held-out bag")
    say(f"fitting {len(taus)} relaxation branch(es) on {len(args.bags)} log(s)")
    logs, lags = _aligned(bags, args, say)
    # Each held-out log is aligned by its own lag; a lag estimated at 0 (not
    # identified: a load test has no sinusoid) takes the fitted logs' median
    # instead.
    held_raw = {n: _read_palpation(p) for n, p in held_paths.items()}
    fit = fit_relaxation(
        logs,
        beta=args.beta,
        initial_time_constants_s=taus,
        max_time_constant_s=args.max_tau,
        indenter_mass_kg=args.indenter_mass,
    )
    median_lag = float(np.median(list(lags.values())))
    held_lags = {}
    for name, data in held_raw.items():
        lag = args.lag if args.lag is not None else estimate_lag(data, args.max_lag)
        held_lags[name] = lag if lag > 0.0 else median_lag
    held = held_out_errors(
        fit.relaxation,
        {n: shift(d, held_lags[n]) for n, d in held_raw.items()},
        beta=args.beta,
        indenter_mass_kg=args.indenter_mass,
    )
    rel = fit.relaxation
    out = {
        "beta": fit.beta,
        "relaxation": {
            **rel.as_dict(),
            "long_term_fraction": rel.long_term_fraction,
        },
        "fitted": {
            n: {
                "lag_s": lags[n],
                "kappa": fit.kappa[n],
                "lam": fit.lam[n],
                "rms_N": fit.rms_N[n],
                "hc_kappa": fit.hc_kappa[n],
                "hc_lam": fit.hc_lam[n],
                "hc_rms_N": fit.hc_rms_N[n],
            }
            for n in logs
        },
        "held_out": {
            n: {
                "lag_s": held_lags[n],
                "rms_N": e.relaxing_rms_N,
                "hc_rms_N": e.hc_rms_N,
                "kappa": e.kappa,
                "lam": e.lam,
                "hc_kappa": e.hc_kappa,
                "hc_lam": e.hc_lam,
                "samples": e.n_samples,
                "phases": e.phases,
            }
            for n, e in held.items()
        },
    }
    branches = ", ".join(
        f"g = {g:.3f}, tau = {t:.1f} s"
        for g, t in zip(rel.fractions, rel.time_constants_s)
    )
    lines = [
        f"relaxation: {branches} (long-term fraction {rel.long_term_fraction:.3f})"
    ]
    lines += [
        f"  fitted {n}: RMS {v['rms_N']:.4f} N relaxing, {v['hc_rms_N']:.4f} N plain HC"
        for n, v in out["fitted"].items()
    ]
    for n, v in out["held_out"].items():
        lines.append(
            f"  held out {n}: RMS {v['rms_N']:.4f} N relaxing, {v['hc_rms_N']:.4f} N "
            "plain HC"
        )
        for phase, p in (v["phases"] or {}).items():
            lines.append(
                f"    {phase:8s} RMS {p['rms_N']:.4f} N (mean {p['mean_N']:+.4f}) "
                f"relaxing, {p['hc_rms_N']:.4f} N ({p['hc_mean_N']:+.4f}) plain HC"
            )
    emit(out, args.json, "\n".join(lines))
    return 0


def register(subparsers) -> None:
    """Adds ``fit-relaxation``."""
    p = subparsers.add_parser(
        "fit-relaxation",
        help="fit the relaxing Hunt-Crossley law to palpation logs, score held-out logs",
        description=help_text(__doc__, 1),
    )
    p.add_argument(
        "bags",
        nargs="+",
        metavar="BAG_DIR",
        help="6-column palpation or load-test bags to fit on (absolute, relative, or "
        "relative to the data folder, e.g. palpation/test_soft_1hz)",
    )
    p.add_argument(
        "--held-out",
        nargs="+",
        default=[],
        metavar="BAG_DIR",
        help="bags scored with the fitted relaxation (kappa, lambda refit on each; "
        "each aligned by its own lag, or by the fitted logs' median lag where its "
        "own is not identified)",
    )
    p.add_argument(
        "--tau0",
        default=None,
        metavar="S1,S2,...",
        help="starting time constants, s; their count is the number of branches "
        "(default: 5, one branch)",
    )
    p.add_argument(
        "--max-tau",
        type=float,
        default=None,
        metavar="S",
        help="upper bound of every time constant, s (default: the longest log)",
    )
    p.add_argument(
        "--beta",
        type=float,
        default=1.35,
        help="Hunt-Crossley exponent, in (0, 3] (default %(default)s)",
    )
    _add_fit_options(p)
    add_bag_data_dir_option(p)
    add_json_option(p)
    p.set_defaults(handler=_fit_relaxation)
