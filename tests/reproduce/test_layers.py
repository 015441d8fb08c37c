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
