"""The pure layers import no Drake systems (import-linter checks the rest:
see [tool.importlinter] in pyproject.toml, run by .ci/run)."""

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "vic_drake"
PURE_LAYERS = ("tissue", "control", "estimation")
FORBIDDEN = "pydrake.systems"


def _imports(path: Path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, alias.name
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            yield node.lineno, node.module


@pytest.mark.parametrize("layer", PURE_LAYERS)
def test_pure_layer_imports_no_drake_systems(layer):
    offenders = [
        f"{path.relative_to(PACKAGE.parent)}:{line} imports {name}"
        for path in sorted((PACKAGE / layer).rglob("*.py"))
        for line, name in _imports(path)
        if name == FORBIDDEN or name.startswith(FORBIDDEN + ".")
    ]
    assert not offenders, "\n".join(offenders)


def test_every_module_is_at_most_500_lines():
    lengths = {
        path: len(path.read_text().splitlines()) for path in PACKAGE.rglob("*.py")
    }
    long = [
        f"{path.relative_to(PACKAGE.parent)}: {n} lines"
        for path, n in sorted(lengths.items())
        if n > 500
    ]
    assert not long, "\n".join(long)
