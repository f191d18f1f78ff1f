"""The store names every file the pipeline writes, its partitions hold the key columns it
declares, and its writers leave the old file or the new one, never a part."""
from __future__ import annotations

import json
import os
import re

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from vipvflow.errors import InputError
from vipvflow.simulation.dictionary import OUTPUTS
from vipvflow.simulation.rundir import open_run
from vipvflow.store import (ALL_MONTHS, GEOMETRY_CACHE_FILES, GTFS_TABLES, HOURLY_METADATA, PARTS,
                            TIMELINE_TABLES, DataDir, RunDir, atomic_path, remove_stale, staging_dir,
                            swap_dir, write_json)


def _named_by_store(data_dir, run_dir) -> set:
    """Every file the store names for this data dir and run (the run's tiles and months)."""
    data, run = DataDir(data_dir), RunDir(run_dir)
    manifest = json.loads(run.manifest.read_text())
    year, months = manifest["year"], manifest["config"]["run"]["months"]
    tiles = set(json.loads(data.city.tiles_json.read_text())["tiles"])
    tiles |= set(pd.read_parquet(data.gtfs.segments, columns=["tile"])["tile"].astype(str))
    city, gtfs, rad = data.city, data.gtfs, data.radiation
    names = {city.tiles_json, city.report, city.stamp, city.terrain, city.coverage,
             gtfs.feed_json, gtfs.stamp, rad.table, rad.report, rad.stamp,
             run.manifest, run.config_stamp, run.inputs_stamp, run.report,
             run.output("summary.json"), run.output("city.glb")}
    names |= {city.mesh(t) for t in tiles} | {city.surface_part(t) for t in tiles}
    names |= {city.tree_points} | {city.trees_file(t) for t in tiles}     # the trees' crowns
    names |= {gtfs.table(n) for n in GTFS_TABLES}
    # the geometry cache's entries, each of its two files (their keys: content digests)
    if data.geometry_cache().is_dir():
        names |= {e / n for e in data.geometry_cache().iterdir() for n in GEOMETRY_CACHE_FILES}
    names |= {run.output(f"{name}.parquet") for name in OUTPUTS}
    names |= {run.timeline_table(n) for n in TIMELINE_TABLES}
    for kind, spec in PARTS.items():
        if spec.per == "tile/month":
            names |= {run.part(kind, t, m) for t in tiles
                      for m in [f"{year}-{m:02d}" for m in months] + [ALL_MONTHS]}
        elif spec.per == "tile":
            names |= {run.tile_part(kind, t) for t in tiles}
    return names


def test_every_file_of_a_run_is_one_the_store_names(small_run):
    run = RunDir(small_run)
    data = DataDir(open_run(run.root).data_dir)
    named = _named_by_store(data.root, run.root)
    written = {p for root in (data.root, run.root) for p in root.rglob("*") if p.is_file()}
    # figures, VECTO files, the datasets' partitions and the table and sky caches are named by
    # the modules that draw or compute them, in the folders the store gives them
    datasets = {run.dataset("segments"), run.dataset("segment_month")}
    free = [p for p in written
            if run.figures in p.parents or run.vecto in p.parents or p.parent in datasets
            or (p.parent == data.radiation.root and p.name.startswith(("table_", "sky_")))]
    assert all(p.suffix == ".png" for p in free if run.figures in p.parents)
    parts = [p.name for p in free if p.parent in datasets]
    assert parts and all(re.fullmatch(r"part\.\d+\.parquet", n) for n in parts), parts
    unnamed = sorted(str(p) for p in written - named - set(free))
    assert unnamed == [], "files the store does not name (or temporaries left):\n" + "\n".join(unnamed)
    # and the run wrote what the store promises: every partition of every tile it computed
    computed = {p.parent.name[5:] for p in run.part_files("segment_month")}
    assert computed, "no partitions"
    for tile in computed:
        assert run.tile_part("geometry", tile).is_file() and run.tile_part("horizon", tile).is_file()


def test_every_entry_of_a_run_folder_is_one_a_run_writes(small_run):
    """``simulate --force`` replaces a folder holding only what a run writes: a finished run
    holds nothing else (an output added without its name in the data dictionary fails here)."""
    entries = sorted(p.name for p in small_run.iterdir())
    assert "manifest.json" in entries and "parts" in entries
    assert [e for e in entries if not RunDir.written_by_run(e)] == []
    assert not RunDir.written_by_run("notes.txt") and not RunDir.written_by_run("my.parquet")


def test_partitions_hold_the_key_columns_the_store_declares(small_run):
    run = RunDir(small_run)
    seen = set()
    for kind, spec in PARTS.items():
        for path in run.part_files(kind):
            schema = pq.read_schema(path)
            for column, arrow_type in spec.key.items():
                assert str(schema.field(column).type) == arrow_type, (path, column)
            seen.add(kind)
    assert {"trip", "segment_month", "geometry", "horizon", "timeline"} <= seen
    assert "hourly" not in seen           # the sums per local hour are in the segment files
    for path in run.part_files("segment_month"):
        hourly = json.loads(pq.read_schema(path).metadata[HOURLY_METADATA])
        assert set(hourly) >= {"hour", "h_total", "seconds"}, path
        assert len(set(hourly["hour"])) == len(hourly["hour"]) <= 24, path


def test_paths_of_a_kind_stored_otherwise_are_refused(tmp_path):
    run = RunDir(tmp_path)
    assert run.part("trip", "E1N2", "2024-06") == tmp_path / "parts/trip/tile=E1N2/month=2024-06.parquet"
    assert run.tile_part("geometry", "E1N2") == tmp_path / "parts/geometry/tile=E1N2.parquet"
    with pytest.raises(ValueError):
        run.part("geometry", "E1N2", "2024-06")
    with pytest.raises(ValueError):
        run.tile_part("trip", "E1N2")
    with pytest.raises(ValueError):
        DataDir(tmp_path).gtfs.table("stop_times")


def test_tile_size_from_the_feed_then_the_city_else_one_line(tmp_path):
    data = DataDir(tmp_path)
    with pytest.raises(InputError, match=r"gtfs/feed.json: not found.*ingest gtfs"):
        data.tile_size_m()
    write_json({"crs": "EPSG:2169", "tile_size_m": 250, "tiles": {}}, data.city.tiles_json)
    assert data.tile_size_m() == 250.0
    write_json({"tile_size_m": 1000}, data.gtfs.feed_json)
    assert data.tile_size_m() == 1000.0
    data.gtfs.feed_json.write_text("[1, 2]")
    with pytest.raises(InputError, match="feed.json: not a JSON object"):
        data.tile_size_m()


def test_a_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path):
    path = write_json({"v": 1}, tmp_path / "a.json")
    with pytest.raises(RuntimeError):
        with atomic_path(path) as tmp:
            tmp.write_text('{"v": 2')          # half written, then the writer fails
            raise RuntimeError("killed")
    assert json.loads(path.read_text()) == {"v": 1}
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]


def test_a_folder_swapped_whole_and_a_killed_swap_repaired(tmp_path):
    final = tmp_path / "gtfs"
    final.mkdir()
    (final / "old.txt").write_text("old")
    stage = staging_dir(final)
    (stage / "new.txt").write_text("new")
    swap_dir(stage, final)
    assert [p.name for p in final.iterdir()] == ["new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gtfs"]
    # a kill between the two renames of a swap: the previous version lies aside, none in place
    dead = 2 ** 22 + 1
    while True:
        try:
            os.kill(dead, 0)
            dead += 1
        except ProcessLookupError:
            break
        except PermissionError:
            dead += 1
    final.rename(tmp_path / f".gtfs-old-{dead}")
    remove_stale(final)
    assert (final / "new.txt").read_text() == "new"


def test_wide_and_float32_tables_read_back_as_written(tmp_path):
    """The writer's fast paths: a wide table (the geometry partitions) taken out one dtype
    block at a time, and float columns stored as float32 by prefix, read back equal to the
    frame (the float32 ones equal to numpy's rounding)."""
    import numpy as np

    from vipvflow.models.view_factors import _frame_by_dtype
    from vipvflow.store import WIDE_COLUMNS, write_parquet

    rng = np.random.default_rng(7)
    n = 50
    columns = {"segment_id": np.arange(n, dtype=np.int64), "name": [f"s{i}" for i in range(n)]}
    for k in range(WIDE_COLUMNS + 40):
        columns[f"p{k}"] = rng.random(n) if k % 3 else rng.random(n).astype(np.float32)
    columns["surface"] = rng.integers(0, 9, n).astype(np.int32)
    wide = _frame_by_dtype({k: v for k, v in columns.items() if k != "name"})
    plain = pd.DataFrame({k: v for k, v in columns.items() if k != "name"})
    pd.testing.assert_frame_equal(wide, plain)          # same columns, order and dtypes
    wide["name"] = columns["name"]
    back = pd.read_parquet(write_parquet(wide, tmp_path / "wide.parquet"))
    pd.testing.assert_frame_equal(back, wide, check_dtype=False)
    assert list(back.dtypes[:3].astype(str)) == ["int64", "float32", "float64"]

    trip = pd.DataFrame({"trip_id": ["a", "b"], "pv_kwh": [1.0 / 3, 2.0], "pv_kwh_x": [0.1, 0.2],
                         "seconds": [61.7, 12.0], "other": [1.0 / 3, 0.5]})
    back = pd.read_parquet(write_parquet(trip, tmp_path / "trip.parquet", compact=True,
                                         float32=("pv_kwh", "seconds")))
    for c in ("pv_kwh", "pv_kwh_x", "seconds"):
        assert back[c].dtype == np.float32
        np.testing.assert_array_equal(back[c].to_numpy(), trip[c].to_numpy().astype(np.float32))
    assert back["other"].dtype == np.float64 and back["other"][0] == 1.0 / 3


def test_nullable_numbers_keep_their_type_and_their_gaps_as_nulls(tmp_path):
    """pandas' nullable integers and bools (a route's ``direction_id`` where the feed leaves it
    out) are written as the integers and bools they are, each gap a null: not a double with
    NaN in its place; a table of plain strings beside them keeps Arrow's plain strings."""
    from vipvflow.store import write_parquet

    frame = pd.DataFrame({"route_id": ["a", "b", "c"],
                          "direction_id": pd.array([0, None, 1], dtype="Int32"),
                          "wheelchair": pd.array([True, None, False], dtype="boolean"),
                          "pv_kwh": [1.0, 2.0, 3.0]})
    table = pq.read_table(write_parquet(frame, tmp_path / "routes.parquet"))
    assert [str(f.type) for f in table.schema] == ["string", "int32", "bool", "double"]
    assert table.column("direction_id").to_pylist() == [0, None, 1]
    assert table.column("wheelchair").to_pylist() == [True, None, False]


def test_runs_with_hourly_files_reduce_to_the_same_hours(small_run, tmp_path):
    """A run folder written before the sums per local hour moved into the segment files'
    metadata (one ``parts/hourly`` file per partition) reduces to the same sums; a segment
    file with neither is named."""
    import shutil

    import pyarrow as pa

    from vipvflow.simulation.reduce import partial_sums

    old = tmp_path / "run"
    shutil.copytree(small_run / "parts", old / "parts")
    run = RunDir(old)
    files = run.part_files("segment_month")
    for path in files:
        table = pq.read_table(path)
        meta = dict(table.schema.metadata)
        hourly = json.loads(meta.pop(HOURLY_METADATA))
        legacy = run.part("hourly", path.parent.name[5:], path.stem[6:])
        legacy.parent.mkdir(parents=True, exist_ok=True)
        pq.write_table(pa.table({**hourly, "hour": pa.array(hourly["hour"], pa.int8())}), legacy)
        pq.write_table(table.replace_schema_metadata(meta), path)
    want = partial_sums(small_run)["hourly"]
    got = partial_sums(old)["hourly"]
    assert len(want) and want["hour"].dtype == np.int8
    pd.testing.assert_frame_equal(got, want)
    run.part("hourly", files[0].parent.name[5:], files[0].stem[6:]).unlink()
    with pytest.raises(InputError, match=f"{files[0]}: no sums per local hour"):
        partial_sums(old)
