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

import json
import uuid
from pathlib import Path

import numpy as np

from ..store import RunDir, staging_dir, swap_dir

#: segments per partition the tiles are grouped to (a tile is never split)
SEGMENTS_PER_PARTITION = 2000
#: rows of a dataset held at once: its partitions are written in passes over the file, each
#: of consecutive partitions of about this many rows (a partition is never split)
ROWS_PER_PASS = 250_000
#: rows of a file read at a time in a pass
READ_BATCH_ROWS = 65_536
#: the datasets: name -> the run output holding the same rows
DATASETS = {"segments": "segments.parquet", "segment_month": "segment_month.parquet"}


def tile_groups(segments, per_partition: int = SEGMENTS_PER_PARTITION) -> dict[str, int]:
    """The partition of each tile: tiles in the Hilbert order of their segments' mean
    midpoint (*segments*: ``tile, x, y, x_end, y_end``), cut into groups of about
    *per_partition* segments (whole tiles)."""
    import geopandas as gpd
    import pandas as pd

    counts = segments.groupby("tile").size()
    mid = pd.DataFrame({"tile": segments["tile"].to_numpy(),
                        "x": (segments["x"].to_numpy() + segments["x_end"].to_numpy()) / 2,
                        "y": (segments["y"].to_numpy() + segments["y_end"].to_numpy()) / 2})
    mean = mid.groupby("tile")[["x", "y"]].mean().loc[counts.index]
    points = gpd.GeoSeries(gpd.points_from_xy(mean["x"], mean["y"]), index=mean.index)
    order = points.hilbert_distance().sort_values(kind="stable").index
    group, filled, out = 0, 0, {}
    for tile in order:
        if filled and filled + counts[tile] > per_partition:
            group, filled = group + 1, 0
        out[tile] = group
        filled += int(counts[tile])
    return out


def write_datasets(run_dir, per_partition: int = SEGMENTS_PER_PARTITION,
                   rows_per_pass: int = ROWS_PER_PASS) -> dict:
    """Write ``geoparquet/segments/`` and ``geoparquet/segment_month/`` from the run's
    ``segments.parquet`` and ``segment_month.parquet``; return the partitions of each.  The
    partitions are written in passes over each file of about *rows_per_pass* rows."""
    import dask
    import dask.dataframe as dd
    import dask_geopandas  # noqa: F401  (registers the GeoDataFrame backend of dask)
    import pandas as pd
    import pyarrow as pa
    import pyarrow.compute as pc
    import pyarrow.parquet as pq
    import pyproj

    from ..simulation.partition import hand_back_memory

    run = RunDir(run_dir)
    segments = pd.read_parquet(run.output(DATASETS["segments"]),
                               columns=["tile", "x", "y", "x_end", "y_end"])
    groups = tile_groups(segments, per_partition)
    out = {}
    if not groups:                          # a run without segments: no dataset
        return out
    for name, source in DATASETS.items():
        path = run.output(source)
        meta = pq.read_schema(path).metadata or {}
        crs_json = json.loads(meta[b"geo"])["columns"]["geometry"].get("crs")
        crs = pyproj.CRS.from_json_dict(crs_json) if crs_json else None
        # each row's partition from its tile, looked up in Arrow (3.7 M tile names of a
        # network's segment-months as Python strings took ~0.25 GB)
        at = pc.index_in(pq.read_table(path, columns=["tile"]).column("tile").cast(pa.string()),
                         value_set=pa.array(list(groups), pa.string()))
        if at.null_count:
            raise ValueError(f"{path}: rows of tiles without segments in "
                             f"{run.output(DATASETS['segments'])}")
        part = np.asarray(list(groups.values()), np.int64)[at.to_numpy()]
        del at
        custom = {k: v for k, v in meta.items() if k.startswith(b"vipvflow:")}
        final = run.dataset(name)
        stage = staging_dir(final)
        sizes = np.bincount(part, minlength=max(groups.values()) + 1)
        for first, last in _passes(sizes, rows_per_pass):
            # this pass's rows, streamed from the file (the file whole, read at once, took
            # its worker to 0.82 GB on a 50-line network, and grew with it); each partition
            # takes its own rows when it is written, in file order
            mine = (part >= first) & (part < last)
            table = _rows_of(path, mine)
            hand_back_memory()              # the read's buffers
            at = part[mine]
            order = np.argsort(at, kind="stable")
            bounds = np.searchsorted(at[order], np.arange(first, last + 1))
            pieces = [(int(a), int(b)) for a, b in zip(bounds[:-1], bounds[1:])]
            rows = _Rows(table, order, crs)
            # the partitions' strings as Arrow made them (pandas' own string dtype, as the single
            # file reads back): Dask's conversion of each to string[pyarrow] was a quarter of
            # the datasets' time on a 50-line network, for the same Arrow columns
            with dask.config.set({"dataframe.convert-string": False}):
                ddf = dd.from_map(rows, pieces, meta=rows((0, 0)), enforce_metadata=False)
                # month a date, as in the single file (pandas holds dates as timestamps)
                ddf.to_parquet(stage, write_index=False, custom_metadata=custom, overwrite=False,
                               schema={"month": pa.date32()} if "month" in table.column_names
                               else "infer",
                               name_function=lambda i, first=first: f"part.{first + i}.parquet",
                               compute_kwargs={"scheduler": "sync"})
            del table, ddf, rows
            hand_back_memory()
        swap_dir(stage, final)
        out[name] = len(sizes)
    return out


def _passes(sizes, rows_per_pass: int) -> list[tuple[int, int]]:
    """Consecutive partitions ``[first, last)`` of about *rows_per_pass* rows together
    (*sizes*: the rows of each partition; a partition larger than that is a pass alone)."""
    passes, first, rows = [], 0, 0
    for i, n in enumerate(sizes):
        if rows and rows + n > rows_per_pass:
            passes.append((first, i))
            first, rows = i, 0
        rows += int(n)
    passes.append((first, len(sizes)))
    return passes


def _rows_of(path, mine):
    """The rows of the Parquet file *path* where the boolean array *mine* is true, as one
    Arrow table, read in batches and streamed (neither the file nor a row group is held
    whole: pre-buffering a row group held its column chunks)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    source, kept, at = pq.ParquetFile(path, pre_buffer=False, buffer_size=1 << 20), [], 0
    for batch in source.iter_batches(batch_size=READ_BATCH_ROWS):
        kept.append(batch.filter(pa.array(mine[at:at + batch.num_rows])))
        at += batch.num_rows
    return pa.Table.from_batches(kept, schema=source.schema_arrow)


class _Rows:
    """``rows((a, b))``: the rows ``order[a:b]`` of an Arrow table of a run output as a
    GeoDataFrame (columns in the file's order).  Named for Dask by a random token: hashing
    the table to name the tasks cost more than writing it."""

    def __init__(self, table, order, crs):
        self.table, self.order, self.crs, self.token = table, order, crs, uuid.uuid4().hex

    def __dask_tokenize__(self):
        return self.token

    def __call__(self, rows):
        import geopandas as gpd
        import pandas as pd

        df = self.table.take(self.order[rows[0]:rows[1]]).to_pandas()
        if "month" in df:
            df["month"] = pd.to_datetime(df["month"])
        df["geometry"] = gpd.GeoSeries.from_wkb(df["geometry"].to_numpy(), crs=self.crs)
        return gpd.GeoDataFrame(df, geometry="geometry", crs=self.crs)


def read_dataset(run_dir, name: str):
    """The dataset *name* (``segments`` or ``segment_month``) of a run as a dask-geopandas
    GeoDataFrame with its ``spatial_partitions``."""
    import dask_geopandas

    if name not in DATASETS:
        raise ValueError(f"no dataset {name!r}: {', '.join(DATASETS)}")
    return dask_geopandas.read_parquet(Path(RunDir(run_dir).dataset(name)))
