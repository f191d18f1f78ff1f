"""Run a scenario-year on a Dask cluster: prepare, map over partitions, reduce, write."""
from __future__ import annotations

import contextlib
import dataclasses
import functools
import gc
import importlib
import importlib.util
import json
import logging
import os
import threading
import time
from pathlib import Path

import pandas as pd

from ..config import Config
from ..errors import InputError
from ..progress import FolderProgress
from ..store import DataDir, FolderLock, data_dir_lock, folder_path, lock_for_writing, run_dir_lock
from .cluster import (bound_dashboard, check_scheduler, close_client, fewer_fresh_workers,
                      fresh_workers, local_cluster_size, make_client)
from .manifest import claim_run_dir, write_manifest
from .network import selected_network
from .partition import RunContext, arrow_on_the_heap, hand_back_memory, partition_done, worker_bvh_builds
from .standing import standing_done, write_timeline
from .tasks import collect_map, submit_standing, submit_tiles

log = logging.getLogger(__name__)


def run_dir_of(cfg: Config, year: int) -> Path:
    return Path(cfg.out_dir) / cfg.scenario / str(year)


def _months(cfg: Config, year: int) -> list[str]:
    return [f"{year}-{m:02d}" for m in cfg.run.months]


def plan(cfg: Config, year: int) -> pd.DataFrame:
    """The partitions of a scenario-year as a table: one row per (tile, month) with the key
    of the task that computes it on the LocalCluster the configuration starts
    (``irradiance-<TILE>``: the tile's geometry, then its months; split by month when the
    cluster has many worker threads for the tiles, :func:`vipvflow.simulation.tasks.tile_tasks`)
    and whether it is already written (a resumed run skips those)."""
    from .tasks import task_keys, tile_tasks

    _, _, tiles = selected_network(cfg)
    run_dir = run_dir_of(cfg, year)
    n, threads = local_cluster_size(cfg)
    tasks = tile_tasks([(t, m) for t in tiles for m in _months(cfg, year)], n * threads)
    rows = [{"tile": t, "month": m, "key": key, "done": partition_done(run_dir, t, m)}
            for (t, ms), key in zip(tasks, task_keys(tasks)) for m in ms]
    return pd.DataFrame(rows, columns=["tile", "month", "key", "done"])


def run_simulation(cfg: Config, year: int, scheduler: str | None = None,
                   n_workers: int | None = None, say=print, max_partitions: int | None = None,
                   force: bool = False) -> Path:
    """Compute the scenario's fleet-year and write all outputs; returns the run directory.

    An interrupted run resumes: finished partitions (written atomically) are not recomputed.
    A run directory holding a run of another configuration or of other input files is
    refused (:class:`InputError` naming both digests), or with *force* replaced as a whole
    (see :func:`claim_run_dir`). A run folder another process runs in, or a data dir another
    run reads while this one would ingest into it, is refused (docs/run_folders.md).
    *max_partitions* stops after that many new partitions (for tests of resuming).
    """
    from .prepare import check_year

    check_year(year)
    if n_workers is not None and n_workers < 1:
        raise InputError(f"--workers {n_workers}: a LocalCluster needs at least one worker")
    if scheduler or cfg.dask.scheduler:
        check_scheduler(scheduler or cfg.dask.scheduler)
    folder_path(cfg.out_dir, "out_dir")
    folder_path(cfg.data_dir, "data_dir")
    with contextlib.ExitStack() as held:        # the locks of the run folder and the data dir
        return _run(cfg, year, scheduler, n_workers, say, max_partitions, force, held)


def _run(cfg: Config, year: int, scheduler, n_workers, say, max_partitions, force,
         held: contextlib.ExitStack) -> Path:
    """:func:`run_simulation` holding its locks in *held*."""
    from .manifest import check_run_dir
    from .prepare import ensure_demo, ensure_ingested, input_digests, preflight
    from .reduce import reduce_run

    arrow_on_the_heap()
    t_start = time.perf_counter()
    timings: dict[str, float] = {}
    run_dir = run_dir_of(cfg, year)
    # the cluster starts (worker processes, their imports) while the inputs are checked
    # and the timeline is written; closed again if those stop the run
    starting = _Starting(cfg, scheduler, n_workers)
    timeline = None
    try:
        ensure_demo(cfg, year, say=say)
        inputs = input_digests(cfg)
        # a folder of another run (configuration or input files) is refused before the data
        # dir is ingested again for this one
        check_run_dir(run_dir, cfg.digest(), inputs, force)
        data_lock = held.enter_context(_lock_data_dir(cfg, inputs))
        inputs = ensure_ingested(cfg, say=say, inputs=inputs)
        preflight(cfg, year, say=say)
        data_lock.take(shared=True)             # other runs may read the data dir with this one
        # one run at a time in a run folder: a second one (another configuration with
        # --force, say) is refused before it writes there
        held.enter_context(lock_for_writing(run_dir_lock(run_dir), "run the command"))
        claim_run_dir(run_dir, cfg.digest(), force=force, say=say, inputs=inputs)
        timings["prepare_s"] = time.perf_counter() - t_start
        ctx, tiles = _run_context(cfg, year, run_dir)
        routes = cfg.run.routes
        todo = [(t, m) for t in tiles for m in _months(cfg, year) if not partition_done(run_dir, t, m)]
        if max_partitions is not None:
            todo = todo[:max_partitions]
        # the timeline (layovers and parked time: the standing tasks' points; the trips the
        # vehicle model drives) is written in a thread of its own, while the cluster starts
        # and the tiles' tasks begin: none of them needs it
        timeline = _Background(write_timeline, cfg, year, run_dir, routes=routes, name="timeline")
        # the radiation table's sun positions are computed (and cached beside the radiation
        # file, where every worker loads them) while the cluster starts
        warm = threading.Thread(target=_warm_radiation, daemon=True, name="sun-positions",
                                args=(ctx.data_dir, year, cfg.irradiance.diffuse_model == "perez_svf"))
        warm.start()
        t_wait = time.perf_counter()
        client, cluster = starting.result()
        timings["cluster_wait_s"] = time.perf_counter() - t_wait
    except BaseException:
        if timeline is not None:
            timeline.wait()
        starting.close()
        raise
    closer = threading.Thread(target=close_client, args=(client, cluster), name="close-cluster")
    froze = False
    try:
        n_workers_now = len(client.scheduler_info()["workers"])
        if not n_workers_now:
            n_workers_now = _wait_for_workers(client, scheduler or cfg.dask.scheduler)
        # a LocalCluster's workers share the machine's cores for ray casting
        ray_threads = cfg.dask.ray_threads or (
            max(1, (os.cpu_count() or 1) // max(1, n_workers_now)) if cluster is not None else 1)
        ctx = dataclasses.replace(ctx, ray_threads=ray_threads)
        say(_dashboard_line(client, cluster, cfg.dask.dashboard_port))
        warm.join()
        # what the ingest and the radiation table's load freed here goes back to the system
        # before the map (~150 MB of the radiation's temporaries alone, kept by the heap)
        hand_back_memory()
        # what this process holds by now (the libraries, the inputs' tables) outlives the
        # run: the cyclic collector leaves it alone until the run is done (each of its full
        # passes walked ~300,000 objects, ~0.15 s, while the scheduler and the reduce work
        # here); a freeze of the caller's own is left as it is
        froze = gc.get_freeze_count() == 0
        if froze:
            gc.freeze()
        t_map = time.perf_counter()
        # the run's context sent to the workers once: each task carried its own copy, held by
        # the scheduler (in this process) until it ran (a network's 105 tasks x 0.63 MB of
        # context: ~0.47 GB here through the map and the reduce)
        shared = client.scatter(ctx, broadcast=True, hash=False)
        futures = submit_tiles(client, shared, todo)
        # the reduce's modules load while the workers compute (not matplotlib: the workers
        # draw the figures)
        threading.Thread(target=importlib.import_module, args=("vipvflow.outputs.report",),
                         daemon=True, name="import-report").start()
        standing = timeline.result()
        timings["timeline_s"] = timeline.seconds
        standing_todo = [t for t in standing if not standing_done(run_dir, t)]
        if max_partitions is not None:
            standing_todo = standing_todo[:max(0, max_partitions - len(todo))]
        total = len(tiles) * len(cfg.run.months) + len(standing)
        n_todo = len(todo) + len(standing_todo)
        say(f"{len(tiles)} tiles x {len(cfg.run.months)} months + {len(standing)} standing = {total} "
            f"partitions, {n_todo} to compute ({total - n_todo} already done) with {n_workers_now} workers")
        futures = submit_standing(client, shared, standing_todo) + futures
        # the trip patterns' consumption (vehicle model, VECTO cycles) is computed with the map
        from .reduce import consumption_tasks

        consumption = consumption_tasks(client, cfg, year, run_dir, say=say)
        # what the timeline's and the patterns' reads freed, handed back before the map's
        # long wait (a network's ~0.15 GB, else held by this process through the reduce)
        hand_back_memory()
        results = collect_map(client, futures, n_todo)
        timings["map_s"] = time.perf_counter() - t_map
        # the BVH builds of each worker, whose caches of the map are then dropped
        builds = client.run(worker_bvh_builds, release=True)
        if not (all(partition_done(run_dir, t, m) for t in tiles for m in _months(cfg, year))
                and all(standing_done(run_dir, t) for t in standing)):
            say("stopped before all partitions were computed; run the same command again to resume")
            return run_dir
        restart = None
        if cluster is not None:
            # the run's own workers start the reduce afresh, with the patterns' consumption
            # fetched first (what the map left in their heaps, under the sums' reads, was
            # the top of a network-year's peak), and once the sums are gathered, all but one
            # are closed and that one restarted (:func:`cluster.fewer_fresh_workers`)
            t_restart = time.perf_counter()
            consumption.results()
            del shared
            fresh_workers(client, say)
            timings["restart_s"] = time.perf_counter() - t_restart
            restart = functools.partial(fewer_fresh_workers, client, cluster, say)
        # the partitions are read and summed by tasks on the cluster; the joins and the
        # outputs are made here
        t_red = time.perf_counter()
        with FolderProgress("reduce", run_dir):
            # the cluster shuts down once the partitions are summed and the figures drawn,
            # while this process writes the report
            summary = reduce_run(cfg, year, run_dir, say=say, client=client,
                                 cluster_done=lambda: closer.start(), timings=timings,
                                 consumption=consumption, fresh_workers=restart)
        timings["reduce_s"] = time.perf_counter() - t_red
    finally:
        t_close = time.perf_counter()
        if closer.ident is not None:         # started by the reduce
            closer.join()
        else:
            close_client(client, cluster)
        timings["close_wait_s"] = time.perf_counter() - t_close
        if froze:
            gc.unfreeze()
    timings["total_s"] = time.perf_counter() - t_start
    write_manifest(cfg, year, run_dir, inputs, timings, results, builds)
    say(_summary_line(summary))
    say(f"outputs in {run_dir}")
    return run_dir


def _dashboard_line(client, cluster, port: int | None) -> str:
    """Where the Dask dashboard is (the address its socket is bound to); for a LocalCluster
    whose configured port was taken, that it serves on another."""
    from urllib.parse import urlsplit

    from .cluster import bound_dashboard

    if not importlib.util.find_spec("bokeh"):
        return "dask dashboard: off (it needs bokeh: pip install 'vipvflow[app]')"
    link = bound_dashboard(client, cluster)       # the address its socket is bound to
    if cluster is not None and port and urlsplit(link).port != port:
        return f"dask dashboard: {link} (port {port} is taken)"
    return f"dask dashboard: {link}"


def _run_context(cfg: Config, year: int, run_dir: Path) -> tuple[RunContext, list[str]]:
    """What every task of the run is told, and the tiles the selected routes cross."""
    data_dir = Path(cfg.data_dir)
    feed = json.loads(DataDir(data_dir).gtfs.feed_json.read_text())
    trips, shapes, tiles = selected_network(cfg)
    routes = cfg.run.routes
    ctx = RunContext(
        data_dir=str(data_dir.resolve()), run_dir=str(run_dir.resolve()), year=year,
        irradiance=cfg.irradiance.model_dump(), pv_system=cfg.pv_system().model_dump(),
        pv_mode=cfg.pv.mode, monthly_temperature_c=tuple(cfg.monthly_temperature_c()),
        wind_speed_mps=cfg.climate.wind_speed_mps, timezone=feed["timezone"],
        bvh_cache_size=cfg.dask.bvh_cache_size, ground_albedo=cfg.city.albedo.ground,
        road_albedo=cfg.city.albedo.road, roof_height_m=cfg.trajectory.roof_height_m,
        routes=tuple(routes) if routes is not None else None, shapes=shapes,
        # the progress view's kWh per route, by the routes' public names
        route_of_trip=dict(zip(trips["trip_id"], trips["route_short_name"].astype(str))))
    return ctx, tiles


#: how long a run waits for the first worker of a scheduler that has none (s)
WORKER_WAIT_S = 60.0


def _wait_for_workers(client, address) -> int:
    """The workers of a scheduler that had none, once one joined; :class:`InputError` when
    none joins within :data:`WORKER_WAIT_S` (the run would wait for ever)."""
    try:
        client.wait_for_workers(1, timeout=WORKER_WAIT_S)
    except (TimeoutError, OSError):
        raise InputError(f"--scheduler {address}: the scheduler has no workers (none joined "
                         f"within {WORKER_WAIT_S:g} s): start some (dask worker {address})") from None
    return len(client.scheduler_info()["workers"])


def _lock_data_dir(cfg: Config, inputs) -> FolderLock:
    """The data dir's lock, taken exclusively (this run may ingest into it), or shared when
    another run reads it and these inputs need no ingest; else :class:`InputError` in one
    line naming the folder and the process holding it."""
    from .prepare import ingest_needed

    lock = data_dir_lock(folder_path(cfg.data_dir, "data_dir"))
    if lock.take():
        return lock
    if not lock.take(shared=True):
        lock.release()
        raise InputError(f"{cfg.data_dir}: another vipvflow process{lock.holder()} is ingesting "
                         "into this data dir; wait for it to finish, then run the command again")
    needed = ingest_needed(cfg, inputs)
    if needed:
        lock.release()
        raise InputError(f"{cfg.data_dir}: another vipvflow run{lock.holder()} is reading this data "
                         f"dir, and this scenario's inputs would replace its "
                         f"{', '.join(n + '/' for n in needed)}: "
                         "wait for that run to finish, or give this scenario a data_dir of its own")
    return lock


class _Background:
    """``fn(*args, **kwargs)`` in a thread of its own: :meth:`result` waits for it and returns
    its value (or raises its error); :attr:`seconds` is how long it took."""

    def __init__(self, fn, *args, name: str = "background", **kwargs):
        self._out: dict = {}
        self.seconds = 0.0
        self._thread = threading.Thread(target=self._call, args=(fn, args, kwargs), daemon=True,
                                        name=name)
        self._thread.start()

    def _call(self, fn, args, kwargs) -> None:
        t = time.perf_counter()
        try:
            self._out["value"] = fn(*args, **kwargs)
        except BaseException as exc:  # noqa: BLE001 - raised again by result()
            self._out["error"] = exc
        self.seconds = time.perf_counter() - t

    def wait(self) -> None:
        """Wait for it, whatever its outcome."""
        self._thread.join()

    def result(self):
        self._thread.join()
        if "error" in self._out:
            raise self._out["error"]
        return self._out["value"]


class _Starting(_Background):
    """:func:`make_client` in a thread of its own: :meth:`result` waits for it (and raises
    its error), :meth:`close` closes what it started."""

    def __init__(self, cfg: Config, scheduler: str | None, n_workers: int | None):
        super().__init__(make_client, cfg, scheduler, n_workers, name="start-cluster")

    def close(self) -> None:
        self.wait()
        if "value" in self._out:
            close_client(*self._out["value"])


def _warm_radiation(data_dir: str, year: int, sky: bool = False) -> None:
    """Load the radiation table once in this process (writes its sun-position cache, and
    with *sky* the Perez sky's tables), and compute the site's irradiation of the year the
    summary gives (kept by :func:`vipvflow.simulation.annual.site_ghi_kwh_m2`: its read,
    done here before the workers hold their memory, not in the reduce beside them); a
    failure is left for the workers and the reduce to report with the file named."""
    from ..models.sun_sky import RadiationTable
    from .annual import site_ghi_kwh_m2

    try:
        table = RadiationTable.load(data_dir, year)
        if sky:
            table.sky_index()           # computes and keeps the sky's tables where there are none
        del table
        site_ghi_kwh_m2(data_dir, year)
    except Exception:  # noqa: BLE001 - the same load fails again in the tasks, with its message
        pass


def _period(months: list[int]) -> str:
    """'the year', or the run's months ('June', 'June-August', 'Jan, Mar')."""
    import calendar

    if len(months) == 12:
        return "the year"
    names = [calendar.month_abbr[m] for m in months]
    if len(months) > 2 and months == list(range(months[0], months[-1] + 1)):
        return f"{names[0]}-{names[-1]}"
    return calendar.month_name[months[0]] if len(months) == 1 else ", ".join(names)


def _summary_line(s: dict) -> str:
    """The run's headline: the yield the batteries take (per year; a partial year's
    annualised, said so) with the harvested yields beside it, then the energies of the run's
    own months side by side (PV taken and curtailed, the demand it covers, grid energy
    avoided), the charging plan's infeasible block-days, the part of the lines inside the
    city model and what the shading statistics left out."""
    def kwp(key):
        return "n/a" if s.get(key) is None else f"{s[key]:.0f}"

    months = s.get("months") or list(range(1, 13))
    partial = len(months) < 12
    scale = len(months) / 12.0 if partial else 1.0         # annual figures back to the months
    period = _period(months)
    harvested = ", ".join(f"{label} {kwp(key)}" for label, key in (
        ("driving", "kwh_per_kwp_driving"), ("in service", "kwh_per_kwp_in_service"),
        ("whole day", "kwh_per_kwp_whole_day")) if s.get(key) is not None)
    line = (f"annual yield the batteries take {kwp('kwh_per_kwp_usable')} kWh/kWp "
            f"({'annualised from ' + period + '; ' if partial else ''}harvested: {harvested} "
            f"kWh/kWp; driving clear-sky {kwp('kwh_per_kwp_driving_clearsky')}); "
            f"shading loss {100 * s['shading_loss_allsky']:.1f} % on the road; "
            f"in {period} the batteries take {s['pv_kwh_usable'] / 1000:.1f} MWh "
            f"({s['pv_kwh_curtailed'] / 1000:.1f} MWh curtailed): "
            f"PV covers {100 * s['coverage']:.2f} % of the {s['fleet_demand_in_service_mwh'] * scale:.1f} "
            f"MWh the buses use in service (trips and layovers); "
            f"grid energy avoided {s['grid_kwh_avoided'] / 1000:.1f} MWh (depot "
            f"{s['grid_kwh_avoided_depot'] / 1000:.1f}, terminals {s['grid_kwh_avoided_opportunity'] / 1000:.1f}); "
            f"{s['avoided_charging_cycles_per_bus']:.1f} charging cycles avoided per bus"
            f"{' (annualised)' if partial else ''}; payback {s['payback_years']:.1f} years")
    n_bad, n_days = s.get("block_days_infeasible", 0), s.get("block_days", 0)
    if n_bad:
        first = "; ".join(s.get("infeasible_block_days_first") or [])
        line += (f". The charging plan cannot serve {n_bad} of {n_days} block-days (the battery "
                 f"would fall below its minimum; first: {first}): see block_day.parquet")
    elif n_days:
        line += f". The charging plan serves all {n_days} block-days"
    share = s.get("route_km_in_city_model_share")
    if share is not None and share < 1.0:
        inside = s.get("kwh_per_kwp_driving_in_city_model")
        loss = s.get("shading_loss_allsky_in_city_model")
        line += (f". In the city model: {100 * share:.0f} % of {s['route_km']:.1f} route-km, "
                 f"{100 * (s.get('pv_kwh_driving_in_city_model_share') or 0):.0f} % of the driving PV; "
                 f"driving yield there {'n/a' if inside is None else f'{inside:.0f} kWh/kWp'}, "
                 f"shading loss there {'n/a' if loss is None else f'{100 * loss:.1f} %'}; "
                 "outside it the roads are under open sky")
    n_bld = s.get("segments_in_buildings") or 0
    if n_bld:
        line += (f". {n_bld} segments ({100 * (s.get('route_km_in_buildings_share') or 0):.1f} % of "
                 "the route-km) lie inside building footprints: lit as the street next to them, "
                 "left out of the shading statistics")
    return line
