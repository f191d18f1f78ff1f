"""City ingest speed and memory on a generated city of gabled houses.

Figures: surfaces per second (whole ingest: parse, clean, triangulate, tile, write), the
parse share of the time, peak RSS of an ingest of N and of 2N buildings (each in a fresh
subprocess) and their ratio, which should stay near 1 (streamed, spooled ingest).
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

PROBE = textwrap.dedent("""
    import json, resource, sys, time
    from vipvflow.inputs.city import ingest_city
    from vipvflow.config import CityCfg
    t0 = time.perf_counter()
    r = ingest_city(sys.argv[1], sys.argv[2], CityCfg(tile_size_m=500, buffer_m=300))
    print(json.dumps({"surfaces": r.n_surfaces, "elapsed_s": time.perf_counter() - t0,
                      "tiles": r.tiles, "triangles": r.triangles,
                      "peak_rss_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}))
""")


def _ingest(path: Path, out: Path) -> dict:
    res = subprocess.run([sys.executable, "-c", PROBE, str(path), str(out)],
                         capture_output=True, text=True, check=True)
    return json.loads(res.stdout.strip().splitlines()[-1])


def run(tiny: bool = False) -> dict:
    from vipvflow.inputs.city.citygml import CityGMLReader
    from vipvflow.inputs.city.synthetic import write_synthetic_city

    n = 300 if tiny else 6000
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        write_synthetic_city(tmp / "n.gml", n)
        write_synthetic_city(tmp / "2n.gml", 2 * n)
        t0 = time.perf_counter()
        with open(tmp / "2n.gml", "rb") as fh:
            n_parsed = sum(len(f.surfaces) for f in CityGMLReader(fh, "2n.gml"))
        parse_s = time.perf_counter() - t0
        a = _ingest(tmp / "n.gml", tmp / "a")
        b = _ingest(tmp / "2n.gml", tmp / "b")
        size_mb = (tmp / "2n.gml").stat().st_size / 2**20
    return {
        "figures": {
            "surfaces_per_s": round(b["surfaces"] / b["elapsed_s"], 1),
            "parse_only_surfaces_per_s": round(n_parsed / parse_s, 1),
            "parse_share_of_ingest": round(parse_s / b["elapsed_s"], 3),
            "surfaces_2n": b["surfaces"],
            "file_mb_2n": round(size_mb, 1),
            "peak_rss_mb_n": round(a["peak_rss_mb"], 1),
            "peak_rss_mb_2n": round(b["peak_rss_mb"], 1),
            "peak_rss_ratio_2n_over_n": round(b["peak_rss_mb"] / a["peak_rss_mb"], 3),
        },
        "targets": {
            "surfaces_per_s": "> 5,000 (a 1M-surface national model in minutes)",
            "peak_rss_ratio_2n_over_n": "< 1.3 (memory independent of city size)",
        },
        "buildings": [n, 2 * n],
    }


if __name__ == "__main__":
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2))
