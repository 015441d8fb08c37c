"""Subcommands of ``vic-drake``; each module has ``register(subparsers)``.

Every command module is imported to build the parser, so each handler
imports what it runs (pydrake, the pipeline, pandas) inside itself: the
function-local imports of this package keep ``vic-drake --help`` and a bad
option's error instant.
"""
