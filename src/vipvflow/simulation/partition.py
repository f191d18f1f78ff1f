"""Work done on a worker: per-tile geometry factors and per-(tile, month) irradiance and PV.

Each task loads what it needs from disk (tile mesh, segments, radiation), keeps the heavy
parts in per-process caches (the tile's Embree BVH, the radiation table), evaluates every
pass of its partition with the irradiance engine and writes its partition files atomically.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import IrradianceCfg, PVSystem
from .storage import geometry_path, partition_path, write_parquet

#: per-pass energy columns (kWh) and irradiation columns (Wh/m2) summed in a partition
PV_COMPONENTS = ("direct", "diffuse", "reflected")
VARIANTS = {
    "": "total", "_clear": "total_clear",
    "_unshaded": "total_unshaded", "_clear_unshaded": "total_clear_unshaded",
}
COMPONENTS = ["direct", "diffuse", "reflected", "total", "total_unshaded",
              "direct_clear", "diffuse_clear", "reflected_clear", "total_clear",
              "total_clear_unshaded", "ghi", "ghi_clear"]


@dataclass(frozen=True)
class RunContext:
    """What a task needs to know about the run (small and picklable)."""

    data_dir: str
    run_dir: str
    year: int
    irradiance: dict
    pv_system: dict
    pv_mode: str
    monthly_temperature_c: tuple
    wind_speed_mps: float
    timezone: str
    bvh_cache_size: int = 8
    ground_albedo: float = 0.2
    routes: tuple | None = None
    ray_threads: int | None = None
    shapes: tuple | None = None
    route_of_trip: dict = field(default_factory=dict, compare=False, hash=False)


@lru_cache(maxsize=4)
def _segments(data_dir: str) -> pd.DataFrame:
    cols = ["segment_id", "shape_id", "x", "y", "z", "x_end", "y_end", "z_end", "heading_deg",
            "gradient", "length_m", "tile"]
    seg = pd.read_parquet(Path(data_dir) / "gtfs" / "segments.parquet", columns=cols)
    return seg.set_index("segment_id", drop=False).sort_index()


@lru_cache(maxsize=2)
def _radiation(data_dir: str, year: int):
    from ..radiation import RadiationTable

    return RadiationTable.load(data_dir, year)


def _scene(ctx: RunContext, tile: str):
    from ..shading import get_scene

    return get_scene(ctx.data_dir, tile, cache_size=ctx.bvh_cache_size, n_threads=ctx.ray_threads)


def tile_geometry(ctx: RunContext, tile: str) -> pd.DataFrame:
    """Per-segment geometry factors of a tile (sky view factor, reflector groups), computed
    once per run and stored in ``parts/geometry/tile=<TILE>.parquet``, and the segments'
    horizon profiles (:func:`vipvflow.horizon.horizon_profile` from the roof ray origins)
    in ``parts/horizon/tile=<TILE>.parquet``, so a trip can be recomputed without rays."""
    from ..horizon import horizon_frame, horizon_path, horizon_profile
    from ..irradiance import segment_geometry

    path = geometry_path(Path(ctx.run_dir), tile)
    if path.exists():
        geom = pd.read_parquet(path)
    else:
        seg = _segments(ctx.data_dir)
        seg = seg[seg["tile"] == tile]
        if ctx.shapes is not None:
            seg = seg[seg["shape_id"].isin(ctx.shapes)]
        geom = segment_geometry(_scene(ctx, tile), seg, IrradianceCfg(**ctx.irradiance))
        write_parquet(geom, path)
    hpath = horizon_path(ctx.run_dir, tile)
    if not hpath.exists():
        origins = geom[["px", "py", "pz"]].to_numpy(np.float64)
        profile = horizon_profile(_scene(ctx, tile), origins,
                                  max_distance_m=IrradianceCfg(**ctx.irradiance).ray_length_m)
        write_parquet(horizon_frame(geom["segment_id"].to_numpy(), profile), hpath)
    return geom


def pv_energy_kwh(poa_wm2: np.ndarray, dt_s: np.ndarray, speed_mps: np.ndarray, month: int,
                  ctx: RunContext) -> np.ndarray:
    """PV energy per pass (kWh) in the run's PV mode."""
    from .. import pv

    system = PVSystem(**ctx.pv_system)
    if ctx.pv_mode == "paper":
        return pv.energy_paper(poa_wm2, dt_s, system.kwp, system.performance_ratio)
    temp = ctx.monthly_temperature_c[month - 1]
    return pv.energy_pvlib(poa_wm2, dt_s, system, temp_air_c=temp,
                           wind_speed_mps=ctx.wind_speed_mps + speed_mps)


def _local_hours(t_utc: np.ndarray, timezone: str) -> np.ndarray:
    """Local clock hour (0..23) of Unix times, converting each distinct UTC hour once."""
    if not len(t_utc):
        return np.zeros(0, np.int8)
    utc_hour = np.floor(t_utc / 3600.0).astype(np.int64)
    uniq, inverse = np.unique(utc_hour, return_inverse=True)
    start = pd.to_datetime(uniq * 3600, unit="s", utc=True).tz_convert(timezone)
    # UTC offset of each distinct UTC hour (daylight-saving changes fall on UTC hour starts)
    offset = np.asarray([o.total_seconds() for o in start.map(lambda t: t.utcoffset())])
    return (np.floor((t_utc + offset[inverse]) / 3600.0).astype(np.int64) % 24).astype(np.int8)


def aggregate_partition(passes: pd.DataFrame, irr: pd.DataFrame, month: int, ctx: RunContext):
    """Sum a partition's passes per trip and service date, per segment and per local hour.

    Vectorised with numpy (``reduceat`` over the passes, which come sorted by service date,
    trip and time; ``bincount`` per segment and hour), so the reduce costs a small part of
    the irradiance evaluation.
    """
    n = len(passes)
    dt = passes["dt_s"].to_numpy(np.float64)
    # irradiation (Wh/m2) received during each pass
    h = {f"h_{c}": irr[c].to_numpy(np.float64) * dt / 3600.0 for c in COMPONENTS}
    pv_cols = [f"pv_kwh{suffix}" for suffix in VARIANTS] + [f"pv_kwh_{c}" for c in PV_COMPONENTS]
    pv_source = {**{f"pv_kwh{suffix}": col for suffix, col in VARIANTS.items()},
                 **{f"pv_kwh_{c}": c for c in PV_COMPONENTS}}
    system = PVSystem(**ctx.pv_system)
    linear = ctx.pv_mode == "paper"
    if linear:
        # paper mode is linear in the irradiation: kWh = kWp x PR x H / 1000 (H in Wh/m2),
        # so the energy of any group of passes comes from its irradiation sum
        sums = {"seconds": dt, **{f"h_{c}": h[f"h_{c}"] for c in sorted(set(pv_source.values()))}}
    else:
        speed = passes["speed_mps"].to_numpy(np.float64)
        sums = {name: pv_energy_kwh(irr[col].to_numpy(np.float64), dt, speed, month, ctx)
                for name, col in pv_source.items()}
        sums["seconds"] = dt

    def energy(table: dict) -> dict:
        """PV kWh columns of a table of sums."""
        if linear:
            k = system.kwp * system.performance_ratio / 1000.0
            return {name: k * table[f"h_{col}"] for name, col in pv_source.items()}
        return {name: table[name] for name in pv_cols}

    # per trip and service date: runs of equal (date, trip) in the sorted passes
    trip_code = np.asarray(passes["trip_id"].cat.codes if hasattr(passes["trip_id"], "cat")
                           else pd.factorize(passes["trip_id"])[0], dtype=np.int64)
    day = passes["service_date"].to_numpy().astype("datetime64[D]").astype(np.int64)
    if n:
        change = np.flatnonzero((np.diff(trip_code) != 0) | (np.diff(day) != 0)) + 1
        starts = np.concatenate([[0], change])
    else:
        starts = np.zeros(0, np.int64)
    names = list(sums)
    block = np.column_stack([sums[k] for k in names]) if n else np.zeros((0, len(names)))
    total = np.add.reduceat(block, starts, axis=0) if n else block
    per_trip = {k: total[:, i] for i, k in enumerate(names)}
    trip = pd.DataFrame({**energy(per_trip), "seconds": per_trip["seconds"]})
    trip.insert(0, "service_date", passes["service_date"].to_numpy()[starts])
    trip.insert(0, "trip_id", np.asarray(passes["trip_id"].to_numpy()[starts]).astype(str))
    trip = trip.groupby(["trip_id", "service_date"], sort=True).sum().reset_index()

    # per segment
    seg_ids, seg_pos = np.unique(passes["segment_id"].to_numpy(np.int64), return_inverse=True)
    cols = {**sums, **h}
    per_seg = {name: np.bincount(seg_pos, weights=w, minlength=len(seg_ids)) for name, w in cols.items()}
    segm = pd.DataFrame({"segment_id": seg_ids,
                         "n_passes": np.bincount(seg_pos, minlength=len(seg_ids)).astype(np.int64),
                         **energy(per_seg), **{k: per_seg[k] for k in h}, "seconds": per_seg["seconds"]})

    # per local hour
    hour = _local_hours(passes["t_utc"].to_numpy(np.float64), ctx.timezone)
    hours = np.unique(hour)
    pos = np.searchsorted(hours, hour)
    hourly = pd.DataFrame({"hour": hours.astype(np.int8)})
    for name in list(h) + ["seconds"]:
        hourly[name] = np.bincount(pos, weights=cols[name], minlength=len(hours))
    return trip, segm, hourly


def run_partition(ctx: RunContext, tile: str, month: str, geometry: pd.DataFrame | None = None) -> dict:
    """Evaluate every pass of *tile* in *month* and write the partition's files.

    Writes ``parts/trip/tile=T/month=M.parquet`` (per trip and service date: PV kWh for
    all-sky, clear-sky and the unshaded references, and per component) and
    ``parts/segment_month/...`` (per segment: passes, irradiation sums in Wh/m2, kWh) and
    ``parts/hourly/...`` (per local hour: irradiation and pass time, for the daily pattern).
    Returns a small summary for the progress view.
    """
    from ..irradiance import evaluate_passes, stage_seconds
    from ..trajectory import iter_passes

    t0 = time.perf_counter()
    run_dir = Path(ctx.run_dir)
    if geometry is None:
        geometry = tile_geometry(ctx, tile)
    passes = iter_passes(ctx.data_dir, tile, month, ctx.year, routes=ctx.routes)
    timings = {"passes_s": time.perf_counter() - t0}
    n = len(passes)
    seg = _segments(ctx.data_dir)
    if n:
        t1 = time.perf_counter()
        before = dict(stage_seconds())
        irr = evaluate_passes(passes, seg, geometry, _radiation(ctx.data_dir, ctx.year),
                              _scene(ctx, tile), IrradianceCfg(**ctx.irradiance),
                              ground_albedo=ctx.ground_albedo)
        timings["irradiance_s"] = time.perf_counter() - t1
        # the irradiance time split by stage (lookup, ray setup, rays, components, pack)
        timings.update({f"irradiance_{k}": v - before[k] for k, v in stage_seconds().items()})
    else:
        irr = pd.DataFrame({c: np.zeros(0, np.float32) for c in COMPONENTS})
    t2 = time.perf_counter()
    trip, segm, hourly = aggregate_partition(passes, irr, int(month[5:7]), ctx)
    for df in (trip, segm, hourly):
        df["tile"] = tile
    segm["month"] = month
    hourly["month"] = month
    timings["reduce_s"] = time.perf_counter() - t2

    t3 = time.perf_counter()
    write_parquet(hourly, partition_path(run_dir, "hourly", tile, month))
    write_parquet(trip, partition_path(run_dir, "trip", tile, month))
    # segment_month last: its presence marks the partition complete
    write_parquet(segm, partition_path(run_dir, "segment_month", tile, month))
    timings["write_s"] = time.perf_counter() - t3

    by_route: dict[str, float] = {}
    if ctx.route_of_trip and len(trip):
        routes = trip["trip_id"].map(ctx.route_of_trip)
        by_route = trip.groupby(routes)["pv_kwh"].sum().to_dict()
    return {"tile": tile, "month": month, "passes": n, "trips": int(len(trip)),
            "kwh": float(trip["pv_kwh"].sum()) if len(trip) else 0.0,
            "kwh_by_route": by_route, "timings": timings,
            "elapsed_s": time.perf_counter() - t0}


def partition_done(run_dir: Path, tile: str, month: str) -> bool:
    return all(partition_path(run_dir, kind, tile, month).exists()
               for kind in ("hourly", "trip", "segment_month"))


def worker_bvh_builds() -> dict:
    """BVH builds per tile in this process (collected from every worker after a run)."""
    from .. import shading

    return {tile: n for (_, tile), n in shading.BVH_BUILDS.items()}
