"""``python -m benchmarks [NAME ...] [--tiny]``: run benchmarks, write results/<name>.json, print a table.

Each module ``benchmarks/bench_<name>.py`` defines ``run(tiny=False) -> dict`` returning
``{"figures": {label: value}, "targets": {label: "text"}, ...}``; this harness adds the
machine and the library versions and writes ``benchmarks/results/<name>.json`` atomically.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import sys
import time
from importlib import metadata
from pathlib import Path

HERE = Path(__file__).resolve().parent
PACKAGES = ["vipvflow", "numpy", "pandas", "dask", "distributed", "pyarrow", "embreex",
            "trimesh", "pvlib", "gtfs-kit", "lxml", "psycopg"]


def machine() -> dict:
    import psutil

    return {"python": platform.python_version(), "platform": platform.platform(),
            "cpu_count": os.cpu_count(), "memory_gib": round(psutil.virtual_memory().total / 2**30, 1),
            "processor": platform.processor() or platform.machine()}


def versions() -> dict:
    out = {}
    for name in PACKAGES:
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = None
    return out


def discover() -> list[str]:
    return sorted(p.stem[len("bench_"):] for p in HERE.glob("bench_*.py"))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("names", nargs="*", help=f"benchmarks to run (default all: {', '.join(discover())})")
    ap.add_argument("--tiny", action="store_true", help="tiny inputs (smoke test)")
    ap.add_argument("--results", default=str(HERE / "results"), help="folder for the JSON files")
    args = ap.parse_args(argv)
    names = args.names or discover()
    results = Path(args.results)
    results.mkdir(parents=True, exist_ok=True)
    rows = []
    for name in names:
        module = importlib.import_module(f"benchmarks.bench_{name}")
        t0 = time.perf_counter()
        res = module.run(tiny=args.tiny)
        res.update(name=name, tiny=args.tiny, wall_s=round(time.perf_counter() - t0, 2),
                   machine=machine(), versions=versions(),
                   date=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()))
        path = results / f"{name}{'.tiny' if args.tiny else ''}.json"
        tmp = path.with_suffix(".json.tmp")
        tmp.write_text(json.dumps(res, indent=2, default=str))
        tmp.replace(path)
        for label, value in res.get("figures", {}).items():
            rows.append((name, label, value, res.get("targets", {}).get(label, "")))
    width = max((len(r[1]) for r in rows), default=10)
    print(f"{'benchmark':<16} {'figure':<{width}} {'value':>14}  target")
    for name, label, value, target in rows:
        v = f"{value:,.3g}" if isinstance(value, float) else str(value)
        print(f"{name:<16} {label:<{width}} {v:>14}  {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
