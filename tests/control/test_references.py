"""Force references, contact, penetration rate and the surface-velocity filter."""

import pytest

from vic_drake.control.params import ReferenceParams, StiffnessQpParams
from vic_drake.control.references import (
    constant_stiffness,
    force_references,
    hunt_crossley_at_depth,
    in_contact,
    penetration,
    penetration_rate,
    surface_velocity_gradient,
    surface_velocity_initial_state,
    surface_velocity_step,
    uses_qp,
)

QP = StiffnessQpParams()
KAPPA, LAM, BETA = 5000.0, 40000.0, 1.35


def refs(controller, contact=True, eps_dot=0.002, **kw):
    return force_references(
        contact=contact, kappa=KAPPA, lam=LAM, eps_dot=eps_dot, beta=BETA,
        ref=ReferenceParams(controller=controller, **kw), qp=QP,
    )  # fmt: skip


def test_contact_threshold_and_penetration():
    ref = ReferenceParams()
    assert (
        in_contact(-0.51, ref)
        and not in_contact(-0.5, ref)
        and not in_contact(2.0, ref)
    )
    assert penetration(0.10, 0.095) == pytest.approx(0.005)
    assert penetration_rate(z_dot=-0.01, surface_velocity=0.002) == pytest.approx(0.012)
    assert hunt_crossley_at_depth(KAPPA, LAM, -0.001, 0.0, BETA) == 0.0


def test_vs_cf_constant_reference_and_hc_minimum():
    r = refs("vs-cf", force_ref_N=7.0, eps_max_m=0.008)
    assert r.force_ref == (0.0, 0.0, -7.0)
    assert r.force_min[2] == pytest.approx(
        -(KAPPA + LAM * 0.002) * 0.008**BETA, rel=1e-14
    )
    assert r.force_min[:2] == (-15.0, -15.0) and r.target_force == (0.0, 0.0, 0.0)


def test_vs_vf_hc_reference_and_constant_minimum():
    r = refs("vs-vf", eps_d_m=0.006, force_min_z_N=-9.0)
    assert r.force_ref[2] == pytest.approx(
        -(KAPPA + LAM * 0.002) * 0.006**BETA, rel=1e-14
    )
    assert r.force_min == (-15.0, -15.0, -9.0) and r.target_force == (0.0, 0.0, 0.0)


@pytest.mark.parametrize("controller", ["vs-cf", "vs-vf"])
def test_out_of_contact_references(controller):
    r = refs(controller, contact=False)
    assert r.force_ref == (0.0, 0.0, 0.0) and r.force_min == (-15.0, -15.0, -15.0)


def test_cs_and_cf_mapping():
    cs = refs("cs")
    assert cs.target_force == (0.0, 0.0, 0.0) and cs.force_ref == (0.0, 0.0, 0.0)
    cf = refs("cf", force_ref_N=7.0, contact=False)  # CF presses even before contact.
    assert cf.target_force == (0.0, 0.0, -7.0)
    k = [400.0, 350.0, 380.0]
    assert constant_stiffness(
        ReferenceParams(controller="cs", constant_stiffness_N_per_m=k)
    ) == tuple(k)
    assert constant_stiffness(
        ReferenceParams(controller="cf", constant_stiffness_N_per_m=k)
    ) == (400.0, 350.0, 0.0)
    assert constant_stiffness(ReferenceParams(controller="vs-vf")) is None
    assert uses_qp(ReferenceParams(controller="vs-cf")) and not uses_qp(
        ReferenceParams(controller="cf")
    )


def test_surface_velocity_moving_average():
    state = surface_velocity_initial_state(4)
    heights = [0.100, 0.101, 0.103, 0.103, 0.104, 0.100]
    rates, values = [], []
    for k, z in enumerate(heights):
        state, v = surface_velocity_step(state, z, 0.002)
        rates.append(0.0 if k == 0 else (z - heights[k - 1]) / 0.002)
        values.append(v)
    for k in range(len(heights)):
        window = rates[max(0, k - 3) : k + 1]
        assert values[k] == pytest.approx(sum(window) / 4, rel=1e-12)
    assert surface_velocity_gradient(0.1, -0.2, 0.01, 0.02) == pytest.approx(
        0.001 - 0.004
    )


@pytest.mark.parametrize("lookup", ["bilinear", "nearest"])
def test_scalar_sampler_equals_phantom_sample(lookup):
    import numpy as np

    from vic_drake.control.references import scalar_sampler
    from vic_drake.tissue.phantom import GridPhantom

    rng = np.random.default_rng(7)
    x = np.cumsum(rng.uniform(0.5e-3, 2e-3, 12))
    y = np.cumsum(rng.uniform(0.5e-3, 2e-3, 9)) - 0.4
    shape = (x.size, y.size)
    phantom = GridPhantom(
        x_m=x, y_m=y, z_m=rng.uniform(0.08, 0.12, shape), kappa=rng.uniform(2e3, 1e4, shape),
        lam=rng.uniform(2e4, 2e5, shape), surface_offset_m=0.0025, lookup=lookup,
    )  # fmt: skip
    sample = scalar_sampler(phantom)
    qx = np.concatenate(
        [rng.uniform(x[0] - 0.005, x[-1] + 0.005, 400), x, [x[0], x[-1]]]
    )
    qy = np.concatenate(
        [
            rng.uniform(y[0] - 0.005, y[-1] + 0.005, 400),
            y[:1].repeat(x.size),
            [y[-1], y[0]],
        ]
    )
    for xi, yi in zip(qx, qy):
        s = phantom.sample(xi, yi)
        expected = [
            float(s.surface_z_m),
            float(s.dz_dx),
            float(s.dz_dy),
            float(s.kappa),
            float(s.lam),
        ]
        assert sample(float(xi), float(yi)) == pytest.approx(
            expected, rel=1e-13, abs=1e-15
        )
