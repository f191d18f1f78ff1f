"""The subcommands of ``vipvflow``: one module each, defining ``register(subparsers)``.

This package holds what the subcommands share: :func:`register_all` (used by :mod:`vipvflow.cli`
and by ``ingest`` for its own subcommands, so no command module imports the CLI) and
:func:`add_config`, the one ``--config`` option of every subcommand that reads a scenario.
"""
from __future__ import annotations

import importlib

#: the help of ``--config`` (every subcommand that reads a scenario)
CONFIG_HELP = ("scenario: a YAML file, or the name of a shipped scenario ({names}); "
               "default: {default}")


def register_all(subparsers, modules: list[str]) -> None:
    """Let each module of :mod:`vipvflow.commands` named in *modules* add its subcommand."""
    for name in modules:
        importlib.import_module(f"{__name__}.{name}").register(subparsers)


def add_config(parser, default: str | None = None) -> None:
    """Add ``--config/-c`` to *parser*: a scenario YAML or a shipped scenario's name, read by
    :func:`vipvflow.config.load_config` (names resolved by :func:`vipvflow.config.scenario_path`).
    *default* ``None`` means the shipped defaults alone."""
    from ..config import shipped_scenarios

    parser.add_argument("--config", "-c", default=default, metavar="SCENARIO",
                        help=CONFIG_HELP.format(names=", ".join(shipped_scenarios()),
                                                default=default or "the shipped defaults alone"))


def port_number(suggest: int, allow_zero: bool = False):
    """An argparse type: a TCP port, 1..65535 (0 too with *allow_zero*: any free port); else
    one line saying what is wrong and suggesting port *suggest*."""
    import argparse

    low = 0 if allow_zero else 1

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            value = None
        if value is None or not low <= value <= 65535:
            raise argparse.ArgumentTypeError(f"{text!r} is not a port number ({low}..65535): "
                                             f"try {suggest}")
        return value

    parse.__name__ = "port"
    return parse


def add_accept(parser) -> None:
    """Add ``--accept FINDING`` (repeatable) to *parser*: a plausibility finding to accept for
    the rare real case, added to ``checks.accept`` of the scenario (docs/checks.md)."""
    from ..config import PLAUSIBILITY_FINDINGS

    parser.add_argument("--accept", action="append", default=[], metavar="FINDING",
                        choices=sorted(PLAUSIBILITY_FINDINGS),
                        help="accept a plausibility finding the inputs are refused for, when it is "
                        "right after all (also checks.accept): " + "; ".join(
                            f"{k}: {v}" for k, v in PLAUSIBILITY_FINDINGS.items()))


def accepted(cfg, args) -> tuple[str, ...]:
    """The plausibility findings accepted: ``checks.accept`` of *cfg* and ``--accept``."""
    return tuple(sorted({*cfg.checks.accept, *(getattr(args, "accept", None) or [])}))


def ingest_lock(data_dir):
    """The data dir's lock taken for an ingest (exclusively), as a context manager; a data
    dir that is a file, or that another vipvflow process uses, is refused in one line."""
    from ..store import data_dir_lock, folder_path, lock_for_writing

    return lock_for_writing(data_dir_lock(folder_path(data_dir, "--data-dir")), "ingest")
