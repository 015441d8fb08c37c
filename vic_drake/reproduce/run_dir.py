"""The output folder of a reproduce run, written through a marker.

A run writes into a work folder beside ``--out`` (``.NAME.partial``) whose
``run.json`` says ``"complete": false`` until the end. Only a finished run
(every selected stage ran, failed or not) writes ``"complete": true`` and is
renamed to ``--out``, replacing the previous run there. An interrupted or
crashed run never touches ``--out``: the previous run stays whole, and the
partial one is kept aside, marked incomplete, until the next run. So a
partial run can never look complete, and a folder never mixes two runs.

:func:`prepare_run_dir` does every check on the output before any work.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

from vic_drake.errors import VicDrakeError
from vic_drake.paths import check_output_dir

#: The marker file of a run folder.
RUN_FILE = "run.json"


def work_dir_for(out_dir: Path) -> Path:
    """The work folder of a run into ``out_dir``: ``.NAME.partial`` beside it."""
    return out_dir.parent / f".{out_dir.name}.partial"


def _is_run_dir(path: Path) -> bool:
    return (path / RUN_FILE).is_file()


def write_marker(folder: Path, *, complete: bool, **fields) -> None:
    """Writes ``run.json``: ``complete`` first, then the given fields."""
    body = {"complete": complete, **fields}
    (folder / RUN_FILE).write_text(json.dumps(body, indent=2) + "\n", encoding="utf-8")


def prepare_run_dir(out_dir: str | os.PathLike) -> Path:
    """Checks ``--out`` and makes the run's work folder; returns the work folder.

    ``out_dir`` may be new, empty, or a previous run's folder (holding
    ``run.json``); anything else is refused, so a run never replaces a
    folder of other files.

    Raises:
        VicDrakeError: ``out_dir`` is a file, a folder of other files, or
            it or its parent cannot be written.
    """
    out = Path(out_dir).expanduser().resolve()
    if out.exists() and not out.is_dir():
        raise VicDrakeError(
            f"--out {str(out)!r} is a file; give a folder (it is created)"
        )
    if out.is_dir() and any(out.iterdir()) and not _is_run_dir(out):
        raise VicDrakeError(
            f"--out {str(out)!r} holds files that are not a vic-drake reproduce run "
            f"(no {RUN_FILE}); give a new or empty folder, or a previous run's folder"
        )
    check_output_dir(out.parent, option="--out's parent folder")
    if out.is_dir() and not os.access(out, os.W_OK | os.X_OK):
        raise VicDrakeError(f"--out {str(out)!r} cannot be written")
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
    try:
        pid = json.loads((work / RUN_FILE).read_text(encoding="utf-8")).get("pid")
    except (OSError, ValueError, AttributeError):
        return None
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
