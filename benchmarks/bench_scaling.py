"""1 versus 2 Dask workers on the line-year, same process, same inputs.

Line ``L1`` of the full demo for all of 2024, run by :func:`run_simulation` on a LocalCluster
of 1 and of 2 worker processes, each from a fresh output folder, in the order 1, 2, 1, 2: the
machine is shared and noisy, so the best wall and map time of each count.  Figures: those
times, the speed-ups, and whether every run gives the same results (``trip_energy.parquet``
and ``segment_month.parquet`` compared column by column, relative tolerance 1e-9).

Each worker gets one core's worth of work: one task thread and one Embree ray thread
(``dask.ray_threads: 1``; the default for 2 workers on 2 cores), so the 1-worker run is
strictly serial.  Left to its default, a lone worker traces its ray batches on both cores:
that run is made once as well and its wall time reported (``wall_s_1_worker_all_cores``,
with ``speedup_wall_vs_1_worker_all_cores``).

The machine's own 2-process ceiling is measured before every pair of runs and after the
last (the machine is shared: its ceiling changes during the benchmark), with the same
statistic as the runs' speed-up, the best time of one process over the best time of two
(``2 x best(1 process) / best(2 processes)``), by two probes of work that needs nothing from
the other process:
* ``machine_speedup_2_processes``: the bare kernel's own work (``bench_kernel``: the line's
  passes of a few months, Embree occlusion, energy per trip) once in one process, then in
  each of two at the same time: the ceiling of this work on this machine, and the one the
  target is measured against;
* ``machine_speedup_2_processes_numpy``: a fixed piece of numpy work (gather, multiply,
  bincount), the probe of earlier runs (which took the best single probe's ratio of one
  before and one after the runs).
The issue's target: the whole run at least 1.8x faster, or within 5 % of that ceiling
(``speedup_wall_share_of_machine`` >= 0.95; ``speedup_wall_share_of_numpy_ceiling`` states
the same against the numpy probe).

Where the rest goes, from the fastest run of each: the time outside the map (the start and
the reduce), the CPU seconds of the command's process (scheduler, client, prepare, the
reduce's joins) and of the workers, the cores the 2-worker run kept busy, and
``speedup_wall_if_map_at_machine``: the whole run's speed-up had its map scaled as the
machine's ceiling with the time outside the map as measured (Amdahl's bound of the run);
``speedup_wall_if_2_cores_busy``: the speed-up had the 2-worker run kept both cores busy
throughout with the CPU seconds it spent (the bound its extra CPU leaves).

``tiny``: the small demo, one month, once.
"""
from __future__ import annotations

import json
import sys

import numpy as np
import pandas as pd

from benchmarks.bench_kernel import _tiles_of_route
from benchmarks.common import YEAR, demo_config, demo_paths, fresh_dir, prepare_demo, remove, run_pipeline


def _same(a, b) -> tuple[bool, float]:
    """Whether two result tables are equal (numeric columns to 1e-9 relative); max rel. diff."""
    if list(a.columns) != list(b.columns) or len(a) != len(b):
        return False, float("inf")
    keys = [c for c in a.columns if not pd.api.types.is_numeric_dtype(a[c])]
    keys = [c for c in keys if c != "geometry"]
    a = a.sort_values(keys).reset_index(drop=True) if keys else a
    b = b.sort_values(keys).reset_index(drop=True) if keys else b
    worst = 0.0
    for c in a.columns:
        if c == "geometry":
            continue
        if pd.api.types.is_numeric_dtype(a[c]):
            x, y = a[c].to_numpy(np.float64), b[c].to_numpy(np.float64)
            scale = np.maximum(np.abs(x), np.abs(y))
            rel = np.where(scale > 0, np.abs(x - y) / np.where(scale > 0, scale, 1), 0.0)
            worst = max(worst, float(np.nanmax(rel)) if len(rel) else 0.0)
        elif not (a[c].astype(str).to_numpy() == b[c].astype(str).to_numpy()).all():
            return False, float("inf")
    return worst <= 1e-9, worst


def _probe_kernel(n_iter: int) -> float:
    """A fixed piece of the hot path's kind of work (gather, multiply, bincount over 150,000
    float32 values), timed in this process (s)."""
    import time

    rng = np.random.default_rng(0)
    a = rng.random(150_000).astype(np.float32)
    idx = rng.integers(0, 150_000, 150_000)
    t = time.perf_counter()
    for _ in range(n_iter):
        np.bincount(idx % 1000, a[idx] * 2.0, 1000)
    return time.perf_counter() - t


def _probe_line(data_dir: str, tiles: list[str], months: list[int]) -> float:
    """The bare kernel's timed work (passes, lookup, rays, energy per trip) over *tiles* x
    *months* of line ``L1``, in this process (s; the scenes' builds and the tables' loads
    are not timed)."""
    from benchmarks.bench_kernel import _tile_work

    r = _tile_work(data_dir, tiles, "L1", months)
    return r["passes_s"] + r["kernel_s"]


def machine_probe(data_dir: str, tiles: list[str], months: list[int], n_iter: int) -> dict:
    """Both probes once, each first in one process, then in each of two at the same time
    (a fresh pair of processes, warmed up with a piece of the same work first): seconds of
    the one process and of the slower of the two."""
    from concurrent.futures import ProcessPoolExecutor

    out = {}
    with ProcessPoolExecutor(2) as pool:
        list(pool.map(_probe_line, [data_dir] * 2, [tiles[:1]] * 2, [months[:1]] * 2))
        for name, fn, args in (("numpy", _probe_kernel, (n_iter,)),
                               ("kernel", _probe_line, (data_dir, tiles, months))):
            one = pool.submit(fn, *args).result()
            two = list(pool.map(fn, *[[a] * 2 for a in args]))
            out[name] = {"s_1_process": round(one, 3), "s_2_processes": round(max(two), 3)}
    return out


def ceiling(probes: list[dict], name: str) -> float:
    """The machine's 2-process speed-up by probe *name*: twice the best time of one process
    over the best time of two (the statistic of the runs' own speed-up)."""
    return round(2 * min(p[name]["s_1_process"] for p in probes)
                 / min(p[name]["s_2_processes"] for p in probes), 3)


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    months = [6] if tiny else list(range(1, 13))
    repeats = 1 if tiny else 5
    prepare_demo(size)
    runs: dict = {1: [], 2: [], "1_all_cores": []}
    tables = []
    data_dir = str(demo_paths(size)["data"])
    tiles = _tiles_of_route(data_dir, "L1")
    probe_months = [6] if tiny else [2, 5, 8, 11]
    n_iter = 100 if tiny else 1500
    probes = []
    # 1, 2, 1, 2, ... workers: a noisy shared machine slows runs in turn, the best of each
    # counts; then one lone worker left to use both cores for its rays; the machine's
    # ceiling probed before each pair and after the last
    order = [(w, 1) for _ in range(repeats) for w in (1, 2)] + [(1, None)]
    for workers, ray_threads in order:
        if workers == 1 and ray_threads:
            probes.append(machine_probe(data_dir, tiles, probe_months, n_iter))
        out = fresh_dir(f"scaling-{workers}w")
        try:
            cfg = demo_config(size, out_dir=out, routes=["L1"], months=months, n_workers=workers)
            cfg.dask.ray_threads = ray_threads
            r = run_pipeline(cfg, YEAR, n_workers=workers, rss_interval_s=1.0)
            tables.append({name: pd.read_parquet(r["run_dir"] / f"{name}.parquet")
                           for name in ("trip_energy", "segment_month")})
        finally:
            remove(out)
        runs[workers if ray_threads else "1_all_cores"].append({
            "wall_s": r["wall_s"], "map_s": r["manifest"]["timings_s"]["map_s"],
            "reduce_s": r["manifest"]["timings_s"]["reduce_s"],
            "outside_map_s": r["wall_s"] - r["manifest"]["timings_s"]["map_s"],
            "cpu_s_command": r["cpu_s_command"], "cpu_s_workers": r["cpu_s_workers"],
            "cores_busy": (r["cpu_s_command"] + r["cpu_s_workers"]) / r["wall_s"],
            "passes": r["manifest"]["passes_computed"], "peak_rss_mb": r["peak_rss_mb"]})
    probes.append(machine_probe(data_dir, tiles, probe_months, n_iter))
    checks = [_same(tables[0][name], t[name]) for t in tables[1:] for name in t]
    best = {w: {k: min(x[k] for x in runs[w]) for k in ("wall_s", "map_s")} for w in (1, 2)}
    fastest = {w: min(runs[w], key=lambda x: x["wall_s"]) for w in (1, 2)}
    machine, machine_numpy = ceiling(probes, "kernel"), ceiling(probes, "numpy")
    speedup = best[1]["wall_s"] / best[2]["wall_s"]
    figures = {
        "passes": runs[2][0]["passes"],
        "wall_s_1_worker": round(best[1]["wall_s"], 2),
        "wall_s_2_workers": round(best[2]["wall_s"], 2),
        "speedup_wall": round(speedup, 3),
        "speedup_wall_share_of_machine": round(speedup / machine, 3),
        "map_s_1_worker": best[1]["map_s"],
        "map_s_2_workers": best[2]["map_s"],
        "speedup_map": round(best[1]["map_s"] / best[2]["map_s"], 3),
        "wall_s_1_worker_all_cores": round(runs["1_all_cores"][0]["wall_s"], 2),
        "speedup_wall_vs_1_worker_all_cores": round(runs["1_all_cores"][0]["wall_s"] / best[2]["wall_s"], 3),
        "machine_speedup_2_processes": machine,
        "machine_speedup_2_processes_numpy": machine_numpy,
        "speedup_wall_share_of_numpy_ceiling": round(speedup / machine_numpy, 3),
        # each probe's own ratio, in the order measured (before each pair, after the last)
        "machine_speedup_2_processes_probes": [
            round(2 * p["kernel"]["s_1_process"] / p["kernel"]["s_2_processes"], 3) for p in probes],
        "machine_speedup_2_processes_numpy_probes": [
            round(2 * p["numpy"]["s_1_process"] / p["numpy"]["s_2_processes"], 3) for p in probes],
        # the fastest run of each: the time outside the map (start, reduce), the CPU seconds
        # of the command's process and of the workers, and the cores they kept busy
        "outside_map_s_1_worker": round(fastest[1]["outside_map_s"], 2),
        "outside_map_s_2_workers": round(fastest[2]["outside_map_s"], 2),
        "cpu_s_command_1_worker": round(fastest[1]["cpu_s_command"], 2),
        "cpu_s_command_2_workers": round(fastest[2]["cpu_s_command"], 2),
        "cpu_s_workers_1_worker": round(fastest[1]["cpu_s_workers"], 2),
        "cpu_s_workers_2_workers": round(fastest[2]["cpu_s_workers"], 2),
        "cores_busy_2_workers": round(fastest[2]["cores_busy"], 2),
        # the whole run's speed-up had its map scaled as the machine's ceiling, with the
        # time outside the map as measured (Amdahl's bound for this run)
        "speedup_wall_if_map_at_machine": round(
            fastest[1]["wall_s"] / (fastest[1]["map_s"] / machine + fastest[2]["outside_map_s"]), 3),
        # the whole run's speed-up had the 2-worker run kept both cores busy all the time
        # with the CPU seconds it spent (its workers' and the command's): the bound the
        # extra CPU of a second worker (its start, its figures' imports, the two processes'
        # contention) leaves, whatever the scheduling
        "speedup_wall_if_2_cores_busy": round(
            fastest[1]["wall_s"] / ((fastest[2]["cpu_s_workers"] + fastest[2]["cpu_s_command"]) / 2), 3),
        "results_equal": all(ok for ok, _ in checks) if checks else True,
        "max_rel_diff": max((d for _, d in checks), default=0.0),
    }
    # the acceptance: at least 1.8x, or within 5 % of the machine's own ceiling
    targets = {"speedup_wall": ">= 1.8, or speedup_wall_share_of_machine >= 0.95",
               "results_equal": "True"}
    return {"figures": figures, "targets": targets, "runs": runs, "probes": probes,
            "config": {"size": size, "routes": ["L1"], "months": months, "repeats": repeats,
                       "ray_threads_per_worker": 1, "probe_months": probe_months,
                       "probe_numpy_iterations": n_iter}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
