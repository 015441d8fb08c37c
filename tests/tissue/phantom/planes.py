"""A grid phantom of planes, whose bilinear lookup is exact."""

import numpy as np

from vic_drake.tissue import GridPhantom


def plane_phantom(**kwargs):
    x = np.linspace(0.0, 0.1, 11)
    y = np.linspace(0.0, 0.05, 6)
    X, Y = np.meshgrid(x, y, indexing="ij")
    return GridPhantom(
        x_m=x,
        y_m=y,
        z_m=0.1 + 0.2 * X - 0.1 * Y,
        kappa=1000 + 1e4 * X,
        lam=2e4 + 0 * X,
        beta=1.35,
        **kwargs,
    )
