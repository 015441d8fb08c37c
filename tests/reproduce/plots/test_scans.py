"""The scan figures: no panel without information, and Jupyter shows them."""

import numpy as np

from tests.analysis.scans import make_scan


def _scan(k_varies: bool, tank_varies: bool):
    t = np.arange(0, 4, 0.01)
    return make_scan(
        t,
        6 + np.sin(t),
        z_m=0.09 - 0.001 * t,
        penetration_m=0.005 + 0.001 * np.sin(t),
        force_ref_z_N=np.full(t.size, -7.0),
        force_min_z_N=np.full(t.size, -15.0),
        stiffness_z_N_per_m=400 + (100 * np.sin(t) if k_varies else 0.0),
        tank_energy_J=1.0 - (0.1 * t if tank_varies else 0.0),
        surface_z_m=np.full(t.size, 0.095),
        phantom_lift_m=np.zeros(t.size),
    )


def _texts(ax):
    return " ".join(t.get_text() for t in ax.texts)


def test_flat_stiffness_and_tank_rows_are_not_drawn():
    from vic_drake.reproduce.plots.scans import plot_fig6, plot_fig7

    base = plot_fig6({"cs": _scan(False, False), "cf": _scan(False, False)})
    # Force and penetration only: CS's and CF's K_z and tank are constant.
    assert len(base.axes) == 2 * 2
    assert [a.get_ylabel() for a in base.axes[::2]] == [
        "pressing force (N)",
        "penetration (mm)",
    ]
    mixed = plot_fig7({"vs-vf": _scan(True, True), "cs": _scan(False, False)})
    grid = np.array(mixed.axes).reshape(3, 2)
    assert grid[2, 0].axison and grid[2, 0].get_ylabel() == "K_z (N/m)"
    # CS's K_z panel states the constant instead of a flat line.
    assert not grid[2, 1].axison
    assert "CS: K_z fixed at 400 N/m" in _texts(grid[2, 1])
    assert not grid[2, 1].lines


def test_plot_functions_return_figures_jupyter_shows():
    from vic_drake.reproduce.plots.scans import plot_fig6

    fig = plot_fig6({"vs-vf": _scan(True, True)})
    png = fig._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def _legend(ax):
    legend = ax.get_legend()
    return [] if legend is None else [t.get_text() for t in legend.get_texts()]


def test_the_force_bound_is_drawn_only_where_it_binds():
    """Issue: CS's and CF's legends listed "-F_min sim" for a line that had no
    visible point: the bound is 0 in the first sample (the controller's
    output before its first tick) and 15 N after."""
    from vic_drake.reproduce.plots.scans import plot_fig6

    unbound = _scan(False, False)
    unbound.loc[0, "force_min_z_N"] = 0.0
    bound = _scan(True, True)
    bound["force_min_z_N"] = np.where(bound["t_s"] > 2.0, -9.0, -15.0)
    fig = plot_fig6({"cs": unbound, "vs-vf": bound})
    grid = np.array(fig.axes).reshape(-1, 2)
    assert "-F_min sim" not in _legend(grid[0, 0])
    assert "-F_min sim" in _legend(grid[0, 1])
