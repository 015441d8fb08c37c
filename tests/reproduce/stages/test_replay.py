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


def test_replay_page_shows_the_scan_in_a_browser(tmp_path):
    """The page loads in headless Chromium, framed on the probe and phantom
    (the phantom's skin colour fills a visible part of the view, not a speck)
    and shows its title and caption."""
    import numpy as np
    import pandas as pd

    from tests.browser import chromium, screenshot
    from vic_drake.reproduce import replay_scan, scan_scenario
    from vic_drake.station import initial_q_for_tip
    from vic_drake.tissue import load_phantom

    chromium()
    scenario = scan_scenario(
        "vs-vf", disturbed=False, phantom_kind="synthetic", quick=True
    )
    q0 = initial_q_for_tip(np.array([0.036, -0.36, 0.11]), scenario.station)
    t = np.linspace(0, 0.4, 11)
    df = pd.DataFrame(
        {
            "t_s": t,
            "phantom_lift_m": np.zeros(t.size),
            **{f"q_cmd_{i}_rad": np.full(t.size, q0[i]) for i in range(6)},
        }
    )
    page = tmp_path / "replay.html"
    page.write_text(
        replay_scan(
            df,
            scenario,
            phantom=load_phantom("synthetic"),
            fps=20.0,
            title="Replay title XYZ",
            caption="caption naming the scan",
        ),
        encoding="utf-8",
    )
    text = page.read_text(encoding="utf-8")
    assert "<title>Replay title XYZ</title>" in text
    assert "caption naming the scan" in text
    img = screenshot(page, tmp_path / "replay.png").astype(int)
    r, b = img[..., 0], img[..., 2]
    skin = (r - b > 25) & (r > 150)  # the phantom; the background is grey-blue
    assert skin.mean() > 0.02, f"phantom covers {skin.mean():.2%} of the view"
    # Not asserted: the arm. Its meshes (most of the 17 MB page) may still be
    # loading when headless Chromium takes the screenshot after "load".
    box = img[12:60, 25:300]  # the title box: light, with dark text
    assert box.mean() > 180 and (box.sum(axis=-1) < 300).mean() > 0.02
