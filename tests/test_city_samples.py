"""City ingest on real CityGML samples: counts agree with an independent lxml XPath count."""
from __future__ import annotations

import json
import zipfile

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
import shapely
from lxml import etree

from vipvflow.errors import InputError
from vipvflow.inputs.city import TerrainModel, ingest_city, load_tile_mesh

TYPES = {"roof": "RoofSurface", "wall": "WallSurface", "ground": "GroundSurface"}


def xpath_counts(source) -> dict:
    """Buildings, thematic surfaces and their polygons per type, counted with XPath."""
    tree = etree.parse(source)

    def n(expr):
        return int(tree.xpath(f"count({expr})"))

    return {
        "buildings": n("//*[local-name()='Building']"),
        "parts": n("//*[local-name()='BuildingPart']"),
        "thematic": {t: n(f"//*[local-name()='{c}']") for t, c in TYPES.items()},
        "polygons": {t: sum(len(e.xpath(".//*[local-name()='Polygon']"))
                            for e in tree.xpath(f"//*[local-name()='{c}']"))
                     for t, c in TYPES.items()},
    }


def check_counts(report, expected):
    assert report.buildings == expected["buildings"]
    assert report.building_parts == expected["parts"]
    assert report.thematic_surfaces == {k: v for k, v in expected["thematic"].items() if v}
    for t, n_poly in expected["polygons"].items():
        written = report.surfaces.get(t, 0)
        assert written + report.skipped_by_type.get(t, 0) == n_poly, t
    # skips only for sliver polygons, never more than 1 in 500
    assert set(report.skipped) <= {"too_small", "degenerate"}
    assert report.n_skipped <= report.n_surfaces / 500


def read_back(data_dir):
    tiles = sorted((data_dir / "city" / "surfaces").glob("tile=*/part-0.parquet"))
    return gpd.GeoDataFrame(
        pd.concat([gpd.read_parquet(p) for p in tiles], ignore_index=True))


# -- samples copied into tests/data (always run) ----------------------------------------------
LOCAL = [
    ("fzk_haus_lod2_v2.gml", "EPSG:25832"),                      # CityGML 2.0, gml:pos, xlink solid
    ("FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml", "EPSG:25832"),  # CityGML 3.0, gml:pos
    ("TUM-Main-Entrance.gml", "EPSG:25832"),                     # CityGML 3.0, posList, holes
]


@pytest.mark.parametrize("name,crs", LOCAL)
def test_local_samples_counts(test_data, tmp_path, name, crs):
    path = test_data / "citygml" / name
    report = ingest_city(path, tmp_path)
    assert report.crs == crs
    check_counts(report, xpath_counts(str(path)))
    gdf = read_back(tmp_path)
    assert len(gdf) == report.n_surfaces
    assert gdf.crs.to_epsg() == int(crs.split(":")[1])
    assert gdf.geometry.has_z.all() and (gdf.geom_type == "Polygon").all()
    assert gdf["surface_id"].is_unique


def test_fzk_haus_v2_and_v3_agree(test_data, tmp_path):
    """The same house in CityGML 2.0 (pos + xlink solid) and 3.0 gives the same surfaces."""
    r2 = ingest_city(test_data / "citygml" / "fzk_haus_lod2_v2.gml", tmp_path / "v2")
    r3 = ingest_city(test_data / "citygml" / "FZK-Haus-LoD2-KIT-IAI-KHH-B36-V1__v3.gml", tmp_path / "v3")
    assert r2.surfaces == r3.surfaces == {"roof": 2, "wall": 4, "ground": 1}
    # FZK-Haus: 12 m x 10 m footprint (lowerCorner 457842 5439083, upperCorner 457854 5439093)
    assert r2.area_m2["ground"] == pytest.approx(120.0, rel=1e-6)
    for t in r2.area_m2:
        assert r2.area_m2[t] == pytest.approx(r3.area_m2[t], rel=1e-9)


def test_holes_area_independent(test_data, tmp_path):
    """Surfaces with interior rings: area = shapely area on an SVD-fitted plane (independent)."""
    path = test_data / "citygml" / "TUM-Main-Entrance.gml"
    ingest_city(path, tmp_path)
    gdf = read_back(tmp_path)
    tree = etree.parse(str(path))
    holed = tree.xpath("//*[local-name()='Polygon'][*[local-name()='interior']]")
    assert len(holed) >= 1
    for poly in holed:
        surface = poly.xpath("ancestor::*[local-name()='WallSurface' or local-name()='RoofSurface'"
                             " or local-name()='GroundSurface'][1]")[0]
        sid = surface.get("{http://www.opengis.net/gml/3.2}id")
        rings = [np.array(r.xpath(".//*[local-name()='posList']/text()")[0].split(), float).reshape(-1, 3)
                 for r in poly.xpath(".//*[local-name()='LinearRing']")]
        c = rings[0].mean(0)
        _, _, vt = np.linalg.svd(rings[0] - c)
        to2d = lambda r: (r - c) @ vt[:2].T  # noqa: E731
        expected = shapely.Polygon(to2d(rings[0]), [to2d(r) for r in rings[1:]]).area
        row = gdf[gdf.surface_id == sid]
        assert len(row) == 1
        assert row.area_m2.iloc[0] == pytest.approx(expected, rel=1e-6)
        assert row.geometry.iloc[0].interiors and len(row.geometry.iloc[0].interiors) == len(rings) - 1


# -- the larger real samples in ../shared/data --------------------------------------------------
@pytest.mark.shared
def test_hamburg_buildingparts_no_ids(shared_data, tmp_path):
    path = shared_data / "citygml" / "hamburg" / "LoD2_576_5950_1_HH_2022.xml"
    report = ingest_city(path, tmp_path)
    expected = xpath_counts(str(path))
    check_counts(report, expected)
    assert report.crs == "EPSG:25832"
    gdf = read_back(tmp_path)
    tree = etree.parse(str(path))
    top_ids = set(tree.xpath("//*[local-name()='Building']/@*[local-name()='id']"))
    part_ids = set(tree.xpath("//*[local-name()='BuildingPart']/@*[local-name()='id']"))
    # geometry inside BuildingParts belongs to the parent Building
    assert set(gdf.building_id) <= top_ids and not set(gdf.building_id) & part_ids
    # thematic surfaces without gml:id get stable generated ids <building>_<type>_<n>
    assert gdf.surface_id.is_unique
    roof = gdf[gdf.surface_type == "roof"].iloc[0]
    assert roof.surface_id.startswith(roof.building_id + "_roof_")
    # every tile of the 350 m x 850 m sheet lies within its extent
    assert report.tiles >= 2
    x, y = gdf.geometry.centroid.x, gdf.geometry.centroid.y
    assert x.between(576229, 576577).all() and y.between(5949995, 5950846).all()
    # terrain falls back to building ground surfaces: 26..40 m NHN in this sheet
    z = TerrainModel.load(tmp_path).elevation(np.array([576400.0]), np.array([5950400.0]))
    assert 20 < z[0] < 45


@pytest.mark.shared
def test_munich_zip_compound_urn(shared_data, tmp_path):
    path = shared_data / "citygml" / "munich_tum" / "TUM_Munich.zip"
    report = ingest_city(path, tmp_path)          # zip input is read directly
    with zipfile.ZipFile(path) as zf, zf.open("TUM Munich/TUM Munich.gml") as fh:
        expected = xpath_counts(fh)
    check_counts(report, expected)
    # urn:ogc:def:crs,crs:EPSG:7.7:31468,crs:EPSG:7.7:5783 -> horizontal part
    assert report.crs == "EPSG:31468"
    first_tile = next(iter(json.loads((tmp_path / "city" / "tiles.json").read_text())["tiles"]))
    mesh = load_tile_mesh(tmp_path, first_tile)
    assert mesh.n_triangles > 0 and mesh.vertices[:, 2].min() > 450  # Munich ~ 500 m a.s.l.


@pytest.mark.shared
def test_citygml4j_v3_versioned_urn(shared_data, tmp_path):
    path = shared_data / "citygml" / "samples" / "citygml4j_lod2_buildings_v3.gml"
    report = ingest_city(path, tmp_path)
    check_counts(report, xpath_counts(str(path)))
    assert report.crs == "EPSG:3068"


@pytest.mark.shared
def test_citygml4j_v100_latin1_needs_crs(shared_data, tmp_path):
    path = shared_data / "citygml" / "samples" / "citygml4j_LOD2_Buildings_v100.gml"
    with pytest.raises(InputError, match="--crs"):
        ingest_city(path, tmp_path / "a")
    report = ingest_city(path, tmp_path / "b", crs="EPSG:2169")
    check_counts(report, xpath_counts(str(path)))
    assert report.crs == "EPSG:2169"
