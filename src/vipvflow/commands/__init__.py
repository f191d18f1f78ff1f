"""Subcommands of the ``vipvflow`` CLI, one module each (see :mod:`vipvflow.cli`)."""
