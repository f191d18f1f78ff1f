"""The reduce's reading of partition files: one Arrow dataset per kind, trips summed in Arrow."""
from __future__ import annotations

import json
import logging
import os
import subprocess
import sys
import threading

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from vipvflow.errors import InputError
from vipvflow.simulation.reduce import (_join_months, _months_frame, _part_table, _trip_totals,
                                       forget_and_hand_back, segment_month_part, sum_trips)
from vipvflow.store import HOURLY_METADATA, RunDir, write_parquet, write_parquet_parts

PV = ["pv_kwh", "pv_kwh_clear", "pv_kwh_direct"]


def _trip_part(rng, trips, dates) -> pd.DataFrame:
    rows = [(t, d) for t in trips for d in dates]
    df = pd.DataFrame(rows, columns=["trip_id", "service_date"])
    df["service_date"] = pd.to_datetime(df["service_date"])
    for c in PV + ["seconds"]:
        df[c] = rng.random(len(df))
    return df


def test_trips_are_summed_over_tiles_and_sorted(tmp_path):
    rng = np.random.default_rng(3)
    parts = []
    for tile, trips in [("a", ["t2", "t1"]), ("b", ["t1", "t3"]), ("c", ["t3", "t2", "t1"])]:
        for month, dates in [("2024-01", ["2024-01-02", "2024-01-01"]), ("2024-02", ["2024-02-05"])]:
            df = _trip_part(rng, trips, dates)
            df["tile"] = tile
            write_parquet(df, RunDir(tmp_path).part("trip", tile, month))
            parts.append(df)
    # a partition without passes
    write_parquet(parts[0].iloc[:0], RunDir(tmp_path).part("trip", "d", "2024-01"))
    got = _trip_totals(tmp_path)
    want = (pd.concat(parts).groupby(["trip_id", "service_date"], sort=True)[PV + ["seconds"]]
            .sum().reset_index())
    assert list(got.columns) == ["trip_id", "service_date"] + PV + ["seconds"]
    assert got[["trip_id", "service_date"]].equals(want[["trip_id", "service_date"]])
    np.testing.assert_allclose(got[PV + ["seconds"]].to_numpy(), want[PV + ["seconds"]].to_numpy(),
                               rtol=1e-14)
    assert len(got) == 3 * 3


def test_trip_files_read_a_few_at_a_time_are_summed_as_all_at_once(tmp_path, monkeypatch):
    """A task reads its trip files a few at a time, each group summed into the sums so far:
    the sums are bit for bit those of every row in file order (each key's values added one
    after another), whatever the group size."""
    from vipvflow.simulation import reduce as R

    rng = np.random.default_rng(11)
    files, rows = [], []
    for i in range(7):
        df = _trip_part(rng, [f"t{j}" for j in rng.permutation(6)[:4]], ["2024-03-01", "2024-03-02"])
        for c in PV + ["seconds"]:                 # magnitudes whose order of addition shows
            df[c] = rng.standard_normal(len(df)) * 10.0 ** rng.integers(-4, 7, len(df))
        files.append(str(write_parquet(df, tmp_path / f"tile=x{i}" / "month=2024-03.parquet")))
        rows.append(df)
    whole = pd.concat(rows, ignore_index=True)
    for size in (1, 2, 3, 100):
        monkeypatch.setattr(R, "TRIP_READ_FILES", size)
        got = sum_trips(files).to_pandas()
        for (trip, date), g in whole.groupby(["trip_id", "service_date"], sort=True):
            one = got[(got["trip_id"] == trip) & (got["service_date"] == date)]
            for c in PV + ["seconds"]:              # one after another, from zero
                assert one[c].item() == np.cumsum(g[c].to_numpy(np.float64))[-1], (size, trip, c)
        assert got[["trip_id", "service_date"]].equals(
            whole[["trip_id", "service_date"]].drop_duplicates().sort_values(["trip_id", "service_date"])
            .reset_index(drop=True))


def test_months_are_joined_as_the_sum_of_all_their_rows(tmp_path):
    """A trip past midnight at a month's end is in two months' sums: the join sums those
    rows again and takes the rest as they are; the table is the whole's sum, exactly."""
    rng = np.random.default_rng(5)
    months = {"2024-01": ["2024-01-30", "2024-01-31"], "2024-02": ["2024-01-31", "2024-02-01", "2024-02-29"],
              "2024-03": ["2024-02-29", "2024-03-01"], "2024-05": ["2024-05-02"]}
    tables = []
    for month, dates in months.items():
        df = _trip_part(rng, ["t2", "t10", "t1"], dates).iloc[::-1]
        df["tile"] = "a"
        write_parquet(df, RunDir(tmp_path / month).part("trip", "a", month))
        tables.append(sum_trips([RunDir(tmp_path / month).part("trip", "a", month)]))
    got = _join_months(tables + [None])
    assert got.equals(sum_trips(tables))
    assert got.num_rows == 3 * 6                  # 6 service dates, two of them in two months
    twice = got.to_pandas().set_index(["trip_id", "service_date"]).loc[("t10", pd.Timestamp("2024-01-31"))]
    jan, feb = (t.to_pandas().set_index(["trip_id", "service_date"]).loc[("t10", pd.Timestamp("2024-01-31"))]
                for t in tables[:2])
    assert twice["pv_kwh"] == jan["pv_kwh"] + feb["pv_kwh"]
    assert _join_months(tables[:1]) is tables[0] and _join_months([]) is None


def test_the_months_segment_tables_are_one_frame_with_tile_and_month(tmp_path):
    """The months' segment tables (Arrow, from the cluster) make the frame the months'
    DataFrames concatenated would: the same columns, dtypes and values, each row with the
    tile and month of its file (as categories: the same strings); an older run's DataFrame
    joins them."""
    rng = np.random.default_rng(7)
    parts, want = [], []
    for month in ("2024-01", "2024-02"):
        files = []
        for tile, n in (("E1", 3), ("E2", 2)):
            df = pd.DataFrame({"segment_id": np.arange(n, dtype=np.int64), "h_total": rng.random(n),
                               "shape_id": [f"s{i}" for i in range(n)]})
            files.append(RunDir(tmp_path).part("segment_month", tile, month))
            hourly = json.dumps({"hour": [12], "h_total": [float(df["h_total"].sum())], "seconds": [1.0]})
            write_parquet(pa.Table.from_pandas(df, preserve_index=False)
                          .replace_schema_metadata({HOURLY_METADATA: hourly}), files[-1])
            want.append(df.assign(tile=tile, month=month))
        parts.append(segment_month_part([str(f) for f in files], month)[0])
    got = _months_frame(list(parts))
    assert all(isinstance(got[c].dtype, pd.CategoricalDtype) for c in ("tile", "month"))
    pd.testing.assert_frame_equal(got.astype({"tile": "str", "month": "str"}), pd.concat(want, ignore_index=True),
                                  check_exact=True)
    older = want[0].copy()
    mixed = _months_frame([parts[1], older])
    pd.testing.assert_frame_equal(mixed, pd.concat(want[2:] + [older], ignore_index=True), check_exact=True)
    assert _months_frame([]).empty


#: the months' tables received from a worker and made one (``segments``: the frame of the
#: segment-months, ``trips``: the trips' sums joined), the peak RSS over what they take
#: when received printed (a process of its own, each allocation of its heap above 64 kB
#: mapped apart, so what is freed leaves its RSS)
MONTHS_JOIN_PEAK = """
import sys, threading, time
import numpy as np, psutil, pyarrow as pa
from dask.distributed import Client, LocalCluster
from vipvflow.simulation.partition import arrow_on_the_heap
from vipvflow.simulation.reduce import _join_months, _months_frame

N = 1_000_000

def segments(m):
    import numpy as np, pyarrow as pa
    rng = np.random.default_rng(m)
    return pa.table({f"h_{i}": rng.random(N) for i in range(8)} | {"tile": pa.array(["E1"] * N)})

def trips(m):
    import numpy as np, pyarrow as pa
    rng = np.random.default_rng(m)
    ids = np.char.add("t", np.char.zfill(np.arange(N).astype(str), 7)).astype(object)
    date = pa.array(np.full(N, np.datetime64(f"2024-0{m + 1}-01", "ns")))
    return pa.table({"trip_id": pa.array(ids, pa.string()), "service_date": date}
                    | {f"pv_kwh_{i}": rng.random(N) for i in range(5)} | {"seconds": rng.random(N)})

if __name__ == "__main__":
    kind = sys.argv[1]
    arrow_on_the_heap()
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \\
            Client(cluster) as client:
        parts = [client.submit(globals()[kind], m, pure=False).result() for m in range(4)]
    size = sum(t.nbytes for t in parts)
    me, peak, done = psutil.Process(), [0], threading.Event()
    def sample():
        while not done.is_set():
            peak[0] = max(peak[0], me.memory_info().rss)
            time.sleep(0.001)
    base = me.memory_info().rss
    sampler = threading.Thread(target=sample)
    sampler.start()
    out = _months_frame(parts) if kind == "segments" else _join_months(parts)
    done.set()
    sampler.join()
    assert len(out) == 4 * N and parts == []
    print(size / 2**20, (peak[0] - base) / 2**20)
"""


@pytest.mark.parametrize("kind", ["segments", "trips"])
def test_the_months_received_from_the_cluster_are_joined_holding_them_once(tmp_path, kind):
    """The months' tables as a worker sends them (each column a view of the message it was
    received in) are made one holding little more than the tables: each month is copied out
    of its message and the message let go, then the months' columns are joined one at a
    time, each released as it is (joined as received, every message stayed until the last
    column was, beside the whole result: twice the tables)."""
    script = tmp_path / "months_join_peak.py"
    script.write_text(MONTHS_JOIN_PEAK)
    env = {**os.environ, "MALLOC_MMAP_THRESHOLD_": "65536"}
    proc = subprocess.run([sys.executable, str(script), kind], capture_output=True, text=True, env=env,
                          cwd=tmp_path, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    size, peak = (float(v) for v in proc.stdout.split()[-2:])
    # measured: segments 0.25 of the tables (0.97 as received), trips 0.72 (1.5: the taken
    # keys, the sort's indices and the columns taken are temporaries of their own)
    assert peak < {"segments": 0.5, "trips": 1.0}[kind] * size, (size, peak)


def test_files_with_different_schemas_are_promoted(tmp_path):
    a = pd.DataFrame({"segment_id": np.array([1, 2], np.int64), "h_total": [1.0, 2.0]})
    b = pd.DataFrame({"segment_id": np.array([3], np.int32), "h_total": np.array([3.0], np.float32)})
    write_parquet(a, RunDir(tmp_path).part("segment_month", "a", "2024-01"))
    write_parquet(b, RunDir(tmp_path).part("segment_month", "b", "2024-01"))
    got = _part_table(tmp_path, "segment_month").to_pandas()
    assert got["segment_id"].tolist() == [1, 2, 3]
    assert got["h_total"].tolist() == [1.0, 2.0, 3.0]


def test_a_run_without_any_pass_is_named(tmp_path):
    empty = _trip_part(np.random.default_rng(0), ["t1"], ["2024-01-01"]).iloc[:0]
    write_parquet(empty, RunDir(tmp_path).part("trip", "a", "2024-01"))
    with pytest.raises(InputError, match="no trip partitions with passes"):
        _trip_totals(tmp_path)
    with pytest.raises(InputError, match="parts/trip"):
        _trip_totals(tmp_path / "elsewhere")


def test_trip_sums_from_unaligned_buffers_are_summed_without_a_warning(capfd):
    """Trip sums that crossed processes may hold buffers off 8-byte alignment (unpickled Arrow
    tables): they are summed as any others, with nothing printed to stderr."""
    import pyarrow as pa

    from vipvflow.simulation.reduce import sum_trips

    def unaligned(values: np.ndarray) -> pa.Array:
        raw = np.zeros(values.nbytes + 1, np.uint8)
        raw[1:] = values.view(np.uint8)
        return pa.array(np.frombuffer(raw.data, dtype=values.dtype, count=len(values), offset=1))

    n = 1000
    tables = [pa.table({"trip_id": pa.array([f"t{i % 7}" for i in range(n)]),
                        "service_date": pa.array(np.full(n, np.datetime64("2024-06-03", "ns"))),
                        "pv_kwh": unaligned(np.arange(n, dtype=np.float64) + k),
                        "seconds": unaligned(np.ones(n))}) for k in (0, 1)]
    got = sum_trips(tables).to_pandas()
    assert got["trip_id"].tolist() == [f"t{i}" for i in range(7)]
    assert got["pv_kwh"].sum() == 2 * np.arange(n).sum() + n and got["seconds"].sum() == 2 * n
    assert "aligned" not in capfd.readouterr().err


def test_a_worker_hands_back_once_it_has_dropped_the_results():
    """The reduce's sums gathered, each worker waits until it has dropped them (a release
    reaches it on its own), then hands back what they took; a result still held does not
    stop it past its wait."""
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        def held(dask_worker=None):
            return key in dask_worker.data

        future = client.submit(np.ones, 1000, pure=False)
        future.result()
        key = future.key
        threading.Timer(1.0, future.release).start()    # released while the worker waits
        client.run(forget_and_hand_back, [key])
        assert list(client.run(held).values()) == [False]

        kept = client.submit(np.ones, 1000, pure=False)
        kept.result()
        key = kept.key
        client.run(forget_and_hand_back, [key], wait_s=0.2)
        assert list(client.run(held).values()) == [True]


def test_a_runs_workers_are_new_processes_with_the_consumption_fetched_before(caplog):
    """Before the reduce, a run's LocalCluster has as many workers as before, each a new
    process (the map's heaps let go), and the nannies' warnings of it are not shown; the
    patterns' consumption, fetched first, stays."""
    from dask.distributed import Client, LocalCluster

    from vipvflow.simulation.cluster import fresh_workers
    from vipvflow.simulation.reduce import Consumption

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        before = set(client.run(os.getpid).values())
        made = Consumption([client.submit(dict, a=1, pure=False), client.submit(dict, b=2, pure=False)], {})
        assert made.results() == {"a": 1, "b": 2} and made.futures == []
        said = []
        with caplog.at_level(logging.WARNING, logger="distributed.nanny"):
            assert fresh_workers(client, said.append) > 0
        after = set(client.run(os.getpid).values())
        assert len(after) == 2 and not after & before and said == []
        assert "Restarting worker" not in caplog.text
        assert made.results() == {"a": 1, "b": 2}
        assert client.submit(sum, [1, 2], pure=False).result() == 3


def test_the_sums_on_a_runs_own_cluster_restart_its_workers_once_gathered(small_run, tmp_path):
    """The sums on a run's own LocalCluster equal those made in this process, and its
    workers are new processes once they are gathered (what the sums' reads left in their
    heaps let go)."""
    import shutil

    from dask.distributed import Client, LocalCluster

    from vipvflow.simulation import reduce as R
    from vipvflow.simulation.cluster import fresh_workers

    run = tmp_path / "run"
    shutil.copytree(small_run / "parts", run / "parts")
    want = R.partial_sums(run)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        before = set(client.run(os.getpid).values())
        got = R.partial_sums(run, client, lambda: fresh_workers(client))
        after = set(client.run(os.getpid).values())
    assert len(after) == 2 and not after & before
    assert got["trip"].equals(want["trip"])
    for name in ("segment_month", "hourly", "geometry"):
        pd.testing.assert_frame_equal(got[name], want[name], check_exact=True)


def test_the_reduces_tail_keeps_one_new_worker_of_a_runs_cluster(caplog):
    """Once the sums are gathered, a run's LocalCluster keeps one worker, a new process (the
    other closed with its nanny, not restarted), and no nanny's warning is shown; a
    cluster of one worker has it restarted."""
    import psutil
    from dask.distributed import Client, LocalCluster

    from vipvflow.simulation.cluster import fewer_fresh_workers

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        before = set(client.run(os.getpid).values())
        said = []
        with caplog.at_level(logging.WARNING, logger="distributed.nanny"):
            assert fewer_fresh_workers(client, cluster, said.append) > 0
        after = set(client.run(os.getpid).values())
        assert len(after) == 1 and not after & before and said == []
        assert len(cluster.workers) == 1 and len(cluster.worker_spec) == 1
        assert "Restarting worker" not in caplog.text
        assert client.submit(sum, [1, 2], pure=False).result() == 3
        fewer_fresh_workers(client, cluster, said.append)
        again = set(client.run(os.getpid).values())
        assert len(again) == 1 and not again & after and said == []
    assert not any(psutil.pid_exists(p) for p in before | after | again)


def test_segment_month_is_written_in_parts_as_the_whole_merge_was(tmp_path, monkeypatch):
    """segment_month.parquet, written a slice of rows at a time, holds what writing the
    merge of the segments, their month rows and the shapes' routes at once wrote: the
    merge's row order (a row whose segment is not run dropped, a shape without routes
    null), schema and metadata; in one part, the same bytes."""
    import geopandas as gpd
    from shapely.geometry import LineString

    from vipvflow.simulation import reduce as R

    segments = gpd.GeoDataFrame(
        {"segment_id": [7, 3, 5, 9], "shape_id": ["b", "a", "b", "c"], "length_m": [10.0] * 4},
        geometry=[LineString([(i, 0, 3.2), (i + 1, 1 + i, 3.2)]) for i in range(4)], crs="EPSG:25833")
    rng = np.random.default_rng(5)
    sm = pd.DataFrame({"segment_id": [5, 3, 11, 7, 5, 3, 9, 7],
                       "month": ["2024-01"] * 4 + ["2024-02"] * 4,
                       "n_passes": rng.integers(1, 50, 8), "pv_kwh": rng.random(8)})
    for c in ("h_direct", "h_diffuse", "h_reflected", "h_total_unshaded", "h_direct_clear",
              "h_diffuse_clear", "h_total_clear_unshaded"):
        sm[c] = rng.random(8) * 1000.0
    sm.loc[2, "h_total_unshaded"] = 0.0           # no light: no loss or gain
    shape_route = pd.DataFrame({"shape_id": ["a", "b"],
                                "route_short_name": pd.array(["1", "2, 3"], dtype="string"),
                                "direction_id": pd.array([0, pd.NA], dtype="Int32")})
    # with the losses of each row (made a part at a time)
    unshaded = sm["h_total_unshaded"].where(sm["h_total_unshaded"] > 0)
    losses = sm.assign(shading_loss=1.0 - (sm["h_direct"] + sm["h_diffuse"]) / unshaded,
                       shading_loss_clear=1.0 - (sm["h_direct_clear"] + sm["h_diffuse_clear"])
                       / sm["h_total_clear_unshaded"],
                       reflection_gain=sm["h_reflected"] / unshaded)
    whole = segments[["segment_id", "shape_id", "geometry"]].merge(losses, on="segment_id", how="inner")
    whole = gpd.GeoDataFrame(whole.merge(shape_route, on="shape_id", how="left"), geometry="geometry",
                             crs=segments.crs)
    at_once = write_parquet(whole, tmp_path / "whole" / "segment_month.parquet")

    rows, geo = R._segment_month_rows(segments, sm, shape_route)
    one = write_parquet_parts(rows, tmp_path / "one" / "segment_month.parquet", geo)
    assert one.read_bytes() == at_once.read_bytes()

    # parts of 2 rows in row groups of 3: a row group made of parts, a part split by one
    monkeypatch.setattr(R, "SEGMENT_MONTH_PART_ROWS", 2)
    rows, geo = R._segment_month_rows(segments, sm, shape_route)
    parts = write_parquet_parts(rows, tmp_path / "parts" / "segment_month.parquet", geo, row_group_rows=3)
    a, b = pq.read_table(at_once), pq.read_table(parts)
    assert b.schema.equals(a.schema, check_metadata=True) and b.equals(a)
    file = pq.ParquetFile(parts).metadata
    assert [file.row_group(i).num_rows for i in range(file.num_row_groups)] == [3, 3, 1]
    assert b.column("segment_id").to_pylist() == [7, 7, 3, 3, 5, 5, 9]


def test_the_reduce_writes_segment_months_and_trips_in_row_groups_of_their_own(small_config, small_run,
                                                                               tmp_path, monkeypatch):
    """The reduce writes ``segment_month.parquet`` and ``trip_energy.parquet`` in row groups
    of ``SEGMENT_MONTH_GROUP_ROWS`` and ``TRIP_GROUP_ROWS`` rows, not pyarrow's 1 M (a
    network's row group was ~0.35 and ~0.25 GB of Arrow columns held beside the
    segment-months or the trips until it was written): the same rows and schema as the run's
    files, in row groups of that size."""
    import shutil

    from vipvflow.config import load_config
    from vipvflow.simulation import reduce as R

    run = tmp_path / "run"
    shutil.copytree(small_run / "parts", run / "parts")
    shutil.copy(small_run / "manifest.json", run / "manifest.json")
    cfg = load_config(small_config)
    parts = R.partial_sums(run)                         # in this process
    totals = R._trip_totals(run, parts.pop("trip"))
    placed = R._placed_trips(run, totals)
    n_buses = int(placed.groupby("service_date")["block_id"].nunique().max())
    trips_meta = pd.read_parquet(R.DataDir(cfg.data_dir).gtfs.trips)
    groups = {}
    for name, const, part in (("segment_month", "SEGMENT_MONTH_GROUP_ROWS", "SEGMENT_MONTH_PART_ROWS"),
                              ("trip_energy", "TRIP_GROUP_ROWS", "TRIP_PART_ROWS")):
        groups[name] = max(pq.read_metadata(small_run / f"{name}.parquet").num_rows // 3, 2)
        monkeypatch.setattr(R, part, max(groups[name] // 3, 1))
        monkeypatch.setattr(R, const, groups[name])
    R._segment_outputs(cfg, run, parts["segment_month"], parts["geometry"], totals, n_buses, trips_meta)
    R._trip_outputs(cfg, 2024, run, totals, placed, trips_meta, say=lambda *a: None)

    for name, group in groups.items():
        path = RunDir(run).output(f"{name}.parquet")
        got, want = pq.read_table(path), pq.read_table(small_run / f"{name}.parquet")
        assert got.schema.equals(want.schema, check_metadata=True) and got.equals(want), name
        meta = pq.read_metadata(path)
        sizes = [meta.row_group(i).num_rows for i in range(meta.num_row_groups)]
        assert sizes[:-1] == [group] * (len(sizes) - 1) and 0 < sizes[-1] <= group and len(sizes) >= 3, (
            name, sizes)


def test_the_service_intervals_are_each_kind_of_the_buses_in_service_in_file_order(tmp_path):
    """The layovers and parked intervals the battery's day takes, read a batch at a time:
    each kind's rows in the file's order, without the idle buses' block or other kinds."""
    from vipvflow.inputs.gtfs.schedule import IDLE_BLOCK
    from vipvflow.simulation import reduce as R

    rng = np.random.default_rng(2)
    n = 5000
    iv = pd.DataFrame({"block_id": rng.choice(["b1", "b2", IDLE_BLOCK], n),
                       "service_date": pd.to_datetime("2024-06-01") + pd.to_timedelta(rng.integers(0, 3, n), "D"),
                       "kind": rng.choice(["layover", "parked", "driving"], n),
                       "after_trip": rng.integers(-1, 9, n), "point_id": rng.integers(0, 50, n),
                       "t0_utc": rng.random(n), "t1_utc": rng.random(n) + 1})
    path = write_parquet(iv, tmp_path / "intervals.parquet")
    cols = ["block_id", "service_date", "after_trip", "point_id", "t0_utc", "t1_utc"]
    pq.write_table(pq.read_table(path), tmp_path / "small_groups.parquet", row_group_size=700)
    for f in (path, tmp_path / "small_groups.parquet"):
        lay, parked = R._service_intervals(f, ("layover", "parked"), cols)
        for got, kind in ((lay, "layover"), (parked, "parked")):
            want = iv[(iv["block_id"] != IDLE_BLOCK) & (iv["kind"] == kind)][cols].reset_index(drop=True)
            pd.testing.assert_frame_equal(got, want)


def test_trips_placed_by_their_keys_are_those_of_the_left_join(tmp_path):
    """Each trip-day's block and position (:func:`_placed_trips`, keys looked up in Arrow)
    is what the left join on (trip, date) gives, row by row with the trips: with every trip
    in the timeline, and with some in none (missing, as the join leaves them); a key given
    twice is refused."""
    from vipvflow.simulation.reduce import _placed_trips, _rows_of_trip_days

    rng = np.random.default_rng(5)
    days = pd.date_range("2024-03-30", periods=4, freq="D")
    runs = pd.DataFrame([(f"t{i}", d) for i in range(60) for d in days if rng.random() < 0.8],
                        columns=["trip_id", "service_date"]).sample(frac=1.0, random_state=1)
    runs["block_id"] = rng.choice(["b1", "b 2", "x"], len(runs))
    runs["position"] = rng.integers(0, 9, len(runs))
    write_parquet(runs, RunDir(tmp_path).timeline_table("trip_runs"))
    runs = pd.read_parquet(RunDir(tmp_path).timeline_table("trip_runs"))
    for totals in (runs[["trip_id", "service_date"]].sample(frac=0.7, random_state=2),
                   pd.concat([runs[["trip_id", "service_date"]].iloc[:30],
                              pd.DataFrame({"trip_id": ["t3", "nope"],
                                            "service_date": pd.to_datetime(["2024-05-01", "2024-03-31"])})])):
        totals = totals.reset_index(drop=True).astype({"trip_id": object})
        want = (totals.merge(runs, on=["trip_id", "service_date"], how="left", validate="one_to_one")
                [["service_date", "block_id", "position"]])
        pd.testing.assert_frame_equal(_placed_trips(tmp_path, totals), want, check_exact=True)
    assert (_rows_of_trip_days(runs, totals) < 0).sum() == 2
    with pytest.raises(ValueError, match="twice"):
        _rows_of_trip_days(pd.concat([runs, runs.iloc[:1]]), totals)


def test_segment_sums_take_the_road_without_the_segments_inside_buildings():
    """The fleet-year's light sums: every segment-month row for the roofs' light; for the
    shading statistics only the road's (a segment inside a building footprint left out, a
    segment the flags do not know taken as road); the passes and each segment's sums."""
    from vipvflow.simulation import reduce as R

    segments = pd.DataFrame({"segment_id": [4, 1, 2], "length_m": [10.0, 10.0, 5.0],
                             "in_city_model": [True, True, False], "in_building": [False, True, False]})
    sm = pd.DataFrame({"segment_id": [1, 4, 2, 1, 4, 9],
                       "n_passes": [1, 2, 3, 4, 5, 6],
                       "seconds": [1.0] * 6, "pv_kwh": [0.5] * 6,
                       "h_direct": [1.0, 2.0, 4.0, 8.0, 16.0, 32.0],
                       "h_diffuse": [0.5, 0.25, 0.125, 1.0, 2.0, 4.0],
                       "h_total_unshaded": [10.0, 20.0, 30.0, 40.0, 50.0, 60.0]})
    s = R._SegmentSums.of(sm, segments)
    assert s.light.to_dict() == {"h_direct": 63.0, "h_diffuse": 7.875, "h_total_unshaded": 210.0}
    # segment 1 (inside a building) left out of the road; segment 9 (unknown) kept
    assert s.road.to_dict() == {"h_direct": 54.0, "h_diffuse": 6.375, "h_total_unshaded": 160.0}
    assert s.passes == 21
    assert s.per_segment.loc[1, "h_direct"] == 9.0 and s.per_segment.loc[9, "seconds"] == 1.0
    assert bool(s.flags.loc[1, "in_building"]) and not s.flags.loc[2, "in_city_model"]


def test_layover_pv_is_the_join_of_the_standing_rows_sums_with_the_layovers():
    """Each layover's PV: the standing rows of its block-day and the trip before it summed,
    as a join of their (block-day, trip) sums with the layovers gives it; 0 for a layover of
    no block-day, or after a trip no standing row follows (beyond the rows' last)."""
    from vipvflow.simulation import reduce as R

    rng = np.random.default_rng(8)
    n = 4000
    st = pd.DataFrame({"at": rng.integers(0, 60, n), "after": rng.integers(-1, 6, n), "pv": rng.random(n)})
    lay = pd.DataFrame({"at": rng.integers(-1, 70, 900), "after": rng.integers(-1, 9, 900)})
    sums = st.groupby(["at", "after"], as_index=False)["pv"].sum()
    want = lay.merge(sums, on=["at", "after"], how="left")["pv"].fillna(0.0).to_numpy()
    got = R._LayoverPV(st["at"].to_numpy(), st["after"].to_numpy(), st["pv"].to_numpy()).of(
        lay["at"].to_numpy(), lay["after"].to_numpy())
    assert (lay["after"] > st["after"].max()).any() and (lay["at"] < 0).any()
    assert np.array_equal(got, want) and (got > 0).sum() > 400


def test_trips_share_of_their_block_days_is_that_of_the_join_by_block_and_date():
    """Each trip's share of its block-day's values by its time among the block-day's trips:
    what joining the block-days by block and date and grouping the trips by them gave, value
    for value; NaN for a trip of no block-day."""
    from vipvflow.simulation import reduce as R

    rng = np.random.default_rng(4)
    blocks = [f"b{i}" for i in range(30)]
    days = pd.to_datetime(["2024-06-01", "2024-06-02", "2024-06-03"])
    bd = pd.DataFrame([(b, d) for b in blocks for d in days], columns=["block_id", "service_date"])
    bd["usable"], bd["grid"] = rng.random(len(bd)), rng.random(len(bd))
    n = 2000
    trip = pd.DataFrame({"block_id": rng.choice(blocks + ["nowhere"], n),
                         "service_date": days[rng.integers(0, 3, n)], "seconds": rng.random(n) * 3600})
    key = ["block_id", "service_date"]
    share = trip["seconds"] / trip.groupby(key)["seconds"].transform("sum")
    want = trip[key].join(bd.set_index(key)[["usable", "grid"]], on=key).drop(columns=key).mul(share, axis=0)
    got = R.TripShares(R.BlockDayRows(bd).of(trip), trip["seconds"]).of(bd, ["usable", "grid"], trip.index)
    no_day = (trip["block_id"] == "nowhere").to_numpy()
    assert no_day.any() and got.loc[no_day].isna().all().all()
    pd.testing.assert_frame_equal(got[["usable", "grid"]], want, check_exact=True)
    np.testing.assert_array_equal(got["share"].to_numpy()[~no_day], share.to_numpy()[~no_day])


def test_parts_typed_apart_by_their_values_are_refused_and_leave_no_file(tmp_path):
    """Parts whose values give a column another type (a column of Python objects: strings in
    one part, only gaps in the other) are refused with PartSchemaError (the trips' writer
    then writes the whole at once), and no file or temporary file is left.  A nullable
    integer column with a gap in one part only is one type in every part (its gaps nulls)."""
    from vipvflow.store import PartSchemaError

    parts = [pd.DataFrame({"block_id": pd.Series(["b1", "b2"], dtype=object), "x": [1.0, 2.0]}),
             pd.DataFrame({"block_id": pd.Series([None, None], dtype=object), "x": [3.0, 4.0]})]
    with pytest.raises(PartSchemaError):
        write_parquet_parts(iter(parts), tmp_path / "t.parquet", row_group_rows=1)
    assert list(tmp_path.iterdir()) == []
    whole = write_parquet(pd.concat(parts, ignore_index=True), tmp_path / "t.parquet")
    assert pq.read_table(whole).column("block_id").to_pylist() == ["b1", "b2", None, None]

    parts = [pd.DataFrame({"direction_id": pd.array([0, 1], dtype="Int32"), "x": [1.0, 2.0]}),
             pd.DataFrame({"direction_id": pd.array([1, None], dtype="Int32"), "x": [3.0, 4.0]})]
    table = pq.read_table(write_parquet_parts(iter(parts), tmp_path / "n.parquet", row_group_rows=1))
    assert str(table.schema.field("direction_id").type) == "int32"
    assert table.column("direction_id").to_pylist() == [0, 1, 1, None]
