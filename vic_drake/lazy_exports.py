"""A package's exports imported on first use (PEP 562 ``__getattr__``)."""

from __future__ import annotations

import importlib


def lazy_exports(package: dict, exports: dict[str, str]):
    """(``__getattr__``, ``__dir__``) for the package whose globals are
    ``package``: each name of ``exports`` is imported from its module (a full
    module path) on first use, then kept in the package's globals."""
    name = package["__name__"]

    def __getattr__(attr: str):
        module = exports.get(attr)
        if module is None:
            raise AttributeError(f"module {name!r} has no attribute {attr!r}")
        value = getattr(importlib.import_module(module), attr)
        package[attr] = value  # Imported once.
        return value

    def __dir__() -> list[str]:
        return sorted({*package, *exports})

    return __getattr__, __dir__


__all__ = ["lazy_exports"]
