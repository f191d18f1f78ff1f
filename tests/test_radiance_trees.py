"""Acceptance (issue 36, trees): a street canyon with a row of tree crowns, the engine against
Radiance (``rtrace -I``) with the same crowns, leaf-on and leaf-off.

The scene is :data:`test_radiance.SCENES`'s symmetric canyon (blocks 16 m high either side of
an 18 m street along y, facades and roofs albedo 0.35, the road 0.15 in the mesh) with a row
of eleven crowns along its east pavement: spheres of 7 m diameter, crown base 4.5 m, top 11.5
m, every 12 m from y = -60 to 60 m at x = 5 m (0.5 m from the facade).  Spheres, because
Radiance has them exactly (``sphere``); the engine's crowns are spheroids, which a sphere is.
In Radiance each crown's surface is ``trans`` with all its transmission specular and no
reflection (``0 0 7 t t t 0 0 1 1``, ``t = sqrt(tau)``): a ray through a crown crosses its
surface twice and keeps ``tau`` of its light, shadow rays to the sun and ambient rays to the
sky alike, as the engine's crowns (which reflect nothing either).

The sky: Radiance's Perez sky (``gendaylit -W``) against the engine's default
``perez_svf``, and a uniform sky (a glow of radiance DHI / pi) against ``sky_view_factor``.

Roof points at 3.2 m (+ the engine's ray offset): under a crown's middle (5, 0) and under its
side (2.5, 0), in the gap between two crowns (5, 6), in the street's middle (0, 6) and beside
the row in the west lane (-4.5, 0).  Eight instants of 2024 in Luxembourg: four in the trees'
leaf-on months (June, May, July, August; tau 0.20) and four in their leaf-off months (March,
December, April, February; tau 0.60), the engine taking the class of the instant's month; the sun
from the east, south and west, 17 to 64 deg high; the clear sky's DNI / DHI on two of them,
hazy and thin-overcast skies (the clear sky's DNI and DHI scaled) on the others.

The engine runs as a run does: the instants' radiation in a radiation table
(:meth:`RadiationTable.from_grid`), :func:`evaluate_passes` with the fused kernel at its
defaults, every reflector sample point traced (``reflector_sampling: all``, one sun at a
time).  Radiance gives the direct part (the sun alone, black surfaces, ``-ab
0``), the direct and sky part (black surfaces) and the total (the real reflectances), ``-ab 8
-ad 16384``.  Criterion: at every point-instant the engine's direct part within 10 % of
Radiance's (or within 2 % of the unobstructed beam where Radiance's is below that: the
buildings' shade), its total within 10 %.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

pr = pytest.importorskip("pyradiance", reason="the Radiance cross-check needs pyradiance")

import pvlib  # noqa: E402

from vipvflow.config import IrradianceCfg  # noqa: E402
from vipvflow.models.params import TreeCfg  # noqa: E402
from vipvflow.models.trees import TreeTable  # noqa: E402

from test_radiance import (LAT, LON, ALT, ROOF_Z, SCENES, _canyon_surfaces,  # noqa: E402
                           _rtrace_irradiance, _tile_mesh, gendaylit_sky, json_line)

CROWN_D, CROWN_BASE, HEIGHT, ROW_X = 7.0, 4.5, 11.5, 5.0
ROW_Y = np.arange(-60.0, 61.0, 12.0)
POINTS = [(5.0, 0.0), (2.5, 0.0), (5.0, 6.0), (0.0, 6.0), (-4.5, 0.0)]
POINT_NAMES = ["under crown", "under crown side", "gap in the row", "street middle", "beside the row"]
#: (UTC instant, DNI factor, DHI factor on the clear sky)
INSTANTS = [("2024-06-21 11:30", 1.0, 1.0), ("2024-05-21 14:00", 0.6, 2.0),
            ("2024-07-21 09:45", 0.8, 1.5), ("2024-08-21 16:00", 0.25, 2.6),
            ("2024-03-20 12:00", 1.0, 1.0), ("2024-12-21 11:45", 0.6, 2.0),
            ("2024-04-10 09:30", 0.8, 1.5), ("2024-02-21 14:30", 0.25, 2.6)]
TREES = TreeCfg(transmittance_leaf_on=0.20, transmittance_leaf_off=0.60)
#: Radiance's sky and the engine's diffuse model: the Perez sky (gendaylit, perez_svf: the
#: default) and a uniform sky (a glow of radiance DHI / pi, sky_view_factor)
SKIES = {"perez": IrradianceCfg(reflector_sampling="all", trees=TREES),
         "uniform": IrradianceCfg(reflector_sampling="all", trees=TREES,
                                  diffuse_model="sky_view_factor")}
RT_TREES = ["-ab", "8", "-ad", "16384"]
TOL_DIRECT, TOL_DIRECT_FLOOR, TOL_TOTAL = 0.10, 0.02, 0.10


def tree_row() -> TreeTable:
    n = len(ROW_Y)
    return TreeTable(x=np.full(n, ROW_X), y=ROW_Y, z=np.zeros(n), height=np.full(n, HEIGHT),
                     crown_diameter=np.full(n, CROWN_D), crown_base=np.full(n, CROWN_BASE),
                     leaf_type=np.zeros(n), leaf_off=np.full(n, -1), source=np.full(n, 2),
                     tree_id=[f"t{i}" for i in range(n)], latitude=LAT)


def _radiance_scene(spec, sky_text: str, tau: float | None, black: bool) -> str:
    """The canyon and its crowns (transmittance *tau*; None: no crowns) under *sky_text*."""
    lines = [sky_text]
    lines += _canyon_surfaces(spec, black)
    if tau is not None:
        t = math.sqrt(tau)
        lines.append(f"void trans m_crown 0 0 7 {t:.9g} {t:.9g} {t:.9g} 0 0 1 1")
        zc, r = CROWN_BASE + CROWN_D / 2, CROWN_D / 2
        for i, y in enumerate(ROW_Y):
            lines.append(f"m_crown sphere crown_{i} 0 0 4 {ROW_X} {y} {zc} {r}")
    return "\n".join(lines) + "\n"


def _sun_only(sun, dni: float) -> str:
    """The sun of gendaylit's description alone: a 0.533 deg disc of radiance DNI / omega."""
    omega = 2 * math.pi * (1 - math.cos(math.radians(0.533 / 2)))
    s = dni / omega
    return (f"void light solar 0 0 3 {s:.9g} {s:.9g} {s:.9g}\n"
            "solar source sun 0 0 4 {:.12f} {:.12f} {:.12f} 0.533\n".format(*sun))


def _table(times, dni, dhi):
    """A year of minutes of 2024, the instants' DNI / DHI (and GHI) over the minutes around
    each, 0 elsewhere (all-sky = clear-sky)."""
    from vipvflow.models.sun_sky import RadiationTable

    t0 = pd.Timestamp("2024-01-01", tz="UTC").timestamp()
    grid = t0 + 60.0 * np.arange(366 * 1440)
    loc = pvlib.location.Location(LAT, LON, altitude=ALT)
    el = loc.get_solarposition(times)["apparent_elevation"].to_numpy()
    vals = {c: np.zeros(len(grid)) for c in ("ghi", "dni", "dhi", "ghi_clear", "dni_clear", "dhi_clear")}
    for i, t in enumerate(times):
        k = int((t.timestamp() - t0) // 60)
        for sfx in ("", "_clear"):
            vals["dni" + sfx][k - 5:k + 6] = dni[i]
            vals["dhi" + sfx][k - 5:k + 6] = dhi[i]
            vals["ghi" + sfx][k - 5:k + 6] = dhi[i] + dni[i] * np.sin(np.radians(el[i]))
    return RadiationTable.from_grid(grid, vals, LAT, LON, ALT)


def _uniform_sky(sun, dni: float, dhi: float) -> str:
    """The sun and a uniform sky glow of radiance DHI / pi (reached by ambient rays only)."""
    return (_sun_only(sun, dni) + f"void glow sky_glow 0 0 4 {dhi / math.pi:.9g} {dhi / math.pi:.9g} "
            f"{dhi / math.pi:.9g} 0\nsky_glow source sky 0 0 4 0 0 1 180\n")


@pytest.fixture(scope="module", params=list(SKIES))
def tree_results(request, tmp_path_factory) -> pd.DataFrame:
    from vipvflow.models.irradiance import evaluate_passes
    from vipvflow.models.shading import Scene
    from vipvflow.models.view_factors import segment_geometry

    sky_name, CFG = request.param, SKIES[request.param]
    work = tmp_path_factory.mktemp(f"radiance_trees_{sky_name}")
    spec = SCENES["canyon"]
    scene = Scene(_tile_mesh(spec), trees=tree_row())
    pts = np.asarray(POINTS, float)
    k = len(pts)
    segs = pd.DataFrame({"segment_id": np.arange(k), "x": pts[:, 0], "y": pts[:, 1],
                         "z": np.full(k, ROOF_Z), "heading_deg": np.zeros(k), "gradient": np.zeros(k)})
    geo = segment_geometry(scene, segs, CFG, road_albedo=spec["rho_road"])
    times = pd.DatetimeIndex([t for t, _, _ in INSTANTS], tz="UTC")
    cs = pvlib.location.Location(LAT, LON, altitude=ALT).get_clearsky(times)
    dni = cs["dni"].to_numpy() * [a for _, a, _ in INSTANTS]
    dhi = cs["dhi"].to_numpy() * [b for _, _, b in INSTANTS]
    table = _table(times, dni, dhi)
    t_s = np.array([when.timestamp() for when in times])
    t = np.repeat(t_s, k)
    passes = pd.DataFrame({"segment_id": np.tile(np.arange(k), len(times)), "t_utc": t})
    eng = evaluate_passes(passes, None, geo, table, scene, CFG, ground_albedo=spec["rho_road"],
                          time_at="start")
    look = table.lookup(t_s)
    origin = geo[["px", "py", "pz"]].to_numpy(float)
    crowns = scene.crowns(CFG)
    recs = []
    for i, when in enumerate(times):
        sun = np.array([look["sun_x"][i], look["sun_y"][i], look["sun_z"][i]], float)
        sun /= np.linalg.norm(sun)
        cls = crowns.class_of_month[when.month - 1]
        tau = float(crowns.tau[0, cls])
        if sky_name == "perez":
            sky = gendaylit_sky(sun, float(look["dni"][i]), float(look["dhi"][i]), spec["rho_road"])
        else:
            sky = _uniform_sky(sun, float(look["dni"][i]), float(look["dhi"][i]))
        direct = _rtrace_irradiance(work, f"d{i}", _radiance_scene(spec, _sun_only(sun, float(look["dni"][i])),
                                                                   tau, True), origin, ["-ab", "0"])
        black, grey = (_rtrace_irradiance(work, f"{tag}{i}", _radiance_scene(spec, sky, tau, tag == "b"),
                                          origin, RT_TREES) for tag in ("b", "g"))
        for j in range(k):
            q = i * k + j
            recs.append({"sky": sky_name, "sun": when.strftime("%m-%d %H:%M"), "leaf": "off" if tau > 0.4 else "on",
                         "point": POINT_NAMES[j], "elevation": float(90 - np.degrees(np.arccos(sun[2]))),
                         "beam": float(look["dni"][i]) * sun[2],
                         "eng_direct": float(eng["direct"].iloc[q]),
                         "eng_direct_no_trees": float(eng["direct_no_trees"].iloc[q]),
                         "eng_diffuse": float(eng["diffuse"].iloc[q]),
                         "eng_reflected": float(eng["reflected"].iloc[q]),
                         "eng_total": float(eng["total"].iloc[q]),
                         "rad_direct": direct[j], "rad_diffuse": black[j] - direct[j],
                         "rad_reflected": grey[j] - black[j], "rad_total": grey[j]})
    df = pd.DataFrame(recs)
    df["direct_err"] = np.where(df["rad_direct"] > TOL_DIRECT_FLOOR * df["beam"],
                                df["eng_direct"] / df["rad_direct"].clip(lower=1e-9) - 1,
                                (df["eng_direct"] - df["rad_direct"]) / df["beam"])
    df["total_err"] = df["eng_total"] / df["rad_total"] - 1
    df["diffuse_err"] = df["eng_diffuse"] / df["rad_diffuse"] - 1
    return df


def test_tree_report_table(tree_results, record_property, capsys):
    df = tree_results
    cols = ["elevation", "eng_direct", "rad_direct", "direct_err", "eng_diffuse", "rad_diffuse",
            "diffuse_err", "eng_reflected", "rad_reflected", "eng_total", "rad_total", "total_err"]
    table = df.set_index(["sky", "leaf", "sun", "point"])[cols].round(3).to_string()
    summary = {f"{leaf}_{c}_worst": float(df.loc[df["leaf"] == leaf, c].abs().max())
               for leaf in ("on", "off") for c in ("direct_err", "total_err")}
    summary.update({f"{leaf}_total_mean_abs": float(df.loc[df["leaf"] == leaf, "total_err"].abs().mean())
                    for leaf in ("on", "off")})
    summary["diffuse_mean_abs"] = float(df["diffuse_err"].abs().mean())
    record_property(f"radiance_trees_summary_{df['sky'].iloc[0]}", json_line(summary))
    with capsys.disabled():
        print(f"\nRadiance, canyon with a row of crowns ({' '.join(RT_TREES)}), {df['sky'].iloc[0]} "
              f"sky, engine {SKIES[df['sky'].iloc[0]].diffuse_model}:\n{table}\n{json_line(summary)}")
    # the case has it all: crowns that shade the sun (leaf-on and off), free sun, buildings' shade
    crossed = df["eng_direct"] < 0.9 * df["eng_direct_no_trees"]
    assert crossed[df["leaf"] == "on"].any() and crossed[df["leaf"] == "off"].any()
    assert (df["eng_direct"] == df["eng_direct_no_trees"]).any() and (df["rad_direct"] < 1).any()


@pytest.mark.parametrize("leaf", ["on", "off"])
def test_direct_within_10_percent_under_and_beside_the_crowns(tree_results, leaf):
    r = tree_results[tree_results["leaf"] == leaf]
    bad = r[r["direct_err"].abs() > TOL_DIRECT]
    assert bad.empty, bad[["sun", "point", "eng_direct", "rad_direct", "beam"]].to_string()


@pytest.mark.parametrize("leaf", ["on", "off"])
def test_total_within_10_percent_under_and_beside_the_crowns(tree_results, leaf):
    r = tree_results[tree_results["leaf"] == leaf]
    bad = r[r["total_err"].abs() > TOL_TOTAL]
    assert bad.empty, bad[["sun", "point", "eng_total", "rad_total", "eng_diffuse", "rad_diffuse",
                           "eng_reflected", "rad_reflected"]].to_string()


def test_radiance_crown_transmits_tau(tmp_path):
    """The Radiance crown passes tau of the sun to a sensor under it (two crossings of
    sqrt(tau)), as the engine's crown does: the sun straight above a lone crown."""
    text = _sun_only(np.array([0.0, 0.0, 1.0]), 800.0)
    text += "void trans m 0 0 7 {0} {0} {0} 0 0 1 1\nm sphere c 0 0 4 0 0 8 3.5\n".format(math.sqrt(0.2))
    got = _rtrace_irradiance(tmp_path, "lone", text, [(0.0, 0.0, 1.0), (10.0, 0.0, 1.0)], ["-ab", "0"])
    assert got == pytest.approx([0.2 * 800.0, 800.0], rel=1e-3)
