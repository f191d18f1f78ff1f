"""``vipvflow simulate``: the fleet-year of a scenario on a LocalCluster or any Dask scheduler."""
from __future__ import annotations

from pathlib import Path

from ..config import load_config
from ..progress import set_quiet
from ..store import folder_path
from . import accepted, add_accept, add_config, port_number


def register(sub):
    p = sub.add_parser("simulate", help="compute a scenario's fleet-year (Dask task graph)",
                       description="Prepare inputs (demo generation, ingest), evaluate every pass of "
                       "every trip of the year per (tile, month) partition, reduce and write "
                       "out/<scenario>/<year>/. Re-running resumes an interrupted run.")
    add_config(p, default="demo")
    p.add_argument("--year", type=int, required=True,
                   help="calendar year to simulate (the GTFS calendar must serve it and the CAMS "
                        "radiation cover it; the demo is generated for it)")
    p.add_argument("--out", type=Path, default=None,
                   help="folder for the scenario's relative data_dir and out_dir (and the demo's "
                        "generated inputs) instead of the current directory")
    p.add_argument("--scheduler", default=None,
                   help="address of a running Dask scheduler (tcp://host:8786); default: a LocalCluster")
    p.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes (default: cores)")
    p.add_argument("--dashboard-port", type=port_number(8787, allow_zero=True), default=None, metavar="PORT",
                   help="port of the LocalCluster's Dask dashboard (default: dask.dashboard_port, "
                        "8787; when taken, or 0, any free port: the address is printed)")
    p.add_argument("--db", default=None, help="PostgreSQL DSN: mirror the finished run into PostGIS/Citus")
    p.add_argument("--quiet", "-q", action="store_true",
                   help="no progress bars or progress lines")
    p.add_argument("--force", action="store_true",
                   help="replace a run of another configuration or of other input files in the "
                   "run directory (refused without: the two digests are named); only a folder "
                   "holding nothing but a run's files is replaced")
    add_accept(p)
    p.set_defaults(func=run)


def run(args):
    from ..simulation import run_simulation

    set_quiet(args.quiet)
    cfg = scenario(args)
    run_dir = run_simulation(cfg, args.year, scheduler=args.scheduler, n_workers=args.workers,
                             force=args.force)
    if cfg.db.dsn and (run_dir / "summary.json").exists():
        from ..db import mirror_run

        mirror_run(cfg.db.dsn, run_dir)
    return 0


def scenario(args):
    """The configuration the options make: the scenario, then ``--db``, ``--dashboard-port``,
    ``--out`` and ``--accept`` over it."""
    overrides = {"db": {"dsn": args.db}} if args.db else {}
    if args.dashboard_port is not None:
        overrides["dask"] = {"dashboard_port": args.dashboard_port or None}
    cfg = load_config(args.config, overrides=overrides)
    if args.out is not None:
        folder_path(args.out, "--out")
        cfg = load_config(args.config, overrides={**overrides, **under(cfg, args.out)})
    cfg.checks.accept = list(accepted(cfg, args))
    return cfg


def under(cfg, folder: Path) -> dict:
    """Overrides that put the relative ``data_dir``, ``out_dir`` (and, for the demo, its
    generated input files) under *folder*."""
    def moved(p):
        return str(p if Path(p).is_absolute() else Path(folder) / p)

    out = {"data_dir": moved(cfg.data_dir), "out_dir": moved(cfg.out_dir)}
    if cfg.demo.enabled:
        out["inputs"] = {"citygml": [moved(p) for p in cfg.inputs.citygml],
                         "gtfs": moved(cfg.inputs.gtfs), "cams": [moved(p) for p in cfg.inputs.cams]}
    return out
