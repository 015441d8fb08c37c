"""Figures (matplotlib). Each module takes results and returns Figures.

- :mod:`vic_drake.reproduce.plots.offline`: Table I, load test (Fig. 2), residual
  against palpation time (Fig. 3), beta sweep.
- :mod:`vic_drake.reproduce.plots.maps`: GP maps of kappa and lambda (Fig. 4),
  the surface coloured by kappa (Fig. 5).
- :mod:`vic_drake.reproduce.plots.scans`: the scans (Fig. 6, Fig. 7) and a
  real log against its simulation.
"""
