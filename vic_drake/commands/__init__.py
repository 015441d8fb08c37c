"""Subcommands of ``vic-drake``; each module has ``register(subparsers)``."""
