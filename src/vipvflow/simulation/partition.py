"""Work done on a worker: per-tile geometry factors and per-(tile, month) irradiance and PV
(one task per tile: its geometry, then its months' partitions).

Each task loads what it needs from disk (tile mesh, segments, radiation), keeps the heavy
parts in per-process caches (the tile's Embree BVH, the radiation table), evaluates every
pass of its partition with the irradiance engine and writes its partition files atomically.
"""
from __future__ import annotations

import collections
import json
import time
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import IrradianceCfg, PVSystem
from ..store import HOURLY_METADATA, PARTITION_KINDS, DataDir, RunDir, write_parquet

#: per-pass energy columns (kWh) and irradiation columns (Wh/m2) summed in a partition
PV_COMPONENTS = ("direct", "diffuse", "reflected")
VARIANTS = {
    "": "total", "_clear": "total_clear",
    "_unshaded": "total_unshaded", "_clear_unshaded": "total_clear_unshaded",
}
COMPONENTS = ["direct", "diffuse", "reflected", "total", "total_unshaded",
              "direct_clear", "diffuse_clear", "reflected_clear", "total_clear",
              "total_clear_unshaded", "ghi", "ghi_clear", "direct_no_trees", "diffuse_no_trees"]


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
    road_albedo: float = 0.10
    roof_height_m: float = 3.2
    routes: tuple | None = None
    ray_threads: int | None = None
    shapes: tuple | None = None
    route_of_trip: dict = field(default_factory=dict, compare=False, hash=False)


@lru_cache(maxsize=4)
def _segments(data_dir: str) -> pd.DataFrame:
    """The segments' roof planes as the physics sees them: a segment inside a building
    footprint (``in_building``) is moved by ``light_dx_m, light_dy_m`` to the street point
    its light is taken from (docs/physics.md)."""
    cols = ["segment_id", "shape_id", "x", "y", "z", "x_end", "y_end", "z_end", "heading_deg",
            "gradient", "length_m", "tile"]
    path = DataDir(data_dir).gtfs.segments
    import pyarrow.parquet as pq

    names = set(pq.read_schema(path).names)
    shift = [c for c in ("light_dx_m", "light_dy_m") if c in names]
    seg = pd.read_parquet(path, columns=cols + shift)
    if len(shift) == 2:
        dx, dy = seg.pop("light_dx_m").to_numpy(), seg.pop("light_dy_m").to_numpy()
        for a, d in (("x", dx), ("x_end", dx), ("y", dy), ("y_end", dy)):
            seg[a] = seg[a].to_numpy() + d
    return seg.set_index("segment_id", drop=False).sort_index()


@lru_cache(maxsize=2)
def _radiation(data_dir: str, year: int):
    from ..models.sun_sky import RadiationTable

    table = RadiationTable.load(data_dir, year)
    hand_back_memory()          # the load's temporaries (Arrow's pool kept ~100 MB of them)
    return table


def arrow_on_the_heap() -> None:
    """Arrow's allocations of this process (Parquet reads and writes, tables, the string
    columns pandas gets from them) made from glibc's heap, pyarrow's ``system`` pool, from
    now on, instead of its default mimalloc pool; nothing when ``ARROW_DEFAULT_MEMORY_POOL``
    chooses a pool.  mimalloc kept what a read had freed in pages that
    ``release_unused`` did not give back: a worker held ~140 MB more after the line-year's
    map than before it (its caches dropped), and a process that runs one run after another
    grew ~20 MB a run.  On the heap, :func:`hand_back_memory` gives it back: the line-year's
    peak of its processes' RSS 1.39-1.42 GB instead of 1.53-1.55 (three fresh runs each),
    no slower.  Called by a run's own process, the forkserver its LocalCluster's workers are
    forked from, and each tile task (a worker of a cluster started elsewhere)."""
    import os

    import pyarrow as pa

    if "ARROW_DEFAULT_MEMORY_POOL" not in os.environ and pa.default_memory_pool().backend_name != "system":
        pa.set_memory_pool(pa.system_memory_pool())


def hand_back_memory() -> None:
    """Hand the memory this process has freed back to the operating system: Arrow's pool
    (mimalloc keeps what a Parquet read freed), glibc's heap, and the pages of the
    radiation tables mapped from their file (read again where needed).  A few ms; called
    after the radiation table's load and after each tile task, it keeps a worker's memory
    at what it holds."""
    import pyarrow as pa

    from ..models.sun_sky import release_mapped_pages

    pa.default_memory_pool().release_unused()
    release_mapped_pages()
    try:
        import ctypes

        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):      # not glibc
        pass


def handing_back(fn, *args):
    """``fn(*args)``, then this process's garbage collected and its freed memory handed back
    (:func:`hand_back_memory`): a reduce's task on a worker (a figure, ``city.glb``, the
    GeoParquet datasets), whose temporaries the worker's RSS otherwise kept while it drew
    the next figure beside the other worker's (the line-year's peak of its processes' RSS
    is in those figures)."""
    import gc

    try:
        return fn(*args)
    finally:
        gc.collect()
        hand_back_memory()


def _scene(ctx: RunContext, tile: str):
    from ..models.shading import get_scene

    return get_scene(ctx.data_dir, tile, cache_size=ctx.bvh_cache_size, n_threads=ctx.ray_threads)


_PACKED: "collections.OrderedDict[tuple, tuple]" = collections.OrderedDict()
_MALLOC_TUNED = False


def tune_malloc(mmap_threshold: int = 32 << 20, trim_threshold: int = 128 << 20) -> bool:
    """Let this process reuse freed heap memory for large numpy temporaries (glibc only).

    Dask's nannies start workers with ``MALLOC_TRIM_THRESHOLD_`` set, which also freezes
    glibc's mmap threshold at 128 kB: every large temporary array of a partition is then a
    fresh mapping whose pages fault in again, and the numpy work of a partition ran 2-3x
    slower in a worker than in a plain process (the demo's line-year partitions).  Raising
    the mmap threshold (``M_MMAP_THRESHOLD``) and the trim threshold (``M_TRIM_THRESHOLD``)
    with ``mallopt`` once per process restores plain-process speed on any cluster; freed
    memory above *trim_threshold* still goes back to the OS.  Returns whether it was applied.
    """
    global _MALLOC_TUNED
    if _MALLOC_TUNED:
        return True
    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6")
        ok = bool(libc.mallopt(-3, int(mmap_threshold))) and bool(libc.mallopt(-1, int(trim_threshold)))
    except (OSError, AttributeError):      # not glibc
        ok = False
    _MALLOC_TUNED = ok
    return ok


def _packed_geometry(ctx: RunContext, tile: str, geometry: pd.DataFrame, scene) -> dict:
    """The tile's geometry packed for the hot path, once per worker while the same geometry
    table and scene stay in memory (a bounded cache, like the scenes')."""
    from ..models.view_factors import pack_geometry

    key = (ctx.run_dir, tile)
    hit = _PACKED.get(key)
    if hit is not None and hit[0] is geometry and (
            hit[1] is scene or np.array_equal(hit[2].get("scene_origin"), getattr(scene, "origin", None))):
        # the same table; the same scene, or the tile's scene built again (its BVH dropped
        # from the cache meanwhile) in the same frame: the packing holds (a tile task keeps
        # only the packed geometry and the table's ids, _held_geometry)
        if hit[1] is not scene:
            _PACKED[key] = (geometry, scene, hit[2])
        _PACKED.move_to_end(key)
        return hit[2]
    geo = pack_geometry(geometry, IrradianceCfg(**ctx.irradiance), ctx.ground_albedo, scene)
    if "group_p_local" in geo:
        # the rays start from the scene's frame (float32): the world's float64 sample points
        # are not used here (~85 MB for a network's largest tile)
        del geo["group_p"]
    _PACKED[key] = (geometry, scene, geo)
    while len(_PACKED) > max(1, ctx.bvh_cache_size):
        _PACKED.popitem(last=False)
    return geo


def tile_geometry(ctx: RunContext, tile: str) -> pd.DataFrame:
    """Per-segment geometry factors of a tile (sky view factor, reflector groups), computed
    once per run and stored in ``parts/geometry/tile=<TILE>.parquet``, and the segments'
    horizon profiles (:func:`vipvflow.models.horizon.horizon_profile` from the roof ray origins)
    in ``parts/horizon/tile=<TILE>.parquet``, so a trip can be recomputed without rays.

    Both files are kept in the data dir's cache (:mod:`vipvflow.simulation.geometry_cache`)
    and taken from it by a later run of the same segments, city, settings and code; the
    table's ``attrs["from_cache"]`` says whether this one was."""
    from ..models.horizon import horizon_frame, horizon_profile
    from ..models.shading import modelled_tiles
    from ..models.view_factors import geometry_table, read_geometry, segment_geometry
    from . import geometry_cache

    path = RunDir(ctx.run_dir).tile_part("geometry", tile)
    hpath = RunDir(ctx.run_dir).tile_part("horizon", tile)
    key, cached = None, False
    if path.exists():                   # this run's own (resumed)
        geom = read_geometry(path)
    else:
        seg = _segments(ctx.data_dir)
        seg = seg[seg["tile"] == tile]
        if ctx.shapes is not None:
            seg = seg[seg["shape_id"].isin(ctx.shapes)]
        # an earlier run's geometry of the same segments, city and settings (the data dir's
        # cache, geometry_cache), else computed here and kept there
        key = geometry_cache.tile_key(ctx.data_dir, tile, seg, geometry_settings(ctx),
                                      tile in modelled_tiles(ctx.data_dir))
        cached = geometry_cache.fetch(ctx.data_dir, key, path, hpath)
        if cached:
            geom = read_geometry(path)
        else:
            geom = segment_geometry(_scene(ctx, tile), seg, IrradianceCfg(**ctx.irradiance),
                                    **street_options(ctx))
            write_parquet(geometry_table(geom), path)
    if not hpath.exists():
        profile = geom.attrs.get("horizon_profile")         # computed with the geometry (perez_svf)
        if profile is None or len(profile) != len(geom):
            origins = geom[["px", "py", "pz"]].to_numpy(np.float64)
            profile = horizon_profile(_scene(ctx, tile), origins,
                                      max_distance_m=IrradianceCfg(**ctx.irradiance).ray_length_m)
        write_parquet(horizon_frame(geom["segment_id"].to_numpy(), profile), hpath)
    if key is not None and not cached:
        geometry_cache.keep(ctx.data_dir, key, path, hpath)
    geom.attrs["from_cache"] = cached
    return geom


def geometry_settings(ctx: RunContext) -> dict:
    """The settings a tile's geometry depends on (besides its segments and city): the
    ``irradiance`` section and the street options (:func:`street_options`)."""
    return {"irradiance": ctx.irradiance, "street": street_options(ctx)}


def street_options(ctx: RunContext) -> dict:
    """How :func:`vipvflow.models.view_factors.segment_geometry` places the street where the
    city model has none: the road's albedo and the roof's height above it (None:
    ``irradiance.virtual_street`` off)."""
    on = IrradianceCfg(**ctx.irradiance).virtual_street
    return {"road_albedo": ctx.road_albedo, "roof_height_m": ctx.roof_height_m if on else None}


class TileGeometry:
    """A tile's geometry table as the result of its Dask task (:func:`geometry_task`), and
    the seconds it took.

    Dask measures every result it keeps; walking the thousand columns of a geometry table
    for that cost more than computing the table, so this wrapper gives its size from its
    shape (8 bytes a value)."""
    __slots__ = ("frame", "seconds", "from_cache")

    def __init__(self, frame: pd.DataFrame, seconds: float = 0.0, from_cache: bool = False):
        self.frame = frame
        self.seconds = seconds
        self.from_cache = from_cache

    def __sizeof__(self) -> int:
        return 64 + 8 * self.frame.shape[0] * self.frame.shape[1]


def geometry_task(ctx: RunContext, tile: str) -> TileGeometry:
    """:func:`tile_geometry` as a task of the run's graph (for a tile whose months are split
    over several tasks, :func:`vipvflow.simulation.tasks.tile_tasks`), with its seconds."""
    t = time.perf_counter()
    frame = tile_geometry(ctx, tile)
    return TileGeometry(frame, time.perf_counter() - t, bool(frame.attrs.get("from_cache")))


def tile_task(ctx: RunContext, tile: str, months: list[str],
              geometry: TileGeometry | None = None, counts_geometry: bool = True) -> list[dict]:
    """A tile's geometry (:func:`tile_geometry`, or the result of its :func:`geometry_task`),
    then its partitions of *months* (:func:`run_partition`, each written as it is done): one
    task of the run's graph.  The geometry's seconds go into the first partition's timings
    (``geometry_s``; with its packing for the fused kernel where the tile is one task, a
    split tile's tasks pack it in their first partition) and counts (``geometry_tiles``: 1;
    ``geometry_tiles_from_cache``: 1 where it came from the data dir's cache,
    :mod:`vipvflow.simulation.geometry_cache`), with *counts_geometry* (the first task of a
    tile split over several).

    One task per tile rather than per partition: the tile's BVH is built once and its
    geometry table never leaves the worker, and the scheduler (in the command's process on a
    LocalCluster) handles 12 times fewer tasks: the line-year's 492 partitions as 41 tasks
    took ~2 s of a core off the command's process."""
    arrow_on_the_heap()
    if geometry is not None:
        frame, geometry_s, from_cache = geometry.frame, geometry.seconds, geometry.from_cache
    else:
        t = time.perf_counter()
        frame = tile_geometry(ctx, tile)
        from_cache = bool(frame.attrs.get("from_cache"))
        frame = _held_geometry(ctx, tile, frame)
        geometry_s = time.perf_counter() - t
    done = []
    for month in months:
        done.append(run_partition(ctx, tile, month, frame))
        if counts_geometry and len(done) == 1:
            done[0]["timings"]["geometry_s"] = geometry_s
            done[0]["counts"]["geometry_tiles"] = 1
            done[0]["counts"]["geometry_tiles_from_cache"] = int(from_cache)
        # a month's passes freed, before the next (a few ms): what the worker holds between
        # them is what it keeps, ~0.25 GB less on a network's largest tile
        hand_back_memory()
    if geometry is None:
        # the packed geometry of a table made here: no other task can find it (the cache
        # holds it for the table it was made from), ~70 MB a tile of a network
        kept = _PACKED.get((ctx.run_dir, tile))
        if kept is not None and kept[0] is frame:
            del _PACKED[(ctx.run_dir, tile)]
    hand_back_memory()
    return done


def _held_geometry(ctx: RunContext, tile: str, frame: pd.DataFrame) -> pd.DataFrame:
    """What a tile task holds of the tile's geometry *frame* through its months.  With the
    fused kernel (``paper``) the partitions read the geometry packed (:func:`_packed_geometry`,
    made here) and of the table only the segments' ids and radiation locations: the table
    (~150 MB for a network's largest tile) is then let go, and the packed geometry is kept
    for the slim table returned.  Otherwise *frame* itself."""
    from ..models import passkernel

    if ctx.pv_mode != "paper" or not len(frame):
        return frame
    hand_back_memory()          # the table's read (its Arrow copy) before the packing
    scene = _scene(ctx, tile)
    geo = _packed_geometry(ctx, tile, frame, scene)
    if not passkernel.usable(geo, scene):
        return frame
    slim = frame[[c for c in ("segment_id", "rad_location") if c in frame.columns]].copy()
    _PACKED[(ctx.run_dir, tile)] = (slim, scene, geo)
    return slim


def pv_energy_kwh(poa_wm2: np.ndarray, dt_s: np.ndarray, speed_mps: np.ndarray, month: int,
                  ctx: RunContext) -> np.ndarray:
    """PV energy per pass in the run's PV mode (:func:`vipvflow.models.pv.energy`), at the month's
    mean air temperature and the run's wind.

    Parameters
    ----------
    poa_wm2 : (n,) plane-of-array irradiance on the roof, W/m2
    dt_s : (n,) time at that irradiance, s
    speed_mps : (n,) bus speed, m/s (cools the modules in ``pvlib`` mode)
    month : int, 1..12
    ctx : RunContext (PV system, mode, monthly temperatures in degC, wind in m/s)

    Returns
    -------
    (n,) float64, kWh

    References
    ----------
    Paper section 3.3 (``kWp x POA / 1000 x PR x dt``); pvlib ``pvsystem.pvwatts_dc``,
    ``temperature.sapm_cell`` (``pvlib`` mode).
    """
    from ..models import pv

    return pv.energy(poa_wm2, dt_s, PVSystem(**ctx.pv_system), ctx.pv_mode,
                     temp_air_c=ctx.monthly_temperature_c[month - 1],
                     vehicle_speed_mps=speed_mps, wind_mps=ctx.wind_speed_mps)


def _local_hours(t_utc: np.ndarray, timezone: str) -> np.ndarray:
    """Local clock hour (0..23) of Unix times (s).

    The UTC offset is looked up per UTC hour of the span the times cover (clock changes
    fall on UTC hour starts), from a table of that span: O(n) for the passes.
    """
    if not len(t_utc):
        return np.zeros(0, np.int8)
    utc_hour = np.floor(t_utc / 3600.0).astype(np.int64)
    lo, hi = int(utc_hour.min()), int(utc_hour.max())
    span = pd.DatetimeIndex(pd.to_datetime(np.arange(lo, hi + 1) * 3600, unit="s", utc=True))
    local = span.tz_convert(timezone).tz_localize(None)
    offset = ((local - span.tz_localize(None)) / pd.Timedelta(seconds=1)).to_numpy(np.float64)
    return (np.floor((t_utc + offset[utc_hour - lo]) / 3600.0).astype(np.int64) % 24).astype(np.int8)


def _dense_positions(ids: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sorted distinct integers of *ids* and each element's position among them (like
    ``np.unique(..., return_inverse=True)`` in O(n + range) for ids from a compact range)."""
    if not len(ids):
        return ids[:0], np.zeros(0, np.int64)
    lo, hi = int(ids.min()), int(ids.max())
    if hi - lo > 8 * len(ids) + 1024:
        return np.unique(ids, return_inverse=True)
    present = np.zeros(hi - lo + 1, bool)
    present[ids - lo] = True
    pos = np.cumsum(present) - 1
    return np.flatnonzero(present) + lo, pos[ids - lo]


def partition_groups(passes: pd.DataFrame, ctx: RunContext, seg_ids=None,
                     totals: dict | None = None) -> dict:
    """Each pass's (trip, service date) run, segment position and local hour, and the
    seconds per run, segment and hour (:func:`vipvflow.models.passkernel.pass_groups`, with
    its *seg_ids* and *totals*).

    Returns its dict with ``trip_code`` and ``day`` (days since 1970) of each run, the trip
    names ``trip_uniques`` the codes index, and ``dt`` (n,) s on the segment.  The runs come
    from the pass order (sorted by service date, trip and time, as
    :func:`vipvflow.inputs.gtfs.iter_passes` gives them).
    """
    from ..models.passkernel import pass_groups

    # trip codes in the order of the trip names (categories are sorted by iter_passes)
    trip_col = passes["trip_id"]
    if hasattr(trip_col, "cat"):
        trip_code, trip_uniques = trip_col.cat.codes.to_numpy(), trip_col.cat.categories
    else:
        trip_code, trip_uniques = pd.factorize(trip_col, sort=True)
    trip_code = np.asarray(trip_code, dtype=np.int64)
    day = passes["service_date"].to_numpy().astype("datetime64[D]").astype(np.int64)
    dt = np.ascontiguousarray(passes["dt_s"].to_numpy(np.float64))
    g = pass_groups(trip_code, day, passes["segment_id"].to_numpy(np.int64),
                    passes["t_utc"].to_numpy(np.float64), dt, ctx.timezone, seg_ids, totals)
    # the trip and date of each run, not of each pass (16 bytes a pass held through the kernel)
    g.update(trip_code=trip_code[g["starts"]], trip_uniques=trip_uniques, day=day[g["starts"]], dt=dt)
    return g


def _irradiation_sums(irr: pd.DataFrame, g: dict, n_seg: int, n_runs: int):
    """The numpy reference of the sums: irradiation (Wh/m2) of each component per (segment,
    local hour) bin (n_seg x 24, C) and per run (n_runs, C), over the passes with light."""
    comp = {c: irr[c].to_numpy(np.float32) for c in COMPONENTS}
    n = len(g["dt"])
    lit = np.zeros(n, bool)
    for v in comp.values():
        lit |= v != 0
    act = np.flatnonzero(lit)
    w_act = g["dt"][act] / 3600.0
    h_all = np.empty((len(COMPONENTS), len(act)), np.float64)   # one contiguous row per component
    for j, v in enumerate(comp.values()):
        np.multiply(v[act], w_act, out=h_all[j])
    seg_hour = g["seg_hour"][act]
    table = np.stack([np.bincount(seg_hour, h_all[j], n_seg * 24) for j in range(len(COMPONENTS))], 1)
    # per trip: the runs are contiguous, so one reduceat sums every component
    run_act = g["run"][act]
    per_run = np.zeros((len(COMPONENTS), n_runs))
    if len(act):
        first = np.flatnonzero(np.r_[True, run_act[1:] != run_act[:-1]])
        per_run[:, run_act[first]] = np.add.reduceat(h_all, first, axis=1)
    return table, per_run.T, comp, act


def aggregate_partition(passes: pd.DataFrame, irr: pd.DataFrame | None, month: int, ctx: RunContext,
                        groups: dict | None = None, bins: tuple | None = None):
    """:func:`partition_tables` as three DataFrames (trip, segment, hourly)."""
    return tuple(t.to_pandas() for t in partition_tables(passes, irr, month, ctx, groups, bins))


def partition_tables(passes: pd.DataFrame, irr: pd.DataFrame | None, month: int, ctx: RunContext,
                     groups: dict | None = None, bins: tuple | None = None):
    """Sum a partition's passes per trip and service date, per segment and per local hour.

    Returns three Arrow tables: per trip (``trip_id, service_date``, PV kWh of all-sky,
    clear-sky, the unshaded references and per component, ``seconds``), per segment
    (``segment_id, n_passes``, the same kWh, irradiation ``h_<component>`` in Wh/m2,
    ``seconds``) and per local clock hour (``hour``, irradiation, ``seconds``).  Built from
    numpy columns, with no pandas frame: a tile-month's tables are small, and pandas' fixed
    costs per frame and column were a fifth of a partition's time.

    Parameters
    ----------
    passes : DataFrame of the partition's passes (``trip_id, service_date, segment_id,
        t_utc, dt_s, speed_mps``), in :func:`vipvflow.inputs.gtfs.iter_passes` order; None
        with *groups* and *bins*
    irr : DataFrame of per-pass irradiance (W/m2, :func:`vipvflow.models.irradiance.evaluate_passes`),
        or None with *bins*
    month : int, 1..12 (the month's air temperature in ``pvlib`` mode)
    ctx : RunContext
    groups : dict, optional, :func:`partition_groups` of *passes* when the caller has it
        (with *bins*: per segment of *seg_ids*, those without passes left out)
    bins : (seg_bins, run_bins), optional, irradiation (Wh/m2) already summed per (segment x
        24 + local hour) bin and per run, columns ``COMPONENTS`` (the fused kernel,
        :func:`vipvflow.models.passkernel.accumulate`); only in the linear ``paper`` PV mode

    Notes
    -----
    Irradiation ``H = sum E dt / 3600`` (Wh/m2); in ``paper`` mode the energy is linear in
    it, ``kWh = kWp x PR x H / 1000`` (:func:`vipvflow.models.pv.energy_paper`); in ``pvlib`` mode
    it is summed per pass (:func:`pv_energy_kwh`).  Without *bins*: one ``bincount`` per
    component over (segment, local hour) bins and one ``reduceat`` over the (trip, date)
    runs, over the passes that received any light only (a (trip, date) split over several
    runs is merged).
    """
    import pyarrow as pa

    system = PVSystem(**ctx.pv_system)
    linear = ctx.pv_mode == "paper"
    pv_source = {**{f"pv_kwh{suffix}": col for suffix, col in VARIANTS.items()},
                 **{f"pv_kwh_{c}": c for c in PV_COMPONENTS}}
    g = groups if groups is not None else partition_groups(passes, ctx)
    n_runs, seg_ids, seg_n, seg_s = len(g["trip_code"]), g["seg_ids"], g["seg_n"], g["seg_s"]
    n_seg = len(seg_ids)
    if bins is None:
        table, per_run, comp, act = _irradiation_sums(irr, g, n_seg, n_runs)
    else:
        if not linear:
            raise ValueError("summed bins need the linear 'paper' PV mode")
        table, per_run = bins
    table = table.reshape(n_seg, 24, len(COMPONENTS))
    if bins is not None and not seg_n.all():
        # bins of a tile's segments (passes in chunks): the segments with passes
        kept = seg_n > 0
        table, seg_ids, seg_n, seg_s = table[kept], seg_ids[kept], seg_n[kept], seg_s[kept]
        n_seg = len(seg_ids)
    sums = {"trip": {}, "seg": {}, "hour": {}}
    for j, c in enumerate(COMPONENTS):
        t_c = np.ascontiguousarray(table[:, :, j])
        sums["seg"][f"h_{c}"] = t_c.sum(axis=1)
        sums["hour"][f"h_{c}"] = t_c.sum(axis=0)
        sums["trip"][f"h_{c}"] = per_run[:, j]
    if linear:
        # paper mode is linear in the irradiation: kWh = kWp x PR x H / 1000 (H in Wh/m2)
        from ..models.pv import paper_kw_per_wm2

        k = paper_kw_per_wm2(system.kwp, system.performance_ratio)
        for grp in ("trip", "seg"):
            for name, col in pv_source.items():
                sums[grp][name] = k * sums[grp][f"h_{col}"]
    else:
        speed = passes["speed_mps"].to_numpy(np.float64)[act]
        dt, run, seg_pos = g["dt"], g["run"], g["seg_pos"]
        for name, col in pv_source.items():
            e = pv_energy_kwh(comp[col][act].astype(np.float64), dt[act], speed, month, ctx)
            sums["trip"][name] = np.bincount(run[act], e, n_runs)
            sums["seg"][name] = np.bincount(seg_pos[act], e, n_seg)
    pv_cols = list(pv_source)
    h_cols = [f"h_{c}" for c in COMPONENTS]
    trip = _trip_table(g, {**{c: sums["trip"][c] for c in pv_cols}, "seconds": g["run_s"]})
    segm = pa.table({"segment_id": seg_ids, "n_passes": seg_n,
                     **{c: sums["seg"][c] for c in pv_cols + h_cols}, "seconds": seg_s})
    present = np.flatnonzero(g["hour_n"] > 0)
    hourly = pa.table({"hour": present.astype(np.int8),
                       **{c: sums["hour"][c][present] for c in h_cols},
                       "seconds": g["hour_s"][present]})
    return trip, segm, hourly


def _trip_table(g: dict, per_run: dict):
    """The runs' sums *per_run* (name -> (n_runs,) array) as an Arrow table per trip and
    service date, sorted by both (trip codes follow the sorted trip names); a (trip, date)
    split over several runs is merged."""
    import pyarrow as pa

    code, day = g["trip_code"], g["day"]
    order = np.lexsort((day, code))
    code, day = code[order], day[order]
    dates = day.astype("datetime64[D]").astype("datetime64[ns]")
    cols = {c: v[order] for c, v in per_run.items()}
    first = np.flatnonzero(np.r_[True, (code[1:] != code[:-1]) | (day[1:] != day[:-1])])
    if len(first) < len(code):
        cols = {c: np.add.reduceat(v, first) for c, v in cols.items()}
        code, dates = code[first], dates[first]
    used, inverse = np.unique(code, return_inverse=True)
    names = pa.array(np.asarray(g["trip_uniques"][used], dtype=object).astype(str), pa.string())
    return pa.table({"trip_id": names.take(pa.array(inverse.astype(np.int32))),
                     "service_date": dates, **cols})


def _fused_sums(ctx: RunContext, tile: str, chunks, geometry: pd.DataFrame, timings: dict):
    """The partition's irradiation summed by the fused kernel (:mod:`vipvflow.models.passkernel`)
    into (segment, local hour) and (trip, date) bins, without per-pass outputs; None where
    the kernel cannot run (geometry not in the scene's frame).

    *chunks* gives the partition's passes as frames of consecutive service days, in pass
    order (:class:`vipvflow.inputs.gtfs.PassChunks`, or a list of one frame).  Each chunk is
    grouped and run through the kernel, which adds it to the bins of the tile's segments,
    pass after pass: the sums are those of all the passes at once, bit for bit, while only
    one chunk's passes are held.  Returns (groups, bins, passes): :func:`partition_groups`'s
    dict over the chunks (per run, and per segment of the tile's geometry), the bins as
    :func:`partition_tables` takes them.  Adds to *timings* the pass generation
    (``passes_s``), the grouping (``reduce_s``) and the kernel (``irradiance_s`` and its
    stages, like :func:`vipvflow.models.irradiance.evaluate_passes`).
    """
    from ..models import passkernel

    t0 = time.perf_counter()
    scene = _scene(ctx, tile)
    geo = _packed_geometry(ctx, tile, geometry, scene)
    if not passkernel.usable(geo, scene):
        return None
    radiation = _radiation(ctx.data_dir, ctx.year)
    cfg = IrradianceCfg(**ctx.irradiance)
    ids = geometry["segment_id"].to_numpy(np.int64)
    pos = np.full(int(ids.max()) + 1 if len(ids) else 1, -1, np.int64)
    pos[ids] = np.arange(len(ids))
    seg_ids = np.unique(ids)
    loc = geometry["rad_location"].to_numpy(np.int64) if "rad_location" in geometry else None
    n_bins = len(seg_ids) * 24
    totals = dict(seg_s=np.zeros(len(seg_ids)), hour_s=np.zeros(24),
                  seg_n=np.zeros(len(seg_ids), np.int64), hour_n=np.zeros(24, np.int64))
    seg_bins = np.zeros((n_bins, len(passkernel.BLOCK_COLUMNS)))
    # each run's trip, day, seconds and bins, chunk after chunk (from empty: no chunk, no run)
    per_run = {"trip_code": [np.zeros(0, np.int64)], "day": [np.zeros(0, np.int64)],
               "run_s": [np.zeros(0)], "bins": [np.zeros((0, seg_bins.shape[1]))]}
    stages: dict = {}
    clock = {"passes_s": 0.0, "reduce_s": 0.0, "irradiance_s": time.perf_counter() - t0}
    n, uniques, chunks = 0, None, iter(chunks)
    while True:
        t1 = time.perf_counter()
        passes = next(chunks, None)
        t2 = time.perf_counter()
        clock["passes_s"] += t2 - t1
        if passes is None:
            break
        seg = np.ascontiguousarray(passes["segment_id"].to_numpy(np.int64))
        if len(seg) and (seg.max() >= len(pos) or seg.min() < 0 or (pos[seg] < 0).any()):
            raise KeyError("passes reference segments missing from the geometry")
        g = partition_groups(passes, ctx, seg_ids, totals)
        if uniques is None:
            uniques = g["trip_uniques"]
        elif g["trip_uniques"] is not uniques and not g["trip_uniques"].equals(uniques):
            raise ValueError("the chunks of a partition must share their trip categories")
        t3 = time.perf_counter()
        _, run_bins = passkernel.accumulate(
            seg, np.ascontiguousarray(passes["t_utc"].to_numpy(np.float64)), g["dt"], True,
            pos[seg], geo, cfg, radiation, scene, g["seg_hour"], n_bins, g["run"],
            len(g["starts"]), loc, stages, seg_bins=seg_bins)
        clock["reduce_s"] += t3 - t2
        clock["irradiance_s"] += time.perf_counter() - t3
        for k in ("trip_code", "day", "run_s"):
            per_run[k].append(g[k])
        per_run["bins"].append(run_bins)
        n += len(passes)
        del passes, g, seg
    for k, v in clock.items():
        timings[k] = timings.get(k, 0.0) + v
    timings.update({f"irradiance_{k}": v for k, v in stages.items()})
    order = [passkernel.BLOCK_COLUMNS.index(c) for c in COMPONENTS]
    groups = {k: np.concatenate(v) for k, v in per_run.items() if k != "bins"}
    groups.update(seg_ids=seg_ids, trip_uniques=uniques if uniques is not None else pd.Index([]),
                  **totals)
    run_bins = np.concatenate(per_run["bins"])
    return groups, (seg_bins[:, order], run_bins[:, order]), n


def run_partition(ctx: RunContext, tile: str, month: str,
                  geometry: pd.DataFrame | None = None) -> dict:
    """Evaluate every pass of *tile* in *month* and write the partition's files.

    Writes ``parts/trip/tile=T/month=M.parquet`` (per trip and service date: PV kWh for
    all-sky, clear-sky and the unshaded references, and per component) and
    ``parts/segment_month/...`` (per segment: passes, irradiation sums in Wh/m2, kWh) and
    ``parts/hourly/...`` (per local hour: irradiation and pass time, for the daily pattern).
    The fused kernel takes the passes a few service days at a time
    (:class:`vipvflow.inputs.gtfs.PassChunks`); the numpy reference all at once.
    Returns a small summary for the progress view.
    """
    from ..inputs.gtfs import PassChunks
    from ..models.irradiance import evaluate_passes

    tune_malloc()
    t0 = time.perf_counter()
    run = RunDir(ctx.run_dir)
    if geometry is None:
        geometry = tile_geometry(ctx, tile)
    chunks = PassChunks(ctx.data_dir, tile, month, ctx.year, routes=ctx.routes)
    timings = {"passes_s": time.perf_counter() - t0}
    n = chunks.n
    fused = None
    if n and ctx.pv_mode == "paper":
        fused = _fused_sums(ctx, tile, chunks, geometry, timings)
    passes = None
    if fused is None:
        t1 = time.perf_counter()
        passes = chunks.all()
        timings["passes_s"] += time.perf_counter() - t1
    if fused is not None:
        irr = None
    elif n:
        t1 = time.perf_counter()
        stages: dict = {}
        scene = _scene(ctx, tile)
        irr = evaluate_passes(passes, _segments(ctx.data_dir), geometry,
                              _radiation(ctx.data_dir, ctx.year),
                              scene, IrradianceCfg(**ctx.irradiance),
                              ground_albedo=ctx.ground_albedo,
                              packed=_packed_geometry(ctx, tile, geometry, scene), timings=stages)
        timings["irradiance_s"] = time.perf_counter() - t1
        # the irradiance time split by stage (lookup, ray setup, rays, components, pack)
        timings.update({f"irradiance_{k}": v for k, v in stages.items()})
    else:
        irr = pd.DataFrame({c: np.zeros(0, np.float32) for c in COMPONENTS})
    t2 = time.perf_counter()
    if fused is not None:
        groups, bins, _ = fused
        trip, segm, hourly = partition_tables(None, None, int(month[5:7]), ctx,
                                              groups=groups, bins=bins)
    else:
        trip, segm, hourly = partition_tables(passes, irr, int(month[5:7]), ctx)
    timings["reduce_s"] = timings.get("reduce_s", 0.0) + time.perf_counter() - t2

    t3 = time.perf_counter()
    write_partition_files(run, tile, month, trip, segm, hourly)
    timings["write_s"] = time.perf_counter() - t3
    # the kernel's counts (``*_n``) apart from its seconds
    counts = {k.removeprefix("irradiance_")[:-2]: timings.pop(k) for k in
              [k for k in timings if k.endswith("_n")]}

    kwh = trip.column("pv_kwh").to_numpy()
    return {"tile": tile, "month": month, "passes": n, "trips": trip.num_rows,
            "kwh": float(kwh.sum()), "kwh_by_route": _kwh_by_route(trip, kwh, ctx.route_of_trip),
            "timings": timings, "counts": counts,
            "elapsed_s": time.perf_counter() - t0}


def _kwh_by_route(trip, kwh: np.ndarray, route_of_trip: dict) -> dict[str, float]:
    """The trip table's kWh summed per route (for the progress view)."""
    if not route_of_trip or not trip.num_rows:
        return {}
    ids = trip.column("trip_id").dictionary_encode().combine_chunks()
    routes = np.array([route_of_trip.get(t) for t in ids.dictionary.to_pylist()], dtype=object)
    known = np.array([r is not None for r in routes])
    names, route_code = np.unique(routes[known].astype(str), return_inverse=True)
    code = np.full(len(routes), -1, np.int64)
    code[known] = route_code
    row = code[ids.indices.to_numpy()]
    sums = np.bincount(row[row >= 0], kwh[row >= 0], len(names))
    return dict(zip(names.tolist(), sums.tolist()))


#: float columns of the trip partitions stored as float32: the per-trip kWh and seconds of
#: one tile-month (7 significant digits; the reduce sums them in float64)
TRIP_FLOAT32 = ("pv_kwh", "seconds")


def write_partition_files(run: RunDir, tile: str, month: str, trip, segm, hourly) -> None:
    """Write a partition's two files, holding what the reduce reads: no tile or month
    columns (the path names them), the trip kWh and seconds as float32 (the segment and
    hour sums, whose ratios the summary reports, stay float64), compact Parquet; the sums
    per local hour in the segment file's metadata (:data:`vipvflow.store.HOURLY_METADATA`)."""
    write_parquet(trip, run.part("trip", tile, month), compact=True, float32=TRIP_FLOAT32)
    meta = {**(segm.schema.metadata or {}), HOURLY_METADATA: json.dumps(hourly.to_pydict()).encode()}
    # segment_month last: its presence marks the partition complete
    write_parquet(segm.replace_schema_metadata(meta), run.part("segment_month", tile, month),
                  compact=True)


def partition_done(run_dir: Path, tile: str, month: str) -> bool:
    return all(RunDir(run_dir).part(kind, tile, month).exists() for kind in PARTITION_KINDS)


def release_memory() -> None:
    """Drop this process's caches of the map (the tiles' scenes and packed geometry, the
    segments, the radiation table, the GTFS tables) and hand freed memory back to the
    operating system (Arrow's pool, glibc's heap).  Run on every worker once the map is done:
    the workers live on through the reduce (its sums, the maps), and held their map's
    memory while the client joined the fleet's tables."""
    import gc

    from ..inputs.gtfs import schedule
    from ..models import shading

    shading.clear_scene_cache()
    _PACKED.clear()
    _segments.cache_clear()
    _radiation.cache_clear()
    schedule.clear_caches()
    gc.collect()
    hand_back_memory()


def worker_bvh_builds(release: bool = False) -> dict:
    """BVH builds per tile in this process (collected from every worker after a run); with
    *release*, the map's caches are dropped then (:func:`release_memory`)."""
    from ..models import shading

    builds = {tile: n for (_, tile), n in shading.BVH_BUILDS.items()}
    if release:
        release_memory()
    return builds
