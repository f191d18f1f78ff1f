"""``vipvflow app``: the interactive web app on a finished run."""
from __future__ import annotations

from ..errors import InputError
from ..store import RunDir


def register(sub):
    p = sub.add_parser("app", help="interactive web app on a finished run (Bokeh server)",
                       description="Explore a finished run per trip and per fleet: PV technology "
                       "and size, route, direction, date and departure time, auxiliary load, SoC "
                       "limits. A trip is recomputed from the run's stored geometry factors, "
                       "horizon profiles and radiation data, without ray casting.")
    p.add_argument("run_dir", nargs="?", default="out/demo/2024",
                   help="run directory out/<scenario>/<year> (default out/demo/2024)")
    p.add_argument("--port", type=int, default=5006, help="port (default 5006)")
    p.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    p.add_argument("--show", action="store_true", help="open the app in a browser")
    p.set_defaults(func=run)


def run(args):
    from ..app.model import APP_NEEDS
    from ..app.server import serve
    from ..simulation.rundir import open_run

    run = open_run(args.run_dir, APP_NEEDS)       # from any working directory
    horizons = RunDir(run.path).part_dir("horizon")
    if not horizons.is_dir():
        raise InputError(f"{horizons}: no horizon profiles; the run predates "
                         "them: delete the run's parts/ and simulate again")
    serve(run.path, port=args.port, host=args.host, show=args.show)
    return 0
