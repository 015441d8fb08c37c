"""The indenter-bank diagram: n servo-driven indenters palpating tissue."""

import numpy as np
import pytest
from scipy.optimize import brentq

from vic_drake.experiments.indenter_bank import MakeIndenterDiagram
from vic_drake.systems.indenter import IndenterParams, PalpationParams, SensorParams
from vic_drake.tissue import RelaxationParams

BETA = 1.35
#: A relaxation that settles within the test's 4 s (one branch, as the default).
FAST = RelaxationParams(fractions=(0.3,), time_constants_s=(0.2,))


@pytest.mark.parametrize("relaxation", [None, FAST], ids=["hc", "relaxing"])
def test_indenter_diagram_static_equilibrium_matches_hunt_crossley(relaxation):
    """Constant target: the tip settles where servo and HC forces balance.

    On relaxing tissue (a fast relaxation, settled within the run) the
    balance is with the relaxed kappa, g_inf kappa.
    """
    from pydrake.systems.analysis import Simulator

    indenter = IndenterParams()
    palpation = PalpationParams(amplitude_m=0.0, duration_s=2.5)
    sensor = SensorParams(noise_std_N=0.0)
    n = 2
    s = np.array([0.10, 0.12])
    kappa, lam = np.array([2500.0, 9000.0]), np.array([2e4, 2e5])
    bank = MakeIndenterDiagram(
        n, beta=BETA, indenter=indenter, sensor=sensor, palpation=palpation
    )
    context = bank.diagram.CreateDefaultContext()
    bank.set_points(
        context, surface_z=s, kappa=kappa, lam=lam, start_z=s + 0.002, seed=1
    )
    bank.tissue.set_relaxation(
        bank.tissue.GetMyMutableContextFromRoot(context), relaxation
    )
    g_inf = 1.0 if relaxation is None else relaxation.long_term_fraction
    kappa_eq = g_inf * kappa
    Simulator(bank.diagram, context).AdvanceTo(4.0)
    q = bank.plant.GetPositions(bank.plant.GetMyContextFromRoot(context))
    contact = (
        bank.target.get_contact_output_port()
        .Eval(bank.target.GetMyContextFromRoot(context))
        .reshape(3, n)
    )
    assert np.all(contact[0] == 1.0)
    z_d = contact[1] - palpation.depth_m
    measured = bank.sensor.get_measured_force_output_port().Eval(
        bank.sensor.GetMyContextFromRoot(context)
    )
    k_p = indenter.servo_stiffness_N_per_m
    for i in range(n):
        # Independent oracle: kappa eps^beta = K_p (s - eps - z_d).
        eps = brentq(
            lambda e, i=i: kappa_eq[i] * e**BETA - k_p * (s[i] - e - z_d[i]), 0.0, 0.05
        )
        assert s[i] - q[i] == pytest.approx(eps, abs=2e-6)
        assert measured[i] == pytest.approx(kappa_eq[i] * eps**BETA, rel=1e-3)


def test_simulated_palpations_take_any_number_of_branches():
    """Two branches, the second with g = 0, palpate exactly as one branch;
    with g > 0 the second branch lowers the force once it has built up."""
    from vic_drake.experiments import CampaignParams, simulate_palpations

    params = CampaignParams(palpation=PalpationParams(duration_s=3.0), seed=0)
    point = dict(surface_z=[0.1], kappa=[4000.0], lam=[2e4], beta=BETA, params=params)

    def force(relaxation):
        (rec,) = simulate_palpations([0.0], [0.0], relaxation=relaxation, **point)
        return rec.force_N

    one = force(FAST)
    padded = force(RelaxationParams((0.3, 0.0), (0.2, 5.0)))
    two = force(RelaxationParams((0.3, 0.1), (0.2, 0.5)))
    np.testing.assert_array_equal(padded, one)
    late = slice(-500, None)  # The last second of contact.
    assert np.mean(two[late]) < 0.95 * np.mean(one[late])
