"""Campaign statistics: exceedance probability with its interval, per controller."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from vic_drake.paper import CONTACT_THRESHOLD_N

#: z of a two-sided 95 % interval.
Z95 = 1.959963984540054

#: The fewest runs of one controller from which factor effects are computed.
#: With n runs a perfect rank correlation has the exact two-sided p 2 / n!:
#: 0.083 at n = 4, which chance alone gives; 0.017 at n = 5.
MIN_EFFECT_RUNS = 5


def wilson_interval(successes: int, n: int, z: float = Z95) -> tuple[float, float]:
    """Wilson score interval of a binomial proportion (NaN, NaN for n = 0).

    Unlike the normal approximation it stays inside [0, 1] and is not empty
    at 0 or n successes, which a safety campaign with no exceedance needs.
    """
    if n <= 0:
        return (math.nan, math.nan)
    p = successes / n
    denom = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / denom
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / denom
    # At 0 or n successes the bound is exactly 0 or 1 (the difference of
    # centre and half would leave a rounding residue such as 3e-17).
    low = 0.0 if successes == 0 else max(0.0, centre - half)
    high = 1.0 if successes == n else min(1.0, centre + half)
    return (low, high)


def _finite(values) -> np.ndarray:
    v = np.asarray(values, float)
    return v[np.isfinite(v)]


def _stat(values, fn) -> float:
    v = _finite(values)
    return float(fn(v)) if v.size else math.nan


def touched(peak_force_N) -> np.ndarray:
    """Which runs touched the patient: a peak tissue force above
    :data:`~vic_drake.paper.CONTACT_THRESHOLD_N` (False for NaN)."""
    return np.asarray(peak_force_N, float) > CONTACT_THRESHOLD_N


def _count_finite(rows: pd.DataFrame, column: str) -> int:
    """Rows with a finite ``column`` (0 for rows written before it existed)."""
    if column not in rows:
        return 0
    return int(np.isfinite(pd.to_numeric(rows[column], errors="coerce")).sum())


def per_controller(rows: pd.DataFrame, force_limit_N: float) -> dict:
    """{controller: runs, peak force p50/max, exceedance and CI, contact loss,
    tank min, runs the sensor's watchdog stopped, runs without contact}.

    Runs with status "error" count in ``runs`` but not in the statistics;
    a NaN run's peak force is its finite part's maximum (its row says NaN).
    ``exceed_prob`` is the share of scored runs whose peak force exceeds the
    force limit. ``no_contact_runs`` counts the scored runs whose peak force
    never rose above :data:`~vic_drake.paper.CONTACT_THRESHOLD_N` (e.g. the
    sensor's watchdog stopped them before the probe reached the patient):
    they stay in ``exceed_prob`` (they did not exceed) and in
    ``peak_force_N_p50`` (every scored run), but not in
    ``peak_force_N_p50_contact``, the median of the runs that touched.
    """
    out = {}
    if rows.empty:
        return out
    for name, group in rows.groupby("factor.controller", sort=True):
        scored = group[group["status"] != "error"]
        peaks = _finite(scored["peak_force_N"])
        in_contact = touched(peaks)
        exceed = int(np.sum(peaks > force_limit_N))
        lo, hi = wilson_interval(exceed, peaks.size)
        out[str(name)] = {
            "runs": int(len(group)),
            "peak_force_N_p50": _stat(peaks, np.median),
            "peak_force_N_max": _stat(peaks, np.max),
            "exceed_prob": exceed / peaks.size if peaks.size else math.nan,
            "exceed_prob_ci95": [lo, hi],
            "contact_loss_s_p50": _stat(scored["contact_loss_s"], np.median),
            "tank_min_J": _stat(scored["tank_min_J"], np.min),
            "watchdog_stops": _count_finite(scored, "watchdog_trip_s"),
            "no_contact_runs": int(np.sum(~in_contact)),
            "peak_force_N_p50_contact": _stat(peaks[in_contact], np.median),
        }
    return out


def _is_numeric(column: pd.Series) -> bool:
    """A numeric factor, however few values it takes (bools are labels)."""
    return pd.api.types.is_numeric_dtype(column) and not pd.api.types.is_bool_dtype(
        column
    )


#: A numeric factor with at most this many values is summarised per value.
MAX_LEVELS = 3


def factor_effects(rows: pd.DataFrame, metric: str = "peak_force_N") -> list[dict]:
    """Each factor's effect on a metric, per controller.

    One entry per factor and controller, by ``kind``:

    - ``too_few``: the controller has fewer than :data:`MIN_EFFECT_RUNS`
      scored runs with the metric (``runs``): no effect is computed;
    - ``constant``: the factor took one ``value`` in its runs;
    - ``numeric`` (a numeric factor with more than
      :data:`MAX_LEVELS` values): Spearman's rank correlation with its
      two-sided p and the runs, and the metric's median in the factor's
      lowest and highest third;
    - ``levels`` (a label factor, or a numeric one with at most
      :data:`MAX_LEVELS` values, e.g. a choice of two): the metric's median
      and the runs per value.
    """
    effects = []
    ok = rows[(rows["status"] != "error") & np.isfinite(rows[metric].astype(float))]
    factor_cols = [
        c for c in rows.columns if c.startswith("factor.") and c != "factor.controller"
    ]
    groups = list(ok.groupby("factor.controller", sort=True))
    for col in factor_cols:
        numeric = _is_numeric(rows[col])
        for name, group in groups:
            entry = {"factor": col[len("factor.") :], "controller": str(name)}
            if numeric:  # A run without the factor's value is no point.
                group = group[np.isfinite(group[col].to_numpy(float))]
            x = group[col]
            y = group[metric].to_numpy(float)
            if len(group) < MIN_EFFECT_RUNS:
                entry.update(kind="too_few", runs=int(len(group)))
            elif x.nunique() == 1:
                value = x.iloc[0]
                if isinstance(value, np.generic):
                    value = value.item()
                entry.update(kind="constant", value=value)
            elif numeric and x.nunique() > MAX_LEVELS:
                xv = x.to_numpy(float)
                rho, p = _spearman(xv, y)
                lo, hi = np.quantile(xv, [1 / 3, 2 / 3])
                entry.update(
                    kind="numeric",
                    spearman=rho,
                    spearman_p=p,
                    runs=int(len(group)),
                    low_third_median=_stat(y[xv <= lo], np.median),
                    high_third_median=_stat(y[xv >= hi], np.median),
                )
            else:
                if numeric:  # A few numbers: by value, in order, as text.
                    x = x.astype(float).map(lambda v: f"{v:g}")
                    order = sorted(x.unique(), key=float)
                else:
                    order = sorted(x.astype(str).unique())
                levels = dict(list(group.groupby(x.astype(str), sort=False)))
                levels = [(k, levels[k]) for k in order]
                entry.update(
                    kind="levels",
                    medians={k: _stat(g[metric], np.median) for k, g in levels},
                    runs={k: int(len(g)) for k, g in levels},
                )
            effects.append(entry)
    return effects


def _spearman(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """Spearman's rho (rounded to 12 digits: a zero reads 0, not 3e-17) and
    its two-sided p; NaN where either side is constant."""
    from scipy.stats import spearmanr

    if np.ptp(x) == 0 or np.ptp(y) == 0:
        return math.nan, math.nan
    result = spearmanr(x, y)
    return round(float(result.statistic), 12), float(result.pvalue)


def _discordant(a: np.ndarray, b: np.ndarray) -> dict:
    """Counts of a binary outcome over pairs, and the exact McNemar p."""
    from scipy.stats import binomtest

    only_a, only_b = int(np.sum(a & ~b)), int(np.sum(b & ~a))
    n = only_a + only_b
    p = binomtest(only_a, n, 0.5).pvalue if n else 1.0
    return {
        "both": int(np.sum(a & b)),
        "only_first": only_a,
        "only_second": only_b,
        "mcnemar_p": float(p),
    }


def _pair_keys(ok: pd.DataFrame, grid_size: int) -> pd.Series:
    """A run's pair: its grid round and its values of every factor that
    varies within an arm (the other grid factors' cells; the drawn factors,
    shared in a paired round). A factor that holds one value per arm makes
    the arm (``controller``, ``controller.reference.controller``,
    ``watchdog.enabled``, ...) and is left out, or no two arms would pair."""
    key = (ok["index"] // grid_size).astype(str)
    arms = ok["factor.controller"].astype(str)
    for column in sorted(ok.columns):
        if not column.startswith("factor.") or column == "factor.controller":
            continue
        values = ok[column].astype(str)
        if values.groupby(arms).nunique().max() > 1:
            key = key + "|" + values
    return key


def _one_run_per_key(arm: pd.DataFrame) -> pd.DataFrame:
    """An arm's runs by pair key; a key held twice (one arm twice in a
    cell) pairs with nothing."""
    arm = arm.set_index("_pair")
    return arm[~arm.index.duplicated(keep=False)]


def paired_arms(rows: pd.DataFrame, grid_size: int, force_limit_N: float) -> list[dict]:
    """The arms compared run for run in a paired campaign (the runs of one grid
    round share every draw: ``paired: true``), for each two arms in name order.

    A pair is two runs of one round that differ only in their arm: with
    other grid factors (e.g. a breathing amplitude), each of their cells
    pairs apart. Pairs where either run failed are left out. For each: the
    pairs, the peak force difference (second minus first: median, 10 and 90
    %), and the pairs where one arm, the other or both lost contact or
    exceeded the force limit, with the exact McNemar p of the discordant
    pairs.
    """
    if rows.empty or grid_size < 2:
        return []
    ok = rows[rows["status"] == "ok"]
    ok = ok.assign(_pair=_pair_keys(ok, grid_size))
    arms = sorted(str(a) for a in ok["factor.controller"].unique())
    out = []
    for i, first in enumerate(arms):
        for second in arms[i + 1 :]:
            a = _one_run_per_key(ok[ok["factor.controller"] == first])
            b = _one_run_per_key(ok[ok["factor.controller"] == second])
            common = a.index.intersection(b.index)
            if not common.size:
                continue
            a, b = a.loc[common], b.loc[common]
            diff = _finite(b["peak_force_N"] - a["peak_force_N"])
            p10, p50, p90 = (
                np.quantile(diff, [0.1, 0.5, 0.9]) if diff.size else [math.nan] * 3
            )
            out.append(
                {
                    "first": first,
                    "second": second,
                    "pairs": int(common.size),
                    "peak_force_diff_N_p50": float(p50),
                    "peak_force_diff_N_p10": float(p10),
                    "peak_force_diff_N_p90": float(p90),
                    "contact_loss": _discordant(
                        (a["contact_loss_s"] > 0).to_numpy(),
                        (b["contact_loss_s"] > 0).to_numpy(),
                    ),
                    "exceedance": _discordant(
                        (a["peak_force_N"] > force_limit_N).to_numpy(),
                        (b["peak_force_N"] > force_limit_N).to_numpy(),
                    ),
                }
            )
    return out


def worst_runs(rows: pd.DataFrame, n: int = 10) -> pd.DataFrame:
    """The n worst runs: failed ones first, then by peak force, then contact loss."""
    if rows.empty:
        return rows
    order = rows.assign(
        _failed=(rows["status"] != "ok").astype(int),
        _peak=rows["peak_force_N"].fillna(np.inf),
    ).sort_values(["_failed", "_peak", "contact_loss_s"], ascending=False)
    return order.drop(columns=["_failed", "_peak"]).head(n)


__all__ = [
    "MIN_EFFECT_RUNS",
    "Z95",
    "factor_effects",
    "paired_arms",
    "per_controller",
    "touched",
    "wilson_interval",
    "worst_runs",
]
