"""``vipvflow simulate``: the fleet-year of a scenario on a LocalCluster or any Dask scheduler."""
from __future__ import annotations

from ..config import load_config


def register(sub):
    p = sub.add_parser("simulate", help="compute a scenario's fleet-year (Dask task graph)",
                       description="Prepare inputs (demo generation, ingest), evaluate every pass of "
                       "every trip of the year per (tile, month) partition, reduce and write "
                       "out/<scenario>/<year>/. Re-running resumes an interrupted run.")
    p.add_argument("--config", "-c", default="conf/demo.yaml", help="scenario YAML (default conf/demo.yaml)")
    p.add_argument("--year", type=int, required=True)
    p.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler (tcp://host:8786); default: a LocalCluster")
    p.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes (default: cores)")
    p.add_argument("--db", default=None, help="PostgreSQL DSN: mirror the finished run into PostGIS/Citus")
    p.add_argument("--force", action="store_true",
                   help="replace a run of another configuration in the run directory (refused "
                   "without: the two configuration digests are named)")
    p.set_defaults(func=run)


def run(args):
    from ..simulation import run_simulation

    overrides = {"db": {"dsn": args.db}} if args.db else None
    cfg = load_config(args.config, overrides=overrides)
    run_dir = run_simulation(cfg, args.year, scheduler=args.scheduler, n_workers=args.workers,
                             force=args.force)
    if cfg.db.dsn and (run_dir / "summary.json").exists():
        from ..db import mirror_run

        mirror_run(cfg.db.dsn, run_dir)
    return 0
