"""Run a scenario-year on a Dask cluster: prepare, map over partitions, reduce, write."""
from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import json
import logging
import os
import shutil
import sys
import threading
import time
from pathlib import Path

import pandas as pd

from ..config import Config
from ..errors import InputError
from ..progress import FolderProgress, MapProgress
from .partition import RunContext, partition_done, run_partition, tile_geometry, worker_bvh_builds
from .standing import run_standing, standing_done, write_timeline
from .rundir import data_dir_record, masked_config
from ..store import DataDir, RunDir, aside_folders, set_aside, write_json, write_text

log = logging.getLogger(__name__)


def run_dir_of(cfg: Config, year: int) -> Path:
    return Path(cfg.out_dir) / cfg.scenario / str(year)


def _months(cfg: Config, year: int) -> list[str]:
    return [f"{year}-{m:02d}" for m in cfg.run.months]


def _digest_in(run_dir: Path) -> str | None:
    """The configuration digest of the run (finished or partial) in *run_dir*, if any."""
    run = RunDir(run_dir)
    if run.config_stamp.is_file():
        return run.config_stamp.read_text().strip()
    try:
        return json.loads(run.manifest.read_text()).get("config_digest")
    except (OSError, ValueError, AttributeError):
        return None


def claim_run_dir(run_dir: Path, digest: str, force: bool = False, say=print) -> None:
    """Make *run_dir* the folder of a run of configuration *digest*.

    A folder holding a run (finished or partial) of another configuration is refused with
    both digests named; with *force* it is replaced as a whole: renamed aside in one step,
    then deleted, so that an interruption leaves either the old run or the new one, never
    parts of both. Folders left aside by an interrupted replacement are removed.
    """
    for stale in aside_folders(run_dir):
        shutil.rmtree(stale, ignore_errors=True)
    other = _digest_in(run_dir)
    if other is not None and other != digest:
        if not force:
            raise InputError(
                f"{run_dir}: holds a run of another configuration (digest {other}; this "
                f"configuration's digest is {digest}): pass --force to replace it, or set "
                "another scenario or out_dir")
        aside = set_aside(run_dir, other)
        say(f"replacing the run of configuration {other} in {run_dir}")
        shutil.rmtree(aside, ignore_errors=True)
    stamp = RunDir(run_dir).config_stamp
    if not stamp.is_file():
        write_text(digest, stamp)


#: Dask settings of a LocalCluster started by a run, whose processes share the machine's
#: cores with the simulation: event-loop ticks every 1 s instead of 20 ms, system monitors
#: every 2 s instead of 0.5 s, memory monitors every 0.5 s instead of 0.1 s (the scheduler's
#: and nannies' event loop took ~15 % of a core at the defaults during the line-year)
LOCAL_CLUSTER_DASK_CONFIG = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "500ms",
}


def make_client(cfg: Config, scheduler: str | None, n_workers: int | None):
    """A client of the given scheduler, or of a LocalCluster sized to the machine.

    The LocalCluster's workers run without Dask's statistical profiler unless
    ``dask.worker_profile`` is set: on a machine whose cores the workers fill, its 100 stack
    samples a second per worker come out of the simulation's time (the 2-worker line-year
    spent ~7 % of each worker's CPU on it)."""
    import dask
    from distributed import Client, LocalCluster

    scheduler = scheduler or cfg.dask.scheduler
    if not log.isEnabledFor(logging.INFO):
        for name in ("distributed", "distributed.scheduler", "distributed.nanny", "distributed.core",
                     "distributed.worker", "distributed.http.proxy"):
            logging.getLogger(name).setLevel(logging.WARNING)
    if scheduler:
        return Client(scheduler), None
    n = n_workers or cfg.dask.n_workers or os.cpu_count() or 1
    settings = {**LOCAL_CLUSTER_DASK_CONFIG, "distributed.worker.profile.enabled": cfg.dask.worker_profile,
                # workers ignore Ctrl-C and leave a task's failure for this process to report
                "distributed.worker.preload": ["vipvflow.simulation.worker_setup"],
                "vipvflow.worker-failure-log": log.isEnabledFor(logging.INFO)}
    with dask.config.set(settings):     # the nannies hand this configuration to their workers
        cluster = LocalCluster(n_workers=n, threads_per_worker=cfg.dask.threads_per_worker or 1,
                               processes=True, memory_limit=cfg.dask.memory_limit,
                               dashboard_address=dashboard_address(cfg.dask.dashboard_port),
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster


def dashboard_address(port: int | None) -> str:
    """``:port`` when that port is free on this machine, else ``:0`` (any free port)."""
    import socket

    if port is None:
        return ":0"
    with socket.socket() as s:
        try:
            s.bind(("", port))
        except OSError:
            return ":0"
    return f":{port}"


def selected_network(cfg: Config) -> tuple[pd.DataFrame, tuple | None, list[str]]:
    """The trips (``trip_id, route_id, shape_id``), shapes (``None``: all) and tiles that
    the run covers, after ``run.routes``; needs the ingested GTFS in ``cfg.data_dir``."""
    gtfs = DataDir(cfg.data_dir).gtfs
    trips = pd.read_parquet(gtfs.trips, columns=["trip_id", "route_id", "shape_id"])
    routes = cfg.run.routes
    shapes = None
    if routes is not None:
        unknown = sorted(set(routes) - set(trips["route_id"].astype(str)))
        if unknown:
            raise InputError(f"{cfg._source}: run.routes: route_id(s) not in the feed: {', '.join(unknown)}")
        trips = trips[trips["route_id"].astype(str).isin(routes)]
        shapes = tuple(sorted(trips["shape_id"].unique()))
    seg = pd.read_parquet(gtfs.segments, columns=["tile", "shape_id"])
    if shapes is not None:
        seg = seg[seg["shape_id"].isin(shapes)]
    return trips, shapes, sorted(seg["tile"].unique())


def plan(cfg: Config, year: int) -> pd.DataFrame:
    """The task graph of a scenario-year as a table: one row per ``irradiance`` task with its
    tile, month, key, the ``geometry`` task it depends on, and whether its partition is
    already written (a resumed run skips those)."""
    _, _, tiles = selected_network(cfg)
    run_dir = run_dir_of(cfg, year)
    rows = [{"tile": t, "month": m, "key": f"irradiance-{t}-{m}", "depends_on": f"geometry-{t}",
             "done": partition_done(run_dir, t, m)} for t in tiles for m in _months(cfg, year)]
    return pd.DataFrame(rows, columns=["tile", "month", "key", "depends_on", "done"])


def run_simulation(cfg: Config, year: int, scheduler: str | None = None,
                   n_workers: int | None = None, say=print, max_partitions: int | None = None,
                   force: bool = False) -> Path:
    """Compute the scenario's fleet-year and write all outputs; returns the run directory.

    An interrupted run resumes: finished partitions (written atomically) are not recomputed.
    A run directory holding a run of another configuration is refused (:class:`InputError`
    naming both digests), or with *force* replaced as a whole (see :func:`claim_run_dir`).
    *max_partitions* stops after that many new partitions (for tests of resuming).
    """
    from .prepare import check_year, ensure_demo, ensure_ingested, preflight
    from .reduce import reduce_run

    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    check_year(year)
    ensure_demo(cfg, year, say=say)
    checksums = ensure_ingested(cfg, say=say)
    preflight(cfg, year, say=say)
    run_dir = run_dir_of(cfg, year)
    claim_run_dir(run_dir, cfg.digest(), force=force, say=say)
    timings["prepare_s"] = time.perf_counter() - t_start

    data_dir = Path(cfg.data_dir)
    feed = json.loads(DataDir(data_dir).gtfs.feed_json.read_text())
    trips, shapes, tiles = selected_network(cfg)
    routes = cfg.run.routes
    ctx = RunContext(
        data_dir=str(data_dir.resolve()), run_dir=str(run_dir.resolve()), year=year,
        irradiance=cfg.irradiance.model_dump(), pv_system=cfg.pv_system().model_dump(),
        pv_mode=cfg.pv.mode, monthly_temperature_c=tuple(cfg.climate.monthly_mean_temperature_c),
        wind_speed_mps=cfg.climate.wind_speed_mps, timezone=feed["timezone"],
        bvh_cache_size=cfg.dask.bvh_cache_size, ground_albedo=cfg.city.albedo.ground,
        routes=tuple(routes) if routes is not None else None, shapes=shapes,
        route_of_trip=dict(zip(trips["trip_id"], trips["route_id"].astype(str))))

    todo = [(t, m) for t in tiles for m in _months(cfg, year) if not partition_done(run_dir, t, m)]
    # layovers and parked time: one ``standing`` task per tile holding standing points
    t_tl = time.perf_counter()
    standing = write_timeline(cfg, year, run_dir, routes=routes)
    timings["timeline_s"] = time.perf_counter() - t_tl
    standing_todo = [t for t in standing if not standing_done(run_dir, t)]
    total = len(tiles) * len(cfg.run.months) + len(standing)
    if max_partitions is not None:
        todo = todo[:max_partitions]
        standing_todo = standing_todo[:max(0, max_partitions - len(todo))]
    # the radiation table's sun positions are computed (and cached beside the radiation
    # file, where every worker loads them) while the cluster starts
    warm = threading.Thread(target=_warm_radiation, args=(ctx.data_dir, year), daemon=True,
                            name="sun-positions")
    warm.start()
    client, cluster = make_client(cfg, scheduler, n_workers)
    closer = threading.Thread(target=_close, args=(client, cluster), name="close-cluster")
    try:
        n_workers_now = len(client.scheduler_info()["workers"])
        # a LocalCluster's workers share the machine's cores for ray casting
        ray_threads = cfg.dask.ray_threads or (
            max(1, (os.cpu_count() or 1) // max(1, n_workers_now)) if cluster is not None else 1)
        ctx = dataclasses.replace(ctx, ray_threads=ray_threads)
        say(f"dask dashboard: {client.dashboard_link}" if importlib.util.find_spec("bokeh")
            else "dask dashboard: off (it needs bokeh: pip install 'vipvflow[app]')")
        n_todo = len(todo) + len(standing_todo)
        say(f"{len(tiles)} tiles x {len(cfg.run.months)} months + {len(standing)} standing = {total} "
            f"partitions, {n_todo} to compute ({total - n_todo} already done) with {n_workers_now} workers")
        warm.join()
        t_map = time.perf_counter()
        # the reduce's plotting libraries load while the workers compute
        threading.Thread(target=importlib.import_module, args=("vipvflow.simulation.report",),
                         daemon=True, name="import-report").start()
        results = _map(client, ctx, todo, standing_todo)
        timings["map_s"] = time.perf_counter() - t_map
        builds = client.run(worker_bvh_builds)
        if not (all(partition_done(run_dir, t, m) for t in tiles for m in _months(cfg, year))
                and all(standing_done(run_dir, t) for t in standing)):
            say("stopped before all partitions were computed; run the same command again to resume")
            return run_dir
        # the partitions are read and summed by tasks on the cluster; the joins and the
        # outputs are made here
        t_red = time.perf_counter()
        with FolderProgress("reduce", run_dir):
            # the cluster shuts down once the partitions are read, while this process writes
            summary = reduce_run(cfg, year, run_dir, say=say, client=client,
                                 read=lambda: closer.start())
        timings["reduce_s"] = time.perf_counter() - t_red
    finally:
        if closer.ident is not None:         # started by the reduce
            closer.join()
        else:
            _close(client, cluster)
    timings["total_s"] = time.perf_counter() - t_start
    _write_manifest(cfg, year, run_dir, checksums, timings, results, builds)
    say(_summary_line(summary))
    say(f"outputs in {run_dir}")
    return run_dir


def _close(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()


def _warm_radiation(data_dir: str, year: int) -> None:
    """Load the radiation table once in this process (writes its sun-position cache); a
    failure is left for the workers to report with the file named."""
    from ..radiation import RadiationTable

    try:
        RadiationTable.load(data_dir, year)
    except Exception:  # noqa: BLE001 - the same load fails again in the tasks, with its message
        pass


def _map(client, ctx: RunContext, todo: list[tuple[str, str]], standing: list[str] = (),
         every_s: float = 1.0) -> list[dict]:
    from distributed import as_completed

    geometry = {}
    futures = []
    for tile in sorted({t for t, _ in todo}):
        geometry[tile] = client.submit(tile_geometry, ctx, tile, key=f"geometry-{tile}")
    for tile, month in todo:
        futures.append(client.submit(run_partition, ctx, tile, month, geometry[tile],
                                     key=f"irradiance-{tile}-{month}"))
    for tile in standing:
        futures.append(client.submit(run_standing, ctx, tile, key=f"standing-{tile}"))
    view = MapProgress(len(futures))
    results = []
    done, last = [], time.perf_counter()
    # the finished partitions' summaries are fetched together about once a second: one
    # fetch per partition kept the scheduler's event loop (in this process) busy ~15 % of a
    # core, taken from the workers when they fill the machine
    for n_done, fut in enumerate(as_completed(futures), start=1):
        done.append(fut)
        if time.perf_counter() - last >= every_s or n_done == len(futures):
            for res in client.gather(done):
                results.append(res)
                view.add(res)
            for f in done:
                f.release()
            done, last = [], time.perf_counter()
    view.close()
    return results


def _write_manifest(cfg, year, run_dir, checksums, timings, results, builds) -> None:
    from importlib import metadata

    versions = {}
    for name in ["vipvflow", "numpy", "pandas", "dask", "distributed", "geopandas", "pyarrow",
                 "embreex", "trimesh", "pvlib", "gtfs-kit", "lxml"]:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    stage = {}
    for res in results:
        for k, v in res.get("timings", {}).items():
            stage[k] = stage.get(k, 0.0) + v
    manifest = {
        "scenario": cfg.scenario, "year": year, "config_digest": cfg.digest(),
        "config": masked_config(cfg.model_dump(mode="json")),
        "paths": {"data_dir": data_dir_record(cfg.data_dir, run_dir)},
        "inputs_sha256": checksums, "versions": versions,
        "timings_s": {k: round(v, 3) for k, v in timings.items()},
        "partition_timings_s": {k: round(v, 3) for k, v in stage.items()},
        "partitions_computed": sum(1 for r in results if "intervals" not in r),
        # layovers and parked time (the standing tasks; their worker time is standing_s above)
        "standing_partitions_computed": sum(1 for r in results if "intervals" in r),
        "standing_intervals": int(sum(r.get("intervals", 0) for r in results)),
        "passes_computed": int(sum(r["passes"] for r in results)),
        "bvh_builds_per_worker": builds,
        "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    write_json(manifest, RunDir(run_dir).manifest)


def _summary_line(s: dict) -> str:
    def yield_of(key):
        return "not computed" if s.get(key) is None else f"{s[key]:.0f} kWh/kWp"

    return (f"annual yield (all-sky) driving {s['kwh_per_kwp_allsky']:.0f} kWh/kWp "
            f"({s['kwh_per_kwp_clearsky']:.0f} clear-sky), in service {yield_of('kwh_per_kwp_in_service')}, "
            f"whole day {yield_of('kwh_per_kwp_whole_day')}; "
            f"shading loss {100 * s['shading_loss_allsky']:.1f} % on the road; "
            f"the battery takes {s['pv_kwh_usable'] / 1000:.1f} MWh "
            f"({s['pv_kwh_curtailed'] / 1000:.1f} MWh curtailed): "
            f"PV covers {100 * s['coverage']:.2f} % of {s['fleet_demand_mwh']:.0f} MWh; "
            f"{s['avoided_charging_cycles_per_bus']:.1f} charging cycles avoided per bus; "
            f"payback {s['payback_years']:.1f} years")
