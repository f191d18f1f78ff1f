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

import geopandas as gpd
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from ..config import Config
from ..errors import InputError
from ..models.irradiance import shading_loss
from ..store import HOURLY_METADATA, DataDir, RunDir, write_json, write_parquet

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


def _read_parts(run_dir: Path, kind: str) -> pd.DataFrame:
    """Every partition file of *kind*, in path order, as one DataFrame."""
    table = _part_table(run_dir, kind)
    return pd.DataFrame() if table is None else table.to_pandas()


# --- the partial sums, computed where the partitions are (Dask tasks on the run's workers)

#: trip partition files summed by one task: bounds a task's memory (a network-year month has
#: hundreds of tiles), and with two levels (files -> month -> run) the client sums a table
#: about as long as its output
TRIP_FILES_PER_TASK = 64


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
    every time).  A Dask task of the reduce; ``None`` when no part has a row."""
    if parts and isinstance(parts[0], (str, Path)):
        table = _read_files(parts)
    else:
        tables = [t for t in parts if t is not None and t.num_rows]
        table = pa.concat_tables(tables, promote_options="permissive") if tables else None
    if table is None or not table.num_rows:
        return None
    # float32 partition columns summed in float64
    table = table.cast(pa.schema([f.with_type(pa.float64()) if pa.types.is_floating(f.type) else f
                                  for f in table.schema]))
    cols = [c for c in table.column_names if c.startswith("pv_kwh")] + ["seconds"]
    keys = ["trip_id", "service_date"]
    summed = table.group_by(keys, use_threads=False).aggregate([(c, "sum") for c in cols])
    summed = summed.select(keys + [f"{c}_sum" for c in cols]).rename_columns(keys + cols)
    return summed.sort_by([(k, "ascending") for k in keys])


def segment_month_part(files: list, month: str) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The segment partitions of one month as one table, each row with its ``tile`` and
    ``month`` (named by the file's path; older runs stored them as columns), and the
    month's sums per local hour (:func:`hourly_sums`).  A Dask task of the reduce."""
    files = [Path(f) for f in files]
    if not files:
        return pd.DataFrame(), hourly_sums([], month)
    tables = [_read_file(f) for f in files]
    hourly = hourly_sums([_hourly_of(t, f) for t, f in zip(tables, files)], month)
    try:                                    # one conversion to pandas for the month
        table = pa.concat_tables(tables)
    except pa.ArrowInvalid:                 # schemas differ (an older run's files)
        table = None
    if table is None or "tile" in table.column_names or "month" in table.column_names:
        frames = [_with_tile_month(t.to_pandas(), _tile_of(f), month) for t, f in zip(tables, files)]
        frames = [d for d in frames if len(d)] or frames[:1]
        return pd.concat(frames, ignore_index=True), hourly
    df = table.to_pandas()
    df["tile"] = np.repeat(np.array([_tile_of(f) for f in files], dtype=object),
                           [t.num_rows for t in tables])
    df["month"] = month
    return df, hourly


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


def _join_months(tables: list) -> pa.Table | None:
    """The months' trip sums as one table (a trip past midnight at a month's end is in two)."""
    return sum_trips(tables) if len(tables) > 1 else (tables[0] if tables else None)


def partial_sums(run_dir: Path, client=None) -> dict:
    """The partitions read and summed on the cluster of *client* (in this process without
    one): ``trip`` (Arrow: per trip and service date, sorted), ``segment_month`` (per segment
    and month, with tile and month), ``hourly`` (per month and local hour) and ``geometry``
    (the segments' public geometry factors).

    Each month's files are read by tasks of their own (trips in a tree of partial sums), so
    the reduce's reading grows with the partitions per worker; the client only joins the
    months' tables."""
    client = client or _InProcess()
    run_dir = Path(run_dir)
    trip = _trip_tree(run_dir, client)
    sm = [client.submit(segment_month_part, [str(f) for f in files], m, pure=False)
          for m, files in _month_files(run_dir, "segment_month").items()]
    geometry = client.submit(geometry_factors, [str(f) for f in RunDir(run_dir).part_files(
        "geometry", "tile=*.parquet")], pure=False)
    trip, sm, geometry = client.gather([trip, sm, geometry])
    return {"trip": _join_months(trip),
            "segment_month": pd.concat([s for s, _ in sm], ignore_index=True) if sm else pd.DataFrame(),
            "hourly": (pd.concat([h for _, h in sm], ignore_index=True) if sm
                       else hourly_sums([], "")[:0]),
            "geometry": geometry}


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

    def results(self) -> dict:
        out = {}
        for part in (f.result() for f in self.futures):
            out.update(part)
        return out


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
    for key, why in (("pv_kwh_allsky", "no PV energy"),
                     ("fleet_demand_mwh", "no consumption")):
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
    layovers' auxiliaries, and the PV the battery takes (``pv_kwh_usable``) or not
    (``pv_kwh_curtailed``) under ``fleet.harvest``; the idle buses' parked days; and
    *trip* (the reduce's per-trip table: ``pv_kwh``, ``consumption_kwh``) with the
    timeline's ``block_id`` (the GTFS block, or the inferred one).  The
    layovers' auxiliaries draw the vehicle's base load and HVAC at the month's mean
    temperature through the battery's discharge efficiency.  Balance: the bus leaves the
    depot at ``soc_max``; PV offsets each trip and layover, a surplus charges up to
    ``soc_max`` (the rest is curtailed); PV parked at the depot replaces depot charging up to
    what the block-day used (:func:`vipvflow.models.vehicle.block_day_balance`).  An idle bus's
    battery is full: its PV is all curtailed.  With ``harvest: driving`` (the paper's
    accounting) all the driving PV counts and nothing is curtailed.
    """
    from ..inputs.gtfs.schedule import IDLE_BLOCK
    from ..models.vehicle import block_day_balance

    run = RunDir(run_dir)
    tl = pd.read_parquet(run.timeline_table("block_days"))
    key = ["block_id", "service_date"]
    if len(placed) != len(trip):
        raise ValueError("the trips' blocks are not row by row with the trips")
    trip = trip.assign(block_id=placed["block_id"].to_numpy())
    position = placed["position"].to_numpy(np.int64)
    st = _read_parts(run_dir, "standing")
    if st.empty:
        st = pd.DataFrame({c: pd.Series(dtype=t) for c, t in (
            ("block_id", object), ("service_date", "datetime64[ns]"), ("kind", object),
            ("after_trip", np.int64), ("buses", np.int64), ("seconds", float), ("pv_kwh", float),
            ("pv_kwh_clear", float))})
    idle = st[st["block_id"] == IDLE_BLOCK].copy()
    st = st[st["block_id"] != IDLE_BLOCK]
    idle["month"] = pd.to_datetime(idle["service_date"]).dt.strftime("%Y-%m")
    idle["pv_kwh_curtailed"] = idle["pv_kwh"] if cfg.fleet.harvest != "driving" else 0.0

    bd = tl[key + ["month", "trips", "window_start_utc", "window_end_utc", "first_departure_utc",
                   "last_arrival_utc", "driving_s", "layover_s", "parked_s", "overlap_s"]
            ].sort_values(key).reset_index(drop=True)
    idx = pd.MultiIndex.from_frame(bd[key])
    first = trip.groupby(key)["start_s"].min()
    drive = trip.groupby(key)[["pv_kwh", "pv_kwh_clear", "consumption_kwh"]].sum()
    for c in ("pv_kwh", "pv_kwh_clear", "consumption_kwh"):
        bd[c] = drive[c].reindex(idx, fill_value=0.0).to_numpy()
    bd["first_departure_s"] = first.reindex(idx).to_numpy()
    bd["pv_kwh_driving"] = bd["pv_kwh"]
    bd["seconds_driving"] = bd.pop("driving_s")
    for kind in ("layover", "parked"):
        # the time from the timeline (whatever fleet.harvest evaluates), the PV from the
        # standing partitions (0 where not evaluated)
        part = st[st["kind"] == kind].groupby(key)[["pv_kwh", "pv_kwh_clear"]].sum()
        part = part.reindex(idx, fill_value=0.0)
        bd[f"pv_kwh_{kind}"] = part["pv_kwh"].to_numpy()
        bd[f"pv_kwh_clear_{kind}"] = part["pv_kwh_clear"].to_numpy()
        bd[f"seconds_{kind}"] = bd.pop(f"{kind}_s")
    bd["pv_kwh_whole_day"] = bd["pv_kwh_driving"] + bd["pv_kwh_layover"] + bd["pv_kwh_parked"]
    bd["window_s"] = bd["window_end_utc"] - bd["window_start_utc"]

    # the layovers' auxiliaries (kWh from the battery) at the month's temperature
    temps = np.asarray(cfg.monthly_temperature_c(), float)

    def aux_kwh(service_date, seconds):
        month_no = pd.to_datetime(service_date).dt.month.to_numpy()
        return (np.asarray(vehicle.aux_kw(temps[month_no - 1]), float) * np.asarray(seconds, float)
                / 3600.0 / vehicle.discharge_efficiency)

    lay = st[st["kind"] == "layover"]
    lay = lay.assign(aux_kwh=aux_kwh(lay["service_date"], lay["seconds"]))
    bd["layover_aux_kwh"] = aux_kwh(bd["service_date"], bd["seconds_layover"])
    in_service = cfg.fleet.harvest != "driving"
    bd["demand_kwh"] = bd["consumption_kwh"] + (bd["layover_aux_kwh"] if in_service else 0.0)

    # the battery's share: steps (a trip and the layover after it) per block-day
    if cfg.fleet.harvest == "driving":
        bd["pv_kwh_curtailed"] = 0.0
        bd["pv_kwh_usable"] = bd["pv_kwh_driving"]
        bd["soc_end_pv"] = np.nan
        return bd, idle, trip
    row = pd.Series(np.arange(len(bd)), index=idx)
    n_steps = int(bd["trips"].max()) if len(bd) else 0
    pv_steps = np.zeros((len(bd), max(n_steps, 1)))
    use_steps = np.zeros_like(pv_steps)
    t_row = row.reindex(pd.MultiIndex.from_frame(trip[key])).to_numpy()
    t_pos = position
    np.add.at(pv_steps, (t_row, t_pos), trip["pv_kwh"].to_numpy(float))
    np.add.at(use_steps, (t_row, t_pos), trip["consumption_kwh"].to_numpy(float))
    l_row = row.reindex(pd.MultiIndex.from_frame(lay[key])).to_numpy()
    l_pos = lay["after_trip"].to_numpy(np.int64)
    np.add.at(pv_steps, (l_row, l_pos), lay["pv_kwh"].to_numpy(float))
    np.add.at(use_steps, (l_row, l_pos), lay["aux_kwh"].to_numpy(float))
    bal = block_day_balance(pv_steps, use_steps, bd["pv_kwh_parked"].to_numpy(), vehicle)
    bd["pv_kwh_curtailed"] = bal["curtailed_in_service_kwh"] + bal["curtailed_parked_kwh"]
    bd["pv_kwh_usable"] = bd["pv_kwh_whole_day"] - bd["pv_kwh_curtailed"]
    bd["soc_end_pv"] = bal["soc_end"]
    return bd, idle, trip


def reduce_run(cfg: Config, year: int, run_dir: Path, say=print, client=None, cluster_done=None,
               timings: dict | None = None, consumption: Consumption | None = None) -> dict:
    """Write trip_energy, segments, segment_month, route_month, block_day, monthly, hourly
    outputs, ``summary.json`` and ``report.html``; return the summary.

    The partitions are read and summed by tasks on the cluster of *client* (its workers see
    *run_dir* at the same path), or in this process without one (:func:`partial_sums`);
    the joins, the vehicles' balance and the outputs are computed here, while the workers
    draw the report's figures.  *cluster_done* is called once the cluster's part is done
    (the run shuts its cluster down then, while this process writes the report).  The
    seconds of each step are added to *timings* (``reduce_<step>_s``).  *consumption*: the
    trip patterns' consumption already submitted to the cluster (:func:`consumption_tasks`)."""
    from ..outputs import report

    clock = _Clock(timings)
    parts = partial_sums(run_dir, client)
    clock("sums")
    # the figures are drawn on the cluster's workers as their data is made (here without one):
    # the hourly chart at once, while the segments are joined here
    figures = report.Figures(client)
    hp = _hourly_pattern(parts["hourly"])
    report.add_hourly(figures, hp)
    trips_meta = pd.read_parquet(DataDir(cfg.data_dir).gtfs.trips)
    totals = _trip_totals(run_dir, parts["trip"])
    placed = _placed_trips(run_dir, totals)
    n_buses = int(placed.groupby("service_date")["block_id"].nunique().max())
    # the segments first: the workers draw the maps while the trips are joined here
    _, segments, sm = _segment_outputs(cfg, run_dir, parts["segment_month"], parts["geometry"],
                                       totals, n_buses, trips_meta)
    report.add_maps(figures, run_dir, cfg)
    clock("segments")
    trip, bd, idle = _trip_outputs(cfg, year, run_dir, totals, placed, trips_meta, say, consumption)
    clock("trips")
    rm = _route_month(trip)
    report.add_routes(figures, rm)
    write_parquet(rm, RunDir(run_dir).output("route_month.parquet"))
    write_parquet(bd, RunDir(run_dir).output("block_day.parquet"))
    write_parquet(hp, RunDir(run_dir).output("hourly_pattern.parquet"))
    monthly, summary = _fleet_year(cfg, year, run_dir, trip, bd, idle, sm, segments, n_buses)
    write_parquet(monthly, RunDir(run_dir).output("monthly.parquet"))
    write_json(summary, RunDir(run_dir).output("summary.json"))
    report.add_charts(figures, summary, monthly)
    clock("fleet")
    drawn = figures.results()
    clock("figures")
    if cluster_done is not None:
        cluster_done()
    report.write_report(run_dir, summary, drawn, cfg=cfg, segments=segments)
    clock("report")
    return summary


class _Clock:
    """``clock(step)`` adds the seconds since the last call to ``timings["reduce_<step>_s"]``."""

    def __init__(self, timings: dict | None):
        self._timings = timings if timings is not None else {}
        self._last = time.perf_counter()

    def __call__(self, step: str) -> None:
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
    placed = totals[["trip_id", "service_date"]].merge(runs, on=["trip_id", "service_date"],
                                                      how="left", validate="one_to_one")
    return placed[["service_date", "block_id", "position"]]


def _trip_outputs(cfg: Config, year: int, run_dir: Path, totals: pd.DataFrame, placed: pd.DataFrame,
                  trips_meta: pd.DataFrame, say, consumption: Consumption | None = None):
    """Per trip and service date (PV of *totals*, :func:`_trip_totals`; the trip's metadata,
    the vehicle model's consumption; the timeline's block of each, *placed*, row by row with
    *totals*: the joins here keep their rows' order) and per block-day (driving, layovers,
    parked; the battery's share); writes ``trip_energy.parquet``.  Returns the trips, the
    block-days and the idle buses' days."""
    trip = totals.merge(trips_meta[["trip_id", "route_id", "route_short_name", "direction_id",
                                  "shape_id", "service_id", "block_id", "pattern_id", "start_s"]],
                      on="trip_id", how="left", validate="many_to_one")
    trip["month"] = pd.to_datetime(trip["service_date"]).dt.strftime("%Y-%m")
    cons = trip_consumption(cfg, Path(cfg.data_dir), year, trip["pattern_id"].unique(),
                            vecto_dir=RunDir(run_dir).vecto, say=say, made=consumption)
    trip = trip.merge(cons, on=["pattern_id", "month"], how="left", validate="many_to_one")
    trip["coverage"] = trip["pv_kwh"] / trip["consumption_kwh"]
    # vehicle block per day: driving, layovers, parked; the battery's share (sets the
    # trips' block_id to the timeline's: the GTFS block or the inferred one)
    bd, idle, trip = block_day_table(cfg, run_dir, trip, cfg.vehicle_params(), placed)
    write_parquet(trip, RunDir(run_dir).output("trip_energy.parquet"))
    return trip, bd, idle


def _segment_outputs(cfg: Config, run_dir: Path, sm: pd.DataFrame, geo: pd.DataFrame | None,
                     totals: pd.DataFrame, n_buses: int, trips_meta: pd.DataFrame):
    """Per segment and month (GeoParquet for maps) and per segment over the run (geometry
    factors and year) of the shapes of the trips in *totals* (:func:`_trip_totals`) run by
    *n_buses*; writes ``segment_month.parquet`` and ``segments.parquet``.  Returns both and
    the segment-month sums."""
    from . import annual

    data_dir = Path(cfg.data_dir)
    segments = gpd.read_parquet(DataDir(data_dir).gtfs.segments)
    shapes = trips_meta.loc[trips_meta["trip_id"].isin(totals["trip_id"].unique()), "shape_id"]
    segments = segments[segments["shape_id"].isin(shapes.unique())]
    # shading loss: sky and sun light the buildings take away (1 - (direct + diffuse) / unshaded);
    # the reflected light they add is reported apart as reflection gain
    sm["shading_loss"] = shading_loss(sm["h_direct"], sm["h_diffuse"], sm["h_total_unshaded"])
    sm["shading_loss_clear"] = shading_loss(sm["h_direct_clear"], sm["h_diffuse_clear"],
                                            sm["h_total_clear_unshaded"])
    sm["reflection_gain"] = sm["h_reflected"] / sm["h_total_unshaded"].where(sm["h_total_unshaded"] > 0)
    shape_route = (trips_meta.drop_duplicates("shape_id")[["shape_id", "route_short_name", "direction_id"]])
    smg = segments[["segment_id", "shape_id", "geometry"]].merge(sm, on="segment_id", how="inner")
    smg = gpd.GeoDataFrame(smg.merge(shape_route, on="shape_id", how="left"),
                           geometry="geometry", crs=segments.crs)
    write_parquet(smg, RunDir(run_dir).output("segment_month.parquet"))
    hours_per_bus = annual.service_hours_per_bus(float(totals["seconds"].sum()), n_buses,
                                                 12.0 / len(cfg.run.months))
    segments = annual.segment_year(segments.merge(shape_route, on="shape_id", how="left"), geo, sm,
                                   cfg.pv_system().kwp, hours_per_bus)
    write_parquet(segments, RunDir(run_dir).output("segments.parquet"))
    return smg, segments, sm


def _route_month(trip: pd.DataFrame) -> pd.DataFrame:
    """Per route, direction and month: trips, time, kWh, consumption, coverage, shading loss."""
    kwh_cols = [c for c in trip.columns if c.startswith("pv_kwh")] + ["seconds"]
    rm = (trip.groupby(["route_id", "route_short_name", "direction_id", "month"], sort=True)
          .agg(trips=("trip_id", "size"), **{c: (c, "sum") for c in kwh_cols + ["consumption_kwh"]})
          .reset_index())
    rm["coverage"] = rm["pv_kwh"] / rm["consumption_kwh"]
    rm["shading_loss"] = shading_loss(rm["pv_kwh_direct"], rm["pv_kwh_diffuse"], rm["pv_kwh_unshaded"])
    return rm


def _hourly_pattern(hourly: pd.DataFrame) -> pd.DataFrame:
    """The daily pattern by month and local hour: irradiation sums and the mean irradiance
    ``g_*`` (W/m2) while buses are on the road at that hour."""
    h_cols = [c for c in hourly.columns if c.startswith("h_")]
    hp = hourly.groupby(["month", "hour"], sort=True)[h_cols + ["seconds"]].sum().reset_index()
    for c in h_cols:
        hp["g_" + c[2:]] = hp[c] * 3600.0 / hp["seconds"].where(hp["seconds"] > 0)
    return hp


def _harvest(cfg: Config, bd: pd.DataFrame, idle: pd.DataFrame, kwp_fleet: float, annualise: float) -> dict:
    """The summary's split of the PV by when it is harvested (driving, layover, parked) and
    what the battery takes."""
    parts = {"driving": float(bd["pv_kwh_driving"].sum()), "layover": float(bd["pv_kwh_layover"].sum()),
             "parked": float(bd["pv_kwh_parked"].sum() + idle["pv_kwh"].sum())}
    return {
        "harvest": cfg.fleet.harvest, "depot_shading": cfg.fleet.depot_shading,
        **{f"pv_kwh_{k}": v for k, v in parts.items()},
        "pv_kwh_in_service": parts["driving"] + parts["layover"],
        "pv_kwh_whole_day": sum(parts.values()),
        "kwh_per_kwp_driving": parts["driving"] * annualise / kwp_fleet,
        # the yields of the time the run evaluated (null: not computed under fleet.harvest)
        "kwh_per_kwp_in_service": ((parts["driving"] + parts["layover"]) * annualise / kwp_fleet
                                   if cfg.fleet.harvest != "driving" else None),
        "kwh_per_kwp_whole_day": (sum(parts.values()) * annualise / kwp_fleet
                                  if cfg.fleet.harvest == "whole_day" else None),
        "pv_kwh_usable": float(bd["pv_kwh_usable"].sum()),
        "pv_kwh_curtailed": float(bd["pv_kwh_curtailed"].sum() + idle["pv_kwh_curtailed"].sum()),
        "idle_bus_days": int(idle["buses"].sum()),
        "layover_hours": float(bd["seconds_layover"].sum() / 3600.0),
        "parked_hours": float((bd["seconds_parked"].sum() + idle["seconds"].sum()) / 3600.0),
        "layover_aux_kwh": float(bd["layover_aux_kwh"].sum()),
    }


def _economics(cfg: Config, bd: pd.DataFrame, n_buses: int, annualise: float) -> dict:
    """The fleet's demand, coverage, avoided charging cycles and payback over a year."""
    from ..models import economics

    pv, vehicle, window = cfg.pv_system(), cfg.vehicle_params(), cfg.economics.soc_window
    pv_year = float(bd["pv_kwh_usable"].sum()) * annualise
    demand_year = float(bd["demand_kwh"].sum()) * annualise
    return {
        "fleet_demand_mwh": demand_year / 1000.0,
        "coverage": float(economics.coverage(pv_year, demand_year)),
        "avoided_charging_cycles_fleet": float(economics.avoided_cycles(pv_year, vehicle.battery_kwh, window)),
        "avoided_charging_cycles_per_bus": float(
            economics.avoided_cycles(pv_year / n_buses, vehicle.battery_kwh, window)),
        "system_cost_eur_per_bus": float(economics.system_cost_eur(pv.kwp, cfg.economics.cost_eur_per_wp)),
        "payback_years": float(economics.simple_payback_years(
            pv.kwp, pv_year / n_buses, cfg.economics.cost_eur_per_wp, cfg.economics.tariff_eur_per_kwh)),
    }


def _monthly(cfg: Config, trip: pd.DataFrame, bd: pd.DataFrame, idle: pd.DataFrame, n_buses: int) -> pd.DataFrame:
    """The fleet per month: trips, kWh, consumption, shading loss, the harvest split, avoided
    charging cycles and yields."""
    from ..models import economics

    pv, vehicle = cfg.pv_system(), cfg.vehicle_params()
    monthly = (trip.groupby("month", sort=True)
               .agg(trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"), pv_kwh_clear=("pv_kwh_clear", "sum"),
                    pv_kwh_unshaded=("pv_kwh_unshaded", "sum"),
                    pv_kwh_clear_unshaded=("pv_kwh_clear_unshaded", "sum"),
                    pv_kwh_direct=("pv_kwh_direct", "sum"), pv_kwh_diffuse=("pv_kwh_diffuse", "sum"),
                    pv_kwh_reflected=("pv_kwh_reflected", "sum"),
                    consumption_kwh=("consumption_kwh", "sum")).reset_index())
    monthly["shading_loss"] = shading_loss(monthly["pv_kwh_direct"], monthly["pv_kwh_diffuse"],
                                           monthly["pv_kwh_unshaded"])
    split = bd.groupby("month", sort=True)[
        ["pv_kwh_driving", "pv_kwh_layover", "pv_kwh_parked", "pv_kwh_usable", "pv_kwh_curtailed",
         "layover_aux_kwh"]].sum()
    idle_month = idle.groupby("month")[["pv_kwh", "pv_kwh_curtailed"]].sum()
    split["pv_kwh_parked"] += idle_month["pv_kwh"].reindex(split.index, fill_value=0.0)
    split["pv_kwh_curtailed"] += idle_month["pv_kwh_curtailed"].reindex(split.index, fill_value=0.0)
    split["pv_kwh_whole_day"] = split[["pv_kwh_driving", "pv_kwh_layover", "pv_kwh_parked"]].sum(axis=1)
    monthly = monthly.merge(split.reset_index(), on="month", how="left")
    monthly["avoided_charging_cycles"] = economics.avoided_cycles(
        monthly["pv_kwh_usable"].to_numpy(), vehicle.battery_kwh, cfg.economics.soc_window)
    monthly["kwh_per_kwp_allsky"] = monthly["pv_kwh"] / (pv.kwp * n_buses)
    monthly["kwh_per_kwp_clearsky"] = monthly["pv_kwh_clear"] / (pv.kwp * n_buses)
    return monthly


def _fleet_year(cfg: Config, year: int, run_dir: Path, trip, bd, idle, sm, segments,
                n_buses: int) -> tuple[pd.DataFrame, dict]:
    """The fleet per month and the fleet-year summary (checked: :func:`_check_totals`)."""
    from . import annual

    data_dir = Path(cfg.data_dir)
    pv = cfg.pv_system()
    # a run over some months states annual figures scaled by 12 / months (flagged in the summary)
    annualise = 12.0 / len(cfg.run.months)
    hours_per_bus = annual.service_hours_per_bus(float(trip["seconds"].sum()), n_buses, annualise)
    tot = sm[[c for c in sm.columns if c.startswith("h_")]].sum()
    summary = {
        "scenario": cfg.scenario, "year": year, "months": cfg.run.months, "pv_mode": cfg.pv.mode,
        "diffuse_model": cfg.irradiance.diffuse_model,
        "air_temperature_c": cfg.monthly_temperature_c(),
        "air_temperature_source": cfg.temperature_source(),
        "routes": int(trip["route_id"].nunique()), "trips": int(len(trip)), "buses": n_buses,
        "segments": int(len(segments)), "passes": int(sm["n_passes"].sum()),
        "kwp_per_bus": pv.kwp,
        "pv_kwh_allsky": float(trip["pv_kwh"].sum()),
        "pv_kwh_clearsky": float(trip["pv_kwh_clear"].sum()),
        "pv_kwh_allsky_unshaded": float(trip["pv_kwh_unshaded"].sum()),
        "annualised_from_months": annualise != 1.0,
        "kwh_per_kwp_allsky": float(trip["pv_kwh"].sum() * annualise / (pv.kwp * n_buses)),
        "kwh_per_kwp_clearsky": float(trip["pv_kwh_clear"].sum() * annualise / (pv.kwp * n_buses)),
        "irradiation_kwh_m2": {k[2:]: float(v) / 1000.0 for k, v in tot.items()},
        "shading_loss_allsky": float(shading_loss(tot["h_direct"], tot["h_diffuse"], tot["h_total_unshaded"])),
        "shading_loss_clearsky": float(shading_loss(tot["h_direct_clear"], tot["h_diffuse_clear"],
                                                    tot["h_total_clear_unshaded"])),
        "reflection_gain_allsky": float(tot["h_reflected"] / tot["h_total_unshaded"]),
        "net_building_effect_allsky": float(tot["h_total"] / tot["h_total_unshaded"] - 1),
        "unshaded_to_ghi_allsky": float(tot["h_total_unshaded"] / tot["h_ghi"]),
        "unshaded_to_ghi_clearsky": float(tot["h_total_clear_unshaded"] / tot["h_ghi_clear"]),
        "reflected_share": float(tot["h_reflected"] / tot["h_total"]),
        **_harvest(cfg, bd, idle, pv.kwp * n_buses, annualise),
        **_economics(cfg, bd, n_buses, annualise),
        **annual.per_bus_figures(tot, n_buses, annualise, hours_per_bus, data_dir, year),
    }
    summary.update(_radiation_gaps(data_dir, year, cfg.run.months))
    _check_totals(summary, run_dir)
    return _monthly(cfg, trip, bd, idle, n_buses), summary
