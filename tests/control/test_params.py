"""ControllerParams: defaults, validation messages, YAML round trip."""

import math

import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
    TankParams,
)
from vic_drake.errors import VicDrakeError


def test_defaults_are_the_real_controllers_settings():
    p = ControllerParams()
    assert p.period_s == 0.002
    assert p.qp.stiffness_min_N_per_m == [300.0, 300.0, 100.0]
    assert p.qp.stiffness_max_N_per_m == [1000.0, 1000.0, 1000.0]
    assert p.qp.q_weight == [3200.0] * 3
    assert p.qp.force_max_N == [15.0] * 3 and p.qp.force_min_N == [-15.0] * 3
    assert p.qp.damping_ratio == 0.707 and p.qp.solver == "osqp"
    assert (p.tank.initial_energy_J, p.tank.min_energy_J, p.tank.max_energy_J) == (
        0.5,
        0.4,
        1.0,
    )
    assert p.tank.power_limit_W == -0.1
    assert p.reference.eps_max_m == 0.008 and p.reference.force_min_z_N == -9.0


@pytest.mark.parametrize(
    "build, field, value",
    [
        (
            lambda: StiffnessQpParams(stiffness_min_N_per_m=[300, 300, 1100]),
            "stiffness_min_N_per_m[2]",
            "1100",
        ),
        (lambda: TankParams(min_energy_J=0.0), "min_energy_J", "0.0"),
        (lambda: TankParams(min_energy_J=-1.0), "min_energy_J", "-1.0"),
        (lambda: TankParams(power_limit_W=0.0), "power_limit_W", "0.0"),
        (lambda: TankParams(power_limit_W=0.1), "power_limit_W", "0.1"),
        (lambda: TankParams(max_energy_J=0.3), "max_energy_J", "0.3"),
        (lambda: ControllerParams(period_s=0.0), "period_s", "0.0"),
        (lambda: ControllerParams(period_s=-0.002), "period_s", "-0.002"),
        (lambda: ControllerParams(period_s=math.nan), "period_s", "nan"),
        (lambda: StiffnessQpParams(r_weight=[0.1, 0.0, 0.1]), "r_weight[1]", "0.0"),
        (
            lambda: StiffnessQpParams(q_weight=[3200, 3200, math.inf]),
            "q_weight[2]",
            "inf",
        ),
        (lambda: StiffnessQpParams(force_min_N=[-15, -15, 20]), "force_min_N[2]", "20"),
        (lambda: StiffnessQpParams(solver="qpoases"), "solver", "qpoases"),
        (
            lambda: StiffnessQpParams(stiffness_max_N_per_m=[1, 2]),
            "stiffness_max_N_per_m",
            "[1, 2]",
        ),
        (lambda: ReferenceParams(controller="pid"), "controller", "pid"),
        (lambda: ReferenceParams(force_ref_N=math.nan), "force_ref_N", "nan"),
        (lambda: ReferenceParams(force_min_z_N=9.0), "force_min_z_N", "9.0"),
        (
            lambda: ReferenceParams(surface_velocity_window=0),
            "surface_velocity_window",
            "0",
        ),
    ],
)
def test_invalid_values_name_field_and_value(build, field, value):
    with pytest.raises(VicDrakeError) as info:
        build()
    message = str(info.value)
    assert field in message and value in message


def test_validate_catches_values_set_after_construction():
    p = ControllerParams()
    p.tank.min_energy_J = -0.1  # As yaml_load_typed would, after __init__.
    with pytest.raises(VicDrakeError, match="min_energy_J"):
        p.validate()


def test_yaml_round_trip():
    p = ControllerParams(
        period_s=0.004,
        qp=StiffnessQpParams(r_weight=[1e-5] * 3, solver="osqp"),
        reference=ReferenceParams(controller="vs-vf"),
    )
    text = yaml_dump_typed(p)
    q = yaml_load_typed(schema=ControllerParams, data=text)
    assert q == p
    q.validate()


def test_real_controller_params():
    from vic_drake.control.params import real_controller_params

    assert real_controller_params("vs-vf").qp.r_weight == [1e-5] * 3
    assert real_controller_params("vs-cf").qp.r_weight == [0.1] * 3
    assert (
        real_controller_params("cs").reference.constant_stiffness_N_per_m == [400.0] * 3
    )
    with pytest.raises(VicDrakeError, match="'vs'"):
        real_controller_params("vs")
