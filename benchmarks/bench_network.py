"""A national-size network over a full year, measured end to end (or one week or month).

A synthetic GTFS feed of 200 bus lines over the demo town's streets (the demo
city, its terrain and its CAMS year are reused as ingested): each line is a stretch of one
demo street (5-15 km), or runs along one street to the centre and out along the other; the
lines overlap like the trunk corridors of a real network.  Stops every 400 m, 20 km/h with
dwell, two directions, weekday headways of 10 to 120 min (05:00-23:00), Saturday at twice
and Sunday at three times the weekday headway.

The feed is ingested (timed apart), then :func:`run_simulation` runs the period on a
LocalCluster of 2 workers (or on the cluster at ``VIPVFLOW_BENCH_SCHEDULER``, e.g. one
started with ``dask scheduler`` and two ``dask worker``; the run folder must be on a path
the workers see) from a fresh output folder.  Figures: lines, segments, trips and passes,
wall time, map and reduce time, the reduce's share of the wall time, passes per second,
peak RSS of the process tree (this process and a LocalCluster's workers); on an outside
cluster also each worker's and the scheduler's own peak RSS (``cluster_peak_rss_mb``), asked
of them after the run, and their sum.

Issue 41: the bare kernel (:func:`benchmarks.bench_kernel.bare_kernel`, the line-year's
passes of ``L1``) runs before and after the network, as ``line_year`` pairs them, and
``kernel_ratio`` is its best passes per second over the network's (target 1.5); peak PSS
beside the peak RSS (:class:`benchmarks.common.PeakRSS`) and each process's own peak RSS.
``VIPVFLOW_BENCH_NETWORK_LINES`` sets the lines (default 200; the cost model in README.md
ran 50, 100 and 200).  The run computes its tiles' geometry as a first run does (the data
dir's geometry cache emptied first); with ``VIPVFLOW_BENCH_NETWORK_CACHED`` set, the same
network runs once more from a fresh folder with the geometry the first run left in the
cache (``geometry_cached``: its time, passes per second and kernel ratio, geometry
worker-s, peak RSS, and whether its summary.json equals the first run's).

Periods (``VIPVFLOW_BENCH_NETWORK`` or ``--week``/``--month`` on the module's command line):
``year`` (default: every day of 2024, all 12 months: ~3.5 G passes, 20-40 min of both
cores), ``month`` (June 2024) and ``week`` (Monday 10 to Sunday 16 June 2024; long days:
more daytime passes than an average week), the last two for quick checks of their own:
no year is extrapolated from them, because much of a short period's time does not grow
with the period (each tile's geometry, sky view and reflectors, took ~560 worker
CPU-seconds of this network's week and of its year alike: the week x 52 "year" was
14x the measured one).  ``tiny``: the small demo's street, 4 lines, one weekday.
"""

from __future__ import annotations

import datetime as dt
import io
import json
import os
import shutil
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd

from benchmarks.bench_kernel import bare_kernel
from benchmarks.common import (WORK, YEAR, PeakRSS, demo_config, demo_paths, fresh_dir, prepare_demo,
                               remove, run_pipeline, stage_split)

WEEK_START = dt.date(2024, 6, 10)         # a Monday
PERIODS = ("year", "month", "week")
HEADWAYS_MIN = (10, 15, 20, 30, 30, 60, 60, 120)
SERVICES = {"WD": ((1, 1, 1, 1, 1, 0, 0), "05:00", "23:00", 1),
            "SA": ((0, 0, 0, 0, 0, 1, 0), "06:00", "23:00", 2),
            "SU": ((0, 0, 0, 0, 0, 0, 1), "07:00", "22:00", 3)}


def sub_polyline(xy: np.ndarray, s0: float, s1: float) -> np.ndarray:
    """The part of a polyline between distances *s0* and *s1* (m), reversed when s1 < s0."""
    from vipvflow.demo.layout import cumulative_length, point_at

    cum = cumulative_length(xy)
    a, b = sorted((s0, s1))
    inner = xy[(cum > a) & (cum < b)]
    part = np.concatenate([point_at(xy, [a]), inner, point_at(xy, [b])])
    return part if s0 <= s1 else part[::-1]


def network_paths(layout, n_lines: int, seed: int = 11) -> list[np.ndarray]:
    """*n_lines* polylines (EPSG:2169) over the streets of *layout*."""
    from vipvflow.demo.layout import CENTRE_XY, cumulative_length

    rng = np.random.default_rng(seed)
    streets = [line.xy for line in layout.lines]
    lengths = [float(cumulative_length(xy)[-1]) for xy in streets]
    centre = []
    for xy in streets:
        fine = sub_polyline(xy, 0, cumulative_length(xy)[-1])
        cum = cumulative_length(fine)
        centre.append(float(cum[np.argmin(np.hypot(*(fine - CENTRE_XY).T))]))
    paths = []
    while len(paths) < n_lines:
        if len(streets) > 1 and rng.random() < 0.4:        # along one street to the centre, out another
            i, j = rng.choice(len(streets), 2, replace=False)
            a = np.clip(centre[i] + rng.choice([-1, 1]) * rng.uniform(1500, 7000), 0, lengths[i])
            b = np.clip(centre[j] + rng.choice([-1, 1]) * rng.uniform(1500, 7000), 0, lengths[j])
            path = np.concatenate([sub_polyline(streets[i], a, centre[i]),
                                   sub_polyline(streets[j], centre[j], b)[1:]])
        else:
            i = rng.integers(len(streets))
            length = min(rng.uniform(5000, 15000), lengths[i] * 0.95)
            s0 = rng.uniform(0, lengths[i] - length)
            path = sub_polyline(streets[i], s0, s0 + length) if rng.random() < 0.5 else \
                sub_polyline(streets[i], s0 + length, s0)
        if cumulative_length(path)[-1] > 1000:
            paths.append(path)
    return paths


def _hm(text: str) -> int:
    h, m = text.split(":")
    return int(h) * 3600 + int(m) * 60


def write_network_gtfs(path: Path, paths: list[np.ndarray], days: list[dt.date], seed: int = 12) -> dict:
    """A GTFS zip of one line per polyline, running on *days*; returns counts."""
    from pyproj import Transformer

    from vipvflow.demo.gtfs import _blocks, direction_trips, stop_offsets, stop_positions
    from vipvflow.demo.layout import cumulative_length, densify, point_at

    rng = np.random.default_rng(seed)
    to_wgs84 = Transformer.from_crs("EPSG:2169", "EPSG:4326", always_xy=True)
    stops, shapes, trips, stop_times, routes = [], [], [], [], []
    for k, xy in enumerate(paths):
        rid = f"N{k:03d}"
        length = float(cumulative_length(xy)[-1])
        headway = int(rng.choice(HEADWAYS_MIN))
        routes.append({"route_id": rid, "agency_id": "NET", "route_short_name": str(k + 100),
                       "route_long_name": f"Network line {k + 100}", "route_type": 3})
        pts = densify(xy, 20.0)
        cum = cumulative_length(pts)
        lon, lat = to_wgs84.transform(pts[:, 0], pts[:, 1])
        stop_s = stop_positions(length)
        slon, slat = to_wgs84.transform(*point_at(xy, stop_s).T)
        arr, dep = stop_offsets(stop_s)
        for d in (0, 1):
            order = slice(None) if d == 0 else slice(None, None, -1)
            shapes.append(pd.DataFrame({
                "shape_id": f"{rid}_d{d}", "shape_pt_lat": np.round(lat[order], 7),
                "shape_pt_lon": np.round(lon[order], 7), "shape_pt_sequence": np.arange(len(pts)),
                "shape_dist_traveled": np.round(cum if d == 0 else (cum[-1] - cum)[::-1], 2)}))
            stops.append(pd.DataFrame({
                "stop_id": [f"{rid}_S{i:02d}_d{d}" for i in range(len(stop_s))],
                "stop_name": [f"{rid} stop {i}" for i in range(len(stop_s))],
                "stop_lat": np.round(slat, 7), "stop_lon": np.round(slon, 7)}))
        for sid, (_, start, end, factor) in SERVICES.items():
            t0 = np.arange(_hm(start), _hm(end), headway * 60 * factor, dtype=np.int64)
            buses = _blocks(t0, t0, int(arr[-1]))
            for d in (0, 1):
                t, st = direction_trips(rid, sid, d, t0, buses[d], stop_s, length, arr, dep)
                trips.append(t)
                stop_times.append(st)
    start, end = min(days).strftime("%Y%m%d"), max(days).strftime("%Y%m%d")
    weekdays = {d.weekday() for d in days}
    names = ["monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday"]
    calendar = pd.DataFrame([{"service_id": sid, **{names[i]: int(mask[i] and i in weekdays) for i in range(7)},
                              "start_date": start, "end_date": end}
                             for sid, (mask, *_rest) in SERVICES.items()])
    tables = {
        "agency.txt": pd.DataFrame([{"agency_id": "NET", "agency_name": "vipvflow benchmark network",
                                     "agency_url": "https://example.org/vipvflow-bench",
                                     "agency_timezone": "Europe/Luxembourg"}]),
        "routes.txt": pd.DataFrame(routes), "stops.txt": pd.concat(stops),
        "trips.txt": pd.concat(trips), "stop_times.txt": pd.concat(stop_times),
        "calendar.txt": calendar, "shapes.txt": pd.concat(shapes),
    }
    tmp = path.with_name(path.name + ".tmp")
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, df in tables.items():
            buf = io.StringIO()
            df.to_csv(buf, index=False, lineterminator="\n")
            zf.writestr(name, buf.getvalue())
    os.replace(tmp, path)
    return {"lines": len(paths), "trips": int(len(tables["trips.txt"])),
            "stop_times": int(len(tables["stop_times.txt"])),
            "network_km": round(sum(float(np.hypot(*np.diff(p, axis=0).T).sum()) for p in paths) / 1000, 1)}


def period_days(period: str, tiny: bool = False) -> tuple[list[dt.date], list[int]]:
    """The service days and the run's months of a benchmark period."""
    if tiny:
        return [dt.date(2024, 6, 12)], [6]
    if period == "year":
        first = dt.date(YEAR, 1, 1)
        return [first + dt.timedelta(days=i) for i in range((dt.date(YEAR + 1, 1, 1) - first).days)], \
            list(range(1, 13))
    if period == "month":
        return [dt.date(YEAR, 6, d) for d in range(1, 31)], [6]
    if period == "week":
        return [WEEK_START + dt.timedelta(days=i) for i in range(7)], [6]
    raise ValueError(f"benchmark period {period!r}: not one of {', '.join(PERIODS)}")


def run(tiny: bool = False, period: str | None = None, scheduler: str | None = None) -> dict:
    from vipvflow.demo.layout import build_layout
    from vipvflow.simulation.prepare import ensure_ingested

    period = period or os.environ.get("VIPVFLOW_BENCH_NETWORK", "year")
    scheduler = scheduler or os.environ.get("VIPVFLOW_BENCH_SCHEDULER") or None
    size = "small" if tiny else "full"
    n_lines = 4 if tiny else int(os.environ.get("VIPVFLOW_BENCH_NETWORK_LINES", "200"))
    days, months = period_days(period, tiny)
    prepare_demo(size)
    demo = demo_paths(size)
    root = WORK / f"network-{size}"
    data_dir = root / f"data-{len(days)}d"
    data_dir.mkdir(parents=True, exist_ok=True)
    for part in ("city", "radiation"):                   # the demo's city and sun, as ingested
        link = data_dir / part
        if link.is_symlink() and link.readlink() != demo["data"] / part:
            link.unlink()           # to another checkout's demo (perhaps gone since)
        if not link.exists():
            link.symlink_to(demo["data"] / part, target_is_directory=True)
    feed = root / f"network_{n_lines}_lines_{len(days)}d.zip"
    t = time.perf_counter()
    counts = write_network_gtfs(feed, network_paths(build_layout(42, size), n_lines), days)
    write_s = time.perf_counter() - t
    inputs = {"citygml": [str(demo["input"] / "demo_city.gml")], "gtfs": str(feed),
              "cams": [str(demo["input"] / "cams_radiation_demo.csv")]}
    out = fresh_dir("network")
    try:
        cfg = demo_config(size, data_dir=data_dir, out_dir=out, months=months, n_workers=2,
                          inputs=inputs, scenario=f"network-{size}")
        with PeakRSS() as mem:
            t = time.perf_counter()
            ensure_ingested(cfg, say=lambda *a: None)
            ingest_s = time.perf_counter() - t
        kernel = [bare_kernel(size, months if tiny else list(range(1, 13)))]
        r = run_pipeline(cfg, YEAR, n_workers=None if scheduler else 2, scheduler=scheduler, pss=True)
        kernel.append(bare_kernel(size, months if tiny else list(range(1, 13))))
        cluster_rss = outside_cluster_peak_rss(scheduler) if scheduler else {}
        segments = len(pd.read_parquet(data_dir / "gtfs" / "segments.parquet", columns=["tile"]))
        trip_days = len(pd.read_parquet(r["run_dir"] / "trip_energy.parquet", columns=["trip_id"]))
        part_bytes = _part_bytes(r["run_dir"])
        cached = {}
        if os.environ.get("VIPVFLOW_BENCH_NETWORK_CACHED"):
            # the same network again from a fresh folder, the tiles' geometry from the cache
            # the first run left in the data dir
            summary = json.loads((r["run_dir"] / "summary.json").read_text())
            shutil.rmtree(r["run_dir"])
            c = run_pipeline(cfg, YEAR, n_workers=None if scheduler else 2, scheduler=scheduler,
                             pss=True, geometry_cache=True)
            cached = _cached_figures(c, kernel, summary)
    finally:
        remove(out)
    return _result(r, counts, days, period if not tiny else "day", scheduler,
                   {"segments": segments, "trips_run": trip_days, "gtfs_ingest_s": round(ingest_s, 1),
                    "partition_bytes_per_pass": round(part_bytes / max(r["manifest"]["passes_computed"], 1), 3)},
                   feed_write_s=round(write_s, 1), ingest_peak_rss_mb=round(mem.peak_mb),
                   kernel=kernel, **cached, **cluster_rss)


def _cached_figures(c: dict, kernel: list, summary: dict) -> dict:
    """A second run's figures (``geometry_cached``: its tiles' geometry from the data dir's
    cache): wall and map time, passes per second and their ratio to the bare kernel's best,
    the geometry's worker-s, the tiles taken from the cache, peak RSS, and whether its
    summary.json equals the first run's (as ``line_year`` compares its runs')."""
    m = c["manifest"]
    passes = m["passes_computed"]
    k_pps = max(k["passes"] / k["wall_s"] for k in kernel)
    later = json.loads((c["run_dir"] / "summary.json").read_text())
    return {"geometry_cached": {
        "wall_s": round(c["wall_s"], 1), "map_s": m["timings_s"].get("map_s"),
        "passes_per_s": round(passes / c["wall_s"]),
        "kernel_ratio": round(k_pps / (passes / c["wall_s"]), 3),
        "worker_geometry_s": round(stage_split(m)["geometry_s"], 1),
        "tiles_from_cache": m["partition_counts"].get("geometry_tiles_from_cache", 0),
        "peak_rss_gb": round(c["peak_rss_mb"] / 1024, 3),
        "summary_equal": summary == later}}


def outside_cluster_peak_rss(scheduler: str) -> dict:
    """The peak RSS of the scheduler and of each worker process of the cluster at *scheduler*
    (each process's own high-water mark since it started: a cluster that ran other work
    before shows that too), asked of them through a client; not their nannies."""
    from distributed import Client

    def _own_peak_rss_mb() -> float:      # sent by value: the cluster need not see benchmarks/
        import resource

        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    with Client(scheduler, timeout=60) as client:
        workers = client.run(_own_peak_rss_mb)
        sched = client.run_on_scheduler(_own_peak_rss_mb)
    return {"cluster_peak_rss_mb": {"scheduler": round(sched),
                                     **{addr: round(mb) for addr, mb in sorted(workers.items())}},
            "cluster_peak_rss_gb_sum": round((sched + sum(workers.values())) / 1024, 3)}


def _part_bytes(run_dir: Path) -> int:
    """Bytes of the per-pass partition files (trip, segment_month; hourly in older runs) of a run."""
    return sum(f.stat().st_size for kind in ("trip", "segment_month", "hourly")
               for f in (run_dir / "parts" / kind).glob("tile=*/month=*.parquet"))


def _result(r: dict, counts: dict, days: list, period: str, scheduler, extra: dict, kernel=(),
            **more) -> dict:
    m = r["manifest"]
    passes = m["passes_computed"]
    wall = r["wall_s"]
    reduce_s = m["timings_s"].get("reduce_s")
    figures = {
        "period": period,
        "lines": counts["lines"],
        "network_km": counts["network_km"],
        **{k: extra[k] for k in ("segments", "trips_run")},
        "passes": passes,
        "wall_s": round(wall, 1),
        "wall_min": round(wall / 60, 2),
        "map_s": m["timings_s"].get("map_s"),
        "reduce_s": reduce_s,
        "reduce_share": round(reduce_s / wall, 4) if reduce_s is not None else None,
        "passes_per_s": round(passes / wall),
        "peak_rss_gb": round(r["peak_rss_mb"] / 1024, 3),
        "peak_pss_gb": round(r["peak_pss_mb"] / 1024, 3) if r.get("peak_pss_mb") else None,
        "peak_rss_by_process_mb": r.get("peak_rss_by_process_mb"),
        "peak_rss_main_gb": round(r["peak_rss_main_mb"] / 1024, 3),
        "peak_at_s": r.get("peak_at_s"),
        "rss_at_peak_by_process_mb": r.get("rss_at_peak_by_process_mb"),
        "peak_after_line": r.get("peak_after_line"),
        "peak_rss_by_step_mb": r.get("peak_rss_by_step_mb"),
        "partition_bytes_per_pass": extra["partition_bytes_per_pass"],
        "gtfs_ingest_s": extra["gtfs_ingest_s"],
    }
    if kernel:                                        # the bare kernel before and after
        k_pps = [k["passes"] / k["wall_s"] for k in kernel]
        figures.update(kernel_passes_per_s_runs=[round(v) for v in k_pps],
                       kernel_passes_per_s=round(max(k_pps)),
                       kernel_ratio=round(max(k_pps) / (passes / wall), 3))
    if "cluster_peak_rss_gb_sum" in more:             # an outside cluster's processes
        figures["cluster_peak_rss_gb_sum"] = more.pop("cluster_peak_rss_gb_sum")
    targets = {"wall_min": "< 30 for the year (issue 21)", "reduce_share": "< 0.10",
               "peak_rss_gb": "< 4 (issue 41)", "kernel_ratio": "<= 1.5 (issue 41)"}
    out = {"figures": figures, "targets": targets, "feed": counts,
           "cluster": scheduler or "LocalCluster, 2 workers",
           "peak_rss_note": "process tree of the benchmark (a LocalCluster's workers included; "
                            "an outside cluster's scheduler and workers in cluster_peak_rss_mb)",
           "days": [days[0].isoformat(), days[-1].isoformat(), len(days)],
           "run_timings_s": m["timings_s"], "partition_timings_s": m["partition_timings_s"], **more}
    return out


if __name__ == "__main__":  # pragma: no cover
    args = sys.argv[1:]
    chosen = next((a[2:] for a in args if a[2:] in PERIODS), None)
    print(json.dumps(run(tiny="--tiny" in args, period=chosen), indent=2, default=str))
