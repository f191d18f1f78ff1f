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
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from conftest import REQUIRE_SYSTEM_DEPS, missing_system_package
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
    assert "'block_id'" in dist["trip_energy"] and "'block_id'" in dist["block_day"]
    assert "colocate_with => 'vipvflow.trip_energy'" in dist["block_day"]
    # each group's first table starts a group of its own
    assert "colocate_with => 'none'" in dist["segments"] and "colocate_with => 'none'" in dist["trip_energy"]
    assert ref == {"runs", "mirror_progress", "fleet_month", "hourly_pattern", "fleet_summary",
                   "route_month"}
    # a table is distributed before a table colocated with it
    names = [re.search(r"'vipvflow\.(\w+)'", s).group(1) for s in stmts]
    assert names.index("segments") < names.index("segment_month")
    assert names.index("trip_energy") < names.index("block_day")
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


# ---------------------------------------------------------------- Citus

CITUS_SOURCE = Path(os.environ.get("VIPVFLOW_CITUS_SOURCE", ROOT.parent / "shared" / "vendor" / "citus"))


def citus_source() -> Path | None:
    """The Citus source tarball the tests may build: ``$VIPVFLOW_CITUS_SOURCE`` or
    ``../shared/vendor/citus`` (only on CI and developer machines); None when absent."""
    if CITUS_SOURCE.is_file() or (CITUS_SOURCE.is_dir() and any(CITUS_SOURCE.glob("citus-*.tar.gz"))):
        return CITUS_SOURCE
    return None


@pytest.fixture(scope="session")
def citus_version(postgis_bindir) -> str:
    """Citus for the test server: the installed one, else built from :func:`citus_source` and
    installed (cached; needs root). Skipped with the missing piece named when neither works
    (a failure under ``VIPVFLOW_REQUIRE_SYSTEM_DEPS=1`` when the source is there, as in CI)."""
    from vipvflow.db import citus

    source = citus_source()
    try:
        return citus.ensure(source, say=lambda msg: None, bindir=postgis_bindir)
    except citus.CitusError as exc:
        if REQUIRE_SYSTEM_DEPS and source is not None:
            pytest.fail(f"Citus tests: {exc}")
        where = f"source {source}" if source else f"no Citus source at {CITUS_SOURCE}"
        pytest.skip(f"Citus tests: {exc} ({where})")


@pytest.fixture(scope="session")
def citus_cluster(citus_version):
    """A Citus coordinator and two workers in a temporary folder for the session (as
    ``vipvflow db start --citus-workers 2`` starts them, without fsync)."""
    folder = tempfile.mkdtemp(prefix="vipvflow-citus-")  # under /tmp: reachable by 'postgres'
    try:
        yield pgserver.start(folder, durable=False, say=lambda msg: None, citus_workers=2)
    finally:
        pgserver.stop(folder, say=lambda msg: None)
        shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture
def citus_dsn(citus_cluster):
    """A fresh database on every node of the cluster with citus and the workers registered;
    no PostGIS yet (the mirror creates it, Citus creates it on the workers)."""
    name = f"c{os.getpid()}_{next(_db_counter)}"
    pgserver.create_database(citus_cluster, name, postgis=False)
    yield citus_cluster.dsn_of(name)
    pgserver.drop_database(citus_cluster, name)


def _worker_ports(cluster) -> set[int]:
    return {w.port for w in cluster.workers}


def test_citus_build_resolves_the_header_conflict(tmp_path):
    """The build's fix of Citus 13.x against PostgreSQL 15.20's headers, on Citus's own
    header when the source is beside the clone, else on its two lines."""
    import tarfile

    from vipvflow.db import citus

    src = tmp_path / "citus"
    header = src / "src" / "include" / "pg_version_compat.h"
    header.parent.mkdir(parents=True)
    source = citus_source()
    if source is not None:
        with tarfile.open(citus.find_tarball(source)) as tar:
            member = next(m for m in tar.getmembers() if m.name.endswith("src/include/pg_version_compat.h"))
            header.write_bytes(tar.extractfile(member).read())
    else:
        header.write_text("#include <x.h>\nstatic inline bool\nhave_createdb_privilege(void)\n{\n}\n")
    before = header.read_text()
    assert citus.patch_source(src) is True
    after = header.read_text()
    # Citus's copy now has its own name; calls to have_createdb_privilege() reach it by the macro
    assert after == before.replace(
        "static inline bool\nhave_createdb_privilege(void)\n",
        "#define have_createdb_privilege citus_have_createdb_privilege\n"
        "static inline bool\nhave_createdb_privilege(void)\n")
    assert citus.patch_source(src) is False and header.read_text() == after  # once only
    header.write_text(before + before)                        # not the header it knows
    with pytest.raises(citus.CitusError, match="2 definitions"):
        citus.patch_source(src)


def test_citus_source_and_cache_key(tmp_path):
    from vipvflow.db import citus

    for name in ("citus-12.1.5.tar.gz", "citus-13.2.2.tar.gz", "citus-13.10.0.tar.gz"):
        (tmp_path / name).write_bytes(name.encode())
    assert citus.find_tarball(tmp_path).name == "citus-13.10.0.tar.gz"   # the newest
    with pytest.raises(citus.CitusError, match="no such file or folder"):
        citus.find_tarball(tmp_path / "nothing")
    (tmp_path / "empty").mkdir()
    with pytest.raises(citus.CitusError, match="no citus-"):
        citus.find_tarball(tmp_path / "empty")
    pg = citus.PgInstall(Path("/b"), "15.20", "15", Path("/l"), Path("/s"), Path("/i"))
    key = citus.build_key(tmp_path / "citus-13.2.2.tar.gz", pg)
    assert key.startswith("citus-13.2.2-pg15.20-")
    # another server minor version or another tarball: another build
    assert citus.build_key(tmp_path / "citus-13.2.2.tar.gz",
                           citus.PgInstall(Path("/b"), "15.21", "15", Path("/l"), Path("/s"),
                                           Path("/i"))) != key
    assert citus.build_key(tmp_path / "citus-12.1.5.tar.gz", pg) != key
    line = citus.how_to_get(pg)
    assert "\n" not in line and "postgresql-15-citus" in line and "vipvflow db citus --source" in line
    assert "postgresql-server-dev-15" in pg.build_packages


def test_citus_mirror_distributes_the_run(citus_cluster, citus_dsn, run_dir):
    lines = []
    counts = mirror_run(citus_dsn, run_dir, log=lines.append)
    assert any("Citus on 2 worker(s)" in line for line in lines), lines
    assert counts == file_rows(run_dir)
    for t in schema.DATA_TABLES:
        assert query(citus_dsn, f"SELECT count(*) FROM {t.qualified}")[0][0] == file_rows(run_dir)[t.name]
    layout = {r[0]: r[1:] for r in query(
        citus_dsn, "SELECT table_name::text, citus_table_type, distribution_column, colocation_id "
                   "FROM citus_tables")}
    want = {t.qualified: t.distribute_by for t in schema.ALL_TABLES}
    assert set(layout) == set(want)
    for name, column in want.items():
        kind, dist_column, _ = layout[name]
        assert (kind, dist_column) == (("distributed", column) if column else ("reference", "<none>"))
    group = {name: layout[name][2] for name, column in want.items() if column}
    assert group["vipvflow.segments"] == group["vipvflow.segment_month"]
    assert group["vipvflow.trip_energy"] == group["vipvflow.block_day"]
    assert group["vipvflow.segments"] != group["vipvflow.trip_energy"]
    # every distributed table has shards on both workers, every reference table a copy on
    # every node
    placed = {}
    for name, port in query(citus_dsn, "SELECT table_name::text, nodeport FROM citus_shards"):
        placed.setdefault(name, set()).add(port)
    workers = _worker_ports(citus_cluster)
    for name, column in want.items():
        assert placed[name] == (workers if column else workers | {citus_cluster.port}), name
    # the rows are in the workers' shards: PostGIS is there too (created on the coordinator by
    # the mirror, on the workers by Citus)
    from psycopg.conninfo import conninfo_to_dict

    for w in citus_cluster.workers:
        dsn = w.dsn_of(conninfo_to_dict(citus_dsn)["dbname"])
        assert query(dsn, "SELECT extversion FROM pg_extension WHERE extname = 'postgis'")
    for name, column in want.items():
        if column:  # the rows are in the shards, and the shards on the workers
            on_workers = query(citus_dsn, """
                SELECT sum(result::bigint)::bigint FROM run_command_on_placements(
                    %s, 'SELECT count(*) FROM %%s') WHERE nodeport <> %s""",
                               (name, citus_cluster.port))[0][0]
            assert on_workers == file_rows(run_dir)[name.split(".")[1]], name


def test_citus_mirror_equals_plain_postgis(citus_dsn, dsn, run_dir, tmp_path):
    """The same rows, and the same answers to docs/database.md's queries, on the cluster as
    on plain PostGIS; a second mirror adds nothing."""
    mirror_run(dsn, run_dir, log=lambda m: None)
    mirror_run(citus_dsn, run_dir, log=lambda m: None)
    rid = run_id(run_dir)
    assert table_digest(citus_dsn, rid) == table_digest(dsn, rid)
    blocks = sql_blocks(DOC)
    assert len(blocks) >= 3
    for sql in blocks:
        plain, citus = query(dsn, sql), query(citus_dsn, sql)
        assert citus == plain, sql
    # a second mirror adds nothing
    digest = table_digest(citus_dsn, rid)
    calls = []
    assert mirror_run(citus_dsn, run_dir, log=lambda m: None,
                      on_partition=lambda *a: calls.append(a)) == file_rows(run_dir)
    assert calls == [] and table_digest(citus_dsn, rid) == digest
    assert query(citus_dsn, "SELECT count(*) FROM vipvflow.runs")[0][0] == 1
    # a changed file has its table's rows replaced, on the cluster as on one server
    scenario = json.loads((run_dir / "manifest.json").read_text())["scenario"]
    changed = clone_run(run_dir, tmp_path / "changed", scenario=scenario)   # the same run id
    assert run_id(changed) == rid
    block = pq.read_table(changed / "block_day.parquet")
    block = block.slice(0, block.num_rows - 1)        # one bus-day fewer
    pq.write_table(block, changed / "block_day.parquet")
    lines = []
    mirror_run(citus_dsn, changed, log=lines.append)
    assert any("block_day.parquet changed since its mirror" in line for line in lines)
    assert query(citus_dsn, "SELECT count(*) FROM vipvflow.block_day WHERE run_id = %s",
                 (rid,))[0][0] == block.num_rows
    assert table_digest(citus_dsn, rid)["segments"] == digest["segments"]   # the others kept


KILL_MID_COPY = """
import os, signal, sys
import psycopg
from vipvflow.db import mirror

mirror.COPY_BLOCK = 1024          # many writes per partition
seen = {"copies": 0, "writes": 0, "last": None}
write = psycopg.Copy.write

def killing_write(self, buffer):
    if self is not seen["last"]:
        seen.update(last=self, copies=seen["copies"] + 1, writes=0)
    seen["writes"] += 1
    write(self, buffer)
    if seen["copies"] == int(sys.argv[3]) and seen["writes"] == 2:
        os.kill(os.getpid(), signal.SIGKILL)   # mid-COPY of a partition, its transaction open

psycopg.Copy.write = killing_write
mirror.mirror_run(sys.argv[1], sys.argv[2], log=lambda m: None)
"""


@pytest.mark.parametrize("server", ["postgis", "citus"])
def test_sigkill_mid_mirror_then_rerun_gives_the_same_rows(server, request, run_dir):
    """A mirror killed (SIGKILL) in the middle of a partition's COPY, after two partitions
    were committed: only whole partitions are in the database; the next mirror loads the
    rest and gives the rows of an uninterrupted mirror."""
    target = request.getfixturevalue("dsn" if server == "postgis" else "citus_dsn")
    rid = run_id(run_dir)
    proc = subprocess.run([sys.executable, "-c", KILL_MID_COPY, target, str(run_dir), "3"],
                          capture_output=True, text=True, timeout=300,
                          env=dict(os.environ, PYTHONPATH=str(ROOT / "src")))
    assert proc.returncode == -signal.SIGKILL, (proc.returncode, proc.stderr[-2000:])
    assert query(target, "SELECT status FROM vipvflow.runs WHERE run_id = %s", (rid,)) == [("loading",)]
    recorded = query(target, "SELECT table_name, rows FROM vipvflow.mirror_progress WHERE run_id = %s",
                     (rid,))
    assert [r[0] for r in recorded] == ["segments", "segments"]
    assert query(target, "SELECT count(*) FROM vipvflow.segments WHERE run_id = %s", (rid,))[0][0] \
        == sum(r[1] for r in recorded)                         # nothing of the killed partition
    counts = mirror_run(target, run_dir, log=lambda m: None)
    assert counts == file_rows(run_dir)
    for t in schema.DATA_TABLES:
        keys = ", ".join(f'"{k}"' for k in ("run_id",) + t.key)
        n, distinct = query(target, f"SELECT count(*), count(DISTINCT ({keys})) FROM {t.qualified} "
                                    "WHERE run_id = %s", (rid,))[0]
        assert n == distinct == file_rows(run_dir)[t.name]
    digest = table_digest(target, rid)
    mirror_run(target, run_dir, log=lambda m: None, force=True)   # an uninterrupted mirror
    assert table_digest(target, rid) == digest
    if server == "citus":  # no transaction left prepared on a worker
        assert query(target, "SELECT count(*) FROM pg_prepared_xacts")[0][0] == 0


def test_citus_cluster_cli(citus_cluster, run_dir):
    """``db start`` of a running cluster prints its DSN; ``db stop`` stops every node; a new
    start brings the cluster back on its ports with its nodes and data; the nodes are private
    as a single server is."""
    import stat

    import psycopg

    folder = citus_cluster.dir
    mirror_run(citus_cluster.dsn, run_dir, log=lambda m: None)
    again = _cli("db", "start", "--dir", folder)
    assert again.returncode == 0 and again.stdout == citus_cluster.dsn + "\n", again.stderr
    wrong = _cli("db", "start", "--dir", folder, "--citus-workers", "3")
    assert wrong.returncode == 2 and len(wrong.stderr.strip().splitlines()) == 1
    assert "holds a Citus cluster of 2 worker(s)" in wrong.stderr
    password = _password(citus_cluster)
    for node in citus_cluster.nodes:
        for private in (node.dir, node.dir / "socket"):
            assert stat.S_IMODE(private.stat().st_mode) == 0o700, private
        bare = f"postgresql://postgres@127.0.0.1:{node.port}/postgres"
        with pytest.raises(psycopg.OperationalError, match="password"):
            psycopg.connect(bare, connect_timeout=5, passfile="/nonexistent")
        with psycopg.connect(bare, connect_timeout=5, password=password) as conn:
            assert conn.execute("SHOW listen_addresses").fetchone()[0] == "127.0.0.1"
    stop = _cli("db", "stop", "--dir", folder)
    assert stop.returncode == 0, stop.stderr
    for node in citus_cluster.nodes:
        with pytest.raises(psycopg.OperationalError):
            psycopg.connect(node.admin_dsn, connect_timeout=5)
    start = _cli("db", "start", "--dir", folder)
    assert start.returncode == 0, start.stderr
    assert start.stdout == citus_cluster.dsn + "\n" and password not in start.stderr
    assert pgserver.status(folder) == citus_cluster
    nodes = query(citus_cluster.dsn, "SELECT nodeport, groupid = 0 FROM pg_dist_node WHERE isactive")
    assert sorted(nodes) == sorted([(citus_cluster.port, True)] + [(p, False) for p in _worker_ports(citus_cluster)])
    assert query(citus_cluster.dsn, "SELECT count(*) FROM vipvflow.segment_month")[0][0] == \
        file_rows(run_dir)["segment_month"]
