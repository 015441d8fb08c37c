"""NoiseTable: each channel's noise is its own (seed, id), replayed by time."""

import numpy as np
import pytest

from vic_drake.systems.noise_table import NoiseTable, channel_noise


def test_a_channels_noise_depends_only_on_the_seed_and_its_id():
    table = channel_noise(7, [4, 9, 2], 500)
    assert table.shape == (500, 3)
    np.testing.assert_array_equal(table[:, 1], channel_noise(7, [9], 500)[:, 0])
    assert not np.array_equal(table[:, 0], channel_noise(8, [4], 500)[:, 0])
    assert not np.array_equal(table[:, 0], table[:, 2])
    # Unit Gaussian samples.
    big = channel_noise(1, [0], 20_000)[:, 0]
    assert abs(big.mean()) < 0.03 and abs(big.std() - 1.0) < 0.03


def test_the_output_is_the_row_of_the_nearest_sample_time():
    system = NoiseTable(2, 0.002, 10)
    context = system.CreateDefaultContext()
    system.set_noise(context, seed=5, ids=[3, 1])
    expected = channel_noise(5, [3, 1], 10)
    port = system.get_output_port(0)
    for t, row in ((0.0, 0), (0.0009, 0), (0.0011, 1), (0.004, 2), (1.0, 9)):
        context.SetTime(t)
        np.testing.assert_array_equal(port.Eval(context), expected[row])


def test_wrong_number_of_ids_is_refused():
    system = NoiseTable(2, 0.002, 10)
    with pytest.raises(ValueError, match="2 channel ids needed; got 3"):
        system.set_noise(system.CreateDefaultContext(), seed=0, ids=[0, 1, 2])
