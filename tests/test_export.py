"""CityGML 3.0 Dynamizer export of a finished run (``vipvflow export dynamizer``).

Every export of the small demo run is validated against the official CityGML 3.0 schemas
(``../shared/data/xsd``, offline; skipped with a reason where that folder is absent), and read
back: the values must be the run's own float64 numbers.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from lxml import etree

from vipvflow.cli import main
from vipvflow.errors import InputError
from vipvflow.outputs import read_dynamizers, reflector_contributions, validate, write_dynamizers
from vipvflow.outputs import dynamizer as dz
from vipvflow.outputs.citygml3 import NSMAP, SCHEMA_LOCATIONS, srs_name, vertical_epsg

SAMPLE_V3 = ("citygml", "samples", "citygml4j_lod2_buildings_v3.gml")
NS = {k: v for k, v in NSMAP.items() if k != "xsi"}
NS_BLDG = {**NS, "bldg": "http://www.opengis.net/citygml/building/3.0"}


@pytest.fixture(scope="module")
def xsd(shared_data):
    root = shared_data / "xsd"
    if not (root / "citygml3-all.xsd").exists():
        pytest.skip(f"official CityGML 3.0 schemas not found at {root}")
    return root


@pytest.fixture(scope="module")
def exports(small_run, tmp_path_factory):
    out = tmp_path_factory.mktemp("dynamizer")
    res = {enc: write_dynamizers(small_run, out / f"twin_{enc}.gml", encoding=enc)
           for enc in ("inline", "tabulated")}
    res["route"] = write_dynamizers(small_run, out / "twin_route.gml", aggregate="route")
    return res


@pytest.fixture(scope="module")
def embedded(small_run, shared_data, tmp_path_factory):
    out = tmp_path_factory.mktemp("embedded")
    return write_dynamizers(small_run, out / "embedded.gml", embed=shared_data.joinpath(*SAMPLE_V3))


def _assert_valid(path, xsd):
    v = validate(path, xsd)
    assert v.errors == [] and v.ok, "\n".join(v.errors[:20])
    return v


# ----------------------------------------------------------------------------- schema
@pytest.mark.parametrize("kind", ["inline", "tabulated", "route"])
def test_exports_validate_against_the_official_schema(exports, xsd, kind):
    v = _assert_valid(exports[kind]["files"][0], xsd)
    # the official URLs of the modules used, each mapped to the local copy of that schema
    assert v.schema_locations == SCHEMA_LOCATIONS


def test_embedded_export_validates_and_keeps_the_buildings(embedded, shared_data, xsd):
    src = shared_data.joinpath(*SAMPLE_V3)
    v = _assert_valid(embedded["files"][0], xsd)
    for ns, url in SCHEMA_LOCATIONS.items():          # added to the input's schemaLocation
        assert v.schema_locations[ns] == url
    before = etree.parse(str(src))
    after = etree.parse(str(embedded["files"][0]))
    ids_before = before.xpath("//bldg:Building/@gml:id", namespaces=NS_BLDG)
    assert len(ids_before) == 100
    assert after.xpath("//bldg:Building/@gml:id", namespaces=NS_BLDG) == ids_before
    n_members = int(before.xpath("count(/core:CityModel/core:cityObjectMember)", namespaces=NS))
    n_roads = int(after.xpath("count(/core:CityModel/core:cityObjectMember/tran:Road)", namespaces=NS))
    n_after = int(after.xpath("count(/core:CityModel/core:cityObjectMember)", namespaces=NS))
    assert n_roads >= 1
    assert n_after == n_members + n_roads + 1 + embedded["surfaces"]     # Roads, network, surfaces
    assert int(after.xpath("count(//tran:TrafficSpace)", namespaces=NS)) == embedded["segments"]


def test_a_broken_document_is_reported_invalid(exports, xsd, tmp_path):
    """The check can fail: the element names of the draft schema the first export followed
    (``dyn:contents`` instead of ``dyn:timeValuePair``), and a wrong schema URL."""
    text = exports["inline"]["files"][0].read_text()
    assert "dyn:timeValuePair>" in text
    broken = tmp_path / "broken.gml"
    broken.write_text(text.replace("dyn:timeValuePair>", "dyn:contents>", 1))
    v = validate(broken, xsd)
    assert not v.ok and any("contents" in e for e in v.errors)
    wrong_url = tmp_path / "wrong_url.gml"
    wrong_url.write_text(text.replace("dynamizer/3.0/dynamizer.xsd", "dynamizer/3.0/dynamiser.xsd", 1))
    v = validate(wrong_url, xsd)
    assert not v.ok and any("dynamiser.xsd" in e for e in v.errors)


# ----------------------------------------------------------------------------- round trip
def _months(sm: pd.DataFrame) -> pd.DataFrame:
    """``month`` as ``YYYY-MM`` (a run writes it as a date, the month's first day)."""
    return sm.assign(month=sm["month"].astype(str).str.slice(0, 7))


def _segment_values(df: pd.DataFrame, tz: str) -> pd.DataFrame:
    seg = df[df["object_id"].str.startswith("vipv_seg_")].copy()
    seg["segment_id"] = seg["object_id"].str.slice(len("vipv_seg_")).astype(np.int64)
    seg["month"] = seg["timestamp"].dt.tz_convert(tz).dt.strftime("%Y-%m")
    return seg.pivot_table(index=["segment_id", "month"], columns="attribute", values="value", aggfunc="first")


@pytest.mark.parametrize("encoding", ["inline", "tabulated"])
def test_values_round_trip_exactly(exports, small_run, encoding):
    df = read_dynamizers(exports[encoding]["files"][0])
    sm = _months(pd.read_parquet(small_run / "segment_month.parquet"))
    wide = _segment_values(df, "Europe/Luxembourg")
    expect = sm.set_index(["segment_id", "month"])[list(dz.SEGMENT_SERIES)].sort_index()
    assert len(wide) == len(expect) == len(sm)
    for col in dz.SEGMENT_SERIES:
        np.testing.assert_array_equal(wide.loc[expect.index, col].to_numpy(), expect[col].to_numpy())
    # the network's hourly pattern
    hp = pd.read_parquet(small_run / "hourly_pattern.parquet").sort_values(["month", "hour"])
    net = df[df["object_id"] == "vipv_network"]
    for col in dz.NETWORK_SERIES:
        got = net[net["attribute"] == col].sort_values("timestamp")
        np.testing.assert_array_equal(got["value"].to_numpy(), hp[col].to_numpy())
        assert list(got["timestamp"].dt.tz_convert("Europe/Luxembourg").dt.hour) == list(hp["hour"])


def test_route_aggregation_sums_the_segments(exports, small_run):
    """One TrafficSpace per route and direction; its values are the sums of segment_month."""
    df = read_dynamizers(exports["route"]["files"][0])
    sm = _months(pd.read_parquet(small_run / "segment_month.parquet"))
    expect = sm.groupby(["route_short_name", "direction_id", "month"])[list(dz.SEGMENT_SERIES)].sum()
    assert exports["route"]["route_directions"] == len(expect.droplevel("month").index.unique())
    for (route, direction, month), row in expect.iterrows():
        oid = f"vipv_route_{dz.xml_id(route)}_dir{direction}"
        got = df[df["object_id"] == oid]
        got = got[got["timestamp"].dt.tz_convert("Europe/Luxembourg").dt.strftime("%Y-%m") == month]
        for col in dz.SEGMENT_SERIES:
            np.testing.assert_allclose(got.loc[got["attribute"] == col, "value"].to_numpy(), [row[col]],
                                       rtol=1e-12)
    tree = etree.parse(str(exports["route"]["files"][0]))
    assert int(tree.xpath("count(//tran:TrafficSpace)", namespaces=NS)) == exports["route"]["route_directions"]
    # one LineString per shape, running the whole shape (the segments' lengths add up)
    seg = pd.read_parquet(small_run / "segments.parquet", columns=["shape_id", "length_m"])
    for ls in tree.iterfind(".//gml:LineString", NS):
        xyz = np.array(ls.findtext("gml:posList", namespaces=NS).split(), float).reshape(-1, 3)
        length = np.linalg.norm(np.diff(xyz[:, :2], axis=0), axis=1).sum()      # length_m is horizontal
        assert any(np.isclose(length, g.sum(), rtol=1e-6) for _, g in seg.groupby("shape_id")["length_m"])
    assert exports["route"]["surfaces"] == 0                      # light default: no reflectors


def test_dynamizer_count_with_plain_xpath(exports, small_run):
    sm = pd.read_parquet(small_run / "segment_month.parquet", columns=["segment_id", "month"])
    n_seg = sm["segment_id"].nunique()
    res = exports["inline"]
    tree = etree.parse(str(res["files"][0]))
    n_dyn = int(tree.xpath("count(//dyn:Dynamizer)", namespaces=NS))
    n_ts = int(tree.xpath("count(//tran:TrafficSpace)", namespaces=NS))
    n_surf = int(tree.xpath("count(//gen:GenericThematicSurface)", namespaces=NS))
    assert n_ts == n_seg == res["segments"]
    assert n_surf == res["surfaces"] > 0
    assert n_dyn == n_seg * len(dz.SEGMENT_SERIES) + len(dz.NETWORK_SERIES) + n_surf == res["dynamizers"]
    per_seg = tree.xpath("//tran:TrafficSpace/core:dynamizer/dyn:Dynamizer", namespaces=NS)
    assert len(per_seg) == n_seg * len(dz.SEGMENT_SERIES)
    # one value per segment, month and series
    pairs = int(tree.xpath("count(//tran:TrafficSpace//dyn:TimeValuePair)", namespaces=NS))
    assert pairs == len(sm) * len(dz.SEGMENT_SERIES)
    # every Dynamizer's attributeRef selects exactly one generic attribute value, of its owner
    gml_id = "{http://www.opengis.net/gml/3.2}id"
    for dyn in tree.iter("{http://www.opengis.net/citygml/dynamizer/3.0}Dynamizer"):
        owner = dyn.getparent().getparent()
        ref = dyn.findtext("dyn:attributeRef", namespaces=NS)
        assert "[@gml:id='" + owner.get(gml_id) + "']" in ref
        assert len(tree.xpath(ref, namespaces=NS)) == 1, ref


def test_crs_is_the_runs_with_the_inputs_vertical_crs(exports, small_run):
    """The demo city is in EPSG:2169 with heights in EPSG:5774 (compound srsName)."""
    tree = etree.parse(str(exports["inline"]["files"][0]))
    env = tree.find("gml:boundedBy/gml:Envelope", NS)
    assert env.get("srsName") == "urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774"
    curves = tree.xpath("//gml:MultiCurve", namespaces=NS)
    assert curves and {c.get("srsName") for c in curves} == {env.get("srsName")}
    assert {c.get("srsDimension") for c in curves} == {"3"}
    # the envelope holds every coordinate
    lo = np.array(env.findtext("gml:lowerCorner", namespaces=NS).split(), float)
    hi = np.array(env.findtext("gml:upperCorner", namespaces=NS).split(), float)
    for pos in tree.iterfind(".//gml:posList", NS):
        xyz = np.array(pos.text.split(), float).reshape(-1, 3)
        assert (xyz >= lo - 1e-9).all() and (xyz <= hi + 1e-9).all()
    assert vertical_epsg("urn:ogc:def:crs,crs:EPSG::25832,crs:EPSG::7837") == 7837
    assert vertical_epsg("urn:ogc:def:crs:EPSG::25832") is None
    assert srs_name(25832) == "urn:ogc:def:crs:EPSG::25832"


# ----------------------------------------------------------------------------- streaming
def test_record_batches_do_not_change_the_file(small_run, tmp_path, monkeypatch):
    """Streamed in batches of 7 rows (a segment's months straddle batches) or in one: the same
    bytes."""
    a = write_dynamizers(small_run, tmp_path / "a.gml", max_segments=120, reflectors=False)
    monkeypatch.setattr(dz, "_BATCH_ROWS", 7)
    b = write_dynamizers(small_run, tmp_path / "b.gml", max_segments=120, reflectors=False)
    assert a["segments"] == b["segments"] == 120
    assert (tmp_path / "a.gml").read_bytes() == (tmp_path / "b.gml").read_bytes()


def test_tables_out_of_segment_order_give_the_same_file(small_run, tmp_path):
    """A run whose segment tables are shuffled is read whole and sorted: the same bytes."""
    import shutil

    import pyarrow as pa
    import pyarrow.parquet as pq

    shuffled = tmp_path / "run"
    shuffled.mkdir()
    for f in ("manifest.json", "hourly_pattern.parquet"):
        shutil.copy(small_run / f, shuffled / f)
    for k, f in enumerate(("segments.parquet", "segment_month.parquet")):
        t = pq.read_table(small_run / f)
        pq.write_table(t.take(pa.array(np.random.default_rng(k).permutation(t.num_rows))), shuffled / f)
    a = write_dynamizers(small_run, tmp_path / "a.gml", max_segments=80, reflectors=False)
    b = write_dynamizers(shuffled, tmp_path / "b.gml", max_segments=80, reflectors=False)
    assert a["segments"] == b["segments"] == 80
    assert (tmp_path / "a.gml").read_bytes() == (tmp_path / "b.gml").read_bytes()


def test_output_is_line_broken(exports):
    with open(exports["inline"]["files"][0], "rb") as fh:
        longest = max(len(line) for line in fh)
    assert longest < 20_000


# ----------------------------------------------------------------------------- selection
def test_selection_of_months_routes_and_segments(small_run, tmp_path):
    res = write_dynamizers(small_run, tmp_path / "sel.gml", months=[6], routes=["1"], max_segments=25,
                           reflectors=False)
    assert res["segments"] == 25 and res["surfaces"] == 0
    df = read_dynamizers(res["files"][0])
    assert df[df["object_id"].str.startswith("vipv_seg_")]["object_id"].nunique() == 25
    with pytest.raises(InputError, match="--months: 7 is not a month of the run"):
        write_dynamizers(small_run, tmp_path / "x.gml", months=[7])
    with pytest.raises(InputError, match="--routes: 99 not in the run"):
        write_dynamizers(small_run, tmp_path / "x.gml", routes=["99"])
    assert not (tmp_path / "x.gml").exists()


def test_reflector_attribution_is_a_share_of_the_reflected_energy(small_run):
    run = dz.load_run(small_run)
    refl = reflector_contributions(run)
    total = pd.read_parquet(small_run / "segment_month.parquet")["pv_kwh_reflected"].sum()
    assert total > 0 and len(refl) > 0
    assert set(refl["surface_type"]) <= {"roof", "wall", "closure", "other"}
    attributed = refl["pv_kwh_reflected"].sum()
    assert 0 < attributed <= total * (1 + 1e-12)
    assert refl["building_id"].notna().all()


def test_reflector_attribution_reads_the_surfaces_the_run_found(small_run):
    """The export credits each group's stored dominant surface (``r{g}_surface``): no ray is
    cast again, so every attributed surface is one of the run's, and a segment's credited
    share never exceeds its groups' weight on surfaces."""
    import re

    from vipvflow.models.mesh import TileMesh
    from vipvflow.store import DataDir, RunDir

    run = dz.load_run(small_run)
    refl = reflector_contributions(run)
    stored = set()
    for f in RunDir(small_run).part_files("geometry"):
        geo = pd.read_parquet(f)
        groups = [int(c[1:-2]) for c in geo.columns if re.fullmatch(r"r\d+_w", c)]
        mesh = TileMesh.load(DataDir(run.data_dir).city.mesh(f.stem.split("=", 1)[1]))
        for g in groups:
            idx = geo.loc[(geo[f"r{g}_w"] > 0) & (geo[f"r{g}_surface"] >= 0), f"r{g}_surface"]
            stored |= set(mesh.surface_ids[idx.to_numpy()])
    assert len(refl) and set(refl["surface_id"]) <= stored


# ----------------------------------------------------------------------------- embedding, CLI
def test_embed_refuses_citygml2(small_run, shared_data, tmp_path):
    with pytest.raises(InputError, match="CityGML 3.0"):
        write_dynamizers(small_run, tmp_path / "x.gml",
                         embed=shared_data / "citygml" / "samples" / "fzk_haus_lod2_v2.gml")


def test_embed_goes_before_appearance_members_and_adds_schema_locations(small_run, tmp_path):
    src = tmp_path / "tiny_v3.gml"
    src.write_text(
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        "<!-- a comment > with a bracket -->\n"
        '<CityModel xmlns="http://www.opengis.net/citygml/3.0" xmlns:gml="http://www.opengis.net/gml/3.2"\n'
        '    xmlns:bldg="http://www.opengis.net/citygml/building/3.0"\n'
        '    xmlns:app="http://www.opengis.net/citygml/appearance/3.0" gml:id="m1">\n'
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
    pairs = root.get("{http://www.w3.org/2001/XMLSchema-instance}schemaLocation").split()
    assert dict(zip(pairs[::2], pairs[1::2])) == SCHEMA_LOCATIONS
    assert root.get("{http://www.opengis.net/gml/3.2}id") == "m1"


def test_cli_prints_one_line_per_file(small_run, tmp_path, capsys):
    rc = main(["export", "dynamizer", str(small_run), "--out", str(tmp_path / "t.gml"),
               "--encoding", "tabulated", "--segments", "10", "--months", "2024-06"])
    assert rc == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("wrote ") and str(tmp_path / "t.gml") in lines[0]
    assert str(tmp_path / "t.csv") in lines[1]
    assert (tmp_path / "t.gml").exists() and (tmp_path / "t.csv").exists()


@pytest.mark.parametrize("argv, message", [
    (["nope"], "run directory not found"),
    (["RUN", "--routes", "L9"], "--routes: L9 not in the run"),
])
def test_cli_bad_input_is_one_line(small_run, tmp_path, capsys, argv, message):
    argv = [str(tmp_path / a) if a == "nope" else str(small_run) if a == "RUN" else a for a in argv]
    rc = main(["export", "dynamizer", *argv, "--out", str(tmp_path / "t.gml")])
    assert rc == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and message in err[0]
    assert not (tmp_path / "t.gml").exists()
