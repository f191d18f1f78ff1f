"""The cost of the anisotropic sky (issue 36): the line-year (``line_year``) with the
Perez sky (``irradiance.diffuse_model: perez_svf``) against the same run with the uniform
sky view (``sky_view_factor``), in alternated pairs measured in one invocation.

What the Perez sky adds to a run: the F1/F2 coefficients of every minute of the radiation
table (when it is loaded), the horizon-band rays of the tilted roofs and of the reflectors'
sample points in the per-tile geometry, four more values looked up per pass and a few
multiplications, and sun rays for passes whose DNI is 0 but whose circumsolar sky is not.
``perez_ratio`` is the fastest Perez run over the fastest uniform run; the pairs' own
ratios beside it.  The street where the city model has none (``virtual_street``) is on in
both (the demo has terrain, so it costs no ray there).

``tiny``: the small demo, one month, one pair.
"""
from __future__ import annotations

import json
import sys

from benchmarks.common import YEAR, demo_config, fresh_dir, prepare_demo, remove, run_pipeline


def _line_year(size: str, months: list[int], diffuse_model: str) -> dict:
    out = fresh_dir(f"sky_{diffuse_model}")
    try:
        cfg = demo_config(size, out_dir=out, routes=["L1"], months=months, n_workers=2)
        cfg.irradiance.diffuse_model = diffuse_model
        return run_pipeline(cfg, YEAR, n_workers=2)
    finally:
        remove(out)


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    months = [6] if tiny else list(range(1, 13))
    prepare_demo(size)
    pairs = [(_line_year(size, months, "sky_view_factor"), _line_year(size, months, "perez_svf"))
             for _ in range(1 if tiny else 3)]
    uniform = min(u["wall_s"] for u, _ in pairs)
    perez = min(p["wall_s"] for _, p in pairs)
    figures = {
        "uniform_wall_s": round(uniform, 2),
        "perez_wall_s": round(perez, 2),
        "perez_ratio": round(perez / uniform, 3),
        "perez_ratio_pairs": [round(p["wall_s"] / u["wall_s"], 3) for u, p in pairs],
        "uniform_wall_s_runs": [round(u["wall_s"], 2) for u, _ in pairs],
        "perez_wall_s_runs": [round(p["wall_s"], 2) for _, p in pairs],
    }
    return {"figures": figures, "targets": {"perez_ratio": "<= 1.3 (issue 36, with trees)"},
            "config": {"size": size, "routes": ["L1"], "months": months, "workers": 2}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
