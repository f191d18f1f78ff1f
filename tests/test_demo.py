"""The embedded demo scenario: real formats, closed buildings, a consistent timetable, a
plausible year of sun, and byte-identical output for the same seed."""
from __future__ import annotations

import datetime as dt
import json
from collections import Counter
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import shapely
from lxml import etree
from pyproj import Transformer

from vipvflow.demo import FILES, build_layout, generate_demo
from vipvflow.demo.gtfs import write_gtfs

NS = {"core": "http://www.opengis.net/citygml/2.0",
      "bldg": "http://www.opengis.net/citygml/building/2.0",
      "dem": "http://www.opengis.net/citygml/relief/2.0",
      "gml": "http://www.opengis.net/gml"}
YEAR = 2024


@pytest.fixture(scope="module")
def second_small(tmp_path_factory):
    """A second small generation with the same seed, and what generate_demo returned."""
    out = tmp_path_factory.mktemp("demo_small_again")
    return out, generate_demo(out, year=YEAR, seed=42, size="small")


@pytest.fixture(scope="module")
def layout_doc(demo_small) -> dict:
    return json.loads((demo_small / FILES["layout"]).read_text())


@pytest.fixture(scope="module")
def city(demo_small):
    return etree.parse(str(demo_small / FILES["citygml"]))


def _ring(poslist: str) -> np.ndarray:
    v = np.array(poslist.split(), dtype=float).reshape(-1, 3)
    assert np.array_equal(v[0], v[-1]), "ring not closed"
    return v[:-1]


def _newell(ring: np.ndarray) -> np.ndarray:
    nxt = np.roll(ring, -1, axis=0)
    return np.array([np.sum((ring[:, 1] - nxt[:, 1]) * (ring[:, 2] + nxt[:, 2])),
                     np.sum((ring[:, 2] - nxt[:, 2]) * (ring[:, 0] + nxt[:, 0])),
                     np.sum((ring[:, 0] - nxt[:, 0]) * (ring[:, 1] + nxt[:, 1]))]) / 2


# --------------------------------------------------------------------------- determinism
def test_same_seed_gives_byte_identical_files(demo_small, second_small):
    again, _ = second_small
    for name in FILES.values():
        assert (demo_small / name).read_bytes() == (again / name).read_bytes(), name


# --------------------------------------------------------------------------- CityGML
def test_citygml_counts_match_what_generate_returned(city, second_small):
    counts = second_small[1]["counts"]
    root = city.getroot()
    assert root.tag == f"{{{NS['core']}}}CityModel"
    env = root.find("gml:boundedBy/gml:Envelope", NS)
    assert env.get("srsName") == "urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774"
    n = {k: int(city.xpath(f"count(//bldg:{k})", namespaces=NS))
         for k in ("Building", "RoofSurface", "WallSurface", "GroundSurface")}
    assert n == {"Building": counts["buildings"], "RoofSurface": counts["roof_surfaces"],
                 "WallSurface": counts["wall_surfaces"], "GroundSurface": counts["ground_surfaces"]}
    assert 200 <= n["Building"] <= 1000
    assert n["GroundSurface"] == n["Building"]
    assert int(city.xpath("count(//dem:TINRelief//gml:Triangle)", namespaces=NS)) == counts["terrain_triangles"]
    ids = city.xpath("//@gml:id", namespaces=NS)
    assert len(ids) == len(set(ids))
    # every boundary surface carries one polygon with a gml:id and 3D coordinates
    polys = city.xpath("//bldg:boundedBy/*/bldg:lod2MultiSurface//gml:Polygon", namespaces=NS)
    assert len(polys) == n["RoofSurface"] + n["WallSurface"] + n["GroundSurface"]
    assert all(p.get(f"{{{NS['gml']}}}id") for p in polys)
    assert {p.find(".//gml:posList", NS).get("srsDimension") for p in polys} == {"3"}
    roof_types = Counter(city.xpath("//bldg:roofType/text()", namespaces=NS))
    assert set(roof_types) == {"1000", "1030", "1040"}  # flat, gabled, hipped


def test_buildings_are_closed_shells_with_outward_normals(city):
    for b in city.iterfind(".//bldg:Building", NS):
        rings = {kind: [_ring(p) for p in b.xpath(f"bldg:boundedBy/bldg:{kind}//gml:posList/text()",
                                                 namespaces=NS)]
                 for kind in ("RoofSurface", "WallSurface", "GroundSurface")}
        allr = [r for rs in rings.values() for r in rs]
        edges = Counter()
        for r in allr:
            for a, c in zip(r, np.roll(r, -1, axis=0)):
                edges[(tuple(a), tuple(c))] += 1
        # watertight and consistently oriented: each edge once each way
        assert all(n == 1 for n in edges.values()), b.get(f"{{{NS['gml']}}}id")
        assert all(edges[(c, a)] == 1 for a, c in edges), b.get(f"{{{NS['gml']}}}id")
        centre = np.concatenate(allr).mean(axis=0)
        volume = 0.0
        for r in allr:
            normal = _newell(r)
            assert np.dot(normal, r.mean(axis=0) - centre) > 0  # convex shell: points away
            volume += np.dot(normal, r[0]) / 3.0
        assert volume > 0
        # ground faces down, roofs up, walls vertical
        assert all(_newell(r)[2] < 0 for r in rings["GroundSurface"])
        assert all(_newell(r)[2] > 0 for r in rings["RoofSurface"])
        for r in rings["WallSurface"]:
            nrm = _newell(r)
            assert abs(nrm[2]) < 1e-3 * np.linalg.norm(nrm)
        # volume of the closed shell is at least the footprint times the eaves height
        ground = rings["GroundSurface"][0]
        area = -_newell(ground)[2]
        eaves = min(r[:, 2].min() for r in rings["RoofSurface"]) - ground[0, 2]
        assert volume >= area * eaves * (1 - 1e-6)


def test_buildings_stand_on_the_tin_and_off_the_streets(city, layout_doc):
    tris = np.array([_ring(t) for t in city.xpath("//dem:TINRelief//gml:Triangle//gml:posList/text()",
                                                  namespaces=NS)])
    z = tris[:, :, 2]
    assert 280.0 <= z.min() and z.max() <= 340.0 and z.max() - z.min() > 20.0
    grounds = [_ring(p) for p in city.xpath("//bldg:GroundSurface//gml:posList/text()", namespaces=NS)]
    pts = np.concatenate(grounds)[:, :2]
    # TIN elevation at each ground corner (barycentric in the triangle that holds it)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    det = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (b[:, 1] - a[:, 1])
    tz = np.full(len(pts), np.nan)
    for k, p in enumerate(pts):
        l1 = ((p[0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (c[:, 0] - a[:, 0]) * (p[1] - a[:, 1])) / det
        l2 = ((b[:, 0] - a[:, 0]) * (p[1] - a[:, 1]) - (p[0] - a[:, 0]) * (b[:, 1] - a[:, 1])) / det
        inside = np.flatnonzero((l1 >= -1e-9) & (l2 >= -1e-9) & (l1 + l2 <= 1 + 1e-9))
        t = inside[0]
        tz[k] = a[t, 2] + l1[t] * (b[t, 2] - a[t, 2]) + l2[t] * (c[t, 2] - a[t, 2])
    tz = tz.reshape(len(grounds), -1)
    base = np.array([g[0, 2] for g in grounds])
    assert np.allclose(base, tz.min(axis=1), atol=2e-3)  # base at the lowest terrain point
    # no footprint reaches into a street; the canyon facades line the street edge
    streets = [shapely.Polygon(s["polygon"]) for s in layout_doc["stretches"]]
    prints = shapely.polygons([g[:, :2] for g in grounds])
    hits = shapely.STRtree(shapely.buffer(prints, -0.05)).query(streets, predicate="intersects")
    assert hits.size == 0
    canyon = next(s for s in layout_doc["stretches"] if s["kind"] == "canyon")
    line = shapely.LineString(canyon["centerline"])
    near = shapely.distance(shapely.points(pts), line)
    assert abs(near.min() - canyon["width_m"] / 2) < 0.05
    assert 12.0 <= canyon["width_m"] <= 16.0 and 14.0 <= canyon["building_height_m"] <= 20.0


# --------------------------------------------------------------------------- GTFS
def _seconds(t: pd.Series) -> np.ndarray:
    hms = t.str.split(":", expand=True).astype(int)
    return (hms[0] * 3600 + hms[1] * 60 + hms[2]).to_numpy()


def _trips_per_year_from_calendar(feed, year: int) -> dict:
    cal = feed.calendar.set_index("service_id")
    exc = feed.calendar_dates
    names = ["monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday"]
    days = Counter()
    for day in pd.date_range(f"{year}-01-01", f"{year}-12-31", freq="D"):
        key = day.strftime("%Y%m%d")
        active = {sid for sid, row in cal.iterrows()
                  if row["start_date"] <= key <= row["end_date"] and int(row[names[day.weekday()]])}
        for _, row in exc[exc["date"] == key].iterrows():
            (active.add if int(row["exception_type"]) == 1 else active.discard)(row["service_id"])
        days.update(active)
    trips = feed.trips.merge(feed.routes[["route_id", "route_short_name"]], on="route_id")
    out: dict = {}
    for (line, direction, sid), n in trips.groupby(["route_short_name", "direction_id", "service_id"]).size().items():
        out.setdefault(str(line), Counter())[str(direction)] += int(n) * days[sid]
    return {k: dict(v) for k, v in out.items()}


def test_gtfs_loads_and_is_consistent(demo_small, layout_doc):
    import gtfs_kit as gk

    feed = gk.read_feed(demo_small / FILES["gtfs"], dist_units="m")
    quality = feed.assess_quality().set_index("indicator")["value"]
    assert quality["assessment"] == "good feed"
    assert feed.agency["agency_timezone"].tolist() == ["Europe/Luxembourg"]
    # referential integrity
    assert set(feed.trips["route_id"]) <= set(feed.routes["route_id"])
    assert set(feed.trips["shape_id"]) <= set(feed.shapes["shape_id"])
    assert set(feed.stop_times["trip_id"]) == set(feed.trips["trip_id"])
    assert set(feed.stop_times["stop_id"]) <= set(feed.stops["stop_id"])
    assert set(feed.trips["service_id"]) <= set(feed.calendar["service_id"])
    assert feed.trips["block_id"].notna().all() and feed.trips["direction_id"].isin([0, 1]).all()

    st = feed.stop_times.sort_values(["trip_id", "stop_sequence"])
    arr, dep = _seconds(st["arrival_time"]), _seconds(st["departure_time"])
    same = st["trip_id"].to_numpy()[1:] == st["trip_id"].to_numpy()[:-1]
    assert (dep >= arr).all() and (arr[1:][same] > dep[:-1][same]).all()
    assert (np.diff(st["shape_dist_traveled"].to_numpy())[same] > 0).all()
    assert dep.max() > 24 * 3600  # the last trips run past midnight

    line = layout_doc["lines"][0]
    length = line["length_m"]["0"]
    # one trip takes the line length at 20 km/h including dwell, give or take rounding
    g = st.assign(a=arr, d=dep).groupby("trip_id")
    duration = g["a"].max() - g["d"].min()
    assert np.allclose(duration, length / (20 / 3.6), atol=1.0)
    assert np.allclose(g["shape_dist_traveled"].max(), length, atol=0.01)
    assert (g.size() == line["n_stops"]).all()

    # shapes: along the street centre line, dense, as long as the layout says
    to_luref = Transformer.from_crs("EPSG:4326", "EPSG:2169", always_xy=True)
    centre = shapely.LineString(line["centerline"])
    for d in ("0", "1"):
        shp = feed.shapes[feed.shapes["shape_id"] == line["shape_ids"][d]].sort_values("shape_pt_sequence")
        x, y = to_luref.transform(shp["shape_pt_lon"].to_numpy(), shp["shape_pt_lat"].to_numpy())
        step = np.hypot(np.diff(x), np.diff(y))
        assert step.max() <= 25.0
        assert abs(step.sum() - line["length_m"][d]) < 0.5
        assert shapely.distance(shapely.points(x, y), centre).max() < 0.05

    # blocks: a bus alternates directions, leaving where it arrived after a layover
    trips = feed.trips.set_index("trip_id")
    first = st.groupby("trip_id").first()
    last = st.groupby("trip_id").last()
    for _, block in trips.groupby("block_id"):
        ids = _seconds(first.loc[block.index, "departure_time"]).argsort()
        seq = block.index[ids]
        for p, q in zip(seq[:-1], seq[1:]):
            assert trips.loc[p, "direction_id"] != trips.loc[q, "direction_id"]
            assert (_seconds(first.loc[[q], "departure_time"])[0]
                    - _seconds(last.loc[[p], "arrival_time"])[0]) >= 300
            assert (feed.stops.set_index("stop_id").loc[first.loc[q, "stop_id"], ["stop_lat", "stop_lon"]].tolist()
                    == feed.stops.set_index("stop_id").loc[last.loc[p, "stop_id"], ["stop_lat", "stop_lon"]].tolist())


def test_trips_per_year_from_calendar_match_layout(demo_small, layout_doc):
    import gtfs_kit as gk

    feed = gk.read_feed(demo_small / FILES["gtfs"], dist_units="m")
    counted = _trips_per_year_from_calendar(feed, YEAR)
    expected = {ln["route_short_name"]: ln["trips_per_year"] for ln in layout_doc["lines"]}
    assert counted == expected
    # holidays run the Sunday service: Easter Monday 2024 (1 April) has the trips of a Sunday
    act = feed.compute_trip_activity(["20240401", "20240402", "20240331"])
    n = act[["20240401", "20240402", "20240331"]].sum()
    assert n["20240401"] == n["20240331"] < n["20240402"]


def test_full_layout_line_1_is_about_18_km(tmp_path):
    layout = build_layout(seed=42, size="full")
    line1 = layout.lines[0]
    assert line1.name == "1" and abs(line1.length_m - 18000.0) <= 1000.0
    assert {s.kind for s in line1.stretches} == {"canyon", "suburban", "open"}
    # the lines cross in the town centre
    assert shapely.LineString(line1.xy).distance(shapely.Point(77000, 75000)) < 1.0
    assert shapely.LineString(layout.lines[1].xy).distance(shapely.Point(77000, 75000)) < 1.0
    # the written feed says the same, and line 1 runs on the order of 41,000 trips a year
    import gtfs_kit as gk

    write_gtfs(tmp_path / "full.zip", layout, YEAR)
    feed = gk.read_feed(tmp_path / "full.zip", dist_units="m")
    shp = feed.shapes[feed.shapes["shape_id"] == "L1_d0"]
    assert abs(shp["shape_dist_traveled"].max() - 18000.0) <= 1000.0
    counted = _trips_per_year_from_calendar(feed, YEAR)
    assert 38000 <= sum(counted["1"].values()) <= 44000


# --------------------------------------------------------------------------- CAMS
def test_cams_file_reads_with_pvlib_and_has_a_plausible_year(demo_small):
    from pvlib.iotools import read_cams

    data, meta = read_cams(demo_small / FILES["cams"], integrated=True)
    assert len(data) == 527040  # 366 days of minutes
    assert meta["time_step"] == "1min"
    assert abs(meta["latitude"] - 49.61) < 0.01 and abs(meta["longitude"] - 6.13) < 0.01
    assert 270 <= meta["altitude"] <= 345
    assert data.index[0] == pd.Timestamp("2024-01-01", tz="UTC")
    assert ((data.index[1:] - data.index[:-1]) == pd.Timedelta(minutes=1)).all()
    kwh = data[["ghi", "ghi_clear", "bhi", "dhi"]].sum() / 1000
    assert 1000 <= kwh["ghi"] <= 1200
    assert 1450 <= kwh["ghi_clear"] <= 1700
    assert np.allclose(data["ghi"], data["bhi"] + data["dhi"], atol=2e-4)
    assert (data["ghi"] <= data["ghi_clear"] + 1e-4).all()
    assert (data.loc[data["ghi_extra"] == 0, ["ghi", "ghi_clear", "dni"]] == 0).all().all()
    # more sun in summer than in winter, and a clear June noon near 800-950 W/m2
    monthly = data["ghi"].resample("MS").sum()
    assert monthly.iloc[5] > 4 * monthly.iloc[11]
    w, _ = read_cams(demo_small / FILES["cams"])  # W/m2
    noon = w.loc["2024-06-21 11:45":"2024-06-21 12:15", "ghi_clear"]
    assert 800 <= noon.mean() <= 1000


# --------------------------------------------------------------------------- CLI
def test_cli_registers_demo_data():
    from vipvflow.cli import build_parser

    args = build_parser().parse_args(["demo-data", "--year", "2024"])
    assert args.out == Path("data/demo/input") and args.seed == 42 and args.size == "full"
    assert callable(args.func)
    with pytest.raises(SystemExit):
        build_parser().parse_args(["demo-data"])  # --year is required
