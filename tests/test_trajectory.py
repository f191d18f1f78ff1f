"""Trajectories: GTFS -> hyper-segments, patterns, passes in UTC, driving cycles."""
from __future__ import annotations

import datetime as dt
import json
from pathlib import Path
from zoneinfo import ZoneInfo

import gtfs_kit as gk
import numpy as np
import pandas as pd
import pytest
import shapely
from pyproj import Transformer

from vipvflow.config import CycleCfg, TrajectoryCfg
from vipvflow.models.driving_cycle import driving_cycle, pattern_cycle
from vipvflow.inputs.gtfs import ingest_gtfs, iter_passes, passes_for_trip, service_dates
from vipvflow.inputs.gtfs.segments import build_segments

#: the ground height (m) of feeds ingested without a city model or radiation file
GROUND_M = 0.0

HERE = Path(__file__).resolve().parent
ISRAEL = HERE / "data" / "gtfs" / "israel_route_2126"
LUX = HERE / "data" / "gtfs" / "lux_night"

# gtfs-kit's compute_trip_activity adds one column per date
pytestmark = pytest.mark.filterwarnings("ignore::pandas.errors.PerformanceWarning")


def utc(*args) -> float:
    return dt.datetime(*args, tzinfo=dt.timezone.utc).timestamp()


@pytest.fixture(scope="module")
def israel(tmp_path_factory):
    d = tmp_path_factory.mktemp("israel")
    return d, ingest_gtfs(ISRAEL, d, TrajectoryCfg(ground_elevation_m=GROUND_M))


@pytest.fixture(scope="module")
def lux(tmp_path_factory):
    d = tmp_path_factory.mktemp("lux")
    return d, ingest_gtfs(LUX, d, TrajectoryCfg(ground_elevation_m=GROUND_M), crs="EPSG:2169")


def _read(d, name):
    return pd.read_parquet(Path(d) / "gtfs" / name)


def _check_trip_counts(data_dir, gfeed, year):
    """Trips per service date: ours (calendar + trips.parquet) against gtfs-kit's own."""
    dates = [x for x in gfeed.get_dates() if x.startswith(str(year))]
    assert dates
    act = gk.compute_trip_activity(gfeed, dates)
    theirs = act[dates].sum().rename(index=lambda s: pd.Timestamp(s))
    trips = _read(data_dir, "trips.parquet")
    ours = (trips.merge(service_dates(data_dir, year), on="service_id")
            .groupby("date").size())
    theirs = theirs[theirs > 0]
    pd.testing.assert_series_equal(ours.sort_index(), theirs.sort_index(), check_names=False,
                                   check_dtype=False, check_index_type=False)


def _check_segments(data_dir, gfeed):
    """Sum of segment lengths per shape = projected shape length (0.1 %); all <= 10 m."""
    meta = json.loads((Path(data_dir) / "gtfs" / "feed.json").read_text())
    segs = _read(data_dir, "segments.parquet")
    assert (segs["length_m"] <= 10.0 + 1e-6).all()
    assert segs["segment_id"].tolist() == list(range(len(segs)))
    to_xy = Transformer.from_crs("EPSG:4326", meta["crs"], always_xy=True)
    sh = gfeed.shapes.sort_values(["shape_id", "shape_pt_sequence"])
    used = set(_read(data_dir, "trips.parquet")["shape_id"])
    got = segs.groupby("shape_id")["length_m"].sum()
    assert set(got.index) == used
    for sid, g in sh[sh["shape_id"].isin(used)].groupby("shape_id"):
        x, y = to_xy.transform(g["shape_pt_lon"].to_numpy(), g["shape_pt_lat"].to_numpy())
        length = shapely.LineString(np.column_stack([x, y])).length
        assert got[sid] == pytest.approx(length, rel=1e-3)
        # every segment has the equal share L/n, n = ceil(L / 10)
        n = int(np.ceil(length / 10.0))
        assert (segs["shape_id"] == sid).sum() == n
    # geometry: GeoParquet with CRS, segment ends joined
    import geopandas as gpd
    gseg = gpd.read_parquet(Path(data_dir) / "gtfs" / "segments.parquet")
    assert gseg.crs.to_string() == meta["crs"]
    assert gseg.geometry.has_z.all()
    one = segs[segs["shape_id"] == segs["shape_id"].iloc[0]]
    np.testing.assert_allclose(one["x_end"].to_numpy()[:-1], one["x"].to_numpy()[1:])


def test_israel_feed_real(israel):
    d, report = israel
    gfeed = gk.read_feed(ISRAEL, dist_units="m")
    assert report["counts"]["trips"] == 4 and report["counts"]["shapes"] == 1
    assert report["timezone"] == "Asia/Jerusalem"
    assert report["crs"] == "EPSG:32636"          # local UTM zone of Netanya
    _check_trip_counts(d, gfeed, 2018)
    _check_segments(d, gfeed)
    # the feed's shape_dist_traveled (metres, although gtfs-kit infers km) is used as given
    ps = _read(d, "pattern_stops.parquet")
    st = gfeed.stop_times[gfeed.stop_times["trip_id"] == "435227_230218"]
    np.testing.assert_allclose(ps["dist_m"], st["shape_dist_traveled"].clip(upper=5182.0),
                               atol=5.0)


def test_cairns_feed_real(shared_data, tmp_path):
    path = shared_data / "gtfs" / "cairns_gtfs_kit" / "cairns_gtfs.zip"
    report = ingest_gtfs(path, tmp_path, TrajectoryCfg(ground_elevation_m=GROUND_M))
    gfeed = gk.read_feed(path, dist_units="km")
    c = report["counts"]
    assert (c["trips"], c["shapes"], c["routes"]) == (1339, 54, 22)
    _check_trip_counts(tmp_path, gfeed, 2014)
    _check_segments(tmp_path, gfeed)
    # stops projected onto shapes in order: distances never decrease along a pattern
    ps = _read(tmp_path, "pattern_stops.parquet")
    assert (ps.groupby("pattern_id")["dist_m"].diff().dropna() >= 0).all()
    # a trip's duration on the segments equals its scheduled duration
    trips = _read(tmp_path, "trips.parquet")
    trip = trips.iloc[100]
    p = passes_for_trip(tmp_path, trip["trip_id"], "2014-06-02")
    st = gfeed.stop_times[gfeed.stop_times["trip_id"] == trip["trip_id"]]
    dur = gk.timestr_to_seconds(st["arrival_time"].iloc[-1]) - gk.timestr_to_seconds(
        st["departure_time"].iloc[0])
    assert p["t_utc"].iloc[-1] + p["dt_s"].iloc[-1] - p["t_utc"].iloc[0] == pytest.approx(
        dur, abs=0.01)


def test_frequencies_and_calendar(lux):
    d, report = lux
    gfeed = gk.expand_frequencies(gk.read_feed(LUX, dist_units="m"))
    assert report["counts"]["frequency_trips"] == 4 - 1        # template -> 4 trips
    assert report["counts"]["shapes_built_from_stops"] == 3     # no shapes.txt
    trips = _read(d, "trips.parquet")
    freq = trips[trips["trip_id"].str.startswith("FREQ")].sort_values("start_s")
    assert freq["start_s"].tolist() == [21600, 22500, 23400, 24300]
    sd = service_dates(d, 2024)
    assert (sd["service_id"] == "ALL").sum() == 366 - 1         # leap year, minus 25 Dec
    assert (sd["service_id"] == "WK").sum() == 262 + 1          # weekdays plus Sat 30 Mar
    _check_trip_counts(d, gfeed, 2024)


def _first_last(p):
    return p["t_utc"].iloc[0], p["t_utc"].iloc[-1] + float(p["dt_s"].iloc[-1])


def _check_monotone(p):
    t = p["t_utc"].to_numpy()
    end = t + p["dt_s"].to_numpy(float)
    assert (np.diff(t) >= 0).all()
    np.testing.assert_allclose(end[:-1], t[1:], atol=1e-3)   # segments follow each other
    assert (p["segment_id"].diff().dropna() == 1).all()


def test_trip_across_midnight(lux):
    d, _ = lux
    p = passes_for_trip(d, "NIGHT", "2024-06-15")              # CEST, UTC+2
    first, last = _first_last(p)
    assert first == utc(2024, 6, 15, 21, 50)                  # 23:50 local
    assert last == pytest.approx(utc(2024, 6, 15, 22, 40), abs=1e-3)   # 24:40 = 00:40 next day
    _check_monotone(p)
    # the dwell at S3 (24:15 -> 24:16) lies inside one segment
    assert p["dt_s"].max() >= 60


@pytest.mark.parametrize("date, trip, first, last", [
    # clocks go forward at 02:00 on 31 March: "noon minus 12 h" is 23:00 CET the day before
    ("2024-03-31", "DAY", (2024, 3, 31, 6, 0), (2024, 3, 31, 6, 12)),
    ("2024-03-31", "NIGHT", (2024, 3, 31, 21, 50), (2024, 3, 31, 22, 40)),
    ("2024-03-30", "NIGHT", (2024, 3, 30, 22, 50), (2024, 3, 30, 23, 40)),
    # clocks go back at 03:00 on 27 October: the origin is 01:00 CEST = 23:00 UTC
    ("2024-10-27", "DAY", (2024, 10, 27, 7, 0), (2024, 10, 27, 7, 12)),
    ("2024-10-27", "NIGHT", (2024, 10, 27, 22, 50), (2024, 10, 27, 23, 40)),
    ("2024-10-26", "DAY", (2024, 10, 26, 6, 0), (2024, 10, 26, 6, 12)),
])
def test_dst_days(lux, date, trip, first, last):
    d, _ = lux
    p = passes_for_trip(d, trip, date)
    f, l_ = _first_last(p)
    assert f == utc(*first)
    assert l_ == pytest.approx(utc(*last), abs=1e-3)
    _check_monotone(p)


def test_israel_first_last_times(israel):
    d, _ = israel
    for trip in _read(d, "trips.parquet")["trip_id"]:
        p = passes_for_trip(d, trip, "2018-03-05")             # Asia/Jerusalem, UTC+2
        st = pd.read_csv(ISRAEL / "stop_times.txt", dtype=str)
        st = st[st["trip_id"] == trip]
        f, l_ = _first_last(p)
        assert f == utc(2018, 3, 5) - 7200 + gk.timestr_to_seconds(st["departure_time"].iloc[0])
        assert l_ == pytest.approx(utc(2018, 3, 5) - 7200 + gk.timestr_to_seconds(
            st["arrival_time"].iloc[-1]), abs=1e-3)
        _check_monotone(p)


def _brute_force_passes(d, feed_dir, tile, month):
    """Passes from first principles: a loop over trips, dates and segments."""
    trips = _read(d, "trips.parquet")
    segs = _read(d, "segments.parquet")
    ps = _read(d, "pattern_stops.parquet")
    gfeed = gk.expand_frequencies(gk.read_feed(feed_dir, dist_units="m"))
    st = gfeed.stop_times
    tz = ZoneInfo(json.loads((Path(d) / "gtfs" / "feed.json").read_text())["timezone"])
    period = pd.Period(month, freq="M")
    rows = []
    for day in pd.date_range(period.start_time, period.end_time.normalize(), freq="D"):
        active = set(gk.get_active_services(gfeed, day.strftime("%Y%m%d")))
        noon = dt.datetime(day.year, day.month, day.day, 12, tzinfo=tz)
        origin = noon.timestamp() - 12 * 3600
        for _, trip in trips[trips["service_id"].isin(active)].iterrows():
            times = st[st["trip_id"] == trip["trip_id"]].sort_values("stop_sequence")
            arr = [gk.timestr_to_seconds(x) for x in times["arrival_time"]]
            dep = [gk.timestr_to_seconds(x) for x in times["departure_time"]]
            dist = ps[ps["pattern_id"] == trip["pattern_id"]]["dist_m"].tolist()

            def reach(s):
                if s <= dist[0]:
                    return dep[0]
                for i in range(1, len(dist)):
                    if s <= dist[i]:
                        return dep[i - 1] + (arr[i] - dep[i - 1]) * (s - dist[i - 1]) / (
                            dist[i] - dist[i - 1])
                return arr[-1]

            for _, seg in segs[segs["shape_id"] == trip["shape_id"]].iterrows():
                s0, s1 = seg["cum_dist_m"], seg["cum_dist_m"] + seg["length_m"]
                if s1 <= dist[0] or s0 >= dist[-1] or seg["tile"] != tile:
                    continue
                t0 = reach(max(s0, dist[0]))
                t1 = reach(min(s1, dist[-1]))
                rows.append((seg["segment_id"], trip["trip_id"], day, origin + t0, t1 - t0))
    return pd.DataFrame(rows, columns=["segment_id", "trip_id", "service_date", "t_utc", "dt_s"])


def test_iter_passes_equals_brute_force(lux):
    d, _ = lux
    segs = _read(d, "segments.parquet")
    tile = segs["tile"].value_counts().index[0]
    got = iter_passes(d, tile, "2024-03", 2024)                # holds the DST change
    want = _brute_force_passes(d, LUX, tile, "2024-03")
    assert len(got) == len(want) > 0
    key = ["service_date", "trip_id", "segment_id"]
    got = got.sort_values(key, ignore_index=True)
    want = want.sort_values(key, ignore_index=True)
    assert (got["segment_id"].to_numpy() == want["segment_id"].to_numpy()).all()
    assert (got["trip_id"].astype(str).to_numpy() == want["trip_id"].to_numpy()).all()
    assert (got["service_date"].to_numpy() == want["service_date"].to_numpy()).all()
    np.testing.assert_allclose(got["t_utc"], want["t_utc"], atol=1e-3)
    np.testing.assert_allclose(got["dt_s"], want["dt_s"], atol=1e-3)
    assert got["segment_id"].dtype == np.int64 and got["t_utc"].dtype == np.float64
    assert got["dt_s"].dtype == np.float32 and got["speed_mps"].dtype == np.float32
    # a month holds only its own service dates; another tile has none of these segments
    assert got["service_date"].dt.month.eq(3).all()
    assert iter_passes(d, "E9999N9999", "2024-03").empty


def test_pass_chunks_are_whole_service_days_that_make_up_the_month(lux):
    """A partition's passes a few service days at a time: in order, each chunk whole days
    and at most the budget unless one day alone is more, together iter_passes' frame."""
    from vipvflow.inputs.gtfs import PassChunks

    d, _ = lux
    tile = _read(d, "segments.parquet")["tile"].value_counts().index[0]
    whole = iter_passes(d, tile, "2024-03", 2024)
    per_day = whole.groupby("service_date").size()
    budget = int(per_day.max() * 2.5)
    chunks = PassChunks(d, tile, "2024-03", 2024, max_passes=budget)
    parts = list(chunks)
    assert chunks.n == len(whole) and 3 < len(parts) < len(per_day)
    days = [set(p["service_date"]) for p in parts]
    assert all(not (a & b) for a, b in zip(days, days[1:]))          # no day in two chunks
    assert all(len(p) <= budget or len(days[i]) == 1 for i, p in enumerate(parts))
    # a chunk is as full as the next day allows
    assert all(len(p) + per_day[min(days[i + 1])] > budget for i, p in enumerate(parts[:-1]))
    joined = pd.concat(parts, ignore_index=True)
    pd.testing.assert_frame_equal(joined, whole)
    one_day = list(PassChunks(d, tile, "2024-03", 2024, max_passes=1))
    assert len(one_day) == len(per_day)
    assert PassChunks(d, "E9999N9999", "2024-03").n == 0
    assert not list(PassChunks(d, "E9999N9999", "2024-03"))


# ---- driving cycles ------------------------------------------------------------------------

def _cycle_checks(cyc, stops, length, cfg):
    v, t = cyc["speed_mps"].to_numpy(), cyc["t_s"].to_numpy()
    driven = float(np.sum(0.5 * (v[1:] + v[:-1]) * np.diff(t)))
    # integrated speed over 2 s steps covers the line (trapezoid rule error is small)
    assert driven == pytest.approx(length, rel=0.01)
    assert cyc["dist_m"].iloc[-1] == pytest.approx(stops["dist_m"].iloc[-1], abs=1e-6)
    assert v.max() <= cfg.speed_limit_kmh / 3.6 + 1e-9
    assert np.all(np.diff(cyc["dist_m"]) >= -1e-9)
    assert np.allclose(np.diff(t), cfg.dt_s)


def test_driving_cycle_feasible_schedule(lux):
    d, _ = lux
    cfg = CycleCfg()
    trips = _read(d, "trips.parquet").set_index("trip_id")
    pid = int(trips.loc["DAY", "pattern_id"])
    stops = _read(d, "pattern_stops.parquet").query("pattern_id == @pid")
    segs = _read(d, "segments.parquet")
    length = segs.loc[segs["shape_id"] == trips.loc["DAY", "shape_id"], "length_m"].sum()
    cyc = pattern_cycle(d, pid, cfg)
    assert cyc.attrs["report"]["feasible"] and cyc.attrs["report"]["max_delay_s"] == 0
    _cycle_checks(cyc, stops, length, cfg)
    # arrival at every stop: the first time the cycle is at the stop's distance
    for _, s in stops.iloc[1:].iterrows():
        at = cyc[(cyc["dist_m"] >= s["dist_m"] - 0.01)]
        assert abs(at["t_s"].iloc[0] - s["arr_s"]) <= cfg.dt_s
        assert at["stop"].iloc[0] and at["speed_mps"].iloc[0] == pytest.approx(0, abs=1e-9)
    # it leaves at the scheduled departure (S3 dwells 60 s), or arrival + dwell_s without one
    s3 = stops.iloc[2]
    dwell = cyc[(cyc["dist_m"] - s3["dist_m"]).abs() < 0.01]
    assert dwell["t_s"].iloc[-1] == pytest.approx(s3["dep_s"], abs=cfg.dt_s)
    s2 = stops.iloc[1]
    dwell = cyc[(cyc["dist_m"] - s2["dist_m"]).abs() < 0.01]
    assert dwell["t_s"].iloc[-1] == pytest.approx(s2["arr_s"] + cfg.dwell_s, abs=cfg.dt_s)


def test_driving_cycle_infeasible_reported(lux):
    d, _ = lux
    cfg = CycleCfg()
    trips = _read(d, "trips.parquet").set_index("trip_id")
    pid = int(trips.loc["FAST", "pattern_id"])
    stops = _read(d, "pattern_stops.parquet").query("pattern_id == @pid")
    cyc = pattern_cycle(d, pid, cfg)
    rep = cyc.attrs["report"]
    assert not rep["feasible"] and len(rep["late_legs"]) == 2
    # 4.36 km at <= 50 km/h takes at least 314 s; scheduled 180 s
    vmax = cfg.speed_limit_kmh / 3.6
    assert rep["final_delay_s"] >= stops["dist_m"].iloc[-1] / vmax - 180
    assert cyc["t_s"].iloc[-1] > stops["arr_s"].iloc[-1] + 100
    assert cyc["speed_mps"].max() == pytest.approx(vmax)
    _cycle_checks(cyc, stops, stops["dist_m"].iloc[-1], cfg)


def test_trapezoid_analytic_and_gradient():
    cfg = CycleCfg(dt_s=2.0, max_accel_mps2=1.0, max_decel_mps2=1.0, speed_limit_kmh=72)
    # 1000 m in 100 s with a = b = 1: v^2 - 100 v + 1000 = 0 -> v = 50 - sqrt(1500)
    segs = pd.DataFrame({"cum_dist_m": [0.0, 500.0], "gradient": [0.0, 0.04]})
    cyc = driving_cycle([0.0, 1000.0], [0.0, 100.0], [0.0, 100.0], cfg, segs)
    assert cyc["speed_mps"].max() == pytest.approx(50 - np.sqrt(1500), rel=1e-9)
    assert cyc["t_s"].iloc[-1] == pytest.approx(100.0)
    assert cyc["dist_m"].iloc[-1] == pytest.approx(1000.0)
    assert (cyc.loc[cyc["dist_m"] < 500, "gradient"] == 0).all()
    assert (cyc.loc[cyc["dist_m"] > 500, "gradient"] == 0.04).all()


def test_driving_cycle_timing_mode(tmp_path):
    cfg = TrajectoryCfg(timing="driving_cycle", ground_elevation_m=GROUND_M)
    report = ingest_gtfs(LUX, tmp_path, cfg, crs="EPSG:2169")
    assert any("cannot keep their schedule" in p for p in report["problems"])
    p = passes_for_trip(tmp_path, "DAY", "2024-06-15")        # feasible: same first/last
    f, l_ = _first_last(p)
    assert f == utc(2024, 6, 15, 6, 0)
    assert l_ == pytest.approx(utc(2024, 6, 15, 6, 12), abs=1e-3)
    _check_monotone(p)
    # the cycle brakes to a stop, so the slowest segment is slower than the mean speed
    assert p["speed_mps"].min() < 0.5 * p["speed_mps"].median()


# ---- segments against a known terrain --------------------------------------------------------

class _Plane:
    """Ground rising 2 m per 100 m eastwards, unknown (NaN) west of x = 0."""

    def elevation(self, x, y):
        x = np.asarray(x, float)
        return np.where(x >= 0, 100.0 + 0.02 * x, np.nan)


def test_segments_heading_gradient_terrain():
    # an L-shaped line: 95 m east, then 43 m north
    pts = {"L": np.array([[0.0, 0.0], [95.0, 0.0], [95.0, 43.0]])}
    segs, geom = build_segments(pts, 10.0, 3.2, 500.0, _Plane(), fallback=(300.0, "configured"))
    assert len(segs) == 14 and segs["length_m"].sum() == pytest.approx(138.0)
    east = segs[segs["y_end"] == 0.0]
    north = segs[segs["x"] >= 95.0 - 1e-9]
    assert np.allclose(east["heading_deg"], 90.0) and np.allclose(east["gradient"], 0.02)
    assert np.allclose(north["heading_deg"], 0.0) and np.allclose(north["gradient"], 0.0)
    np.testing.assert_allclose(segs["z"], segs["ground_z"] + 3.2)
    # the piece around the corner keeps the corner vertex
    corner = geom[segs.index[(segs["x"] < 95) & (segs["y_end"] > 0)][0]]
    assert shapely.get_num_coordinates(corner) == 3
    assert (segs["ground_source"] == 0).all()                 # relief
    # NaN ground falls back to the fallback height, said in ground_source; without one the
    # height is unknown (NaN, -1: the ingest refuses it)
    segs2, _ = build_segments({"W": np.array([[-50.0, 0.0], [-10.0, 0.0]])}, 10.0, 3.2, 500.0,
                              _Plane(), fallback=(300.0, "configured"))
    assert (segs2["ground_z"] == 300.0).all() and segs2["tile"].iloc[0] == "E-005N0000"
    assert (segs2["ground_source"] == 3).all()                # configured
    segs3, _ = build_segments({"W": np.array([[-50.0, 0.0], [-10.0, 0.0]])}, 10.0, 3.2, 500.0, _Plane())
    assert segs3["ground_z"].isna().all() and (segs3["ground_source"] == -1).all()


def test_cli_ingest_gtfs(tmp_path, capsys):
    from vipvflow.cli import main

    assert main(["ingest", "gtfs", "--ground-elevation", str(GROUND_M), str(LUX), "--data-dir", str(tmp_path),
                 "--crs", "EPSG:2169"]) == 0
    out = capsys.readouterr().out
    assert "segments 1311" in out and "trips 8" in out and "patterns 4" in out
    assert main(["ingest", "gtfs", "--ground-elevation", str(GROUND_M), str(tmp_path / "missing.zip"), "--data-dir",
                 str(tmp_path)]) == 2


def test_demo_line_segments_and_trips_per_year(tmp_path):
    demo_gtfs = pytest.importorskip("vipvflow.demo.gtfs")
    from vipvflow.demo.layout import build_layout

    # the demo generator's own GTFS writer (what generate_demo writes as demo_gtfs.zip)
    layout = build_layout(seed=42, size="full")
    demo_gtfs.write_gtfs(tmp_path / "demo_gtfs.zip", layout, 2024)
    report = ingest_gtfs(tmp_path / "demo_gtfs.zip", tmp_path, TrajectoryCfg(ground_elevation_m=GROUND_M), crs="EPSG:2169")
    assert report["problems"] == [f"no city model: the ground of all {report['counts']['segments']} "
                                  "segments is trajectory.ground_elevation_m (0.0 m)"]
    segs = _read(tmp_path, "segments.parquet")
    trips = _read(tmp_path, "trips.parquet")
    line1 = trips[trips["route_short_name"] == "1"]
    for shape in line1["shape_id"].unique():
        # an 18 km line: about 1,800 pieces of 10 m per direction (the GTFS coordinates'
        # 7-decimal rounding adds ~1 cm to the length, hence 1,801 pieces of 9.9945 m)
        length = segs.loc[segs["shape_id"] == shape, "length_m"].sum()
        assert length == pytest.approx(18000.0, rel=1e-5)
        n = (segs["shape_id"] == shape).sum()
        assert n == int(np.ceil(length / 10.0)) and abs(n - 1800) <= 1
    per_dir = (line1.merge(service_dates(tmp_path, 2024), on="service_id")
               .groupby("direction_id").size())
    expected = demo_gtfs.trips_per_year("1", 2024)["per_direction"]
    assert {str(k): int(v) for k, v in per_dir.items()} == expected     # 20,570 each way


def test_reingest_replaces_gtfs_folder_as_a_whole(tmp_path):
    """A new ingest swaps a whole new gtfs/ in: nothing of the old folder stays beside the new
    files, and the folder a killed ingest left (its process gone) is removed."""
    import subprocess

    ingest_gtfs(LUX, tmp_path, TrajectoryCfg(ground_elevation_m=GROUND_M), crs="EPSG:2169")
    (tmp_path / "gtfs" / "left-over.parquet").write_bytes(b"old")
    proc = subprocess.Popen(["true"])          # a pid whose process has surely exited
    proc.wait()
    stale = tmp_path / f".gtfs-ingest-{proc.pid}"
    stale.mkdir()
    (stale / "segments.parquet").write_bytes(b"half")
    before = json.loads((tmp_path / "gtfs" / "feed.json").read_text())["counts"]
    ingest_gtfs(LUX, tmp_path, TrajectoryCfg(ground_elevation_m=GROUND_M), crs="EPSG:2169")
    assert not (tmp_path / "gtfs" / "left-over.parquet").exists()
    assert not stale.exists()
    assert json.loads((tmp_path / "gtfs" / "feed.json").read_text())["counts"] == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gtfs"]


def test_month_labels_are_strftime_of_each_date():
    """Months formatted once per distinct date are those of each row's strftime, with the
    same string dtype, missing where the date is."""
    from vipvflow.inputs.gtfs.schedule import month_labels

    dates = pd.Series(pd.to_datetime(["2024-03-31", "2024-04-01", None, "2024-03-31", "2023-12-31"]))
    want = dates.dt.strftime("%Y-%m")
    got = pd.Series(month_labels(dates))
    pd.testing.assert_series_equal(got, want)
    assert got.isna().tolist() == [False, False, True, False, False]
