"""The offline figures (vic_drake.reproduce.plots.offline) drawn from
palpation results on a synthetic comparison."""

from tests.estimation.palpation.synthetic import synthetic_palpation
from vic_drake.estimation.palpation import (
    compare_models,
    residual_vs_palpation_time,
    shift,
)


def test_offline_figures(tmp_path):
    from matplotlib.figure import Figure

    from vic_drake.reproduce.plots.offline import (
        plot_beta_sweep,
        plot_lag_profile,
        plot_palpation_summary,
        plot_residual_vs_time,
        plot_table_i,
    )

    data = synthetic_palpation(lag_s=0.02, noise_N=0.05, duration_s=8.0)
    comparison = compare_models(data)
    curve = residual_vs_palpation_time(shift(data, comparison.lag_s))
    figures = [
        plot_table_i({"synthetic": comparison, "again": comparison}),
        plot_beta_sweep(comparison.sweep),
        plot_residual_vs_time({"synthetic": curve}),
        plot_lag_profile(comparison.lag_profile),
        plot_palpation_summary(
            comparison, title="synthetic", save_path=tmp_path / "s.png"
        ),
    ]
    assert all(isinstance(f, Figure) for f in figures)
    # Bars: 4 models x 2 logs.
    assert len(figures[0].axes[0].patches) == 8
    assert (tmp_path / "s.png").stat().st_size > 10_000
