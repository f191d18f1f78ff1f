"""CityGML 3.0 Dynamizer export of a finished run (``vipvflow export dynamizer``).

The CityGML 3.0 XSDs are not available offline, so the structure is checked against the
content model written down in docs/dynamizer.md (the ``CONTENT`` table below).
"""
from __future__ import annotations

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
from lxml import etree

from vipvflow.cli import main
from vipvflow.export import read_dynamizers, reflector_contributions, write_dynamizers
from vipvflow.export.dynamizer import NETWORK_SERIES, NSMAP, SEGMENT_SERIES, load_run

C, DYN, GEN, TRAN, GML = (NSMAP[k] for k in ("core", "dyn", "gen", "tran", "gml"))


def q(name: str) -> str:
    p, n = name.split(":")
    return f"{{{NSMAP[p]}}}{n}"


# Content model (docs/dynamizer.md): for each element, its allowed children in schema order
# and the ones that are required.  Inherited properties come first (gml:AbstractFeature,
# core:AbstractCityObject, core:AbstractSpace, ...), then the type's own.
GML_FEATURE = ["gml:description", "gml:identifier", "gml:name", "gml:boundedBy"]
CITY_OBJECT = GML_FEATURE + ["core:externalReference", "core:generalizesTo", "core:relativeToTerrain",
                             "core:relativeToWater", "core:relatedTo", "core:appearance",
                             "core:genericAttribute", "core:dynamizer"]
SPACE = ["core:spaceType", "core:volume", "core:area", "core:lod2MultiCurve", "core:lod3MultiSurface",
         "core:lod0MultiSurface", "core:lod1Solid", "core:lod3Solid", "core:boundary",
         "core:lod0MultiCurve", "core:lod2Solid", "core:lod0Point", "core:lod3MultiCurve",
         "core:lod2MultiSurface"]
TIMESERIES = GML_FEATURE + ["dyn:firstTimestamp", "dyn:lastTimestamp"]
ATOMIC = TIMESERIES + ["dyn:observationProperty", "dyn:uom", "dyn:valueType"]
CONTENT = {
    "core:CityModel": (GML_FEATURE + ["core:engineeringCRS", "core:cityObjectMember", "core:appearanceMember",
                                      "core:featureMember", "core:versionMember",
                                      "core:versionTransitionMember"], []),
    "tran:Road": (CITY_OBJECT + SPACE + ["tran:trafficDirection", "tran:occupancy", "tran:trafficSpace",
                                         "tran:auxiliaryTrafficSpace", "tran:hole", "tran:marking",
                                         "tran:class", "tran:function", "tran:usage", "tran:section",
                                         "tran:intersection"], []),
    "tran:TrafficSpace": (CITY_OBJECT + SPACE + ["core:lod1TerrainIntersectionCurve", "core:pointCloud",
                                                 "core:lod3TerrainIntersectionCurve",
                                                 "core:lod2TerrainIntersectionCurve",
                                                 "tran:function", "tran:usage", "tran:granularity",
                                                 "tran:trafficDirection", "tran:occupancy", "tran:predecessor",
                                                 "tran:successor", "tran:clearanceSpace"],
                          ["core:lod0MultiCurve", "tran:granularity"]),
    "gen:GenericLogicalSpace": (CITY_OBJECT + SPACE + ["gen:class", "gen:function", "gen:usage"], []),
    "gen:GenericThematicSurface": (CITY_OBJECT + ["core:area", "core:lod3MultiSurface", "core:lod2MultiSurface",
                                                  "core:lod0MultiSurface", "core:lod0MultiCurve",
                                                  "core:lod1MultiSurface", "core:pointCloud",
                                                  "gen:class", "gen:function", "gen:usage"], []),
    "dyn:Dynamizer": (GML_FEATURE + ["core:creationDate", "core:terminationDate", "core:validFrom",
                                     "core:validTo", "dyn:attributeRef", "dyn:startTime", "dyn:endTime",
                                     "dyn:dynamicData", "dyn:sensorConnection"],
                      ["dyn:attributeRef", "dyn:startTime", "dyn:endTime"]),
    "dyn:GenericTimeseries": (ATOMIC + ["dyn:contents"], ["dyn:observationProperty", "dyn:valueType",
                                                          "dyn:contents"]),
    "dyn:TabulatedFileTimeseries": (ATOMIC + [
        "dyn:fileLocation", "dyn:fileType", "dyn:mimeType", "dyn:numberOfHeaderLines", "dyn:fieldSeparator",
        "dyn:recordSeparator", "dyn:decimalSymbol", "dyn:idColumnNo", "dyn:idColumnName", "dyn:idValue",
        "dyn:timeColumnNo", "dyn:timeColumnName", "dyn:timeFormat", "dyn:valueColumnNo",
        "dyn:valueColumnName"], ["dyn:observationProperty", "dyn:valueType", "dyn:fileLocation",
                                 "dyn:fileType", "dyn:fieldSeparator"]),
    "dyn:TimeValuePair": (["dyn:timestamp", "dyn:intValue", "dyn:doubleValue", "dyn:stringValue",
                           "dyn:geometryValue", "dyn:uriValue", "dyn:boolValue",
                           "dyn:implicitGeometryValue", "dyn:appearanceValue"], ["dyn:timestamp"]),
    "gen:DoubleAttribute": (["gen:name", "gen:value"], ["gen:name", "gen:value"]),
    "gen:StringAttribute": (["gen:name", "gen:value"], ["gen:name", "gen:value"]),
    "gen:IntAttribute": (["gen:name", "gen:value"], ["gen:name", "gen:value"]),
    "gml:LineString": (GML_FEATURE[:3] + ["gml:posList"], ["gml:posList"]),
}
#: property elements that hold exactly one object of the given kinds
PROPERTY = {"core:cityObjectMember": None, "core:dynamizer": ["dyn:Dynamizer"],
            "dyn:dynamicData": ["dyn:GenericTimeseries", "dyn:TabulatedFileTimeseries"],
            "dyn:contents": ["dyn:TimeValuePair"], "tran:trafficSpace": ["tran:TrafficSpace"],
            "core:genericAttribute": ["gen:DoubleAttribute", "gen:StringAttribute", "gen:IntAttribute"]}


@pytest.fixture(scope="module")
def exports(small_run, tmp_path_factory):
    out = tmp_path_factory.mktemp("dynamizer")
    res = {enc: write_dynamizers(small_run, out / f"twin_{enc}.gml", encoding=enc)
           for enc in ("inline", "tabulated")}
    return res


def _check_content(el, path: str) -> int:
    """Recursively check *el* against CONTENT / PROPERTY; returns the number of elements checked."""
    name = etree.QName(el)
    key = f"{[k for k, v in NSMAP.items() if v == name.namespace][0]}:{name.localname}"
    n = 0
    if key in CONTENT:
        allowed, required = CONTENT[key]
        pos = -1
        seen = []
        for child in el:
            cq = etree.QName(child)
            ck = f"{[k for k, v in NSMAP.items() if v == cq.namespace][0]}:{cq.localname}"
            assert ck in allowed, f"{path}/{key}: {ck} not allowed here"
            i = allowed.index(ck)
            assert i >= pos, f"{path}/{key}: {ck} after {allowed[pos]} breaks the order"
            pos = i
            seen.append(ck)
        for r in required:
            assert r in seen, f"{path}/{key}: required {r} missing"
        if key == "dyn:Dynamizer":   # the dynamic data (or a sensor connection) must be there
            assert "dyn:dynamicData" in seen
        if key == "dyn:TimeValuePair":
            assert len(seen) == 2, f"{path}: a TimeValuePair holds a timestamp and one value"
        n += 1
    elif key in PROPERTY:
        kids = list(el)
        assert len(kids) == 1, f"{path}/{key}: a property holds one object"
        if PROPERTY[key] is not None:
            ck = etree.QName(kids[0])
            assert f"{[k for k, v in NSMAP.items() if v == ck.namespace][0]}:{ck.localname}" in PROPERTY[key]
    for child in el:
        if etree.QName(child).namespace in NSMAP.values():
            n += _check_content(child, f"{path}/{key}")
    return n


@pytest.mark.parametrize("encoding", ["inline", "tabulated"])
def test_structure_follows_content_model(exports, encoding):
    path = exports[encoding]["files"][0]
    root = etree.parse(str(path)).getroot()          # well-formed
    assert root.tag == q("core:CityModel")
    checked = _check_content(root, "")
    assert checked > 1000
    # every Dynamizer points at a generic attribute of the city object that holds it
    for dyn in root.iter(q("dyn:Dynamizer")):
        owner = dyn.getparent().getparent()
        ref = dyn.findtext(q("dyn:attributeRef"))
        assert f"[@gml:id='{owner.get(q('gml:id'))}']" in ref
        target = owner.xpath(ref.split("']/", 1)[1], namespaces=NSMAP)
        assert len(target) == 1, ref
    # 3D LineStrings in the run's CRS
    ls = root.find(f".//{q('gml:LineString')}")
    assert ls.get("srsDimension") == "3" and ls.get("srsName").endswith("/EPSG/0/2169")
    assert len(ls.findtext(q("gml:posList")).split()) % 3 == 0


@pytest.mark.parametrize("encoding", ["inline", "tabulated"])
def test_values_round_trip_exactly(exports, small_run, encoding):
    df = read_dynamizers(exports[encoding]["files"][0])
    sm = gpd.read_parquet(small_run / "segment_month.parquet")
    seg = df[df["object_id"].str.startswith("vipv_seg_")].copy()
    seg["segment_id"] = seg["object_id"].str.slice(len("vipv_seg_")).astype(np.int64)
    seg["month"] = seg["timestamp"].dt.tz_convert("Europe/Luxembourg").dt.date  # months are dates
    wide = seg.pivot_table(index=["segment_id", "month"], columns="attribute", values="value",
                           aggfunc="first")
    expect = sm.set_index(["segment_id", "month"])[list(SEGMENT_SERIES)].sort_index()
    assert len(wide) == len(expect) == len(sm)
    for col in SEGMENT_SERIES:
        np.testing.assert_array_equal(wide.loc[expect.index, col].to_numpy(), expect[col].to_numpy())
    # the network's hourly pattern
    hp = pd.read_parquet(small_run / "hourly_pattern.parquet").sort_values(["month", "hour"])
    net = df[df["object_id"] == "vipv_network"]
    for col in NETWORK_SERIES:
        got = net[net["attribute"] == col].sort_values("timestamp")["value"].to_numpy()
        np.testing.assert_array_equal(got, hp[col].to_numpy())
        hours = net[net["attribute"] == col].sort_values("timestamp")["timestamp"]
        assert list(hours.dt.tz_convert("Europe/Luxembourg").dt.hour) == list(hp["hour"])


def test_dynamizer_count_with_plain_xpath(exports, small_run):
    sm = pd.read_parquet(small_run / "segment_month.parquet", columns=["segment_id"])
    n_seg = sm["segment_id"].nunique()
    res = exports["inline"]
    tree = etree.parse(str(res["files"][0]))
    ns = NSMAP
    n_dyn = int(tree.xpath("count(//dyn:Dynamizer)", namespaces=ns))
    n_ts = int(tree.xpath("count(//tran:TrafficSpace)", namespaces=ns))
    n_surf = int(tree.xpath("count(//gen:GenericThematicSurface)", namespaces=ns))
    assert n_ts == n_seg == res["segments"]
    assert n_surf == res["surfaces"]
    assert n_dyn == n_seg * len(SEGMENT_SERIES) + len(NETWORK_SERIES) + n_surf == res["dynamizers"]
    per_seg = tree.xpath("//tran:TrafficSpace/core:dynamizer/dyn:Dynamizer", namespaces=ns)
    assert len(per_seg) == n_seg * len(SEGMENT_SERIES)
    # one series per Dynamizer, one value per month of the run
    months = pd.read_parquet(small_run / "segment_month.parquet", columns=["month"])["month"].nunique()
    pairs = tree.xpath("//tran:TrafficSpace//dyn:TimeValuePair", namespaces=ns)
    assert len(pairs) == n_seg * len(SEGMENT_SERIES) * months


def test_reflector_attribution_is_a_share_of_the_reflected_energy(small_run):
    run = load_run(small_run)
    refl = reflector_contributions(run)
    total = run.segment_month["pv_kwh_reflected"].sum()
    assert total > 0 and len(refl) > 0
    assert set(refl["surface_type"]) <= {"roof", "wall", "closure", "other"}
    attributed = refl["pv_kwh_reflected"].sum()
    assert 0 < attributed <= total * (1 + 1e-12)
    assert refl["building_id"].notna().all()


def test_embed_into_citygml3_keeps_buildings(small_run, shared_data, tmp_path):
    src = shared_data / "citygml" / "samples" / "citygml4j_lod2_buildings_v3.gml"
    ns = {**NSMAP, "bldg": "http://www.opengis.net/citygml/building/3.0"}
    before = etree.parse(str(src))
    n_bldg = int(before.xpath("count(//bldg:Building)", namespaces=ns))
    n_members = int(before.xpath("count(/core:CityModel/core:cityObjectMember)", namespaces=ns))
    assert n_bldg == 100
    res = write_dynamizers(small_run, tmp_path / "embedded.gml", embed=src, max_segments=40)
    after = etree.parse(str(res["files"][0]))
    assert int(after.xpath("count(//bldg:Building)", namespaces=ns)) == n_bldg
    ids_before = before.xpath("//bldg:Building/@gml:id", namespaces=ns)
    assert after.xpath("//bldg:Building/@gml:id", namespaces=ns) == ids_before
    assert int(after.xpath("count(//tran:TrafficSpace)", namespaces=ns)) == res["segments"] == 40
    n_after = int(after.xpath("count(/core:CityModel/core:cityObjectMember)", namespaces=ns))
    n_roads = int(after.xpath("count(/core:CityModel/core:cityObjectMember/tran:Road)", namespaces=ns))
    assert n_roads >= 1
    assert n_after == n_members + n_roads + 1 + res["surfaces"]     # Roads, the network, surfaces
    _check_content(after.getroot().xpath("/core:CityModel/core:cityObjectMember/tran:Road",
                                         namespaces=ns)[0], "")
    df = read_dynamizers(res["files"][0])
    assert df[df["object_id"].str.startswith("vipv_seg_")]["object_id"].nunique() == 40


def test_embed_refuses_citygml2(small_run, shared_data, tmp_path):
    from vipvflow.errors import InputError

    with pytest.raises(InputError, match="CityGML 3.0"):
        write_dynamizers(small_run, tmp_path / "x.gml",
                         embed=shared_data / "citygml" / "samples" / "fzk_haus_lod2_v2.gml")


def test_cli_prints_one_line_per_file(small_run, tmp_path, capsys):
    rc = main(["export", "dynamizer", str(small_run), "--out", str(tmp_path / "t.gml"),
               "--encoding", "tabulated", "--segments", "10"])
    assert rc == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("wrote ") and str(tmp_path / "t.gml") in lines[0]
    assert str(tmp_path / "t.csv") in lines[1]
    assert (tmp_path / "t.gml").exists() and (tmp_path / "t.csv").exists()


def test_cli_missing_run_dir_is_one_line(tmp_path, capsys):
    rc = main(["export", "dynamizer", str(tmp_path / "nope"), "--out", str(tmp_path / "t.gml")])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "run directory not found" in err[0]
    assert not (tmp_path / "t.gml").exists()


def test_embed_goes_before_appearance_members(small_run, tmp_path):
    """CityModel content order: every cityObjectMember before the appearanceMembers."""
    src = tmp_path / "tiny_v3.gml"
    src.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<CityModel xmlns="http://www.opengis.net/citygml/3.0" xmlns:gml="http://www.opengis.net/gml/3.2"\n'
        '    xmlns:bldg="http://www.opengis.net/citygml/building/3.0"\n'
        '    xmlns:app="http://www.opengis.net/citygml/appearance/3.0">\n'
        '  <cityObjectMember><bldg:Building gml:id="b1"/></cityObjectMember>\n'
        '  <appearanceMember><app:Appearance gml:id="a1"><app:theme>t</app:theme></app:Appearance>'
        '</appearanceMember>\n'
        '</CityModel>\n')
    res = write_dynamizers(small_run, tmp_path / "out.gml", embed=src, max_segments=3)
    root = etree.parse(str(res["files"][0])).getroot()
    kinds = [etree.QName(c).localname for c in root]
    assert kinds[-1] == "appearanceMember"
    assert kinds.count("cityObjectMember") == 1 + 1 + 1 + res["surfaces"]
    assert res["segments"] == 3
