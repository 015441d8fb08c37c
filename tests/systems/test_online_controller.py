"""The controller with ``stiffness_source="online"``: the references use the
estimator's kappa (seeded with the prior), not the map; bad options fail."""

import numpy as np
import pytest

from vic_drake.control.params import (
    ControllerParams,
    ReferenceParams,
    StiffnessQpParams,
)
from vic_drake.errors import VicDrakeError
from vic_drake.estimation.online import OnlineEstimatorParams
from vic_drake.scenario import Scenario
from vic_drake.systems.controller import MakeVariableImpedanceController
from vic_drake.tissue.phantom import GridPhantom

EPS_D, BETA = 0.008, 1.35


def _params():
    return ControllerParams(
        qp=StiffnessQpParams(solver="exact"),
        reference=ReferenceParams(controller="vs-vf", eps_d_m=EPS_D),
    )


def _phantom(kappa):
    ones = np.ones((2, 2))
    x = np.array([-1.0, 1.0])
    return GridPhantom(
        x_m=x, y_m=x, z_m=0.1 * ones, kappa=kappa * ones, lam=8 * kappa * ones
    )


def _run_ticks(diagram, n, z=0.094, force_z=-6.0):
    context = diagram.CreateDefaultContext()
    for name, value in (("probe.position", [0.0, -0.36, z]), ("probe.velocity", [0.0, 0.0, 0.0]),
                        ("target_position", [0.0, -0.36, 0.085]),
                        ("ft_sensor.force_W", [0.0, 0.0, force_z])):  # fmt: skip
        diagram.GetInputPort(name).FixValue(context, value)
    for k in range(n):
        context.SetTime(k * 0.002)
        context.SetDiscreteState(diagram.EvalUniquePeriodicDiscreteUpdate(context))
    return context


@pytest.mark.parametrize("surface", ["estimated", "map"])
def test_online_references_follow_the_estimate_not_the_map(surface):
    prior = OnlineEstimatorParams(method="ekf", kappa_prior=3000.0, lam_prior=24000.0)
    # The map says 9000: with "online" only its surface may be read.
    diagram = MakeVariableImpedanceController(
        _params(),
        phantom=_phantom(9000.0),
        stiffness_source="online",
        estimator=prior,
        online_surface=surface,
    )
    context = _run_ticks(diagram, 1)
    est = diagram.GetOutputPort("tissue_estimate").Eval(context)
    f_ref = diagram.GetOutputPort("force_reference").Eval(context)[2]
    # The first tick's reference used the prior (the estimate is from state).
    assert f_ref == pytest.approx(-3000.0 * EPS_D**BETA, rel=1e-9)
    context = _run_ticks(diagram, 200)
    est = diagram.GetOutputPort("tissue_estimate").Eval(context)
    f_ref = diagram.GetOutputPort("force_reference").Eval(context)[2]
    assert np.all(np.isfinite(est[:5]))
    assert f_ref == pytest.approx(-est[0] * EPS_D**BETA, rel=1e-6)
    if surface == "map":  # 6 mm deep in a flat surface at 0.1 m, 6 N.
        assert est[0] == pytest.approx(6.0 / 0.006**BETA, rel=0.02)


def test_online_needs_estimator_params():
    with pytest.raises(VicDrakeError, match="estimator"):
        MakeVariableImpedanceController(
            _params(), phantom=None, stiffness_source="online"
        )
    with pytest.raises(VicDrakeError, match="online_surface"):
        MakeVariableImpedanceController(
            _params(),
            phantom=None,
            stiffness_source="online",
            estimator=OnlineEstimatorParams(),
            online_surface="guess",
        )


@pytest.mark.parametrize(
    "field, value", [("stiffness_source", "prior"), ("online_surface", "none")]
)
def test_scenario_validates_the_source(field, value):
    s = Scenario()
    setattr(s, field, value)
    with pytest.raises(VicDrakeError, match=field):
        s.validate()


DITHERED_ONLINE = """\
stiffness_source: online
controller: {reference: {controller: vs-vf, penetration_dither_m: 0.0003,
                         penetration_dither_hz: 3.0}}
online_estimator: {method: ekf, surface_from_slope: true,
                   surface_walk_m_per_sqrt_s: 0.0}
"""


def test_dithered_online_scenario_loads_from_yaml():
    from vic_drake.scenario import loads_scenario

    s = loads_scenario(DITHERED_ONLINE)
    assert s.controller.reference.penetration_dither_m == 0.0003
    assert s.online_estimator.surface_from_slope is True


@pytest.mark.parametrize(
    "text, match",
    [
        (
            DITHERED_ONLINE.replace(
                "penetration_dither_m: 0.0003", "penetration_dither_m: 0.0"
            ),
            r"online_estimator\.surface_from_slope needs the reference's dither",
        ),
        (
            DITHERED_ONLINE.replace("0.0003", "0.005"),
            r"penetration_dither_m must be in \[0, eps_d_m / 2\].*0\.005",
        ),
        (
            DITHERED_ONLINE.replace(
                "penetration_dither_hz: 3.0", "penetration_dither_hz: 0"
            ),
            r"penetration_dither_hz must be > 0",
        ),
        (
            DITHERED_ONLINE.replace(
                "surface_from_slope: true", "surface_from_slope: 1"
            ),
            "surface_from_slope",
        ),
        (
            DITHERED_ONLINE.replace("method: ekf", "method: rls"),
            "surface_from_slope needs method 'ekf'",
        ),
    ],
)
def test_dithered_online_scenario_is_validated(text, match):
    from vic_drake.scenario import loads_scenario

    with pytest.raises(VicDrakeError, match=match):
        loads_scenario(text)


def test_controller_refuses_the_slope_surface_without_the_dither():
    with pytest.raises(
        VicDrakeError, match="surface_from_slope needs the reference's dither"
    ):
        MakeVariableImpedanceController(
            _params(),
            phantom=None,
            stiffness_source="online",
            estimator=OnlineEstimatorParams(method="ekf", surface_from_slope=True),
        )


@pytest.mark.parametrize("mode", ["tracker", "direct"])
def test_slope_fit_reads_the_controllers_bounds(mode):
    params = ControllerParams(
        qp=StiffnessQpParams(solver="exact"),
        reference=ReferenceParams(
            controller="vs-vf",
            eps_d_m=EPS_D,
            penetration_dither_m=3e-4,
            penetration_dither_hz=3.0,
        ),
    )
    estimator = OnlineEstimatorParams(
        method="ekf",
        surface_from_slope=True,
        surface_walk_m_per_sqrt_s=0.0,
        slope_kappa_mode=mode,
    )
    diagram = MakeVariableImpedanceController(
        params, phantom=None, stiffness_source="online", estimator=estimator
    )
    est = diagram.GetSubsystemByName("tissue_estimator")
    # Both modes read the QP's K (K_z at K_max) and the references (F_ref,z
    # capped by F_min,z); connected: the ticks evaluate them.
    assert est.get_stiffness_input_port() is not None
    assert est.get_references_input_port() is not None
    context = _run_ticks(diagram, 20)
    est = diagram.GetOutputPort("tissue_estimate").Eval(context)
    assert np.all(np.isfinite(est[:5]))


@pytest.mark.parametrize("name, bad", [("stiffness_max_z", 0.0), ("force_min_z", 9.0)])
def test_estimator_bound_inputs_need_the_slope_fit(name, bad):
    from vic_drake.systems.online_estimator import OnlineEstimatorSystem

    with pytest.raises(VicDrakeError, match=f"{name} is for"):
        OnlineEstimatorSystem(
            OnlineEstimatorParams(method="ekf"), period_s=0.002, **{name: -1e3}
        )
    with pytest.raises(VicDrakeError, match=f"{name} must be"):
        OnlineEstimatorSystem(
            OnlineEstimatorParams(method="ekf", surface_from_slope=True),
            period_s=0.002,
            **{name: bad},
        )


@pytest.mark.parametrize(
    "f_ref, f_min, flat",
    [
        (-10.0, -9.0, True),  # capped, the dither's upper half: the bound
        (-10.0, -8.5, False),  # capped, lower half: the bound follows it
        (-8.0, -9.0, False),  # not capped
        (0.0, -30.0, False),  # out of contact (F_min,z = -F_max,z)
    ],
)
def test_flat_force_bound(f_ref, f_min, flat):
    from vic_drake.systems.online_estimator import at_flat_force_bound

    assert at_flat_force_bound(f_ref, f_min, -9.0) is flat
