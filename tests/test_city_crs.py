"""CityGML coordinates as the CRS says: axis order, geographic input (PLATEAU), UTM choice, LoD fallback.

Expected values come from independent sources: XPath counts of the file, pyproj transforms of
the file's own coordinates (done here, in the CRS's authority order) and the file's envelope.
"""
from __future__ import annotations

import json

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
from lxml import etree
from pyproj import CRS, Transformer

from vipvflow.inputs.city import ingest_city, load_tile_mesh
from vipvflow.inputs.city.crs import SourceCRS, horizontal, local_utm, north_first, parse_srs_name
from vipvflow.models.shading import Scene

PLATEAU = ("citygml", "plateau_osaka", "52350301_bldg_6697_op.gml")
TYPES = {"roof": "RoofSurface", "wall": "WallSurface", "ground": "GroundSurface"}


def surfaces_of(data_dir) -> gpd.GeoDataFrame:
    parts = sorted((data_dir / "city" / "surfaces").glob("tile=*/part-0.parquet"))
    return gpd.GeoDataFrame(pd.concat([gpd.read_parquet(p) for p in parts], ignore_index=True))


def rings_of(geom) -> list[np.ndarray]:
    return [np.asarray(geom.exterior.coords)] + [np.asarray(r.coords) for r in geom.interiors]


# -- axis order and CRS names ---------------------------------------------------------------------
@pytest.mark.parametrize("code", [4326, 4258, 6668, 6697])
def test_geographic_crs_are_latitude_first(code):
    """EPSG defines these latitude first; a point written lat, lon is read as lon, lat."""
    assert north_first(f"EPSG:{code}")
    lat, lon = (34.668, 135.399) if code in (6668, 6697, 4326) else (53.55, 9.99)
    src = SourceCRS.decide(f"EPSG:{code}", np.array([[lat, lon]]))
    assert src.swap and src.axis_order == "lat,lon (EPSG order)"
    assert np.allclose(src.read(np.array([[lat, lon, 7.0]])), [[lon, lat, 7.0]])


@pytest.mark.parametrize("srs", [
    "http://www.opengis.net/def/crs/EPSG/0/6697",          # PLATEAU
    "urn:ogc:def:crs:EPSG::6697",
    "urn:ogc:def:crs,crs:EPSG::6668,crs:EPSG::6695",       # compound URN: horizontal + height
    "EPSG:6697",
])
def test_compound_forms_give_the_horizontal_crs(srs):
    assert horizontal(parse_srs_name(srs)) == "EPSG:6668"
    assert CRS.from_user_input("EPSG:6697").sub_crs_list[0].to_epsg() == 6668


def test_projected_axis_order_decided_by_area_of_use():
    """EPSG:31468 (Gauss-Krueger 4) is northing first in EPSG; the Munich file is written easting
    first. Each way round is read so the point lands in Bavaria."""
    assert north_first("EPSG:31468") and not north_first("EPSG:25832")
    e, n = 4467900.0, 5334700.0
    back = Transformer.from_crs("EPSG:31468", "EPSG:4326", always_xy=True)
    for written, swap in (((e, n), False), ((n, e), True)):
        srs = parse_srs_name("urn:ogc:def:crs,crs:EPSG:7.7:31468,crs:EPSG:7.7:5783")
        src = SourceCRS.decide(srs, np.array([written]))
        assert src.swap is swap
        x, y, _ = src.read(np.array([[*written, 0.0]]))[0]
        lon, lat = back.transform(x, y)
        assert 11.5 < lon < 11.6 and 48.1 < lat < 48.2          # TUM, Munich


def test_local_utm_zone_as_geopandas_estimates():
    pts = gpd.GeoSeries(gpd.points_from_xy([135.394], [34.669]), crs="EPSG:6668")
    assert local_utm("EPSG:6668", 135.394, 34.669) == "EPSG:6690"        # JGD2011 / UTM 53N
    assert pts.estimate_utm_crs(datum_name="JGD2011").to_epsg() == 6690
    assert local_utm("EPSG:4326", 10.0, 53.5) == "EPSG:32632"
    assert local_utm("EPSG:4326", -70.6, -33.4) == "EPSG:32719"          # southern hemisphere


# -- a projected sample rewritten in EPSG:4326 (lat, lon) --------------------------------------
def _to_latlon_file(src_path, dst_path, srs_name: str) -> None:
    """Rewrite every coordinate of a EPSG:25832 file as EPSG:4326 latitude, longitude, height."""
    tree = etree.parse(str(src_path))
    t = Transformer.from_crs("EPSG:25832", "EPSG:4326")      # authority order out: lat, lon
    for el in tree.iter("{*}posList", "{*}pos", "{*}lowerCorner", "{*}upperCorner"):
        xyz = np.array(el.text.split(), float).reshape(-1, 3)
        lat, lon = t.transform(xyz[:, 0], xyz[:, 1])
        el.text = " ".join(f"{a:.11f} {b:.11f} {c:.4f}" for a, b, c in zip(lat, lon, xyz[:, 2]))
    for el in tree.iter():
        if el.get("srsName"):
            el.set("srsName", srs_name)
    tree.write(str(dst_path), xml_declaration=True, encoding="UTF-8")


@pytest.mark.parametrize("srs", ["urn:ogc:def:crs:EPSG::4326", "http://www.opengis.net/def/crs/EPSG/0/4326",
                                 "EPSG:4326"])
def test_latlon_file_gives_the_projected_surfaces(test_data, tmp_path, srs):
    original = test_data / "citygml" / "TUM-Main-Entrance.gml"
    ref = ingest_city(original, tmp_path / "ref")
    latlon = tmp_path / "tum_4326.gml"
    _to_latlon_file(original, latlon, srs)
    got = ingest_city(latlon, tmp_path / "got", crs="EPSG:25832")
    assert got.axis_order[str(latlon)] == "lat,lon (EPSG order)"
    assert got.surfaces == ref.surfaces and got.skipped == ref.skipped
    a = surfaces_of(tmp_path / "ref").set_index("surface_id").sort_index()
    b = surfaces_of(tmp_path / "got").set_index("surface_id").sort_index()
    assert list(a.index) == list(b.index)
    for ga, gb in zip(a.geometry, b.geometry):
        for ra, rb in zip(rings_of(ga), rings_of(gb)):
            assert np.abs(ra - rb).max() < 0.01                        # 1 cm, heights included
    assert np.allclose(a.area_m2, b.area_m2, rtol=1e-5)
    # without --crs: the local UTM zone (WGS 84 / UTM 32N for EPSG:4326), said in the report
    auto = ingest_city(latlon, tmp_path / "auto")
    assert auto.crs == "EPSG:32632" and "UTM" in auto.crs_source and "UTM" in auto.summary()
    assert json.loads((tmp_path / "auto" / "city" / "tiles.json").read_text())["crs"] == "EPSG:32632"


# -- PLATEAU Osaka (EPSG:6697, lat lon height) ------------------------------------------------
def check_vertices_by_pyproj(path, out, every: int = 1) -> int:
    """Stored roof/wall vertices equal pyproj's transform of the file's (lat, lon), heights as
    written, to 1 mm; returns the number of surfaces checked."""
    tree = etree.parse(str(path))
    t = Transformer.from_crs("EPSG:6668", "EPSG:6690")       # authority order in: lat, lon
    gdf = surfaces_of(out).set_index("surface_id")
    surfaces = tree.xpath("//*[local-name()='RoofSurface' or local-name()='WallSurface']")[::every]
    for surf in surfaces:
        sid = surf.get("{http://www.opengis.net/gml}id")
        pos = np.array(surf.xpath(".//*[local-name()='posList']/text()")[0].split(), float).reshape(-1, 3)
        e, n = t.transform(pos[:, 0], pos[:, 1])
        stored = np.asarray(gdf.loc[sid].geometry.exterior.coords)
        expect = np.column_stack([e, n, pos[:, 2]])
        # the same points (the writer may drop the closing duplicate or re-close)
        d = np.linalg.norm(stored[:, None, :] - expect[None, :, :], axis=2).min(axis=1)
        assert d.max() < 1e-3, sid
    return len(surfaces)


def test_plateau_excerpt_in_tests_data(test_data, tmp_path):
    """4 buildings of the PLATEAU tile (kept in tests/data): read lat, lon, put into UTM 53N."""
    path = test_data / "citygml" / "plateau_52350301_4bldg.gml"
    report = ingest_city(path, tmp_path)
    tree = etree.parse(str(path))
    expected = {t: int(tree.xpath(f"count(//*[local-name()='{c}'])")) for t, c in TYPES.items()}
    assert report.surfaces == report.thematic_surfaces == expected and report.n_skipped == 0
    assert report.buildings == 4 and report.buildings_by_lod == {"lod2": 4}
    assert (report.crs, report.crs_source) == ("EPSG:6690", "local UTM zone for geographic EPSG:6668")
    assert report.axis_order == {str(path): "lat,lon (EPSG order)"}
    assert check_vertices_by_pyproj(path, tmp_path) == expected["roof"] + expected["wall"]


@pytest.fixture(scope="module")
def plateau(shared_data, tmp_path_factory):
    path = shared_data.joinpath(*PLATEAU)
    out = tmp_path_factory.mktemp("plateau")
    report = ingest_city(path, out)
    return path, out, report


@pytest.mark.shared
def test_plateau_surfaces_match_xpath(plateau):
    path, out, report = plateau
    tree = etree.parse(str(path))
    expected = {t: int(tree.xpath(f"count(//*[local-name()='{c}'])")) for t, c in TYPES.items()}
    assert expected == {"roof": 175, "wall": 368, "ground": 80}
    polygons = {t: int(tree.xpath(f"count(//*[local-name()='{c}']//*[local-name()='Polygon'])"))
                for t, c in TYPES.items()}
    assert report.thematic_surfaces == expected
    # every polygon stored or skipped with a reason
    for t, n in polygons.items():
        assert report.surfaces.get(t, 0) + report.skipped_by_type.get(t, 0) == n
    assert report.surfaces == expected and report.n_skipped == 0
    assert report.buildings == 80 and report.buildings_by_lod == {"lod2": 80}
    assert report.crs == "EPSG:6690" and "UTM" in report.crs_source
    assert "lod2 80" in report.summary() and "EPSG:6690" in report.summary()
    gdf = surfaces_of(out)
    assert len(gdf) == 623 and gdf.crs.to_epsg() == 6690


@pytest.mark.shared
def test_plateau_coordinates_by_independent_transform(plateau):
    """Every stored vertex equals pyproj's transform of the file's (lat, lon) to 1 mm, heights as
    written, and the mesh lies within the file's envelope."""
    path, out, _ = plateau
    assert check_vertices_by_pyproj(path, out, every=5) >= 100
    tree = etree.parse(str(path))
    t = Transformer.from_crs("EPSG:6668", "EPSG:6690")
    lo = [float(v) for v in tree.xpath("//*[local-name()='Envelope']/*[local-name()='lowerCorner']/text()")[0].split()]
    hi = [float(v) for v in tree.xpath("//*[local-name()='Envelope']/*[local-name()='upperCorner']/text()")[0].split()]
    lat = np.linspace(lo[0], hi[0], 50)
    lon = np.linspace(lo[1], hi[1], 50)
    LAT, LON = np.meshgrid(lat, lon)
    E, N = t.transform(LAT.ravel(), LON.ravel())
    for name in json.loads((out / "city" / "tiles.json").read_text())["tiles"]:
        v = load_tile_mesh(out, name).vertices
        assert (v[:, 0] >= E.min() - 0.01).all() and (v[:, 0] <= E.max() + 0.01).all()
        assert (v[:, 1] >= N.min() - 0.01).all() and (v[:, 1] <= N.max() + 0.01).all()
        assert (v[:, 2] >= lo[2]).all() and (v[:, 2] <= hi[2] + 1e-9).all()


@pytest.mark.shared
def test_plateau_in_plane_rectangular_vi_transforms_back(plateau, tmp_path):
    """--crs EPSG:6674 (JGD2011 / Japan Plane Rectangular CS VI): the same geometry to 1 cm."""
    path, out, ref_report = plateau
    report = ingest_city(path, tmp_path, crs="EPSG:6674")
    assert report.crs == "EPSG:6674" and report.crs_source == "--crs"
    assert report.surfaces == ref_report.surfaces
    a = surfaces_of(out).set_index("surface_id").sort_index()
    b = surfaces_of(tmp_path).set_index("surface_id").sort_index()
    assert list(a.index) == list(b.index)
    back = Transformer.from_crs("EPSG:6674", "EPSG:6690", always_xy=True)
    for ga, gb in zip(a.geometry, b.geometry):
        rb = np.asarray(gb.exterior.coords)
        x, y = back.transform(rb[:, 0], rb[:, 1])
        assert np.abs(np.column_stack([x, y, rb[:, 2]]) - np.asarray(ga.exterior.coords)).max() < 0.01
    assert np.allclose(a.area_m2, b.area_m2, rtol=1e-3)     # scale factors of the two projections


@pytest.mark.shared
def test_plateau_lod1_only_buildings_still_shade(shared_data, tmp_path):
    """Buildings stripped of their LoD2 surfaces fall back to their lod1Solid (a block: roof area =
    ground area), are counted as LoD1 and block a ray cast down onto them."""
    tree = etree.parse(str(shared_data.joinpath(*PLATEAU)))
    buildings = tree.xpath("//*[local-name()='Building']")
    stripped = {b.get("{http://www.opengis.net/gml}id") for b in buildings[:10]}
    for b in buildings[:10]:
        for el in b.xpath("./*[local-name()='boundedBy' or local-name()='lod2Solid']"):
            b.remove(el)
    path = tmp_path / "lod1.gml"
    tree.write(str(path), xml_declaration=True, encoding="UTF-8")
    report = ingest_city(path, tmp_path / "out")
    assert report.buildings_by_lod == {"lod2": 70, "lod1": 10}
    assert "lod1 10" in report.summary()
    gdf = surfaces_of(tmp_path / "out")
    lod1 = gdf[gdf.building_id.isin(stripped)]
    assert set(lod1.building_id) == stripped
    for _, g in lod1.groupby("building_id"):
        roof, ground = g[g.surface_type == "roof"], g[g.surface_type == "ground"]
        assert len(roof) >= 1 and roof.nz.min() > 0.999
        assert roof.area_m2.sum() == pytest.approx(ground.area_m2.sum(), rel=1e-9)
    # a ray from 50 m above a point of each LoD1 roof, straight down, stops on that roof
    hits = 0
    for tile, g in lod1[lod1.surface_type == "roof"].groupby("tile"):
        scene = Scene(load_tile_mesh(tmp_path / "out", tile))
        c = np.array([[p.representative_point().x, p.representative_point().y] for p in g.geometry])
        ztop = np.array([np.asarray(p.exterior.coords)[:, 2].max() for p in g.geometry])
        org = np.column_stack([c, ztop + 50.0])
        tri, dist = scene.first_hit(org, np.tile([0.0, 0.0, -1.0], (len(org), 1)))
        assert (tri >= 0).all()
        assert np.allclose(dist, 50.0, atol=0.01)
        hits += len(tri)
    assert hits == int((lod1.surface_type == "roof").sum())


def test_axis_order_option_for_northing_first_files(tmp_path, capsys):
    """EPSG:2169 (LUREF) is northing first in EPSG, but Luxembourg fits its area of use either way
    round: `auto` reads easting first (as producers write); a file really written northing first
    is read right with --axis-order epsg."""
    from vipvflow.cli import main
    from vipvflow.inputs.city.synthetic import HEADER, building_xml, house_polygons

    polys = house_polygons(77000.0, 75000.0, 300.0, 12, 10, 6, 3)
    swapped = {t: [r[:, [1, 0, 2]] for r in rings] for t, rings in polys.items()}
    head = HEADER.format(srs="urn:ogc:def:crs:EPSG::2169", x0=0, y0=0, x1=1, y1=1)
    (tmp_path / "en.gml").write_text(head + building_xml("H", polys) + "</core:CityModel>\n")
    (tmp_path / "ne.gml").write_text(head + building_xml("H", swapped) + "</core:CityModel>\n")
    assert main(["ingest", "city", str(tmp_path / "en.gml"), "--data-dir", str(tmp_path / "en")]) == 0
    assert main(["ingest", "city", str(tmp_path / "ne.gml"), "--data-dir", str(tmp_path / "ne"),
                 "--axis-order", "epsg"]) == 0
    a = surfaces_of(tmp_path / "en").set_index("surface_id").sort_index()
    b = surfaces_of(tmp_path / "ne").set_index("surface_id").sort_index()
    for ga, gb in zip(a.geometry, b.geometry):
        assert np.abs(np.asarray(ga.exterior.coords) - np.asarray(gb.exterior.coords)).max() < 1e-6
    assert (a.nz > 0.5).sum() == 2 and np.allclose(a[["nx", "ny", "nz"]], b[["nx", "ny", "nz"]])
    report = json.loads((tmp_path / "ne" / "city" / "ingest_report.json").read_text())
    assert report["axis_order"] == {str(tmp_path / "ne.gml"): "north,east (--axis-order epsg)"}
    report = json.loads((tmp_path / "en" / "city" / "ingest_report.json").read_text())
    assert report["axis_order"][str(tmp_path / "en.gml")].startswith("east,north (as written by")
