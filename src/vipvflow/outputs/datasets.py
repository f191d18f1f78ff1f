"""The run's segment results as partitioned GeoParquet datasets with spatial partitions.

``segments.parquet`` and ``segment_month.parquet`` are single files (what QGIS, DuckDB, the
web app and the database mirror read).  Beside them the reduce writes the same rows as two
datasets a Dask GIS user opens as one GeoDataFrame each::

    import dask_geopandas
    sm = dask_geopandas.read_parquet("out/demo/2024/geoparquet/segment_month")
    sm.spatial_partitions          # one box per partition, from each file's GeoParquet bbox

A partition is a group of whole tiles of the run, consecutive in the Hilbert order of the
tiles' centres (a compact patch of the city), of about :data:`SEGMENTS_PER_PARTITION`
segments; both datasets use the same groups, so partition ``i`` of ``segments`` and of
``segment_month`` cover the same streets.  Written by dask-geopandas (``to_parquet``: per file
the GeoParquet metadata with its own bbox; the data dictionary's columns as JSON in each
file's ``vipvflow:columns`` key), each dataset folder swapped in as a whole.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..store import RunDir, staging_dir, swap_dir

#: segments per partition the tiles are grouped to (a tile is never split)
SEGMENTS_PER_PARTITION = 2000
#: the datasets: name -> the run output holding the same rows
DATASETS = {"segments": "segments.parquet", "segment_month": "segment_month.parquet"}


def tile_groups(segments, per_partition: int = SEGMENTS_PER_PARTITION) -> dict[str, int]:
    """The partition of each tile: tiles in the Hilbert order of their segments' centre,
    cut into groups of about *per_partition* segments (whole tiles)."""
    import geopandas as gpd

    counts = segments.groupby("tile").size()
    centre = segments.geometry.centroid
    xy = np.column_stack([centre.x, centre.y])
    mean = (gpd.GeoDataFrame({"tile": segments["tile"].to_numpy(), "x": xy[:, 0], "y": xy[:, 1]})
            .groupby("tile")[["x", "y"]].mean().loc[counts.index])
    points = gpd.GeoSeries(gpd.points_from_xy(mean["x"], mean["y"]), index=mean.index)
    order = points.hilbert_distance().sort_values(kind="stable").index
    group, filled, out = 0, 0, {}
    for tile in order:
        if filled and filled + counts[tile] > per_partition:
            group, filled = group + 1, 0
        out[tile] = group
        filled += int(counts[tile])
    return out


def write_datasets(run_dir, per_partition: int = SEGMENTS_PER_PARTITION) -> dict:
    """Write ``geoparquet/segments/`` and ``geoparquet/segment_month/`` from the run's
    ``segments.parquet`` and ``segment_month.parquet``; return the partitions of each."""
    import dask.dataframe as dd
    import dask_geopandas  # noqa: F401  (registers the GeoDataFrame backend of dask)
    import geopandas as gpd
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    run = RunDir(run_dir)
    segments = gpd.read_parquet(run.output(DATASETS["segments"]))
    groups = tile_groups(segments, per_partition)
    out = {}
    for name, source in DATASETS.items():
        frame = segments if name == "segments" else gpd.read_parquet(run.output(source))
        if "month" in frame:
            frame["month"] = pd.to_datetime(frame["month"])
        meta = pq.read_schema(run.output(source)).metadata or {}
        custom = {k: v for k, v in meta.items() if k.startswith(b"vipvflow:")}
        part = frame["tile"].map(groups).to_numpy()
        order = np.argsort(part, kind="stable")
        frame = frame.iloc[order].reset_index(drop=True)
        bounds = np.searchsorted(part[order], np.arange(max(groups.values()) + 2))
        pieces = [frame.iloc[a:b] for a, b in zip(bounds[:-1], bounds[1:])]
        final = run.dataset(name)
        stage = staging_dir(final)
        ddf = dd.from_map(_piece, pieces, meta=frame.iloc[:0], enforce_metadata=False)
        # month a date, as in the single file (pandas holds dates as timestamps)
        ddf.to_parquet(stage, write_index=False, custom_metadata=custom, overwrite=False,
                       schema={"month": pa.date32()} if "month" in frame else "infer",
                       compute_kwargs={"scheduler": "sync"})
        swap_dir(stage, final)
        out[name] = len(pieces)
    return out


def _piece(frame):
    return frame


def read_dataset(run_dir, name: str):
    """The dataset *name* (``segments`` or ``segment_month``) of a run as a dask-geopandas
    GeoDataFrame with its ``spatial_partitions``."""
    import dask_geopandas

    if name not in DATASETS:
        raise ValueError(f"no dataset {name!r}: {', '.join(DATASETS)}")
    return dask_geopandas.read_parquet(Path(RunDir(run_dir).dataset(name)))
