"""Mirror a finished run directory into PostGIS (Citus when the server has it).

Loading is by COPY (CSV produced by Arrow, floats in shortest round-trip form, geometry as
EWKB hex with the city's SRID), one transaction per (table, partition): the transaction
deletes the run's rows of that partition, copies the partition's rows and records the pair in
``vipvflow.mirror_progress``. A mirror that stops half-way therefore resumes where it stopped,
and mirroring the same files again changes nothing. When a file changed since it was mirrored
(its SHA-256 differs), that table's rows of the run are replaced.

The run directory is only read.
"""
from __future__ import annotations

import io
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.csv as pacsv
import pyarrow.parquet as pq

from ..errors import InputError, VipvError
from ..store import sha256
from ..simulation.rundir import mask_text, masked_config
from . import schema as S

COPY_BLOCK = 1 << 20  # bytes handed to COPY per write
ADVISORY_LOCK = 0x76697076  # serialises schema set-up between concurrent mirrors


class DatabaseError(VipvError):
    """The database cannot be reached, or refused what the mirror asked of it."""


class MirrorError(VipvError):
    """The mirror did not complete (the message says what to do)."""


# ---------------------------------------------------------------- connection

def describe_dsn(dsn: str) -> str:
    """``user@host:port/dbname`` of a DSN, without its password."""
    from psycopg.conninfo import conninfo_to_dict

    try:
        d = conninfo_to_dict(dsn)
    except Exception:
        return "<unparsable DSN>"
    host = d.get("host") or d.get("hostaddr") or "localhost"
    user = f"{d['user']}@" if d.get("user") else ""
    return f"{user}{host}:{d.get('port') or 5432}/{d.get('dbname') or ''}"


def _one_line(exc: BaseException) -> str:
    return " ".join(str(exc).split()) or type(exc).__name__


def connect(dsn: str):
    """An autocommit connection, or :class:`DatabaseError` in one line."""
    import psycopg
    from psycopg.conninfo import conninfo_to_dict

    try:
        params = conninfo_to_dict(dsn)
    except psycopg.Error as exc:         # the message may quote the DSN, password included
        raise DatabaseError(f"invalid database DSN: {mask_text(_one_line(exc))}") from None
    kwargs = {} if "connect_timeout" in params else {"connect_timeout": 10}
    try:
        return psycopg.connect(dsn, autocommit=True, application_name="vipvflow-mirror", **kwargs)
    except psycopg.Error as exc:
        raise DatabaseError(f"cannot connect to PostgreSQL at {describe_dsn(dsn)}: "
                            f"{mask_text(_one_line(exc))}") from None


# ---------------------------------------------------------------- set-up

def citus_mode(conn, log=print) -> bool:
    """Create the citus extension when the server offers it; True when it is active."""
    if conn.execute("SELECT 1 FROM pg_extension WHERE extname = 'citus'").fetchone():
        return True
    if not conn.execute("SELECT 1 FROM pg_available_extensions WHERE name = 'citus'").fetchone():
        return False
    preload = conn.execute("SHOW shared_preload_libraries").fetchone()[0]
    if "citus" not in preload:
        log("citus is installed but not in shared_preload_libraries: using plain PostGIS tables")
        return False
    conn.execute("CREATE EXTENSION IF NOT EXISTS citus")
    return True


def _citus_layout(conn) -> str:
    """The log's words for the Citus layout: the nodes that hold shards."""
    workers = conn.execute("SELECT count(*) FROM pg_dist_node WHERE noderole = 'primary' AND "
                           "isactive AND groupid <> 0").fetchone()[0]
    nodes = f"{workers} worker(s)" if workers else "the coordinator alone (no workers registered)"
    return (f"Citus on {nodes}: segment tables distributed by tile, trips and bus-days by "
            "block, small tables replicated")


def setup_schema(conn, citus: bool) -> None:
    """Create (idempotently) the schema, distribute it under Citus, create the views."""
    import psycopg

    try:
        with conn.transaction():
            conn.execute("SELECT pg_advisory_xact_lock(%s)", (ADVISORY_LOCK,))
            for stmt in S.schema_statements():
                conn.execute(stmt)
        if citus:
            done = {r[0] for r in conn.execute(
                "SELECT logicalrelid::regclass::text FROM pg_dist_partition")}
            for stmt in S.citus_statements(done):
                conn.execute(stmt)
        with conn.transaction():
            conn.execute("SELECT pg_advisory_xact_lock(%s)", (ADVISORY_LOCK,))
            for stmt in S.view_statements():
                conn.execute(stmt)
    except psycopg.errors.FeatureNotSupported as exc:  # e.g. postgis not installable
        raise DatabaseError(f"the server cannot host the mirror: {_one_line(exc)}") from None
    except (psycopg.errors.UndefinedFile, psycopg.errors.InsufficientPrivilege) as exc:
        raise DatabaseError("PostGIS is not available to this user on the server "
                            f"({_one_line(exc)})") from None


def _sql_type_of(t: pa.DataType) -> str | None:
    if pa.types.is_dictionary(t):
        t = t.value_type
    if pa.types.is_boolean(t):
        return "boolean"
    if pa.types.is_int8(t) or pa.types.is_int16(t) or pa.types.is_uint8(t):
        return "smallint"
    if pa.types.is_int32(t) or pa.types.is_uint16(t):
        return "integer"
    if pa.types.is_integer(t):
        return "bigint"
    if pa.types.is_float32(t) or pa.types.is_float16(t):
        return "real"
    if pa.types.is_floating(t):
        return "double precision"
    if pa.types.is_string(t) or pa.types.is_large_string(t):
        return "text"
    if pa.types.is_date(t):
        return "date"
    if pa.types.is_timestamp(t):
        return "timestamptz" if t.tz else "timestamp"
    return None


def _arrow_type(sql_type: str) -> pa.DataType | None:
    name = S.ARROW_OF_SQL.get(sql_type)
    if name is None:
        return None
    if name == "timestamp_utc":
        return pa.timestamp("us", tz="UTC")
    return getattr(pa, name)()


# ---------------------------------------------------------------- reading the run

def read_json(path: Path) -> dict:
    try:
        return json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"{path}: missing (is this a finished run directory?)") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: unreadable JSON ({_one_line(exc)})") from None


def run_id_of(manifest: dict, path: Path = Path("manifest.json")) -> str:
    """``<scenario>/<year>/<config_digest>`` of a run's manifest."""
    try:
        return f"{manifest['scenario']}/{manifest['year']}/{manifest['config_digest']}"
    except KeyError as exc:
        raise InputError(f"{path}: no {exc.args[0]!r} key") from None


def geo_epsg(path: Path) -> int:
    """EPSG code of a GeoParquet file's primary geometry column (from its ``geo`` metadata)."""
    meta = pq.read_schema(path).metadata or {}
    if b"geo" not in meta:
        raise InputError(f"{path}: not GeoParquet (no 'geo' metadata)")
    geo = json.loads(meta[b"geo"])
    col = geo["columns"][geo["primary_column"]]
    if "crs" not in col:
        return 4326  # GeoParquet's default, OGC:CRS84
    crs = col["crs"]
    code = None
    if isinstance(crs, dict) and str(crs.get("id", {}).get("authority", "")).upper() == "EPSG":
        code = crs["id"].get("code")
    if code is None and crs is not None:
        from pyproj import CRS

        code = CRS.from_user_input(crs).to_epsg()
    if code is None:
        raise InputError(f"{path}: the geometry's CRS has no EPSG code")
    return int(code)


def _flatten(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flatten(v, f"{prefix}{k}_"))
        elif isinstance(v, (bool, int, float, str)) or v is None:
            out[f"{prefix}{k}"] = v
    return out


def read_source(run_dir: Path, table: S.Table) -> pa.Table:
    """The file a table mirrors, as an Arrow table with the table's column names."""
    path = run_dir / table.source
    if table.source.endswith(".json"):
        row = _flatten(read_json(path))
        return pa.Table.from_pylist([row])
    if not path.exists():
        raise InputError(f"{path}: missing (is this a finished run directory?)")
    try:
        data = pq.read_table(path)
    except (OSError, pa.ArrowException) as exc:
        raise InputError(f"{path}: unreadable Parquet ({_one_line(exc)})") from None
    data = data.drop_columns([c for c in table.drop if c in data.column_names])
    if table.geometry:
        import shapely

        meta = json.loads((data.schema.metadata or {})[b"geo"])
        gcol = meta["primary_column"]
        geoms = shapely.from_wkb(data[gcol].to_numpy(zero_copy_only=False))
        geoms = shapely.set_srid(shapely.force_3d(geoms), geo_epsg(path))
        ewkb = shapely.to_wkb(geoms, hex=True, include_srid=True, output_dimension=3,
                              flavor="extended")
        data = data.drop_columns([gcol]).append_column("geom", pa.array(ewkb, pa.string()))
    missing = [k for k in table.key if k not in data.column_names]
    if missing:
        raise InputError(f"{path}: key column(s) {missing} missing")
    return data


def conform(data: pa.Table, table: S.Table, path: Path) -> tuple[pa.Table, dict[str, str]]:
    """Cast the file's columns to the table's types; returns the data and the SQL types of
    the extra columns (not in the core schema) to add to the table."""
    arrays, names, extra = [], [], {}
    for name in data.column_names:
        col = data[name]
        if pa.types.is_dictionary(col.type):
            col = col.cast(col.type.value_type)
        sql_type = table.sql_type(name) if name != "geom" else "text"
        if sql_type is None:
            sql_type = _sql_type_of(col.type)
            if sql_type is None:
                continue  # nested types: kept in the files only (documented)
            extra[name] = sql_type
        target = _arrow_type(sql_type) if not sql_type.startswith("geometry") else pa.string()
        if target is not None and col.type != target:
            try:
                col = col.cast(target)
            except (pa.ArrowInvalid, pa.ArrowNotImplementedError) as exc:
                raise InputError(f"{path}: column {name!r} ({col.type}) does not convert to "
                                 f"{sql_type}: {_one_line(exc)}") from None
        arrays.append(col)
        names.append(name)
    return pa.table(arrays, names=names), extra


def partitions(data: pa.Table, column: str | None) -> list[tuple[str, object, pa.Table]]:
    """(label, value, rows) per value of *column*, sorted; one partition ``all`` without."""
    if column is None:
        return [("all", None, data)]
    values = data[column].to_pandas()
    codes, uniques = pd.factorize(values, sort=True, use_na_sentinel=False)
    order = np.argsort(codes, kind="stable")
    counts = np.bincount(codes, minlength=len(uniques))
    data = data.take(pa.array(order))
    out, start = [], 0
    for value, n in zip(uniques, counts):
        value = None if pd.isna(value) else (value.item() if hasattr(value, "item") else value)
        out.append(("(null)" if value is None else str(value), value, data.slice(start, int(n))))
        start += int(n)
    return out


def to_csv(data: pa.Table) -> bytes:
    buf = io.BytesIO()
    pacsv.write_csv(data, buf, pacsv.WriteOptions(include_header=False))
    return buf.getvalue()


# ---------------------------------------------------------------- loading

def _ident(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


def _delete_sql(table: S.Table) -> str:
    where = "run_id = %s"
    if table.partition_by:
        where += f" AND {_ident(table.partition_by)} IS NOT DISTINCT FROM %s"
    return f"DELETE FROM {table.qualified} WHERE {where}"


def load_partition(conn, table: S.Table, run_id: str, label: str, value, rows: pa.Table,
                   digest: str, citus: bool) -> int:
    """Replace one (table, partition) of a run in one transaction; returns rows copied."""
    cols = ", ".join(["run_id"] + [_ident(c) for c in rows.column_names])
    rows = rows.add_column(0, "run_id", pa.array([run_id] * rows.num_rows, pa.string()))
    payload = memoryview(to_csv(rows))
    with conn.transaction():
        if citus:  # one connection per worker for the delete, the copy and the progress row
            # (Citus's advice when a transaction writes a reference table after multi-shard
            # statements; parallel mode was no faster on the demo run)
            conn.execute("SET LOCAL citus.multi_shard_modify_mode TO 'sequential'")
        args = (run_id, value) if table.partition_by else (run_id,)
        conn.execute(_delete_sql(table), args)
        with conn.cursor() as cur:
            with cur.copy(f"COPY {table.qualified} ({cols}) FROM STDIN (FORMAT csv)") as copy:
                for i in range(0, len(payload), COPY_BLOCK):
                    copy.write(payload[i:i + COPY_BLOCK])
        conn.execute(
            f"INSERT INTO {S.PROGRESS.qualified} (run_id, table_name, part, rows, source_sha256, "
            "finished_at) VALUES (%s, %s, %s, %s, %s, now()) ON CONFLICT (run_id, table_name, part) "
            "DO UPDATE SET rows = EXCLUDED.rows, source_sha256 = EXCLUDED.source_sha256, "
            "finished_at = EXCLUDED.finished_at",
            (run_id, table.name, label, rows.num_rows, digest))
    return rows.num_rows


def _forget(conn, table: S.Table, run_id: str, citus: bool) -> None:
    with conn.transaction():
        if citus:
            conn.execute("SET LOCAL citus.multi_shard_modify_mode TO 'sequential'")
        conn.execute(f"DELETE FROM {table.qualified} WHERE run_id = %s", (run_id,))
        conn.execute(f"DELETE FROM {S.PROGRESS.qualified} WHERE run_id = %s AND table_name = %s",
                     (run_id, table.name))


def _add_columns(conn, table: S.Table, extra: dict[str, str]) -> None:
    """Add the file's columns the table lacks, in one statement (on Citus each ALTER TABLE
    runs on every shard: the columns already there are not asked for again)."""
    have = {r[0] for r in conn.execute(
        "SELECT attname FROM pg_attribute WHERE attrelid = %s::regclass AND attnum > 0 "
        "AND NOT attisdropped", (table.qualified,))}
    missing = [(n, t) for n, t in extra.items() if n not in have]
    if missing:
        conn.execute(f"ALTER TABLE {table.qualified} "
                     + ", ".join(f"ADD COLUMN IF NOT EXISTS {_ident(n)} {t}" for n, t in missing))


def mirror_table(conn, run_dir: Path, table: S.Table, run_id: str, citus: bool, force: bool,
                 log, on_partition) -> int:
    """Load one table of a run, partition by partition, skipping the ones already there."""
    path = run_dir / table.source
    data, extra = conform(read_source(run_dir, table), table, path)
    digest = sha256(path)
    done = dict(conn.execute(
        f"SELECT part, source_sha256 FROM {S.PROGRESS.qualified} WHERE run_id = %s AND "
        "table_name = %s", (run_id, table.name)).fetchall())
    if force or any(d != digest for d in done.values()):
        if done:
            log(f"  {table.name}: {'reloading' if force else path.name + ' changed since its mirror'}"
                f": replacing the run's rows")
        _forget(conn, table, run_id, citus)
        done = {}
    _add_columns(conn, table, extra)
    parts = partitions(data, table.partition_by)
    todo = [p for p in parts if p[0] not in done]
    loaded = 0
    for label, value, rows in todo:
        loaded += load_partition(conn, table, run_id, label, value, rows, digest, citus)
        if on_partition is not None:
            on_partition(table.name, label, rows.num_rows)
    skipped = len(parts) - len(todo)
    log(f"  {table.name}: {data.num_rows:,} rows in {len(parts)} partition(s)"
        + (f", {skipped} already mirrored" if skipped else "")
        + (f"; {len(extra)} column(s) beyond the core schema" if extra else ""))
    return data.num_rows


def mirror_run(dsn: str, run_dir, log=print, force: bool = False,
               on_partition: Callable[[str, str, int], None] | None = None) -> dict:
    """Mirror the run in *run_dir* (``out/<scenario>/<year>``) into the database at *dsn*.

    Parameters
    ----------
    dsn : str
        libpq connection string or URI.
    run_dir : path
        A finished run directory (``manifest.json``, ``summary.json``, the Parquet outputs).
    log : callable
        Receives one line per step (mode, table, partitions).
    force : bool
        Replace the run's rows even where the files did not change.
    on_partition : callable(table, partition, rows), optional
        Called after each committed partition (progress; tests interrupt a mirror from it).

    Returns
    -------
    dict
        Rows of the run per table in the database after the mirror (equal to the files').
    """
    import psycopg

    run_dir = Path(run_dir)
    # a manifest written before DSNs were masked may hold a password: never stored
    manifest = read_json(run_dir / "manifest.json")
    if isinstance(manifest.get("config"), dict):
        manifest["config"] = masked_config(manifest["config"])
    summary = read_json(run_dir / "summary.json")
    run_id = run_id_of(manifest, run_dir / "manifest.json")
    epsg = geo_epsg(run_dir / "segments.parquet") if (run_dir / "segments.parquet").exists() \
        else None
    conn = connect(dsn)
    where = describe_dsn(dsn)
    try:
        citus = citus_mode(conn, log)
        log(f"mirror {run_id} into {where}: " + (_citus_layout(conn) if citus
                                                 else "plain PostGIS tables (no Citus)"))
        setup_schema(conn, citus)
        with conn.transaction():
            conn.execute(
                f"INSERT INTO {S.RUNS.qualified} (run_id, scenario, year, config_digest, crs_epsg, "
                "status, mirrored_at, manifest, config, summary) "
                "VALUES (%s, %s, %s, %s, %s, 'loading', now(), %s, %s, %s) "
                "ON CONFLICT (run_id) DO UPDATE SET crs_epsg = EXCLUDED.crs_epsg, "
                "status = 'loading', mirrored_at = EXCLUDED.mirrored_at, manifest = EXCLUDED.manifest, "
                "config = EXCLUDED.config, summary = EXCLUDED.summary",
                (run_id, manifest.get("scenario"), manifest.get("year"),
                 manifest.get("config_digest"), epsg, psycopg.types.json.Jsonb(manifest),
                 psycopg.types.json.Jsonb(manifest.get("config")),
                 psycopg.types.json.Jsonb(summary)))
        expected = {}
        for table in S.DATA_TABLES:
            expected[table.name] = mirror_table(conn, run_dir, table, run_id, citus, force, log,
                                                on_partition)
        counts = {t.name: conn.execute(f"SELECT count(*) FROM {t.qualified} WHERE run_id = %s",
                                       (run_id,)).fetchone()[0] for t in S.DATA_TABLES}
        if counts != expected:
            bad = {k: (counts[k], expected[k]) for k in counts if counts[k] != expected[k]}
            raise MirrorError(f"rows in the database differ from the files (db, files): {bad}")
        with conn.transaction():
            conn.execute(f"UPDATE {S.RUNS.qualified} SET status = 'complete', mirrored_at = now(), "
                         "row_counts = %s WHERE run_id = %s",
                         (psycopg.types.json.Jsonb(counts), run_id))
        log(f"mirrored {run_id}: " + ", ".join(f"{k} {v:,}" for k, v in counts.items()))
        return counts
    except psycopg.OperationalError as exc:
        raise DatabaseError(f"lost the database at {where} while mirroring {run_id} "
                            f"({_one_line(exc)}); run the mirror again to resume") from None
    except psycopg.Error as exc:
        raise DatabaseError(f"mirroring {run_id} into {where} failed: {_one_line(exc)}") from None
    finally:
        conn.close()
