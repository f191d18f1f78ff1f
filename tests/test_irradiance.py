"""Roof irradiance against pvlib, analytic shading edges and analytic view factors."""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pvlib
import pytest

from vipvflow.config import IrradianceCfg
from vipvflow.models.irradiance import evaluate_passes, roof_irradiance
from vipvflow.models.view_factors import roof_plane, segment_geometry, sun_vector
from vipvflow.inputs.cams import COLUMNS
from vipvflow.models.sun_sky import RadiationTable
from vipvflow.models.shading import Scene, box_mesh

LONG = 3000.0     # half length of "infinite" walls (m)


def _uniform(**kw) -> IrradianceCfg:
    """The engine's settings under a uniform sky (``sky_view_factor``) unless *kw* names
    another: these tests check geometry and light against analytic forms of that sky."""
    return IrradianceCfg(**{"diffuse_model": "sky_view_factor", **kw})


def _segments(x, y, z, heading=0.0, gradient=0.0):
    n = len(np.atleast_1d(x))
    return pd.DataFrame({"segment_id": np.arange(n), "x": np.atleast_1d(x).astype(float),
                         "y": np.broadcast_to(y, n).astype(float), "z": np.broadcast_to(z, n).astype(float),
                         "heading_deg": np.broadcast_to(heading, n).astype(float),
                         "gradient": np.broadcast_to(gradient, n).astype(float)})


def _kernel(scene, geometry, rows, zenith, azimuth, rad, cfg, ground_albedo=0.2):
    sun = sun_vector(zenith, azimuth).astype(np.float32)
    return roof_irradiance(geometry, rows, sun, {k: np.asarray(v, np.float32) for k, v in rad.items()},
                           scene, cfg, ground_albedo)


def _constant_table(t, **values):
    """A 1-min radiation table over the times *t* (Unix s), Luxembourg's sun, the given
    columns constant (W/m2) and the others 0."""
    grid = np.arange(np.floor(t.min() / 60) * 60 - 120, t.max() + 180, 60.0)
    vals = {c: np.full(len(grid), float(values.get(c, 0.0))) for c in COLUMNS}
    return RadiationTable.from_grid(grid, vals, 49.61, 6.13, 300.0)


def test_roof_faces_downhill():
    tilt, az = roof_plane([0.0, 90.0, 90.0], [0.10, 0.10, -0.05])
    assert np.allclose(tilt, np.degrees(np.arctan([0.10, 0.10, 0.05])))
    assert np.allclose(az, [180.0, 270.0, 90.0])     # climbing north: roof tilts to the south


def test_no_buildings_equals_pvlib_isotropic():
    rng = np.random.default_rng(11)
    n = 1000
    tilt_true = rng.uniform(0, 35, n)
    gradient = np.tan(np.radians(tilt_true)) * rng.choice([-1, 1], n)
    heading = rng.uniform(0, 360, n)
    segs = _segments(rng.uniform(0, 100, n), 0.0, 3.2, heading, gradient)
    scene = Scene(box_mesh(np.zeros((0, 6))))
    cfg = _uniform(svf_rays=16, reflection_rays=16, diffuse_model="isotropic")
    geometry = segment_geometry(scene, segs, cfg, roof_height_m=None)     # nothing, not even a street
    zen, azi = rng.uniform(0, 89, n), rng.uniform(0, 360, n)
    dni, dhi = rng.uniform(0, 900, n), rng.uniform(0, 300, n)
    ghi = dhi + dni * np.cos(np.radians(zen))
    rad = {"dni": dni, "dhi": dhi, "ghi": ghi, "dni_clear": dni * 1.1, "dhi_clear": dhi * 0.5,
           "ghi_clear": ghi}
    out = _kernel(scene, geometry, np.arange(n), zen, azi, rad, cfg)
    surf_tilt, surf_az = roof_plane(heading, gradient)
    ref = pvlib.irradiance.get_total_irradiance(surf_tilt, surf_az, zen, azi, dni, ghi, dhi,
                                                albedo=0.0, model="isotropic")
    ref_c = pvlib.irradiance.get_total_irradiance(surf_tilt, surf_az, zen, azi, dni * 1.1, ghi,
                                                  dhi * 0.5, albedo=0.0, model="isotropic")
    for got, want in ((out["total"], ref["poa_global"]), (out["total_unshaded"], ref["poa_global"]),
                      (out["total_clear"], ref_c["poa_global"]), (out["direct"], ref["poa_direct"])):
        np.testing.assert_allclose(got, want, rtol=1e-3, atol=1e-3)
    assert (out["reflected"] == 0).all() and out["sun_visible"][ref["poa_direct"] > 0].all()


def test_evaluate_passes_full_chain_matches_pvlib():
    """Radiation table + sun position on the grid + pass times, no buildings."""
    grid = np.arange(pd.Timestamp("2024-06-01", tz="UTC").timestamp(),
                     pd.Timestamp("2024-06-03", tz="UTC").timestamp(), 60.0)
    vals = {c: np.full(len(grid), v) for c, v in zip(COLUMNS, (600, 700, 150, 800, 850, 90))}
    table = RadiationTable.from_grid(grid, vals, 49.61, 6.13, 300.0)
    segs = _segments([0.0, 10.0, 20.0], 0.0, 3.2, [0.0, 90.0, 200.0], [0.0, 0.08, -0.03])
    scene = Scene(box_mesh(np.zeros((0, 6))))
    cfg = _uniform(svf_rays=16, reflection_rays=16, diffuse_model="isotropic")
    geometry = segment_geometry(scene, segs, cfg)
    rng = np.random.default_rng(5)
    p = 300
    passes = pd.DataFrame({"segment_id": rng.integers(0, 3, p),
                           "t_utc": rng.uniform(grid[10], grid[-10], p), "dt_s": 2.0})
    out = evaluate_passes(passes, segs, geometry, table, scene, cfg)
    t_mid = pd.to_datetime((passes["t_utc"] + 1.0) * 1e9, utc=True)
    sp = pvlib.solarposition.get_solarposition(t_mid, 49.61, 6.13, altitude=300.0)
    tilt, az = roof_plane(segs["heading_deg"].to_numpy()[passes["segment_id"]],
                          segs["gradient"].to_numpy()[passes["segment_id"]])
    up = sp["apparent_zenith"].to_numpy() < 90
    ref = pvlib.irradiance.get_total_irradiance(tilt, az, sp["apparent_zenith"].to_numpy(),
                                                sp["azimuth"].to_numpy(), np.where(up, 700, 0),
                                                600, 150, albedo=0.0, model="isotropic")
    np.testing.assert_allclose(out["total"], ref["poa_global"], rtol=1e-3, atol=0.05)


def test_long_wall_blocks_below_profile_angle():
    H, D, zr = 15.0, 8.0, 3.2
    scene = Scene(box_mesh([[D, -LONG, 0.0, D + 1.0, LONG, H]]))
    cfg = _uniform(svf_rays=16, reflection_rays=0, ray_length_m=5000.0, ray_offset_m=0.05)
    geometry = segment_geometry(scene, _segments(0.0, 0.0, zr), cfg)
    rng = np.random.default_rng(3)
    n = 4000
    az = rng.uniform(20, 340, n)
    el = rng.uniform(0.5, 70, n)
    rad = {c: np.full(n, 500.0) for c in COLUMNS}
    out = _kernel(scene, geometry, np.zeros(n, int), 90 - el, az, rad, cfg)
    # profile angle in the wall's normal plane (the wall faces west, towards the roof)
    c = np.cos(np.radians(az - 90.0))
    east = c > 0.05
    profile = np.degrees(np.arctan2(np.tan(np.radians(el)), np.where(east, c, 1.0)))
    edge = np.degrees(np.arctan((H - zr - cfg.ray_offset_m) / D))
    blocked = east & (profile < edge)
    clear = np.abs(profile - edge) > 0.1
    assert blocked.sum() > 300 and (~blocked).sum() > 300
    np.testing.assert_array_equal(out["sun_visible"][clear], ~blocked[clear])
    assert (out["direct"][blocked] == 0).all()


@pytest.mark.parametrize("H,W", [(16.0, 20.0), (10.0, 30.0)])
def test_canyon_sky_view_factor(H, W):
    """Horizontal element on the centreline of an infinite canyon: SVF = W / sqrt(W^2 + 4 H^2).

    2D view factor of an element to a strip seen between angles -a and +a from its normal:
    (sin a - sin(-a)) / 2 = sin a with tan a = (W/2) / H, i.e. cos(atan(2H/W)).
    """
    zr = 3.0
    scene = Scene(box_mesh([[-W / 2 - 1, -LONG, 0, -W / 2, LONG, zr + H],
                            [W / 2, -LONG, 0, W / 2 + 1, LONG, zr + H]]))
    cfg = _uniform(svf_rays=4096, reflection_rays=64, ray_length_m=10_000.0, ray_offset_m=0.0)
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr, 0.0, 0.0), cfg)
    expected = np.cos(np.arctan(2 * H / W))
    assert geometry["svf"].iloc[0] == pytest.approx(expected, rel=0.02)


def test_tilted_roof_open_sky_view_factor():
    cfg = _uniform(svf_rays=1024, reflection_rays=8)
    scene = Scene(box_mesh(np.zeros((0, 6))))
    g = np.tan(np.radians([0.0, 10.0, 30.0]))
    geometry = segment_geometry(scene, _segments([0, 1, 2], 0.0, 3.0, 45.0, g), cfg)
    np.testing.assert_allclose(geometry["svf"], (1 + np.cos(np.arctan(g))) / 2, rtol=0.01)


def test_reflection_from_large_wall_matches_view_factor():
    """Horizontal roof at distance D from a wall of height H above it, albedo rho.

    View factor roof -> wall (2D, infinite length): F = (1 - D / sqrt(D^2 + H^2)) / 2.
    Reflected = rho F E_wall, E_wall = DNI cos(theta) + DHI F_sky + GHI rho_g F_ground.  The
    wall stands alone on open ground (no ground in the mesh, nothing in front of it), so its
    own view factors are those of a vertical plane: F_sky = F_ground = 1/2, and it is lit
    over its whole height or not at all.
    """
    D, H, zr, rho, rho_g = 6.0, 25.0, 3.0, 0.4, 0.2
    scene = Scene(box_mesh([[D, -LONG, 0.0, D + 2, LONG, zr + H]], albedo_wall=rho))
    cfg = _uniform(svf_rays=64, reflection_rays=4096, ray_length_m=10_000.0, ray_offset_m=0.0,
                        max_reflector_groups=3, reflector_points=16,
                        reflector_sky_rays=16)
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), cfg, roof_height_m=None)
    F = (1 - D / np.hypot(D, H)) / 2
    assert geometry["refl_vf"].iloc[0] == pytest.approx(rho * F, rel=0.03)
    assert geometry["r0_w"].iloc[0] == pytest.approx(rho * F, rel=0.03)
    assert geometry["r0_nx"].iloc[0] == pytest.approx(-1.0, abs=1e-6)
    assert geometry["r1_w"].iloc[0] == 0
    assert geometry["r0_sky"].iloc[0] == pytest.approx(0.5, abs=0.03)
    assert geometry["r0_open"].iloc[0] == pytest.approx(1 - geometry["r0_sky"].iloc[0], abs=1e-6)
    assert geometry["r0_gnd"].iloc[0] == 0
    P = cfg.reflector_points
    pz = geometry[[f"r0_p{k}_z" for k in range(P)]].to_numpy()
    px = geometry[[f"r0_p{k}_x" for k in range(P)]].to_numpy()
    py = geometry[[f"r0_p{k}_y" for k in range(P)]].to_numpy()
    assert (pz > zr).all() and (pz < zr + H).all()
    # stratified in 2D: the P points hold the P weight strata of height (the view factor of
    # the wall up to height h above the roof is F(h), analytic) ...
    quantile = (1 - D / np.hypot(D, np.sort(pz[0]) - zr)) / (1 - D / np.hypot(D, H))
    np.testing.assert_array_less(np.abs(quantile * P - np.arange(P) - 0.5), 0.5)
    # ... and in each of the sqrt(P) height bands, sqrt(P) strata along the wall, which the
    # roof sees symmetrically about its own position (y = 0): half of each band either side
    B = math.isqrt(P)
    assert B * B == P
    along = np.sort(py[0].reshape(B, B), axis=1)
    assert (along[:, : B // 2] < 0).all() and (along[:, B // 2:] > 0).all()
    np.testing.assert_allclose(px, D - 0.02, atol=1e-5)      # on the face, lifted 2 cm
    # sun in the west at 30 deg elevation lights the wall face (normal -x) at cos = 0.866
    zen, az = np.array([60.0]), np.array([270.0])
    dni, dhi = 700.0, 120.0
    ghi = dhi + dni * np.cos(np.radians(60.0))
    rad = {"dni": [dni], "dhi": [dhi], "ghi": [ghi], "dni_clear": [0.0], "dhi_clear": [dhi],
           "ghi_clear": [dhi]}
    out = _kernel(scene, geometry, np.array([0]), zen, az, rad, cfg, ground_albedo=rho_g)
    e_wall = dni * np.sin(np.radians(60.0)) + dhi / 2 + ghi * rho_g / 2
    assert out["reflected"][0] == pytest.approx(rho * F * e_wall, rel=0.05)
    assert out["reflected_clear"][0] == pytest.approx(rho * F * (dhi / 2 + dhi * rho_g / 2), rel=0.05)
    # sun in the east behind the wall: the wall face is dark, the roof is shaded
    out = _kernel(scene, geometry, np.array([0]), zen, np.array([90.0]), rad, cfg, ground_albedo=rho_g)
    assert out["reflected"][0] == pytest.approx(rho * F * (dhi / 2 + ghi * rho_g / 2), rel=0.05)
    assert out["direct"][0] == 0


def test_sky_view_factor_diffuse_mode():
    H, W, zr = 16.0, 20.0, 3.0
    scene = Scene(box_mesh([[-W / 2 - 1, -LONG, 0, -W / 2, LONG, zr + H],
                            [W / 2, -LONG, 0, W / 2 + 1, LONG, zr + H]]))
    iso = _uniform(svf_rays=1024, reflection_rays=256, ray_length_m=5000.0,
                        diffuse_model="isotropic")
    svf = iso.model_copy(update={"diffuse_model": "sky_view_factor"})
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), svf)
    rad = {c: [300.0] for c in COLUMNS}
    a = _kernel(scene, geometry, np.array([0]), np.array([40.0]), np.array([0.0]), rad, iso)
    b = _kernel(scene, geometry, np.array([0]), np.array([40.0]), np.array([0.0]), rad, svf)
    assert a["diffuse"][0] == pytest.approx(300.0)
    assert b["diffuse"][0] == pytest.approx(300.0 * geometry["svf"].iloc[0])
    assert b["total_unshaded"][0] == a["total_unshaded"][0]


def _canyon(H, W, rho_wall=0.35, rho_road=0.15):
    """Infinite canyon (walls along y) with its road as ground triangles in the mesh."""
    from vipvflow.models.mesh import SURFACE_CODE, TileMesh

    walls = box_mesh([[-W / 2 - 20, -LONG, 0, -W / 2, LONG, H],
                      [W / 2, -LONG, 0, W / 2 + 20, LONG, H]], albedo_wall=rho_wall)
    g = 4 * LONG
    road = np.array([[[-g, -g, 0], [g, -g, 0], [g, g, 0]], [[-g, -g, 0], [g, g, 0], [-g, g, 0]]])
    tris = np.concatenate([walls.vertices[walls.triangles], road])
    mesh = TileMesh.from_triangles(tris, albedo=np.r_[walls.albedo, [rho_road] * 2])
    mesh.surface_type[:] = np.r_[walls.surface_type, [SURFACE_CODE["ground"]] * 2]
    return mesh


@pytest.mark.parametrize("P", [4, 16])
def test_partly_lit_facade_lit_fraction(P):
    """Sun across a canyon at elevation e: the facade facing it is lit above
    z_s = H - W tan e only.  From a horizontal roof at height z_r on the centreline (distance
    D = W/2), a strip of the facade between heights h1 < h2 above the roof has the view factor
    (sin a1 - sin a2) / 2 with sin a = D / sqrt(D^2 + h^2).  Beam reflected once:
    rho DNI cos(theta) F_lit; the P sample points resolve F_lit to within half a point's share
    of the group's weight, F / (2 P)."""
    H, W, zr, rho, el, dni = 16.0, 18.0, 3.2, 0.35, 20.0, 800.0
    scene = Scene(_canyon(H, W, rho))
    cfg = _uniform(svf_rays=64, reflection_rays=8192, ray_length_m=10_000.0,
                        reflector_points=P, reflector_sky_rays=8, reflector_sampling="all")
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), cfg)
    s_ = lambda h: (W / 2) / np.hypot(W / 2, h)
    z_s = H - W * np.tan(np.radians(el))
    r0 = cfg.ray_offset_m
    F = (s_(0.0) - s_(H - zr - r0)) / 2
    F_lit = (s_(z_s - zr - r0) - s_(H - zr - r0)) / 2
    rad = {"dni": [0.0], "dhi": [0.0], "ghi": [0.0], "dni_clear": [dni], "dhi_clear": [0.0],
           "ghi_clear": [0.0]}
    # sunlight reflected once: without the street and the facades' exchange (a geometry
    # table of the first bounce only)
    first = geometry.drop(columns=[c for c in geometry.columns
                                   if c.startswith("st_") or c.endswith("_wall")])
    out = _kernel(scene, first, np.array([0]), np.array([90.0 - el]), np.array([90.0]), rad, cfg)
    e_full = rho * dni * np.cos(np.radians(el))
    assert not out["sun_visible"][0] and out["reflected"][0] == 0
    assert abs(out["reflected_clear"][0] - e_full * F_lit) <= e_full * F * (0.5 / P + 0.03)
    assert out["reflected_clear"][0] < 0.8 * e_full * F        # not lit all-or-nothing


def test_rotating_reflector_sample_is_the_p_point_lit_fraction_on_average():
    """``reflector_sampling: rotate`` traces one sample point per reflector group and pass:
    over P passes that take the points in turn the mean reflected irradiance equals the
    P-point lit fraction of ``all`` exactly, with one reflector ray per group instead of P;
    through evaluate_passes (points chosen by a hash of segment and time) the mean over
    many passes converges to it."""
    H, W, zr, el, dni, P = 16.0, 18.0, 3.2, 20.0, 800.0, 8
    scene = Scene(_canyon(H, W, 0.35))
    all_ = _uniform(svf_rays=64, reflection_rays=4096, ray_length_m=10_000.0,
                         reflector_points=P, reflector_sky_rays=8, reflector_sampling="all")
    rot = all_.model_copy(update={"reflector_sampling": "rotate"})
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), all_)
    rad = {"dni": [0.0] * P, "dhi": [0.0] * P, "ghi": [0.0] * P, "dni_clear": [dni] * P,
           "dhi_clear": [0.0] * P, "ghi_clear": [0.0] * P}
    zen, az = np.full(P, 90.0 - el), np.full(P, 90.0)
    rows = np.zeros(P, np.int64)
    exact = _kernel(scene, geometry, rows, zen, az, rad, all_)["reflected_clear"]
    turns = _kernel(scene, geometry, rows, zen, az, rad, rot)["reflected_clear"]
    assert np.ptp(exact) == 0 and 0 < exact[0]
    assert len(np.unique(turns)) > 1                              # single points: lit or not
    assert turns.mean() == pytest.approx(exact[0], rel=1e-5)

    class Counting(Scene):
        rays = 0

        def occluded_local(self, o, d, tfar):
            Counting.rays += len(o)
            return super().occluded_local(o, d, tfar)

    counting = Counting(_canyon(H, W, 0.35))
    n = 4000
    t = pd.Timestamp("2024-03-20 06:00", tz="UTC").timestamp() + np.arange(n) * 7.0
    table = _constant_table(t, dni_clear=dni)
    passes = pd.DataFrame({"segment_id": np.zeros(n, np.int64), "t_utc": t,
                           "dt_s": np.full(n, 1.0, np.float32)})
    a = evaluate_passes(passes, None, geometry, table, counting, all_)
    rays_all, Counting.rays = Counting.rays, 0
    b = evaluate_passes(passes, None, geometry, table, counting, rot)
    assert Counting.rays < rays_all / 3
    assert b["reflected_clear"].mean() == pytest.approx(a["reflected_clear"].mean(), rel=0.03)
    assert (b["direct_clear"] == a["direct_clear"]).all()
    np.testing.assert_array_equal(b["diffuse_clear"], a["diffuse_clear"])


def test_canyon_facade_sees_its_own_sky_and_road():
    """A point at height z on a canyon wall (height H, width W) sees the sky above the
    opposite roof edge, F_sky = (1 - (H - z) / sqrt((H - z)^2 + W^2)) / 2, and the road below,
    F_road = (1 - z / sqrt(z^2 + W^2)) / 2 (2D, infinite canyon); the group's factors are
    the means over its sample points, the road's weighted by its albedo."""
    H, W, zr, rho_road = 16.0, 18.0, 3.2, 0.15
    scene = Scene(_canyon(H, W, rho_road=rho_road))
    cfg = _uniform(svf_rays=64, reflection_rays=2048, ray_length_m=10_000.0,
                        reflector_points=4, reflector_sky_rays=2048)
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), cfg)
    row = geometry.iloc[0]
    groups = [g for g in range(cfg.max_reflector_groups) if row[f"r{g}_w"] > 0]
    assert len(groups) == 2                                    # the two facades
    for g in groups:
        z = np.array([row[f"r{g}_p{k}_z"] for k in range(cfg.reflector_points)])
        f_sky = (1 - (H - z) / np.hypot(H - z, W)) / 2
        f_road = (1 - z / np.hypot(z, W)) / 2
        assert row[f"r{g}_sky"] == pytest.approx(f_sky.mean(), abs=0.015)
        assert row[f"r{g}_gnd"] == pytest.approx(rho_road * f_road.mean(), abs=0.015 * rho_road)
        assert row[f"r{g}_open"] == 0                           # the road covers the ground


def test_geometry_is_per_segment_and_plain_numeric():
    """A segment's rays come from its own random stream: the same geometry whether it is
    computed with others in one batch or alone; every column is a plain number (parquet)."""
    scene = Scene(box_mesh([[8, -50, 0, 12, 50, 15], [-14, -20, 0, -9, 30, 22]]))
    cfg = _uniform(svf_rays=32, reflection_rays=64, reflector_points=3, reflector_sky_rays=8)
    segs = _segments(np.linspace(-5, 5, 7), np.linspace(-30, 30, 7), 3.2, 10.0, 0.02)
    segs["segment_id"] = [40, 3, 17, 8, 99, 5, 61]
    together = segment_geometry(scene, segs, cfg)
    alone = pd.concat([segment_geometry(scene, segs.iloc[[i]], cfg) for i in (4, 0, 6, 1, 2, 5, 3)])
    alone = alone.set_index("segment_id").loc[segs["segment_id"]].reset_index()
    pd.testing.assert_frame_equal(together, alone[together.columns])
    pd.testing.assert_frame_equal(together, segment_geometry(scene, segs, cfg, chunk=2))
    assert all(np.issubdtype(t, np.number) for t in together.dtypes)
    assert (together["r0_w"] > 0).all()
    assert {f"r2_p2_{c}" for c in "xyz"} | {"r2_sky", "r2_gnd", "r2_open"} <= set(together.columns)


def test_geometry_file_reads_back_as_computed(tmp_path):
    """The geometry file (the sample points in one list column per reflector) reads back
    as the table segment_geometry made: the same columns, in order, dtypes and values; a
    file written the older way (one column per coordinate) too."""
    import pyarrow.parquet as pq

    from vipvflow.models.view_factors import geometry_table, read_geometry
    from vipvflow.store import write_parquet

    scene = Scene(box_mesh([[8, -50, 0, 12, 50, 15], [-14, -20, 0, -9, 30, 22]]))
    cfg = _uniform(svf_rays=32, reflection_rays=64, reflector_points=5, reflector_sky_rays=8)
    segs = _segments(np.linspace(-5, 5, 7), np.linspace(-30, 30, 7), 3.2, 10.0, 0.02)
    segs["segment_id"] = [40, 3, 17, 8, 99, 5, 61]
    geometry = segment_geometry(scene, segs, cfg)
    path = write_parquet(geometry_table(geometry), tmp_path / "tile=A.parquet")
    names = pq.read_schema(path).names
    assert "r0_points" in names and "st_points" in names and "r0_p0_x" not in names
    assert not any("_p0_" in n for n in names) and len(names) == len(geometry.columns) - 3 * 5 * 5 + 5
    pd.testing.assert_frame_equal(read_geometry(path), geometry, check_exact=True)
    pd.testing.assert_frame_equal(read_geometry(path, columns=["segment_id", "svf"]),
                                  geometry[["segment_id", "svf"]], check_exact=True)
    older = write_parquet(geometry, tmp_path / "tile=B.parquet")
    pd.testing.assert_frame_equal(read_geometry(older), geometry, check_exact=True)


def test_exchange_weights_are_the_radiosity_solution():
    """Two facades facing each other (view factors f_A of B from A, f_B of A from B, albedo
    included) and no street: E_A = S_A + f_A E_B, E_B = S_B + f_B E_A, so the roof
    (w_A E_A + w_B E_B) weighs the sources by m_A = (w_A + w_B f_B) / (1 - f_A f_B) and
    m_B = (w_B + w_A f_A) / (1 - f_A f_B).  One facade and its street (f_s of the street
    from the facade, f_w of the facade from the street): m = w / (1 - f_s f_w) for the
    facade and w f_s / (1 - f_s f_w) for the street."""
    from vipvflow.models.view_factors import _exchange_weights

    wA, wB, fA, fB = 0.06, 0.04, 0.12, 0.09
    m = _exchange_weights(np.array([[wA, wB]]), np.zeros((1, 2)), np.array([[fA, fB]]),
                          np.zeros(1), np.array([False]))
    d = 1 - fA * fB
    np.testing.assert_allclose(m[0], [(wA + wB * fB) / d, (wB + wA * fA) / d, 0.0], rtol=1e-12)
    w, fs, fw = 0.05, 0.1, 0.2
    m = _exchange_weights(np.array([[w]]), np.array([[fs]]), np.zeros((1, 1)), np.array([fw]),
                          np.array([True]))
    np.testing.assert_allclose(m[0], [w / (1 - fs * fw), w * fs / (1 - fs * fw)], rtol=1e-12)


def test_sun_along_the_canyon_lights_the_roof_through_the_street():
    """Sun along a long canyon at 40 deg: the facades (normals across) get no beam, the road
    is lit (its sample points all see the sun), and the roof's reflected beam is the road's
    light passed on by the facades: DNI sin(el) x sum_g w_g F_road,g, times the facades'
    exchange factor, between 1 and 1 / (1 - max F_wall)."""
    H, W, zr, el, dni = 16.0, 18.0, 3.2, 40.0, 800.0
    scene = Scene(_canyon(H, W))
    cfg = _uniform(reflection_rays=2048, reflector_sky_rays=64, ray_length_m=10_000.0,
                        reflector_sampling="all")
    geometry = segment_geometry(scene, _segments([0.0], 0.0, zr), cfg)
    row = geometry.iloc[0]
    st_z = np.array([row[f"st_p{k}_z"] for k in range(cfg.reflector_points)])
    st_x = np.array([row[f"st_p{k}_x"] for k in range(cfg.reflector_points)])
    assert np.allclose(st_z, cfg.ray_offset_m, atol=1e-4) and (np.abs(st_x) < W / 2).all()   # road
    rad = {"dni": [0.0], "dhi": [0.0], "ghi": [0.0], "dni_clear": [dni], "dhi_clear": [0.0],
           "ghi_clear": [0.0]}
    out = _kernel(scene, geometry, np.array([0]), np.array([90.0 - el]), np.array([0.0]), rad, cfg)
    groups = [g for g in range(cfg.max_reflector_groups) if row[f"r{g}_w"] > 0]
    via_street = dni * np.sin(np.radians(el)) * sum(row[f"r{g}_w"] * row[f"r{g}_gnd"] for g in groups)
    f_wall = max(row[f"r{g}_wall"] for g in groups)
    assert via_street > 0 and out["sun_visible"][0]
    assert via_street * 0.97 <= out["reflected_clear"][0] <= via_street / (1 - f_wall) * 1.03


def _cosine_directions_numpy(normals, n_rays, uni):
    """The numpy form of ``cosine_directions`` (the product's before it was compiled):
    Malley's method on a jittered Fibonacci spiral about each normal's tangent frame."""
    golden = (np.sqrt(5.0) - 1.0) / 2.0
    k = np.arange(n_rays)
    u = (k[None] + uni[:, :n_rays]) / n_rays
    phi = 2 * np.pi * ((k[None] * golden + uni[:, n_rays:]) % 1.0)
    r = np.sqrt(u)
    lx, ly, lz = r * np.cos(phi), r * np.sin(phi), np.sqrt(np.clip(1 - u, 0, 1))
    ref = np.where(np.abs(normals[:, 0:1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
    t1 = np.cross(normals, ref)
    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(normals, t1)
    return lx[..., None] * t1[:, None] + ly[..., None] * t2[:, None] + lz[..., None] * normals[:, None]


@pytest.mark.parametrize("m, n_rays", [(500, 64), (7, 1024), (1, 1), (0, 16)])
def test_compiled_hemisphere_directions_equal_the_numpy_form(m, n_rays):
    from vipvflow.models.view_factors import cosine_directions, segment_uniforms

    rng = np.random.default_rng(7)
    normals = rng.normal(size=(m, 3))
    normals[: m // 4] = [0.0, 0.0, 1.0]                      # roofs: both tangent frames
    normals[m // 4: m // 2, 0] = 5.0                          # |n_x| >= 0.9: the other reference
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    uni = segment_uniforms(3, 1, np.arange(m), n_rays + 1)
    got = cosine_directions(normals, n_rays, uni)
    want = _cosine_directions_numpy(normals, n_rays, uni)
    assert got.shape == (m, n_rays, 3)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-15)
    if m:
        np.testing.assert_allclose(np.linalg.norm(got, axis=2), 1.0, atol=1e-12)
        assert (np.einsum("mkc,mc->mk", got, normals) >= -1e-12).all()    # the upper hemisphere


def test_segment_uniforms_are_each_keys_own_default_rng():
    from vipvflow.models.view_factors import segment_uniforms

    keys = np.array([0, 7, 123456789, 2**40])
    got = segment_uniforms(42, 2, keys, 33)
    for row, key in zip(got, keys):
        np.testing.assert_array_equal(row, np.random.default_rng([42, 2, int(key)]).random(33))


# ---------------------------------------------------------------------------- the Perez sky
def test_perez_coefficients_give_pvlibs_perez_sky_diffuse():
    """An open tilted plane: the model's Perez sky (isotropic part x (1 + cos tilt) / 2,
    circumsolar part seen with the sun, horizon part x sin tilt) is pvlib's
    ``irradiance.perez`` sky diffuse, component by component."""
    from vipvflow.models.irradiance import roof_components
    from vipvflow.models.sky import perez_coefficients

    rng = np.random.default_rng(3)
    n = 2000
    times = pd.Timestamp("2024-01-01", tz="UTC") + pd.to_timedelta(rng.uniform(0, 366, n), "D")
    zen, azi = rng.uniform(0, 89, n), rng.uniform(0, 360, n)
    tilt, s_az = rng.uniform(0, 90, n), rng.uniform(0, 360, n)
    dni, dhi = rng.uniform(0, 950, n), rng.uniform(1, 400, n)
    e0 = pvlib.irradiance.get_extra_radiation(times).to_numpy()
    am = pvlib.atmosphere.get_relative_airmass(zen)
    ref = pvlib.irradiance.perez(tilt, s_az, dhi, dni, e0, zen, azi, am, return_components=True)
    f1, f2 = perez_coefficients(dhi, dni, e0, zen, am)
    cos_aoi = np.maximum(pvlib.irradiance.aoi_projection(tilt, s_az, zen, azi), 0)
    f = np.float32
    iso = ((1 + np.cos(np.radians(tilt))) / 2).astype(f)
    sin_t = np.sin(np.radians(tilt)).astype(f)
    sky = {"f1": f1.astype(f), "f2": f2.astype(f), "cos_zenith": np.cos(np.radians(zen)).astype(f),
           "horizon_view": sin_t, "reflector_horizon": np.zeros(n, f), "sin_tilt": sin_t}
    z = np.zeros(n, f)
    direct, diffuse, _, unshaded = roof_components(
        dni.astype(f), dhi.astype(f), z, cos_aoi.astype(f), np.ones(n, f), iso, np.zeros((n, 0), f),
        np.zeros((n, 0), f), z, z, iso, sky)
    np.testing.assert_allclose(diffuse, ref["poa_sky_diffuse"], rtol=2e-5, atol=2e-4)
    np.testing.assert_allclose(unshaded - direct, ref["poa_sky_diffuse"], rtol=2e-5, atol=2e-4)
    # in the shade of a building the circumsolar part goes with the sun
    _, shaded, _, _ = roof_components(
        dni.astype(f), dhi.astype(f), z, cos_aoi.astype(f), np.zeros(n, f), iso,
        np.zeros((n, 0), f), np.zeros((n, 0), f), z, z, iso, sky)
    want = np.maximum(ref["poa_isotropic"] + ref["poa_horizon"], 0)
    np.testing.assert_allclose(shaded, want, rtol=2e-5, atol=2e-4)
    assert (ref["poa_circumsolar"] > 50).sum() > 100          # the case has circumsolar light


def test_radiation_table_perez_full_chain_matches_pvlib():
    """Radiation table (its Perez sky per time step) + pass times, no buildings: a level
    roof receives pvlib's Perez plane-of-array irradiance (albedo 0: beam + DHI); a tilted
    one the Perez (1993) sky's luminance on the plane, near pvlib's Perez (1990) model,
    fitted to tilted planes (two models of the same sky: 1.5 % on average, the low sun
    behind a tilted roof up to a fifth apart)."""
    grid = np.arange(pd.Timestamp("2024-06-01", tz="UTC").timestamp(),
                     pd.Timestamp("2024-06-03", tz="UTC").timestamp(), 60.0)
    vals = {c: np.full(len(grid), v) for c, v in zip(COLUMNS, (600, 700, 150, 800, 850, 90))}
    table = RadiationTable.from_grid(grid, vals, 49.61, 6.13, 300.0)
    segs = _segments([0.0, 10.0, 20.0], 0.0, 3.2, [0.0, 90.0, 200.0], [0.0, 0.08, -0.03])
    scene = Scene(box_mesh(np.zeros((0, 6))))
    cfg = _uniform(svf_rays=64, reflection_rays=16, diffuse_model="perez_svf")
    geometry = segment_geometry(scene, segs, cfg)
    # the open roof sees all of the band near the horizon in front of it
    np.testing.assert_allclose(geometry["hbv"], np.sin(np.radians(geometry["tilt_deg"])), rtol=1e-6)
    rng = np.random.default_rng(5)
    p = 300
    t = rng.uniform(grid[10], grid[-10], p)
    t = np.round(t / 60) * 60             # on the grid: no interpolation of the coefficients
    passes = pd.DataFrame({"segment_id": rng.integers(0, 3, p), "t_utc": t})
    out = evaluate_passes(passes, segs, geometry, table, scene, cfg, time_at="start")
    times = pd.to_datetime(t * 1e9, utc=True)
    sp = pvlib.solarposition.get_solarposition(times, 49.61, 6.13, altitude=300.0)
    tilt, az = roof_plane(segs["heading_deg"].to_numpy()[passes["segment_id"]],
                          segs["gradient"].to_numpy()[passes["segment_id"]])
    zen = sp["apparent_zenith"].to_numpy()
    up = zen < 90
    ref = pvlib.irradiance.get_total_irradiance(tilt, az, zen, sp["azimuth"].to_numpy(),
                                                np.where(up, 700, 0), 600, 150, albedo=0.0,
                                                model="perez", dni_extra=pvlib.irradiance.get_extra_radiation(times),
                                                airmass=pvlib.atmosphere.get_relative_airmass(zen))
    # the sky view factor is 64 rays' estimate of (1 + cos tilt) / 2: exact on level roofs
    # (the table's constant DHI at night is the test's, pvlib leaves it out there)
    level = geometry["tilt_deg"].to_numpy()[passes["segment_id"]] == 0
    assert up.sum() > 100 and (level & up).sum() > 30
    got, want = out["total_unshaded"].to_numpy(), ref["poa_global"]
    lv = level & up
    np.testing.assert_allclose(got[lv], want[lv], rtol=2e-3, atol=0.5)   # dawn: 5-min SPA grid
    np.testing.assert_allclose(out["total"][lv], want[lv], rtol=2e-3, atol=0.5)
    np.testing.assert_allclose(out["total"], out["total_unshaded"], rtol=1e-6)   # in the open
    tilted = ~level & up & (want > 50)
    ratio = got[tilted] / want[tilted]
    assert abs(ratio.mean() - 1) < 0.015 and np.abs(ratio - 1).max() < 0.25, ratio


def test_horizon_band_view_of_a_facade_half_hidden():
    """A facade facing east with a tall wall across the north-east half of its view: it
    sees half of the band near the horizon in front of it (the band's light on it is
    symmetric about its normal); an open one sees all of it, a level roof none."""
    from vipvflow.models.view_factors import horizon_band_view, segment_uniforms

    wall = Scene(box_mesh([[5.0, 0.0, -100.0, 6.0, 50_000.0, 500.0]]))
    o = np.array([[0.0, 0.0, 1.0]] * 3)
    nrm = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    uni = segment_uniforms(7, 4, np.arange(3), 2 * 256)
    h = horizon_band_view(wall, o, nrm, uni, 256, 100_000.0)
    assert abs(h[0] - 0.5) < 0.01 and h[2] == 0.0
    open_ = horizon_band_view(Scene(box_mesh(np.zeros((0, 6)))), o, nrm, uni, 256, 300.0)
    assert open_[0] == 1.0 and open_[2] == 0.0


def test_open_street_reflects_like_pvlibs_ground_diffuse():
    """No buildings and no ground in the city model: a tilted roof still sees the street
    it drives on (the level ground 3.2 m below it, road albedo), lit by the full sun and
    sky: ``rho GHI (1 - cos tilt) / 2``, pvlib's ground-reflected irradiance."""
    rng = np.random.default_rng(2)
    n = 40
    tilt_true = rng.uniform(12, 35, n)
    heading = rng.uniform(0, 360, n)
    segs = _segments(rng.uniform(0, 100, n), 0.0, 3.2, heading, np.tan(np.radians(tilt_true)))
    scene = Scene(box_mesh(np.zeros((0, 6))))
    # (rays as long as the street is wide: at 300 m a 20 deg roof loses 8 % of its street,
    # the ground below 0.6 deg of depression, to the open ground beyond the city model)
    cfg = _uniform(svf_rays=64, reflection_rays=1024, reflector_sampling="all",
                        ray_length_m=100_000.0)
    geometry = segment_geometry(scene, segs, cfg, road_albedo=0.12)
    zen, azi = rng.uniform(0, 80, n), rng.uniform(0, 360, n)
    dni, dhi = rng.uniform(0, 900, n), rng.uniform(20, 300, n)
    ghi = dhi + dni * np.cos(np.radians(zen))
    rad = {"dni": dni, "dhi": dhi, "ghi": ghi, "dni_clear": dni, "dhi_clear": dhi, "ghi_clear": ghi}
    out = _kernel(scene, geometry, np.arange(n), zen, azi, rad, cfg, ground_albedo=0.5)
    surf_tilt, _ = roof_plane(heading, np.tan(np.radians(tilt_true)))
    want = pvlib.irradiance.get_ground_diffuse(surf_tilt, ghi, albedo=0.12)
    # the street holds (1 - cos tilt) / 2 of the roof's view, 1-9 %: 11-93 of the 1024
    # stratified rays; the open ground's albedo (0.5) does not enter: every ray that leaves
    # downwards meets the street
    ratio = out["reflected"] / want
    assert np.abs(ratio - 1).max() < 0.3 and abs(ratio.mean() - 1) < 0.04, ratio


def test_reflector_points_sorts_equal_numpys():
    """The reflector groups' stratified points sort their hits in compiled code: the order
    within groups is np.lexsort's (ties keep their order; empty groups; a NaN key falls
    back to np.lexsort), and the first hit reaching each target of a group's cumulative
    weights is the one merging the targets into the hits' order (a target before equal
    hits) finds."""
    from vipvflow.models.view_factors import _first_reaching, _lexsort_groups

    rng = np.random.default_rng(4)
    for n, groups, run in ((5_000, 40, 1), (20_000, 3_000, 2), (3, 10, 1), (0, 4, 1)):
        group = np.sort(rng.integers(0, groups, n)) if run == 1 else rng.integers(0, groups, n)
        key = np.round(rng.normal(size=n), 1)                 # many ties
        key[rng.random(n) < 0.05] = -0.0
        np.testing.assert_array_equal(_lexsort_groups(key, group, groups), np.lexsort((key, group)))
    key = rng.normal(size=300)
    key[[3, 100]] = np.nan
    group = rng.integers(0, 7, 300)
    np.testing.assert_array_equal(_lexsort_groups(key, group, 7), np.lexsort((key, group)))
    # the targets merged into the hits: hits sorted by group, cumulative weights within each
    # (zero weights among them: equal cumulative weights), groups 2 and 5 without hits
    m, P = 8, 5
    gs = np.sort(rng.choice([0, 1, 3, 4, 6, 7], 400))
    w = np.where(rng.random(400) < 0.2, 0.0, rng.random(400))
    cw = pd.Series(w).groupby(gs, sort=False).cumsum().to_numpy()
    total = np.bincount(gs, w, m)
    target = np.sort(rng.random((m, P)), axis=1) * total[:, None]
    target[1, :2] = cw[np.searchsorted(gs, 1) + 3]             # exactly a hit's (a run of equal)
    glo = np.searchsorted(gs, np.arange(m), side="left")
    ghi = np.searchsorted(gs, np.arange(m), side="right") - 1
    q_group = np.repeat(np.arange(m), P)
    order = np.lexsort((np.r_[np.zeros(len(q_group), np.int8), np.ones(len(gs), np.int8)],
                        np.r_[target.reshape(-1), cw], np.r_[q_group, gs]))
    is_hit = order >= len(q_group)
    hits_before = np.cumsum(is_hit) - is_hit
    want = np.empty(len(q_group), np.int64)
    want[order[~is_hit]] = hits_before[~is_hit]
    np.testing.assert_array_equal(_first_reaching(cw, glo, ghi, target), want.reshape(m, P))
