"""The simulation on a real Dask LocalCluster: worker count, interruption, worker loss, BVH
reuse, and physics sanity of the demo's results."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
from shapely.geometry import LineString, Point

from vipvflow.config import load_config
from vipvflow.errors import InputError
from vipvflow.simulation import run_simulation

OUTPUTS = ["trip_energy.parquet", "segment_month.parquet", "route_month.parquet",
           "block_day.parquet", "monthly.parquet", "hourly_pattern.parquet"]
KEYS = {"trip_energy.parquet": ["trip_id", "service_date"],
        "segment_month.parquet": ["segment_id", "month"],
        "route_month.parquet": ["route_id", "direction_id", "month"],
        "block_day.parquet": ["block_id", "service_date"],
        "monthly.parquet": ["month"], "hourly_pattern.parquet": ["month", "hour"]}


def _cfg(small_config, out: Path, **dask):
    return load_config(small_config, overrides={"out_dir": str(out), "dask": dask})


def assert_same_results(a: Path, b: Path):
    for name in OUTPUTS:
        x = pd.read_parquet(a / name).sort_values(KEYS[name]).reset_index(drop=True)
        y = pd.read_parquet(b / name).sort_values(KEYS[name]).reset_index(drop=True)
        x = x.drop(columns=[c for c in ("geometry",) if c in x])
        y = y.drop(columns=[c for c in ("geometry",) if c in y])
        pd.testing.assert_frame_equal(x, y, check_exact=False, rtol=1e-12, atol=0, obj=name)
    sa, sb = (json.loads((p / "summary.json").read_text()) for p in (a, b))
    assert sa == sb


def test_outputs_written(small_run):
    import gc

    for name in OUTPUTS + ["segments.parquet", "summary.json", "manifest.json", "report.html"]:
        assert (small_run / name).exists(), name
    # the run kept this process's heap out of the collector's passes during its reduce only
    assert gc.get_freeze_count() == 0
    smg = gpd.read_parquet(small_run / "segment_month.parquet")
    assert smg.crs.to_epsg() == 2169 and smg.geometry.has_z.all()
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    # every trip of June 2024 of the small demo: the calendar implies 20 weekdays (no holiday
    # in June... except none), 5 Saturdays, 5 Sundays
    layout = json.loads((small_run.parents[2].parent / "demo_small_inputs.json").read_text()) \
        if (small_run.parents[2].parent / "demo_small_inputs.json").exists() else None
    assert trips["consumption_kwh"].gt(0).all() and trips["pv_kwh"].ge(0).all()
    html = (small_run / "report.html").read_text()
    from vipvflow.outputs.report import FIGURE_ORDER

    assert html.count("data:image/png;base64") == len(FIGURE_ORDER)
    del layout


def test_trip_count_matches_calendar(small_run, demo_small):
    from vipvflow.demo.gtfs import service_day_counts  # noqa: F401  (the demo's own calendar)
    import gtfs_kit as gk

    feed = gk.read_feed(demo_small / "demo_gtfs.zip", dist_units="m")
    dates = [d.strftime("%Y%m%d") for d in pd.date_range("2024-06-01", "2024-06-30")]
    expected = int(feed.compute_trip_activity(dates)[dates].to_numpy().sum())
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    assert len(trips) == expected


def test_one_and_two_workers_give_equal_results(small_run, small_config, tmp_path):
    one = run_simulation(_cfg(small_config, tmp_path / "one", n_workers=1), 2024, say=lambda *a: None)
    assert_same_results(small_run, one)


def test_bvh_built_at_most_once_per_worker(small_run):
    manifest = json.loads((small_run / "manifest.json").read_text())
    builds = manifest["bvh_builds_per_worker"]
    assert len(builds) == 2
    counts = [n for per_worker in builds.values() for n in per_worker.values()]
    assert counts and max(counts) == 1


def test_interrupted_run_resumes_to_the_same_result(small_run, small_config, tmp_path):
    out = tmp_path / "resumed"
    cfg = _cfg(small_config, out, n_workers=2)
    run_dir = out / cfg.scenario / "2024"
    cmd = [sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(small_config),
           "--year", "2024", "--workers", "2"]
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    yaml_override = tmp_path / "conf.yaml"
    import yaml

    conf = yaml.safe_load(Path(small_config).read_text())
    conf["out_dir"] = str(out)
    yaml_override.write_text(yaml.safe_dump(conf))
    cmd[cmd.index(str(small_config))] = str(yaml_override)
    proc = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 120
    parts = run_dir / "parts" / "segment_month"
    while time.time() < deadline and proc.poll() is None:
        if len(list(parts.glob("tile=*/month=*.parquet"))) >= 2:
            os.killpg(proc.pid, signal.SIGKILL)
            break
        time.sleep(0.05)
    proc.wait(timeout=60)
    done = len(list(parts.glob("tile=*/month=*.parquet")))
    assert 2 <= done < 6, f"the run was not interrupted mid-way ({done} partitions)"
    assert not (run_dir / "summary.json").exists()
    resumed = run_simulation(cfg, 2024, say=lambda *a: None)
    manifest = json.loads((resumed / "manifest.json").read_text())
    assert manifest["partitions_computed"] == 6 - done
    assert_same_results(small_run, resumed)


def test_a_timeline_that_fails_while_the_tiles_compute_stops_the_run_with_its_error(
        small_config, tmp_path, monkeypatch):
    """The timeline is written while the tiles' tasks already run: its error stops the run
    as it would have before the map (the same error, the cluster closed, no outputs), and
    the same command then resumes from the partitions already written."""
    from vipvflow.simulation import run as run_mod

    real = run_mod.write_timeline
    started = threading.Event()

    def failing(*args, **kwargs):
        started.wait(30)            # the tiles' tasks are submitted by then
        time.sleep(0.5)
        raise InputError("trips.txt: line 7: block_id 'B1' runs two trips at once")

    submit = run_mod.submit_tiles

    def submit_then_fail(*args, **kwargs):
        futures = submit(*args, **kwargs)
        started.set()
        return futures

    monkeypatch.setattr(run_mod, "write_timeline", failing)
    monkeypatch.setattr(run_mod, "submit_tiles", submit_then_fail)
    cfg = _cfg(small_config, tmp_path / "out", n_workers=1)
    run_dir = tmp_path / "out" / cfg.scenario / "2024"
    with pytest.raises(InputError, match="block_id 'B1' runs two trips at once"):
        run_simulation(cfg, 2024, say=lambda *a: None)
    assert started.is_set()
    parts = run_dir / "parts" / "segment_month"
    written = sorted(parts.glob("tile=*/month=*.parquet"))
    time.sleep(2.0)                 # nothing goes on computing after the error
    assert sorted(parts.glob("tile=*/month=*.parquet")) == written
    assert not (run_dir / "summary.json").exists()
    monkeypatch.setattr(run_mod, "write_timeline", real)
    monkeypatch.setattr(run_mod, "submit_tiles", submit)
    resumed = run_simulation(cfg, 2024, say=lambda *a: None)
    manifest = json.loads((resumed / "manifest.json").read_text())
    assert manifest["partitions_computed"] == 6 - len(written)
    assert manifest["standing_partitions_computed"] >= 1     # none was started before
    assert (resumed / "summary.json").exists()


def test_killed_worker_gives_the_same_result(small_run, small_config, tmp_path):
    from distributed import Client, LocalCluster

    out = tmp_path / "killed"
    cfg = _cfg(small_config, out)
    run_dir = out / cfg.scenario / "2024"
    killed = {}
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        pids = client.run(os.getpid)

        def killer():
            deadline = time.time() + 120
            while time.time() < deadline:
                if list((run_dir / "parts" / "geometry").glob("*.parquet")):
                    victim = sorted(pids.values())[0]
                    os.kill(victim, signal.SIGKILL)
                    killed["pid"] = victim
                    killed["done"] = len(list((run_dir / "parts" / "segment_month").glob("*/*.parquet")))
                    return
                time.sleep(0.01)

        t = threading.Thread(target=killer)
        t.start()
        result = run_simulation(cfg, 2024, scheduler=cluster.scheduler_address, say=lambda *a: None)
        t.join()
    assert killed and killed["done"] < 6
    assert_same_results(small_run, result)


def _slow_inc(x, seconds):
    time.sleep(seconds)
    return x + 1


def test_a_result_lost_with_its_worker_is_waited_for_beside_another_default_client(tmp_path):
    """The map's results are awaited on its own client's event loop.  A caller with a client
    of its own (the default client of its thread) ran ``run_simulation`` against its
    scheduler: the run's client, started in a thread, has another loop.  A finished result
    lost with its worker before the map fetched it then failed the run ("bound to a
    different event loop") instead of being waited for while Dask computed it again (how
    ``test_killed_worker_gives_the_same_result`` failed now and then)."""
    from distributed import Client, LocalCluster

    from vipvflow.simulation.tasks import finished_results

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                      local_directory=str(tmp_path)) as cluster, Client(cluster):
        started = {}
        t = threading.Thread(target=lambda: started.update(client=Client(cluster.scheduler_address)))
        t.start()
        t.join()
        client = started["client"]
        try:
            first, second = sorted(client.scheduler_info()["workers"])
            # one result on the worker that dies, one slow task on the other: the lost result
            # is computed again after it, while the map waits for it
            lost = client.submit(_slow_inc, 1, 1.0, key="lost", workers=[first], allow_other_workers=True)
            slow = client.submit(_slow_inc, 10, 3.0, key="slow", workers=[second])
            victim = client.run(os.getpid, workers=[first])[first]

            def kill_when_done():
                deadline = time.time() + 60
                while not lost.done() and time.time() < deadline:
                    time.sleep(0.01)
                os.kill(victim, signal.SIGKILL)

            killer = threading.Thread(target=kill_when_done)
            killer.start()
            out = list(finished_results(client, [lost, slow], every_s=3600.0))
            killer.join()
            assert sorted(out) == [2, 11]
        finally:
            client.close()


def _stretch_kind(segments: gpd.GeoDataFrame, layout: dict) -> np.ndarray:
    lines = [(s["kind"], LineString(s["centerline"])) for s in layout["stretches"]]
    mids = [Point(g.interpolate(0.5, normalized=True).coords[0][:2]) for g in segments.geometry]
    kinds = []
    for p in mids:
        kinds.append(min(lines, key=lambda kl: kl[1].distance(p))[0])
    return np.array(kinds)


def test_physics_sanity(small_run, demo_small):
    s = json.loads((small_run / "summary.json").read_text())
    # without buildings the roof sees the CAMS horizontal irradiation, up to the roof tilt
    # of the road gradients (at most a few degrees): within 1 %
    assert abs(s["unshaded_to_ghi_allsky"] - 1) < 0.01
    assert abs(s["unshaded_to_ghi_clearsky"] - 1) < 0.01
    assert 0 < s["shading_loss_allsky"] < 1 and 0 < s["shading_loss_clearsky"] < 1
    layout = json.loads((demo_small / "demo_layout.json").read_text())
    sm = gpd.read_parquet(small_run / "segment_month.parquet")
    kinds = _stretch_kind(sm, layout)
    loss = 1 - (sm["h_direct"] + sm["h_diffuse"]) / sm["h_total_unshaded"]
    canyon, open_ = loss[kinds == "canyon"], loss[kinds == "open"]
    assert len(canyon) and len(open_)
    assert canyon.mean() > 0.05 > open_.mean() + 0.02
    # open segments lose nothing: zero up to float32 rounding of the per-pass sums
    assert (loss > -1e-6).all() and (loss < 1).all()


def test_vecto_cycles_written_and_vmod_replaces_consumption(small_run, small_config, tmp_path, test_data):
    import shutil

    from vipvflow.outputs import vecto
    from vipvflow.simulation.reduce import trip_consumption

    cfg = load_config(small_config)
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    segs = pd.read_parquet(Path(cfg.data_dir) / "gtfs" / "segments.parquet")
    length = segs.groupby("shape_id")["length_m"].sum()
    files = sorted((small_run / "vecto").glob("pattern_*.vdri"))
    patterns = trips.drop_duplicates("pattern_id").set_index("pattern_id")["shape_id"]
    assert len(files) == len(patterns) and list((small_run / "vecto").glob("*.vecto"))
    for f in files:
        vdri = vecto.read_vdri(f)
        shape = patterns[int(f.stem.split("_")[1])]
        # the cycle's distance is the shape's length (within 1 %)
        assert vdri["s_m"].iloc[-1] == pytest.approx(length[shape], rel=0.01)
    # a battery-electric VECTO modal result for pattern 0 replaces its built-in consumption
    vmod_dir = tmp_path / "vmod"
    vmod_dir.mkdir()
    vmod = vmod_dir / "pattern_0.vmod"
    vmod.write_text("time [s],dt [s],dist [m],P_wheel_in [kW],P_brake_loss [kW],P_aux_el [kW],"
                    "P_REESS_T [kW],P_REESS_int [kW],P_REESS_loss [kW]\n"
                    "0.5,1,0,0,0,12,12,12.4,0.4\n1.5,1,5,80,0,12,95,98,3\n2.5,1,12,-30,-5,12,-15,-14,1\n",
                    encoding="utf-8-sig")
    cfg = load_config(small_config, overrides={"vehicle": {"vmod_dir": str(vmod_dir)}})
    cons = trip_consumption(cfg, Path(cfg.data_dir), 2024, patterns.index, say=lambda *a: None)
    want = (12.4 + 98 - 14) / 3600  # battery energy integrated by hand (kWh)
    assert vecto.vmod_energy(vmod)["battery_kwh"] == pytest.approx(want)
    want = vecto.vmod_energy(vmod)["battery_kwh"]
    got = cons.set_index("pattern_id")
    assert np.all(got.loc[[0], "consumption_kwh"] == want)
    assert np.all(got.loc[[0], "consumption_source"] == "vecto")
    others = got.drop(index=0)
    assert (others["consumption_source"] == "built-in").all()
    # the modal result of a conventional vehicle (no battery) is refused with the file named
    shutil.copy(next((test_data / "vecto").glob("*.vmod")), vmod_dir / "pattern_0.vmod")
    with pytest.raises(InputError, match="pattern_0.vmod.*battery"):
        trip_consumption(cfg, Path(cfg.data_dir), 2024, patterns.index, say=lambda *a: None)


def test_consumption_made_by_tasks_joins_what_the_reduce_computes(small_run, small_config, tmp_path):
    """The patterns a run's tasks computed (:class:`Consumption`) and those the reduce finds
    missing give the table and the VECTO cycles and job of one computation in the reduce."""
    from concurrent.futures import Future

    from vipvflow.simulation.reduce import Consumption, pattern_consumption, trip_consumption

    cfg = load_config(small_config)
    patterns = sorted(pd.read_parquet(small_run / "trip_energy.parquet")["pattern_id"].unique())
    assert len(patterns) >= 2
    here, split = tmp_path / "here", tmp_path / "split"
    whole = trip_consumption(cfg, Path(cfg.data_dir), 2024, patterns, vecto_dir=here, say=lambda *a: None)
    split.mkdir()
    task = Future()
    task.set_result(pattern_consumption(cfg, Path(cfg.data_dir), 2024, patterns[:1], split, {}))
    joined = trip_consumption(cfg, Path(cfg.data_dir), 2024, patterns, vecto_dir=split,
                              say=lambda *a: None, made=Consumption([task], {}))
    pd.testing.assert_frame_equal(joined, whole, check_exact=True)
    names = sorted(p.name for p in here.iterdir())
    assert names == sorted(p.name for p in split.iterdir())
    for name in names:
        if name.endswith(".vdri"):
            assert (here / name).read_bytes() == (split / name).read_bytes(), name
    job = json.loads(next(split.glob("*.vecto")).read_text())
    assert json.dumps(job).count(".vdri") == len(patterns)


def test_plan_lists_the_graph_and_what_is_done(small_run, small_config):
    import runpy

    from vipvflow.simulation.run import plan

    table = plan(load_config(small_config), 2024)
    segs = pd.read_parquet(Path(load_config(small_config).data_dir) / "gtfs" / "segments.parquet")
    assert sorted(table["tile"].unique()) == sorted(segs["tile"].unique())
    assert (table["key"] == "irradiance-" + table["tile"]).all()
    assert (table["month"] == "2024-06").all()
    assert table["done"].all()   # the session's run wrote every partition
    main = runpy.run_path(str(Path(__file__).parents[1] / "pipeline" / "plan.py"))["main"]
    assert main(["--config", str(small_config), "--year", "2024"]) == 0


def test_tiles_run_largest_first(small_run, small_config):
    """The map takes the tiles with the most passes first, so the cluster's last tasks are
    small ones: the planned order against the passes the run counted per tile."""
    from vipvflow.simulation.run import plan

    order = plan(load_config(small_config), 2024).drop_duplicates("tile")["tile"].tolist()
    sm = pd.read_parquet(small_run / "segment_month.parquet", columns=["tile", "n_passes"])
    passes = sm.groupby("tile")["n_passes"].sum().reindex(order, fill_value=0).to_numpy()
    assert len(order) >= 3 and passes[0] == passes.max() > passes.min()
    assert passes[-1] <= np.median(passes)
    assert passes[: len(passes) // 2].sum() > passes[len(passes) // 2:].sum()


def test_map_tasks_take_a_tiles_months_or_split_them_for_a_large_cluster():
    from vipvflow.simulation.tasks import tile_tasks

    def todo(n_tiles):
        return [(f"T{t:02d}", f"2024-{m:02d}") for t in range(n_tiles) for m in range(1, 13)]

    def covers(tasks, pairs):
        """Every pair once, each task's months a run of the tile's months in *pairs*."""
        got = [(t, m) for t, ms in tasks for m in ms]
        assert sorted(got) == sorted(pairs) and len(got) == len(set(got))
        for tile, ms in tasks:
            of_tile = [m for t, m in pairs if t == tile]
            i = of_tile.index(ms[0])
            assert of_tile[i:i + len(ms)] == ms

    line_year = todo(41)           # the line-year on 2 workers: one task per tile, in order
    tasks = tile_tasks(line_year, 2)
    assert [t for t, _ in tasks] == [f"T{t:02d}" for t in range(41)]
    assert all(len(ms) == 12 for _, ms in tasks)
    covers(tasks, line_year)
    small = todo(6)                # 6 tiles for 8 wanted tasks: halves of the year
    tasks = tile_tasks(small, 2)
    assert len(tasks) == 12 and {len(ms) for _, ms in tasks} == {6}
    covers(tasks, small)
    few = todo(3)                  # 3 tiles on 16 slots: every month its own task
    tasks = tile_tasks(few, 16)
    assert len(tasks) == 36 and {len(ms) for _, ms in tasks} == {1}
    covers(tasks, few)
    resumed = [p for p in todo(2) if p[1] not in ("2024-03", "2024-04")]
    covers(tile_tasks(resumed, 1), resumed)


def test_split_tiles_give_the_partitions_of_whole_tiles(small_run, small_config, tmp_path):
    """The small demo's May and June on 2 workers: 6 tiles for 8 wanted tasks, so each tile's
    months run as two tasks after its geometry task; June's partitions equal those of the
    session's June run (one task per tile)."""
    import pyarrow.parquet as pq

    from vipvflow.simulation.tasks import tile_tasks
    from vipvflow.store import PARTITION_KINDS, RunDir

    cfg = load_config(small_config, overrides={"out_dir": str(tmp_path / "split"),
                                               "run": {"months": [5, 6]}, "dask": {"n_workers": 2}})
    run_dir = run_simulation(cfg, 2024, say=lambda *a: None)
    split, whole = RunDir(run_dir), RunDir(small_run)
    tiles = sorted({p.parent.name.split("=", 1)[1] for p in whole.part_files("trip")})
    assert tiles and all(split.part("trip", t, "2024-05").exists() for t in tiles)
    assert len(tile_tasks([(t, m) for t in tiles for m in ("2024-05", "2024-06")], 2)) == 2 * len(tiles)
    # each tile's geometry timed once, by the first of its tasks; so in the one-task run
    manifest = json.loads(split.manifest.read_text())
    assert manifest["partition_counts"]["geometry_tiles"] == len(tiles)
    assert manifest["partition_timings_s"]["geometry_s"] > 0
    manifest = json.loads(whole.manifest.read_text())
    assert manifest["partition_counts"]["geometry_tiles"] == len(tiles)
    for kind in PARTITION_KINDS:
        for tile in tiles:
            a = pq.read_table(split.part(kind, tile, "2024-06"))
            b = pq.read_table(whole.part(kind, tile, "2024-06"))
            assert a.equals(b), (kind, tile)


def _busy(seconds: float) -> int:
    n, end = 0, time.perf_counter() + seconds
    while time.perf_counter() < end:
        n += 1
    return n


@pytest.mark.parametrize("profile", [False, True])
def test_local_cluster_profiles_workers_only_when_asked(small_config, tmp_path, profile):
    import dask

    from vipvflow.simulation.cluster import LOCAL_CLUSTER_DASK_CONFIG, make_client

    cfg = _cfg(small_config, tmp_path, worker_profile=profile)
    client, cluster = make_client(cfg, None, 1)
    try:
        settings = client.run(lambda: {k: dask.config.get(k) for k in LOCAL_CLUSTER_DASK_CONFIG})
        assert list(settings.values()) == [LOCAL_CLUSTER_DASK_CONFIG]
        client.submit(_busy, 1.5, pure=False).result()
        samples = client.profile()["count"]
        assert (samples > 0) is profile, samples
    finally:
        client.close()
        cluster.close()
    # this process's own Dask configuration is left as it was
    assert dask.config.get("distributed.admin.tick.interval") == "20ms"


def _worker_origin() -> tuple:
    import os
    import sys

    import pyarrow as pa

    return (os.getppid(), os.getcwd(), "vipvflow.simulation.worker_preload" in sys.modules,
            "matplotlib.pyplot" in sys.modules, pa.default_memory_pool().backend_name)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="workers are forked on Linux only")
def test_local_cluster_workers_are_forked_from_one_preloaded_server_in_the_callers_directory(
        small_config, tmp_path, monkeypatch):
    """A run's LocalCluster forks its workers from one server process per process, which has
    loaded what a worker's map needs (the simulation; not matplotlib, which only the reduce's
    figures load) and put Arrow's allocations on the heap; a later run's workers come from
    the same server, and each run's work in the directory the run was started from."""
    from vipvflow.simulation.cluster import make_client

    origins = []
    for name in ("first", "second"):
        (tmp_path / name).mkdir()
        monkeypatch.chdir(tmp_path / name)
        client, cluster = make_client(_cfg(small_config, tmp_path), None, 2)
        try:
            origins.append(sorted(client.run(_worker_origin).values()))
        finally:
            client.close()
            cluster.close()
    servers = {ppid for run in origins for ppid, *_ in run}
    assert len(servers) == 1 and os.getpid() not in servers, origins
    assert [[cwd for _, cwd, *_ in run] for run in origins] == [
        [str(tmp_path / "first")] * 2, [str(tmp_path / "second")] * 2]
    assert all(preloaded and not pyplot and pool == "system"
               for run in origins for _, _, preloaded, pyplot, pool in run), origins


def test_arrow_allocates_from_the_heap_unless_a_pool_is_chosen(small_run):
    """A run puts its process's Arrow allocations on glibc's heap (pyarrow's system pool,
    whose freed memory :func:`hand_back_memory` gives back); ``ARROW_DEFAULT_MEMORY_POOL``
    set by the user is left as chosen."""
    import pyarrow as pa

    assert pa.default_memory_pool().backend_name == "system"        # small_run ran here
    code = ("import pyarrow as pa\n"
            "from vipvflow.simulation.partition import arrow_on_the_heap\n"
            "before = pa.default_memory_pool().backend_name\n"
            "arrow_on_the_heap()\n"
            "print(before, pa.default_memory_pool().backend_name)\n")
    env = {k: v for k, v in os.environ.items() if k != "ARROW_DEFAULT_MEMORY_POOL"}
    for chosen, want in ((None, "system"), ("mimalloc", "mimalloc"), ("jemalloc", "jemalloc")):
        if chosen is not None and chosen not in pa.supported_memory_backends():
            continue
        done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                              env=env if chosen is None else {**env, "ARROW_DEFAULT_MEMORY_POOL": chosen})
        assert done.returncode == 0, done.stderr
        before, after = done.stdout.split()
        assert after == want and (chosen is not None or before != "system"), (chosen, done.stdout)


def _frozen_objects() -> int:
    import gc

    return gc.get_freeze_count()


def test_workers_keep_what_they_loaded_out_of_the_collector(small_config, tmp_path):
    """A run's workers move what their set-up loaded (the libraries, the compiled kernels)
    out of the cyclic garbage collector's full passes; the process that starts them is left
    as it was."""
    import gc

    from vipvflow.simulation.cluster import make_client

    client, cluster = make_client(_cfg(small_config, tmp_path), None, 2)
    try:
        frozen = client.run(_frozen_objects)
        assert len(frozen) == 2 and all(n > 50_000 for n in frozen.values()), frozen
    finally:
        client.close()
        cluster.close()
    assert gc.get_freeze_count() == 0


def test_a_dashboard_port_taken_meanwhile_is_not_warned_about(small_config, tmp_path, monkeypatch):
    """Two runs starting together: the port one found free is taken by the other before its
    cluster binds it. Dask serves the dashboard elsewhere; its warning is not printed."""
    import socket
    import warnings

    from vipvflow.simulation import cluster as cluster_mod

    with socket.socket() as taken:
        taken.bind(("", 0))
        taken.listen()
        port = taken.getsockname()[1]
        monkeypatch.setattr(cluster_mod, "dashboard_address",
                            lambda _port, host="127.0.0.1": f"{host}:{port}")
        with warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            client, cluster = cluster_mod.make_client(_cfg(small_config, tmp_path), None, 1)
            try:
                assert not client.dashboard_link.endswith(f":{port}/status")
            finally:
                client.close()
                cluster.close()
    assert not [w for w in seen if "already in use" in str(w.message)], [str(w.message) for w in seen]
