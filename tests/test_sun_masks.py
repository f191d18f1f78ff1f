"""Sun masks among the buildings (issue 41): a sun ray above a roof point's mask is clear
without Embree, and only such rays are spared (the answer is the all-rays answer)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from vipvflow.config import IrradianceCfg
from vipvflow.models import passkernel
from vipvflow.models.horizon import BUILDING_SECTORS, MASK_FLOOR, building_sector, pseudo_azimuth
from vipvflow.models.irradiance import evaluate_passes
from vipvflow.models.mesh import TileMesh
from vipvflow.models.shading import Scene, box_mesh, occluded_reference
from vipvflow.models.view_factors import pack_geometry, segment_geometry

from test_passkernel import _canyon_scene, _clear_day_table


def _city(rng) -> TileMesh:
    """Random blocks, gabled roofs, a bridge deck over the street at 6-7 m and a tower."""
    boxes = []
    for _ in range(40):
        x, y = rng.uniform(-150, 150, 2)
        w, d = rng.uniform(8, 40, 2)
        if abs(x) < 12 + w / 2:            # keep a street along y free
            x += np.sign(x or 1) * (12 + w / 2)
        boxes.append([x - w / 2, y - d / 2, 0, x + w / 2, y + d / 2, rng.uniform(5, 35)])
    boxes.append([-12, 20, 6, 12, 28, 7])          # the bridge: sky below it, sky above
    boxes.append([20, -80, 0, 40, -60, 90])        # a tower beside the street
    mesh = box_mesh(boxes)
    tris = [mesh.vertices[mesh.triangles]]
    for x0, y0, h in rng.uniform([-150, -150, 6], [150, 150, 25], (12, 3)):
        # a gable: two sloped triangles pairs from eaves at h to a ridge 4 m higher
        a, b, r = [x0, y0, h], [x0 + 10, y0, h], [x0 + 5, y0, h + 4]
        c, d, s = [x0, y0 + 12, h], [x0 + 10, y0 + 12, h], [x0 + 5, y0 + 12, h + 4]
        tris.append(np.array([[a, b, s], [a, s, r], [b, d, s], [a, r, c], [r, s, c], [s, d, c]],
                             np.float64))
    return TileMesh.from_triangles(np.concatenate(tris))


def test_pseudo_azimuth_rises_with_the_azimuth_and_is_opposite_two_further_on():
    az = np.radians(np.linspace(0.0, 359.9, 3600))
    p = np.array([pseudo_azimuth(np.sin(a), np.cos(a)) for a in az])
    assert (np.diff(p) > 0).all() and p[0] == 0.0 and p[-1] < 4.0
    opposite = np.array([pseudo_azimuth(-np.sin(a), -np.cos(a)) for a in az])
    np.testing.assert_allclose(opposite, (p + 2.0) % 4.0, atol=1e-12)
    k = np.array([building_sector(np.sin(a), np.cos(a), BUILDING_SECTORS) for a in az])
    assert k.min() == 0 and k.max() == BUILDING_SECTORS - 1 and (np.diff(k) >= 0).all()


def test_sun_masks_tell_clear_only_rays_that_miss_every_triangle():
    """Roof points along a street with a bridge over it, among random blocks, gables and a
    tower; 60,000 rising rays in every direction: no ray above its point's mask meets a
    triangle (the exact float64 test and Embree agree), the points under the bridge have
    no mask, and the masks do spare most of the rays that are clear."""
    rng = np.random.default_rng(41)
    mesh = _city(rng)
    scene = Scene(mesh, n_threads=1)
    n = 60
    pts = np.column_stack([rng.uniform(-8, 8, n), np.linspace(-140, 140, n), np.full(n, 3.2)])
    under = (pts[:, 1] > 20) & (pts[:, 1] < 28)
    pts[0] = [0.0, 24.0, 3.2]                      # one certainly under the deck
    under[0] = True
    local = scene.to_local(pts)
    masks = scene.sun_masks(local, 300.0)
    assert masks.shape == (n, BUILDING_SECTORS) and (masks >= MASK_FLOOR).all()
    assert np.isinf(masks[under]).all() and np.isfinite(masks[~under]).any()

    m = 1000
    el = np.arcsin(rng.uniform(0.0, 1.0, (n, m)))
    az = rng.uniform(0, 2 * np.pi, (n, m))
    d = np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], -1)
    d = d.reshape(-1, 3).astype(np.float32)
    row = np.repeat(np.arange(n), m)
    o = local[row]
    sector = np.array([building_sector(float(a), float(b), BUILDING_SECTORS) for a, b in d[:, :2]])
    h = np.hypot(d[:, 0].astype(np.float64), d[:, 1])
    told_clear = d[:, 2] / np.maximum(h, 1e-300) > masks[row, sector]
    exact = occluded_reference(mesh, o.astype(np.float64) + scene.origin, d, 300.0)
    embree = scene.occluded_local(o, d, 300.0)
    assert not (told_clear & exact).any()
    assert not (told_clear & embree).any()
    clear = ~embree
    assert clear.mean() > 0.3 and (told_clear.sum() / clear.sum()) > 0.5


def test_the_kernel_with_sun_masks_equals_the_kernel_casting_every_ray():
    """A June day in the canyon: with the masks (the default) every component of every pass
    equals, bit for bit, the one with every sun ray cast (``sun_masks: false``); the masks
    spare most sun rays, and the kernel counts the rays it cast and spared."""
    table = _clear_day_table("2024-06-10")
    scene = _canyon_scene()
    n_seg = 12
    segs = pd.DataFrame({"segment_id": np.arange(n_seg, dtype=np.int64) + 100,
                         "x": np.linspace(-6.0, 6.0, n_seg), "y": np.linspace(-300.0, 300.0, n_seg),
                         "z": np.full(n_seg, 3.2), "heading_deg": np.zeros(n_seg),
                         "gradient": np.zeros(n_seg)})
    rng = np.random.default_rng(9)
    day0 = pd.Timestamp("2024-06-10", tz="UTC").timestamp()
    passes = pd.DataFrame({"segment_id": rng.choice(segs["segment_id"].to_numpy(), 20_000),
                           "t_utc": day0 + rng.uniform(0, 86400, 20_000),
                           "dt_s": rng.uniform(1, 8, 20_000).astype(np.float32)})
    out, counts = {}, {}
    for masks in (True, False):
        cfg = IrradianceCfg(sun_masks=masks, reflector_points=4, reflection_rays=128, svf_rays=128)
        geometry = segment_geometry(scene, segs, cfg)
        geo = pack_geometry(geometry, cfg, 0.2, scene)
        assert passkernel.usable(geo, scene)
        clock: dict = {}
        out[masks] = evaluate_passes(passes, None, geometry, table, scene, cfg, packed=geo,
                                     timings=clock)
        counts[masks] = (clock["sun_rays_cast_n"], clock["sun_rays_masked_n"])
    pd.testing.assert_frame_equal(out[True], out[False], check_exact=True)
    cast, masked = counts[True]
    assert counts[False] == (cast + masked, 0)
    assert out[True]["sun_visible"].any() and (~out[True]["sun_visible"] & (out[True]["ghi"] > 0)).any()
    assert masked > 0.5 * out[True]["sun_visible"].sum()
