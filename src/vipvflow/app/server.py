"""The Bokeh server of the web app, started programmatically with a function handler.

BokehJS and the app's assets are served by the server itself (resources ``"server"``):
the page makes no request beyond the server's host, and the route is drawn in projected
x/y without map tiles.
"""
from __future__ import annotations

import os
from functools import partial


def make_server(run_dir=None, port: int = 5006, host: str = "127.0.0.1", model=None, io_loop=None):
    """A started-not-running :class:`bokeh.server.server.Server` serving the app at ``/``.

    Parameters
    ----------
    run_dir : path of a finished run (``out/<scenario>/<year>/``); ignored with *model*
    port, host : where to listen (default 127.0.0.1:5006)
    model : a loaded :class:`vipvflow.app.model.TripModel` (loaded from *run_dir* if None)
    io_loop : tornado IOLoop (default: the current thread's)
    """
    os.environ["BOKEH_RESOURCES"] = "server"      # BokehJS from this server, never a CDN
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server

    from .layout import build_document
    from .model import TripModel

    model = model if model is not None else TripModel(run_dir)
    app = Application(FunctionHandler(partial(build_document, model)))
    origins = [f"{host}:{port}", f"localhost:{port}", f"127.0.0.1:{port}"]
    kw = {"io_loop": io_loop} if io_loop is not None else {}
    server = Server({"/": app}, port=port, address=host, allow_websocket_origin=origins,
                    num_procs=1, **kw)
    return server


def serve(run_dir, port: int = 5006, host: str = "127.0.0.1", show: bool = False, say=print) -> None:
    """Load the run, start the server and block until interrupted."""
    server = make_server(run_dir, port=port, host=host)
    server.start()
    say(f"vipvflow app on http://{host}:{port}/ (run {run_dir}); Ctrl-C stops it")
    if show:
        server.io_loop.add_callback(server.show, "/")
    server.io_loop.start()
