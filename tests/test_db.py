"""The PostGIS mirror against a real PostgreSQL 15 + PostGIS started by the test session.

The run directory is the session's real small-demo simulation (``small_run`` in conftest),
or ``$VIPVFLOW_TEST_RUN_DIR`` (any ``out/<scenario>/<year>``): the tests only read its files
and compare the database with them.
"""
from __future__ import annotations

import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from conftest import missing_system_package
from db_run import checksums, clone_run
from vipvflow.db import DatabaseError, citus_statements, ddl, mirror_run, run_id_of, schema
from vipvflow.db import server as pgserver

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "database.md"
_db_counter = itertools.count()


# ---------------------------------------------------------------- fixtures

@pytest.fixture(scope="session")
def postgis_bindir():
    """The PostgreSQL server programs' folder, PostGIS installed for them.

    Skipped with what to install when the server programs or PostGIS are absent (a failure
    under ``VIPVFLOW_REQUIRE_SYSTEM_DEPS=1``, as in CI).
    """
    bindir = pgserver.find_bindir()
    if bindir is None:
        missing_system_package("PostgreSQL server programs (initdb, pg_ctl) not found",
                               "postgresql-15 postgresql-15-postgis-3")
    if not pgserver.postgis_available(bindir):
        missing_system_package(f"PostGIS not installed for {bindir}", "postgresql-15-postgis-3")
    return bindir


@pytest.fixture(scope="session")
def pg(postgis_bindir):
    """A PostgreSQL + PostGIS cluster in a temporary folder on a free port, for the session."""
    folder = tempfile.mkdtemp(prefix="vipvflow-pg-")  # under /tmp: reachable by 'postgres'
    srv = pgserver.start(folder, durable=False, say=lambda msg: None)
    try:
        yield srv
    finally:
        pgserver.stop(folder, say=lambda msg: None)
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture
def dsn(pg):
    """A fresh, empty database (no PostGIS yet: the mirror creates it) for one test."""
    import psycopg

    name = f"t{os.getpid()}_{next(_db_counter)}"
    with psycopg.connect(pg.admin_dsn, autocommit=True) as conn:
        conn.execute(f"CREATE DATABASE {name}")
    yield pg.dsn_of(name)
    with psycopg.connect(pg.admin_dsn, autocommit=True) as conn:
        conn.execute(f"DROP DATABASE {name} WITH (FORCE)")


@pytest.fixture(scope="session")
def run_dir(request) -> Path:
    """The run directory under test (only read by the tests): the session's real small-demo
    simulation, or ``$VIPVFLOW_TEST_RUN_DIR``."""
    real = os.environ.get("VIPVFLOW_TEST_RUN_DIR")
    if real:
        return Path(real)
    return request.getfixturevalue("small_run")


@pytest.fixture
def other_run(run_dir, tmp_path) -> Path:
    """The same outputs under another scenario name: another run id."""
    return clone_run(run_dir, tmp_path / "other", scenario="other-scenario")


# ---------------------------------------------------------------- helpers

def query(dsn, sql, args=()):
    import psycopg

    with psycopg.connect(dsn) as conn:
        return conn.execute(sql, args).fetchall()


def run_id(run: Path) -> str:
    return run_id_of(json.loads((run / "manifest.json").read_text()))


def file_rows(run: Path) -> dict[str, int]:
    out = {t.name: pq.ParquetFile(run / t.source).metadata.num_rows
           for t in schema.DATA_TABLES if t.source.endswith(".parquet")}
    out["fleet_summary"] = 1
    return out


def table_digest(dsn, rid) -> dict[str, str]:
    """md5 of every table's rows of a run, ordered by key (same rows <=> same digest)."""
    out = {}
    for t in schema.DATA_TABLES + [schema.PROGRESS]:
        key = ", ".join(("run_id",) + t.key)
        cols = "*" if t is not schema.PROGRESS else "run_id, table_name, part, rows, source_sha256"
        out[t.name] = query(dsn, f"SELECT md5(coalesce(string_agg(x::text, '|' ORDER BY {key}), '')) "
                                 f"FROM (SELECT {cols} FROM {t.qualified} WHERE run_id = %s) x",
                            (rid,))[0][0]
    return out


def sql_blocks(path: Path) -> list[str]:
    return re.findall(r"```sql\n(.*?)```", path.read_text(), flags=re.S)


def _same(a, b) -> bool:
    if isinstance(b, np.float32) and isinstance(a, float):
        # a real column comes back as the shortest decimal of the float32: compare as float32
        return np.float32(a) == b or (np.isnan(a) and np.isnan(b))
    if a is None or (isinstance(a, float) and math.isnan(a)):
        return b is None or (isinstance(b, float) and math.isnan(b))
    return a == b


# ---------------------------------------------------------------- tests without a server

def test_citus_statements_distribute_big_tables_and_replicate_small_ones():
    stmts = citus_statements()
    dist = {re.search(r"'vipvflow\.(\w+)'", s).group(1): s for s in stmts
            if "create_distributed_table" in s}
    ref = {re.search(r"'vipvflow\.(\w+)'", s).group(1) for s in stmts if "create_reference_table" in s}
    assert "'tile'" in dist["segments"] and "'tile'" in dist["segment_month"]
    assert "colocate_with => 'vipvflow.segments'" in dist["segment_month"]
    assert "'route_id'" in dist["trip_energy"]
    assert "colocate_with => 'vipvflow.trip_energy'" in dist["route_month"]
    assert "'block_id'" in dist["block_day"]
    assert ref == {"runs", "mirror_progress", "fleet_month", "hourly_pattern", "fleet_summary"}
    # a table is distributed before a table colocated with it
    names = [re.search(r"'vipvflow\.(\w+)'", s).group(1) for s in stmts]
    assert names.index("segments") < names.index("segment_month")
    assert names.index("trip_energy") < names.index("route_month")
    # Citus requires the distribution column in every primary key
    for t in schema.ALL_TABLES:
        if t.distribute_by:
            assert t.distribute_by in t.key
    # nothing left to do once every table is distributed
    assert citus_statements({t.qualified for t in schema.ALL_TABLES}) == []
    full = ddl(citus=True)
    assert full.index(stmts[0]) > full.index(schema.create_table_sql(schema.BLOCK_DAY))
    assert "create_distributed_table" not in " ".join(ddl(citus=False))


# ---------------------------------------------------------------- tests on the server

def test_mirror_equals_the_files(dsn, run_dir):
    lines = []
    counts = mirror_run(dsn, run_dir, log=lines.append)
    rid = run_id(run_dir)
    assert any("plain PostGIS" in l for l in lines)  # this server has no Citus
    assert counts == file_rows(run_dir)
    assert query(dsn, "SELECT status, row_counts FROM vipvflow.runs WHERE run_id = %s", (rid,)) == \
        [("complete", counts)]

    # every value of every core and extra column, row for row, bit for bit
    for t in schema.DATA_TABLES:
        if t is schema.FLEET_SUMMARY:
            continue
        df = pd.read_parquet(run_dir / t.source).drop(columns=["geometry", *t.drop], errors="ignore")
        num = [c for c in df.columns if df[c].dtype.kind in "fiu"]
        keys = list(t.key)
        df = df.sort_values(keys).reset_index(drop=True)
        order = ", ".join(f'"{k}"' for k in keys)
        got = query(dsn, f"SELECT {', '.join(f'{chr(34)}{c}{chr(34)}' for c in num)} "
                         f"FROM {t.qualified} WHERE run_id = %s ORDER BY {order}", (rid,))
        assert len(got) == len(df)
        want = df[num].astype(object).where(df[num].notna(), None).itertuples(index=False)
        for g, w in zip(got, want):
            f32 = {c for c in num if df[c].dtype == np.float32}
            bad = [(c, a, b) for c, a, b in zip(num, g, w)
                   if not _same(a, np.float32(b) if c in f32 and b is not None
                                else (float(b) if isinstance(a, float) else b))]
            assert not bad, (t.name, bad[:3])
        # kWh sums: the database's SUM against the files' exact sum
        for c in [c for c in num if "kwh" in c]:
            db_sum = query(dsn, f'SELECT sum("{c}") FROM {t.qualified} WHERE run_id = %s', (rid,))[0][0]
            assert db_sum == pytest.approx(math.fsum(df[c].dropna()), rel=1e-12, abs=1e-12), (t.name, c)

    # geometry: the file's coordinates in the file's CRS, and WGS84 in the view
    import geopandas as gpd
    import shapely
    from pyproj import Transformer

    seg = gpd.read_parquet(run_dir / "segments.parquet").sort_values("segment_id")
    epsg = seg.crs.to_epsg()
    rows = query(dsn, "SELECT segment_id, ST_SRID(geom), ST_AsBinary(geom) FROM vipvflow.segments "
                      "WHERE run_id = %s ORDER BY segment_id", (rid,))
    assert {r[1] for r in rows} == {epsg}
    got = shapely.from_wkb([bytes(r[2]) for r in rows])
    assert all(shapely.equals_exact(a, b, tolerance=0) for a, b in zip(got, seg.geometry))
    assert all(shapely.has_z(got))
    assert query(dsn, "SELECT count(*) FROM pg_indexes WHERE schemaname = 'vipvflow' "
                      "AND indexdef ILIKE '%%USING gist (geom)%%'", ())[0][0] == 1
    wgs = query(dsn, "SELECT ST_X(ST_StartPoint(geom)), ST_Y(ST_StartPoint(geom)), ST_SRID(geom) "
                     "FROM vipvflow.segments_4326 WHERE run_id = %s ORDER BY segment_id", (rid,))
    tr = Transformer.from_crs(epsg, 4326, always_xy=True)
    lon, lat = tr.transform(seg["x"].to_numpy(), seg["y"].to_numpy())
    assert np.allclose([r[0] for r in wgs], lon, atol=1e-9)
    assert np.allclose([r[1] for r in wgs], lat, atol=1e-9)
    assert {r[2] for r in wgs} == {4326}

    summary = json.loads((run_dir / "summary.json").read_text())
    got = query(dsn, "SELECT pv_kwh_driving, trips, summary FROM vipvflow.fleet_summary "
                     "JOIN vipvflow.runs USING (run_id) WHERE run_id = %s", (rid,))
    assert got == [(summary["pv_kwh_driving"], summary["trips"], summary)]


def test_mirroring_twice_leaves_the_same_rows(dsn, run_dir):
    mirror_run(dsn, run_dir, log=lambda m: None)
    rid = run_id(run_dir)
    first = table_digest(dsn, rid)
    calls = []
    assert mirror_run(dsn, run_dir, log=lambda m: None,
                      on_partition=lambda *a: calls.append(a)) == file_rows(run_dir)
    assert calls == []  # every partition was already there
    assert table_digest(dsn, rid) == first
    mirror_run(dsn, run_dir, log=lambda m: None, force=True)  # delete-then-insert of every partition
    assert table_digest(dsn, rid) == first


def test_two_runs_side_by_side(dsn, run_dir, other_run):
    a, b = run_id(run_dir), run_id(other_run)
    assert a != b
    mirror_run(dsn, run_dir, log=lambda m: None)
    mirror_run(dsn, other_run, log=lambda m: None)
    digest_b = table_digest(dsn, b)
    mirror_run(dsn, run_dir, log=lambda m: None, force=True)
    assert table_digest(dsn, b) == digest_b
    for t in schema.DATA_TABLES:
        per_run = dict(query(dsn, f"SELECT run_id, count(*) FROM {t.qualified} GROUP BY run_id"))
        assert per_run == {a: file_rows(run_dir)[t.name], b: file_rows(other_run)[t.name]}
    assert query(dsn, "SELECT count(*) FROM vipvflow.runs WHERE status = 'complete'")[0][0] == 2


class Interrupt(Exception):
    pass


def test_interrupted_mirror_resumes_without_duplicates_or_gaps(dsn, run_dir):
    rid = run_id(run_dir)
    done = []

    def stop_after_five(table, part, rows):
        done.append((table, part))
        if len(done) == 5:
            raise Interrupt

    with pytest.raises(Interrupt):
        mirror_run(dsn, run_dir, log=lambda m: None, on_partition=stop_after_five)
    assert query(dsn, "SELECT status FROM vipvflow.runs WHERE run_id = %s", (rid,)) == [("loading",)]
    recorded = query(dsn, "SELECT table_name, part FROM vipvflow.mirror_progress WHERE run_id = %s",
                     (rid,))
    assert sorted(recorded) == sorted(done)

    resumed = []
    counts = mirror_run(dsn, run_dir, log=lambda m: None, on_partition=lambda t, p, n: resumed.append((t, p)))
    assert counts == file_rows(run_dir)
    assert not set(resumed) & set(done)  # finished partitions are not loaded again
    total = query(dsn, "SELECT count(*) FROM vipvflow.mirror_progress WHERE run_id = %s", (rid,))[0][0]
    assert len(done) + len(resumed) == total
    for t in schema.DATA_TABLES:  # no duplicate keys, no missing rows
        keys = ", ".join(f'"{k}"' for k in ("run_id",) + t.key)
        n, distinct = query(dsn, f"SELECT count(*), count(DISTINCT ({keys})) FROM {t.qualified} "
                                 "WHERE run_id = %s", (rid,))[0]
        assert n == distinct == file_rows(run_dir)[t.name]
    # and the result is the one of a mirror that was never interrupted
    digest = table_digest(dsn, rid)
    mirror_run(dsn, run_dir, log=lambda m: None, force=True)
    assert table_digest(dsn, rid) == digest


def test_bad_dsn_is_one_clear_line_and_leaves_the_run_untouched(pg, run_dir):
    before = checksums(run_dir)
    bad = ["this is not a dsn = =", f"postgresql://postgres@127.0.0.1:{pgserver.free_port()}/vipvflow",
           pg.dsn_of("no_such_database")]
    for dsn in bad:
        with pytest.raises(DatabaseError) as err:
            mirror_run(dsn, run_dir, log=lambda m: None)
        msg = str(err.value)
        assert "\n" not in msg and msg
        proc = subprocess.run([sys.executable, "-m", "vipvflow.cli", "mirror", "--db", dsn,
                               str(run_dir)], capture_output=True, text=True, timeout=120)
        assert proc.returncode == 2
        err_lines = proc.stderr.strip().splitlines()
        assert len(err_lines) == 1 and err_lines[0].startswith("vipvflow mirror: error: "), proc.stderr
        assert "Traceback" not in proc.stderr
    assert checksums(run_dir) == before


def test_doc_sql_examples_run_as_written(dsn, run_dir):
    mirror_run(dsn, run_dir, log=lambda m: None)
    blocks = sql_blocks(DOC)
    readme = sql_blocks(ROOT / "README.md")
    # the README shows the same examples as the doc, so they run as written there too
    assert readme and all(b in blocks for b in readme)
    assert len(blocks) >= 3
    routes = set(pd.read_parquet(run_dir / "route_month.parquet")["route_short_name"].astype(str))
    for sql in blocks:
        rows = query(dsn, sql)
        if "route_short_name = '1'" in sql and "1" not in routes:
            continue  # a run without a route "1": the query runs, the answer is empty
        assert rows, sql
    shaded = query(dsn, blocks[0])
    losses = [float(r[3]) for r in shaded]
    assert losses == sorted(losses, reverse=True) and len(shaded) <= 10
    monthly = pd.read_parquet(run_dir / "monthly.parquet").sort_values("month")
    yield_rows = query(dsn, blocks[1])
    assert [r[2] for r in yield_rows] == list(monthly["month"])
    assert [float(r[3]) for r in yield_rows] == pytest.approx(list(monthly["pv_kwh"]), abs=0.0501)
    geojson = query(dsn, blocks[2])[0][0]
    assert geojson["type"] == "FeatureCollection"
    assert len(geojson["features"]) == file_rows(run_dir)["segments"]


# ---------------------------------------------------------------- secrets, any directory

def _cli(*args, cwd=None, env=None):
    env = dict(os.environ if env is None else env, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "vipvflow.cli", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=300)


def _password(pg) -> str:
    return (pg.dir / pgserver.PASSFILE).read_text().split("\n")[0].rsplit(":", 1)[1]


def test_server_socket_is_private_and_tcp_asks_for_the_password(pg):
    import stat

    import psycopg

    for private in (pg.dir, pg.dir / "socket"):
        assert stat.S_IMODE(private.stat().st_mode) == 0o700, private
    socket = next((pg.dir / "socket").glob(".s.PGSQL.*[0-9]"))
    assert stat.S_IMODE(socket.stat().st_mode) & 0o077 == 0
    assert stat.S_IMODE((pg.dir / pgserver.PASSFILE).stat().st_mode) == 0o600
    password = _password(pg)
    assert len(password) >= 24 and password not in pg.dsn
    bare = f"postgresql://postgres@127.0.0.1:{pg.port}/postgres"
    with pytest.raises(psycopg.OperationalError, match="password"):
        psycopg.connect(bare, connect_timeout=5, passfile="/nonexistent")
    with pytest.raises(psycopg.OperationalError, match="password authentication failed"):
        psycopg.connect(bare + "?password=wrong", connect_timeout=5)
    for dsn in (pg.dsn, f"postgresql://postgres:{password}@127.0.0.1:{pg.port}/postgres"):
        with psycopg.connect(dsn, connect_timeout=5) as conn:
            assert conn.execute("SELECT current_user").fetchone()[0] == "postgres"
    with psycopg.connect(bare, connect_timeout=5, password=password) as conn:  # as $PGPASSWORD would
        assert conn.execute("SELECT 1").fetchone()[0] == 1


def test_db_start_prints_the_password_once(postgis_bindir):
    folder = tempfile.mkdtemp(prefix="vipvflow-pg-cli-")   # under /tmp: reachable by 'postgres'
    try:
        first = _cli("db", "start", "--dir", folder)
        assert first.returncode == 0, first.stderr
        dsn = first.stdout.strip()
        password = (Path(folder) / pgserver.PASSFILE).read_text().split("\n")[0].rsplit(":", 1)[1]
        assert password in first.stderr and password not in dsn
        assert first.stderr.count(password) == 1
        again = _cli("db", "start", "--dir", folder)                       # already running
        _cli("db", "stop", "--dir", folder)
        restarted = _cli("db", "start", "--dir", folder)                   # stopped and started
        assert again.returncode == restarted.returncode == 0
        assert password not in again.stderr + restarted.stderr
        import psycopg

        with psycopg.connect(restarted.stdout.strip(), connect_timeout=5) as conn:
            assert conn.execute("SELECT postgis_version()").fetchone()[0]
    finally:
        _cli("db", "stop", "--dir", folder)
        shutil.rmtree(folder, ignore_errors=True)


def test_mirror_from_root_keeps_no_password(dsn, pg, run_dir, tmp_path):
    """A copy of the run whose manifest holds a password DSN (as written before masking),
    mirrored from / with a DSN carrying the password: neither the runs table nor the log
    holds it."""
    run = tmp_path / "copy" / "out" / "small" / "2024"
    shutil.copytree(run_dir, run, ignore=shutil.ignore_patterns("parts", "figures", "*.html"))
    password = _password(pg)
    with_password = dsn.split("?")[0].replace("postgres@", f"postgres:{password}@")
    manifest = json.loads((run / "manifest.json").read_text())
    manifest["config"]["db"] = {"dsn": with_password}
    (run / "manifest.json").write_text(json.dumps(manifest))
    env = {k: v for k, v in os.environ.items() if k not in ("PGPASSWORD", "PGPASSFILE")}
    proc = _cli("mirror", "--db", with_password, run.relative_to("/"), cwd="/", env=env)
    assert proc.returncode == 0, proc.stderr
    assert password not in proc.stdout + proc.stderr
    rid = run_id(run)
    stored = query(dsn, "SELECT manifest::text, config::text, status FROM vipvflow.runs "
                        "WHERE run_id = %s", (rid,))
    assert stored and stored[0][2] == "complete"
    assert password not in stored[0][0] + stored[0][1]
    assert "postgres:***@127.0.0.1" in stored[0][1]
