"""Reduce the partitions of a run into its outputs.

Per trip (trip x service date): PV kWh joined with the vehicle model's consumption;
per segment-month (with geometry, for maps); per route-direction-month; per vehicle block
and day; and the fleet-year summary with coverage, avoided charging cycles and payback.
"""
from __future__ import annotations

import json
import logging
import re
import time
from pathlib import Path
from typing import NamedTuple

import geopandas as gpd
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from ..config import Config
from ..errors import InputError
from ..models.loss import shading_loss
from ..store import (HOURLY_METADATA, ROW_GROUP_ROWS, DataDir, PartSchemaError, RunDir, write_json,
                     write_parquet, write_parquet_parts)
from .partition import hand_back_memory, handing_back

log = logging.getLogger(__name__)


def _read_file(path, columns: list[str] | None = None) -> pa.Table:
    """One partition file as an Arrow table, on this thread (with *columns*, those of them
    it has).  On the line-year's partitions (tens of kB) an Arrow dataset scan or
    ``read_table`` (threads, pre-buffering) cost up to twice the CPU of this plain read per
    file; on the 200-line network's (MBs) they were about even."""
    with pq.ParquetFile(path) as pf:
        if columns is not None:
            columns = [c for c in columns if c in pf.schema_arrow.names]
        return pf.read(columns=columns, use_threads=False)


def _read_files(files, columns: list[str] | None = None) -> pa.Table | None:
    """The partition *files* (in the given order) as one Arrow table (``None``: no files);
    with *columns*, only those of them the files have.

    Each file is read on this thread (:func:`_read_file`: a run has hundreds to thousands
    of small files) and the tables are joined; files whose schemas differ (an empty
    partition's columns, an older run's extra ``tile`` column, say) have their schemas
    promoted."""
    files = [str(f) for f in files]
    if not files:
        return None
    tables = [_read_file(f, columns) for f in files]
    try:
        return pa.concat_tables(tables)
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
        pass
    filled = [t for t in tables if t.num_rows] or tables[:1]
    return pa.concat_tables(filled, promote_options="permissive")


def _part_table(run_dir: Path, kind: str, pattern: str = "tile=*/month=*.parquet",
                columns: list[str] | None = None) -> pa.Table | None:
    """Every partition file of *kind* (``parts/<kind>/<pattern>``), in path order, as one Arrow
    table (``None``: no files); with *columns*, only those."""
    return _read_files(RunDir(run_dir).part_files(kind, pattern), columns)


# --- the partial sums, computed where the partitions are (Dask tasks on the run's workers)

#: trip partition files summed by one task: bounds a task's memory (a network-year month has
#: hundreds of tiles), and with two levels (files -> month -> run) the client sums a table
#: about as long as its output
TRIP_FILES_PER_TASK = 64
#: trip partition files a task reads at once (:func:`sum_trips`)
TRIP_READ_FILES = 8
#: rows of segment_month.parquet made into a frame at a time (an eighth of a row group: a
#: network's parts of a whole row group took 0.5 GB more each, their frame and its Arrow copy)
SEGMENT_MONTH_PART_ROWS = ROW_GROUP_ROWS // 8
#: rows of trip_energy.parquet converted at a time (:func:`_trip_outputs`)
TRIP_PART_ROWS = ROW_GROUP_ROWS // 8
#: rows of a row group of segment_month.parquet and trip_energy.parquet: a part's.  A row
#: group of pyarrow's default 1 M rows was held as Arrow columns until it was written, beside
#: the segment-months or the trips: ~0.35 and ~0.25 GB of a network's reduce
SEGMENT_MONTH_GROUP_ROWS = SEGMENT_MONTH_PART_ROWS
TRIP_GROUP_ROWS = TRIP_PART_ROWS


def _tile_of(path: Path) -> str:
    return path.parent.name.split("=", 1)[1]


def _month_files(run_dir: Path, kind: str) -> dict[str, list[Path]]:
    """The partition files of *kind* per month (``YYYY-MM``), each list in path order."""
    out: dict[str, list[Path]] = {}
    for f in RunDir(run_dir).part_files(kind):
        out.setdefault(f.stem.split("=", 1)[1], []).append(f)
    return dict(sorted(out.items()))


def sum_trips(parts: list) -> pa.Table | None:
    """Trip rows summed per trip and service date: the PV columns (``pv_kwh*``) and
    ``seconds``, sorted by both keys.  *parts* are partition files or tables of trip sums;
    summed by Arrow on one thread (a fixed order of addition, so a run gives the same figures
    every time).  A Dask task of the reduce; ``None`` when no part has a row.

    The files are read :data:`TRIP_READ_FILES` at a time, each group summed into the sums
    so far: Arrow adds a group's values in row order, so the sums are those of all rows at
    once, bit for bit (a network month's 56 files at once took 1.2 GB for 34 MB of sums)."""
    if parts and isinstance(parts[0], (str, Path)):
        pieces = (_read_files(parts[i:i + TRIP_READ_FILES]) for i in range(0, len(parts), TRIP_READ_FILES))
    else:
        pieces = iter(parts)
    keys = ["trip_id", "service_date"]
    summed = None
    for table in pieces:
        if table is None or not table.num_rows:
            continue
        # float32 partition columns summed in float64
        table = table.cast(pa.schema([f.with_type(pa.float64()) if pa.types.is_floating(f.type) else f
                                      for f in table.schema]))
        if summed is not None:
            table = pa.concat_tables([summed, table], promote_options="permissive")
        cols = [c for c in table.column_names if c.startswith("pv_kwh")] + ["seconds"]
        summed = table.group_by(keys, use_threads=False).aggregate([(c, "sum") for c in cols])
        summed = summed.select(keys + [f"{c}_sum" for c in cols]).rename_columns(keys + cols)
    return summed.sort_by([(k, "ascending") for k in keys]) if summed is not None else None


def segment_month_part(files: list, month: str) -> tuple[pa.Table | pd.DataFrame, pd.DataFrame]:
    """The segment partitions of one month as one table, each row with its ``tile`` and
    ``month`` (named by the file's path; older runs stored them as columns), and the
    month's sums per local hour (:func:`hourly_sums`).  A Dask task of the reduce: the
    table in Arrow (:func:`_months_frame` makes the run's frame of them), an older run's
    as a DataFrame."""
    files = [Path(f) for f in files]
    if not files:
        return pd.DataFrame(), hourly_sums([], month)
    tables = [_read_file(f) for f in files]
    hourly = hourly_sums([_hourly_of(t, f) for t, f in zip(tables, files)], month)
    try:
        table = pa.concat_tables(tables)
    except pa.ArrowInvalid:                 # schemas differ (an older run's files)
        table = None
    if table is None or "tile" in table.column_names or "month" in table.column_names:
        frames = [_with_tile_month(t.to_pandas(), _tile_of(f), month) for t, f in zip(tables, files)]
        frames = [d for d in frames if len(d)] or frames[:1]
        return pd.concat(frames, ignore_index=True), hourly
    tile = np.repeat(np.array([_tile_of(f) for f in files], dtype=object), [t.num_rows for t in tables])
    table = table.append_column("tile", pa.array(tile, pa.string()))
    return table.append_column("month", pa.array(np.full(table.num_rows, month, object), pa.string())), hourly


def _months_frame(parts: list) -> pd.DataFrame:
    """The months' segment tables (:func:`segment_month_part`) as one DataFrame, *parts*
    emptied.  Each month's columns are first copied out of the message the table was
    received in, which is let go then (a received table's columns are views of one message,
    which the conversion could free only once every column was converted: the months' tables
    were held twice).  The months are then joined without a copy and converted column by
    column, each column its own block, its Arrow buffers released as it is converted (pandas'
    blocks of one type were allocated whole before the first column was released)."""
    if parts and all(isinstance(p, pa.Table) for p in parts):
        owned = []
        while parts:
            owned.append(_own_buffers(parts.pop(0)))
        table = pa.concat_tables(owned)
        owned.clear()
        # the strings copied: pandas keeps Arrow's string columns as they are, and each
        # received column is a view of its whole message, which it would keep alive; the
        # tiles and months (a few values on every row: a network's 0.12 GB as strings) as
        # categories, written as the strings they are (_segment_month_rows)
        import pyarrow.compute as pc

        for i, field in enumerate(table.schema):
            if not (pa.types.is_floating(field.type) or pa.types.is_integer(field.type)):
                column = table.column(i).combine_chunks()
                if field.name in ("tile", "month"):
                    column = pc.dictionary_encode(column)
                table = table.set_column(i, pa.field(field.name, column.type), pa.chunked_array([column]))
        return table.to_pandas(self_destruct=True, split_blocks=True)
    frames = [p.to_pandas() if isinstance(p, pa.Table) else p for p in parts]
    return pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()


def _with_tile_month(df: pd.DataFrame, tile: str, month: str) -> pd.DataFrame:
    """*df* with ``tile`` and ``month`` columns (an older run's files have them)."""
    if "tile" not in df:
        df["tile"] = tile
    if "month" not in df:
        df["month"] = month
    return df


def _hourly_of(table: pa.Table, path: Path) -> pa.Table:
    """A segment partition's sums per local hour: from its metadata (:data:`HOURLY_METADATA`),
    or from the hourly file beside it (runs before 2026-11-26)."""
    meta = (table.schema.metadata or {}).get(HOURLY_METADATA)
    if meta is not None:
        return pa.table(json.loads(meta))
    tile, month = _tile_of(path), path.stem.split("=", 1)[1]
    legacy = RunDir(path.parents[3]).part("hourly", tile, month)
    if not legacy.exists():
        raise InputError(f"{path}: no sums per local hour (neither in its metadata nor in "
                         f"{legacy}): compute the partition again (delete the file and rerun)")
    return pq.read_table(legacy)


def hourly_sums(tables: list, month: str) -> pd.DataFrame:
    """The partitions' sums per local hour (*tables*) summed per hour (``month, hour``, the
    irradiation sums ``h_*`` in Wh/m2, ``seconds``)."""
    tables = [t for t in tables if t.num_rows]
    hourly = (pa.concat_tables(tables, promote_options="permissive").to_pandas() if tables
              else pd.DataFrame({"hour": [], "seconds": []}))
    cols = [c for c in hourly.columns if c.startswith("h_")] + ["seconds"]
    out = hourly.groupby("hour", sort=True)[cols].sum().reset_index()
    out["hour"] = out["hour"].astype(np.int8)
    out.insert(0, "month", month)
    return out


class _InProcess:
    """The reduce's tasks run in this process (no cluster given): ``submit`` calls at once."""

    @staticmethod
    def submit(fn, *args, **_):
        return fn(*args)

    @staticmethod
    def gather(results):
        return results


def _trip_tree(run_dir: Path, client) -> list:
    """Submit the tree of trip sums: files -> tasks of up to :data:`TRIP_FILES_PER_TASK`
    files -> one per month; returns the months' futures (or tables) in month order."""
    months = []
    for files in _month_files(run_dir, "trip").values():
        batches = [files[i:i + TRIP_FILES_PER_TASK] for i in range(0, len(files), TRIP_FILES_PER_TASK)]
        sums = [client.submit(sum_trips, [str(f) for f in b], pure=False) for b in batches]
        months.append(sums[0] if len(sums) == 1 else client.submit(sum_trips, sums, pure=False))
    return months


def _own_buffers(table: pa.Table) -> pa.Table:
    """*table* with each column copied into buffers of its own: a table received from a
    worker is a view of the message it came in, which stays whole while any of its columns
    is held."""
    return pa.table([pa.concat_arrays(c.chunks) if c.num_chunks else c for c in table.columns],
                    schema=table.schema)


def _join_months(tables: list) -> pa.Table | None:
    """The months' trip sums (:func:`sum_trips`, each one row per trip and service date) as
    one table sorted by both; *tables* emptied.  A trip past midnight at a month's end is in
    two months: the rows whose date lies within another month's dates are summed again (in
    month order, as a sum of the whole would), the rest taken as they are (summing the whole
    held four times its size).  Each month is first copied out of the message it was
    received in (:func:`_own_buffers`), which is let go then, and the joined table is taken
    a column at a time, the months' column released as it is (taken at once, beside the
    received months, the trip sums were held twice)."""
    import pyarrow.compute as pc

    months = [t for t in tables if t is not None and t.num_rows]
    tables.clear()
    if len(months) <= 1:
        return months[0] if months else None
    owned = []
    while months:
        owned.append(_own_buffers(months.pop(0)))
    keys = ["trip_id", "service_date"]
    spans = [(pc.min(t.column("service_date")), pc.max(t.column("service_date"))) for t in owned]
    shared = []
    for k, t in enumerate(owned):
        date, mask = t.column("service_date"), np.zeros(t.num_rows, bool)
        for j, (lo, hi) in enumerate(spans):
            if j != k:
                mask |= pc.and_(pc.greater_equal(date, lo), pc.less_equal(date, hi)).to_numpy(
                    zero_copy_only=False)
        shared.append(mask)
    again = sum_trips([t.filter(pa.array(m)) for t, m in zip(owned, shared)])
    whole = pa.concat_tables(owned + ([again] if again is not None else []), promote_options="permissive")
    owned.clear()
    keep = np.concatenate([~m for m in shared] + [np.ones(again.num_rows if again is not None else 0, bool)])
    del again, shared
    # the rows kept in the order of their keys (each pair once among them): the whole's order
    # without the rows summed again (the kept rows' keys taken to sort them were a copy)
    order = pc.sort_indices(whole.select(keys), sort_keys=[(k, "ascending") for k in keys]).to_numpy()
    at, schema, columns = pa.array(order[keep[order]]), whole.schema, []
    while whole.num_columns:
        columns.append(whole.column(0).take(at))
        whole = whole.remove_column(0)
    return pa.table(columns, schema=schema)


def partial_sums(run_dir: Path, client=None, fresh_workers=None) -> dict:
    """The partitions read and summed on the cluster of *client* (in this process without
    one): ``trip`` (Arrow: per trip and service date, sorted), ``segment_month`` (per segment
    and month, with tile and month), ``hourly`` (per month and local hour) and ``geometry``
    (the segments' public geometry factors).

    Each month's files are read by tasks of their own (trips in a tree of partial sums), so
    the reduce's reading grows with the partitions per worker; the client only joins the
    months' tables.  Once they are gathered, *fresh_workers* (a run's own LocalCluster:
    :func:`vipvflow.simulation.cluster.fresh_workers`) restarts the workers, else each
    worker hands back what the sums freed."""
    client = client or _InProcess()
    run_dir = Path(run_dir)
    # one list of the tasks (trips' months, segments' months, geometry): no other reference
    # keeps a result on its worker once it is fetched
    tasks = _trip_tree(run_dir, client)
    n_trip = len(tasks)
    tasks += [client.submit(segment_month_part, [str(f) for f in files], m, pure=False)
              for m, files in _month_files(run_dir, "segment_month").items()]
    tasks.append(client.submit(geometry_factors, [str(f) for f in RunDir(run_dir).part_files(
        "geometry", "tile=*.parquet")], pure=False))
    if not isinstance(client, _InProcess):
        tasks = _gather_as_done(tasks)
        if fresh_workers is not None:
            # what the sums' reads left in the workers' heaps (200 lines: ~440 MiB each, ~260
            # in a new one) is not held through the rest of the reduce
            fresh_workers()
        else:
            # the workers, once they have dropped the results, hand back what the reads and
            # sums took (200 lines: 1.9 and 2.3 GB held, 0.4 after)
            client.run(forget_and_hand_back, tasks.keys)
    trip, sm, geometry = tasks[:n_trip], tasks[n_trip:-1], tasks[-1]
    del tasks
    hourly = pd.concat([h for _, h in sm], ignore_index=True) if sm else hourly_sums([], "")[:0]
    tables = [s for s, _ in sm]
    del sm
    # one after the other: the months' trip sums are let go once joined, before the
    # segment-months' frame is made (held through it, 0.4 GB more of a network's peak)
    trip = _join_months(trip)
    return {"trip": trip, "segment_month": _months_frame(tables), "hourly": hourly, "geometry": geometry}


class _Results(list):
    """Results in the order of their futures, with the futures' ``keys``."""
    keys: list


def _gather_as_done(futures: list) -> _Results:
    """The results of *futures*, in their order, each fetched as soon as its task is done and
    its future dropped then, so the worker drops it (gathered at the end, a network's
    months of sums piled up on the workers: 2.1 GB on one of them)."""
    from distributed import as_completed

    out = _Results([None] * len(futures))
    out.keys = [f.key for f in futures]
    at = {key: i for i, key in enumerate(out.keys)}
    pending = as_completed(futures)
    futures.clear()
    for future in pending:
        out[at[future.key]] = future.result()
        del future
    return out


async def forget_and_hand_back(keys: list, dask_worker=None, wait_s: float = 10.0) -> None:
    """On a worker (``client.run``; a coroutine, so the worker's event loop goes on): wait
    until it has dropped the results *keys* (a client's release reaches the workers on its
    own, after this call may), then hand the memory freed back to the operating system
    (:func:`hand_back_memory`)."""
    import asyncio

    if dask_worker is not None:
        keys, end = set(keys), time.monotonic() + wait_s
        while time.monotonic() < end and not keys.isdisjoint(dask_worker.data):
            await asyncio.sleep(0.01)
    hand_back_memory()


def geometry_factors(files: list) -> pd.DataFrame | None:
    """The public geometry factors (:data:`annual.PUBLIC_FACTORS`) of the segments in the
    geometry partition *files* (``None``: no files).  A Dask task of the reduce."""
    from . import annual

    table = _read_files(files, columns=["segment_id", *annual.PUBLIC_FACTORS])
    return table.to_pandas() if table is not None else None


def _trip_totals(run_dir: Path, table: pa.Table | None = None) -> pd.DataFrame:
    """The trip partitions summed per trip and service date (a trip crosses many tiles),
    sorted by both; the PV columns (``pv_kwh*``) and ``seconds``.  *table*: the trip sums of
    :func:`partial_sums` (without: summed here, in this process)."""
    if table is None:
        table = _join_months(_trip_tree(Path(run_dir), _InProcess()))
    if table is None or not table.num_rows:
        raise InputError(f"{RunDir(run_dir).part_dir('trip')}: no trip partitions with passes: "
                         "the run's routes never pass its tiles in its months")
    return table.to_pandas()


def trip_consumption(cfg: Config, data_dir: Path, year: int, pattern_ids, vecto_dir: Path | None = None,
                     say=print, made: "Consumption | None" = None) -> pd.DataFrame:
    """Battery energy per trip pattern and month (kWh) from the vehicle model run over each
    pattern's 2 s driving cycle at the month's mean ambient temperature.

    With *vecto_dir* each pattern's cycle is also written as a VECTO driving cycle
    (``pattern_<id>.vdri``) with a VECTO job of the vehicle, so a VECTO user can run them;
    with ``vehicle.vmod_dir`` the VECTO modal results ``pattern_<id>.vmod`` found there
    replace the built-in consumption of those patterns (for every month).  *made*: the
    patterns already computed by the run's tasks (:func:`consumption_tasks`, into the same
    *vecto_dir*); the others of *pattern_ids* are computed here.
    """
    from ..outputs import vecto

    vmod = _vmod_consumption(cfg, say) if made is None else made.vmod
    done = made.results() if made is not None else {}
    if vecto_dir is not None:
        vecto_dir.mkdir(parents=True, exist_ok=True)
    missing = sorted(set(pattern_ids) - set(done))
    if missing:
        done.update(pattern_consumption(cfg, data_dir, year, missing, vecto_dir, vmod))
    patterns = sorted(done)
    if vecto_dir is not None and patterns:
        vecto.write_vecto_job(vecto_dir, cfg.vehicle_params(), cycles=[done[p][1] for p in patterns])
    return pd.DataFrame([row for p in patterns for row in done[p][0]])


def _vmod_consumption(cfg: Config, say) -> dict:
    """Battery energy per pattern (kWh) from the VECTO modal results in ``vehicle.vmod_dir``
    (empty without)."""
    from ..outputs import vecto

    if cfg.vehicle.vmod_dir is None:
        return {}
    files = {int(p.stem.split("_", 1)[1]): p for p in Path(cfg.vehicle.vmod_dir).glob("pattern_*.vmod")}
    if not files:
        return {}
    vmod = vecto.vmod_trip_energies(files)["consumption_kwh"].to_dict()
    bad = [str(files[k]) for k, v in vmod.items() if not np.isfinite(v)]
    if bad:
        raise InputError(f"{bad[0]}: no battery power columns (P_REESS_*): not the modal "
                         "result of a battery-electric VECTO run")
    say(f"consumption of {len(vmod)} pattern(s) from VECTO results in {cfg.vehicle.vmod_dir}")
    return vmod


def pattern_consumption(cfg: Config, data_dir: Path, year: int, pattern_ids, vecto_dir: Path | None,
                        vmod: dict) -> dict:
    """Per pattern of *pattern_ids*: its rows of :func:`trip_consumption` (one per month of
    the run) and the name of its VECTO cycle file (written into *vecto_dir*; None without).
    A Dask task of the run (:func:`consumption_tasks`)."""
    from ..models.driving_cycle import pattern_cycle
    from ..models.vehicle import simulate_cycle
    from ..outputs import vecto

    params = cfg.vehicle_params()
    temps = cfg.monthly_temperature_c()
    out = {}
    for pattern_id in sorted(set(pattern_ids)):
        cycle = pattern_cycle(data_dir, pattern_id, cfg.trajectory.cycle)
        name = None
        if vecto_dir is not None:
            name = Path(vecto.write_vdri(cycle, vecto_dir / f"pattern_{pattern_id}.vdri")).name
        rows = []
        for m in cfg.run.months:
            e = simulate_cycle(cycle, params, ambient_c=temps[m - 1])
            rows.append({"pattern_id": pattern_id, "month": f"{year}-{m:02d}",
                         "consumption_kwh": vmod.get(int(pattern_id), e["battery_kwh"]),
                         "consumption_source": "vecto" if int(pattern_id) in vmod else "built-in",
                         "traction_kwh": e["traction_kwh"], "recuperated_kwh": e["recuperated_kwh"],
                         "aux_kwh": e["aux_kwh"]})
        out[pattern_id] = (rows, name)
    return out


#: trip patterns per consumption task of a run
PATTERNS_PER_TASK = 20


class Consumption:
    """The consumption of a run's trip patterns, computed by tasks on its cluster while the
    partitions are (:func:`consumption_tasks`); :meth:`results` waits for them."""

    def __init__(self, futures: list, vmod: dict):
        self.futures, self.vmod = futures, vmod
        self._results = None

    def results(self) -> dict:
        """The patterns' consumption, fetched once: the futures are let go then (the workers
        may be restarted before the reduce, :func:`vipvflow.simulation.cluster.fresh_workers`)."""
        if self._results is None:
            out = {}
            for part in (f.result() for f in self.futures):
                out.update(part)
            self._results, self.futures = out, []
        return self._results


def consumption_tasks(client, cfg: Config, year: int, run_dir: Path, say=print) -> Consumption:
    """Submit the vehicle model over the driving cycles of the patterns of the trips that run
    in the run's months (the timeline's trips; :func:`pattern_consumption`, a task per
    :data:`PATTERNS_PER_TASK`), writing their VECTO cycles into the run folder: none of it
    waits for the partitions (at network scale it was most of the reduce's time in this
    process)."""
    data_dir = Path(cfg.data_dir)
    vmod = _vmod_consumption(cfg, say)
    runs = pd.read_parquet(RunDir(run_dir).timeline_table("trip_runs"), columns=["trip_id"])
    trips = pd.read_parquet(DataDir(data_dir).gtfs.trips, columns=["trip_id", "pattern_id"])
    patterns = sorted(set(trips.loc[trips["trip_id"].isin(runs["trip_id"].unique()), "pattern_id"]))
    vecto_dir = RunDir(run_dir).vecto
    vecto_dir.mkdir(parents=True, exist_ok=True)
    futures = [client.submit(pattern_consumption, cfg, data_dir, year, patterns[i:i + PATTERNS_PER_TASK],
                             vecto_dir, vmod, pure=False)
               for i in range(0, len(patterns), PATTERNS_PER_TASK)]
    return Consumption(futures, vmod)


def _radiation_gaps(data_dir: Path, year: int, months) -> dict:
    """Gaps in the radiation data within the run's months (interpolated at ingest)."""
    import json

    try:
        rad = json.loads(DataDir(data_dir).radiation.report.read_text())
    except (OSError, ValueError):
        return {}
    spans = [(pd.Timestamp(year, m, 1, tz="UTC").timestamp(),
              (pd.Timestamp(year, m, 1, tz="UTC") + pd.offsets.MonthBegin(1)).timestamp())
             for m in months]
    hit = [g for loc in rad.get("locations", []) for g in loc.get("gaps", [])
           if any(g["start_utc"] < b and g["end_utc"] > a for a, b in spans)]
    return {"radiation_gaps_interpolated": len(hit),
            "radiation_gap_minutes_interpolated": int(sum(g["minutes"] for g in hit))}


def _check_totals(summary: dict, run_dir: Path) -> None:
    """A run whose energy or irradiation totals are zero or undefined stops with a reason,
    and summary.json is strict JSON: any other undefined figure is named, not written as NaN."""
    import json

    def bad(v):
        return isinstance(v, float) and not np.isfinite(v)

    irr = summary.get("irradiation_kwh_m2", {})
    for key, why in (("pv_kwh_driving", "no PV energy"),
                     ("fleet_demand_in_service_mwh", "no consumption")):
        v = summary.get(key)
        if v is None or bad(v) or v <= 0:
            raise InputError(f"{run_dir}: the run's {key} is {v}: {why} over {summary['passes']} "
                             f"passes (unshaded irradiation {irr.get('total_unshaded')} kWh/m2); "
                             "check the radiation values and the trips' stop times")
    flat = {**{k: v for k, v in summary.items() if not isinstance(v, dict)},
            **{f"irradiation_kwh_m2.{k}": v for k, v in irr.items()}}
    undefined = sorted(k for k, v in flat.items() if bad(v))
    if undefined:
        raise InputError(f"{run_dir}: undefined figures in the summary: {', '.join(undefined)} "
                         "(a total they divide by is zero)")
    json.dumps(summary, allow_nan=False, default=str)


def block_day_table(cfg: Config, run_dir: Path, trip: pd.DataFrame, vehicle, placed: pd.DataFrame):
    """Per block-day: PV driving, at layovers and parked (kWh), the time of each, the
    layovers' auxiliaries, and the battery's day under the charging plan (``charging``):
    the SoC at departure, lowest and at the end, whether the plan serves the block
    (``feasible``; else when and at what SoC it fails), the PV the battery takes
    (``pv_kwh_usable``) or not (``pv_kwh_curtailed``), and the grid energy of the depot and
    the terminals' chargers with PV and without (:func:`vipvflow.models.charging.block_day_soc`).
    Also the idle buses' parked days (their battery is full: their PV is curtailed), and
    *trip* (the reduce's per-trip table: ``pv_kwh``, ``consumption_kwh``) with the
    timeline's ``block_id`` (the GTFS block, or the inferred one) and each trip's SoC at
    departure, and each trip's row of the block-days (-1: none; :meth:`BlockDayRows.of`).
    The layovers' auxiliaries draw the vehicle's base load and HVAC at the
    month's mean temperature through the battery's discharge efficiency; the PV of layovers
    and parking counts only when ``fleet.harvest`` evaluates it.
    """
    from ..inputs.gtfs.schedule import month_labels

    run = RunDir(run_dir)
    tl = pd.read_parquet(run.timeline_table("block_days"))
    key = ["block_id", "service_date"]
    if len(placed) != len(trip):
        raise ValueError("the trips' blocks are not row by row with the trips")
    trip = trip.assign(block_id=placed["block_id"].array)   # as read: no Python string per row
    position = placed["position"].to_numpy(np.int64)
    bd = tl[key + ["month", "trips", "window_start_utc", "window_end_utc", "first_departure_utc",
                   "last_arrival_utc", "driving_s", "layover_s", "parked_s", "overlap_s"]
            ].sort_values(key).reset_index(drop=True)
    rows = BlockDayRows(bd)
    st, idle = _standing_rows(run_dir, rows)
    idle["month"] = month_labels(idle["service_date"])
    idle["pv_kwh_curtailed"] = idle["pv_kwh"]            # an idle bus's battery is full
    trip_at = rows.of(trip)
    first = trip["start_s"].groupby(trip_at).min()
    drive = trip[["pv_kwh", "pv_kwh_clear", "consumption_kwh"]].groupby(trip_at).sum()
    for c in ("pv_kwh", "pv_kwh_clear", "consumption_kwh"):
        bd[c] = rows.spread(drive[c], 0.0)
    bd["first_departure_s"] = rows.spread(first, np.nan)
    bd["pv_kwh_driving"] = bd["pv_kwh"]
    bd["seconds_driving"] = bd.pop("driving_s")
    st_at = st["at"]
    for kind in ("layover", "parked"):
        # the time from the timeline (whatever fleet.harvest evaluates), the PV from the
        # standing partitions (0 where not evaluated)
        mine = st[kind]
        part = pd.DataFrame({c: st[c][mine] for c in ("pv_kwh", "pv_kwh_clear")}).groupby(st_at[mine]).sum()
        bd[f"pv_kwh_{kind}"] = rows.spread(part["pv_kwh"], 0.0)
        bd[f"pv_kwh_clear_{kind}"] = rows.spread(part["pv_kwh_clear"], 0.0)
        bd[f"seconds_{kind}"] = bd.pop(f"{kind}_s")
    bd["pv_kwh_whole_day"] = bd["pv_kwh_driving"] + bd["pv_kwh_layover"] + bd["pv_kwh_parked"]
    bd["window_s"] = bd["window_end_utc"] - bd["window_start_utc"]
    del tl
    # each layover's PV: the standing rows of its block-day and the trip before it, summed
    # per (block-day, trip) pair as one integer before the layovers are read (the standing
    # rows held beside them were a network's 0.2 GB)
    mine = st["layover"] & (st_at >= 0)
    at, after, pv = st_at[mine], st["after_trip"][mine], st["pv_kwh"][mine]
    del st, st_at, mine                 # the layovers' rows picked: the others not held while they are summed
    lit = _LayoverPV(at, after, pv)
    del at, after, pv
    hand_back_memory()

    # the layovers (every one, with its terminal and PV) and the parked time at the depot
    lay, parked = _service_intervals(run.timeline_table("intervals"), ("layover", "parked"), [
        "block_id", "service_date", "after_trip", "point_id", "t0_utc", "t1_utc"])
    hand_back_memory()
    lay = lay.merge(pd.read_parquet(run.timeline_table("points"), columns=["point_id", "stop_id"]),
                    on="point_id", how="left").drop(columns="point_id")
    lay_at = rows.of(lay)
    lay = lay.drop(columns="block_id")      # its block-day found: its ids not held through the battery's day
    lay["pv_kwh"] = lit.of(lay_at, lay["after_trip"].to_numpy(np.int64))
    lay["seconds"] = (lay["t1_utc"] - lay["t0_utc"]).to_numpy(float)
    parked = parked.assign(seconds=(parked["t1_utc"] - parked["t0_utc"]).to_numpy(float))
    del lit

    # the layovers' auxiliaries (kWh from the battery) at the month's temperature
    temps = np.asarray(cfg.monthly_temperature_c(), float)

    def aux_kwh(service_date, seconds):
        month_no = pd.to_datetime(service_date).dt.month.to_numpy()
        return (np.asarray(vehicle.aux_kw(temps[month_no - 1]), float) * np.asarray(seconds, float)
                / 3600.0 / vehicle.discharge_efficiency)

    lay["aux_kwh"] = aux_kwh(lay["service_date"], lay["seconds"])
    bd["layover_aux_kwh"] = rows.spread(lay["aux_kwh"].groupby(lay_at).sum(), 0.0)
    # the battery's demand in service: the trips and the layovers' auxiliaries
    bd["demand_kwh"] = bd["consumption_kwh"] + bd["layover_aux_kwh"]
    balance = _battery_day(cfg, run_dir, bd, rows, trip, trip_at, position, lay, lay_at, parked,
                           vehicle)
    for c, v in balance.items():
        if c not in ("soc_at_departure", "traces"):
            bd[c] = v
    trip["soc_at_departure"] = balance["soc_at_departure"]
    bd["pv_kwh_usable"] = bd["pv_kwh_whole_day"] - bd["pv_kwh_curtailed"]
    return bd, idle, trip, balance["traces"], trip_at


class _LayoverPV:
    """The standing rows' PV at layovers summed per layover: per block-day row (*at*) and
    trip before it (*after*, -1: before the first), the pair as one integer (not a join of
    the standing rows with the layovers)."""

    def __init__(self, at: np.ndarray, after: np.ndarray, pv: np.ndarray):
        after = np.asarray(after, np.int64)
        self._width = int(after.max(initial=0)) + 2
        key = np.asarray(at, np.int64) * self._width          # the pair, made in place
        key += after
        key += 1
        self._sums = pd.Series(pv).groupby(key).sum()

    def of(self, at: np.ndarray, after: np.ndarray) -> np.ndarray:
        """Each layover's PV (kWh; 0 where no standing row is of its block-day and trip)."""
        after = np.asarray(after, np.int64) + 1
        key = np.where((at >= 0) & (after >= 0) & (after < self._width), at * self._width + after, -1)
        return self._sums.reindex(key).fillna(0.0).to_numpy()


#: the standing partitions' columns of the idle buses' rows (:func:`_standing_rows`)
IDLE_COLUMNS = (("block_id", object), ("service_date", "datetime64[ns]"), ("kind", object),
                ("after_trip", np.int64), ("buses", np.int64), ("seconds", float), ("pv_kwh", float),
                ("pv_kwh_clear", float))


def _standing_rows(run_dir: Path, rows: "BlockDayRows") -> tuple[dict, pd.DataFrame]:
    """The standing partitions' rows (every file, in path order), read a file at a time: of
    the buses in service, as arrays (``at``: the row's block-day, :meth:`BlockDayRows.of`;
    ``layover``, ``parked``: its kind; ``after_trip``, ``pv_kwh``, ``pv_kwh_clear``); of
    the idle buses' block, a DataFrame of :data:`IDLE_COLUMNS` indexed by the row's place
    among all rows.  A network's 4.9 M rows were held whole, with their block ids and kinds
    as strings, to pick these columns (0.6 GB at the reduce's peak)."""
    import pyarrow.compute as pc

    from ..inputs.gtfs.schedule import IDLE_BLOCK

    names = [c for c, _ in IDLE_COLUMNS]
    busy = {"at": [], "layover": [], "parked": [], "after_trip": [], "pv_kwh": [], "pv_kwh_clear": []}
    idle, offset = [], 0
    for f in RunDir(run_dir).part_files("standing"):
        t = _read_file(f, names)
        if not t.num_rows:
            continue
        on_duty = pc.fill_null(pc.not_equal(t.column("block_id"), IDLE_BLOCK), True)
        if not pc.all(on_duty).as_py():
            off = t.filter(pc.invert(on_duty)).to_pandas()
            off.index = offset + np.flatnonzero(~on_duty.to_numpy(zero_copy_only=False))
            idle.append(off)
        t = t.filter(on_duty)
        busy["at"].append(rows.of(t.select(["block_id", "service_date"]).to_pandas()))
        for kind in ("layover", "parked"):
            busy[kind].append(pc.fill_null(pc.equal(t.column("kind"), kind), False).to_numpy(zero_copy_only=False))
        for c, dtype in (("after_trip", np.int64), ("pv_kwh", float), ("pv_kwh_clear", float)):
            busy[c].append(t.column(c).to_numpy().astype(dtype, copy=False))
        offset += len(on_duty)
    empty = {"at": np.int64, "layover": bool, "parked": bool, "after_trip": np.int64,
             "pv_kwh": float, "pv_kwh_clear": float}
    busy = {c: np.concatenate(v) if v else np.zeros(0, empty[c]) for c, v in busy.items()}
    idle = (pd.concat(idle) if idle else
            pd.DataFrame({c: pd.Series(dtype=t) for c, t in IDLE_COLUMNS}))
    return busy, idle


def _service_intervals(path: Path, kinds: tuple, columns: list) -> list:
    """The timeline's intervals (*path*) of each of *kinds* of the buses in service (not the
    idle buses' block), each kind's rows in the file's order as a DataFrame of *columns*;
    read a batch at a time (a network's 4.9 M intervals were held whole, with two copies of
    their strings, to pick them)."""
    import pyarrow.compute as pc

    from ..inputs.gtfs.schedule import IDLE_BLOCK

    pieces = {k: [] for k in kinds}
    with pq.ParquetFile(path) as pf:
        schema = pa.schema([pf.schema_arrow.field(c) for c in columns])
        for batch in pf.iter_batches(batch_size=1 << 20, columns=list(dict.fromkeys([*columns, "kind"])),
                                     use_threads=False):
            busy = pc.fill_null(pc.not_equal(batch.column("block_id"), IDLE_BLOCK), True)
            for k in kinds:
                chosen = pc.and_(busy, pc.equal(batch.column("kind"), k))
                pieces[k].append(batch.filter(chosen).select(columns))
    return [pa.Table.from_batches(pieces[k], schema=schema).to_pandas() for k in kinds]


#: block-days whose battery is run at once (:func:`_battery_day`): each morning starts at
#: the depot's SoC, so the rows are independent, and a chunk's (rows x trips) grids stay
#: ~25 MB where a network's year held all of them at once (hundreds of MB); 8192 rows
#: added 0.05 GB to a network's trips step, and twice the chunks cost no time measured
BATTERY_ROWS = 4096


class DayRows:
    """The rows of a *table* whose rows are each named by an id (its *column*: a block, a
    trip) and a service date, each pair once, that other tables' rows have, as integers:
    the ids are looked up in Arrow (no Python string per row) and the pairs compared as one
    integer, not joined or grouped by (string, date) pairs (a network's 4.7 M trips and
    4.9 M intervals were, several times over)."""

    def __init__(self, table: pd.DataFrame, column: str):
        import pyarrow.compute as pc

        self.n, self._column = len(table), column
        self._known = pc.drop_null(pc.unique(self._arrow(table[column])))
        self._index = pd.Index(self._known.to_numpy(zero_copy_only=False))
        days = self._days(table)
        self._d0 = int(days.min()) if len(days) else 0
        self._span = int(days.max()) - self._d0 + 1 if len(days) else 1
        self._key = self._keys(table)
        self._check()
        self._order = np.argsort(self._key, kind="stable")
        self._sorted = self._key[self._order]

    def _check(self) -> None:
        key = np.sort(self._key[self._key >= 0])
        if len(key) > 1 and (key[1:] == key[:-1]).any():
            raise ValueError(f"a {self._column} and service date is given twice: the rows are not "
                             "one per pair")

    @staticmethod
    def _arrow(values: pd.Series) -> pa.Array:
        return pa.array(values.array if pd.api.types.is_string_dtype(values.dtype)
                        else values.astype(str).array, from_pandas=True).cast(pa.large_string())

    @staticmethod
    def _days(frame: pd.DataFrame) -> np.ndarray:
        return frame["service_date"].to_numpy("datetime64[D]").astype(np.int64)

    def _keys(self, frame: pd.DataFrame) -> np.ndarray:
        """Each row's (id, day) as one integer; -1 where the id or the day is none of the
        table's."""
        import pyarrow.compute as pc

        ids = frame[self._column]
        if isinstance(ids.dtype, pd.CategoricalDtype):     # its categories, looked up once
            code = self._index.get_indexer(ids.cat.categories.astype(str))[ids.cat.codes.to_numpy()]
            code[ids.cat.codes.to_numpy() < 0] = -1
        else:
            code = pc.fill_null(pc.index_in(self._arrow(ids), value_set=self._known), -1).to_numpy()
        day = self._days(frame) - self._d0
        ok = (code >= 0) & (day >= 0) & (day < self._span)
        return np.where(ok, code.astype(np.int64) * self._span + day, -1)

    def of(self, frame: pd.DataFrame) -> np.ndarray:
        """Each row's row of the table (-1: none)."""
        key = self._keys(frame)
        at = np.searchsorted(self._sorted, key)
        hit = (key >= 0) & (at < self.n)
        hit[hit] = self._sorted[at[hit]] == key[hit]
        return np.where(hit, self._order[np.minimum(at, max(self.n - 1, 0))], -1)


class BlockDayRows(DayRows):
    """The rows of a block-day table (*bd*: ``block_id, service_date``, sorted by them, each
    pair once) that other tables' rows belong to (:class:`DayRows`): the block-days' sums are
    grouped by that integer and spread back over *bd* (:meth:`spread`)."""

    def __init__(self, bd: pd.DataFrame):
        super().__init__(bd, "block_id")

    def _check(self) -> None:
        if len(self._key) and not (np.diff(self._key) > 0).all():
            raise ValueError("the block-days must be sorted by block and date, each once")

    def spread(self, sums: pd.Series, fill: float) -> np.ndarray:
        """Per block-day (row of *bd*) the values of *sums* (indexed by row, as grouped by
        :meth:`of`'s rows), *fill* where a block-day has none."""
        return sums.reindex(np.arange(self.n), fill_value=fill).to_numpy()


def _battery_day(cfg: Config, run_dir: Path, bd: pd.DataFrame, rows: BlockDayRows,
                 trip: pd.DataFrame, trip_at: np.ndarray, position: np.ndarray, lay: pd.DataFrame,
                 lay_at: np.ndarray, parked: pd.DataFrame, vehicle) -> dict:
    """The block-days' battery under the charging plan, with PV and without
    (:func:`vipvflow.models.charging.block_day_soc`, :data:`BATTERY_ROWS` block-days at a
    time), from their trips, layovers (*lay*) and parked time (*parked*), each row's
    block-day given by *rows* (*trip_at*, *lay_at*: :meth:`BlockDayRows.of` of *trip* and
    *lay*): the columns of ``block_day`` it gives, and ``soc_at_departure`` row by row with
    *trip*."""
    import json

    from ..inputs.gtfs.schedule import service_day_origin_utc
    from ..models.charging import Charger, Vehicle, block_day_soc, window_overlap_s

    plan = cfg.charging
    tz = json.loads(DataDir(cfg.data_dir).gtfs.feed_json.read_text())["timezone"]
    n, K = len(bd), max(int(bd["trips"].max()) if len(bd) else 1, 1)

    t0 = (service_day_origin_utc(trip["service_date"].to_numpy(), tz)
          + trip["start_s"].to_numpy(float))
    t1 = t0 + trip["seconds"].to_numpy(float)
    if (trip_at < 0).any():              # the timeline places every trip in a block-day
        raise ValueError(f"{int((trip_at < 0).sum())} trips have no block-day in the run's timeline")
    lpos = lay["after_trip"].to_numpy(np.int64)
    opp = plan.opportunity
    at_charger = (np.ones(len(lay), bool) if opp.terminals == "all" else
                  lay["stop_id"].astype(str).isin(opp.terminals or []).to_numpy())
    charge = at_charger & (lay["seconds"].to_numpy() >= opp.min_layover_min * 60.0)
    steps = {"trip": (trip_at, position, {"pv": trip["pv_kwh"], "use": trip["consumption_kwh"],
                                          "t0": t0, "t1": t1}),
             "lay": (lay_at, lpos, {"pv": lay["pv_kwh"], "use": lay["aux_kwh"], "t0": lay["t0_utc"],
                                    "t1": lay["t1_utc"], "charge": charge})}
    steps = {k: (at, np.asarray(pos, np.int64), {c: np.asarray(v, float) for c, v in vals.items()},
                 np.argsort(at, kind="stable"))
             for k, (at, pos, vals) in steps.items()}
    # the depot's hours: the parked time within the chargers' local hours
    if plan.depot.hours is None:
        hours_s = parked["seconds"].to_numpy(float)
    else:
        offset = (pd.DatetimeIndex(pd.to_datetime(parked["t0_utc"], unit="s", utc=True))
                  .tz_convert(tz).tz_localize(None)
                  - pd.to_datetime(parked["t0_utc"], unit="s")).total_seconds().to_numpy()
        hours_s = window_overlap_s(parked["t0_utc"].to_numpy(float) + offset,
                                   parked["t1_utc"].to_numpy(float) + offset, *plan.depot.hours)
    depot_hours = rows.spread(pd.Series(hours_s).groupby(rows.of(parked)).sum(), 0.0)
    parked_pv = bd["pv_kwh_parked"].to_numpy()
    car = Vehicle(vehicle.battery_kwh, vehicle.soc_min, vehicle.soc_max)
    depot = Charger(plan.depot.power_kw, plan.depot.efficiency,
                    plan.depot.target_soc if plan.depot.target_soc is not None else vehicle.soc_max)
    opportunity = None if opp.terminals is None else Charger(
        opp.power_kw, opp.efficiency, opp.target_soc if opp.target_soc is not None else vehicle.soc_max)

    def run(a: int, b: int):
        """Block-days a:b with PV and without (traced), their steps' grids, and the rows of
        *trip* in them."""
        grids, taken = {}, {}
        for kind, (at, pos, vals, order) in steps.items():
            lo, hi = np.searchsorted(at, [a, b], sorter=order)
            i = order[lo:hi]                       # in their order: a step given twice keeps the last
            taken[kind] = i
            r, p = at[i] - a, pos[i]
            ok = (p >= 0) & (p < K)
            for c, v in vals.items():
                g = np.full((b - a, K), np.nan if kind == "trip" and c in ("t0", "t1") else 0.0)
                g[r[ok], p[ok]] = v[i][ok]
                grids[f"{kind}_{c}"] = g
        common = dict(trip_t0=grids["trip_t0"], trip_t1=grids["trip_t1"], lay_t0=grids["lay_t0"],
                      lay_t1=grids["lay_t1"], lay_charge=grids["lay_charge"] > 0,
                      depot_hours_s=depot_hours[a:b], depot=depot, opportunity=opportunity,
                      connect_s=opp.connect_min * 60.0)
        with_pv = block_day_soc(car, grids["trip_pv"], grids["trip_use"], lay_pv=grids["lay_pv"],
                                lay_use=grids["lay_use"], parked_pv=parked_pv[a:b], trace=True, **common)
        no_pv = block_day_soc(car, np.zeros((b - a, K)), grids["trip_use"], lay_pv=np.zeros((b - a, K)),
                              lay_use=grids["lay_use"], parked_pv=np.zeros(b - a), trace=True, **common)
        return with_pv, no_pv, grids, taken["trip"]

    with_pv, no_pv = {}, {}
    soc_dep = np.full(len(trip), np.nan)
    for a in range(0, max(n, 1), BATTERY_ROWS):
        b = min(n, a + BATTERY_ROWS)
        w, o, _, i = run(a, b)
        for out, part in ((with_pv, w), (no_pv, o)):
            for c, v in part.items():
                if np.ndim(v) == 1:
                    out.setdefault(c, []).append(v)
        # each trip's SoC at its departure: the morning's, or after the layover before it
        before = np.column_stack([w["soc_start"], w["soc_after_layover"][:, :-1]])
        soc_dep[i] = before[trip_at[i] - a, np.clip(position[i], 0, K - 1)]
    with_pv = {c: np.concatenate(v) for c, v in with_pv.items()}
    no_pv = {c: np.concatenate(v) for c, v in no_pv.items()}
    # to the second (interpolated within a trip: finer would be false precision)
    fail = pd.to_datetime(np.round(with_pv["fail_utc"]), unit="s", utc=True)
    grid_pv = with_pv["depot_grid_kwh"] + with_pv["opportunity_grid_kwh"]
    grid_nopv = no_pv["depot_grid_kwh"] + no_pv["opportunity_grid_kwh"]
    return {
        "soc_start": with_pv["soc_start"], "soc_lowest_pv": with_pv["soc_lowest"],
        "soc_end_pv": with_pv["soc_end"], "soc_lowest_nopv": no_pv["soc_lowest"],
        "feasible": with_pv["feasible"], "feasible_without_pv": no_pv["feasible"],
        "infeasible_at_utc": fail, "infeasible_soc": with_pv["fail_soc"],
        "depot_short_kwh": with_pv["depot_short_kwh"],
        "pv_kwh_curtailed": with_pv["curtailed_in_service_kwh"] + with_pv["curtailed_parked_kwh"],
        "grid_kwh_depot": with_pv["depot_grid_kwh"], "grid_kwh_depot_without_pv": no_pv["depot_grid_kwh"],
        "grid_kwh_opportunity": with_pv["opportunity_grid_kwh"],
        "grid_kwh_opportunity_without_pv": no_pv["opportunity_grid_kwh"],
        "grid_kwh_avoided": grid_nopv - grid_pv,
        "soc_at_departure": soc_dep,
        "traces": _soc_traces(bd, with_pv["soc_lowest"], run),
    }


def _soc_traces(bd: pd.DataFrame, lowest: np.ndarray, run) -> pd.DataFrame:
    """The SoC through two block-days, with PV and without, at each trip's departure and
    arrival and each layover's end: the worst (lowest SoC with PV, *lowest*) and a typical
    one (the median lowest SoC), each run again alone (``run(i, i + 1)``, as
    :func:`_battery_day`'s): ``which, block_id, service_date, t_utc, soc_pv, soc_nopv``."""
    if not len(bd):
        return pd.DataFrame(columns=["which", "block_id", "service_date", "t_utc", "soc_pv", "soc_nopv"])
    order = np.argsort(lowest, kind="stable")
    picks = {"worst": int(order[0]), "typical": int(order[len(order) // 2])}
    rows = []
    for which, i in picks.items():
        with_pv, no_pv, grids, _ = run(i, i + 1)
        trip_t0, trip_t1, lay_t1 = grids["trip_t0"][0], grids["trip_t1"][0], grids["lay_t1"][0]
        k_n = int(bd["trips"].iloc[i])
        pts = [(trip_t0[0], with_pv["soc_start"][0], no_pv["soc_start"][0])]
        for k in range(k_n):
            pts.append((trip_t1[k], with_pv["soc_after_trip"][0, k], no_pv["soc_after_trip"][0, k]))
            if k < k_n - 1:
                pts.append((lay_t1[k], with_pv["soc_after_layover"][0, k],
                            no_pv["soc_after_layover"][0, k]))
        for t, a, b in pts:
            rows.append({"which": which, "block_id": str(bd["block_id"].iloc[i]),
                         "service_date": bd["service_date"].iloc[i], "t_utc": float(t),
                         "soc_pv": float(a), "soc_nopv": float(b)})
    return pd.DataFrame(rows)


def reduce_run(cfg: Config, year: int, run_dir: Path, say=print, client=None, cluster_done=None,
               timings: dict | None = None, consumption: Consumption | None = None,
               fresh_workers=None) -> dict:
    """Write trip_energy, segments, segment_month, route_month, block_day, monthly, hourly
    outputs, ``summary.json``, ``city.glb``, the ``geoparquet/`` datasets and ``report.html``;
    return the summary.

    The partitions are read and summed by tasks on the cluster of *client* (its workers see
    *run_dir* at the same path), or in this process without one (:func:`partial_sums`);
    the joins, the vehicles' balance and the outputs are computed here, while the workers
    draw the report's figures.  *cluster_done* is called once the cluster's part is done
    (the run shuts its cluster down then, while this process writes the report).  The
    seconds of each step are added to *timings* (``reduce_<step>_s``).  *consumption*: the
    trip patterns' consumption already submitted to the cluster (:func:`consumption_tasks`).
    *fresh_workers*: restarts the workers of a run's own cluster once the sums are gathered
    (:func:`partial_sums`; a run keeps one of them for the figures, ``city.glb`` and the
    datasets: :func:`vipvflow.simulation.cluster.fewer_fresh_workers`)."""
    from ..outputs import gltf, report
    from ..outputs.datasets import write_datasets

    clock = _Clock(timings)
    parts = partial_sums(run_dir, client, fresh_workers)
    clock("sums")
    # the figures are drawn on the cluster's workers as their data is made (here without one):
    # the hourly chart at once, while the segments are joined here
    figures = report.Figures(client)
    hp = _hourly_pattern(parts["hourly"])
    report.add_hourly(figures, hp)
    trips_meta = pd.read_parquet(DataDir(cfg.data_dir).gtfs.trips)
    parts["totals"] = _trip_totals(run_dir, parts.pop("trip"))     # the Arrow sums not held on
    parts["placed"] = _placed_trips(run_dir, parts["totals"])
    n_buses = int(parts["placed"].groupby("service_date")["block_id"].nunique().max())
    # the segments first (their files are what the maps, city.glb and the datasets are made of)
    segments, crs, sums = _segment_outputs(cfg, run_dir, parts.pop("segment_month"), parts["geometry"],
                                           parts["totals"], n_buses, trips_meta)
    clock("segments")
    # the trip sums and their blocks handed over: the trips' step lets them go once they are
    # joined into its table
    trip, bd, idle, traces, shares = _trip_outputs(cfg, year, run_dir, parts.pop("totals"),
                                                   parts.pop("placed"), trips_meta, say, consumption)
    del parts
    clock("trips")
    rm = _route_month(trip, bd, shares)
    # the fleet's coverage (summary.json's: annual scaling cancels) beside the routes'
    coverage = float(bd["pv_kwh_usable"].sum() / bd["demand_kwh"].sum()) if len(bd) else None
    report.add_routes(figures, rm, coverage)
    report.add_battery(figures, traces, cfg.vehicle_params().soc_min)
    write_parquet(rm, RunDir(run_dir).output("route_month.parquet"))
    write_parquet(bd, RunDir(run_dir).output("block_day.parquet"))
    ranking = _ranking(cfg, bd, trip, shares, 12.0 / len(cfg.run.months))
    write_parquet(ranking, RunDir(run_dir).output("ranking.parquet"))
    report.add_ranking(figures, ranking)
    write_parquet(hp, RunDir(run_dir).output("hourly_pattern.parquet"))
    monthly, summary = _fleet_year(cfg, year, run_dir, trip, bd, idle, sums, segments, n_buses)
    write_parquet(monthly, RunDir(run_dir).output("monthly.parquet"))
    write_json(summary, RunDir(run_dir).output("summary.json"))
    report.add_charts(figures, summary, monthly)
    # the trips' and block-days' tables are written and summed: not held while the maps,
    # city.glb and the GeoParquet datasets are made on the workers from the segments' files
    # (made beside the trips' step, they added ~0.7 GB per worker to the run's peak)
    del trip, bd, idle, traces, rm, ranking, monthly, trips_meta, hp
    clock("fleet")
    report.add_maps(figures, run_dir, cfg)
    model = _Aside(client, "city-glb", gltf.write_gltf, str(run_dir),
                   str(RunDir(run_dir).output("city.glb")), str(cfg.data_dir))
    datasets = _Aside(client, "geoparquet-datasets", write_datasets, str(run_dir))
    drawn = figures.results()
    glb = model.result()
    datasets.result()
    clock("figures")
    if cluster_done is not None:
        cluster_done()
    report.write_report(run_dir, summary, drawn, cfg=cfg, segments=segments, model=glb, crs=crs)
    clock("report")
    return summary


class _Aside:
    """``fn(*args)`` on a worker of *client* while the reduce goes on (like the report's
    figures), or at once here without one; :meth:`result` waits for its result."""

    def __init__(self, client, key: str, fn, *args):
        self._client = client
        self._job = (client.submit(handing_back, fn, *args, pure=False, key=key)
                     if client is not None else fn(*args))

    def result(self):
        return self._client.gather(self._job) if self._client is not None else self._job


class _Clock:
    """``clock(step)`` adds the seconds since the last call to ``timings["reduce_<step>_s"]``
    and hands the memory the step freed back to the operating system."""

    def __init__(self, timings: dict | None):
        self._timings = timings if timings is not None else {}
        self._last = time.perf_counter()

    def __call__(self, step: str) -> None:
        # the step's temporaries handed back (Arrow's pool keeps what its reads and string
        # columns freed, and numpy's allocations cannot reuse it): a few ms
        hand_back_memory()
        now = time.perf_counter()
        self._timings[f"reduce_{step}_s"] = now - self._last
        self._last = now


def _placed_trips(run_dir: Path, totals: pd.DataFrame) -> pd.DataFrame:
    """The timeline's vehicle block (the GTFS block or the inferred one) and position in it of
    each trip of *totals* (:func:`_trip_totals`), row by row: ``service_date, block_id,
    position``.  The fleet is the most blocks on one service date; the block-days
    (:func:`block_day_table`) take the trips' blocks from it."""
    runs = pd.read_parquet(RunDir(run_dir).timeline_table("trip_runs"),
                           columns=["trip_id", "service_date", "block_id", "position"])
    at = _rows_of_trip_days(runs, totals)
    if (at >= 0).all():
        placed = runs[["block_id", "position"]].take(at)
    else:                       # the rows of no run: missing, as a left join leaves them
        placed = runs[["block_id", "position"]].reindex(at)
    placed.index = pd.RangeIndex(len(totals))
    placed.insert(0, "service_date", totals["service_date"].to_numpy())
    return placed


def _rows_of_trip_days(table: pd.DataFrame, frame: pd.DataFrame) -> np.ndarray:
    """For each row of *frame*, the row of *table* with the same ``trip_id`` and
    ``service_date`` (-1: none; :class:`DayRows`); each pair must be once in both (else
    ``ValueError``): a network's 4.7 M trip-days joined by their string keys took 1 GB for
    a moment."""
    at = DayRows(table, "trip_id").of(frame)
    found = np.sort(at[at >= 0])
    if len(found) > 1 and (found[1:] == found[:-1]).any():
        raise ValueError("a trip and service date is given twice: the join is not one to one")
    return at


def _trip_outputs(cfg: Config, year: int, run_dir: Path, totals: pd.DataFrame, placed: pd.DataFrame,
                  trips_meta: pd.DataFrame, say, consumption: Consumption | None = None):
    """Per trip and service date (PV of *totals*, :func:`_trip_totals`; the trip's metadata,
    the vehicle model's consumption; the timeline's block of each, *placed*, row by row with
    *totals*: the joins here keep their rows' order) and per block-day (driving, layovers,
    parked; the battery's share); writes ``trip_energy.parquet``.  Returns the trips, the
    block-days, the idle buses' days, the batteries' traces and the trips' shares of their
    block-days (:class:`TripShares`)."""
    from ..inputs.gtfs.schedule import month_labels

    meta = trips_meta.reindex(columns=["trip_id", "route_id", "route_short_name", "route_long_name",
                                       "trip_headsign", "direction_id", "shape_id", "service_id",
                                       "block_id", "pattern_id", "start_s"])
    # the trips' names and ids repeat on every service day: held as categories through the
    # block-days (a network's strings were half its trip table), written as the strings they are
    # (:func:`_as_values`)
    strings = [c for c in meta.columns.drop(["trip_id", "pattern_id"])
               if pd.api.types.is_string_dtype(meta[c].dtype)]
    trip = totals.merge(meta.astype({c: "category" for c in strings}), on="trip_id", how="left",
                        validate="many_to_one")
    del totals          # joined (the caller hands it over)
    trip["month"] = month_labels(trip["service_date"])
    cons = trip_consumption(cfg, Path(cfg.data_dir), year, trip["pattern_id"].unique(),
                            vecto_dir=RunDir(run_dir).vecto, say=say, made=consumption)
    trip = trip.merge(cons, on=["pattern_id", "month"], how="left", validate="many_to_one")
    trip["coverage"] = trip["pv_kwh"] / trip["consumption_kwh"]
    trip = trip.astype({c: "category" for c in ("pattern_id", "month", "consumption_source")
                        if c in trip and pd.api.types.is_string_dtype(trip[c].dtype)})
    # vehicle block per day: driving, layovers, parked; the battery's share (sets the
    # trips' block_id to the timeline's: the GTFS block or the inferred one)
    bd, idle, trip, traces, trip_at = block_day_table(cfg, run_dir, trip, cfg.vehicle_params(), placed)
    del placed
    shares = TripShares(trip_at, trip["seconds"])
    del trip_at
    path = RunDir(run_dir).output("trip_energy.parquet")
    try:
        # a slice at a time, each with its names as strings (the whole table's Arrow copy
        # beside it was the top of a network's trips' step)
        write_parquet_parts((_as_values(trip.iloc[i:i + TRIP_PART_ROWS])
                             for i in range(0, max(len(trip), 1), TRIP_PART_ROWS)), path,
                            row_group_rows=TRIP_GROUP_ROWS)
    except PartSchemaError:     # slices typed apart by their values: the whole at once
        write_parquet(_as_values(trip), path)
    # the trips go on with their names as categories: the routes', the ranking's and the
    # months' tables take them back to their values (a network's table as strings was
    # 0.45 GB more, at the trips' and the fleet's steps)
    return trip, bd, idle, traces, shares


def _segment_outputs(cfg: Config, run_dir: Path, sm: pd.DataFrame, geo: pd.DataFrame | None,
                     totals: pd.DataFrame, n_buses: int, trips_meta: pd.DataFrame):
    """Per segment and month (GeoParquet for maps) and per segment over the run (geometry
    factors and year) of the shapes of the trips in *totals* (:func:`_trip_totals`) run by
    *n_buses*; writes ``segment_month.parquet`` and ``segments.parquet``.  Returns the
    segments (a DataFrame, without their lines), their CRS and the sums over them the
    fleet-year's summary takes (:class:`_SegmentSums`; not the per segment-month table: a
    network's is hundreds of MB the trips' step does not need)."""
    from . import annual

    data_dir = Path(cfg.data_dir)
    segments = gpd.read_parquet(DataDir(data_dir).gtfs.segments)
    run_trips = trips_meta[trips_meta["trip_id"].isin(totals["trip_id"].unique())]
    segments = segments[segments["shape_id"].isin(run_trips["shape_id"].unique())]
    shape_route = shape_routes(run_trips)
    del run_trips
    shape_route = shape_route[["shape_id", "route_short_name", "direction_id"]]
    # the segments' year and the summary's sums first (made beside the segment-months'
    # file, the year's sums were the top of a network's segments step)
    hours_per_bus = annual.service_hours_per_bus(float(totals["seconds"].sum()), n_buses,
                                                 12.0 / len(cfg.run.months))
    year = annual.segment_year(segments.merge(shape_route, on="shape_id", how="left"), geo, sm,
                               cfg.pv_system().kwp, hours_per_bus)
    write_parquet(year, RunDir(run_dir).output("segments.parquet"))
    sums = _SegmentSums.of(sm, year)
    # held on through the trips' step without their lines (a network's 300,000 shapely
    # lines and strings were ~0.3 GB of the command's peak): the report takes their CRS
    crs, year = year.crs, pd.DataFrame(year.drop(columns="geometry"))
    parts, geo_meta = _segment_month_rows(segments, sm, shape_route)
    write_parquet_parts(parts, RunDir(run_dir).output("segment_month.parquet"), geo_meta,
                        SEGMENT_MONTH_GROUP_ROWS)
    return year, crs, sums


def _with_losses(sm: pd.DataFrame) -> pd.DataFrame:
    """*sm* (segment-month rows) with their shading loss: sky and sun light the buildings
    take away (1 - (direct + diffuse) / unshaded), in the weather and under clear sky, and
    the reflected light they add, reported apart as reflection gain."""
    return sm.assign(
        shading_loss=shading_loss(sm["h_direct"], sm["h_diffuse"], sm["h_total_unshaded"]),
        shading_loss_clear=shading_loss(sm["h_direct_clear"], sm["h_diffuse_clear"],
                                        sm["h_total_clear_unshaded"]),
        reflection_gain=sm["h_reflected"] / sm["h_total_unshaded"].where(sm["h_total_unshaded"] > 0))


def _segment_month_rows(segments: gpd.GeoDataFrame, sm: pd.DataFrame, shape_route: pd.DataFrame):
    """The rows of ``segment_month.parquet``: each row of *sm* whose segment is one of
    *segments*, with the segment's ``shape_id`` and line, its losses (:func:`_with_losses`,
    made a part at a time) and the shape's routes (*shape_route*), in the order of
    ``segments.merge(sm).merge(shape_route, how="left")``,
    as GeoDataFrames of :data:`SEGMENT_MONTH_PART_ROWS` rows (a network's whole, 3.7 M
    rows, took 1.3 GB more than *sm*); and the GeoParquet metadata of all rows (the lines'
    bounding box and types), for :func:`write_parquet_parts`."""
    from geopandas.io.arrow import _geopandas_to_arrow

    seg = segments[["segment_id", "shape_id", "geometry"]].reset_index(drop=True)
    at = pd.Index(seg["segment_id"]).get_indexer(sm["segment_id"])
    # a merge keeps the order of the left's rows, each with its matches in their order
    rows = np.flatnonzero(at >= 0)
    rows = rows[np.argsort(at[rows], kind="stable")]
    routes = shape_route.set_index("shape_id")
    sums = sm.drop(columns="segment_id")
    used = np.unique(at[rows])
    geo_meta = {b"geo": _geopandas_to_arrow(gpd.GeoDataFrame(seg.iloc[used][["geometry"]], crs=segments.crs),
                                            index=False).schema.metadata[b"geo"]}

    def parts():
        for start in range(0, max(len(rows), 1), SEGMENT_MONTH_PART_ROWS):
            take = rows[start:start + SEGMENT_MONTH_PART_ROWS]
            left = seg.iloc[at[take]].reset_index(drop=True)
            right = routes.reindex(left["shape_id"].to_numpy()).reset_index(drop=True)
            rows_sums = _with_losses(_as_values(sums.iloc[take].reset_index(drop=True)))
            yield gpd.GeoDataFrame(pd.concat([left, rows_sums, right], axis=1),
                                   geometry="geometry", crs=segments.crs)

    return parts(), geo_meta


class _SegmentSums(NamedTuple):
    """What the fleet-year's summary takes of the segment-month rows: the irradiation sums
    ``h_*`` of all of them (*light*) and of the road's (*road*: not inside a building
    footprint), the passes, each segment's sums (*per_segment*, :func:`_study_area`) and
    the segments' flags (:func:`_segment_flags`)."""
    light: pd.Series
    road: pd.Series
    passes: int
    per_segment: pd.DataFrame
    flags: pd.DataFrame

    @classmethod
    def of(cls, sm: pd.DataFrame, segments: pd.DataFrame) -> "_SegmentSums":
        h_cols = [c for c in sm.columns if c.startswith("h_")]
        # the light on the roofs: every segment; the shading statistics: the road, without
        # the segments inside building footprints (they take a nearby street's light)
        flags = _segment_flags(segments)
        at = flags.index.get_indexer(sm["segment_id"])
        street = ~np.where(at >= 0, flags["in_building"].to_numpy(bool)[at], False)
        # column by column (the road's rows of all columns at once were a 0.4 GB copy; each
        # column's sum is the same), the segments' sums too
        groups = sm.groupby("segment_id")
        return cls(light=pd.Series({c: sm[c].sum() for c in h_cols}, dtype=float),
                   road=pd.Series({c: sm.loc[street, c].sum() for c in h_cols}, dtype=float),
                   passes=int(sm["n_passes"].sum()),
                   per_segment=pd.DataFrame({c: groups[c].sum() for c in (
                       "seconds", "pv_kwh", "h_direct", "h_diffuse", "h_total_unshaded")}),
                   flags=flags)


def shape_routes(trips: pd.DataFrame) -> pd.DataFrame:
    """Per shape, every route that drives it: ``route_short_name`` and ``route_id`` (the
    routes' names and ids, sorted, joined by ", ": a shape shared by several routes carries
    them all) and ``direction_id`` (null when its trips run in both directions)."""
    def joined(v):
        return ", ".join(sorted({str(x) for x in v.dropna()}))

    g = trips.groupby("shape_id", sort=True)
    out = pd.DataFrame({"route_short_name": g["route_short_name"].agg(joined).astype("string"),
                        "route_id": g["route_id"].agg(joined).astype("string")})
    direction = g["direction_id"].agg(lambda v: v.iloc[0] if v.nunique(dropna=False) == 1 else pd.NA)
    out["direction_id"] = direction.astype("Int32")
    return out.reset_index()


def _as_values(frame: pd.DataFrame) -> pd.DataFrame:
    """*frame* with its categorical columns as the values they stand for (their categories'
    own dtype: the trips' names are held as categories through the reduce, their tables'
    keys written as the strings they are)."""
    cats = {c: frame[c].cat.categories.dtype for c in frame.columns
            if isinstance(frame[c].dtype, pd.CategoricalDtype)}
    return frame.astype(cats) if cats else frame


class TripShares:
    """Each trip's share of its block-day by its time among the block-day's trips (*at*: the
    trips' rows of the block-days, :meth:`BlockDayRows.of`, -1 for none; *seconds*: their
    time), found once for the routes and the ranking (not by joining or grouping by block
    and date strings: a network's 4.7 M trips took 0.3 GB for it, twice, at the reduce's
    peak).  ``share``: row by row with the trips, NaN for a trip of no block-day."""

    def __init__(self, at: np.ndarray, seconds):
        self.at = np.asarray(at, np.int64)
        seconds = np.asarray(seconds, float)
        self.share = seconds / pd.Series(seconds).groupby(self.at).transform("sum").to_numpy()
        self.share[self.at < 0] = np.nan

    def of(self, bd: pd.DataFrame, columns: list, index=None) -> pd.DataFrame:
        """The trips' shares of their block-days' *columns* (*bd*'s, the rows *at* is of),
        and the share itself (``share``), indexed by *index* (the trips')."""
        at, has = np.maximum(self.at, 0), self.at >= 0
        out = pd.DataFrame({c: np.where(has, bd[c].to_numpy(float)[at], np.nan) * self.share
                            for c in columns}, index=index)
        out["share"] = self.share
        return out


def _route_month(trip: pd.DataFrame, bd: pd.DataFrame, shares: TripShares) -> pd.DataFrame:
    """Per route, direction and month: trips, time, kWh, consumption, coverage, shading loss,
    and the block-days' PV at layovers, parked, curtailed and taken by the batteries, shared
    among the routes by their trips' time in each block-day."""
    shared = shares.of(bd, ["pv_kwh_layover", "pv_kwh_parked", "pv_kwh_curtailed", "pv_kwh_usable"],
                       trip.index).drop(columns="share")
    trip = pd.concat([trip.drop(columns=[c for c in shared.columns if c in trip]), shared], axis=1)
    trip = trip.assign(pv_kwh_driving=trip["pv_kwh"])
    kwh_cols = [c for c in trip.columns if c.startswith("pv_kwh")] + ["seconds"]
    key = ["route_id", "route_short_name", "direction_id", "month"]
    rm = (trip.groupby(key, sort=True, dropna=False, observed=True)
          .agg(trips=("trip_id", "size"), **{c: (c, "sum") for c in kwh_cols + ["consumption_kwh"]})
          .reset_index())
    # the route's long name and the direction's most frequent headsign
    names = (trip.groupby(key[:3], sort=True, dropna=False, observed=True)
             .agg(route_long_name=("route_long_name", "first"),
                  trip_headsign=("trip_headsign", lambda v: v.mode().iloc[0] if v.notna().any() else pd.NA))
             .reset_index())
    rm = _as_values(rm.merge(names, on=key[:3], how="left"))
    rm.insert(2, "route_long_name", rm.pop("route_long_name").astype("string"))
    rm.insert(4, "trip_headsign", rm.pop("trip_headsign").astype("string"))
    rm["coverage"] = rm["pv_kwh"] / rm["consumption_kwh"]
    rm["shading_loss"] = shading_loss(rm["pv_kwh_direct"], rm["pv_kwh_diffuse"], rm["pv_kwh_unshaded"])
    return rm


def _ranking(cfg: Config, bd: pd.DataFrame, trip: pd.DataFrame, shares: TripShares,
             annualise: float) -> pd.DataFrame:
    """Which buses to equip first: the blocks (a bus's daily duty) and the routes ranked by
    the grid energy PV avoids per installed kWp and year, with the simple payback of one
    bus's system on it.  A block's year is its block-days in the run (scaled to a year); a
    route gets each block-day's avoided energy in proportion to its trips' time in that
    block-day, per bus on the route (its share of the block-days, per service day).

    Returns
    -------
    DataFrame, one row per block and per route: ``kind`` (block | route), ``id``, ``name``,
    ``block_days`` (or bus-days on the route), ``grid_kwh_avoided_per_year`` (per bus),
    ``kwh_avoided_per_kwp_year``, ``pv_kwh_usable_per_year`` (per bus), ``payback_years``,
    ``rank`` (1: the most avoided per kWp, within its kind).
    """
    pv = cfg.pv_system()
    cost = cfg.economics.cost_eur_per_wp * 1000.0 * pv.kwp
    tariff = cfg.economics.tariff_eur_per_kwh
    days = max(bd["service_date"].nunique(), 1)
    period_days = days                         # the service days of the run's months
    blk = bd.groupby("block_id").agg(block_days=("service_date", "size"),
                                     grid=("grid_kwh_avoided", "sum"), usable=("pv_kwh_usable", "sum"))
    # per bus on the block: its year is its block-days scaled to a year
    blocks = pd.DataFrame({"kind": "block", "id": blk.index.astype(str), "name": blk.index.astype(str),
                           "block_days": blk["block_days"].to_numpy(),
                           "grid_kwh_avoided_per_year": blk["grid"].to_numpy() * annualise,
                           "pv_kwh_usable_per_year": blk["usable"].to_numpy() * annualise})
    per = shares.of(bd, ["grid_kwh_avoided", "pv_kwh_usable"], trip.index)
    t = trip[["route_id", "route_short_name"]].assign(grid=per["grid_kwh_avoided"], usable=per["pv_kwh_usable"],
                                                      bus_days=per["share"])
    rt = t.groupby("route_id", observed=True).agg(name=("route_short_name", "first"),
                                                  bus_days=("bus_days", "sum"), grid=("grid", "sum"),
                                                  usable=("usable", "sum"))
    buses = rt["bus_days"] / period_days       # buses the route keeps busy, on average
    routes = pd.DataFrame({"kind": "route", "id": rt.index.astype(str), "name": rt["name"].astype(str).to_numpy(),
                           "block_days": rt["bus_days"].to_numpy(),
                           "grid_kwh_avoided_per_year": (rt["grid"] / buses).to_numpy() * annualise,
                           "pv_kwh_usable_per_year": (rt["usable"] / buses).to_numpy() * annualise})
    out = pd.concat([blocks, routes], ignore_index=True)
    out["kwh_avoided_per_kwp_year"] = out["grid_kwh_avoided_per_year"] / pv.kwp
    saving = out["grid_kwh_avoided_per_year"] * tariff
    out["payback_years"] = np.where(saving > 0, cost / saving.where(saving > 0, 1.0), np.inf)
    out["rank"] = (out.groupby("kind")["kwh_avoided_per_kwp_year"].rank(ascending=False, method="first")
                   .astype(np.int64))
    return out.sort_values(["kind", "rank"], ignore_index=True)


def _hourly_pattern(hourly: pd.DataFrame) -> pd.DataFrame:
    """The daily pattern by month and local hour: irradiation sums and the mean irradiance
    ``g_*`` (W/m2) while buses are on the road at that hour."""
    h_cols = [c for c in hourly.columns if c.startswith("h_")]
    hp = hourly.groupby(["month", "hour"], sort=True)[h_cols + ["seconds"]].sum().reset_index()
    for c in h_cols:
        hp["g_" + c[2:]] = hp[c] * 3600.0 / hp["seconds"].where(hp["seconds"] > 0)
    return hp


def _harvest(cfg: Config, bd: pd.DataFrame, idle: pd.DataFrame, kwp_fleet: float, annualise: float) -> dict:
    """The summary's PV by when it is harvested (driving, layover, parked: each null when
    ``fleet.harvest`` does not count it), what the batteries take and curtail, and the yields
    of each accounting (the headline: ``kwh_per_kwp_usable``, what the batteries take)."""
    harvest = cfg.fleet.harvest
    parts = {"driving": float(bd["pv_kwh_driving"].sum()), "layover": float(bd["pv_kwh_layover"].sum()),
             "parked": float(bd["pv_kwh_parked"].sum() + idle["pv_kwh"].sum())}
    in_service = parts["driving"] + parts["layover"]
    whole_day = sum(parts.values())
    counts_layover, counts_parked = harvest != "driving", harvest == "whole_day"
    usable = float(bd["pv_kwh_usable"].sum())
    harvested = whole_day if counts_parked else in_service if counts_layover else parts["driving"]
    return {
        "harvest": harvest, "depot_shading": cfg.fleet.depot_shading,
        "pv_kwh_driving": parts["driving"],
        "pv_kwh_layover": parts["layover"] if counts_layover else None,
        "pv_kwh_parked": parts["parked"] if counts_parked else None,
        "pv_kwh_in_service": in_service if counts_layover else None,
        "pv_kwh_whole_day": whole_day if counts_parked else None,
        "pv_kwh_harvested": harvested,
        "pv_kwh_usable": usable,
        "pv_kwh_curtailed": float(bd["pv_kwh_curtailed"].sum() + idle["pv_kwh_curtailed"].sum()),
        "kwh_per_kwp_usable": usable * annualise / kwp_fleet,
        "kwh_per_kwp_harvested": harvested * annualise / kwp_fleet,
        "kwh_per_kwp_driving": parts["driving"] * annualise / kwp_fleet,
        # the yields of the time the run evaluated (null: not computed under fleet.harvest)
        "kwh_per_kwp_in_service": in_service * annualise / kwp_fleet if counts_layover else None,
        "kwh_per_kwp_whole_day": whole_day * annualise / kwp_fleet if counts_parked else None,
        "idle_bus_days": int(idle["buses"].sum()),
        "layover_hours": float(bd["seconds_layover"].sum() / 3600.0),
        "parked_hours": float((bd["seconds_parked"].sum() + idle["seconds"].sum()) / 3600.0),
        "layover_aux_kwh": float(bd["layover_aux_kwh"].sum()),
    }


#: block-days named in the summary (and the console line, the report) when infeasible
_NAMED_BLOCKS = 5


def _economics(cfg: Config, bd: pd.DataFrame, n_buses: int, annualise: float) -> dict:
    """The fleet's demand, coverage, the battery's balance under the charging plan (infeasible
    block-days, grid energy avoided at the depot and the terminals), avoided charging cycles
    (the balance's, and the paper's formula beside it) and payback, over a year."""
    from ..models import economics

    pv, vehicle, window = cfg.pv_system(), cfg.vehicle_params(), cfg.economics.soc_window
    usable_year = float(bd["pv_kwh_usable"].sum()) * annualise
    driving_year = float(bd["pv_kwh_driving"].sum()) * annualise
    demand_year = float(bd["demand_kwh"].sum()) * annualise
    driving_demand_year = float(bd["consumption_kwh"].sum()) * annualise
    # grid energy over the run's months (like the pv_kwh figures); cycles and payback per year
    avoided_depot = float((bd["grid_kwh_depot_without_pv"] - bd["grid_kwh_depot"]).sum())
    avoided_opp = float((bd["grid_kwh_opportunity_without_pv"] - bd["grid_kwh_opportunity"]).sum())
    plan = cfg.charging
    # battery energy the chargers need not put in, per year: the balance's avoided cycles
    battery_avoided = (avoided_depot * plan.depot.efficiency
                       + avoided_opp * plan.opportunity.efficiency) * annualise
    cycle = float(economics.cycle_energy_kwh(vehicle.battery_kwh, window))
    bad = bd[~bd["feasible"].to_numpy(bool)]
    named = [f"{b} on {pd.Timestamp(d):%Y-%m-%d}" + (f" at {pd.Timestamp(t).tz_convert('UTC'):%H:%M} UTC"
                                                     if pd.notna(t) else " (depot charge short)")
             for b, d, t in bad[["block_id", "service_date", "infeasible_at_utc"]]
             .head(_NAMED_BLOCKS).itertuples(index=False)]
    tariff, cost = cfg.economics.tariff_eur_per_kwh, cfg.economics.cost_eur_per_wp
    return {
        "fleet_demand_in_service_mwh": demand_year / 1000.0,
        "fleet_demand_driving_mwh": driving_demand_year / 1000.0,
        "coverage": float(economics.coverage(usable_year, demand_year)),
        "coverage_driving": float(economics.coverage(driving_year, driving_demand_year)),
        "block_days": int(len(bd)),
        "block_days_infeasible": int(len(bad)),
        "block_days_infeasible_without_pv": int((~bd["feasible_without_pv"].to_numpy(bool)).sum()),
        "infeasible_block_days_first": named,
        "soc_lowest_pv": float(bd["soc_lowest_pv"].min()) if len(bd) else None,
        "grid_kwh_without_pv": float((bd["grid_kwh_depot_without_pv"]
                                      + bd["grid_kwh_opportunity_without_pv"]).sum()),
        "grid_kwh_avoided": avoided_depot + avoided_opp,
        "grid_kwh_avoided_depot": avoided_depot,
        "grid_kwh_avoided_opportunity": avoided_opp,
        "avoided_charging_cycles_fleet": battery_avoided / cycle,
        "avoided_charging_cycles_per_bus": battery_avoided / cycle / n_buses,
        "avoided_charging_cycles_per_bus_paper": float(
            economics.avoided_cycles(usable_year / n_buses, vehicle.battery_kwh, window)),
        "system_cost_eur_per_bus": float(economics.system_cost_eur(pv.kwp, cost)),
        "payback_years": float(economics.simple_payback_years(
            pv.kwp, (avoided_depot + avoided_opp) * annualise / n_buses, cost, tariff)),
        "payback_years_paper": float(economics.simple_payback_years(
            pv.kwp, usable_year / n_buses, cost, tariff)),
    }


def _monthly(cfg: Config, trip: pd.DataFrame, bd: pd.DataFrame, idle: pd.DataFrame, n_buses: int) -> pd.DataFrame:
    """The fleet per month: trips, kWh, consumption, shading loss, the harvest split, avoided
    charging cycles and yields."""
    from ..models import economics

    pv, vehicle = cfg.pv_system(), cfg.vehicle_params()
    months = trip.groupby("month", sort=True, observed=True)
    monthly = _as_values(months.agg(
        trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"), pv_kwh_clear=("pv_kwh_clear", "sum"),
        pv_kwh_unshaded=("pv_kwh_unshaded", "sum"), pv_kwh_clear_unshaded=("pv_kwh_clear_unshaded", "sum"),
        pv_kwh_direct=("pv_kwh_direct", "sum"), pv_kwh_diffuse=("pv_kwh_diffuse", "sum"),
        pv_kwh_reflected=("pv_kwh_reflected", "sum"), consumption_kwh=("consumption_kwh", "sum")
    ).reset_index())
    monthly["shading_loss"] = shading_loss(monthly["pv_kwh_direct"], monthly["pv_kwh_diffuse"],
                                           monthly["pv_kwh_unshaded"])
    bd = bd.assign(infeasible=~bd["feasible"].to_numpy(bool),
                   grid_kwh_avoided_depot=bd["grid_kwh_depot_without_pv"] - bd["grid_kwh_depot"],
                   grid_kwh_avoided_opportunity=(bd["grid_kwh_opportunity_without_pv"]
                                                 - bd["grid_kwh_opportunity"]))
    split = bd.groupby("month", sort=True).agg(
        pv_kwh_driving=("pv_kwh_driving", "sum"), pv_kwh_layover=("pv_kwh_layover", "sum"),
        pv_kwh_parked=("pv_kwh_parked", "sum"), pv_kwh_usable=("pv_kwh_usable", "sum"),
        pv_kwh_curtailed=("pv_kwh_curtailed", "sum"), layover_aux_kwh=("layover_aux_kwh", "sum"),
        demand_kwh=("demand_kwh", "sum"), grid_kwh_avoided=("grid_kwh_avoided", "sum"),
        grid_kwh_avoided_depot=("grid_kwh_avoided_depot", "sum"),
        grid_kwh_avoided_opportunity=("grid_kwh_avoided_opportunity", "sum"),
        block_days=("feasible", "size"), block_days_infeasible=("infeasible", "sum"))
    idle_month = idle.groupby("month")[["pv_kwh", "pv_kwh_curtailed"]].sum()
    split["pv_kwh_parked"] += idle_month["pv_kwh"].reindex(split.index, fill_value=0.0)
    split["pv_kwh_curtailed"] += idle_month["pv_kwh_curtailed"].reindex(split.index, fill_value=0.0)
    split["pv_kwh_whole_day"] = split[["pv_kwh_driving", "pv_kwh_layover", "pv_kwh_parked"]].sum(axis=1)
    monthly = monthly.merge(split.reset_index(), on="month", how="left")
    plan = cfg.charging
    cycle = economics.cycle_energy_kwh(vehicle.battery_kwh, cfg.economics.soc_window)
    monthly["avoided_charging_cycles"] = (monthly["grid_kwh_avoided_depot"] * plan.depot.efficiency
                                          + monthly["grid_kwh_avoided_opportunity"]
                                          * plan.opportunity.efficiency) / cycle
    monthly["coverage"] = monthly["pv_kwh_usable"] / monthly["demand_kwh"]
    monthly["kwh_per_kwp_usable"] = monthly["pv_kwh_usable"] / (pv.kwp * n_buses)
    monthly["kwh_per_kwp_driving"] = monthly["pv_kwh"] / (pv.kwp * n_buses)
    monthly["kwh_per_kwp_driving_clearsky"] = monthly["pv_kwh_clear"] / (pv.kwp * n_buses)
    return monthly


def _segment_flags(segments: pd.DataFrame) -> pd.DataFrame:
    """Per segment id: ``length_m``, ``in_city_model``, ``in_building`` and ``ground_source``
    (segments ingested before these existed: in the model, on the road)."""
    out = pd.DataFrame({"length_m": segments["length_m"].to_numpy(float)},
                       index=segments["segment_id"].to_numpy())
    for col, default in (("in_city_model", True), ("in_building", False)):
        out[col] = segments[col].to_numpy(bool) if col in segments else default
    out["ground_source"] = (segments["ground_source"].astype(str).to_numpy()
                            if "ground_source" in segments else "unknown")
    return out


def _study_area(sums: pd.DataFrame, flags: pd.DataFrame, kwh_per_kwp_driving: float) -> dict:
    """What of the run lies in the city model: route-km, driving time and PV inside it, the
    driving yield of the whole lines and of the part inside (a bus driving only the
    modelled streets: the yield scaled by the PV per second inside over the PV per second
    of the whole), the shading loss inside, the segments inside building footprints and
    where the segments' ground heights come from.  *sums*: per segment id, its ``seconds,
    pv_kwh, h_direct, h_diffuse, h_total_unshaded`` (:class:`_SegmentSums`)."""
    f = flags.reindex(sums.index)
    inside, street = f["in_city_model"].to_numpy(bool), ~f["in_building"].to_numpy(bool)
    seg = flags[flags.index.isin(sums.index)]
    km = float(seg["length_m"].sum()) / 1000.0
    km_in = float(seg.loc[seg["in_city_model"], "length_m"].sum()) / 1000.0
    pv, t = sums["pv_kwh"].to_numpy(), sums["seconds"].to_numpy()

    def ratio(a, b):
        return float(a / b) if b > 0 else None

    rate_all = ratio(pv.sum(), t.sum())

    def yield_of(sel):
        rate = ratio(pv[sel].sum(), t[sel].sum())
        return None if rate is None or not rate_all else kwh_per_kwp_driving * rate / rate_all

    def loss(sel):
        h = sums[sel]
        return (float(shading_loss(h["h_direct"].sum(), h["h_diffuse"].sum(), h["h_total_unshaded"].sum()))
                if h["h_total_unshaded"].sum() > 0 else None)

    in_bld = ~street
    return {
        "route_km": km,
        "route_km_in_city_model": km_in,
        "route_km_in_city_model_share": ratio(km_in, km),
        "driving_time_in_city_model_share": ratio(t[inside].sum(), t.sum()),
        "pv_kwh_driving_in_city_model_share": ratio(pv[inside].sum(), pv.sum()),
        "kwh_per_kwp_driving_in_city_model": yield_of(inside),
        "kwh_per_kwp_driving_outside_city_model": yield_of(~inside),
        "shading_loss_allsky_in_city_model": loss(inside & street),
        "shading_loss_allsky_outside_city_model": loss(~inside & street),
        "segments_in_buildings": int(seg["in_building"].sum()),
        "route_km_in_buildings_share": ratio(float(seg.loc[seg["in_building"], "length_m"].sum()) / 1000.0, km),
        "driving_time_in_buildings_share": ratio(t[in_bld].sum(), t.sum()),
        "ground_sources": {k: int(v) for k, v in seg["ground_source"].value_counts().sort_index().items()},
    }


def _tree_figures(cfg: Config, tot: pd.Series) -> dict:
    """The trees' part of the shading loss on the road (all-sky): the loss with the
    buildings alone (the ``_no_trees`` light) and what the crowns add to it, and how many
    trees the city model holds (the city ingest's count; 0 with ``irradiance.trees.enabled``
    false; None when the ingest's report cannot be read: unknown, not 0)."""
    import json

    report = DataDir(cfg.data_dir).city.report
    try:
        kept = int(json.loads(report.read_text()).get("trees", {}).get("kept", 0))
    except (OSError, ValueError, AttributeError, TypeError):
        kept = None
    without = float(shading_loss(tot["h_direct_no_trees"], tot["h_diffuse_no_trees"],
                                 tot["h_total_unshaded"]))
    with_trees = float(shading_loss(tot["h_direct"], tot["h_diffuse"], tot["h_total_unshaded"]))
    return {"trees_in_city_model": kept if cfg.irradiance.trees.enabled else 0,
            "shading_loss_allsky_without_trees": without,
            "tree_shading_loss_allsky": with_trees - without}


def _fleet_year(cfg: Config, year: int, run_dir: Path, trip, bd, idle, sums: _SegmentSums,
                segments, n_buses: int) -> tuple[pd.DataFrame, dict]:
    """The fleet per month and the fleet-year summary (checked: :func:`_check_totals`)."""
    from . import annual

    data_dir = Path(cfg.data_dir)
    pv = cfg.pv_system()
    # a run over some months states annual figures scaled by 12 / months (flagged in the summary)
    annualise = 12.0 / len(cfg.run.months)
    hours_per_bus = annual.service_hours_per_bus(float(trip["seconds"].sum()), n_buses, annualise)
    tot_all, tot = sums.light, sums.road
    summary = {
        "scenario": cfg.scenario, "year": year, "months": cfg.run.months, "pv_mode": cfg.pv.mode,
        "diffuse_model": cfg.irradiance.diffuse_model,
        "air_temperature_c": cfg.monthly_temperature_c(),
        "air_temperature_source": cfg.temperature_source(),
        "routes": int(trip["route_id"].nunique()), "trips": int(len(trip)), "buses": n_buses,
        "segments": int(len(segments)), "passes": sums.passes,
        "kwp_per_bus": pv.kwp,
        "pv_kwh_driving_clearsky": float(trip["pv_kwh_clear"].sum()),
        "pv_kwh_driving_unshaded": float(trip["pv_kwh_unshaded"].sum()),
        "annualised_from_months": annualise != 1.0,
        "kwh_per_kwp_driving_clearsky": float(trip["pv_kwh_clear"].sum() * annualise / (pv.kwp * n_buses)),
        "irradiation_kwh_m2": {k[2:]: float(v) / 1000.0 for k, v in tot_all.items()},
        "shading_loss_allsky": float(shading_loss(tot["h_direct"], tot["h_diffuse"], tot["h_total_unshaded"])),
        **_tree_figures(cfg, tot),
        "shading_loss_clearsky": float(shading_loss(tot["h_direct_clear"], tot["h_diffuse_clear"],
                                                    tot["h_total_clear_unshaded"])),
        "reflection_gain_allsky": float(tot["h_reflected"] / tot["h_total_unshaded"]),
        "net_building_effect_allsky": float(tot["h_total"] / tot["h_total_unshaded"] - 1),
        "unshaded_to_ghi_allsky": float(tot["h_total_unshaded"] / tot["h_ghi"]),
        "unshaded_to_ghi_clearsky": float(tot["h_total_clear_unshaded"] / tot["h_ghi_clear"]),
        "reflected_share": float(tot["h_reflected"] / tot["h_total"]),
        **_harvest(cfg, bd, idle, pv.kwp * n_buses, annualise),
        **_economics(cfg, bd, n_buses, annualise),
        **annual.per_bus_figures(tot_all, n_buses, annualise, hours_per_bus, data_dir, year),
    }
    summary.update(_study_area(sums.per_segment, sums.flags, summary["kwh_per_kwp_driving"]))
    summary.update(_radiation_gaps(data_dir, year, cfg.run.months))
    _check_totals(summary, run_dir)
    return _monthly(cfg, trip, bd, idle, n_buses), summary
