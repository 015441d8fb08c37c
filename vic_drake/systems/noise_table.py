"""Sensor noise that belongs to each channel: :class:`NoiseTable`.

Drake's ``RandomSource`` draws all its channels from one generator, so a
channel's noise depends on how many channels share the source and in which
order. The palpation campaign simulates its points in batches whose split
follows the number of workers; with one source per batch, a point's noise
(and so its fit) moved with the number of workers. Here each channel's
samples are drawn up front from a generator of its own, seeded with
``(seed, channel id)`` (:func:`channel_noise`), and replayed by time.
"""

from __future__ import annotations

import math

import numpy as np
from pydrake.common.value import AbstractValue
from pydrake.systems.framework import AbstractParameterIndex, LeafSystem


def channel_noise(seed: int, ids, samples: int) -> np.ndarray:
    """(samples, len(ids)) unit Gaussian samples; column j depends only on
    ``seed`` and ``ids[j]`` (numpy's default generator seeded with both)."""
    ids = np.asarray(ids, dtype=np.int64).ravel()
    table = np.empty((int(samples), ids.size))
    for j, channel in enumerate(ids):
        rng = np.random.default_rng([int(seed), int(channel)])
        table[:, j] = rng.standard_normal(int(samples))
    return table


class NoiseTable(LeafSystem):
    """Output ``noise`` (n): row k of a (samples, n) table of unit Gaussian
    samples, k the sample (k period) nearest the context's time; the last
    row after the table ends. The table is an abstract parameter
    (:meth:`set_noise`); by default ``channel_noise(0, range(n), samples)``."""

    def __init__(self, n: int, period_s: float, samples: int):
        super().__init__()
        self._n = int(n)
        self._period = float(period_s)
        self._table = self.DeclareAbstractParameter(
            AbstractValue.Make(channel_noise(0, range(self._n), samples))
        )
        self.DeclareVectorOutputPort(
            "noise",
            self._n,
            self._calc,
            {
                self.time_ticket(),
                self.abstract_parameter_ticket(AbstractParameterIndex(self._table)),
            },
        )

    def set_noise(self, context, *, seed: int, ids) -> None:
        """Draws the table anew: channel j from ``(seed, ids[j])``."""
        ids = np.asarray(ids).ravel()
        if ids.size != self._n:
            raise ValueError(
                f"NoiseTable: {self._n} channel ids needed; got {ids.size}"
            )
        value = context.get_mutable_abstract_parameter(self._table)
        samples = value.get_value().shape[0]
        value.set_value(channel_noise(seed, ids, samples))

    def _calc(self, context, output) -> None:
        table = context.get_abstract_parameter(self._table).get_value()
        # The sensor samples at multiples of the period: round, not floor.
        k = int(math.floor(context.get_time() / self._period + 0.5))
        k = min(max(k, 0), len(table) - 1)
        output.SetFromVector(table[k])


__all__ = ["NoiseTable", "channel_noise"]
