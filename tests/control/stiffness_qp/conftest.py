"""Fixtures of the stiffness QP tests: the two MathematicalProgram solvers."""

import pytest

from vic_drake.control.stiffness_qp.program import StiffnessQp


@pytest.fixture(scope="module")
def osqp():
    return StiffnessQp("osqp")


@pytest.fixture(scope="module")
def clarabel():
    return StiffnessQp("clarabel")
