"""glibc's malloc cache setting: merged into GLIBC_TUNABLES, set once at start."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

from vic_drake.malloc_tuning import (
    ENV_VAR,
    TUNABLES,
    is_tuned,
    tuned_environment,
    tuned_tunables,
    uses_glibc,
)

ROOT = Path(__file__).resolve().parents[1]
OURS = ":".join(f"{name}={value}" for name, value in TUNABLES)
needs_glibc = pytest.mark.skipif(
    not (uses_glibc() and Path("/proc/self/environ").exists()),
    reason="glibc on Linux only",
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
    assert is_tuned({ENV_VAR: mine})
    assert not is_tuned({})
    assert not is_tuned({ENV_VAR: "glibc.malloc.mxfast=0"})


def test_tuned_environment_copies():
    env = {"A": "1"}
    tuned = tuned_environment(env)
    assert env == {"A": "1"}
    assert tuned == {"A": "1", ENV_VAR: OURS}
    assert is_tuned(tuned)


def _environ_at_exec():
    """Python code printing GLIBC_TUNABLES as the kernel started the process with it."""
    return (
        "import sys;"
        "env = dict(e.split(b'=', 1) for e in"
        " open('/proc/self/environ', 'rb').read().split(b'\\0') if b'=' in e);"
        f"print('exec:', env.get(b'{ENV_VAR}', b'').decode())"
    )


def _run(code, env):
    env = {**env, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


@needs_glibc
def test_reexec_restarts_once_with_the_tunables_in_the_start_environment():
    env = {k: v for k, v in os.environ.items() if k != ENV_VAR}
    code = (
        "import vic_drake.malloc_tuning as m;"
        "print('start');"
        "m.reexec_tuned();" + _environ_at_exec()
    )
    # "start" twice: the first process printed it, then was replaced.
    assert _run(code, env) == ["start", "start", f"exec: {OURS}"]


@needs_glibc
def test_reexec_leaves_a_users_setting_alone():
    env = {**os.environ, ENV_VAR: "glibc.malloc.tcache_count=7"}
    code = "import vic_drake.malloc_tuning as m;m.reexec_tuned();" + _environ_at_exec()
    assert _run(code, env) == ["exec: glibc.malloc.tcache_count=7"]


@needs_glibc
def test_the_command_line_restarts_tuned_and_then_runs_the_command():
    env = {k: v for k, v in os.environ.items() if k != ENV_VAR}
    code = (
        "import sys;"
        "from vic_drake.cli import main;"
        + _environ_at_exec()
        + ";sys.argv = ['vic-drake', '--version'];main()"
    )
    lines = _run(code, env)
    assert lines[:2] == ["exec: ", f"exec: {OURS}"]
    assert lines[2].startswith("vic-drake ")


def test_the_command_line_called_as_a_function_does_not_restart(capsys):
    from vic_drake.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert capsys.readouterr().out.startswith("vic-drake ")


@needs_glibc
def test_local_campaign_workers_start_with_the_tunables():
    from vic_drake.experiments.campaign.engine import _client

    client, cluster = _client(1, None)
    try:
        at_exec = client.run(
            lambda: open("/proc/self/environ", "rb").read().split(b"\0")
        )
    finally:
        client.close()
        cluster.close()
    (environ,) = at_exec.values()
    assert f"{ENV_VAR}={OURS}".encode() in environ
