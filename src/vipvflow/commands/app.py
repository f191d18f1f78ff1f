"""``vipvflow app``: the interactive web app on a finished run."""
from __future__ import annotations

import errno
import socket

from ..errors import InputError
from ..store import RunDir
from . import port_number


def register(sub):
    p = sub.add_parser("app", help="interactive web app on a finished run (Bokeh server)",
                       description="Explore a finished run per trip and per fleet: PV technology "
                       "and size, route, direction, date and departure time, auxiliary load, SoC "
                       "limits. A trip is recomputed from the run's stored geometry factors, "
                       "horizon profiles and radiation data, without ray casting.")
    p.add_argument("run_dir", nargs="?", default="out/demo/2024",
                   help="run directory out/<scenario>/<year> (default out/demo/2024)")
    p.add_argument("--port", type=port_number(5006), default=5006,
                   help="port to listen on, 1..65535 (default 5006; when it is taken, the error "
                        "names a free one)")
    p.add_argument("--host", default="127.0.0.1",
                   help="address to listen on (default 127.0.0.1: this machine only; 0.0.0.0: "
                        "every interface)")
    p.add_argument("--show", action="store_true", help="open the app in a browser")
    p.set_defaults(func=run)


def run(args):
    from ..app.model import APP_NEEDS
    from ..app.server import serve
    from ..simulation.rundir import open_run

    check_listen(args.host, args.port)           # before the run is loaded (seconds)
    run = open_run(args.run_dir, APP_NEEDS)       # from any working directory
    horizons = RunDir(run.path).part_dir("horizon")
    if not horizons.is_dir():
        raise InputError(f"{horizons}: no horizon profiles; the run predates "
                         "them: delete the run's parts/ and simulate again")
    try:
        serve(run.path, port=args.port, host=args.host, show=args.show)
    except OSError as exc:                       # taken meanwhile
        raise InputError(listen_error(args.host, args.port, exc)) from None
    return 0


def check_listen(host: str, port: int) -> None:
    """Raise :class:`InputError` with one line (and a port or host to try instead) when the
    app cannot listen on *host*:*port*."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror as exc:
        raise InputError(f"--host {host}: not an address of this machine ({exc.strerror}); "
                         "try --host 127.0.0.1") from None
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)   # as the server binds
        try:
            s.bind(address)
        except OSError as exc:
            raise InputError(listen_error(host, port, exc)) from None


def listen_error(host: str, port: int, exc: OSError) -> str:
    """The line of a failed listen: what is wrong and what to try."""
    if exc.errno == errno.EADDRINUSE:
        return f"port {port} on {host} is in use (another app?): try --port {free_port(host, port)}"
    if exc.errno == errno.EACCES:
        return f"port {port} needs privileges on {host}: try --port {free_port(host, 5006)}"
    if exc.errno == errno.EADDRNOTAVAIL:
        return f"--host {host}: not an address of this machine; try --host 127.0.0.1"
    return f"cannot listen on {host}:{port} ({exc.strerror or exc}): try --port {free_port(host, port)}"


def free_port(host: str, after: int) -> int:
    """The first port above *after* (from 1024) free on *host*, else one the system picks."""
    for candidate in range(max(after + 1, 1024), min(max(after + 1, 1024) + 100, 65536)):
        with socket.socket() as s:
            try:
                s.bind((host, candidate))
                return candidate
            except OSError:
                continue
    with socket.socket() as s:
        s.bind((host, 0))
        return s.getsockname()[1]
