"""``vipvflow db start|stop``: a local PostgreSQL + PostGIS server for the mirror."""
from __future__ import annotations

import sys


def register(sub):
    p = sub.add_parser("db", help="start / stop a local PostgreSQL+PostGIS server",
                       description="A throwaway PostgreSQL + PostGIS cluster in one folder "
                       "(as the postgres system user when run as root). On TCP it listens on "
                       "127.0.0.1 only and asks for a password (scram-sha-256) of the postgres "
                       "role, generated on the first start, printed once and kept in "
                       "<dir>/pgpass (mode 0600); its unix socket, in a folder only the server's "
                       "user can open, is trusted. `start` prints the DSN to pass to `vipvflow "
                       "mirror --db`: it names the password file, never the password.")
    actions = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    start = actions.add_parser("start", help="create (first time) and start the server; print its DSN")
    start.add_argument("--dir", required=True, help="folder of the cluster (e.g. data/pg)")
    start.add_argument("--port", type=int, default=None, help="TCP port (default: a free one)")
    start.set_defaults(func=run_start)
    stop = actions.add_parser("stop", help="stop the server")
    stop.add_argument("--dir", required=True)
    stop.set_defaults(func=run_stop)


def _say(msg):
    print(msg, file=sys.stderr)


def run_start(args):
    from ..db import server
    from ..store import folder_path

    folder_path(args.dir, "--dir")
    srv = server.start(args.dir, port=args.port, say=_say)
    print(srv.dsn)  # stdout holds only the DSN: DSN=$(vipvflow db start --dir data/pg)
    return 0


def run_stop(args):
    from ..db import server

    server.stop(args.dir, say=_say)
    return 0
