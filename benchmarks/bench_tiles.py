"""Segments to tiles: today's arithmetic against a dask-geopandas spatial join.

Every segment's tile is the square of the grid holding its start (``gtfs/segments.parquet``'s
``tile``, written by the GTFS ingest with :func:`vipvflow.inputs.tiles.tile_names`: floor of
the coordinates over the tile size, then the names of the distinct tiles).  The alternative a
Dask GIS user would write: the start points as a dask-geopandas GeoDataFrame (two partitions,
the threaded scheduler on the machine's two cores) joined (``sjoin``, ``within``) with the
grid's tile squares as a GeoDataFrame.  Both on the same points: 400,000 segment starts
spread over a 25 km x 25 km city (about the 200-line network's 153,000 segments, x 2.6), on
500 m tiles; best of three alternated runs of each, the same tile for every point checked.
``tiny``: 20,000 points.
"""
from __future__ import annotations

import time

import numpy as np


def _points(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    return rng.uniform(60_000, 85_000, n), rng.uniform(60_000, 85_000, n)


def today(x, y, size):
    from vipvflow.inputs.tiles import tile_names

    return tile_names(x, y, size)


def with_dask_geopandas(x, y, size, tiles):
    import dask_geopandas
    import geopandas as gpd

    points = gpd.GeoDataFrame(geometry=gpd.points_from_xy(x, y), crs="EPSG:2169")
    ddf = dask_geopandas.from_geopandas(points, npartitions=2)
    joined = ddf.sjoin(tiles, predicate="within").compute(scheduler="threads", num_workers=2)
    out = np.empty(len(x), dtype=object)
    out[joined.index.to_numpy()] = joined["tile"].to_numpy()
    return out


def _grid(size: float):
    import geopandas as gpd
    import shapely

    from vipvflow.inputs.tiles import tile_name

    ix, iy = np.meshgrid(np.arange(int(60_000 // size), int(85_000 // size) + 1),
                         np.arange(int(60_000 // size), int(85_000 // size) + 1))
    ix, iy = ix.ravel(), iy.ravel()
    boxes = shapely.box(ix * size, iy * size, (ix + 1) * size, (iy + 1) * size)
    return gpd.GeoDataFrame({"tile": [tile_name(a, b, size) for a, b in zip(ix, iy)]},
                            geometry=boxes, crs="EPSG:2169")


def run(tiny: bool = False) -> dict:
    n, size = (20_000 if tiny else 400_000), 500.0
    x, y = _points(n)
    tiles = _grid(size)
    times = {"today": [], "dask_geopandas": []}
    results = {}
    for _ in range(1 if tiny else 3):
        for name, fn in (("today", lambda: today(x, y, size)),
                         ("dask_geopandas", lambda: with_dask_geopandas(x, y, size, tiles))):
            t0 = time.perf_counter()
            results[name] = fn()
            times[name].append(time.perf_counter() - t0)
    same = bool((results["today"] == results["dask_geopandas"]).all())
    best = {k: min(v) for k, v in times.items()}
    return {
        "figures": {
            "points": n, "tiles": len(tiles),
            "today_s": round(best["today"], 4), "dask_geopandas_s": round(best["dask_geopandas"], 4),
            "dask_geopandas_over_today": round(best["dask_geopandas"] / best["today"], 1),
            "today_runs_s": [round(t, 4) for t in times["today"]],
            "dask_geopandas_runs_s": [round(t, 4) for t in times["dask_geopandas"]],
            "same_tiles": same,
        },
        "targets": {"dask_geopandas_over_today": "<= 1 to replace today's code (else kept)",
                    "same_tiles": "True"},
    }
