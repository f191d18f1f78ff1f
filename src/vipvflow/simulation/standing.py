"""A bus standing still: layovers at terminals and parking at the depot.

A standing roof is a fixed point, so it goes through the same irradiance kernel as a road
segment: its geometry factors (sky view factor, reflector groups) once per point with
:func:`vipvflow.models.view_factors.segment_geometry` (a flat roof: no gradient), then
:func:`vipvflow.models.irradiance.evaluate_passes` at the middle of every minute the point's
intervals cover, and of no other (the radiation table's own grid: CAMS minute means at minute
centres).  The minute values are summed into a running total per point, and an interval
``[t0, t1)`` takes the difference of that total at its ends, interpolated within a minute:
the exact integral of the minute-constant irradiance, whatever the interval's length, so
splitting a span into intervals never changes its sum.

``depot_shading``: ``city`` points are evaluated in their tile's city model, ``open`` points
in an empty scene (no shade, no reflection: the roof of a bus in an open field, so the
all-sky ``total`` is ``DNI cos(zenith) + DHI``), ``covered`` points receive nothing.
"""
from __future__ import annotations

import time
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import IrradianceCfg
from ..store import ALL_MONTHS, DataDir, RunDir, write_parquet

#: energy (kWh) columns of an interval and the irradiance component each integrates
PV_SOURCE = {"pv_kwh": "total", "pv_kwh_clear": "total_clear", "pv_kwh_unshaded": "total_unshaded",
             "pv_kwh_clear_unshaded": "total_clear_unshaded", "pv_kwh_direct": "direct",
             "pv_kwh_diffuse": "diffuse", "pv_kwh_reflected": "reflected"}
H_COMPONENTS = ("direct", "diffuse", "reflected", "total", "total_unshaded", "direct_clear",
                "diffuse_clear", "reflected_clear", "total_clear", "total_clear_unshaded", "ghi",
                "ghi_clear")
_MINUTE = 60.0


def timeline_dir(run_dir) -> Path:
    return RunDir(run_dir).timeline


def open_scene():
    """A scene without any surface: an open field."""
    from ..models.shading import Scene, box_mesh

    return Scene(box_mesh([]))


def point_geometry(scene, points: pd.DataFrame, cfg: IrradianceCfg, **street) -> pd.DataFrame:
    """Geometry factors of standing roof points (``point_id, x, y, z``, m): a flat roof;
    *street*: :func:`vipvflow.simulation.partition.street_options`."""
    from ..models.view_factors import segment_geometry

    seg = pd.DataFrame({"segment_id": points["point_id"].to_numpy(np.int64),
                        "x": points["x"].to_numpy(float), "y": points["y"].to_numpy(float),
                        "z": points["z"].to_numpy(float), "heading_deg": 0.0, "gradient": 0.0})
    return segment_geometry(scene, seg, cfg, **street)


def interval_integrals(intervals: pd.DataFrame, geometry: pd.DataFrame, radiation, scene,
                       cfg: IrradianceCfg, energy_kwh, ground_albedo: float = 0.20,
                       dark: bool = False, packed: dict | None = None) -> pd.DataFrame:
    """Irradiation and PV energy of standing intervals.

    Parameters
    ----------
    intervals : DataFrame with ``point_id`` and ``t0_utc, t1_utc`` (Unix s)
    geometry : :func:`point_geometry` of the points (``segment_id`` = ``point_id``)
    radiation : vipvflow.models.sun_sky.RadiationTable
    scene : vipvflow.models.shading.Scene
    cfg : IrradianceCfg
    energy_kwh : callable ``(poa_wm2, dt_s) -> kWh`` per minute (the run's PV model, still)
    ground_albedo : float
    dark : bool, a covered depot: no light at all
    packed : dict, optional, ``pack_geometry(geometry, cfg, ground_albedo, scene)`` when the
        caller keeps it: the points' packing and sun masks are then made once, not per point

    Returns
    -------
    DataFrame indexed like *intervals*: ``seconds``, :data:`PV_SOURCE` columns (kWh) and
    ``h_<component>`` (Wh/m2) for :data:`H_COMPONENTS`.
    """
    from ..models.irradiance import evaluate_passes

    n = len(intervals)
    out = {"seconds": (intervals["t1_utc"] - intervals["t0_utc"]).to_numpy(float)}
    for c in PV_SOURCE:
        out[c] = np.zeros(n)
    for c in H_COMPONENTS:
        out[f"h_{c}"] = np.zeros(n)
    if dark or not n:
        return pd.DataFrame(out, index=intervals.index)
    pid = intervals["point_id"].to_numpy(np.int64)
    t0 = intervals["t0_utc"].to_numpy(float)
    t1 = intervals["t1_utc"].to_numpy(float)
    names = list(PV_SOURCE) + [f"h_{c}" for c in H_COMPONENTS]
    for p in np.unique(pid):
        sel = np.flatnonzero(pid == p)
        lo = np.floor(t0[sel].min() / _MINUTE) * _MINUTE
        # the minutes the point's intervals cover, and only those, through the kernel
        first = np.floor((t0[sel] - lo) / _MINUTE).astype(np.int64)
        end = np.ceil((t1[sel] - lo) / _MINUTE).astype(np.int64)
        span = int(end.max()) + 1
        depth = np.cumsum(np.bincount(first, minlength=span) - np.bincount(end, minlength=span))
        minute = np.flatnonzero(depth[:-1] > 0)
        if not len(minute):         # every interval of the point is empty, at a minute's edge
            continue
        minutes = pd.DataFrame({"segment_id": np.full(len(minute), p, np.int64),
                                "t_utc": lo + minute * _MINUTE,
                                "dt_s": np.full(len(minute), _MINUTE, np.float32)})
        irr = evaluate_passes(minutes, None, geometry, radiation, scene, cfg,
                              ground_albedo=ground_albedo, time_at="mid", packed=packed)
        dt = minutes["dt_s"].to_numpy(np.float64)
        per_minute = np.empty((len(names), len(dt) + 1))      # running totals from 0
        per_minute[:, 0] = 0.0
        for j, comp in enumerate(PV_SOURCE.values()):
            per_minute[j, 1:] = energy_kwh(irr[comp].to_numpy(np.float64), dt)
        for j, c in enumerate(H_COMPONENTS, start=len(PV_SOURCE)):
            per_minute[j, 1:] = irr[c].to_numpy(np.float64) * dt / 3600.0
        total = np.cumsum(per_minute, axis=1)

        def at(t):
            # the running totals at times t: those of the covered minutes before t's minute,
            # and t's share of its own (linear within a minute); t lies in a covered
            # minute or at the end of one
            f = np.maximum((t - lo) / _MINUTE, 0.0)
            i = np.floor(f).astype(np.int64)
            k = np.searchsorted(minute, i)
            kk = np.minimum(k, len(minute) - 1)
            own = (k < len(minute)) & (minute[kk] == i)
            return total[:, k] + np.where(own, f - i, 0.0) * (total[:, kk + 1] - total[:, kk])

        sums = at(t1[sel]) - at(t0[sel])
        for j, name in enumerate(names):
            out[name][sel] = sums[j]
    return pd.DataFrame(out, index=intervals.index)



def run_standing(ctx, tile: str) -> dict:
    """Evaluate the layover and parked intervals at the points of *tile* (``open`` and
    ``covered``: the depot outside the city model) of the run's block-days; writes
    ``parts/standing/tile=T/month=all.parquet``, one row per interval (``seconds`` and the
    sums are per bus times ``buses``: more than 1 only for the idle buses of a day)."""
    from ..models.view_factors import pack_geometry
    from .partition import _radiation, _scene, pv_energy_kwh, street_options, tune_malloc

    tune_malloc()
    t_start = time.perf_counter()
    run = RunDir(ctx.run_dir)
    points = pd.read_parquet(run.timeline_table("points"))
    points = points[points["tile"] == tile]
    iv = harvested_intervals(run, points=points["point_id"].to_numpy(np.int64))
    cfg = IrradianceCfg(**ctx.irradiance)
    dark = tile == "covered" or not len(iv)
    timings = {"standing_load_s": time.perf_counter() - t_start}
    packed = None
    if not dark:
        t = time.perf_counter()
        scene = open_scene() if tile == "open" else _scene(ctx, tile)
        _radiation(ctx.data_dir, ctx.year)
        timings["standing_scene_s"] = time.perf_counter() - t
        t = time.perf_counter()
        geom = point_geometry(scene, points, cfg, **street_options(ctx))
        # packed once for all the points and months (with the points' sun masks among the
        # buildings, kept in it): evaluate_passes would otherwise pack them all for each point
        packed = pack_geometry(geom, cfg, ctx.ground_albedo, scene)
        timings["standing_geometry_s"] = time.perf_counter() - t
    t_eval = time.perf_counter()
    # each month's sums into its rows of one array (iv is numbered from 0), not a frame per
    # month joined and re-indexed: a copy less of the largest tile's 0.9 M intervals each
    res = interval_integrals(iv.iloc[:0], None, None, None, cfg, None, dark=True)
    values = np.zeros((len(iv), res.shape[1]))
    for month, group in iv.groupby("month", sort=True):
        m = int(month[5:7])

        def energy(poa, dt, m=m):        # the run's PV model, standing still (no cooling by speed)
            return pv_energy_kwh(poa, dt, np.zeros(len(poa)), m, ctx)

        if dark:
            part = interval_integrals(group, None, None, None, cfg, energy, dark=True)
        else:
            part = interval_integrals(group, geom, _radiation(ctx.data_dir, ctx.year), scene, cfg,
                                      energy, ground_albedo=ctx.ground_albedo, packed=packed)
        values[group.index.to_numpy()] = part[res.columns].to_numpy(np.float64)
        del part, group
    timings["standing_eval_s"] = time.perf_counter() - t_eval
    # idle rows stand for several buses: their sums are per bus times the buses
    values *= iv["buses"].to_numpy(np.float64)[:, None]
    res = pd.DataFrame(values, index=iv.index, columns=res.columns, copy=False)
    table = pd.concat([iv[["block_id", "service_date", "kind", "after_trip", "point_id", "t0_utc",
                           "t1_utc", "buses"]].astype({"block_id": str, "kind": str}), res], axis=1)
    table["tile"] = tile
    write_parquet(table, RunDir(ctx.run_dir).part("standing", tile, ALL_MONTHS))
    elapsed = time.perf_counter() - t_start
    # standing_s in all; its parts: reading the timeline, the tile's scene and radiation table
    # (cached per worker), the points' geometry factors, the minutes through the kernel
    return {"tile": tile, "month": ALL_MONTHS, "passes": 0, "trips": 0, "kwh": float(res["pv_kwh"].sum()),
            "kwh_by_route": {}, "timings": {"standing_s": elapsed, **timings}, "intervals": int(len(iv)),
            "elapsed_s": elapsed}


def depot_point(cfg, data_dir) -> tuple | None:
    """The configured depot (``fleet.depot``, WGS84) as ``(x, y, z, tile)`` in the run's CRS:
    the roof height above the road nearest to it; ``None`` when no depot is configured.
    With ``depot_shading: city`` a depot where the city model has no building within its
    buffer stands in the open (:func:`vipvflow.models.shading.get_scene`)."""
    import json

    from pyproj import Transformer

    from ..inputs.tiles import tile_names

    depot = cfg.fleet.depot
    if depot is None:
        return None
    data = DataDir(data_dir)
    feed = json.loads(data.gtfs.feed_json.read_text())
    x, y = Transformer.from_crs("EPSG:4326", feed["crs"], always_xy=True).transform(depot.lon, depot.lat)
    seg = pd.read_parquet(data.gtfs.segments, columns=["x", "y", "z"])
    near = int(np.argmin(np.hypot(seg["x"].to_numpy() - x, seg["y"].to_numpy() - y)))
    tile = str(tile_names([x], [y], data.tile_size_m())[0])
    return float(x), float(y), float(seg["z"].to_numpy()[near]), tile


#: trip-days (trips in the feed x days of the run's months) from which the timeline is cut
#: in a process of its own: its tables (~0.7 GB per million trip-days at their peak) then
#: leave the command's memory with it, instead of staying with the command for the run
#: (a 200-line network year: 3.4 GB at the peak, 1.5 GB kept after the tables were freed)
TIMELINE_PROCESS_TRIP_DAYS = 300_000


def write_timeline(cfg, year: int, run_dir, routes=None) -> list[tuple[str, str]]:
    """Cut the run's block-days into driving, layover and parked time
    (:func:`vipvflow.inputs.gtfs.schedule.block_timeline`), keep the kinds ``fleet.harvest``
    counts, write ``parts/timeline/{block_days,intervals,points,trip_runs}.parquet`` once per
    run and return the tiles that have standing intervals (one ``standing`` task each).

    A large timeline (:data:`TIMELINE_PROCESS_TRIP_DAYS`) is written by a child process
    (spawned: the caller's threads stay out of it), its error raised here as it is."""
    run = RunDir(run_dir)
    if not run.timeline_table("points").exists():
        if _trip_days(cfg) >= TIMELINE_PROCESS_TRIP_DAYS:
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor

            with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn")) as pool:
                pool.submit(_write_timeline_tables, cfg, year, str(run_dir), routes).result()
        else:
            _write_timeline_tables(cfg, year, run_dir, routes)
    iv = harvested_intervals(run, columns=["point_id"])
    tiles = pd.read_parquet(run.timeline_table("points")).set_index("point_id")["tile"]
    return sorted(set(tiles.reindex(iv["point_id"].unique()).astype(str)))


def _trip_days(cfg) -> int:
    """Trips in the ingested feed times the days of the run's months (an upper bound of the
    trip-days, from the Parquet footer alone)."""
    import pyarrow.parquet as pq

    path = DataDir(cfg.data_dir).gtfs.trips
    try:
        trips = pq.ParquetFile(path).metadata.num_rows
    except OSError:
        return 0
    return int(trips * 31 * len(cfg.run.months))


def _write_timeline_tables(cfg, year: int, run_dir, routes=None) -> None:
    """:func:`write_timeline`'s tables (in whichever process calls it)."""
    from ..inputs.gtfs.schedule import block_timeline

    run = RunDir(run_dir)
    tl = block_timeline(cfg.data_dir, year, months=cfg.run.months, routes=routes,
                        depot=depot_point(cfg, cfg.data_dir), depot_shading=cfg.fleet.depot_shading)
    iv = tl["intervals"]
    # every interval, for the battery's balance (layover times, auxiliaries, chargers);
    # the roof's light only of those fleet.harvest counts
    harvest = {"whole_day": ("layover", "parked"), "in_service": ("layover",),
               "driving": ()}[cfg.fleet.harvest]
    iv = iv.assign(harvested=iv["kind"].astype(str).isin(harvest))
    write_parquet(tl["block_days"].reset_index(drop=True), run.timeline_table("block_days"))
    write_parquet(iv.astype({"kind": str}).reset_index(drop=True), run.timeline_table("intervals"))
    write_parquet(tl["trip_runs"], run.timeline_table("trip_runs"))
    write_parquet(tl["points"].astype({"stop_id": str, "tile": str, "shading": str}),
                  run.timeline_table("points"))


def harvested_intervals(run: RunDir, columns=None, points=None) -> pd.DataFrame:
    """The timeline's intervals whose light ``fleet.harvest`` counts (a timeline written
    before the ``harvested`` column: all of its intervals).  *points*: only the intervals
    at these ``point_id``, read a batch at a time and renumbered from 0 (a standing task
    held the whole network's 4.9 M intervals to keep its tile's)."""
    import pyarrow.parquet as pq

    path = run.timeline_table("intervals")
    has = "harvested" in pq.read_schema(path).names
    cols = None if columns is None else list(columns) + (["harvested"] if has else [])
    if points is not None:
        return _intervals_at(path, cols, has, np.asarray(points, np.int64))
    iv = pd.read_parquet(path, columns=cols)
    if has:
        iv = iv[iv.pop("harvested").to_numpy(bool)]
    return iv


#: rows of the timeline's intervals read at a time for one tile's points
INTERVAL_BATCH = 1 << 18


def _intervals_at(path, cols, has: bool, points: np.ndarray) -> pd.DataFrame:
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq

    with pq.ParquetFile(path) as pf:
        schema = pf.schema_arrow
        names = schema.names if cols is None else [c for c in schema.names if c in cols]
        wanted = pa.array(points, pa.int64())
        kept = []
        for batch in pf.iter_batches(batch_size=INTERVAL_BATCH, columns=list(dict.fromkeys(
                [*names, "point_id"])), use_threads=False):
            mask = pc.is_in(batch.column("point_id").cast(pa.int64()), value_set=wanted)
            if has:
                mask = pc.and_(mask, pc.fill_null(batch.column("harvested"), False))
            kept.append(batch.filter(mask).select(names))
        table = pa.Table.from_batches(kept, schema=pa.schema([schema.field(c) for c in names],
                                                             metadata=schema.metadata))
    iv = table.to_pandas().reset_index(drop=True)
    if has:
        iv = iv.drop(columns="harvested")
    return iv


def standing_done(run_dir, tile: str) -> bool:
    return RunDir(run_dir).part("standing", tile, ALL_MONTHS).exists()
