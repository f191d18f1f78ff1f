"""The mirror of the demo run into plain PostGIS and into a 2-worker Citus cluster on this machine.

Servers: a PostgreSQL 15 + PostGIS server and a Citus coordinator with two workers, both
started by :func:`vipvflow.db.server.start` (as ``vipvflow db start [--citus-workers 2]``
does: durable, fsync on) in folders under /tmp; the Citus part is left out, and said so,
when Citus is not installed (``vipvflow db citus``). Each repeat mirrors the run into a fresh
database of each (PostGIS already created, as in ``db start``'s ``vipvflow`` database), in
turn: the mirror's wall time includes creating and distributing the tables. Then the same
mirror again (nothing to load: the partitions are checked and skipped). Figures: the best
of the repeats of each, their ratio, and where the Citus shards and rows are (per
distributed table and worker, from ``citus_shards`` and a ``count(*)`` on every placement).

The run is ``$VIPVFLOW_BENCH_MIRROR_RUN``, else the repository's ``out/demo/2024``, else a
fresh full demo run (~3 min). ``tiny``: the small demo, June, one repeat.
"""
from __future__ import annotations

import json
import shutil
import sys
import tempfile
import time
from pathlib import Path


def _quiet(*_args, **_kw) -> None:
    pass


def run(tiny: bool = False) -> dict:
    from .common import demo_run, remove

    run_dir, source = demo_run(tiny, "VIPVFLOW_BENCH_MIRROR_RUN", "mirror")
    try:
        res = _measure(run_dir, repeats=1 if tiny else 3)
        res.update(run=str(run_dir), run_source=source)
        return res
    finally:
        if source.startswith("fresh"):
            remove(run_dir.parents[1])


def placement(dsn: str, workers: dict[int, str]) -> dict:
    """{table: {worker: {"shards": n, "rows": n}}} of the distributed tables at *dsn*
    (*workers*: port -> name)."""
    import psycopg

    out: dict = {}
    with psycopg.connect(dsn) as conn:
        tables = [r[0] for r in conn.execute(
            "SELECT table_name::text FROM citus_tables WHERE citus_table_type = 'distributed' "
            "ORDER BY 1")]
        for table in tables:
            per = out.setdefault(table.removeprefix("vipvflow."), {})
            for port, shards, rows in conn.execute(
                    "SELECT nodeport, count(*), sum(result::bigint)::bigint FROM "
                    "run_command_on_placements(%s, 'SELECT count(*) FROM %%s') GROUP BY 1 ORDER BY 1",
                    (table,)):
                per[workers.get(port, str(port))] = {"shards": shards, "rows": rows}
    return out


def _measure(run_dir: Path, repeats: int) -> dict:
    from vipvflow.db import citus, mirror_run, server

    bindir = server.find_bindir()
    if bindir is None or not server.postgis_available(bindir):
        raise RuntimeError("the mirror benchmark needs PostgreSQL 15 + PostGIS (make system-deps)")
    citus_version = citus.installed(citus.pg_install(bindir))
    folders = {"postgis": tempfile.mkdtemp(prefix="vipvflow-bench-pg-")}
    if citus_version:
        folders["citus"] = tempfile.mkdtemp(prefix="vipvflow-bench-citus-")
    servers = {}
    try:
        for kind, folder in folders.items():
            servers[kind] = server.start(folder, say=_quiet,
                                         citus_workers=2 if kind == "citus" else None)
        first: dict[str, list[float]] = {k: [] for k in servers}
        again: dict[str, list[float]] = {k: [] for k in servers}
        rows, where = None, None
        for i in range(repeats):
            for kind, srv in servers.items():
                name = f"bench_mirror_{i}"
                server.create_database(srv, name)
                dsn = srv.dsn_of(name)
                t0 = time.perf_counter()
                counts = mirror_run(dsn, run_dir, log=_quiet)
                t1 = time.perf_counter()
                assert mirror_run(dsn, run_dir, log=_quiet) == counts
                t2 = time.perf_counter()
                first[kind].append(round(t1 - t0, 3))
                again[kind].append(round(t2 - t1, 3))
                assert rows in (None, counts), (rows, counts)
                rows = counts
                if kind == "citus" and i == repeats - 1:
                    where = placement(dsn, {w.port: f"worker{j}"
                                            for j, w in enumerate(srv.workers, 1)})
                server.drop_database(srv, name)
    finally:
        for folder in folders.values():
            server.stop(folder, say=_quiet)
            shutil.rmtree(folder, ignore_errors=True)
    figures = {"rows": sum(rows.values()), "mirror_s_postgis": min(first["postgis"]),
               "second_mirror_s_postgis": min(again["postgis"])}
    if "citus" in servers:
        figures.update(mirror_s_citus_2_workers=min(first["citus"]),
                       second_mirror_s_citus_2_workers=min(again["citus"]),
                       citus_over_postgis=round(min(first["citus"]) / min(first["postgis"]), 2))
    return {"figures": figures, "targets": {}, "rows_per_table": rows,
            "mirror_s_each": first, "second_mirror_s_each": again,
            "citus": citus_version or "not installed (vipvflow db citus): Citus part left out",
            "citus_placement": where}


if __name__ == "__main__":
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2))
