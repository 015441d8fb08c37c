"""StationParams: validation naming the field, Drake's typed YAML, copies."""

import copy
import pickle

import pytest
from pydrake.common.yaml import yaml_dump_typed, yaml_load_typed
from pydrake.multibody.plant import MultibodyPlantConfig

from vic_drake.errors import VicDrakeError
from vic_drake.paper import GRAVITY_M_PER_S2
from vic_drake.station import StationParams


@pytest.mark.parametrize(
    "field, value, match",
    [
        ("plant", MultibodyPlantConfig(time_step=0.0), "plant.time_step"),
        ("sensor_lag_samples", -2, "sensor_lag_samples"),
        ("joint_kp_Nm_per_rad", (1.0,) * 5, "joint_kp_Nm_per_rad"),
        (
            "plant",
            MultibodyPlantConfig(discrete_contact_approximation="tamsi"),
            "plant.discrete_contact_approximation",
        ),
        ("sensor_noise_std_N", (0, 0, -1), "sensor_noise_std_N"),
    ],
)
def test_bad_params_name_the_field(field, value, match):
    with pytest.raises(VicDrakeError, match=match):
        StationParams(**{field: value})


def test_defaults_plant_config_and_gravity():
    params = StationParams()
    assert params.plant.time_step == 0.002
    assert params.plant.discrete_contact_approximation == "sap"
    assert params.plant.contact_model == "hydroelastic_with_fallback"
    assert params.gravity_m_per_s2 == GRAVITY_M_PER_S2


def test_loads_with_drakes_typed_yaml_and_validates_after():
    params = yaml_load_typed(
        schema=StationParams,
        data="plant: {time_step: 0.001}\nsensor_noise_std_N: [0.1, 0.1, 0.1]\n",
    )
    assert params.plant.time_step == 0.001
    assert params.plant.discrete_contact_approximation == "sap"  # default kept
    assert params.sensor_noise_std_N == [0.1, 0.1, 0.1]
    assert params.validate() is params
    assert yaml_dump_typed(StationParams(), defaults=StationParams()).strip() == "{}"
    bad = yaml_load_typed(schema=StationParams, data="sensor_lag_samples: -1\n")
    with pytest.raises(VicDrakeError, match="sensor_lag_samples"):
        bad.validate()


def test_equality_copies_and_pickling_compare_the_plant_config():
    params = StationParams()
    assert params == StationParams()
    assert pickle.loads(pickle.dumps(params)) == params
    other = copy.deepcopy(params)
    assert other == params
    other.plant.time_step = 0.001
    assert other != params
    assert params.plant.time_step == 0.002  # the copy is deep
