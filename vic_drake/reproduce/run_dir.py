"""The output folder of a reproduce run, written through a marker.

A run writes into a work folder beside ``--out`` (``.NAME.partial``) whose
``run.json`` says ``"complete": false`` until the end. Only a finished run
(every selected stage ran, failed or not) writes ``"complete": true`` and is
renamed to ``--out``, replacing the previous run there. An interrupted or
crashed run never touches ``--out``: the previous run stays whole, and the
partial one is kept aside, marked incomplete, until the next run. So a
partial run can never look complete, and a folder never mixes two runs.

A run replaces a previous complete run only when it covers it: it runs
every stage that ran there (``--stages``), and it has the paper's data when
that run had it. Otherwise it is refused unless asked (``--overwrite``): a
``--stages`` subset or a run without the data would silently put a partial
run in place of a whole one. The earlier run's outputs are not carried
forward: the stages hand their results to the later ones in memory (the
claims and the report need them), and a folder never mixes two runs.

:func:`prepare_run_dir` does every check on the output before any work.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

from vic_drake.errors import VicDrakeError
from vic_drake.paths import REPRODUCE_RUN_FILE, check_output_dir, check_run_folder

#: The marker file of a run folder.
RUN_FILE = REPRODUCE_RUN_FILE


def work_dir_for(out_dir: Path) -> Path:
    """The work folder of a run into ``out_dir``: ``.NAME.partial`` beside it."""
    return out_dir.parent / f".{out_dir.name}.partial"


def _is_run_dir(path: Path) -> bool:
    return (path / RUN_FILE).is_file()


def write_marker(folder: Path, *, complete: bool, **fields) -> None:
    """Writes ``run.json``: ``complete`` first, then the given fields."""
    body = {"complete": complete, **fields}
    (folder / RUN_FILE).write_text(json.dumps(body, indent=2) + "\n", encoding="utf-8")


def _read_marker(folder: Path) -> dict:
    """A run folder's ``run.json`` ({} when it is missing or unreadable)."""
    try:
        body = json.loads((folder / RUN_FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return body if isinstance(body, dict) else {}


#: Stages that run only with the paper's data: a marker from before
#: ``data_dir`` was recorded had the data when one of them ran.
_DATA_STAGES = ("offline_real", "real_scans", "compare_real")


def _had_data(marker: dict) -> bool:
    if "data_dir" in marker:
        return marker["data_dir"] is not None
    return any(
        s.get("name") in _DATA_STAGES and s.get("status") == "ok"
        for s in _stage_list(marker)
    )


def _stage_list(marker: dict) -> list[dict]:
    stages = marker.get("stages")
    return (
        [s for s in stages if isinstance(s, dict)] if isinstance(stages, list) else []
    )


def check_replace(
    out: Path,
    *,
    stages: tuple[str, ...] | None,
    data_dir: Path | None,
    quick: bool = False,
) -> None:
    """Refuses to replace the complete run in ``out`` with one that covers less.

    Args:
        out: ``--out`` (resolved).
        stages: the stages this run will run (None: all).
        data_dir: the paper's data this run uses (None: none).
        quick: this run is a quick one (a full run is not replaced by it).

    Raises:
        VicDrakeError: ``out`` holds a complete run with a stage that ran
            there and is not selected now, or made with the data when this
            run has none; naming the ways on (a new ``--out``, or
            ``--overwrite``).
    """
    marker = _read_marker(out)
    if marker.get("complete") is not True:
        return
    done = [s.get("name") for s in _stage_list(marker) if s.get("status") == "ok"]
    dropped = [n for n in done if stages is not None and n not in stages]
    reasons = []
    if dropped:
        reasons.append(
            f"its stage(s) {', '.join(map(str, dropped))} would not run again "
            f"(--stages {','.join(stages or ())})"
        )
    if quick and marker.get("quick") is False:
        reasons.append(
            "it is a full run and this one is quick (shorter scans and "
            "palpations, no compare_real)"
        )
    if _had_data(marker) and data_dir is None:
        reasons.append(
            "it was made with the paper's data and this run has none (pass "
            "--data-dir DIR or set VIC_DRAKE_DATA)"
        )
    if reasons:
        raise VicDrakeError(
            f"--out {str(out)!r} holds a complete run that this one does not "
            f"cover: {'; '.join(reasons)}. Replacing it would lose the outputs "
            "that this run does not remake (report, logs, figures); give another "
            "--out, or pass --overwrite to replace it"
        )


def prepare_run_dir(
    out_dir: str | os.PathLike,
    *,
    stages: tuple[str, ...] | None = None,
    data_dir: Path | None = None,
    overwrite: bool = False,
    quick: bool = False,
) -> Path:
    """Checks ``--out`` and makes the run's work folder; returns the work folder.

    ``out_dir`` may be new, empty, or a previous run's folder (holding
    ``run.json``); anything else is refused, so a run never replaces a
    folder of other files. A previous complete run is replaced only by a run
    that covers it (:func:`check_replace`) or with ``overwrite``.

    Args:
        out_dir: ``--out``.
        stages: the stages this run will run (None: all).
        data_dir: the paper's data this run uses (None: none).
        overwrite: replace a previous run even when this one covers less.
        quick: this run is a quick one.

    Raises:
        VicDrakeError: ``out_dir`` is a file, a folder of other files, a
            complete run that this run does not cover (without
            ``overwrite``), or it or its parent cannot be written.
    """
    out = Path(out_dir).expanduser().resolve()
    check_run_folder(out, RUN_FILE, others="a previous run's folder")
    if out.is_dir():  # (A new --out's parent is checked above.) The work
        # folder is made beside --out, whatever --out holds.
        check_output_dir(out.parent, option="--out's parent folder")
    if not overwrite:
        check_replace(out, stages=stages, data_dir=data_dir, quick=quick)
    work = work_dir_for(out)
    if work.exists():
        if not (work.is_dir() and (_is_run_dir(work) or not any(work.iterdir()))):
            raise VicDrakeError(
                f"{str(work)!r} (the work folder of --out) exists and is not a "
                "vic-drake run; move it away"
            )
        pid = _writer_pid(work)
        if pid is not None and pid != os.getpid() and _alive(pid):
            raise VicDrakeError(
                f"another vic-drake run (process {pid}) is writing into --out "
                f"{str(out)!r}; wait for it or give another folder"
            )
        shutil.rmtree(work)  # An earlier interrupted run.
    check_output_dir(work, option="--out's work folder")
    write_marker(
        work, complete=False, started_utc=_now(), out_dir=str(out), pid=os.getpid()
    )
    return work


def finish_run_dir(work: Path, out_dir: str | os.PathLike, **fields) -> Path:
    """Marks the run complete and moves it to ``out_dir``; returns ``out_dir``."""
    out = Path(out_dir).expanduser().resolve()
    write_marker(work, complete=True, finished_utc=_now(), **fields)
    old = None
    if out.exists():
        old = out.parent / f".{out.name}.old-{os.getpid()}"
        out.rename(old)
    work.rename(out)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
    return out


def _writer_pid(work: Path) -> int | None:
    """The process that wrote a work folder's marker, if it says."""
    pid = _read_marker(work).get("pid")
    return pid if isinstance(pid, int) else None


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _now() -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime())
