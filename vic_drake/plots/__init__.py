"""Figures (matplotlib). Each module takes results and returns Figures.

- :mod:`vic_drake.plots.offline`: Table I, load test (Fig. 2), residual
  against palpation time (Fig. 3), beta sweep.
"""
