"""Tree crowns: the ray walk against the plain-numpy reference and analytic cases, the classes
of months, the geometry and passes through crowns, the fused kernel against the numpy
reference with crowns, and the ingest of CityGML vegetation and tree tables."""
from __future__ import annotations

import json

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest

from vipvflow.config import CityCfg, IrradianceCfg, load_config
from vipvflow.errors import ConfigError, InputError
from vipvflow.models.params import TreeCfg
from vipvflow.models.trees import (Crowns, TreeTable, month_classes, month_mask, month_of,
                                   transmittance_reference)


def table(x, y, z=0.0, height=12.0, crown=7.0, base=4.5, leaf=0, leaf_off=-1, lat=49.6):
    x = np.atleast_1d(np.asarray(x, float))
    n = len(x)
    full = lambda v: np.broadcast_to(np.asarray(v), (n,)).copy()       # noqa: E731
    return TreeTable(x=x, y=full(y), z=full(z), height=full(height), crown_diameter=full(crown),
                     crown_base=full(base), leaf_type=full(leaf), leaf_off=full(leaf_off),
                     source=np.full(n, 2), tree_id=[f"t{i}" for i in range(n)], latitude=lat)


# ---------------------------------------------------------------------------- the ray walk
def test_walk_equals_the_numpy_reference_on_random_rays():
    """Crowns of every size and shape scattered over 500 m, rays from anywhere in any
    direction and of any length: the grid walk finds exactly the crowns every ray-every crown
    test finds (the product, in crown order, equal to the last bit), for every class."""
    rng = np.random.default_rng(3)
    n = 400
    t = TreeTable(x=rng.uniform(-250, 250, n), y=rng.uniform(-250, 250, n), z=rng.uniform(0, 3, n),
                  height=rng.uniform(5, 25, n), crown_diameter=rng.uniform(2, 14, n),
                  crown_base=rng.uniform(1, 4, n), leaf_type=rng.integers(-1, 2, n),
                  leaf_off=np.where(rng.random(n) < 0.3, month_mask([12, 1, 2]), -1),
                  source=np.zeros(n), tree_id=[str(i) for i in range(n)], latitude=50.0)
    crowns = Crowns(t, TreeCfg(), origin=(10.0, -5.0, 1.0))
    m = 30_000
    o = np.column_stack([rng.uniform(-300, 300, m), rng.uniform(-300, 300, m), rng.uniform(-2, 30, m)])
    d = rng.normal(size=(m, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    d[:500, 2] = 0.0                                   # level rays
    d[500:1000] = [0.0, 0.0, 1.0]                      # straight up
    tmax = rng.uniform(1, 400, m)
    got, want = crowns.transmittance(o, d, tmax), transmittance_reference(crowns, o, d, tmax)
    assert crowns.n_classes == 3 and (got == want).all()
    assert 0.05 < (got < 1).mean() < 0.9 and (got[:, 0] < 0.2 * 0.2 + 1e-7).any()   # two crowns
    cls = rng.integers(0, crowns.n_classes, m)
    assert (crowns.transmittance(o, d, tmax, cls) == transmittance_reference(crowns, o, d, tmax, cls)).all()


def test_a_ray_through_a_crown_analytic():
    """A lone spheroid crown: a ray through it (from below, along the axis; sideways through
    its middle; grazing inside its edge) keeps tau, one that passes 1 cm outside it or ends
    1 cm before it keeps everything; from inside the crown tau too."""
    crowns = Crowns(table(0.0, 0.0, height=12.0, crown=8.0, base=4.0), TreeCfg(transmittance_leaf_on=0.3))
    a, c, zc = 4.0, 4.0, 8.0
    o = np.array([[0, 0, 1.0], [-20, 0, zc], [-20, a - 0.01, zc], [-20, a + 0.01, zc], [0, 0, 1.0],
                  [0, 0, 8.0]])
    d = np.array([[0, 0, 1.0], [1, 0, 0], [1, 0, 0], [1, 0, 0], [0, 0, 1.0], [1, 0, 0]])
    tmax = np.array([100, 100, 100, 100, zc - c - 1.0 - 0.01, 100])
    got = crowns.transmittance(o, d, tmax, np.zeros(len(o), np.int64))
    np.testing.assert_allclose(got, [0.3, 0.3, 0.3, 1.0, 1.0, 0.3], rtol=1e-6)


def test_classes_of_months_follow_leaf_type_and_hemisphere():
    """Deciduous trees shed their leaves in the default months of their hemisphere (Nov-Apr
    north, May-Oct south) or their own; evergreen ones keep tau leaf-on all year; an unknown
    leaf type follows ``unknown_leaf_type``."""
    cfg = TreeCfg(transmittance_leaf_on=0.2, transmittance_leaf_off=0.6)
    north = table([0, 10, 20], 0, leaf=[0, 1, -1])
    cls, tau = month_classes(north, cfg)
    leafless = tau[:, cls]                                           # (trees, months)
    np.testing.assert_allclose(leafless[0], [0.6] * 4 + [0.2] * 6 + [0.6] * 2)
    np.testing.assert_allclose(leafless[1], [0.2] * 12)
    np.testing.assert_allclose(leafless[2], leafless[0])
    _, tau_ev = month_classes(north, cfg.model_copy(update={"unknown_leaf_type": "evergreen"}))
    assert tau_ev.shape[1] == 2 and np.allclose(tau_ev[2], 0.2)
    cls, tau = month_classes(table([0], 0, lat=-33.9), cfg)
    np.testing.assert_allclose(tau[0, cls], [0.2] * 4 + [0.6] * 6 + [0.2] * 2)
    own = table([0, 1], 0, leaf_off=[month_mask([1, 2]), -1])
    cls, tau = month_classes(own, cfg.model_copy(update={"leaf_off_months": [12, 1]}))
    assert tau.shape[1] == 4                          # Jan (both off), Feb, Dec, Mar-Nov (none)
    np.testing.assert_allclose(tau[0, cls], [0.6, 0.6] + [0.2] * 10)
    np.testing.assert_allclose(tau[1, cls], [0.6] + [0.2] * 10 + [0.6])


def test_month_of_a_time_in_the_compiled_kernel():
    from numba import njit

    from vipvflow.models.trees import month0

    @njit
    def months(t, out):
        for i in range(len(t)):
            out[i] = month0(t[i])

    t = np.random.default_rng(1).uniform(-2e9, 5e9, 200_000)
    out = np.empty(len(t), np.int64)
    months(t, out)
    assert (out + 1 == month_of(t)).all()


# ---------------------------------------------------------------------------- the geometry
def _open_scene(trees=None):
    from vipvflow.models.mesh import SURFACE_CODE, TileMesh
    from vipvflow.models.shading import Scene

    g = 500.0
    road = np.array([[[-g, -g, 0], [g, -g, 0], [g, g, 0]], [[-g, -g, 0], [g, g, 0], [-g, g, 0]]])
    mesh = TileMesh.from_triangles(road, albedo=0.15)
    mesh.surface_type[:] = SURFACE_CODE["ground"]
    return Scene(mesh, trees=trees)


def test_sky_view_under_a_crown_is_its_solid_angle_darkened():
    """A roof point on open ground under a lone sphere crown: the sky view factor without the
    crown is 1, with it 1 - (1 - tau) sin^2(half angle) (the sphere's cosine-weighted view
    from a point on its axis), leaf-on and leaf-off by month; the Perez sky's cells lose the
    same share of a uniform sky; direct light under it is tau x the beam."""
    from vipvflow.models.view_factors import segment_geometry

    r, zc, zp = 4.0, 9.0, 3.25
    trees = table(0.0, 0.0, height=zc + r, crown=2 * r, base=zc - r)
    scene = _open_scene(trees)
    cfg = IrradianceCfg(svf_rays=8192, reflection=False, trees=TreeCfg(transmittance_leaf_on=0.2,
                                                                          transmittance_leaf_off=0.6))
    segs = pd.DataFrame({"segment_id": [0], "x": [0.0], "y": [0.0], "z": [zp - 0.05],
                         "heading_deg": [0.0], "gradient": [0.0]})
    geo = segment_geometry(scene, segs, cfg)
    sin2 = (r / (zc - zp)) ** 2
    months = geo[[f"tree_month_{m:02d}" for m in range(1, 13)]].to_numpy()[0]
    assert geo["svf"].iloc[0] == pytest.approx(1.0)
    for month, tau in ((7, 0.2), (1, 0.6)):
        svf = geo[f"svf_t{months[month - 1]}"].iloc[0]
        assert svf == pytest.approx(1 - (1 - tau) * sin2, abs=0.01), (month, svf)
    # the crown's share of a uniform sky from the sky cells (the loss x the cells' sin cos weight)
    from vipvflow.models.trees import sky_cells

    el = np.radians((np.arange(9) + 0.5) * 10.0)
    w = np.tile(np.sin(el) * np.cos(el) * np.radians(10.0) ** 2, 36)
    w /= w.sum()
    loss = geo[[f"tsky_t{months[6]}_{j:03d}" for j in range(len(sky_cells()))]].to_numpy()[0]
    assert (loss * w).sum() == pytest.approx((1 - 0.2) * sin2, rel=0.08)


def test_sun_masks_rule_out_only_rays_that_miss_every_crown(monkeypatch):
    """Crowns of every size scattered around roof points above, among and below them, sun
    rays in every direction: where the compiled kernel skips the grid walk (the ray rises
    above its origin's mask in its azimuth sector) the walk finds no crown, and the masks
    rule out most rays."""
    from vipvflow.models.passkernel import _may_cross
    from vipvflow.models.trees import _MAX_HITS, MASK_SECTORS, transmit_one

    rng = np.random.default_rng(11)
    n = 300
    t = TreeTable(x=rng.uniform(-150, 150, n), y=rng.uniform(-150, 150, n), z=rng.uniform(0, 3, n),
                  height=rng.uniform(5, 25, n), crown_diameter=rng.uniform(2, 14, n),
                  crown_base=rng.uniform(1, 4, n), leaf_type=rng.integers(-1, 2, n),
                  leaf_off=np.full(n, -1), source=np.zeros(n), tree_id=[str(i) for i in range(n)],
                  latitude=50.0)
    crowns = Crowns(t, TreeCfg(), origin=(3.0, -2.0, 0.5))
    k, m = 300, 100
    origins = np.column_stack([rng.uniform(-160, 160, k), rng.uniform(-160, 160, k),
                               rng.uniform(0, 30, k)]).astype(np.float32)
    masks = crowns.sun_masks(origins)
    assert masks.shape == (k, MASK_SECTORS) and np.isinf(masks).any()
    d = rng.normal(size=(k * m, 3)).astype(np.float32)
    d[:, 2] = np.abs(d[:, 2]) + np.float32(1e-3)                  # towards the sky
    d[:50] = [0.0, 0.0, 1.0]                                      # straight up
    row = np.repeat(np.arange(k), m)
    o = origins[row]
    hits = np.empty(_MAX_HITS, np.int64)
    tr = crowns.arrays()
    walk = np.array([transmit_one(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], 400.0, 0,
                                  *tr, hits) for i in range(len(o))], np.float32)
    may = np.array([_may_cross(masks, row[i], d[i, 0], d[i, 1], d[i, 2]) for i in range(len(o))])
    assert (walk[~may] == 1.0).all()
    assert (~may).mean() > 0.5 and (walk[may] < 1).any()
    # the crowns' share of each sky cell skips the rays of its cells the same way
    from vipvflow.models.sky import SKY_AZIMUTH_BINS
    from vipvflow.models.trees import sky_cell_loss

    pts, levels = origins[:40].astype(np.float64), np.zeros((40, SKY_AZIMUTH_BINS))
    got = sky_cell_loss(crowns, pts, levels, 400.0)
    monkeypatch.setattr(Crowns, "sun_masks", lambda self, o: np.full((len(o), MASK_SECTORS), np.inf))
    want = sky_cell_loss(crowns, pts, levels, 400.0)             # every ray walked
    assert (got == want).all() and (want > 0).any()


@pytest.mark.parametrize("leaf_type", [1, 0], ids=["evergreen_one_class", "deciduous_two_classes"])
def test_sky_cell_loss_is_the_weighted_loss_of_each_cells_own_directions(monkeypatch, leaf_type):
    """The crowns' share of each sky cell, points taken in blocks and only the cells the
    crowns could take from: for every point, class and cell, the ``sin cos``-weighted mean
    over the cell's 16 directions above the point's horizon of ``1 - T`` with ``T`` from
    the plain-numpy every-ray-every-crown reference (float32 rounding); the result does not
    depend on the block size (bit for bit)."""
    from vipvflow.models import trees
    from vipvflow.models.sky import SKY_AZIMUTH_BINS, SKY_LEVEL_DEG, SKY_LEVELS

    rng = np.random.default_rng(5)
    n = 60
    t = TreeTable(x=rng.uniform(-60, 60, n), y=rng.uniform(-60, 60, n), z=np.zeros(n),
                  height=rng.uniform(6, 20, n), crown_diameter=rng.uniform(3, 12, n),
                  crown_base=rng.uniform(2, 4, n), leaf_type=np.full(n, leaf_type),
                  leaf_off=np.full(n, -1), source=np.zeros(n), tree_id=[str(i) for i in range(n)],
                  latitude=50.0)
    crowns = Crowns(t, TreeCfg(), origin=(0.0, 0.0, 0.0))
    assert crowns.n_classes == (1 if leaf_type == 1 else 2)
    k = 25
    pts = np.column_stack([rng.uniform(-50, 50, k), rng.uniform(-50, 50, k), rng.uniform(2, 6, k)])
    levels = rng.integers(0, 4, (k, SKY_AZIMUTH_BINS)).astype(np.float32)     # horizons 0-30 deg
    got = trees.sky_cell_loss(crowns, pts, levels, 200.0)
    monkeypatch.setattr(trees, "SKY_LOSS_BLOCK", 3 * SKY_AZIMUTH_BINS * SKY_LEVELS * 16)
    assert np.array_equal(trees.sky_cell_loss(crowns, pts, levels, 200.0), got)   # 3 points a block
    # the reference, direction by direction
    S = trees.SKY_CELL_SAMPLES
    sub = (np.arange(S) + 0.5) / S
    for i in rng.choice(k, 6, replace=False):
        for cell in range(SKY_AZIMUTH_BINS * SKY_LEVELS):
            sector, band = divmod(cell, SKY_LEVELS)
            az = np.radians((sector + sub) * 360.0 / SKY_AZIMUTH_BINS)[:, None]
            el = np.radians((band + sub) * SKY_LEVEL_DEG)[None, :]
            d = np.stack(np.broadcast_arrays(np.cos(el) * np.sin(az), np.cos(el) * np.cos(az),
                                             np.sin(el)), -1).reshape(-1, 3)
            wt = np.broadcast_to(np.sin(el) * np.cos(el), (S, S)).reshape(-1)
            seen = np.degrees(np.broadcast_to(el, (S, S)).reshape(-1)) > levels[i, sector] * SKY_LEVEL_DEG
            T = transmittance_reference(crowns, np.broadcast_to(pts[i], (len(d), 3)), d, 200.0)
            want = ((1.0 - T.astype(np.float64)) * (wt * seen)[:, None]).sum(0) / wt.sum()
            np.testing.assert_allclose(got[i, :, cell], want, rtol=1e-5, atol=1e-7)
    assert (got > 0).mean() > 0.05 and (got == 0).any()


def test_fused_kernel_equals_the_numpy_reference_with_crowns(monkeypatch):
    """A canyon with rows of crowns (deciduous and evergreen, some with their own leaf-off
    months: three classes of months) over two days, one in leaf and one not: every
    component of the fused kernel equals the numpy reference's, in both reflector samplings
    and both skies (the Perez sky's per-segment sums also in blocks of one segment); the
    crowns darken the direct and diffuse light they shade, and the ``_no_trees``
    components are the buildings' alone."""
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from test_passkernel import _assert_same, _canyon_scene, _clear_day_table

    from vipvflow.models import passkernel
    from vipvflow.models.irradiance import evaluate_passes
    from vipvflow.models.shading import Scene
    from vipvflow.models.view_factors import pack_geometry, segment_geometry

    ys = np.arange(-380, 380, 12.0)
    n = 2 * len(ys)
    trees = table(np.r_[np.full(len(ys), -5.0), np.full(len(ys), 5.0)], np.r_[ys, ys + 6],
                  height=12.0, crown=7.0, base=4.5, leaf=np.where(np.arange(n) % 5 == 0, 1, 0),
                  leaf_off=np.where(np.arange(n) % 7 == 0, month_mask([1, 2, 3, 4]), -1))
    scene = Scene(_canyon_scene().mesh, trees=trees)
    n_seg = 10
    segs = pd.DataFrame({"segment_id": np.arange(n_seg) + 100, "x": np.linspace(-6.0, 6.0, n_seg),
                         "y": np.linspace(-300.0, 300.0, n_seg), "z": np.full(n_seg, 3.2),
                         "heading_deg": np.where(np.arange(n_seg) % 2, 0.0, 180.0),
                         "gradient": np.linspace(-0.06, 0.06, n_seg)})
    rng = np.random.default_rng(5)
    for day in ("2024-06-10", "2024-03-28"):
        table_ = _clear_day_table(day)
        d0 = pd.Timestamp(day, tz="UTC").timestamp()
        passes = pd.DataFrame({"segment_id": rng.choice(segs["segment_id"].to_numpy(), 8000),
                               "t_utc": d0 + rng.uniform(0, 86400, 8000),
                               "dt_s": rng.uniform(1, 8, 8000).astype(np.float32)})
        for sampling, diffuse in (("rotate", "perez_svf"), ("all", "sky_view_factor")):
            cfg = IrradianceCfg(reflector_sampling=sampling, diffuse_model=diffuse,
                                reflector_points=4, reflection_rays=128, svf_rays=256)
            geometry = segment_geometry(scene, segs, cfg)
            geo = pack_geometry(geometry, cfg, 0.2, scene)
            assert geo["svf"].shape[1] == 3
            ref = evaluate_passes(passes, None, geometry, table_, scene, cfg, packed=geo, kernel="numpy")
            _assert_same(ref, evaluate_passes(passes, None, geometry, table_, scene, cfg, packed=geo))
            if diffuse == "perez_svf":
                with monkeypatch.context() as mp:
                    mp.setattr(passkernel, "SKY_GRID_BUDGET", 1)
                    _assert_same(ref, evaluate_passes(passes, None, geometry, table_, scene, cfg, packed=geo))
            assert (ref["direct"] <= ref["direct_no_trees"] + 1e-4).all()
            assert (ref["direct"] < 0.9 * ref["direct_no_trees"]).any()
            assert (ref["diffuse"] < 0.9 * ref["diffuse_no_trees"]).any()


def test_geometry_of_other_trees_is_refused():
    """A tile's geometry computed with crowns other than the scene's now (another leaf-off
    calendar: other classes of months) is refused, not read wrongly."""
    from vipvflow.models.view_factors import pack_geometry, segment_geometry

    cfg = IrradianceCfg(reflection=False, svf_rays=64)
    scene = _open_scene(table([0.0, 5.0], 0.0, leaf_off=[month_mask([1]), -1]))
    segs = pd.DataFrame({"segment_id": [0], "x": [0.0], "y": [0.0], "z": [3.2],
                         "heading_deg": [0.0], "gradient": [0.0]})
    geometry = segment_geometry(scene, segs, cfg)
    other = cfg.model_copy(update={"trees": TreeCfg(leaf_off_months=[6])})
    with pytest.raises(InputError, match="other trees"):
        pack_geometry(geometry, other, 0.2, scene)
    pack_geometry(geometry, cfg, 0.2, scene)


def test_geometry_file_round_trip_with_crowns(tmp_path):
    """The geometry table with crowns (per-class columns, the sky cells' losses, the points'
    factors) is written with its list columns and read back as it was."""
    import pyarrow.parquet as pq

    from vipvflow.models.view_factors import geometry_table, read_geometry, segment_geometry

    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).parent))
    from test_passkernel import _canyon_scene
    from vipvflow.models.shading import Scene

    scene = Scene(_canyon_scene().mesh, trees=table([5.0, -5.0], [0.0, 12.0]))
    cfg = IrradianceCfg(reflector_points=4, reflection_rays=64, svf_rays=64)
    segs = pd.DataFrame({"segment_id": [1, 2], "x": [0.0, 4.0], "y": [0.0, 10.0], "z": [3.2, 3.2],
                         "heading_deg": [0.0, 90.0], "gradient": [0.0, 0.02]})
    geo = segment_geometry(scene, segs, cfg)
    assert {"tsky_t0_000", "r0_q0_t1", "st_q3_t0", "svf_t1", "tree_month_01"} <= set(geo.columns)
    path = tmp_path / "g.parquet"
    pq.write_table(geometry_table(geo), path)
    names = pq.read_schema(path).names
    assert "tsky_t0" in names and "r0_q_t1" in names and "r0_q0_t1" not in names
    back = read_geometry(path)
    assert list(back.columns) == list(geo.columns)
    for c in geo.columns:
        np.testing.assert_array_equal(back[c].to_numpy(), geo[c].to_numpy(), err_msg=c)


# ---------------------------------------------------------------------------- the ingest
NS = ('xmlns="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" '
      'xmlns:veg="http://www.opengis.net/citygml/vegetation/2.0" xmlns:gml="http://www.opengis.net/gml" '
      'xmlns:gen="http://www.opengis.net/citygml/generics/2.0" xmlns:xlink="http://www.w3.org/1999/xlink"')
X0, Y0 = 77200.0, 75200.0


def _gml(members: list[str]) -> str:
    return (f'<?xml version="1.0" encoding="UTF-8"?>\n<CityModel {NS}><gml:boundedBy><gml:Envelope '
            'srsName="EPSG:2169" srsDimension="3"><gml:lowerCorner>0 0 0</gml:lowerCorner>'
            '<gml:upperCorner>1 1 1</gml:upperCorner></gml:Envelope></gml:boundedBy>'
            + "".join(f"<cityObjectMember>{m}</cityObjectMember>" for m in members) + "</CityModel>")


def _poly(ring) -> str:
    ring = np.vstack([ring, ring[:1]])
    return ("<gml:Polygon><gml:exterior><gml:LinearRing><gml:posList>"
            + " ".join(f"{v:.4f}" for v in np.asarray(ring).ravel())
            + "</gml:posList></gml:LinearRing></gml:exterior></gml:Polygon>")


def _building(x, y, h=10.0, ground=False) -> str:
    walls = []
    c = [(x, y), (x + 10, y), (x + 10, y + 10), (x, y + 10)]
    for i in range(4):
        (ax, ay), (bx, by) = c[i], c[(i + 1) % 4]
        walls.append(_poly(np.array([[ax, ay, 300], [bx, by, 300], [bx, by, 300 + h], [ax, ay, 300 + h]])))
    roof = _poly(np.array([[px, py, 300 + h] for px, py in c]))
    surf = "".join(f"<bldg:boundedBy><bldg:WallSurface><bldg:lod2MultiSurface><gml:MultiSurface>"
                   f"<gml:surfaceMember>{w}</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface>"
                   f"</bldg:WallSurface></bldg:boundedBy>" for w in walls)
    surf += (f"<bldg:boundedBy><bldg:RoofSurface><bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>"
             f"{roof}</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface></bldg:RoofSurface>"
             f"</bldg:boundedBy>")
    if ground:
        floor = _poly(np.array([[px, py, 300.0] for px, py in c[::-1]]))
        surf += (f"<bldg:boundedBy><bldg:GroundSurface><bldg:lod2MultiSurface><gml:MultiSurface>"
                 f"<gml:surfaceMember>{floor}</gml:surfaceMember></gml:MultiSurface>"
                 f"</bldg:lod2MultiSurface></bldg:GroundSurface></bldg:boundedBy>")
    return f'<bldg:Building gml:id="B">{surf}</bldg:Building>'


def _spheroid_polys(x, y, base, top, d, n=12, z=300.0):
    """A low-poly tree (the demo's unit tree: trunk and crown, rings every 30 deg) standing
    at (x, y, z), as polygons."""
    from vipvflow.demo.city import unit_tree

    out = []
    shape = base / top
    for ring in unit_tree(shape, n):
        v = ring * [d, d, top] + [x, y, z]
        out.append(v)
    return out


def test_citygml_vegetation_in_all_its_forms(tmp_path):
    """Trees with explicit geometry only (their size from it), attributes and an implicit
    geometry defined inline and then referred to by a later feature, a library object (its
    attributes serve), a position in both the matrix and the reference point (placed once),
    a tree without any geometry and one placed but without a height (skipped, counted by
    reason), and a plant cover (filled with crowns): every
    tree a crown, none a surface of the mesh."""
    from vipvflow.inputs.city import ingest_city, load_tile_mesh
    from vipvflow.models.mesh import SURFACE_CODE

    explicit = "".join(f"<gml:surfaceMember>{_poly(p)}</gml:surfaceMember>"
                       for p in _spheroid_polys(X0 + 40, Y0 + 5, 4.0, 12.0, 8.0))
    members = [_building(X0, Y0),
               f'<veg:SolitaryVegetationObject gml:id="T1"><veg:species>Tilia cordata</veg:species>'
               f'<veg:lod2Geometry><gml:MultiSurface>{explicit}</gml:MultiSurface></veg:lod2Geometry>'
               f'</veg:SolitaryVegetationObject>']
    unit = "".join(f"<gml:surfaceMember>{_poly(p)}</gml:surfaceMember>"
                   for p in _spheroid_polys(0, 0, 0.4, 1.0, 1.0, z=0.0))
    implicit = ('<veg:lod2ImplicitRepresentation><ImplicitGeometry><transformationMatrix>{m}'
                '</transformationMatrix>{rel}<referencePoint><gml:Point><gml:pos>{p}</gml:pos>'
                '</gml:Point></referencePoint></ImplicitGeometry></veg:lod2ImplicitRepresentation>')
    members.append('<veg:SolitaryVegetationObject gml:id="T2"><veg:class>coniferous tree</veg:class>'
                   '<veg:height uom="m">15</veg:height><veg:crownDiameter uom="m">6</veg:crownDiameter>'
                   + implicit.format(m="6 0 0 0 0 6 0 0 0 0 15 0 0 0 0 1",
                                     rel=f'<relativeGMLGeometry><gml:MultiSurface gml:id="UNIT">{unit}'
                                         '</gml:MultiSurface></relativeGMLGeometry>',
                                     p=f"{X0 + 60} {Y0} 300")
                   + '</veg:SolitaryVegetationObject>')
    members.append('<veg:SolitaryVegetationObject gml:id="T3">'
                   + implicit.format(m=f"9 0 0 {X0 + 80} 0 9 0 {Y0} 0 0 20 300 0 0 0 1",
                                     rel='<relativeGMLGeometry xlink:href="#UNIT"/>',
                                     p=f"{X0 + 80} {Y0} 300")
                   + '</veg:SolitaryVegetationObject>')
    members.append('<veg:SolitaryVegetationObject gml:id="T4"><veg:height uom="m">10</veg:height>'
                   '<veg:crownDiameter uom="m">5</veg:crownDiameter>'
                   + implicit.format(m="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1",
                                     rel="<libraryObject>tree.dae</libraryObject>",
                                     p=f"{X0 + 100} {Y0} 300").replace("<libraryObject>", "<libraryObject>")
                   + '</veg:SolitaryVegetationObject>')
    members.append('<veg:SolitaryVegetationObject gml:id="T5"><veg:species>Quercus</veg:species>'
                   '</veg:SolitaryVegetationObject>')
    members.append('<veg:SolitaryVegetationObject gml:id="T6"><veg:crownDiameter uom="m">5</veg:crownDiameter>'
                   + implicit.format(m="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1",
                                     rel="<libraryObject>tree.dae</libraryObject>",
                                     p=f"{X0 + 110} {Y0} 300")
                   + '</veg:SolitaryVegetationObject>')
    cover = _poly(np.array([[X0 + 120, Y0, 301.0], [X0 + 150, Y0, 301.0], [X0 + 150, Y0 + 20, 301.0],
                            [X0 + 120, Y0 + 20, 301.0]]))
    members.append('<veg:PlantCover gml:id="P1"><veg:averageHeight uom="m">6</veg:averageHeight>'
                   f'<veg:lod1MultiSurface><gml:MultiSurface><gml:surfaceMember>{cover}</gml:surfaceMember>'
                   '</gml:MultiSurface></veg:lod1MultiSurface></veg:PlantCover>')
    path = tmp_path / "veg.gml"
    path.write_text(_gml(members))
    rep = ingest_city(path, tmp_path / "data", CityCfg(tile_size_m=500, buffer_m=100))
    trees = gpd.read_parquet(tmp_path / "data" / "city" / "trees.parquet").set_index("tree_id")
    t1 = trees.loc["T1"]                   # from its explicit crown: base at the widest ring's
    assert (t1.geometry.x, t1.geometry.y, t1.geometry.z) == pytest.approx((X0 + 40, Y0 + 5, 300.0), abs=0.01)
    assert t1.height_m == pytest.approx(12.0) and t1.leaf_type == "deciduous"
    assert 7.0 < t1.crown_diameter_m <= 8.0 and 4.0 < t1.crown_base_m < 5.3
    t2 = trees.loc["T2"]                   # attributes win; crown base from the unit tree
    assert (t2.height_m, t2.crown_diameter_m) == pytest.approx((15.0, 6.0))
    assert t2.leaf_type == "evergreen" and 0.4 * 15 < t2.crown_base_m < 0.5 * 15
    t3 = trees.loc["T3"]                   # the template by xlink, placed once
    assert (t3.geometry.x, t3.geometry.y) == pytest.approx((X0 + 80, Y0))
    assert t3.height_m == pytest.approx(20.0) and 7.5 < t3.crown_diameter_m <= 9.0
    t4 = trees.loc["T4"]                   # library object: attributes, the default crown base
    assert (t4.height_m, t4.crown_diameter_m, t4.crown_base_m) == pytest.approx((10.0, 5.0, 3.5))
    assert "T5" not in trees.index and "T6" not in trees.index
    cover = trees[trees["source"] == "plant_cover"]
    assert len(cover) == 5 * 3                         # 30 x 20 m, every 6 m (its height)
    assert (cover["height_m"] == 6.0).all() and (cover["crown_base_m"] == 0.0).all()
    assert np.allclose(cover["crown_diameter_m"], 1.2 * 6.0)
    r = rep.trees
    assert r["kept"] == 4 + len(cover) and r["skipped"] == {"no_position": 1, "no_height": 1}
    assert r["by_source"] == {"citygml": 4, "plant_cover": len(cover)}
    assert r["implicit_geometry"] == {"inline": 1, "template": 1, "library": 2}
    assert rep.problems.get("implicit_position_in_matrix_and_reference_point") == 1
    assert rep.surfaces == {"roof": 1, "wall": 4}                     # no vegetation surface
    for tile in json.loads((tmp_path / "data" / "city" / "tiles.json").read_text())["tiles"]:
        assert not (load_tile_mesh(tmp_path / "data", tile).surface_type == SURFACE_CODE["vegetation"]).any()
    assert "trees (citygml 4, plant_cover" in rep.summary()


def test_berlin_lidar_tree_models(tmp_path):
    """Twelve trees of a Berlin LiDAR tree model written by FME (tests/data/citygml/
    berlin_trees_12.gml): implicit geometries whose prototypes are defined inline by one tree
    and referred to by others, scaled and rotated by their matrices; height, crown diameter
    and trunk height (``h_trunk``, the crown base) as attributes.  Every tree is read at its
    reference point with its attributes; without its attributes, its size from the scaled
    (elliptic) prototype comes within 1 % of them (the crown diameter as the mean of the
    crown's two axes, as the file's own attributes are)."""
    from pathlib import Path

    from vipvflow.inputs.city import ingest_city

    src = Path(__file__).parent / "data" / "citygml" / "berlin_trees_12.gml"
    rep = ingest_city(src, tmp_path / "a")
    assert rep.trees["kept"] == 12 and rep.trees["implicit_geometry"] == {"inline": 3, "template": 9}
    assert rep.crs == "EPSG:25833" and 52.4 < rep.trees["latitude"] < 52.6
    a = gpd.read_parquet(tmp_path / "a" / "city" / "trees.parquet")
    assert a.iloc[0].geometry.coords[0] == pytest.approx((396801.75, 5819590.41, 43.36))
    assert (a.iloc[0].height_m, a.iloc[0].crown_diameter_m, a.iloc[0].crown_base_m) == pytest.approx(
        (7.07, 3.57, 2.89))
    # the same file without its size attributes: the prototypes tell
    text = src.read_text()
    import re

    bare = re.sub(r"<veg:height[^<]*</veg:height>|<veg:crownDiameter[^<]*</veg:crownDiameter>", "", text)
    bare = bare.replace('name="h_trunk"', 'name="h_trunk_unused"')
    (tmp_path / "bare.gml").write_text(bare)
    ingest_city(tmp_path / "bare.gml", tmp_path / "b")
    b = gpd.read_parquet(tmp_path / "b" / "city" / "trees.parquet")
    np.testing.assert_allclose(b["height_m"], a["height_m"], rtol=0.01)
    np.testing.assert_allclose(b["crown_diameter_m"], a["crown_diameter_m"], rtol=0.01)


def _city(tmp_path):
    path = tmp_path / "city.gml"
    path.write_text(_gml([_building(X0, Y0, ground=True)]))
    return path


def test_tree_tables_csv_and_geoparquet(tmp_path):
    """A CSV in lon/lat with a tree cadastre's column names, genera, leaf-off months and bad
    rows (skipped by reason, the lines named), a CSV in x/y of the city's CRS, and a
    GeoParquet in another CRS with 3-D points: all in the city's CRS, the ground from the
    relief-less city model's buildings where the table gives none."""
    from pyproj import Transformer

    from vipvflow.inputs.city import ingest_city

    to_ll = Transformer.from_crs("EPSG:2169", "EPSG:4326", always_xy=True)
    lon, lat = to_ll.transform(X0 + 20, Y0 + 20)
    rows = [("a1", lon, lat, 12, 7, "Tilia cordata", ""), ("a2", lon, lat, "", 7, "Acer", ""),
            ("a3", lon, lat, 12, 7, "Pinus nigra", "11-3"), ("a4", lon, lat, 5, 4, "?", "13"),
            ("a5", lon, lat, 300, 7, "Acer", "")]
    csv = tmp_path / "cadastre.csv"
    pd.DataFrame(rows, columns=["gisid", "lon", "lat", "baumhoehe", "kronedurch", "art_bot",
                                "leaf_off_months"]).to_csv(csv, index=False)
    xy = tmp_path / "xy.csv"
    pd.DataFrame({"x": [X0 + 30], "y": [Y0 + 30], "height": [10], "crown_diameter": [6],
                  "crown_base": [3], "z": [305.0], "leaf_type": ["evergreen"]}).to_csv(xy, index=False)
    to_utm = Transformer.from_crs("EPSG:2169", "EPSG:32631", always_xy=True)
    ux, uy = to_utm.transform(X0 + 40, Y0 + 40)
    gp = tmp_path / "trees.parquet"
    gpd.GeoDataFrame({"height_m": [9.0], "crown_diameter_m": [5.0], "species": ["Betula pendula"]},
                     geometry=gpd.points_from_xy([ux], [uy], [302.0]), crs="EPSG:32631").to_parquet(gp)
    rep = ingest_city(_city(tmp_path), tmp_path / "data", CityCfg(tile_size_m=500, buffer_m=100),
                      trees=[csv, xy, gp])
    r = rep.trees
    assert r["kept"] == 4 and r["by_source"] == {"table": 4}
    assert r["skipped"] == {"no_height": 1, "unreadable_leaf_off_months": 1, "size_beyond_a_tree": 1}
    assert r["skipped_examples"]["no_height"] == [f"{csv}: line 3"]
    assert r["by_leaf_type"] == {"deciduous": 2, "evergreen": 2}
    t = gpd.read_parquet(tmp_path / "data" / "city" / "trees.parquet").set_index("tree_id")
    assert (t.loc["a1"].geometry.x, t.loc["a1"].geometry.y) == pytest.approx((X0 + 20, Y0 + 20), abs=0.01)
    assert t.loc["a1"].geometry.z == pytest.approx(300.0)          # the building's ground nearby
    assert t.loc["a3"].leaf_off_months == "1,2,3,11,12" and t.loc["a3"].leaf_type == "evergreen"
    assert t.loc["a1"].crown_base_m == pytest.approx(0.35 * 12)
    xy_tree = t[t["crown_base_m"] == 3.0].iloc[0]
    assert xy_tree.geometry.z == 305.0 and xy_tree.leaf_type == "evergreen"
    g = t[t["leaf_type"] == "deciduous"].drop("a1")
    assert (g.iloc[0].geometry.x, g.iloc[0].geometry.y, g.iloc[0].geometry.z) == pytest.approx(
        (X0 + 40, Y0 + 40, 302.0), abs=0.01)


@pytest.mark.parametrize("content, message", [
    ("x,y,crown_diameter\n1,2,3\n", "no height column"),
    ("a,b\n1,2\n", "no tree positions"),
    ("", "empty file"),
])
def test_bad_tree_tables_in_one_line(tmp_path, content, message):
    from vipvflow.inputs.city import ingest_city

    bad = tmp_path / "bad.csv"
    bad.write_text(content)
    with pytest.raises(InputError, match=message) as err:
        ingest_city(_city(tmp_path), tmp_path / "data", trees=[bad])
    assert str(bad) in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "data" / "city").exists()               # nothing half made


def test_config_refuses_the_vegetation_albedo(tmp_path):
    path = tmp_path / "c.yaml"
    path.write_text("city:\n  albedo: {vegetation: 0.2}\n")
    with pytest.raises(ConfigError, match="vegetation is gone"):
        load_config(path)
    cfg = load_config(None, {"irradiance": {"trees": {"leaf_off_months": [12, 1, 1]}}})
    assert cfg.irradiance.trees.leaf_off_months == [1, 12]
    with pytest.raises(ConfigError, match="months 1..12"):
        load_config(None, {"irradiance": {"trees": {"leaf_off_months": [13]}}})
