"""The bare kernel of one line-year: the reference the whole pipeline is measured against.

The same passes as ``line_year`` (the demo's line ``L1``, every month of 2024, every tile it
crosses), through the least work that still gives PV energy per trip:

* the passes of a (tile, month) from the timetable (:func:`vipvflow.inputs.gtfs.iter_passes`,
  timed apart as ``passes_s``);
* radiation and sun at each daytime pass from a per-minute table (nearest minute, one gather);
* one Embree occlusion ray per daytime pass from the segment's roof point towards the sun;
* direct = DNI cos(AOI) on a flat roof x visibility, diffuse = DHI x a per-segment sky factor,
  reflected = GHI x a per-segment reflection factor (constant factors: this measures cost,
  not physics);
* energy per pass (kWp x POA / 1000 x PR x dt) summed per trip with one bincount;
* nothing written.

Two processes of one thread each take the tiles in turn, as two Dask workers would.  The
figure to compare is the line-year's wall time over this one's: ``line_year`` measures both
itself, in alternated pairs (``kernel_ratio``); the issue's target is within 3x.
"""
from __future__ import annotations

import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from benchmarks.common import YEAR, PeakRSS, demo_paths, prepare_demo

KWP, PR = 3.5, 0.75
SKY_FACTOR, REFLECTION_FACTOR = 0.8, 0.02


def _tiles_of_route(data_dir: str, route: str) -> list[str]:
    import pandas as pd

    gdir = f"{data_dir}/gtfs"
    trips = pd.read_parquet(f"{gdir}/trips.parquet", columns=["route_id", "shape_id"])
    shapes = set(trips.loc[trips["route_id"].astype(str) == route, "shape_id"].astype(str))
    seg = pd.read_parquet(f"{gdir}/segments.parquet", columns=["shape_id", "tile"])
    return sorted(seg.loc[seg["shape_id"].astype(str).isin(shapes), "tile"].astype(str).unique())


def _minute_table(data_dir: str):
    """(t0, per-minute float32 columns dni, dhi, ghi, sun_x, sun_y, sun_z) for the year."""
    from vipvflow.models.sun_sky import RadiationTable

    rad = RadiationTable.load(data_dir, YEAR)
    t = rad.t0 + np.arange(rad.n, dtype=np.float64) * rad.step_s
    v = rad.lookup(t, angles=False)
    return rad.t0, rad.step_s, np.stack([v[c] for c in ("dni", "dhi", "ghi", "sun_x", "sun_y", "sun_z")])


def _tile_work(data_dir: str, tiles: list[str], route: str, months: list[int]) -> dict:
    """Every pass of *tiles* x *months*: passes, lookup, rays, energy per trip."""
    from vipvflow.inputs.gtfs import iter_passes
    from vipvflow.models.shading import get_scene
    from vipvflow.simulation.partition import _segments, tune_malloc

    tune_malloc()
    t_load = time.perf_counter()
    t0, step, table = _minute_table(data_dir)
    seg = _segments(data_dir)
    load_s = time.perf_counter() - t_load
    passes_s = kernel_s = 0.0
    n_passes = n_rays = 0
    kwh = 0.0
    for tile in tiles:
        scene = get_scene(data_dir, tile, n_threads=1)
        for month in months:
            a = time.perf_counter()
            p = iter_passes(data_dir, tile, f"{YEAR}-{month:02d}", YEAR, routes=[route])
            b = time.perf_counter()
            passes_s += b - a
            if not len(p):
                continue
            sid = p["segment_id"].to_numpy()
            i = np.clip(((p["t_utc"].to_numpy() - t0) / step + 0.5).astype(np.int64), 0, table.shape[1] - 1)
            row = table[:, i]
            day = row[5] > 0
            pos = seg.loc[sid[day], ["x", "y", "z"]].to_numpy(np.float64)
            sun = np.ascontiguousarray(row[3:6, day].T)
            vis = ~scene.occluded_local(scene.to_local(pos), sun, 1e4)
            poa = np.zeros(len(p), np.float32)
            poa[day] = (row[0, day] * row[5, day] * vis + row[1, day] * SKY_FACTOR
                        + row[2, day] * REFLECTION_FACTOR)
            e = KWP * poa / 1000.0 * PR * p["dt_s"].to_numpy(np.float32) / 3600.0
            per_trip = np.bincount(p["trip_id"].cat.codes.to_numpy(), weights=e)
            kwh += float(per_trip.sum())
            n_passes += len(p)
            n_rays += int(day.sum())
            kernel_s += time.perf_counter() - b
    return {"passes": n_passes, "rays": n_rays, "kwh": kwh, "passes_s": passes_s,
            "kernel_s": kernel_s, "load_s": load_s}


def bare_kernel(size: str, months: list[int], route: str = "L1") -> dict:
    """One timed run of the bare kernel over *route*'s tiles x *months* of the prepared demo
    of *size* on two processes: ``wall_s``, ``peak_rss_mb`` and the workers' sums."""
    data_dir = str(demo_paths(size)["data"])
    tiles = _tiles_of_route(data_dir, route)
    halves = [tiles[0::2], tiles[1::2]]
    with PeakRSS() as mem:
        t0 = time.perf_counter()
        with ProcessPoolExecutor(2) as pool:
            parts = list(pool.map(_tile_work, [data_dir] * 2, halves, [route] * 2, [months] * 2))
        wall = time.perf_counter() - t0
    tot = {k: sum(p[k] for p in parts) for k in parts[0]}
    return {"wall_s": wall, "peak_rss_mb": mem.peak_mb, "tiles": len(tiles), **tot}


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    prepare_demo(size)
    route = "L1"
    months = [6] if tiny else list(range(1, 13))
    k = bare_kernel(size, months, route)
    wall = k["wall_s"]
    figures = {
        "kernel_wall_s": round(wall, 2),
        "passes": k["passes"],
        "daytime_rays": k["rays"],
        "passes_per_s": round(k["passes"] / wall),
        "worker_passes_s": round(k["passes_s"], 2),
        "worker_kernel_s": round(k["kernel_s"], 2),
        "worker_load_s": round(k["load_s"], 2),
        "kwh_all_trips": round(k["kwh"], 1),
        "peak_rss_gb": round(k["peak_rss_mb"] / 1024, 3),
    }
    return {"figures": figures, "targets": {"kernel_wall_s": "line_year.kernel_ratio measures its own pairs"},
            "config": {"size": size, "route": route, "months": months, "tiles": k["tiles"], "workers": 2,
                       "sky_factor": SKY_FACTOR, "reflection_factor": REFLECTION_FACTOR}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
