"""1 versus 2 Dask workers on a fixed slice of the line-year, same process, same inputs.

Line ``L1`` of the full demo for two months (May and June 2024: long days, the most rays),
run by :func:`run_simulation` on a LocalCluster of 1 and then 2 worker processes, each from
a fresh output folder.  Figures: wall time and map time (the partitions alone) of each,
the speed-ups, and whether both runs give the same results (``trip_energy.parquet`` and
``segment_month.parquet`` compared column by column, relative tolerance 1e-9).

Twice: with the default ray threads (cores / workers: the 1-worker run traces its large ray
batches on both cores, so it is not serial) and with one ray thread per task in both runs
(``dask.ray_threads: 1``: the scaling of the task graph itself).  All four runs must give
the same results.

``tiny``: the small demo, one month.
"""
from __future__ import annotations

import json
import sys

import numpy as np
import pandas as pd

from benchmarks.common import YEAR, demo_config, fresh_dir, prepare_demo, remove, run_pipeline


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


def machine_scaling(n_iter: int = 1500) -> dict:
    """How much faster this machine does 2 x the same numpy work in 2 processes than 1 x in
    one: the ceiling the pipeline's 1 -> 2 worker speed-up is measured against."""
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2) as pool:
        one = pool.submit(_probe_kernel, n_iter).result()
        two = list(pool.map(_probe_kernel, [n_iter, n_iter]))
    return {"probe_s_1_process": round(one, 3), "probe_s_2_processes": round(max(two), 3),
            "machine_speedup_2_processes": round(2 * one / max(two), 3)}


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    months = [6] if tiny else [5, 6]
    prepare_demo(size)
    runs, tables = {}, {}
    # "default": ray threads per task = cores / workers (the 1-worker run traces on both
    # cores); "rt1": one ray thread per task in both runs (the task graph's own scaling)
    for mode, ray_threads in (("default", None), ("rt1", 1)):
        for workers in (1, 2):
            out = fresh_dir(f"scaling-{mode}-{workers}w")
            try:
                cfg = demo_config(size, out_dir=out, routes=["L1"], months=months, n_workers=workers)
                if ray_threads:
                    cfg = cfg.model_copy(update={"dask": cfg.dask.model_copy(
                        update={"ray_threads": ray_threads})})
                r = run_pipeline(cfg, YEAR, n_workers=workers)
                tables[(mode, workers)] = {name: pd.read_parquet(r["run_dir"] / f"{name}.parquet")
                                           for name in ("trip_energy", "segment_month")}
            finally:
                remove(out)
            runs[f"{mode}_{workers}"] = {"wall_s": r["wall_s"],
                                         "map_s": r["manifest"]["timings_s"]["map_s"],
                                         "passes": r["manifest"]["passes_computed"],
                                         "peak_rss_mb": r["peak_rss_mb"]}
    ref = tables[("default", 1)]
    checks = [_same(ref[name], t[name]) for key, t in tables.items() for name in ref]
    figures = {"passes": runs["default_2"]["passes"]}
    for mode in ("default", "rt1"):
        one, two = runs[f"{mode}_1"], runs[f"{mode}_2"]
        sfx = "" if mode == "default" else "_ray_threads_1"
        figures.update({
            f"wall_s_1_worker{sfx}": round(one["wall_s"], 2),
            f"wall_s_2_workers{sfx}": round(two["wall_s"], 2),
            f"speedup_wall{sfx}": round(one["wall_s"] / two["wall_s"], 3),
            f"map_s_1_worker{sfx}": one["map_s"],
            f"map_s_2_workers{sfx}": two["map_s"],
            f"speedup_map{sfx}": round(one["map_s"] / two["map_s"], 3),
        })
    figures.update(machine_scaling(100 if tiny else 1500))
    figures["map_speedup_vs_machine"] = round(figures["speedup_map"]
                                              / figures["machine_speedup_2_processes"], 3)
    figures["results_equal"] = all(ok for ok, _ in checks)
    figures["max_rel_diff"] = max(d for _, d in checks)
    targets = {"speedup_wall": ">= 1.7", "speedup_map": ">= 1.7",
               "speedup_wall_ray_threads_1": ">= 1.7", "speedup_map_ray_threads_1": ">= 1.7",
               "results_equal": "True"}
    return {"figures": figures, "targets": targets, "runs": runs,
            "config": {"size": size, "routes": ["L1"], "months": months}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
