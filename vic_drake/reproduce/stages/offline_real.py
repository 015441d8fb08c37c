"""Stage ``offline_real``: Table I, beta sweep, Fig. 3 and the load test
(Fig. 2) on the paper's palpation logs."""

from __future__ import annotations

from vic_drake.realdata import read_bag
from vic_drake.reproduce.context import RunContext, StageSkipped
from vic_drake.reproduce.stages.offline_fits import offline_fits

#: The paper's palpation logs (Table I, Fig. 3) and the load test (Fig. 2).
REAL_PALPATION_LOGS = ("test_soft_1hz", "test_soft_2hz", "test_soft_25hz")
REAL_LOAD_LOG = "test_soft_1"


def stage_offline_real(ctx: RunContext) -> dict:
    """Table I, the beta sweep, residual vs time and the load test on real logs."""
    if ctx.data_dir is None:
        raise StageSkipped("no real data (pass --data-dir or set VIC_DRAKE_DATA)")
    # Function-local: the fits pull in scipy and the plots matplotlib (heavy).
    from vic_drake.estimation.loadtest import load_test
    from vic_drake.estimation.palpation import PalpationData
    from vic_drake.reproduce.plots.offline import plot_load_test

    logs = {}
    for name in REAL_PALPATION_LOGS:
        path = ctx.data_dir / "palpation" / name
        logs[name] = (
            PalpationData.from_frame(read_bag(path, expect="palpation")),
            None,
        )
    out = offline_fits(ctx, logs, "real")
    load = PalpationData.from_frame(
        read_bag(ctx.data_dir / "loadcycle" / REAL_LOAD_LOG, expect="palpation")
    )
    first = REAL_PALPATION_LOGS[0]
    lt = load_test(load, logs[first][0], lag_s=out["comparisons"][first].lag_s)
    ctx.add_figure(
        "Fig. 2 (real): load test",
        f"Load/unload test {REAL_LOAD_LOG} against Kelvin-Voigt and Hunt-Crossley "
        f"fitted on {first} (paper's Fig. 2).",
        plot_load_test(lt),
        "fig2_load_test_real.png",
    )
    out["load_test"] = {
        "kelvin_voigt_rms_N": lt.kelvin_voigt_rms_N,
        "hunt_crossley_rms_N": lt.hunt_crossley_rms_N,
    }
    return out
