"""Signal conditioning: smoothed derivatives and lag shifts on uneven timestamps."""

import numpy as np
import pytest

from vic_drake.errors import VicDrakeError
from vic_drake.estimation.signals import shift_signal, smoothed_derivatives


def test_smoothed_derivatives_of_sinusoid_on_uneven_timestamps():
    rng = np.random.default_rng(1)
    t = 0.002 * np.arange(5000) + rng.uniform(-2e-4, 2e-4, 5000)
    w = 2 * np.pi * 2.5
    x = 0.002 * np.sin(w * t)
    xs, xd, xdd = smoothed_derivatives(t, x)
    inner = slice(50, -50)
    np.testing.assert_allclose(xs[inner], x[inner], atol=0.002 * 2e-3)
    np.testing.assert_allclose(
        xd[inner], 0.002 * w * np.cos(w * t[inner]), atol=0.002 * w * 1e-2
    )
    np.testing.assert_allclose(
        xdd[inner], -0.002 * w**2 * np.sin(w * t[inner]), atol=0.002 * w**2 * 3e-2
    )


def test_smoothed_derivatives_exact_for_cubic():
    t = 0.002 * np.arange(400)
    x = 1.0 + 2.0 * t - 3.0 * t**2 + 0.5 * t**3
    xs, xd, xdd = smoothed_derivatives(t, x)
    np.testing.assert_allclose(xs, x, atol=1e-10)
    np.testing.assert_allclose(xd, 2.0 - 6.0 * t + 1.5 * t**2, atol=1e-8)
    np.testing.assert_allclose(xdd, -6.0 + 3.0 * t, atol=1e-6)


def test_smoothed_derivatives_bad_input():
    with pytest.raises(VicDrakeError, match="increase"):
        smoothed_derivatives([0.0, 0.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(VicDrakeError, match="window"):
        smoothed_derivatives(0.002 * np.arange(10), np.zeros(10))


def test_shift_signal_advances_a_ramp():
    t = np.array([0.0, 0.0021, 0.0039, 0.0061, 0.008])
    out = shift_signal(t, 3.0 * t, 0.002)
    np.testing.assert_allclose(out[:3], 3.0 * (t[:3] + 0.002))
    assert np.isnan(out[3:]).all()  # t + lag past the last sample.
