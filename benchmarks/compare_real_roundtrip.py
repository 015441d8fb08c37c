"""How well does compare-real reproduce a log whose truth is known?

Per seed, one :func:`vic_drake.experiments.hand_roundtrip.hand_moved_roundtrip`:
a shared log's scenario with random hand motion (``--events`` lifts and fast
drops below rest) is simulated, written as the rig's bag and fed to
compare-real. Printed: the motion estimate against the truth (RMS in and out
of contact, mm), the replayed motion against the truth, whether compare-real
replayed it (and the fraction beyond 3 sigma), force RMSE, peaks,
contact loss of the bag vs the replay and their overlap. Needs the data (the
measured map).

    python benchmarks/compare_real_roundtrip.py [--log NAME] [--seeds 0,1]
        [--events 5] [--keep DIR]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from common import comma_list, data_dir_with_log, print_row, versions

from vic_drake.experiments.hand_roundtrip import MAX_EVENTS, hand_moved_roundtrip


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--log", default="test_nardi_matForce_lowR")
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--events", type=int, default=5)
    parser.add_argument("--data-dir", default=None)
    parser.add_argument(
        "--keep",
        default=None,
        help="folder to keep the bags in, with the true and the replayed scans (pickles)",
    )
    args = parser.parse_args()
    seeds = comma_list(parser, "--seeds", args.seeds, int)
    if not 1 <= args.events <= MAX_EVENTS:
        parser.error(
            f"--events takes an integer from 1 to {MAX_EVENTS}; got {args.events}"
        )
    data_dir = data_dir_with_log(parser, args.data_dir, args.log)
    print(versions())
    keep = Path(args.keep) if args.keep else None
    with tempfile.TemporaryDirectory() as tmp:
        out_dir = keep or Path(tmp)
        out_dir.mkdir(parents=True, exist_ok=True)
        for seed in seeds:
            t0 = time.perf_counter()
            row = hand_moved_roundtrip(
                data_dir, args.log, seed, args.events, out_dir, keep=keep is not None
            )
            row["wall_s"] = round(time.perf_counter() - t0, 1)
            print_row(row)


if __name__ == "__main__":
    main()
