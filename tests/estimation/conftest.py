"""Fixtures of the GP map tests: noisy samples of a smooth field, a fitted GP."""

import pytest

from vic_drake.estimation.gp_fit import fit_gp

from .gp_samples import noisy_samples


@pytest.fixture(scope="module")
def samples():
    return noisy_samples()


@pytest.fixture(scope="module")
def gp(samples):
    return fit_gp(*samples)
