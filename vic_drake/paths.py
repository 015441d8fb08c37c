"""Where the paper's measurements live.

The real data is never copied into this repository. It is found, in order:

1. an explicit path (the ``--data-dir`` option of the command line),
2. the ``VIC_DRAKE_DATA`` environment variable,
3. ``../shared/data`` relative to the project root (the folder holding
   ``pyproject.toml``), the layout of the development checkout.
"""

from __future__ import annotations

import difflib
import os
from pathlib import Path

from vic_drake.errors import DataNotFoundError, VicDrakeError

DATA_ENV_VAR = "VIC_DRAKE_DATA"
PROJECT_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_DATA_DIR = PROJECT_ROOT.parent / "shared" / "data"
#: The scenario files of the paper's runs (the source of truth of reproduce).
DIAGRAMS_DIR = PROJECT_ROOT / "diagrams"
#: The marker file of a ``vic-drake reproduce`` run's folder (written by
#: vic_drake.reproduce.run_dir; :func:`check_run_folder` names such a folder).
REPRODUCE_RUN_FILE = "run.json"
#: A campaign folder's spec and its folder of run scenarios (written by
#: vic_drake.experiments.campaign.engine; scan reads a run's force limit
#: from the spec beside its scenario).
CAMPAIGN_SPEC_FILE = "spec.yaml"
CAMPAIGN_SCENARIOS_DIR = "scenarios"


def diagram_names() -> list[str]:
    """The shipped scenarios: the stems of ``diagrams/*.yaml``, sorted."""
    return sorted(p.stem for p in DIAGRAMS_DIR.glob("*.yaml"))


def scenario_path(text: str, say=None) -> Path:
    """The scenario file ``text`` names.

    A bare name that is not a file here (``nominal_vs_vf_synthetic``, with
    or without ``.yaml``) names the shipped ``diagrams/<name>.yaml`` when
    there is one (``say`` reports it), else the error names the closest
    shipped ones. Anything else is returned as given; load_scenario says
    when it is a folder or missing.
    """
    path = Path(text).expanduser()
    if path.exists() or len(path.parts) != 1:
        return path
    stem = path.stem if path.suffix in (".yaml", ".yml") else path.name
    shipped = DIAGRAMS_DIR / f"{stem}.yaml"
    if shipped.is_file():
        if say is not None:
            say(f"scenario {text!r}: the shipped {shipped}")
        return shipped
    near = difflib.get_close_matches(stem, diagram_names(), n=3, cutoff=0.6)
    hint = (
        "; did you mean " + ", ".join(f"diagrams/{n}.yaml" for n in near) + "?"
        if near
        else f"; the shipped scenarios are in {str(DIAGRAMS_DIR)!r}"
    )
    raise VicDrakeError(
        f"scenario file {text!r} does not exist here nor as diagrams/{stem}.yaml{hint}"
    )


def resolve_data_dir(data_dir: str | os.PathLike | None = None) -> Path:
    """Returns the data folder to use (it may not exist; see require_data_dir)."""
    if data_dir is not None:
        return Path(data_dir).expanduser()
    env = os.environ.get(DATA_ENV_VAR)
    if env:
        return Path(env).expanduser()
    return DEFAULT_DATA_DIR


def has_data(data_dir: str | os.PathLike | None = None) -> bool:
    """True when the data folder exists and holds the phantom map."""
    return (resolve_data_dir(data_dir) / "phantom_map" / "z.txt").is_file()


_DATA_LAYOUT = "phantom_map/, experiments/, palpation/ and loadcycle/"


#: What a command does without the data, as :func:`check_data_dir` words it.
WITHOUT_DATA_SYNTHETIC = "run on the synthetic phantom"


def check_data_dir(
    data_dir: str | os.PathLike | None = None,
    without: str | None = WITHOUT_DATA_SYNTHETIC,
) -> None:
    """Fails when the user named a data folder that does not hold the data.

    A folder given as ``--data-dir`` or in ``$VIC_DRAKE_DATA`` must hold the
    paper's measurements (both are the same error); only the default
    ``../shared/data`` may be absent.

    Args:
        without: what the command does without a data folder, for the
            message's "omit the option to ..." (default: it runs on the
            synthetic phantom); None when it cannot run without the data.

    Raises:
        DataNotFoundError: naming the option or variable, the path and the
            expected layout.
    """
    if data_dir is not None:
        source, hint = f"--data-dir {str(data_dir)!r}", "omit the option"
    elif os.environ.get(DATA_ENV_VAR):
        source = f"{DATA_ENV_VAR}={os.environ[DATA_ENV_VAR]!r}"
        hint = f"unset {DATA_ENV_VAR}"
    else:
        return
    path = resolve_data_dir(data_dir)
    if not has_data(path):
        what = (
            "does not exist" if not path.exists() else "does not hold the paper's data"
        )
        tail = (
            f"{hint} to {without}"
            if without
            else "this command needs the data: name the folder that holds them"
        )
        raise DataNotFoundError(
            f"{source}: {str(path)!r} {what}; expected {_DATA_LAYOUT} in it ({tail})"
        )


def _data_dir_source(data_dir: str | os.PathLike | None) -> str:
    """Where :func:`resolve_data_dir` took the data folder from, for messages."""
    if data_dir is not None:
        return "--data-dir"
    if os.environ.get(DATA_ENV_VAR):
        return f"${DATA_ENV_VAR}"
    return "the default, ../shared/data beside the project"


def _close_names(folder: Path, name: str) -> list[str]:
    """Entries of ``folder`` whose names are close to ``name`` (difflib)."""
    import difflib

    try:
        names = sorted(p.name for p in folder.iterdir())
    except OSError:
        return []
    return difflib.get_close_matches(name, names, n=3, cutoff=0.6)


def _did_you_mean(folder: Path, name: str, shown: Path | None = None) -> str:
    """ " (did you mean ...?)" naming :func:`_close_names`, each as ``shown /
    name`` (the bare name without ``shown``); "" when none is close."""
    near = _close_names(folder, name)
    if not near:
        return ""
    items = (repr(n) if shown is None else repr(str(shown / n)) for n in near)
    return f" (did you mean {', '.join(items)}?)"


def find_bag(
    text: str | os.PathLike,
    data_dir: str | os.PathLike | None = None,
    *,
    what: str = "bag",
    expected: str = "a ROS 2 bag folder (metadata.yaml + .db3)",
) -> Path:
    """The bag folder (or file) ``text`` names, for every command that reads one.

    ``text`` as given (absolute, or relative to the current folder), else,
    when relative, relative to the data folder (:func:`resolve_data_dir` of
    ``data_dir``: ``--data-dir``, ``$VIC_DRAKE_DATA``, ``../shared/data``),
    so ``palpation/test_soft_1hz`` names the paper's log from any folder.

    Raises:
        DataNotFoundError: found in neither; the message says where it
            looked (or that there is no data folder, and how to name one),
            names close matches, and ``expected``.
    """
    path = Path(text).expanduser()
    if path.exists():
        return path
    if path.is_absolute():
        hint = _did_you_mean(path.parent, path.name)
        raise DataNotFoundError(
            f"{what} {str(text)!r} does not exist{hint}; expected {expected}"
        )
    folder = resolve_data_dir(data_dir)
    source = _data_dir_source(data_dir)
    candidate = folder / path
    if candidate.exists():
        return candidate
    here = f"in the current folder ({str(Path.cwd())!r})"
    if folder.is_dir():
        there = f"nor in the data folder {str(folder)!r} ({source})"
        there += _did_you_mean(candidate.parent, candidate.name, path.parent)
    else:
        there = (
            f"and there is no data folder ({source}: {str(folder)!r} does not "
            f"exist; pass --data-dir DIR or set {DATA_ENV_VAR})"
        )
    raise DataNotFoundError(
        f"{what} {str(text)!r} does not exist {here} {there}; expected {expected}"
    )


def find_data_dir(data_dir: str | os.PathLike | None = None) -> Path | None:
    """The data folder to use, or None where there is none (synthetic phantom).

    Raises:
        DataNotFoundError: ``--data-dir`` or ``$VIC_DRAKE_DATA`` names a folder
            without the data (:func:`check_data_dir`).
    """
    check_data_dir(data_dir)
    path = resolve_data_dir(data_dir)
    return path if has_data(path) else None


def require_data_dir(data_dir: str | os.PathLike | None = None) -> Path:
    """Returns the data folder, or raises DataNotFoundError naming where it looked."""
    path = resolve_data_dir(data_dir)
    if not path.is_dir():
        raise DataNotFoundError(
            f"data folder {str(path)!r} does not exist; pass --data-dir DIR or set "
            f"{DATA_ENV_VAR} to the folder holding {_DATA_LAYOUT}"
        )
    return path


def check_input_file(
    path: str | os.PathLike, what: str, suffixes: tuple[str, ...] = (".yaml", ".yml")
) -> Path:
    """Checks that ``path`` is a file to read; returns it.

    Raises:
        VicDrakeError: it is a folder (the message names one of its files
            with ``suffixes`` as an example), or it does not exist (naming
            close matches in its folder).
    """
    p = Path(path).expanduser()
    if p.is_file():
        return p
    if p.is_dir():
        files = sorted(f for f in p.iterdir() if f.suffix in suffixes and f.is_file())
        if files:
            example = str(Path(path) / files[0].name)
            raise VicDrakeError(
                f"{what} {str(path)!r} is a folder; give one of its "
                f"{suffixes[0]} files, e.g. {example}"
            )
        raise VicDrakeError(
            f"{what} {str(path)!r} is a folder (with no {suffixes[0]} files in it); "
            f"give a {suffixes[0]} file"
        )
    hint = _did_you_mean(p.parent, p.name, Path(path).parent)
    raise VicDrakeError(f"{what} {str(path)!r} does not exist{hint}")


#: Figure files the commands' --plot can write (matplotlib's formats).
PLOT_SUFFIXES = (
    ".png",
    ".pdf",
    ".svg",
    ".jpg",
    ".jpeg",
    ".eps",
    ".ps",
    ".tif",
    ".tiff",
)


def _first_existing_parent(path: Path) -> Path:
    p = path
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def check_output_dir(path: str | os.PathLike, option: str = "--out") -> Path:
    """Checks, before any work, that ``path`` can be a folder we write into.

    Creates it (and its parents) and writes and removes a probe file.

    Raises:
        VicDrakeError: it is a file, or cannot be created or written.
    """
    out = Path(path).expanduser()
    if out.exists() and not out.is_dir():
        raise VicDrakeError(
            f"{option} {str(out)!r} is a file; give a folder (it is created)"
        )
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / f".vic-drake-write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise VicDrakeError(
            f"{option} {str(out)!r} cannot be written: {exc.strerror or exc} "
            f"(check {str(_first_existing_parent(out))!r}); give a folder you can "
            "write to"
        ) from None
    return out


#: The run folders vic-drake writes, by their marker file: what
#: :func:`check_run_folder` calls a folder that holds one.
_RUN_FOLDERS = {
    REPRODUCE_RUN_FILE: "reproduce run",
    CAMPAIGN_SPEC_FILE: "campaign",
}


def check_run_folder(out: Path, marker: str, *, others: str) -> bool:
    """Checks the ``--out`` folder of a run before any work, writing nothing.

    ``out`` may be new, an empty folder, or a folder holding ``marker``
    (one of :data:`REPRODUCE_RUN_FILE`, :data:`CAMPAIGN_SPEC_FILE`: a
    previous run of the same command); anything else is refused, naming
    what it holds, so a run never mixes its files into another folder.

    Args:
        out: ``--out``, resolved.
        marker: the file that marks this command's folders.
        others: what the refusal offers instead of a new or empty folder
            (e.g. "a previous run's folder").

    Returns:
        Whether ``out`` holds ``marker``.

    Raises:
        VicDrakeError: ``out`` is a file, holds other files, or cannot be
            written; or it does not exist and its parent cannot be written.
    """
    kind = _RUN_FOLDERS[marker]
    if out.exists() and not out.is_dir():
        raise VicDrakeError(
            f"--out {str(out)!r} is a file; give a folder (it is created)"
        )
    own = (out / marker).is_file()
    if not own and out.is_dir() and any(out.iterdir()):
        raise VicDrakeError(
            f"--out {str(out)!r} holds {_folder_contents(out)}, not a {kind}; "
            f"give a new or empty folder, or {others}"
        )
    if not out.is_dir():
        check_output_dir(out.parent, option="--out's parent folder")
    elif not os.access(out, os.W_OK | os.X_OK):
        raise VicDrakeError(f"--out {str(out)!r} cannot be written")
    return own


def _run_folder_kind(out: Path) -> str | None:
    """ "a vic-drake <kind> (<marker>)" if ``out`` holds a run's marker, else None."""
    for marker, kind in _RUN_FOLDERS.items():
        if (out / marker).is_file():
            return f"a vic-drake {kind} ({marker})"
    return None


def check_not_a_run_folder(out: Path, option: str = "--out") -> None:
    """Refuses a folder that holds a reproduce run or a campaign (their
    marker files): a command that writes loose files never mixes them in."""
    kind = _run_folder_kind(out)
    if kind is not None:
        raise VicDrakeError(
            f"{option} {str(out)!r} holds {kind}; give a new or empty folder"
        )


def _folder_contents(out: Path) -> str:
    """What a folder that is not the asked kind of run holds."""
    kind = _run_folder_kind(out)
    if kind is not None:
        return kind
    names = sorted(p.name + ("/" if p.is_dir() else "") for p in out.iterdir())
    shown = ", ".join(names[:4]) + (", ..." if len(names) > 4 else "")
    return f"other files ({shown})"


def check_output_file(
    path: str | os.PathLike,
    option: str,
    suffixes: tuple[str, ...] | None = None,
) -> Path:
    """Checks, before any work, that a file can be written at ``path``.

    Creates the parent folder, and checks the suffix (when ``suffixes`` is
    given), that ``path`` is not a folder, and that the folder is writable.

    Raises:
        VicDrakeError: naming the option, the path and what is allowed.
    """
    out = Path(path).expanduser()
    if suffixes is not None and out.suffix.lower() not in suffixes:
        raise VicDrakeError(
            f"{option} must end in {' or '.join(suffixes)}; got {str(out)!r}"
        )
    if out.is_dir():
        raise VicDrakeError(f"{option} {str(out)!r} is a folder; give a file name")
    check_output_dir(out.parent, option=f"{option}'s folder")
    if out.exists() and not os.access(out, os.W_OK):
        raise VicDrakeError(f"{option} {str(out)!r} exists and cannot be overwritten")
    return out
