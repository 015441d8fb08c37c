"""vic_drake.reproduce sits below the command line: it never imports it."""

import subprocess
import sys


def test_reproduce_does_not_import_the_commands():
    code = (
        "import sys, vic_drake.reproduce, vic_drake.reproduce.plots.scans\n"
        "bad = sorted(m for m in sys.modules if m.startswith('vic_drake.commands'))\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_command_line_parser_does_not_import_the_pipeline():
    """The reproduce help names the stages without importing the pipeline
    (vic_drake.reproduce imports its names on first use)."""
    code = (
        "import sys\n"
        "from vic_drake.cli import build_parser\n"
        "build_parser()\n"
        "bad = sorted(m for m in sys.modules if m.startswith('vic_drake.reproduce.')\n"
        "             and m != 'vic_drake.reproduce.stage_names')\n"
        "assert not bad, bad\n"
        "import vic_drake.reproduce as r\n"
        "assert r.reproduce is r.pipeline.reproduce and 'scan_scenario' in dir(r)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_the_command_line_parser_imports_no_simulation_nor_cluster():
    """The parser (its --help) is built without pydrake, pandas or Dask:
    the commands import them when they run."""
    code = (
        "import sys\n"
        "from vic_drake.cli import build_parser\n"
        "build_parser()\n"
        "heavy = ('pydrake', 'pandas', 'distributed', 'dask', 'matplotlib')\n"
        "bad = sorted(m for m in heavy if m in sys.modules)\n"
        "assert not bad, bad\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
