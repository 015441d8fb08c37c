"""The map figures (vic_drake.reproduce.plots.maps) on the synthetic chest's
exact map: every panel on the same cm axes, the ribs where they are."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from vic_drake.estimation.tissue_map import TissueMap, map_axis
from vic_drake.tissue import SyntheticChestPhantom

REGION = (-0.16, 0.04, -0.38, -0.34)


@pytest.fixture(scope="module")
def exact_map():
    phantom = SyntheticChestPhantom()
    xs = map_axis(REGION[0], REGION[1], 0.002)
    ys = map_axis(REGION[2], REGION[3], 0.002)
    truth = phantom.sample(*np.meshgrid(xs, ys, indexing="ij"))
    points = pd.DataFrame(
        {
            "x_m": [-0.1, 0.0],
            "y_m": [-0.36, -0.35],
            "surface_z_m": [0.0, 0.0],
            "ok": [True, True],
        }
    )
    return TissueMap(
        xs,
        ys,
        truth.surface_z_m,
        truth.kappa,
        truth.lam,
        0.05 * truth.kappa,
        0.05 * truth.lam,
        1.35,
        points,
        None,
        "",
        "",
        {},
    )


def _extent_cm(ax):
    return ax.get_images()[0].get_extent()


def test_every_map_figure_is_drawn_in_cm(exact_map, tmp_path):
    from vic_drake.reproduce.plots.maps import (
        plot_map_vs_truth,
        plot_maps_vs_paper,
        plot_std_maps,
        plot_stiffness_damping_maps,
        plot_surface_kappa,
    )

    paper = SimpleNamespace(
        x_m=exact_map.x_m, y_m=exact_map.y_m, kappa=exact_map.kappa, lam=exact_map.lam
    )
    figures = [
        plot_stiffness_damping_maps(exact_map),
        plot_std_maps(exact_map),
        plot_map_vs_truth(exact_map, exact_map.kappa),
        plot_maps_vs_paper(exact_map, paper, ribs_m=[-0.05], paper_ribs_m=[-0.05]),
        plot_maps_vs_paper(exact_map, save_path=tmp_path / "m.png"),
        plot_surface_kappa(exact_map),
    ]
    for fig in figures:
        for ax in fig.axes:
            if ax.get_label() == "<colorbar>":
                continue
            assert ax.get_xlabel() == "x [cm]", fig
            if ax.get_images():
                np.testing.assert_allclose(
                    _extent_cm(ax), [100 * v for v in REGION], atol=1e-9
                )
    assert (tmp_path / "m.png").stat().st_size > 10_000


def test_maps_vs_paper_draws_both_maps_and_their_ribs(exact_map):
    from vic_drake.reproduce.plots.maps import plot_maps_vs_paper

    paper = SimpleNamespace(
        x_m=exact_map.x_m, y_m=exact_map.y_m, kappa=exact_map.kappa, lam=exact_map.lam
    )
    fig = plot_maps_vs_paper(
        exact_map, paper, ribs_m=[-0.05, 0.01], paper_ribs_m=[-0.04]
    )
    panels = [ax for ax in fig.axes if ax.get_images()]
    assert len(panels) == 4
    rib_x = [[line.get_xdata()[0] for line in ax.get_lines()[1:]] for ax in panels]
    # Rib lines on the kappa panels only, in cm (the first line is the points).
    assert rib_x[0] == pytest.approx([-5.0, 1.0])
    assert [line.get_xdata()[0] for line in panels[2].get_lines()] == pytest.approx(
        [-4.0]
    )
    assert not panels[1].get_lines() and not panels[3].get_lines()
    assert "measured" in panels[2].get_title()
    # One colour scale per column, so the rows compare.
    clims = [ax.get_images()[0].get_clim() for ax in panels]
    assert clims[0] == clims[2] and clims[1] == clims[3]
    # Without the paper's map: one row.
    assert (
        len([ax for ax in plot_maps_vs_paper(exact_map).axes if ax.get_images()]) == 2
    )
