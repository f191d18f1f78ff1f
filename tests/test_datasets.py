"""The run's segment results as partitioned GeoParquet datasets: dask-geopandas opens each as
one GeoDataFrame with spatial partitions holding the rows of the single-file outputs."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import dask_geopandas
import geopandas as gpd
import pandas as pd
import pyarrow.parquet as pq
import pytest
import shapely

from vipvflow.outputs import datasets
from vipvflow.outputs.datasets import read_dataset, write_datasets


def _same_rows(ddf, single: Path, keys: list[str]) -> None:
    got = ddf.compute().sort_values(keys).reset_index(drop=True)
    want = gpd.read_parquet(single).sort_values(keys).reset_index(drop=True)
    assert list(got.columns) == list(want.columns) and got.crs == want.crs
    # the same values (Dask reads strings as pyarrow strings with pd.NA: another dtype flavour)
    pd.testing.assert_frame_equal(pd.DataFrame(got.drop(columns="geometry")),
                                  pd.DataFrame(want.drop(columns="geometry")), check_dtype=False)
    assert got.geometry.geom_equals_exact(want.geometry, tolerance=0).all()


def test_the_run_writes_both_datasets_with_spatial_partitions(small_run):
    run = Path(small_run)
    for name, keys in (("segments", ["segment_id"]), ("segment_month", ["segment_id", "month"])):
        ddf = dask_geopandas.read_parquet(run / "geoparquet" / name)     # the user's line
        assert ddf.spatial_partitions is not None and len(ddf.spatial_partitions) == ddf.npartitions
        assert ddf.crs.to_epsg() == 2169
        _same_rows(ddf, run / f"{name}.parquet", keys)
        meta = pq.read_schema(next((run / "geoparquet" / name).glob("part.*.parquet"))).metadata
        columns = json.loads(meta[b"vipvflow:columns"])
        assert columns["kwh_per_kwp_year" if name == "segments" else "h_total"]["unit"]
        # a part read with geopandas: the single file's columns and dtypes (strings included)
        part = gpd.read_parquet(next((run / "geoparquet" / name).glob("part.*.parquet")))
        single = gpd.read_parquet(run / f"{name}.parquet")
        assert part.dtypes.astype(str).to_dict() == single.dtypes.astype(str).to_dict()


def test_partitions_are_whole_tiles_in_their_boxes(small_run, tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    for name in ("segments.parquet", "segment_month.parquet"):
        shutil.copy(Path(small_run) / name, run / name)
    n_segments = len(pd.read_parquet(run / "segments.parquet", columns=["segment_id"]))
    per = max(1, n_segments // 6)
    parts = write_datasets(run, per_partition=per)
    assert parts["segments"] == parts["segment_month"] >= 3
    for name in ("segments", "segment_month"):
        ddf = read_dataset(run, name)
        assert ddf.npartitions == parts[name]
        tiles_seen = set()
        for i in range(ddf.npartitions):
            piece = ddf.get_partition(i).compute()
            box = ddf.spatial_partitions.iloc[i]
            assert shapely.covers(box, piece.geometry.values).all()
            tiles = set(piece["tile"])
            assert not tiles & tiles_seen                   # a tile is in one partition
            tiles_seen |= tiles
            if name == "segments" and len(tiles) > 1:
                assert len(piece) <= per
    # the partitions of both datasets cover the same tiles, in the same order
    a, b = read_dataset(run, "segments"), read_dataset(run, "segment_month")
    for i in range(a.npartitions):
        assert set(a.get_partition(i).compute()["tile"]) == set(b.get_partition(i).compute()["tile"])
    # written again: the folders replaced as a whole
    write_datasets(run, per_partition=n_segments)
    assert read_dataset(run, "segments").npartitions == 1
    assert [p.name for p in (run / "geoparquet" / "segments").iterdir()] == ["part.0.parquet"]
    with pytest.raises(ValueError, match="no dataset"):
        read_dataset(run, "trips")


def test_passes_over_the_file_write_the_files_of_one_pass(small_run, tmp_path, monkeypatch):
    """The partitions written in passes over each file (a partition a pass, or a few, each
    pass holding its rows alone) are the files written in one pass, byte for byte in their
    values, schema and metadata."""
    run = tmp_path / "run"
    run.mkdir()
    for name in ("segments.parquet", "segment_month.parquet"):
        shutil.copy(Path(small_run) / name, run / name)
    rows = len(pd.read_parquet(run / "segment_month.parquet", columns=["segment_id"]))
    n_segments = len(pd.read_parquet(run / "segments.parquet", columns=["segment_id"]))
    per = max(1, n_segments // 6)
    monkeypatch.setattr(datasets, "READ_BATCH_ROWS", 7)      # a pass's rows from many batches
    written = {}
    for rows_per_pass in (rows, rows // 3, 1):
        parts = write_datasets(run, per_partition=per, rows_per_pass=rows_per_pass)
        assert parts["segment_month"] >= 3
        written[rows_per_pass] = {
            f"{name}/{f.name}": pq.read_table(f)
            for name in ("segments", "segment_month")
            for f in sorted((run / "geoparquet" / name).glob("*"))}
    one = written[rows]
    for rows_per_pass in (rows // 3, 1):
        assert written[rows_per_pass].keys() == one.keys()
        for f, table in one.items():
            got = written[rows_per_pass][f]
            assert got.schema.equals(table.schema, check_metadata=True), f
            assert got.equals(table), f


def test_rows_of_a_tile_without_segments_are_refused_with_the_file_named(small_run, tmp_path):
    import pyarrow as pa

    run = tmp_path / "run"
    run.mkdir()
    for name in ("segments.parquet", "segment_month.parquet"):
        shutil.copy(Path(small_run) / name, run / name)
    table = pq.read_table(run / "segment_month.parquet")
    tiles = table.column("tile").to_pylist()
    tiles[len(tiles) // 2] = "E9999N9999"
    i = table.schema.get_field_index("tile")
    pq.write_table(table.set_column(i, table.schema.field(i), pa.array(tiles, table.schema.field(i).type)),
                   run / "segment_month.parquet")
    with pytest.raises(ValueError, match=r"segment_month\.parquet: rows of tiles without segments"):
        write_datasets(run)
