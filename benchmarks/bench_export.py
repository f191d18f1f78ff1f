"""CityGML 3.0 Dynamizer export of the demo run: seconds, peak RSS and size of each file.

Each export runs in a fresh subprocess (peak RSS = that process's high-water mark ``VmHWM``,
imports included; ``import_rss_mb`` is the part the imports alone take).  The run exported is, in
order: ``$VIPVFLOW_BENCH_EXPORT_RUN``; the repository's ``out/demo/2024`` when a demo run is
there (``vipvflow simulate --config conf/demo.yaml --year 2024``); else a fresh run of the full
demo for the year made here (~3 min).  ``--tiny``: the small demo, June.

Before the streamed writer (2026-11-23, demo run, inline): 28 s, 570 MB peak RSS, 94 MB file
written as one line, 34,090 schema errors.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

PROBE = """
import json, sys, time


def hwm_mb():
    # the process's own peak RSS (VmHWM: reset by exec, unlike ru_maxrss, which keeps the
    # parent's high-water mark at the fork)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024


t0 = time.perf_counter()
from vipvflow.outputs import write_dynamizers
import vipvflow.outputs.dynamizer, shapely, pyarrow.parquet, vipvflow.models.shading, vipvflow.models.mesh
import_rss = hwm_mb()
t1 = time.perf_counter()
kw = json.loads(sys.argv[3])
res = write_dynamizers(sys.argv[1], sys.argv[2], **kw)
t2 = time.perf_counter()
print(json.dumps({"seconds": t2 - t1, "import_s": t1 - t0, "import_rss_mb": import_rss,
                  "peak_rss_mb": hwm_mb(),
                  "bytes": sum(f.stat().st_size for f in res["files"]),
                  "segments": res["segments"], "dynamizers": res["dynamizers"], "surfaces": res["surfaces"]}))
"""


def _export(run_dir: Path, out: Path, **kw) -> dict:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    res = subprocess.run([sys.executable, "-c", PROBE, str(run_dir), str(out), json.dumps(kw)],
                         capture_output=True, text=True, check=True, cwd=ROOT, env=env)
    return json.loads(res.stdout.strip().splitlines()[-1])


def run(tiny: bool = False) -> dict:
    from .common import demo_run, remove

    run_dir, source = demo_run(tiny, "VIPVFLOW_BENCH_EXPORT_RUN", "export")
    try:
        return _measure(run_dir, source)
    finally:
        if source.startswith("fresh"):
            remove(run_dir.parents[1])


def _measure(run_dir: Path, source: str) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        inline = _export(run_dir, tmp / "inline.gml", encoding="inline", aggregate="segment")
        tab = _export(run_dir, tmp / "tab.gml", encoding="tabulated", aggregate="segment")
        route = _export(run_dir, tmp / "route.gml", encoding="inline", aggregate="route")
        half = _export(run_dir, tmp / "half.gml", encoding="inline", aggregate="segment", reflectors=False,
                       max_segments=max(inline["segments"] // 2, 1))
        whole = _export(run_dir, tmp / "whole.gml", encoding="inline", aggregate="segment", reflectors=False)
        with open(tmp / "inline.gml", "rb") as fh:
            lines = sum(1 for _ in fh)
    figures = {
        "inline_s": round(inline["seconds"], 2),
        "inline_peak_rss_mb": round(inline["peak_rss_mb"], 1),
        "inline_mb": round(inline["bytes"] / 1e6, 1),
        "inline_lines": lines,
        "import_rss_mb": round(inline["import_rss_mb"], 1),
        "segments": inline["segments"],
        "dynamizers": inline["dynamizers"],
        "reflecting_surfaces": inline["surfaces"],
        "tabulated_s": round(tab["seconds"], 2),
        "tabulated_peak_rss_mb": round(tab["peak_rss_mb"], 1),
        "tabulated_mb": round(tab["bytes"] / 1e6, 1),
        "route_s": round(route["seconds"], 2),
        "route_peak_rss_mb": round(route["peak_rss_mb"], 1),
        "route_mb": round(route["bytes"] / 1e6, 2),
        "no_reflectors_half_peak_rss_mb": round(half["peak_rss_mb"], 1),
        "no_reflectors_all_peak_rss_mb": round(whole["peak_rss_mb"], 1),
        "peak_rss_ratio_all_over_half_segments": round(whole["peak_rss_mb"] / half["peak_rss_mb"], 3),
    }
    return {
        "figures": figures,
        "targets": {
            "inline_s": "< 28 s (before the streamed writer, demo run)",
            "inline_peak_rss_mb": "< 570 MB (before)",
            "peak_rss_ratio_all_over_half_segments": "about 1 (memory independent of the segments)",
        },
        "run": str(run_dir), "run_source": source,
        "before": {"inline_s": 28, "inline_peak_rss_mb": 570, "inline_mb": 94, "inline_lines": 2,
                   "schema_errors": 34090},
    }


if __name__ == "__main__":
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2))
