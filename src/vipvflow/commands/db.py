"""``vipvflow db start|stop|citus``: a local PostgreSQL + PostGIS server (or a Citus cluster)
for the mirror, and Citus for it."""
from __future__ import annotations

import sys


def register(sub):
    p = sub.add_parser("db", help="start / stop a local PostgreSQL+PostGIS server or Citus cluster",
                       description="A throwaway PostgreSQL + PostGIS server in one folder "
                       "(DIR/pgdata, DIR/socket, DIR/postgresql.log), or a Citus coordinator with "
                       "workers on this machine (DIR/worker<i>), run as the postgres system user "
                       "when started as root. Authentication: on TCP it listens on 127.0.0.1 only "
                       "and asks for the password of role postgres (scram-sha-256), generated on "
                       "the first start, printed once on stderr and kept in DIR/pgpass (mode "
                       "0600); the unix socket in DIR/socket (folder mode 0700) trusts the "
                       "server's own user. `start` prints the DSN to pass to `vipvflow mirror "
                       "--db` on stdout: it names DIR/pgpass (?passfile=) and holds no password.")
    actions = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    start = actions.add_parser("start", help="create (first time) and start the server; print its DSN")
    start.add_argument("--dir", required=True, help="folder of the server (e.g. data/pg)")
    start.add_argument("--port", type=int, default=None, help="TCP port (default: a free one)")
    start.add_argument("--citus-workers", type=int, default=None, metavar="N",
                       help="a Citus cluster: the coordinator and N workers (own ports and "
                       "folders under DIR); needs Citus installed (`vipvflow db citus`). "
                       "Kept: a later start of DIR starts the same cluster")
    start.set_defaults(func=run_start)
    stop = actions.add_parser("stop", help="stop the server (all nodes of a Citus cluster)")
    stop.add_argument("--dir", required=True, help="folder of the cluster given to start")
    stop.set_defaults(func=run_stop)
    citus = actions.add_parser(
        "citus", help="use the installed Citus, or build and install it from source",
        description="Says which Citus the local PostgreSQL has; without one, builds it from a "
        "Citus source tarball (--source; cached under ~/.cache/vipvflow/citus) and installs it "
        "into the server's folders (root). Otherwise one line on how to get it.")
    citus.add_argument("--source", default=None, metavar="TARBALL",
                       help="citus-<version>.tar.gz, or a folder holding one")
    citus.set_defaults(func=run_citus)


def _say(msg):
    print(msg, file=sys.stderr)


def run_start(args):
    from ..db import server
    from ..store import folder_path

    folder_path(args.dir, "--dir")
    srv = server.start(args.dir, port=args.port, say=_say, citus_workers=args.citus_workers)
    print(srv.dsn)  # stdout holds only the DSN: DSN=$(vipvflow db start --dir data/pg)
    return 0


def run_stop(args):
    from ..db import server

    server.stop(args.dir, say=_say)
    return 0


def run_citus(args):
    from ..db import citus

    citus.ensure(args.source, say=_say)
    return 0
