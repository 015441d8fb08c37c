"""The ``replay`` stage: a logged scan as a standalone Meshcat animation."""

import pytest

from vic_drake.errors import VicDrakeError


def test_replay_scan_writes_an_animation():
    import numpy as np
    import pandas as pd

    from vic_drake.reproduce import replay_scan, scan_scenario
    from vic_drake.station import initial_q_for_tip
    from vic_drake.tissue import load_phantom

    scenario = scan_scenario(
        "vs-vf", disturbed=False, phantom_kind="synthetic", quick=True
    )
    q0 = initial_q_for_tip(np.array([0.036, -0.36, 0.11]), scenario.station)
    t = np.linspace(0, 0.4, 11)
    df = pd.DataFrame(
        {
            "t_s": t,
            "phantom_lift_m": 0.01 * t,
            **{f"q_cmd_{i}_rad": np.full(t.size, q0[i]) for i in range(6)},
        }
    )
    html = replay_scan(df, scenario, phantom=load_phantom("synthetic"), fps=20.0)
    import base64
    import re

    # The recording is one base64 msgpack command "set_animation" among the scene's.
    blobs = re.findall(r'fetch\("data:application/octet-binary;base64,([^"]+)"\)', html)
    assert sum(b"set_animation" in base64.b64decode(b) for b in blobs) == 1
    with pytest.raises(VicDrakeError, match="lacks columns"):
        replay_scan(
            df.drop(columns=["q_cmd_0_rad"]),
            scenario,
            phantom=load_phantom("synthetic"),
        )
