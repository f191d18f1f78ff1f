"""City ingest on small hand-written CityGML: analytic areas, normals, holes, bad input, CRS, terrain."""
from __future__ import annotations

import json

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest

from vipvflow.config import CityCfg
from vipvflow.errors import InputError
from vipvflow.inputs.city import TerrainModel, ingest_city, load_tile_mesh, parse_srs_name, prepare_polygon
from vipvflow.inputs.city.geometry import Skip

NS1 = ('xmlns="http://www.opengis.net/citygml/1.0" xmlns:bldg="http://www.opengis.net/citygml/building/1.0" '
       'xmlns:gml="http://www.opengis.net/gml"')
NS2 = ('xmlns="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" '
       'xmlns:dem="http://www.opengis.net/citygml/relief/2.0" '
       'xmlns:veg="http://www.opengis.net/citygml/vegetation/2.0" xmlns:gml="http://www.opengis.net/gml" '
       'xmlns:xlink="http://www.w3.org/1999/xlink"')
NS3 = ('xmlns="http://www.opengis.net/citygml/3.0" xmlns:bldg="http://www.opengis.net/citygml/building/3.0" '
       'xmlns:con="http://www.opengis.net/citygml/construction/3.0" xmlns:gml="http://www.opengis.net/gml/3.2"')


def pos_list(ring, close=True):
    ring = np.asarray(ring, float)
    if close:
        ring = np.vstack([ring, ring[:1]])
    return " ".join(f"{v:.6f}" for v in ring.ravel())


def polygon(ring, holes=(), close=True, pos=False):
    def lr(r):
        if pos:
            r = np.vstack([r, r[:1]]) if close else np.asarray(r)
            return "<gml:LinearRing>" + "".join(f"<gml:pos>{p[0]} {p[1]} {p[2]}</gml:pos>" for p in r) + "</gml:LinearRing>"
        return f"<gml:LinearRing><gml:posList srsDimension=\"3\">{pos_list(r, close)}</gml:posList></gml:LinearRing>"
    inner = "".join(f"<gml:interior>{lr(h)}</gml:interior>" for h in holes)
    return f"<gml:Polygon><gml:exterior>{lr(ring)}</gml:exterior>{inner}</gml:Polygon>"


def gabled(x, y, z, w, d, h, r):
    """Gabled house rings (outward, counter-clockwise): ridge along x at y + d/2, height h + r."""
    x1, y1, ym, zt, zr = x + w, y + d, y + d / 2, z + h, z + h + r
    return {"GroundSurface": [[(x, y, z), (x, y1, z), (x1, y1, z), (x1, y, z)]],
            "WallSurface": [[(x, y, z), (x1, y, z), (x1, y, zt), (x, y, zt)],
                            [(x1, y1, z), (x, y1, z), (x, y1, zt), (x1, y1, zt)],
                            [(x1, y, z), (x1, y1, z), (x1, y1, zt), (x1, ym, zr), (x1, y, zt)],
                            [(x, y1, z), (x, y, z), (x, y, zt), (x, ym, zr), (x, y1, zt)]],
            "RoofSurface": [[(x, y, zt), (x1, y, zt), (x1, ym, zr), (x, ym, zr)],
                            [(x1, y1, zt), (x, y1, zt), (x, ym, zr), (x1, ym, zr)]]}


def box(x, y, z, w, d, h):
    x1, y1, zt = x + w, y + d, z + h
    return {"GroundSurface": [[(x, y, z), (x, y1, z), (x1, y1, z), (x1, y, z)]],
            "WallSurface": [[(x, y, z), (x1, y, z), (x1, y, zt), (x, y, zt)],
                            [(x1, y, z), (x1, y1, z), (x1, y1, zt), (x1, y, zt)],
                            [(x1, y1, z), (x, y1, z), (x, y1, zt), (x1, y1, zt)],
                            [(x, y1, z), (x, y, z), (x, y, zt), (x, y1, zt)]],
            "RoofSurface": [[(x, y, zt), (x1, y, zt), (x1, y1, zt), (x, y1, zt)]]}


def building_v1(bid, surfaces):
    """CityGML 1.0 building, gml:pos, thematic surfaces WITHOUT gml:id (as the Hamburg tiles)."""
    out = [f'<cityObjectMember><bldg:Building gml:id="{bid}">']
    for cls, rings in surfaces.items():
        for ring in rings:
            out.append(f"<bldg:boundedBy><bldg:{cls}><bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>"
                       f"{polygon(ring, pos=True)}</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface>"
                       f"</bldg:{cls}></bldg:boundedBy>")
    out.append("</bldg:Building></cityObjectMember>")
    return "".join(out)


def building_v3(bid, surfaces):
    out = [f'<cityObjectMember><bldg:Building gml:id="{bid}">']
    for k, (cls, rings) in enumerate(surfaces.items()):
        for j, ring in enumerate(rings):
            out.append(f'<boundary><con:{cls} gml:id="{bid}_{k}_{j}"><lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>'
                       f"{polygon(ring)}</gml:surfaceMember></gml:MultiSurface></lod2MultiSurface>"
                       f"</con:{cls}></boundary>")
    out.append("</bldg:Building></cityObjectMember>")
    return "".join(out)


def city(ns, members, srs="EPSG:2169", encoding="UTF-8"):
    env = f'<gml:boundedBy><gml:Envelope srsName="{srs}"/></gml:boundedBy>' if srs else ""
    return f'<?xml version="1.0" encoding="{encoding}"?>\n<CityModel {ns}>{env}{"".join(members)}</CityModel>\n'


def surfaces_of(data_dir) -> gpd.GeoDataFrame:
    parts = sorted((data_dir / "city" / "surfaces").glob("tile=*/part-0.parquet"))
    return gpd.GeoDataFrame(pd.concat([gpd.read_parquet(p) for p in parts], ignore_index=True))


# -- analytic areas and normals ---------------------------------------------------------------
def test_box_and_gabled_house_areas_and_normals(tmp_path):
    w, d, h, r = 12.0, 8.0, 6.0, 3.0
    x0, y0, z0 = 77010.0, 75020.0, 300.0
    f1 = tmp_path / "box_v1.gml"
    f1.write_text(city(NS1, [building_v1("BOX", box(x0, y0, z0, w, d, h))]))
    f3 = tmp_path / "gabled_v3.gml"
    f3.write_text(city(NS3, [building_v3("GAB", gabled(x0 + 40, y0, z0, w, d, h, r))]))
    report = ingest_city([f1, f3], tmp_path / "out")
    gdf = surfaces_of(tmp_path / "out")
    box_ = gdf[gdf.building_id == "BOX"].groupby("surface_type").area_m2.sum()
    gab = gdf[gdf.building_id == "GAB"].groupby("surface_type").area_m2.sum()
    assert box_["roof"] == pytest.approx(w * d, rel=1e-3)
    assert box_["wall"] == pytest.approx(2 * (w + d) * h, rel=1e-3)
    assert box_["ground"] == pytest.approx(w * d, rel=1e-3)
    assert gab["roof"] == pytest.approx(2 * w * np.hypot(d / 2, r), rel=1e-3)
    assert gab["wall"] == pytest.approx(2 * w * h + 2 * (d * h + d * r / 2), rel=1e-3)
    assert report.surfaces == {"roof": 3, "wall": 8, "ground": 2}
    # ids: generated for the v1 surfaces without gml:id, taken from the v3 file otherwise
    assert set(gdf[gdf.building_id == "BOX"].surface_id) >= {"BOX_roof_0", "BOX_wall_3", "BOX_ground_0"}
    assert "GAB_2_1" in set(gdf.surface_id)
    # normals: box roof up, ground down, walls outward; gabled roof tilt atan(r / (d/2))
    b = gdf[gdf.building_id == "BOX"].set_index("surface_id")
    assert b.loc["BOX_roof_0", "nz"] == pytest.approx(1.0)
    assert b.loc["BOX_ground_0", "nz"] == pytest.approx(-1.0)
    walls = b[b.surface_type == "wall"]
    cx = walls.geometry.centroid.x - (x0 + w / 2)
    cy = walls.geometry.centroid.y - (y0 + d / 2)
    assert ((walls.nx * cx + walls.ny * cy) > 0).all() and np.allclose(walls.nz, 0)
    g = gdf[(gdf.building_id == "GAB") & (gdf.surface_type == "roof")]
    assert np.allclose(np.degrees(np.arccos(g.nz)), np.degrees(np.arctan2(r, d / 2)))
    # albedo by type from the config
    assert np.allclose(gdf[gdf.surface_type == "wall"].albedo, CityCfg().albedo.wall)
    # every triangle's winding normal agrees with its surface normal
    tiles = json.loads((tmp_path / "out" / "city" / "tiles.json").read_text())["tiles"]
    for name in tiles:
        mesh = load_tile_mesh(tmp_path / "out", name)
        p = mesh.vertices[mesh.triangles]
        n = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        tri_area = np.linalg.norm(n, axis=1) / 2
        n /= 2 * tri_area[:, None]
        assert (np.einsum("ij,ij->i", n, mesh.normals) > 0.9999).all()
        # the triangles tile each surface exactly
        per_surface = np.bincount(mesh.surface_index, tri_area, minlength=len(mesh.surface_ids))
        own = gdf.set_index("surface_id").loc[mesh.surface_ids[:tiles[name]["n_surfaces"]], "area_m2"]
        assert np.allclose(per_surface[:len(own)], own.to_numpy(), rtol=1e-9)


def test_polygon_with_hole_triangulates_to_right_area():
    # 10 m x 6 m facade with a 2 m x 1.5 m window, on a plane tilted 30 deg and turned 40 deg
    outer = np.array([[0, 0], [10, 0], [10, 6], [0, 6]], float)
    hole = np.array([[3, 2], [3, 3.5], [5, 3.5], [5, 2]], float)
    t, a = np.radians(30), np.radians(40)
    ex = np.array([np.cos(a), np.sin(a), 0.0])
    ey = np.array([-np.sin(a) * np.cos(t), np.cos(a) * np.cos(t), np.sin(t)])
    lift = lambda p: 1000 + p[:, :1] * ex + p[:, 1:] * ey  # noqa: E731
    prep = prepare_polygon([lift(outer), lift(hole)], 0.01)
    assert prep.area == pytest.approx(60 - 3, rel=1e-12)
    p = prep.vertices[prep.triangles]
    cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    assert np.linalg.norm(cross, axis=1).sum() / 2 == pytest.approx(57, rel=1e-12)
    assert np.allclose(prep.normal, np.cross(ex, ey))
    assert (cross @ prep.normal > 0).all()
    # no triangle covers the window's centre
    c = lift(np.array([[4.0, 2.75]]))[0]
    bary_in = []
    for tri in p:
        m = np.column_stack([tri[1] - tri[0], tri[2] - tri[0]])
        uv, *_ = np.linalg.lstsq(m, c - tri[0], rcond=None)
        bary_in.append(uv.min() > 0 and uv.sum() < 1)
    assert not any(bary_in)


# -- bad input ------------------------------------------------------------------------------
def test_bad_polygons_are_counted_not_fatal(tmp_path):
    x, y, z = 77100.0, 75100.0, 300.0
    good = box(x, y, z, 10, 10, 5)
    bad = {
        "RoofSurface": [
            [(x, y, z + 9), (x + 5, y, z + 9), (x + 10, y, z + 9)],                         # collinear
            [(x, y, z + 9), (x + 1e-9, y, z + 9)],                                          # 2 points
            [(x, y, z + 9), (x + 10, y, z + 9), (x + 10, y + 10, z + 9.5), (x, y + 10, z + 9)],  # bent 0.5 m
            [(x, y, z + 9), (x + 10, y + 10, z + 9), (x + 10, y, z + 9), (x, y + 6, z + 9)],     # bow tie
        ]}
    members = [building_v1("GOOD", good), building_v1("BAD", bad)]
    # an unclosed ring (repaired) and a ring with a repeated point (repaired)
    unclosed = [(x, y + 20, z), (x + 4, y + 20, z), (x + 4, y + 24, z + 4), (x, y + 24, z + 4)]
    members.append('<cityObjectMember><bldg:Building gml:id="REPAIR"><bldg:boundedBy><bldg:RoofSurface>'
                   f'<bldg:lod2MultiSurface><gml:MultiSurface><gml:surfaceMember>{polygon(unclosed, close=False)}'
                   '</gml:surfaceMember><gml:surfaceMember>'
                   f'{polygon([unclosed[0], unclosed[1], unclosed[1], unclosed[2], unclosed[3]])}'
                   '</gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface></bldg:RoofSurface>'
                   '</bldg:boundedBy></bldg:Building></cityObjectMember>')
    path = tmp_path / "bad.gml"
    path.write_text(city(NS1, members))
    report = ingest_city(path, tmp_path / "out")
    assert report.skipped == {"degenerate": 2, "non_planar": 1, "self_intersecting": 1}
    assert report.repaired == {"closed_ring": 1, "duplicate_points": 1}
    assert report.surfaces == {"roof": 3, "wall": 4, "ground": 1}
    assert report.buildings == 3
    gdf = surfaces_of(tmp_path / "out")
    rep = gdf[gdf.building_id == "REPAIR"]
    assert np.allclose(rep.area_m2, 4 * np.hypot(4, 4))
    stored = json.loads((tmp_path / "out" / "city" / "ingest_report.json").read_text())
    assert stored["skipped"] == report.skipped


def test_prepare_polygon_reasons():
    sq = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    with pytest.raises(Skip) as e:
        prepare_polygon([sq * 0.01], 0.1, min_area_m2=0.01)
    assert e.value.reason == "too_small"
    hole_outside = sq + [5, 5, 0]
    with pytest.raises(Skip) as e:
        prepare_polygon([sq * 2, hole_outside], 0.1)
    assert e.value.reason == "invalid_rings"


def test_broken_xml_names_file_and_line(tmp_path):
    text = city(NS2, [building_v1("A", box(77000, 75000, 300, 5, 5, 5))]).replace(NS1, NS2)
    lines = text.splitlines()
    lines.insert(2, "<bldg:Building><oops></bldg:Building>")
    path = tmp_path / "broken.gml"
    path.write_text("\n".join(lines))
    with pytest.raises(InputError) as e:
        ingest_city(path, tmp_path / "out")
    assert "broken.gml" in str(e.value) and "line 3" in str(e.value)


def test_missing_file_and_missing_crs(tmp_path):
    with pytest.raises(InputError, match="not found"):
        ingest_city(tmp_path / "nope.gml", tmp_path / "out")
    path = tmp_path / "nosrs.gml"
    path.write_text(city(NS1, [building_v1("A", box(77000, 75000, 300, 5, 5, 5))], srs=None))
    with pytest.raises(InputError, match="pass --crs"):
        ingest_city(path, tmp_path / "out")
    assert ingest_city(path, tmp_path / "out", crs="EPSG:2169").crs == "EPSG:2169"


def test_latin1_file(tmp_path):
    body = city(NS1, [building_v1("Straße_1", box(77000, 75000, 300, 5, 5, 5))], encoding="ISO-8859-1")
    body = body.replace("<cityObjectMember>", "<gml:name>Müller-Haus</gml:name><cityObjectMember>", 1)
    path = tmp_path / "latin1.gml"
    path.write_bytes(body.encode("latin-1"))
    report = ingest_city(path, tmp_path / "out")
    assert report.surfaces == {"roof": 1, "wall": 4, "ground": 1}
    assert set(surfaces_of(tmp_path / "out").building_id) == {"Straße_1"}


# -- CRS ----------------------------------------------------------------------------------
@pytest.mark.parametrize("srs,epsg", [
    ("EPSG:2169", "EPSG:2169"),
    ("urn:ogc:def:crs:EPSG::25832", "EPSG:25832"),
    ("urn:ogc:def:crs:EPSG:6.12:3068", "EPSG:3068"),
    ("urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774", "EPSG:2169"),
    ("urn:ogc:def:crs,crs:EPSG:7.7:31468,crs:EPSG:7.7:5783", "EPSG:31468"),
    ("http://www.opengis.net/def/crs/EPSG/0/25832", "EPSG:25832"),
    ("urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH", "EPSG:25832"),
    ("urn:adv:crs:ETRS89_UTM32*DE_DHHN92_NH", "EPSG:25832"),
    ("urn:adv:crs:ETRS89_UTM33*DE_DHHN2016_NH", "EPSG:25833"),
    ("urn:adv:crs:DE_DHDN_3GK2*DE_DHHN92_NH", "EPSG:31466"),
    ("urn:adv:crs:DE_DHDN_3GK3", "EPSG:31467"),
    ("urn:adv:crs:DE_DHDN_3GK4*DE_DHHN92_NH", "EPSG:31468"),
])
def test_srs_names(srs, epsg):
    assert parse_srs_name(srs) == epsg


def test_unknown_srs_name():
    with pytest.raises(InputError, match="--crs"):
        parse_srs_name("urn:adv:crs:MARS_GRID")


def test_files_in_other_crs_are_transformed(tmp_path):
    from pyproj import Transformer

    rings = box(77050.0, 75050.0, 300.0, 10, 8, 6)
    to3035 = Transformer.from_crs("EPSG:2169", "EPSG:3035", always_xy=True)
    moved = {cls: [np.column_stack([*to3035.transform(np.array(r)[:, 0], np.array(r)[:, 1]),
                                    np.array(r)[:, 2]]) for r in rs] for cls, rs in rings.items()}
    (tmp_path / "a.gml").write_text(city(NS1, [building_v1("A", rings)], srs="EPSG:2169"))
    (tmp_path / "b.gml").write_text(city(
        NS1, [building_v1("B", moved)], srs="http://www.opengis.net/def/crs/EPSG/0/3035"))
    report = ingest_city([tmp_path / "a.gml", tmp_path / "b.gml"], tmp_path / "out")
    assert report.crs == "EPSG:2169"
    assert report.file_crs[str(tmp_path / "b.gml")] == "EPSG:3035"
    gdf = surfaces_of(tmp_path / "out").set_index("surface_id")
    for k in ("roof_0", "wall_2", "ground_0"):
        a, b = gdf.loc[f"A_{k}"], gdf.loc[f"B_{k}"]
        assert np.allclose(np.asarray(a.geometry.exterior.coords), np.asarray(b.geometry.exterior.coords),
                           atol=0.01)
        assert b.area_m2 == pytest.approx(a.area_m2, rel=1e-5)


# -- fallback geometry, xlink, BuildingPart, terrain, vegetation --------------------------------
def test_solid_fallback_xlink_parts_terrain_vegetation(tmp_path):
    x, y, z = 77200.0, 75200.0, 310.0
    # building with a BuildingPart, geometry only as an lod2Solid whose members are xlinks
    rings = box(x, y, z, 10, 10, 8)
    flat = [r for rs in rings.values() for r in rs]
    polys = "".join("<gml:surfaceMember>" + polygon(r).replace("<gml:Polygon>", f'<gml:Polygon gml:id="P{i}">')
                    + "</gml:surfaceMember>" for i, r in enumerate(flat[:3]))
    refs = "".join(f'<gml:surfaceMember xlink:href="#P{i}"/>' for i in range(3))
    inline = "".join(f"<gml:surfaceMember>{polygon(r)}</gml:surfaceMember>" for r in flat[3:])
    building = ('<cityObjectMember><bldg:Building gml:id="PARENT"><bldg:consistsOfBuildingPart>'
                '<bldg:BuildingPart gml:id="PART1">'
                f'<bldg:lod2MultiSurface><gml:MultiSurface>{polys}</gml:MultiSurface></bldg:lod2MultiSurface>'
                f'<bldg:lod2Solid><gml:Solid><gml:exterior><gml:CompositeSurface>{refs}{inline}'
                '</gml:CompositeSurface></gml:exterior></gml:Solid></bldg:lod2Solid>'
                '</bldg:BuildingPart></bldg:consistsOfBuildingPart></bldg:Building></cityObjectMember>')
    # TIN relief of the plane z = 250 + 0.05 (x - x0) + 0.02 (y - y0) over 200 m x 200 m
    gx, gy = np.meshgrid(np.linspace(x - 100, x + 100, 5), np.linspace(y - 100, y + 100, 5))
    plane = lambda px, py: 250 + 0.05 * (px - x) + 0.02 * (py - y)  # noqa: E731
    tris = []
    for i in range(4):
        for j in range(4):
            c = [(gx[i, j], gy[i, j]), (gx[i, j + 1], gy[i, j + 1]), (gx[i + 1, j + 1], gy[i + 1, j + 1]),
                 (gx[i + 1, j], gy[i + 1, j])]
            for t in ((c[0], c[1], c[2]), (c[0], c[2], c[3])):
                ring = [(px, py, plane(px, py)) for px, py in t]
                tris.append(f"<gml:Triangle><gml:exterior><gml:LinearRing><gml:posList>{pos_list(ring)}"
                            "</gml:posList></gml:LinearRing></gml:exterior></gml:Triangle>")
    relief = ('<cityObjectMember><dem:ReliefFeature gml:id="DEM"><dem:lod>2</dem:lod><dem:reliefComponent>'
              '<dem:TINRelief gml:id="TIN"><dem:lod>2</dem:lod><dem:tin><gml:TriangulatedSurface>'
              f'<gml:trianglePatches>{"".join(tris)}</gml:trianglePatches></gml:TriangulatedSurface>'
              '</dem:tin></dem:TINRelief></dem:reliefComponent></dem:ReliefFeature></cityObjectMember>')
    crown = [(x + 30, y + 30, 260.0), (x + 34, y + 30, 262.0), (x + 34, y + 34, 266.0), (x + 30, y + 34, 264.0)]
    tree = ('<cityObjectMember><veg:SolitaryVegetationObject gml:id="TREE"><veg:lod2Geometry>'
            f'<gml:MultiSurface><gml:surfaceMember>{polygon(crown)}</gml:surfaceMember></gml:MultiSurface>'
            '</veg:lod2Geometry></veg:SolitaryVegetationObject></cityObjectMember>')
    path = tmp_path / "mixed.gml"
    path.write_text(city(NS2, [building, relief, tree]))
    report = ingest_city(path, tmp_path / "out", CityCfg(tile_size_m=500, buffer_m=100))
    # the solid wins over the lod2MultiSurface; xlinks resolved; typed from the normal; the
    # tree is a crown (its polygon's extent), never a surface of the mesh
    assert report.surfaces == {"roof": 1, "wall": 4, "ground": 1, "terrain": 32}
    assert report.trees["kept"] == 1 and report.trees["crown_base_from"] == {"default": 1}
    trees = gpd.read_parquet(tmp_path / "out" / "city" / "trees.parquet")
    t = trees.iloc[0]
    assert (t.geometry.x, t.geometry.y, t.geometry.z) == pytest.approx((x + 32, y + 32, 260.0))
    assert t.height_m == pytest.approx(6.0) and t.crown_base_m == pytest.approx(0.35 * 6.0)
    assert t.crown_diameter_m == pytest.approx(4.0)      # the mean of its two widths (4 x 4 m)
    assert report.buildings == 1 and report.building_parts == 1
    assert report.terrain_features == 1 and report.vegetation_features == 1
    assert report.terrain_triangles == 32
    gdf = surfaces_of(tmp_path / "out")
    bld = gdf[gdf.building_id == "PARENT"]
    assert set(bld.surface_id) >= {"P0", "P1", "P2"} and len(bld) == 6
    assert gdf[gdf.surface_type == "terrain"].area_m2.sum() == pytest.approx(
        200 * 200 * np.sqrt(1 + 0.05 ** 2 + 0.02 ** 2), rel=1e-9)
    terrain = TerrainModel.load(tmp_path / "out")
    rng = np.random.default_rng(3)
    px, py = rng.uniform(x - 99, x + 99, 500), rng.uniform(y - 99, y + 99, 500)
    assert np.allclose(terrain.elevation(px, py), plane(px, py), atol=1e-9)
    # outside the TIN: building ground surfaces near the point, else NaN
    far = TerrainModel.load(tmp_path / "out", max_distance_m=200).elevation(
        np.array([x + 5, x + 5000]), np.array([y - 150, y]))
    assert far[0] == pytest.approx(z) and np.isnan(far[1])
    assert terrain.elevation(np.full((2, 3), x), np.full((2, 3), y)).shape == (2, 3)
