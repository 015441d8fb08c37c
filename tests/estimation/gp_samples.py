"""A smooth test field and its noisy samples, shared by the GP tests."""

import numpy as np


def field(x, y):
    return 4000.0 + 1500.0 * np.sin(x / 0.02) * np.cos(y / 0.04)


def noisy_samples():
    """(x, y, values): the field on a 1 cm grid with 1 % noise."""
    x, y = np.meshgrid(
        np.arange(0.0, 0.1001, 0.01), np.arange(0.0, 0.0801, 0.01), indexing="ij"
    )
    x, y = x.ravel(), y.ravel()
    rng = np.random.default_rng(0)
    return x, y, field(x, y) * (1 + 0.01 * rng.standard_normal(x.size))
