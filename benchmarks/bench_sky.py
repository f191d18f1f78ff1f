"""The cost of the anisotropic sky and of the trees (issue 36): the line-year
(``line_year``) three ways, in alternated rounds measured in one invocation: the uniform sky
view without trees (``irradiance.diffuse_model: sky_view_factor``, ``irradiance.trees.enabled:
false``: the run before issue 36), the Perez sky without trees (``perez_svf``), and the Perez
sky with the city's trees (the default).

What the Perez sky adds to a run: the F1/F2 coefficients of every minute of the radiation
table (when it is loaded), the horizon-band rays of the tilted roofs and of the reflectors'
sample points in the per-tile geometry, four more values looked up per pass and a few
multiplications, and sun rays for passes whose DNI is 0 but whose circumsolar sky is not.
What the trees add: the tile's crowns loaded and gridded, the geometry's sky view, sky cells
and reflector points per class of months (leaf-on / leaf-off) through the crowns, and per pass
the sun ray's walk through the crown grid.

``perez_ratio`` is the fastest Perez run without trees over the fastest uniform run;
``trees_ratio`` the fastest Perez run with trees over the fastest without; ``both_ratio`` the
fastest Perez run with trees over the fastest uniform run without (the issue's target); each
round's own ratios beside them.  The street where the city model has none
(``virtual_street``) is on in all (the demo has terrain, so it costs no ray there).

``tiny``: the small demo, one month, one round.
"""
from __future__ import annotations

import json
import sys

from benchmarks.common import YEAR, demo_config, fresh_dir, prepare_demo, remove, run_pipeline

#: the legs of a round: (label, diffuse model, trees)
LEGS = (("uniform", "sky_view_factor", False), ("perez", "perez_svf", False),
        ("perez_trees", "perez_svf", True))


def _line_year(size: str, months: list[int], diffuse_model: str, trees: bool) -> dict:
    out = fresh_dir(f"sky_{diffuse_model}_{'trees' if trees else 'no_trees'}")
    try:
        cfg = demo_config(size, out_dir=out, routes=["L1"], months=months, n_workers=2)
        cfg.irradiance.diffuse_model = diffuse_model
        cfg.irradiance.trees.enabled = trees
        return run_pipeline(cfg, YEAR, n_workers=2)
    finally:
        remove(out)


def _trees_in_city(size: str) -> int:
    from benchmarks.common import demo_paths
    from vipvflow.store import DataDir

    report = DataDir(demo_paths(size)["data"]).city.report
    return int(json.loads(report.read_text())["trees"]["kept"])


def run(tiny: bool = False) -> dict:
    size = "small" if tiny else "full"
    months = [6] if tiny else list(range(1, 13))
    prepare_demo(size)
    rounds = [{label: _line_year(size, months, model, trees) for label, model, trees in LEGS}
              for _ in range(1 if tiny else 3)]
    fastest = {label: min(r[label]["wall_s"] for r in rounds) for label, _, _ in LEGS}

    def ratio(a, b):
        return round(fastest[a] / fastest[b], 3), [round(r[a]["wall_s"] / r[b]["wall_s"], 3) for r in rounds]

    figures = {"trees_in_city_model": _trees_in_city(size)}
    for label, _, _ in LEGS:
        figures[f"{label}_wall_s"] = round(fastest[label], 2)
    for name, (a, b) in {"perez_ratio": ("perez", "uniform"), "trees_ratio": ("perez_trees", "perez"),
                         "both_ratio": ("perez_trees", "uniform")}.items():
        figures[name], figures[f"{name}_rounds"] = ratio(a, b)
    for label, _, _ in LEGS:
        figures[f"{label}_wall_s_runs"] = [round(r[label]["wall_s"], 2) for r in rounds]
    return {"figures": figures,
            "targets": {"both_ratio": "<= 1.3 (issue 36: the Perez sky and the trees together)"},
            "config": {"size": size, "routes": ["L1"], "months": months, "workers": 2,
                       "legs": [dict(zip(("label", "diffuse_model", "trees"), leg)) for leg in LEGS]}}


if __name__ == "__main__":  # pragma: no cover
    print(json.dumps(run(tiny="--tiny" in sys.argv), indent=2, default=str))
