"""1 versus 2 Dask workers on a fixed slice of the line-year, same process, same inputs.

Line ``L1`` of the full demo for two months (May and June 2024: long days, the most rays),
run by :func:`run_simulation` on a LocalCluster of 1 and then 2 worker processes, each from
a fresh output folder.  Figures: wall time and map time (the partitions alone) of each,
the speed-ups, and whether both runs give the same results (``trip_energy.parquet`` and
``segment_month.parquet`` compared column by column, relative tolerance 1e-9).

Note: each worker process also traces large ray batches on a thread pool the size of the
cores it may use (:mod:`vipvflow.shading`), so the 1-worker run is not strictly serial.

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


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    months = [6] if tiny else [5, 6]
    prepare_demo(size)
    runs, tables = {}, {}
    for workers in (1, 2):
        out = fresh_dir(f"scaling-{workers}w")
        try:
            cfg = demo_config(size, out_dir=out, routes=["L1"], months=months, n_workers=workers)
            r = run_pipeline(cfg, YEAR, n_workers=workers)
            tables[workers] = {name: pd.read_parquet(r["run_dir"] / f"{name}.parquet")
                               for name in ("trip_energy", "segment_month")}
        finally:
            remove(out)
        runs[workers] = {"wall_s": r["wall_s"], "map_s": r["manifest"]["timings_s"]["map_s"],
                         "passes": r["manifest"]["passes_computed"],
                         "peak_rss_mb": r["peak_rss_mb"]}
    checks = {name: _same(tables[1][name], tables[2][name]) for name in tables[1]}
    figures = {
        "passes": runs[2]["passes"],
        "wall_s_1_worker": round(runs[1]["wall_s"], 2),
        "wall_s_2_workers": round(runs[2]["wall_s"], 2),
        "speedup_wall": round(runs[1]["wall_s"] / runs[2]["wall_s"], 3),
        "map_s_1_worker": runs[1]["map_s"],
        "map_s_2_workers": runs[2]["map_s"],
        "speedup_map": round(runs[1]["map_s"] / runs[2]["map_s"], 3),
        "results_equal": all(ok for ok, _ in checks.values()),
        "max_rel_diff": max(d for _, d in checks.values()),
    }
    targets = {"speedup_wall": ">= 1.7", "speedup_map": ">= 1.7", "results_equal": "True"}
    return {"figures": figures, "targets": targets, "runs": runs,
            "config": {"size": size, "routes": ["L1"], "months": months}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
