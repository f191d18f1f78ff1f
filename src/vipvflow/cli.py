"""The ``vipvflow`` command.

Each subcommand lives in a module of :mod:`vipvflow.commands` that defines
``register(subparsers)``; the subparser's ``func(args)`` does the work by calling the
library.  Errors caused by input or configuration (:class:`vipvflow.errors.VipvError`)
are printed as one line, never as a traceback.
"""
from __future__ import annotations

import argparse
import errno
import gc
import logging
import os
import sys

from . import __version__
from .commands import register_all
from .errors import VipvError

# subcommand modules in the order --help lists them
COMMANDS = [
    "demo",       # vipvflow demo-data
    "ingest",     # vipvflow ingest city|gtfs|cams
    "simulate",   # vipvflow simulate
    "track",      # vipvflow track
    "economics",  # vipvflow economics
    "vecto",      # vipvflow vecto
    "mirror",     # vipvflow mirror
    "export",     # vipvflow export dynamizer
    "app",        # vipvflow app
    "config",     # vipvflow config
    "data",       # vipvflow data fetch
    "db",         # vipvflow db start|stop
]

DESCRIPTION = """\
Solar energy harvested by PV modules on the roofs of an electric bus fleet along its real
routes in a real 3D city (CityGML LoD2 + GTFS + CAMS radiation), set against what the
buses consume.

typical use:
  vipvflow demo-data --out data/demo/input --year 2024   generate the embedded demo town
  vipvflow simulate --config demo --year 2024 [--out DIR]
  vipvflow simulate --config my_city.yaml --year 2024 --scheduler tcp://host:8786
"""


class Parser(argparse.ArgumentParser):
    """argparse's parser, whose usage errors are one line (what is wrong, where the help is)
    rather than the usage text and then the error; its subcommands' parsers are of this
    class too."""

    def error(self, message: str):
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="vipvflow", description=DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"vipvflow {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0,
                        help="more log output (-vv for debug)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    register_all(sub, COMMANDS)
    return parser


# optional packages and the extra that installs them (pyproject.toml)
OPTIONAL = {"bokeh": "app", "psycopg": "db"}


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(
        level=[logging.WARNING, logging.INFO, logging.DEBUG][min(args.verbose, 2)],
        format="%(levelname)s %(name)s: %(message)s")
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except VipvError as exc:
        print(f"vipvflow {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except ModuleNotFoundError as exc:
        extra = OPTIONAL.get((exc.name or "").split(".")[0])
        if extra is None:
            raise
        print(f"vipvflow {args.command}: error: needs the optional package '{exc.name}': "
              f"pip install 'vipvflow[{extra}]'", file=sys.stderr)
        return 2
    except OSError as exc:
        if exc.errno not in DISK_ERRORS | PATH_ERRORS:
            raise
        print(f"vipvflow {args.command}: error: {disk_error_line(exc)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # on a terminal, below a progress bar that is still drawing its line
        print(("\n" if sys.stderr.isatty() else "") + "vipvflow: interrupted", file=sys.stderr)
        return 130


#: errors of the disk a user points the command at: not writable, read-only, full, over quota,
#: over the size limit
DISK_ERRORS = {errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.EFBIG}


#: errors of a path naming a file where a folder is expected, or the other way round (an
#: output option given an existing file): the commands check their own options first, this
#: catches the rest
PATH_ERRORS = {errno.EEXIST, errno.ENOTDIR, errno.EISDIR}


def disk_error_line(exc: OSError) -> str:
    """``<file>: <reason> (<what to do>)`` of an OSError of :data:`DISK_ERRORS` or
    :data:`PATH_ERRORS`."""
    where = f"{exc.filename}: " if exc.filename else ""
    reason = " ".join(str(exc.strerror or os.strerror(exc.errno)).split())
    if exc.errno in PATH_ERRORS:
        return f"{where}{reason} (a file where a folder is expected, or a folder where a file is)"
    if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
        hint = "free space or choose another out_dir / data_dir; the same command then resumes"
    else:
        hint = "choose a writable out_dir / data_dir, or check the file's permissions"
    return f"{where}{reason} ({hint})"


def entry() -> int:
    """The ``vipvflow`` command: :func:`main`, then out of the process without the cyclic
    garbage collector's passes over everything loaded (a simulate's exit took ~1 s on them):
    nothing is left to clean up that the operating system does not."""
    code = main()
    gc.freeze()
    return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(entry())
