"""vic_drake: passive variable impedance control for robotic ultrasonography.

A Drake implementation of Beber et al., "A Passive Variable Impedance Control
Strategy with Viscoelastic Parameters Estimation of Soft Tissues for Safe
Ultrasonography". Subpackages:

- ``vic_drake.tissue``: Hunt-Crossley / Kelvin-Voigt forces and phantoms.
- ``vic_drake.estimation``: palpation fits, surface fits, Gaussian-process maps.
- ``vic_drake.control``: energy tank, stiffness QP, force references, FDCC.
- ``vic_drake.systems``: thin Drake LeafSystems wrapping ``control``.
"""

__version__ = "0.1.0"
