"""The Bokeh server of the web app, started programmatically with a function handler.

BokehJS and the app's assets are served by the server itself (resources ``"server"``):
the page makes no request beyond the server's host, and the route is drawn in projected
x/y without map tiles.
"""
from __future__ import annotations

import logging
import os
from functools import partial

from ..errors import InputError


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

    if not 0 <= int(port) <= 65535:
        raise InputError(f"--port {port}: not a TCP port (0..65535; 0 picks a free one)")
    model = model if model is not None else TripModel(run_dir)
    app = Application(FunctionHandler(partial(build_document, model)))
    origins = [f"{host}:{port}", f"localhost:{port}", f"127.0.0.1:{port}"]
    kw = {"io_loop": io_loop} if io_loop is not None else {}
    try:
        server = Server({"/": app}, port=port, address=host, allow_websocket_origin=origins,
                        num_procs=1, **kw)
    except OSError as exc:         # the port is taken, or the address is not this machine's
        reason = " ".join(str(exc.strerror or exc).split())
        raise InputError(f"--host {host} --port {port}: cannot listen there ({reason}); choose "
                         "another --port (or --host)") from None
    _refusals_in_one_line()
    return server


class _OneLine(logging.Filter):
    """A request the server refuses as the client's error (a raw WebSocket request without
    Bokeh's subprotocol: :class:`bokeh.protocol.exceptions.ProtocolError`) is logged in one
    warning line naming the request, not as an "Uncaught exception" with a traceback."""

    def filter(self, record: logging.LogRecord) -> bool:
        from bokeh.protocol.exceptions import ProtocolError

        exc = record.exc_info[1] if record.exc_info else None
        if isinstance(exc, ProtocolError):
            what = record.args[0] if isinstance(record.args, tuple) and record.args else "a request"
            record.msg, record.args = "refused %s: %s", (what, exc)
            record.exc_info, record.exc_text = None, None
            record.levelno, record.levelname = logging.WARNING, "WARNING"
        return True


def _refusals_in_one_line() -> None:
    """Put :class:`_OneLine` on tornado's application log (once)."""
    logger = logging.getLogger("tornado.application")
    if not any(isinstance(f, _OneLine) for f in logger.filters):
        logger.addFilter(_OneLine())


def serve(run_dir, port: int = 5006, host: str = "127.0.0.1", show: bool = False, say=print) -> None:
    """Load the run, start the server and block until interrupted."""
    server = make_server(run_dir, port=port, host=host)
    server.start()
    say(f"vipvflow app on http://{host}:{port}/ (run {run_dir}); Ctrl-C stops it")
    if show:
        server.io_loop.add_callback(server.show, "/")
    server.io_loop.start()
