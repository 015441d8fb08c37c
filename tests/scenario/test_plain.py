"""Plain forms of config trees: equality across tuples/lists and Drake configs."""

from pydrake.systems.analysis import SimulatorConfig

from vic_drake.scenario import Scenario, TrajectoryConfig, as_plain, differences


def test_plain_form_reads_drake_configs_and_tuples():
    plain = as_plain({"sim": SimulatorConfig(max_step_size=0.5), "v": (1, 2)})
    assert plain["sim"]["max_step_size"] == 0.5 and plain["v"] == [1, 2]


def test_differences_name_each_field():
    a = Scenario(trajectory=TrajectoryConfig(target_z_m=0.08), seed=1)
    b = Scenario(seed=2)
    assert differences(a, b) == [
        "trajectory.target_z_m: 0.08 in the first, 0.085 in the second",
        "seed: 1 in the first, 2 in the second",
    ]
    assert differences(a, a) == []
    assert differences([1.0], [1.0 + 1e-12], rtol=1e-9) == []


def test_scenario_equality_ignores_tuple_versus_list():
    a = Scenario()
    b = Scenario()
    b.controller.qp.r_weight = tuple(b.controller.qp.r_weight)
    assert a == b
    b.simulator.accuracy = 1e-3
    assert a != b


def test_scenario_pickles_and_copies_with_its_simulator_config():
    import copy
    import pickle

    scenario = Scenario(seed=5)
    scenario.simulator.max_step_size = 0.01
    for clone in (pickle.loads(pickle.dumps(scenario)), copy.deepcopy(scenario)):
        assert clone == scenario
        assert clone.simulator is not scenario.simulator
