"""Does compare-real read a known phantom placement back, and what does it do?

Per slope, one :func:`vic_drake.experiments.placement_roundtrip.placed_roundtrip`:
a shared log's scenario simulated on the published map raised by a known
plane (``--offset`` mm at the track's middle, rising ``--slopes`` mm/m along
+x; relaxing tissue, its kappa ``--kappa-scale`` times the map's, the
controller reading the published map), written as
the rig's bag and fed to compare-real under each ``--modes`` surface mode.
Printed per mode: the plane read back and its error, the source compare-real
used, force RMSE, z RMSE, K_z correlation, peaks, contact loss. Needs the
data (the measured map).

    python benchmarks/placement_roundtrip.py [--log NAME] [--slopes -20,0,10]
        [--offset 3] [--kappa-scale 1] [--modes "first contact,anchors,placement"]
        [--keep DIR]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from common import comma_list, data_dir_with_log, print_row, versions

from vic_drake.experiments.placement_roundtrip import placed_roundtrip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="test_nardi_matForce_lowR")
    parser.add_argument("--slopes", default="-20,0,10", help="mm/m along +x")
    parser.add_argument("--offset", type=float, default=3.0, help="mm at the middle")
    parser.add_argument("--modes", default="first contact,anchors,placement")
    parser.add_argument(
        "--kappa-scale", type=float, default=1.0, help="tissue kappa / map kappa"
    )
    parser.add_argument("--data-dir", default=None)
    parser.add_argument("--keep", default=None, help="folder to keep the bags in")
    args = parser.parse_args()
    slopes = comma_list(parser, "--slopes", args.slopes, float)
    modes = comma_list(parser, "--modes", args.modes)
    data_dir = data_dir_with_log(parser, args.data_dir, args.log)
    print(versions())
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = Path(args.keep) if args.keep else Path(tmp)
        out_dir.mkdir(parents=True, exist_ok=True)
        for slope in slopes:
            t0 = time.perf_counter()
            rows = placed_roundtrip(
                data_dir,
                args.log,
                out_dir,
                offset_m=1e-3 * args.offset,
                slope_m_per_m=1e-3 * slope,
                kappa_scale=args.kappa_scale,
                modes=modes,
            )
            wall = round(time.perf_counter() - t0, 1)
            for row in rows:
                print_row({**row, "wall_s": wall})


if __name__ == "__main__":
    main()
