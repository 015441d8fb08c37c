"""The penetration dither of VS-VF: its references, its bound, its settings,
and the reference system's time dependence."""

import math

import numpy as np
import pytest

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.control.references import desired_penetration, force_references
from vic_drake.errors import VicDrakeError
from vic_drake.systems.references import ForceReferenceSystem
from vic_drake.tissue.phantom import GridPhantom

QP = StiffnessQpParams()
KAPPA, LAM, BETA = 5000.0, 40000.0, 1.35
DITHER = dict(controller="vs-vf", penetration_dither_m=3e-4, penetration_dither_hz=3.0)


def refs(t_s, kappa=KAPPA, **kw):
    return force_references(
        contact=True, kappa=kappa, lam=LAM, eps_dot=0.0, beta=BETA,
        ref=ReferenceParams(**kw), qp=QP, t_s=t_s,
    )  # fmt: skip


def test_reference_follows_the_dithered_penetration():
    t = np.linspace(0.0, 1.0, 301)
    eps = np.array([desired_penetration(ReferenceParams(**DITHER), tk) for tk in t])
    assert eps == pytest.approx(0.008 + 3e-4 * np.sin(2 * np.pi * 3.0 * t), abs=1e-15)
    f_ref = np.array([refs(tk, **DITHER).force_ref[2] for tk in t])
    assert f_ref == pytest.approx(-KAPPA * eps**BETA, rel=1e-12)
    # 0.3 mm on 8 mm: the force swings by +-5 % (beta 0.3/8 = 0.051).
    assert f_ref.min() / f_ref.mean() == pytest.approx(1.051, abs=0.003)


def test_bound_is_lowered_with_the_dither_and_never_raised():
    t = np.linspace(0.0, 1.0, 301)
    f_min = np.array([refs(tk, kappa=9000.0, **DITHER).force_min[2] for tk in t])
    assert f_min.min() >= -9.0  # never pressing harder than F_min,z
    low = np.sin(2 * np.pi * 3.0 * t) < 0.0
    assert np.all(f_min[~low] == -9.0)
    eps = 0.008 + 3e-4 * np.sin(2 * np.pi * 3.0 * t[low])
    assert f_min[low] == pytest.approx(-9.0 * (eps / 0.008) ** BETA, rel=1e-12)


def test_no_dither_is_the_plain_reference_at_any_time():
    plain = refs(0.0, controller="vs-vf")
    for t in (0.0, 0.0123, 7.5):
        assert refs(t, controller="vs-vf") == plain
        assert desired_penetration(ReferenceParams(controller="vs-vf"), t) == 0.008


@pytest.mark.parametrize(
    "kw, field, value",
    [
        (dict(penetration_dither_m=-1e-4), "penetration_dither_m", "-0.0001"),
        (dict(penetration_dither_m=0.0041), "penetration_dither_m", "0.0041"),
        (dict(penetration_dither_m=math.nan), "penetration_dither_m", "nan"),
        (dict(penetration_dither_m=True), "penetration_dither_m", "True"),
        (dict(penetration_dither_hz=0.0), "penetration_dither_hz", "0.0"),
        (dict(penetration_dither_hz=-3.0), "penetration_dither_hz", "-3.0"),
        (
            dict(controller="vs-cf", penetration_dither_m=3e-4),
            "penetration_dither_m needs controller 'vs-vf'",
            "'vs-cf'",
        ),
    ],
)
def test_dither_fields_are_validated(kw, field, value):
    base = dict(controller="vs-vf")
    base.update(kw)
    with pytest.raises(VicDrakeError) as info:
        ReferenceParams(**base)
    assert field in str(info.value) and value in str(info.value)


def test_dither_frequency_is_bounded_by_the_control_rate():
    ref = ReferenceParams(controller="vs-vf", penetration_dither_hz=60.0)
    with pytest.raises(
        VicDrakeError, match=r"penetration_dither_hz .* 50\.0 Hz.*60\.0"
    ):
        ControllerParams(reference=ref)
    ControllerParams(reference=ref, period_s=0.001)  # 100 Hz allowed at 1 kHz


def _reference_at(system, t):
    context = system.CreateDefaultContext()
    # p_WP, v_WP, the F/T force.
    measurement = [0.0, 0.0, 0.094, 0.0, 0.0, 0.0, 0.0, 0.0, -6.0]
    system.GetInputPort("measurement").FixValue(context, measurement)
    context.SetTime(t)
    return system.GetOutputPort("references").Eval(context)[2]


@pytest.mark.parametrize("dither_m", [0.0, 3e-4])
def test_reference_system_reads_the_time_only_with_the_dither(dither_m):
    ones = np.ones((2, 2))
    x = np.array([-1.0, 1.0])
    phantom = GridPhantom(
        x_m=x, y_m=x, z_m=0.1 * ones, kappa=KAPPA * ones, lam=LAM * ones
    )
    params = ControllerParams(
        reference=ReferenceParams(controller="vs-vf", penetration_dither_m=dither_m)
    )
    system = ForceReferenceSystem(params, phantom=phantom)
    quarter = 0.25 / params.reference.penetration_dither_hz  # sin = 1
    f0, f1 = _reference_at(system, 0.0), _reference_at(system, quarter)
    assert f0 == pytest.approx(-KAPPA * 0.008**BETA, rel=1e-9)
    assert f1 == pytest.approx(-KAPPA * (0.008 + dither_m) ** BETA, rel=1e-9)
