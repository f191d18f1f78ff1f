"""Acceptance: the roof irradiance engine against Radiance (``rtrace -I``) in street canyons.

Each scene is built twice, with the same coordinates: as a vipvflow ``TileMesh`` of triangles
(Embree) and as Radiance polygons with grey Lambertian ``plastic`` (reflectance = albedo, no
specularity, no roughness).  Blocks are boxes (four facades and a flat roof); a 2 km x 2 km
ground plane (the road, surface type ground) at z = 0.

* ``canyon``: two blocks 16 m high, 300 m long (along y, north-south), 20 m deep, either side
  of an 18 m street.  Facades and roofs albedo 0.35, road 0.15.
* ``crossing``: an asymmetric street 14 m wide between blocks of 24 m (north-west), 18 m
  (south-west), 10 m (north-east) and 12 m (south-east), cut by a 16 m cross street
  (east-west) at y = 0.  Facades and roofs albedo 0.30, road 0.12.
* Roof points: horizontal, at bus-roof height 3.2 m, three in the canyon and four around the
  crossing (centre of the crossing, near its corner, inside the streets).  Radiance measures
  at the engine's ray origin (the roof point lifted by ``ray_offset_m``).
* Light: 12 real instants of 2024 in Luxembourg (49.61 N, 6.13 E; one per month, the sun
  from east, south and west, down to 15-17 deg elevation in November and at the winter
  solstice), sun position and clear-sky DNI / DHI from pvlib (Ineichen).  Radiance sun =
  ``light`` source of 0.533 deg whose radiance x solid angle = DNI; sky = a uniform
  ``glow`` hemisphere of radiance DHI / pi and radius 0, i.e. an isotropic sky reached only
  by ambient rays (as a gensky sky), matching the engine's isotropic sky.
* Ground: no ``-ground`` glow below the horizon.  Everything below the horizon is the
  modelled road, lit and shaded by the scene itself.

Radiance's reflected part = (run with the real reflectances) - (same run with every surface
black), ``-ab 8`` (inter-reflection converged).  The engine runs with its default settings
(``IrradianceCfg()``: sky-view-factor diffuse, 512 sky rays, 256 reflection rays (1024 where the
sky view factor is below 0.75), 4 reflector groups and the street, 64 sample points per
reflector (stratified 8 x 8 over its surface), 4 rays per point for the reflectors' own
surroundings) except that
every sample point is traced for each sun (``reflector_sampling: all``: one sun is
compared at a time, while the default ``rotate`` is exact only on average over passes,
tests/test_irradiance.py).

Criteria (issue 16), at every roof point and instant: the engine's total within 8 % of
Radiance and its reflected part within 20 %, for the default seed and for others
(:func:`test_reflected_within_20_percent_for_other_seeds`); the paper's isotropic mode overestimates (it
counts the sky hidden by the facades).  The per-point table is printed by
:func:`test_report_table` (and stored as junit properties).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

pr = pytest.importorskip(
    "pyradiance",
    reason="the Radiance cross-check needs pyradiance (it ships rtrace and oconv): "
           "pip install 'vipvflow[test]'")

import pvlib  # noqa: E402

from vipvflow.config import IrradianceCfg  # noqa: E402
from vipvflow.models.irradiance import roof_irradiance
from vipvflow.models.mesh import SURFACE_CODE, TileMesh  # noqa: E402
from vipvflow.models.shading import Scene  # noqa: E402
from vipvflow.models.view_factors import segment_geometry, sun_vector  # noqa: E402

GROUND_HALF = 1000.0                           # half side of the road plane (m)
ROOF_Z = 3.2                                   # bus roof height (m)
SUN_DEG = 0.533                                # solar disc (deg)
LAT, LON, ALT = 49.61, 6.13, 300.0

#: scene -> blocks (xmin, ymin, xmax, ymax, height; m), facade/roof and road albedo, roof
#: points (x, y; m)
SCENES = {
    "canyon": {"blocks": [(-29, -150, -9, 150, 16), (9, -150, 29, 150, 16)],
               "rho": 0.35, "rho_road": 0.15, "points": [(0, 0), (-4, 50), (5, -80)]},
    "crossing": {"blocks": [(-27, 8, -7, 150, 24), (-27, -150, -7, -8, 18),
                            (7, 8, 27, 150, 10), (7, -150, 27, -8, 12)],
                 "rho": 0.30, "rho_road": 0.12,
                 "points": [(0, 0), (-4, 11), (0, 40), (4, -30)]},
}
#: one instant a month of 2024 (UTC), the sun in the east, south and west
INSTANTS = ["2024-01-21 10:00", "2024-02-21 14:30", "2024-03-20 08:00", "2024-04-21 12:00",
            "2024-05-21 16:00", "2024-06-21 11:30", "2024-07-21 06:30", "2024-08-21 13:00",
            "2024-09-22 15:00", "2024-10-21 09:30", "2024-11-21 13:30", "2024-12-21 11:45"]
SUN_IDS = [t[:10] for t in INSTANTS]

# Radiance: pure Monte Carlo (no ambient cache, no super-sampling), deep enough to converge.
# -lw must stay far below 1 / ad: an ambient ray's weight is about 1 / ad, and with -lw 1e-6
# and -ad 131072 every bounce after the second is culled (the reflected part drops by ~10 %).
RT_COMMON = ["-aa", "0", "-as", "0", "-av", "0", "0", "0", "-lw", "1e-10", "-lr", "16",
             "-dj", "0", "-n", "1"]
RT_ABN = ["-ab", "8", "-ad", "32768"]
# rtrace has no seed option; its run-to-run spread here is below 0.2 W/m2 on every part

CFG_SVF = IrradianceCfg(reflector_sampling="all", diffuse_model="sky_view_factor")

TOL_TOTAL, TOL_REFLECTED = 0.08, 0.20


# ---------------------------------------------------------------------------- the scenes
def _quads(spec):
    """(kind, albedo, 4 corners counter-clockwise seen from outside) of every surface."""
    out = []
    for x0, y0, x1, y1, h in spec["blocks"]:
        out += [("wall", [(x0, y0, 0), (x1, y0, 0), (x1, y0, h), (x0, y0, h)]),      # south
                ("wall", [(x1, y0, 0), (x1, y1, 0), (x1, y1, h), (x1, y0, h)]),      # east
                ("wall", [(x1, y1, 0), (x0, y1, 0), (x0, y1, h), (x1, y1, h)]),      # north
                ("wall", [(x0, y1, 0), (x0, y0, 0), (x0, y0, h), (x0, y1, h)]),      # west
                ("roof", [(x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h)])]
    g = GROUND_HALF
    out.append(("ground", [(-g, -g, 0), (g, -g, 0), (g, g, 0), (-g, g, 0)]))
    albedo = {"wall": spec["rho"], "roof": spec["rho"], "ground": spec["rho_road"]}
    return [(kind, albedo[kind], np.asarray(c, float)) for kind, c in out]


def _tile_mesh(spec) -> TileMesh:
    quads = _quads(spec)
    tris = np.concatenate([c[[[0, 1, 2], [0, 2, 3]]] for _, _, c in quads])
    mesh = TileMesh.from_triangles(tris, albedo=np.repeat([a for _, a, _ in quads], 2),
                                   name="canyon")
    mesh.surface_type[:] = np.repeat([SURFACE_CODE[k] for k, _, _ in quads], 2)
    return mesh


def _canyon_surfaces(spec, black: bool) -> list[str]:
    """The canyon's materials (grey plastic of its albedos; *black*: all 0) and its quads, as
    Radiance scene lines."""
    lines = []
    for kind, rho in (("wall", spec["rho"]), ("roof", spec["rho"]), ("ground", spec["rho_road"])):
        r = 0.0 if black else rho
        lines.append(f"void plastic m_{kind} 0 0 5 {r:.6g} {r:.6g} {r:.6g} 0 0")
    for i, (kind, _, c) in enumerate(_quads(spec)):
        coords = " ".join(f"{v:.9g}" for v in c.ravel())
        lines.append(f"m_{kind} polygon {kind}_{i} 0 0 12 {coords}")
    return lines


def _radiance_scene(spec, sun: np.ndarray, dni: float, dhi: float, black: bool) -> str:
    """Radiance description of a scene, its sun and its uniform sky."""
    omega = 2 * math.pi * (1 - math.cos(math.radians(SUN_DEG / 2)))
    l_sun, l_sky = dni / omega, dhi / math.pi
    lines = [f"void light solar 0 0 3 {l_sun:.9g} {l_sun:.9g} {l_sun:.9g}",
             "solar source sun 0 0 4 {:.12f} {:.12f} {:.12f} {}".format(*sun, SUN_DEG),
             f"void glow sky_glow 0 0 4 {l_sky:.9g} {l_sky:.9g} {l_sky:.9g} 0",
             "sky_glow source sky 0 0 4 0 0 1 180"]
    lines += _canyon_surfaces(spec, black)
    return "\n".join(lines) + "\n"


def _rtrace_irradiance(workdir: Path, tag: str, scene_text: str, points, ambient=None) -> np.ndarray:
    """Irradiance (W/m2) on upward-facing sensors at *points*, from ``rtrace -I``
    (*ambient*: the ``-ab``/``-ad`` options, default :data:`RT_ABN`)."""
    rad = workdir / f"{tag}.rad"
    rad.write_text(scene_text)
    octree = workdir / f"{tag}.oct"
    octree.write_bytes(pr.oconv(str(rad)))
    rays = "".join("{:.9f} {:.9f} {:.9f} 0 0 1\n".format(*p) for p in points).encode()
    out = pr.rtrace(rays, octree, header=False, irradiance=True, params=RT_COMMON + (ambient or RT_ABN))
    rgb = np.array(out.split(), float).reshape(len(points), 3)
    assert np.ptp(rgb, axis=1).max() < 1e-6 * max(1.0, rgb.max()), out      # grey
    return rgb.mean(1)


def _sky():
    """Sun vectors, elevations (deg) and clear-sky DNI, DHI, GHI (W/m2) of the instants."""
    loc = pvlib.location.Location(LAT, LON, altitude=ALT)
    times = pd.DatetimeIndex(INSTANTS, tz="UTC")
    sp = loc.get_solarposition(times)
    cs = loc.get_clearsky(times)
    el = sp["apparent_elevation"].to_numpy()
    return (sun_vector(90.0 - el, sp["azimuth"].to_numpy()), el, cs["dni"].to_numpy(),
            cs["dhi"].to_numpy(), cs["ghi"].to_numpy())


# ---------------------------------------------------------------------------- both runs
def _engine(name: str, cfg: IrradianceCfg):
    """The engine's geometry of a scene's roof points and its components at every instant
    (arrays of instant x point, the point fastest), for the sky-view-factor *cfg* and the
    paper's isotropic diffuse."""
    spec = SCENES[name]
    scene = Scene(_tile_mesh(spec))
    pts = np.asarray(spec["points"], float)
    k = len(pts)
    segs = pd.DataFrame({"segment_id": np.arange(k), "x": pts[:, 0], "y": pts[:, 1],
                         "z": np.full(k, ROOF_Z), "heading_deg": np.zeros(k),
                         "gradient": np.zeros(k)})
    geo = segment_geometry(scene, segs, cfg)
    sun, _, dni, dhi, ghi = _sky()
    f = np.float32
    rows = np.tile(np.arange(k), len(INSTANTS))
    rep = lambda v: np.repeat(np.asarray(v, f), k)             # noqa: E731
    rad = {"dni": rep(dni), "dhi": rep(dhi), "ghi": rep(ghi), "dni_clear": rep(dni),
           "dhi_clear": rep(dhi), "ghi_clear": rep(ghi)}
    sun_rows = np.repeat(sun.astype(f), k, axis=0)
    svf = roof_irradiance(geo, rows, sun_rows, rad, scene, cfg, ground_albedo=spec["rho_road"])
    paper = roof_irradiance(geo, rows, sun_rows, rad, scene,
                            cfg.model_copy(update={"diffuse_model": "isotropic"}),
                            ground_albedo=spec["rho_road"])
    return geo, svf, paper


def _run(name: str, work: Path) -> pd.DataFrame:
    spec = SCENES[name]
    k = len(spec["points"])
    n = len(INSTANTS)
    sun, el, dni, dhi, _ = _sky()
    geo, svf, paper = _engine(name, CFG_SVF)
    origin = geo[["px", "py", "pz"]].to_numpy(float)
    recs = []
    for i in range(n):
        s = sun[i] / np.linalg.norm(sun[i])
        grey, black = (_rtrace_irradiance(work, f"{name}_s{i}_{tag}",
                                          _radiance_scene(spec, s, dni[i], dhi[i], tag == "black"),
                                          origin) for tag in ("grey", "black"))
        for j in range(k):
            q = i * k + j
            recs.append({
                "scene": name, "sun": SUN_IDS[i], "point": j, "elevation": el[i],
                "dni": dni[i], "dhi": dhi[i], "svf": float(geo["svf"].iloc[j]),
                "sun_visible": bool(svf["sun_visible"][q]),
                "eng_direct": float(svf["direct"][q]), "eng_diffuse": float(svf["diffuse"][q]),
                "eng_reflected": float(svf["reflected"][q]), "eng_total": float(svf["total"][q]),
                "paper_total": float(paper["total"][q]),
                "rad_total": grey[j], "rad_black": black[j], "rad_reflected": grey[j] - black[j]})
    return pd.DataFrame(recs)


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> pd.DataFrame:
    work = tmp_path_factory.mktemp("radiance")
    df = pd.concat([_run(name, work) for name in SCENES], ignore_index=True)
    df["total_ratio"] = df["eng_total"] / df["rad_total"]
    df["reflected_ratio"] = df["eng_reflected"] / df["rad_reflected"]
    df["paper_ratio"] = df["paper_total"] / df["rad_total"]
    return df


# ---------------------------------------------------------------------------- tests
CASES = [(name, sun) for name in SCENES for sun in SUN_IDS]
CASE_IDS = [f"{name}-{sun}" for name, sun in CASES]


def _case(results, name, sun):
    return results[(results["scene"] == name) & (results["sun"] == sun)]


def test_report_table(results, record_property, capsys):
    cols = ["elevation", "svf", "sun_visible", "eng_total", "rad_total", "total_ratio",
            "eng_reflected", "rad_reflected", "reflected_ratio", "paper_ratio"]
    table = results.set_index(["scene", "sun", "point"])[cols].round(3).to_string()
    worst = {c: float((results[c] - 1).abs().max()) for c in ("total_ratio", "reflected_ratio")}
    summary = (f"worst |ratio - 1|: total {worst['total_ratio']:.3f}, reflected "
               f"{worst['reflected_ratio']:.3f}; mean |ratio - 1|: total "
               f"{(results['total_ratio'] - 1).abs().mean():.3f}, reflected "
               f"{(results['reflected_ratio'] - 1).abs().mean():.3f}; paper mode mean "
               f"x{results['paper_ratio'].mean():.3f}")
    record_property("radiance_summary", summary)
    with capsys.disabled():
        print(f"\nRadiance cross-check ({' '.join(RT_ABN)}), engine defaults:\n{table}\n{summary}")
    shaded = results[~results["sun_visible"]]
    assert len(results) == 12 * 7 and len(shaded) >= 12 and (results["sun_visible"]).sum() >= 12


def test_radiance_scenes_are_calibrated(results):
    """Black scenes: Radiance gives DNI sin(el) where the sun reaches the roof, plus DHI x the
    sky view factor (the engine's, 128 stratified rays: within 3 %); the engine's direct
    part is exactly the beam on the roof."""
    sky = results["dhi"] * results["svf"]
    dark = results[~results["sun_visible"]]
    np.testing.assert_allclose(dark["rad_black"], sky[dark.index], rtol=0.03)
    lit = results[results["sun_visible"]]
    beam = lit["dni"] * np.sin(np.radians(lit["elevation"]))
    np.testing.assert_allclose(lit["rad_black"], beam + sky[lit.index], rtol=0.01)
    np.testing.assert_allclose(lit["eng_direct"], beam, rtol=2e-3)


@pytest.mark.parametrize("name,sun", CASES, ids=CASE_IDS)
def test_total_within_8_percent_at_every_point(results, name, sun):
    r = _case(results, name, sun)
    bad = r[(r["total_ratio"] - 1).abs() > TOL_TOTAL]
    assert bad.empty, "engine total vs Radiance (W/m2):\n" + bad[
        ["point", "eng_total", "rad_total", "eng_reflected", "rad_reflected"]].to_string()


@pytest.mark.parametrize("name,sun", CASES, ids=CASE_IDS)
def test_reflected_within_20_percent_at_every_point(results, name, sun):
    r = _case(results, name, sun)
    bad = r[(r["reflected_ratio"] - 1).abs() > TOL_REFLECTED]
    assert bad.empty, "engine reflected vs Radiance (W/m2):\n" + bad[
        ["point", "eng_reflected", "rad_reflected"]].to_string()


def test_paper_mode_overestimates(results):
    """The paper's isotropic diffuse counts the sky hidden by the facades: above the
    sky-view-factor mode by exactly DHI (1 - SVF), and above Radiance wherever the hidden
    sky outweighs the engine's error (SVF below 0.8)."""
    np.testing.assert_allclose(results["paper_total"] - results["eng_total"],
                               results["dhi"] * (1 - results["svf"]), rtol=1e-3, atol=1e-3)
    street = results[results["svf"] < 0.8]
    assert len(street) >= 24 and (street["paper_total"] > street["rad_total"]).all()


@pytest.mark.parametrize("seed", [1, 2, 3, 4, 5, 6])
def test_reflected_within_20_percent_for_other_seeds(results, seed):
    """The bounds are no luck of the default seed: the same scenes under other seeds (other
    rays and sample points for every segment) stay within them at every point."""
    cfg = CFG_SVF.model_copy(update={"seed": seed})
    for name in SCENES:
        _, svf, _ = _engine(name, cfg)
        r = results[results["scene"] == name]
        reflected = svf["reflected"] / r["rad_reflected"].to_numpy() - 1
        total = svf["total"] / r["rad_total"].to_numpy() - 1
        bad = r.assign(reflected=reflected, total=total)[
            (np.abs(reflected) > TOL_REFLECTED) | (np.abs(total) > TOL_TOTAL)]
        assert bad.empty, f"seed {seed}, engine / Radiance - 1:\n" + bad[
            ["sun", "point", "reflected", "total"]].to_string()


# ---------------------------------------------------------------------------- Perez sky
# Issue 36: the same scenes under Radiance's Perez all-weather sky (``gendaylit -W DNI DHI``,
# solar radiance) against the engine's ``perez_svf`` diffuse model (its defaults, every
# reflector sample point traced).  The instants' DNI / DHI are the clear sky's scaled to a
# range of skies (clear, hazy, thin overcast), so circumsolar and horizon parts vary.
CFG_PEREZ = IrradianceCfg(reflector_sampling="all", diffuse_model="perez_svf")
#: per instant: factors on the clear-sky DNI and DHI (a clear, a hazy and a thin-overcast sky)
SKY_MIX = [(1.0, 1.0), (0.6, 2.0), (0.25, 2.6)]
TOL_PEREZ_MEAN, TOL_PEREZ_WORST, TOL_PEREZ_SHADE, TOL_PEREZ_REFL_SUM = 0.05, 0.15, 0.10, 0.05


def gendaylit_sky(sun: np.ndarray, dni: float, dhi: float, ground_albedo: float) -> str:
    """Radiance's Perez all-weather sky for a sun vector (east, north, up) and DNI / DHI
    (W/m2): ``gendaylit -ang ALT AZ -W DNI DHI -O 1 -g RHO`` (solar radiance; the azimuth
    in degrees west of south), its sky glow over the upper hemisphere (below it the
    scene's own ground)."""
    alt = math.degrees(math.asin(float(sun[2])))
    az_north = math.degrees(math.atan2(float(sun[0]), float(sun[1])))
    text = pr.gendaylit(altitude=alt, azimuth=az_north - 180.0, dirnorm=float(dni),
                        diffhor=float(dhi), solar=True, grefl=float(ground_albedo),
                        silent=True).decode()
    return text + "\nskyfunc glow sky_glow 0 0 4 1 1 1 0\nsky_glow source sky 0 0 4 0 0 1 180\n"


def _perez_scene(spec, sun, dni, dhi, black: bool) -> str:
    lines = [gendaylit_sky(sun, dni, dhi, spec["rho_road"])]
    lines += _canyon_surfaces(spec, black)
    return "\n".join(lines) + "\n"


def perez_radiation(times, dni, dhi, ghi, sun, geo=None) -> dict:
    """The engine's radiation of a set of instants with the Perez coefficients
    (:func:`vipvflow.models.sky.perez_coefficients`, pvlib's extraterrestrial irradiance
    and airmass), float32, all-sky = clear-sky; with the segments' geometry *geo* per
    (instant, segment), instant-major, with the Perez (1993) sky's share of each, as
    :meth:`RadiationTable.sky_share` gives it (:func:`vipvflow.models.sky.sky_table`)."""
    from vipvflow.models.sky import open_share, open_terms, perez_coefficients, sky_share, sky_table
    from vipvflow.models.view_factors import SKY_COLUMNS

    zen = np.degrees(np.arccos(np.clip(sun[:, 2], -1, 1)))
    e0 = pvlib.irradiance.get_extra_radiation(pd.DatetimeIndex(times).day_of_year.to_numpy())
    f1, f2 = perez_coefficients(dhi, dni, e0, zen, pvlib.atmosphere.get_relative_airmass(zen))
    f = np.float32
    out = {"dni": dni, "dhi": dhi, "ghi": ghi, "f1": f1, "f2": f2}
    if geo is not None:
        tg, th = sky_table(dhi, dni, e0, sun)
        k = len(geo)
        levels = np.tile(geo[SKY_COLUMNS].to_numpy(np.float32), (len(dhi), 1))
        normal = np.tile(geo[["nx", "ny", "nz"]].to_numpy(np.float32), (len(dhi), 1))
        out = {c: np.repeat(v, k) for c, v in out.items()}
        tg, th = np.repeat(tg, k, axis=0), np.repeat(th, k, axis=0)
        out["sky_share"] = sky_share(tg, th, levels, normal)
        out["sky_open"] = open_share(open_terms(th), normal)
    out.update({f"{c}_clear": v for c, v in list(out.items())})
    return {c: np.asarray(v, f) for c, v in out.items()}


def _perez_sky():
    """Sun vectors, elevations and the instants' DNI, DHI, GHI under :data:`SKY_MIX`
    (instant ``i`` takes the mix ``i mod 3``)."""
    sun, el, dni, dhi, _ = _sky()
    k = np.arange(len(INSTANTS)) % len(SKY_MIX)
    a = np.array([SKY_MIX[j][0] for j in k])
    b = np.array([SKY_MIX[j][1] for j in k])
    dni, dhi = dni * a, dhi * b
    return sun, el, dni, dhi, dhi + dni * sun[:, 2]


def _perez_run(name: str, work: Path) -> pd.DataFrame:
    spec = SCENES[name]
    scene = Scene(_tile_mesh(spec))
    pts = np.asarray(spec["points"], float)
    k, n = len(pts), len(INSTANTS)
    segs = pd.DataFrame({"segment_id": np.arange(k), "x": pts[:, 0], "y": pts[:, 1],
                         "z": np.full(k, ROOF_Z), "heading_deg": np.zeros(k), "gradient": np.zeros(k)})
    geo = segment_geometry(scene, segs, CFG_PEREZ, road_albedo=spec["rho_road"])
    sun, el, dni, dhi, ghi = _perez_sky()
    rad = perez_radiation(INSTANTS, dni, dhi, ghi, sun, geo)
    rows = np.tile(np.arange(k), n)
    eng = roof_irradiance(geo, rows, np.repeat(sun.astype(np.float32), k, axis=0), rad, scene,
                          CFG_PEREZ, ground_albedo=spec["rho_road"])
    origin = geo[["px", "py", "pz"]].to_numpy(float)
    recs = []
    for i in range(n):
        s = sun[i] / np.linalg.norm(sun[i])
        grey, black = (_rtrace_irradiance(work, f"perez_{name}_s{i}_{tag}",
                                          _perez_scene(spec, s, dni[i], dhi[i], tag == "black"), origin)
                       for tag in ("grey", "black"))
        for j in range(k):
            q = i * k + j
            recs.append({"scene": name, "sun": SUN_IDS[i], "point": j, "elevation": el[i],
                         "dni": dni[i], "dhi": dhi[i], "f1": float(rad["f1"][i * k]),
                         "svf": float(geo["svf"].iloc[j]), "sun_visible": bool(eng["sun_visible"][q]),
                         "eng_direct": float(eng["direct"][q]), "eng_diffuse": float(eng["diffuse"][q]),
                         "eng_reflected": float(eng["reflected"][q]), "eng_total": float(eng["total"][q]),
                         "rad_total": grey[j], "rad_black": black[j],
                         "rad_reflected": grey[j] - black[j]})
    return pd.DataFrame(recs)


def perez_summary(df: pd.DataFrame) -> dict:
    """The issue-36 figures of a comparison table (columns of :func:`_perez_run`)."""
    total = df["eng_total"] / df["rad_total"] - 1
    shade = df[~df["sun_visible"]]
    diffuse = shade["eng_diffuse"] / shade["rad_black"] - 1
    return {"n": len(df), "total_mean_abs": float(total.abs().mean()),
            "total_worst": float(total.abs().max()), "n_shade": len(shade),
            "shade_diffuse_worst": float(diffuse.abs().max()) if len(shade) else 0.0,
            "shade_diffuse_mean": float(diffuse.mean()) if len(shade) else 0.0,
            "reflected_sum_bias": float(df["eng_reflected"].sum() / df["rad_reflected"].sum() - 1)}


@pytest.fixture(scope="module")
def perez_results(tmp_path_factory) -> pd.DataFrame:
    work = tmp_path_factory.mktemp("radiance_perez")
    df = pd.concat([_perez_run(name, work) for name in SCENES], ignore_index=True)
    df["total_ratio"] = df["eng_total"] / df["rad_total"]
    df["shade_diffuse_ratio"] = np.where(df["sun_visible"], np.nan, df["eng_diffuse"] / df["rad_black"])
    return df


def test_perez_report_table(perez_results, record_property, capsys):
    cols = ["elevation", "dni", "dhi", "f1", "svf", "sun_visible", "eng_total", "rad_total",
            "total_ratio", "shade_diffuse_ratio", "eng_reflected", "rad_reflected"]
    table = perez_results.set_index(["scene", "sun", "point"])[cols].round(3).to_string()
    summary = perez_summary(perez_results)
    record_property("radiance_perez_summary", json_line(summary))
    with capsys.disabled():
        print(f"\nRadiance gendaylit Perez sky ({' '.join(RT_ABN)}), engine perez_svf:\n{table}\n"
              f"{json_line(summary)}")
    assert summary["n_shade"] >= 12 and perez_results["sun_visible"].sum() >= 12


def json_line(d: dict) -> str:
    return ", ".join(f"{k} {v:.4f}" if isinstance(v, float) else f"{k} {v}" for k, v in d.items())


def test_perez_black_open_sky_is_calibrated(tmp_path):
    """An open horizontal sensor under the gendaylit sky (black ground): Radiance gives
    DNI sin(el) + DHI within 1.5 % (the sky's normalisation; the sky below 10 deg blends
    into the ground's brightness in perezlum.cal)."""
    sun, el, dni, dhi, ghi = _perez_sky()
    for i in range(0, len(INSTANTS), 3):
        text = gendaylit_sky(sun[i] / np.linalg.norm(sun[i]), dni[i], dhi[i], 0.0)
        got = _rtrace_irradiance(tmp_path, f"open{i}", text, [(0.0, 0.0, 1.0)])[0]
        assert got == pytest.approx(ghi[i], rel=0.015), (INSTANTS[i], got, ghi[i])


def test_perez_total_within_5_percent_mean_15_worst(perez_results):
    s = perez_summary(perez_results)
    assert s["total_mean_abs"] < TOL_PEREZ_MEAN and s["total_worst"] < TOL_PEREZ_WORST, s


def test_perez_diffuse_within_10_percent_in_the_shade(perez_results):
    s = perez_summary(perez_results)
    assert s["shade_diffuse_worst"] < TOL_PEREZ_SHADE, s


def test_perez_svf_is_nearer_radiance_than_the_uniform_sky_view(perez_results):
    """Under Radiance's Perez sky the anisotropic model is nearer Radiance than DHI x SVF
    (which counts the circumsolar sky behind the buildings as seen): in the shade its
    diffuse error is smaller on average and at most points, and its total error too."""
    df = perez_results
    shade = df[~df["sun_visible"]]
    svf_diffuse = shade["dhi"] * shade["svf"]
    err_perez = (shade["eng_diffuse"] / shade["rad_black"] - 1).abs()
    err_svf = (svf_diffuse / shade["rad_black"] - 1).abs()
    assert err_perez.mean() < 0.5 * err_svf.mean() and (err_perez < err_svf).mean() > 0.6
    svf_total = df["eng_total"] - df["eng_diffuse"] + df["dhi"] * df["svf"]
    assert ((df["eng_total"] / df["rad_total"] - 1).abs().mean()
            < (svf_total / df["rad_total"] - 1).abs().mean())


def test_perez_reflected_bias_within_5_percent(perez_results):
    s = perez_summary(perez_results)
    assert abs(s["reflected_sum_bias"]) < TOL_PEREZ_REFL_SUM, s
