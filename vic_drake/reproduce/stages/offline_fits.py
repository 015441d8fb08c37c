"""The offline fits shared by ``offline_real`` and ``offline_sim``.

Table I (Kelvin-Voigt and Hunt-Crossley per beta), the beta sweep and the
residual against palpation time (Fig. 3) on a set of palpation logs, with
their report table and figures.
"""

from __future__ import annotations

import numpy as np

from vic_drake.analysis import claims as claims_mod
from vic_drake.paper import BEST_BETA, TABLE_I_BETAS, paper_table_i
from vic_drake.reproduce.context import RunContext
from vic_drake.reproduce.report import ReportTable


def offline_fits(ctx: RunContext, logs: dict, label: str) -> dict:
    """Table I fits and residual-vs-time curves on {name: PalpationData}.

    Args:
        logs: {name: (PalpationData, lag_s or None)}.
        label: "real" or "sim" (figure names and titles).
    """
    # Function-local: the fits pull in scipy and the plots matplotlib (heavy).
    from vic_drake.estimation.palpation import (
        compare_models,
        residual_vs_palpation_time,
        shift,
    )
    from vic_drake.reproduce.plots.offline import (
        plot_beta_sweep,
        plot_residual_vs_time,
        plot_table_i,
    )

    comparisons, curves = {}, {}
    for name, (data, lag) in logs.items():
        ctx.progress(f"  {label}: fitting {name} ({data.duration_s:.0f} s)")
        comparisons[name] = compare_models(data, TABLE_I_BETAS, lag_s=lag)
        curves[name] = residual_vs_palpation_time(shift(data, comparisons[name].lag_s))
    kv = float(np.mean([c.kelvin_voigt.relative for c in comparisons.values()]))
    hc = {
        b: float(np.mean([c.hunt_crossley[b].relative for c in comparisons.values()]))
        for b in TABLE_I_BETAS
    }
    residuals = claims_mod.ModelResiduals(kv, hc)
    paper = paper_table_i()
    betas = TABLE_I_BETAS  # The paper's column order, as the figure's bars.
    rows = []
    for name, c in comparisons.items():
        rows.append(
            [
                name,
                c.lag_s * 1e3,
                c.kelvin_voigt.relative,
                *(c.hunt_crossley[b].relative for b in betas),
                c.best_beta,
            ]
        )
    rows.append(["mean", None, kv, *(hc[b] for b in betas), None])
    rows.append(
        [
            "paper",
            None,
            paper["kelvin_voigt"],
            *(paper[f"hc_{b:g}"] for b in betas),
            BEST_BETA,
        ]
    )
    ctx.tables.append(
        ReportTable(
            f"Table I ({label}): relative residual per model",
            [
                "log",
                "lag [ms]",
                "Kelvin-Voigt",
                *(f"HC beta={b:g}" for b in betas),
                "best beta (sweep)",
            ],
            rows,
            "Relative residual = RMS least-squares residual / RMS fitted force over the "
            "in-contact samples (vic_drake.estimation.palpation). The paper does not define "
            "its number: compare orderings.",
        )
    )
    ctx.add_figure(
        f"Table I ({label})",
        "Relative residual of Kelvin-Voigt and "
        "Hunt-Crossley fits; black bars: the paper's values.",
        plot_table_i(comparisons),
        f"table1_{label}.png",
    )
    ctx.add_figure(
        f"Beta sweep ({label})",
        "Hunt-Crossley relative residual against "
        "beta; dotted: best beta per log, dashed: the paper's 1.35.",
        plot_beta_sweep({n: c.sweep for n, c in comparisons.items()}),
        f"beta_sweep_{label}.png",
    )
    skipped = ", ".join(
        f"{n} {c.approach.cycles_skipped}"
        for n, c in curves.items()
        if c.approach is not None
    )
    ctx.add_figure(
        f"Fig. 3 ({label}): residual vs palpation time",
        "Relative residual on the whole palpation of the parameters fitted on its "
        "first T seconds, with an exponential fit (paper's Fig. 3). The palpation "
        "starts after the approach: the whole cycles in which the probe still sank "
        f"towards its operating depth are left out (cycles skipped: {skipped}).",
        plot_residual_vs_time(curves),
        f"fig3_residual_vs_time_{label}.png",
    )
    decay = {n: (c.window_s, c.relative) for n, c in curves.items()}
    return {
        "comparisons": comparisons,
        "curves": curves,
        "residuals": residuals,
        "decay": decay,
    }
