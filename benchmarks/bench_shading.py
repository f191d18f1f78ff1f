"""Shading kernel vs bare embreex, and full-physics passes per second on a synthetic city.

Figures (all measured in one run, same process, same rays):
- ``raw_embreex_rays_per_s``: ``EmbreeScene.run(..., query='OCCLUDED')`` on ready float32
  arrays, one thread;
- ``kernel_rays_per_s_1thread``: :meth:`vipvflow.models.shading.Scene.occluded` on float64 world
  coordinates (origin shift, float32 conversion), one thread; ``kernel_vs_raw`` the ratio;
- ``kernel_rays_per_s``: the same with the thread pool (all available cores);
- ``passes_per_s`` / ``passes_per_s_per_core``: :func:`vipvflow.models.irradiance.evaluate_passes`
  (radiation lookup, sun position, direct ray, diffuse, reflected with one ray per sample
  point of every sunlit reflector group, all-sky + clear-sky + unshaded) on a grid city of box
  buildings, default configuration (``reflector_points`` = 4, ``reflector_sampling`` =
  rotate); pass times uniform over June days and nights, ``daylight_share`` of them with any
  light (night passes cost only the check) and ``daylight_passes_per_s_per_core`` counting
  those only;
- ``passes_per_s_{rotate,all}_P{n}``, ``rays_per_pass_..``: the same with 1, 4, 8 sample
  points per reflector group, traced one per pass in turn (rotate) or all every pass (all);
  ``segment_geometry_s_P{n}`` the geometry stage's time, and ``reflected_mean_..`` the mean
  reflected irradiance over the passes (the effect of P and of the sampling on it).
"""
from __future__ import annotations

import time

import numpy as np
import pandas as pd


def grid_city(n_blocks: int, seed: int = 0, x0: float = 77_000.0, y0: float = 75_000.0):
    """Blocks of 2 x 2 box buildings (8-30 m high) between 20 m streets; returns mesh, streets."""
    from vipvflow.models.shading import box_mesh

    rng = np.random.default_rng(seed)
    pitch, block, street = 80.0, 60.0, 20.0
    boxes = []
    for i in range(n_blocks):
        for j in range(n_blocks):
            bx, by = x0 + i * pitch + street / 2, y0 + j * pitch + street / 2
            for a in range(2):
                for b in range(2):
                    w = block / 2
                    boxes.append([bx + a * w + 0.5, by + b * w + 0.5, 0.0, bx + (a + 1) * w - 0.5,
                                  by + (b + 1) * w - 0.5, rng.uniform(8, 30)])
    return box_mesh(np.array(boxes)), (x0, y0, pitch, n_blocks)


def street_segments(streets, n: int, seed: int = 1) -> pd.DataFrame:
    x0, y0, pitch, nb = streets
    rng = np.random.default_rng(seed)
    along = rng.uniform(0, nb * pitch, n)
    line = x0 + pitch * rng.integers(0, nb + 1, n)           # street centre lines
    ns = rng.random(n) < 0.5
    x = np.where(ns, line, x0 + along)
    y = np.where(ns, y0 + along, line - x0 + y0)
    heading = np.where(ns, 0.0, 90.0) + 180.0 * (rng.random(n) < 0.5)
    return pd.DataFrame({"segment_id": np.arange(n), "x": x, "y": y, "z": 3.2,
                         "heading_deg": heading % 360, "gradient": rng.normal(0, 0.02, n)})


def _best(fn, repeat: int) -> float:
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best


def run(tiny: bool = False) -> dict:
    from vipvflow.config import IrradianceCfg
    from vipvflow.inputs.cams import COLUMNS
    from vipvflow.models.irradiance import evaluate_passes
    from vipvflow.models.shading import Scene, available_cores
    from vipvflow.models.sun_sky import RadiationTable
    from vipvflow.models.view_factors import segment_geometry

    n_blocks = 4 if tiny else 28
    n_rays = 20_000 if tiny else 2_000_000
    n_seg = 200 if tiny else 20_000
    n_pass = 20_000 if tiny else 4_000_000
    repeat = 1 if tiny else 3
    mesh, streets = grid_city(n_blocks)
    scene1 = Scene(mesh, n_threads=1)
    scene = Scene(mesh)
    cores = available_cores()

    # --- identical rays: street points towards random suns above 5 deg
    rng = np.random.default_rng(2)
    segs = street_segments(streets, n_rays, seed=3)
    o = segs[["x", "y", "z"]].to_numpy() + [0, 0, 0.05]
    el, az = np.radians(rng.uniform(5, 65, n_rays)), np.radians(rng.uniform(0, 360, n_rays))
    d = np.column_stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])
    o32 = np.ascontiguousarray((o - scene1.origin).astype(np.float32))
    d32 = np.ascontiguousarray(d.astype(np.float32))
    tf = np.full(n_rays, 300.0, np.float32)
    raw = scene1._scene
    t_raw = _best(lambda: raw.run(o32, d32, dists=tf.copy(), query="OCCLUDED"), repeat)
    t_k1 = _best(lambda: scene1.occluded(o, d, 300.0), repeat)
    t_kn = _best(lambda: scene.occluded(o, d, 300.0), repeat)
    same = bool((scene1.occluded(o, d, 300.0) == (raw.run(o32, d32, dists=tf.copy(),
                                                           query="OCCLUDED") != -1)).all())

    # --- full physics on passes
    cfg = IrradianceCfg()
    segs = street_segments(streets, n_seg, seed=4)
    t = time.perf_counter()
    geometry = segment_geometry(scene, segs, cfg)
    t_geom = time.perf_counter() - t
    start = pd.Timestamp("2024-06-01", tz="UTC").timestamp()
    grid = np.arange(start, start + 30 * 86400, 60.0)
    zeros = {c: np.zeros(len(grid)) for c in COLUMNS}
    table = RadiationTable.from_grid(grid, zeros, 49.61, 6.13, 300.0)
    sz = np.clip(table.data["sun_z"], 0, None)
    up = sz > 0
    dni_c = np.where(up, 900 * sz ** 0.3, 0).astype(np.float32)
    dhi_c = np.where(up, 110 * sz ** 0.5, 0).astype(np.float32)
    cloud = (np.random.default_rng(5).random(sz.shape) < 0.35).astype(np.float32)
    table.data.update(dni_clear=dni_c, dhi_clear=dhi_c, ghi_clear=dni_c * sz + dhi_c,
                      dni=dni_c * (1 - cloud), dhi=dhi_c * (1 + 2 * cloud))
    table.data["ghi"] = table.data["dni"] * sz + table.data["dhi"]
    passes = pd.DataFrame({"segment_id": rng.integers(0, n_seg, n_pass),
                           "t_utc": rng.uniform(grid[0], grid[-2], n_pass),
                           "dt_s": np.full(n_pass, 1.5, np.float32)})
    evaluate_passes(passes.iloc[:1000], segs, geometry, table, scene, cfg)
    res = {}
    t_pass = _best(lambda: res.update(r=evaluate_passes(passes, segs, geometry, table, scene, cfg)),
                   1 if tiny else 2)
    r = res["r"]
    # passes with any light (the rest, at night, are skipped by the engine)
    daylight = float(table.has_light(passes["t_utc"].to_numpy() + 0.75).mean())
    # --- the number of sample points per reflector group: cost and effect
    from vipvflow.models.shading import Scene as _Scene

    n_p = n_pass // 4
    per_p = {}
    counted = {"rays": 0}

    class Counting(_Scene):
        def occluded(self, origins, dirs, tfar=np.inf):
            counted["rays"] += len(origins)
            return super().occluded(origins, dirs, tfar)

        def occluded_local(self, origins, dirs, tfar):
            counted["rays"] += len(origins)
            return super().occluded_local(origins, dirs, tfar)

    cscene = Counting(mesh)
    geos = {}
    for sampling, P in (("rotate", 1), ("rotate", 4), ("rotate", 8), ("all", 4), ("all", 8)):
        cfg_p = cfg.model_copy(update={"reflector_points": P, "reflector_sampling": sampling})
        if P not in geos:
            t = time.perf_counter()
            geos[P] = segment_geometry(scene, segs, cfg_p)
            per_p[f"segment_geometry_s_P{P}"] = time.perf_counter() - t
        name = f"{sampling}_P{P}"
        counted["rays"] = 0
        rp = evaluate_passes(passes.iloc[:n_p], segs, geos[P], table, cscene, cfg_p)
        per_p[f"rays_per_pass_{name}"] = counted["rays"] / n_p
        per_p[f"reflected_mean_{name}"] = float(rp["reflected"].mean())
        t_p = _best(lambda: evaluate_passes(passes.iloc[:n_p], segs, geos[P], table, scene, cfg_p),
                    1 if tiny else 2)
        per_p[f"passes_per_s_{name}"] = n_p / t_p
    figures = {
        "raw_embreex_rays_per_s": n_rays / t_raw,
        "kernel_rays_per_s_1thread": n_rays / t_k1,
        "kernel_vs_raw": t_raw / t_k1,
        "kernel_rays_per_s": n_rays / t_kn,
        "kernel_threads": cores,
        "kernel_equals_raw": same,
        "triangles": int(mesh.n_triangles),
        "buildings": int(mesh.n_triangles // 10),
        "segments": n_seg,
        "segment_geometry_s": t_geom,
        "passes": n_pass,
        "passes_per_s": n_pass / t_pass,
        "passes_per_s_per_core": n_pass / t_pass / cores,
        "daylight_share": daylight,
        "daylight_passes_per_s_per_core": daylight * n_pass / t_pass / cores,
        "sun_visible_share": float(r["sun_visible"].mean()),
        "shading_loss_share": float(1 - r["total"].sum() / r["total_unshaded"].sum()),
        "reflector_points": cfg.reflector_points,
        "reflector_sampling": cfg.reflector_sampling,
        **per_p,
    }
    targets = {"kernel_vs_raw": ">= 0.5", "passes_per_s_per_core": ">= 1e6 (full physics)",
               "kernel_equals_raw": "True"}
    return {"figures": figures, "targets": targets}


if __name__ == "__main__":  # pragma: no cover
    import json

    print(json.dumps(run(), indent=2, default=float))
