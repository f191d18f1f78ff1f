"""``vipvflow mirror``: copy a finished run into PostGIS (Citus when the server has it)."""
from __future__ import annotations

import os


def register(sub):
    p = sub.add_parser(
        "mirror", help="mirror a finished run directory into PostGIS/Citus",
        description="COPY the outputs of a run directory (out/<scenario>/<year>) into tables of "
        "schema vipvflow keyed by run id. Idempotent: mirroring again changes nothing, an "
        "interrupted mirror resumes. With the citus extension the big tables are distributed. "
        "See docs/database.md.")
    p.add_argument("run_dir", metavar="RUN_DIR", help="run directory, e.g. out/demo/2024")
    p.add_argument("--db", default=os.environ.get("VIPVFLOW_DB"), metavar="DSN",
                   help="PostgreSQL DSN, e.g. postgresql://postgres@127.0.0.1:5432/vipvflow "
                   "(default: $VIPVFLOW_DB; `vipvflow db start` prints one)")
    p.add_argument("--force", action="store_true",
                   help="replace the run's rows even where its files did not change")
    p.set_defaults(func=run)


def run(args):
    from ..db import mirror_run
    from ..errors import ConfigError

    if not args.db:
        raise ConfigError("no database given: pass --db DSN or set VIPVFLOW_DB")
    mirror_run(args.db, args.run_dir, force=args.force)
    return 0
