"""The scan processes' allocator: mimalloc preloaded and glibc's cache enlarged, set once at start."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from vic_drake.malloc_tuning import (
    ALLOCATOR_VAR,
    ENV_VAR,
    PRELOAD_VAR,
    TUNABLES,
    allocator,
    is_tuned,
    mimalloc_library,
    tuned_environment,
    tuned_preload,
    tuned_tunables,
    uses_glibc,
)

ROOT = Path(__file__).resolve().parents[1]
OURS = ":".join(f"{name}={value}" for name, value in TUNABLES)
MIMALLOC = mimalloc_library()
needs_glibc = pytest.mark.skipif(
    not (uses_glibc() and Path("/proc/self/environ").exists()),
    reason="glibc on Linux only",
)
needs_mimalloc = pytest.mark.skipif(
    MIMALLOC is None or not uses_glibc(),
    reason="cmeel-mimalloc is installed on Linux only",
)


def test_the_tunables_are_added_to_what_is_there():
    assert tuned_tunables(None) == OURS
    assert tuned_tunables("") == OURS
    assert tuned_tunables("glibc.malloc.trim_threshold=1") == (
        "glibc.malloc.trim_threshold=1:" + OURS
    )


def test_a_tunable_set_by_the_user_keeps_its_value():
    mine = "glibc.malloc.tcache_count=7:glibc.malloc.mxfast=0"
    assert tuned_tunables(mine) == mine
    glibc = {ALLOCATOR_VAR: "glibc"}
    assert is_tuned({**glibc, ENV_VAR: mine})
    assert not is_tuned(glibc)
    assert not is_tuned({**glibc, ENV_VAR: "glibc.malloc.mxfast=0"})


def test_tuned_environment_copies():
    env = {"A": "1"}
    tuned = tuned_environment(env)
    assert env == {"A": "1"}
    expected = {"A": "1", ENV_VAR: OURS}
    if MIMALLOC is not None:
        expected[PRELOAD_VAR] = MIMALLOC
    assert tuned == expected
    assert is_tuned(tuned)
    assert not is_tuned(env)


@needs_mimalloc
def test_mimalloc_is_preloaded_unless_the_user_chose_otherwise():
    assert Path(MIMALLOC).is_file() and "mimalloc" in Path(MIMALLOC).name
    assert tuned_preload({}) == MIMALLOC
    assert tuned_preload({PRELOAD_VAR: ""}) == MIMALLOC  # empty: nothing chosen
    # A user's own preload is kept as it is, and counts as tuned.
    assert tuned_preload({PRELOAD_VAR: "/opt/lib/libjemalloc.so"}) == (
        "/opt/lib/libjemalloc.so"
    )
    assert is_tuned({PRELOAD_VAR: "/opt/lib/libjemalloc.so", ENV_VAR: OURS})
    # glibc asked for: the tunables only.
    glibc = tuned_environment({ALLOCATOR_VAR: "glibc"})
    assert PRELOAD_VAR not in glibc and glibc[ENV_VAR] == OURS
    assert is_tuned(glibc)
    assert tuned_environment({ALLOCATOR_VAR: " MiMalloc "})[PRELOAD_VAR] == MIMALLOC


def test_an_unknown_allocator_is_named_with_the_choices():
    assert allocator({}) == "mimalloc"
    assert allocator({ALLOCATOR_VAR: "glibc"}) == "glibc"
    with pytest.raises(ValueError, match="'tcmalloc': choose from mimalloc, glibc"):
        tuned_environment({ALLOCATOR_VAR: "tcmalloc"})


def _environ_at_exec():
    """Python code printing GLIBC_TUNABLES as the kernel started the process
    with it, and whether mimalloc is mapped into the process."""
    return (
        "import sys;"
        "env = dict(e.split(b'=', 1) for e in"
        " open('/proc/self/environ', 'rb').read().split(b'\\0') if b'=' in e);"
        f"print('exec:', env.get(b'{ENV_VAR}', b'').decode());"
        "print('mimalloc:', 'libmimalloc' in open('/proc/self/maps').read())"
    )


def _without_ours(**extra):
    env = {
        k: v
        for k, v in os.environ.items()
        if k not in (ENV_VAR, PRELOAD_VAR, ALLOCATOR_VAR)
    }
    return {**env, **extra}


def _run(code, env):
    env = {**env, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


@needs_glibc
def test_reexec_restarts_once_with_the_tunables_in_the_start_environment():
    code = (
        "import vic_drake.malloc_tuning as m;"
        "print('start');"
        "m.reexec_tuned();" + _environ_at_exec()
    )
    # "start" twice: the first process printed it, then was replaced.
    mapped = f"mimalloc: {MIMALLOC is not None}"
    assert _run(code, _without_ours()) == ["start", "start", f"exec: {OURS}", mapped]


@needs_glibc
def test_reexec_leaves_a_users_setting_alone():
    env = _without_ours(**{ENV_VAR: "glibc.malloc.tcache_count=7"})
    code = "import vic_drake.malloc_tuning as m;m.reexec_tuned();" + _environ_at_exec()
    mapped = f"mimalloc: {MIMALLOC is not None}"
    # Restarted for the allocator (when installed), the tunable kept.
    assert _run(code, env)[-2:] == ["exec: glibc.malloc.tcache_count=7", mapped]
    env = _without_ours(
        **{ENV_VAR: "glibc.malloc.tcache_count=7", ALLOCATOR_VAR: "glibc"}
    )
    assert _run(code, env) == ["exec: glibc.malloc.tcache_count=7", "mimalloc: False"]


@needs_glibc
def test_the_command_line_restarts_tuned_and_then_runs_the_command():
    code = (
        "import sys;"
        "from vic_drake.cli import main;"
        + _environ_at_exec()
        + ";sys.argv = ['vic-drake', '--version'];main()"
    )
    lines = _run(code, _without_ours())
    assert lines[:4] == [
        "exec: ",
        "mimalloc: False",
        f"exec: {OURS}",
        f"mimalloc: {MIMALLOC is not None}",
    ]
    assert lines[4].startswith("vic-drake ")


def test_the_command_line_names_an_unknown_allocator():
    env = {**_without_ours(**{ALLOCATOR_VAR: "tcmalloc"}), "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [
            sys.executable,
            "-c",
            "import sys; from vic_drake.cli import main; sys.exit(main())",
        ],
        env=env,
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    assert done.stderr.strip() == (
        f"vic-drake: error: {ALLOCATOR_VAR}='tcmalloc': choose from mimalloc, glibc"
    )


@pytest.mark.parametrize(
    "args, first",
    [
        (["--help"], "usage: vic-drake [-h]"),
        (["--version"], "vic-drake "),
        (["scan", "--help"], "usage: vic-drake scan"),
        (["map", "-h", "--out", "x"], "usage: vic-drake map"),
    ],
)
def test_help_and_version_print_despite_an_unknown_allocator(args, first):
    """The allocator matters to the commands, not to their help: it prints,
    after a note naming the bad value; a command still refuses to run."""
    env = {**_without_ours(**{ALLOCATOR_VAR: "tcmalloc"}), "PYTHONPATH": str(ROOT)}
    code = (
        f"import sys; sys.argv = ['vic-drake', *{args!r}];"
        "from vic_drake.cli import main; sys.exit(main())"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(first)
    assert done.stderr.strip() == (
        f"vic-drake: note: {ALLOCATOR_VAR}='tcmalloc': choose from mimalloc, glibc "
        "(commands will not run)"
    )
    # After "--", -h is an argument, not a request for help.
    code = (
        "import sys; sys.argv = ['vic-drake', 'scan', '--', '-h'];"
        "from vic_drake.cli import main; sys.exit(main())"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True
    )
    assert done.returncode == 2 and "tcmalloc" in done.stderr
    assert "note:" not in done.stderr


def test_the_command_line_called_as_a_function_does_not_restart(capsys):
    from vic_drake.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.startswith("vic-drake ")


def test_the_campaign_leaves_the_session_environment_alone():
    """Dask's pre-spawn settings would stay in this process's os.environ (and
    reach every program it starts later); the engine sets none."""
    from vic_drake.experiments.dask_cluster import dask_client

    before = {k: os.environ.get(k) for k in (ENV_VAR, PRELOAD_VAR)}
    client, cluster = dask_client(1, None)
    try:
        client.run(lambda: None)
    finally:
        client.close()
        cluster.close()
    assert {k: os.environ.get(k) for k in (ENV_VAR, PRELOAD_VAR)} == before


def test_each_campaign_run_process_starts_with_the_allocator(monkeypatch):
    import vic_drake.experiments.campaign.run as run
    import vic_drake.experiments.child_process as child

    seen = {}

    def fake_run(args, **kwargs):
        seen.update(kwargs)
        return subprocess.CompletedProcess(args, 1, b"", b"stopped by the test")

    monkeypatch.setattr(child.subprocess, "run", fake_run)
    plan = run.RunPlan.__new__(run.RunPlan)
    monkeypatch.setattr(run, "failed_row", lambda plan, error, **kw: {"error": error})
    assert "stopped by the test" in run.execute_run_in_child(plan)["error"]
    assert seen["env"] == tuned_environment()
    # A bad allocator name on the worker's machine: the run's error says so.
    monkeypatch.setenv(ALLOCATOR_VAR, "tcmalloc")
    error = run.execute_run_in_child(plan)["error"]
    assert error == f"{ALLOCATOR_VAR}='tcmalloc': choose from mimalloc, glibc"
