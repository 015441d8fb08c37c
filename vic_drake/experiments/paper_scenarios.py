"""The paper's scan scenarios: the synthetic runs and the real logs' replays.

:func:`paper_scenarios` is every scenario of ``diagrams/``: the synthetic
nominal scans of the four controllers (paper Fig. 6), the synthetic
disturbance scans (Fig. 7, :func:`disturbance_lifts`) and one replay per real
scan log (:data:`REAL_EXPERIMENTS`); :func:`write_paper_scenarios` writes
them as YAML.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from vic_drake.analysis.columns import real_to_canonical
from vic_drake.control.params import ReferenceParams
from vic_drake.errors import VicDrakeError
from vic_drake.experiments.compare_real import phantom_replay
from vic_drake.experiments.real_logs import (
    CF_FDCC_Z_GAINS,
    CS_FDCC_Z_GAINS,
    DEFAULT_CF_FORCE_N,
    DEFAULT_CS_STIFFNESS_N_PER_M,
    DEFAULT_R,
    scenario_from_real_log,
    with_z_gains,
)
from vic_drake.paper import CONTROLLERS, DISTURBANCE_CONTROLLERS
from vic_drake.paths import DIAGRAMS_DIR, diagram_names, require_data_dir
from vic_drake.realdata import read_bag
from vic_drake.scenario import (
    DisturbanceConfig,
    PhantomLift,
    Scenario,
    TrajectoryConfig,
    load_scenario,
    save_scenario,
)
from vic_drake.tissue.phantom import load_phantom

#: The paper's scan logs under ``<data>/experiments`` that have a scenario in diagrams/.
REAL_EXPERIMENTS = (
    "test_compliance_control400",
    "test_compliance_control400_dist",
    "test_force_control",
    "test_force_control_dist",
    "test_tracking5",
    "test_nardi_matForce_lowR",
)

#: The disturbance events start this long after the target reaches its
#: scanning height (the first, or both).
DISTURBANCE_DELAYS_S = (0.5, 8.0)


def scan_start_s(trajectory: TrajectoryConfig) -> float:
    """When the target reaches its scanning height and starts to move, s."""
    return (
        trajectory.start_delay_s
        + (trajectory.approach_z_m - trajectory.target_z_m)
        / trajectory.approach_speed_m_per_s
        + trajectory.dwell_s
    )


def disturbance_lifts(t_scan_start_s: float, *, events: int = 2) -> list[PhantomLift]:
    """The phantom lifted by hand, let go and caught again (Fig. 7).

    Each event (``events`` of them, :data:`DISTURBANCE_DELAYS_S` after the
    scan starts): the phantom rises 15 mm over 0.5 s and is held 1 s (the
    probe is pushed away from its target; the size of the real lifts: see
    docs/decisions.md, "Disturbance lifts"), then drops
    over 0.2 s to 10 mm below its rest, faster than the compliant probe
    follows, so contact is lost, stays there 0.8 s and comes back up over
    0.5 s (re-contact).
    """
    if not 1 <= events <= len(DISTURBANCE_DELAYS_S):
        raise VicDrakeError(
            f"events must be 1..{len(DISTURBANCE_DELAYS_S)}, got {events!r}"
        )
    lifts = []
    for delay in DISTURBANCE_DELAYS_S[:events]:
        t = round(t_scan_start_s + delay, 6)  # Readable scenario files.
        lifts.append(
            PhantomLift(start_s=t, height_m=0.015, rise_s=0.5, hold_s=1.0, fall_s=0.2)
        )
        lifts.append(
            PhantomLift(
                start_s=round(t + 1.7, 6),
                height_m=-0.010,
                rise_s=0.2,
                hold_s=0.8,
                fall_s=0.5,
            )
        )
    return lifts


def synthetic_scenario(controller: str, *, disturbed: bool = False) -> Scenario:
    """A paper scan on the synthetic phantom with one of the four controllers.

    The target comes down from 12 cm (2.0 cm above the synthetic chest's
    surface at the start) to z = 0.085 at 1 cm/s, moves 20 cm along -x at 1 cm/s and is
    raised 4.8 cm; controllers as on the real rig (CS 400 N/m and CF 7 N with
    the FDCC's default z gains, see :data:`CF_FDCC_Z_GAINS`; VS-CF 7 N with R = 0.1, VS-VF eps_d = 8 mm,
    F_min = -9 N, R = 1e-5). ``disturbed`` adds :func:`disturbance_lifts`
    (both events).
    """
    if controller not in CONTROLLERS:
        raise VicDrakeError(
            f"controller must be cs, cf, vs-cf or vs-vf; got {controller!r}"
        )
    base = Scenario()
    ref = ReferenceParams(controller=controller)
    fdcc = base.fdcc
    if controller == "cs":
        k = DEFAULT_CS_STIFFNESS_N_PER_M
        ref = replace(ref, constant_stiffness_N_per_m=[k, k, k])
        fdcc = with_z_gains(fdcc, *CS_FDCC_Z_GAINS)
    elif controller == "cf":
        ref = replace(ref, force_ref_N=DEFAULT_CF_FORCE_N)
        fdcc = with_z_gains(fdcc, *CF_FDCC_Z_GAINS)
    r = DEFAULT_R.get(controller, 0.1)
    # The default scenario's controller carries the scans' QP solver.
    ctrl = replace(
        base.controller,
        reference=ref,
        qp=replace(base.controller.qp, r_weight=[r, r, r]),
    )
    kind = "disturbance" if disturbed else "nominal"
    trajectory = TrajectoryConfig(approach_z_m=0.12)
    lifts = disturbance_lifts(scan_start_s(trajectory)) if disturbed else []
    return replace(
        base,
        name=f"{kind}_{controller.replace('-', '_')}_synthetic",
        description=(
            f"{controller.upper()} {kind} scan on the synthetic chest "
            f"(paper Fig. {'7' if disturbed else '6'})"
        ),
        controller=ctrl,
        fdcc=fdcc,
        trajectory=trajectory,
        disturbance=DisturbanceConfig(lifts=lifts),
    )


def real_experiment_scenario(
    name: str, *, data_dir=None, waypoints: bool = False
) -> Scenario:
    """The scenario of one of the paper's scan logs on the measured map.

    As compare-real builds it (:func:`scenario_from_real_log`; the phantom's
    motion replayed where the log shows it,
    :func:`~vic_drake.experiments.compare_real.phantom_replay`), with the
    parametric target fit by default so the scenario file stays short.
    """
    bag = require_data_dir(data_dir) / "experiments" / name
    raw = read_bag(bag)
    phantom = load_phantom("measured", data_dir=data_dir, lookup="bilinear")
    _, table, _ = phantom_replay(bag, real_to_canonical(raw), phantom)
    disturbance = DisturbanceConfig(table=table) if table else None
    return scenario_from_real_log(
        raw, name=name, disturbance=disturbance, waypoints=waypoints
    )


def paper_scenarios(*, data_dir=None, include_real: bool = True) -> dict[str, Scenario]:
    """Every scenario of ``diagrams/``: the synthetic nominal runs of the four
    controllers, the synthetic disturbance runs (VS-VF, CS, CF), and one per
    real scan log (:data:`REAL_EXPERIMENTS`, needs the data)."""
    out = {}
    for c in CONTROLLERS:
        s = synthetic_scenario(c)
        out[s.name] = s
    for c in DISTURBANCE_CONTROLLERS:
        s = synthetic_scenario(c, disturbed=True)
        out[s.name] = s
    if include_real:
        for name in REAL_EXPERIMENTS:
            s = real_experiment_scenario(name, data_dir=data_dir)
            out[f"real_{name}"] = replace(s, name=f"real_{name}")
    return out


def load_diagram(name: str) -> Scenario:
    """The scenario ``diagrams/<name>.yaml``, as the runs of the paper load it.

    ``diagrams/`` is the source of truth of the paper's runs: ``reproduce``
    builds its scans from these files, and the tests check that each file
    agrees with :func:`paper_scenarios` (written by
    :func:`write_paper_scenarios`).

    Raises:
        VicDrakeError: no such file; the message lists the files there are.
    """
    path = DIAGRAMS_DIR / f"{name}.yaml"
    if not path.is_file():
        known = diagram_names()
        raise VicDrakeError(
            f"no scenario file {str(path)!r}; diagrams/ holds {known or 'nothing'}"
        )
    return load_scenario(path)


def write_paper_scenarios(
    directory, *, data_dir=None, include_real: bool = True
) -> list[Path]:
    """Writes :func:`paper_scenarios` as ``<directory>/<name>.yaml`` (how
    ``diagrams/`` was made), each with only the fields that differ from the
    defaults; returns the paths."""
    directory = Path(directory)
    return [
        save_scenario(s, directory / f"{name}.yaml", only_changes=True)
        for name, s in paper_scenarios(
            data_dir=data_dir, include_real=include_real
        ).items()
    ]


__all__ = [
    "DISTURBANCE_DELAYS_S",
    "load_diagram",
    "REAL_EXPERIMENTS",
    "disturbance_lifts",
    "paper_scenarios",
    "real_experiment_scenario",
    "scan_start_s",
    "synthetic_scenario",
    "write_paper_scenarios",
]
