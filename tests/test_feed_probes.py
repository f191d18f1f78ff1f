"""Hostile and wild input, tried through the CLI as a user would (issues 18, 19, 22).

Every probe builds its bad file in ``tmp_path`` and runs ``vipvflow`` in a subprocess: it
must end either in one line on stderr (exit code 2, no traceback) or in a repair that the
command's output counts.
"""
from __future__ import annotations

import gzip
import json
import resource
import subprocess
import sys
import zipfile
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gtfs_probe_feeds import vbb_like_tables, write_feed

#: the ground height (m) of feeds ingested without a city model or radiation file
GROUND_M = 0.0

HERE = Path(__file__).resolve().parent
# CAMS McClear, 1 min, 60 rows (12:00-13:00 UTC of a declared day): TOA, then the clear-sky
# GHI, BHI, DHI, BNI columns
CAMS_1MIN = HERE / "data" / "cams" / "cams_mcclear_1min_verbose_60rows_pvlib-527fa1c.csv"

pytestmark = pytest.mark.filterwarnings("ignore::pandas.errors.PerformanceWarning")


def vipvflow(*args, cwd=None, timeout=300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "vipvflow.cli", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


def one_line_error(res: subprocess.CompletedProcess, *words: str) -> str:
    """The probe ended in exit code 2 with one stderr line holding *words*."""
    err = res.stderr.strip()
    assert "Traceback" not in res.stderr and "Traceback" not in res.stdout, res.stderr
    assert res.returncode == 2, (res.returncode, res.stdout[-2000:], err[-2000:])
    assert len(err.splitlines()) == 1, err
    for w in words:
        assert w in err, (w, err)
    return err


def repaired(res: subprocess.CompletedProcess, *words: str) -> str:
    """The probe succeeded and its output counts the repair (*words*)."""
    assert "Traceback" not in res.stderr, res.stderr
    assert res.returncode == 0, res.stderr[-2000:]
    for w in words:
        assert w in res.stdout, (w, res.stdout)
    return res.stdout


# ------------------------------------------------------------------------------------ GTFS
def _tables(**changes) -> dict[str, str]:
    t = vbb_like_tables()
    for name, text in changes.items():
        name = name.replace("_txt", ".txt")
        if text is None:
            t.pop(name, None)
        else:
            t[name] = text
    return t


def _backwards(t):
    rows = t["stop_times.txt"].splitlines()
    head, body = rows[0], rows[1:]
    out = []
    for r in body:        # hours run backwards along every trip: 10:00, 09:58, ...
        trip, arr, dep, stop, seq = r.split(",")
        m = 60 * int(arr[:2]) + int(arr[3:5])
        back = 60 * int(arr[:2]) - 2 * (int(seq) - 1)
        new = f"{back // 60:02d}:{back % 60:02d}:00"
        out.append(",".join([trip, new, new, stop, seq]))
        assert m >= 0
    return "\n".join([head] + out) + "\n"


def _arrival_only(t):
    rows = [r.split(",") for r in t["stop_times.txt"].splitlines()]
    return "\n".join(",".join(r[:2] + r[3:]) for r in rows) + "\n"


def _single_point_shapes(t):
    return ("shape_id,shape_pt_lat,shape_pt_lon,shape_pt_sequence\n"
            "SH1,52.5163,13.3777,0\nSH1,52.5163,13.3777,1\nSH2,52.5177,13.3913,0\n")


GTFS_PROBES = {
    # name: (tables, extra CLI args, None for a repair or the error's words, repair words)
    "shapes_named_but_absent": (lambda: _tables(), [], None,
                                ["4 trips name a shape_id but the feed has no shapes.txt",
                                 "shapes 2", "trips 4"]),
    "no_agency": (lambda: _tables(agency_txt=None), [], ["agency.txt is missing", "--timezone"],
                  None),
    "no_agency_timezone_given": (lambda: _tables(agency_txt=None), ["--timezone", "Europe/Berlin"],
                                 None, ["agency.txt is missing; timezone Europe/Berlin as given",
                                        "timezone Europe/Berlin"]),
    "bad_timezone": (lambda: _tables(agency_txt=None), ["--timezone", "Mars/Olympus"],
                     ["--timezone: 'Mars/Olympus' is not an IANA time zone"], None),
    "unknown_route_id": (lambda: _tables(trips_txt=vbb_like_tables()["trips.txt"]
                                         + "R999,WD,T9,SH1,0\n"), [], None,
                         ["1 trips name a route_id missing from routes.txt (R999); dropped",
                          "trips 4"]),
    "single_point_shapes": (lambda: _tables(shapes_txt=_single_point_shapes(None)), [], None,
                            ["fewer than two distinct points", "shapes 2", "trips 4"]),
    "all_trips_backwards": (lambda: _tables(stop_times_txt=_backwards(vbb_like_tables())), [],
                            ["no usable trip", "no later than they leave"], None),
    "arrival_times_only": (lambda: _tables(stop_times_txt=_arrival_only(vbb_like_tables())), [],
                           None, ["16 stop_times give only an arrival", "trips 4"]),
    "stop_at_latitude_999": (lambda: _tables(stops_txt=vbb_like_tables()["stops.txt"].replace(
        "52.5168,13.3822", "999,13.3822")), [], None,
        ["1 stops served by trips have missing or impossible coordinates (e.g. S2); their 4 "
         "stop_times dropped", "trips 4"]),
    "stop_without_coordinates": (lambda: _tables(stops_txt=vbb_like_tables()["stops.txt"].replace(
        "52.5168,13.3822", ",")), [], None, ["1 stops served by trips have missing"]),
    "shape_point_at_infinity": (lambda: _tables(shapes_txt=vbb_like_tables(shapes=True)["shapes.txt"]
                                                + "SH1,inf,13.39,9\n"), [], None,
                                ["1 shape points have missing or impossible coordinates",
                                 "trips 4"]),
    "unreadable_time": (lambda: _tables(stop_times_txt=vbb_like_tables()["stop_times.txt"].replace(
        "08:02:00", "8h02")), [], None, ["1 stop_times have times that are not H:MM:SS", "trips 4"]),
    "calendar_iso_dates": (lambda: _tables(calendar_txt=vbb_like_tables()["calendar.txt"].replace(
        "20240101", "2024-01-01")), [],
        ["calendar.txt line 2: start_date '2024-01-01' is not a date YYYYMMDD"], None),
    "trips_without_routes": (lambda: _tables(trips_txt="route_id,service_id,trip_id\n"
                                             "RX,WD,T1\n"), [], ["no trip left"], None),
}


@pytest.mark.parametrize("name", sorted(GTFS_PROBES))
def test_gtfs_probe(name, tmp_path):
    tables, args, error, repair = GTFS_PROBES[name]
    feed = write_feed(tmp_path / "feed.zip", tables())
    # every route type of the probe feed (bus 3 and 700, tram 900) is kept
    conf = tmp_path / "all_types.yaml"
    conf.write_text("run:\n  route_types: all\n")
    res = vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir",
                   tmp_path / "data", "--config", conf, *args)
    if error is not None:
        one_line_error(res, *error)
        assert not (tmp_path / "data" / "gtfs" / "feed.json").exists()
    else:
        repaired(res, *repair)


def test_shapeless_vbb_like_feed_segments(tmp_path):
    """Trips name shapes, no shapes.txt: the shapes come from the stops, so each is the
    polyline through the four stops (length checked with pyproj's geodesic), cut into
    10 m segments; route types 3, 700 and 900 all kept."""
    from pyproj import Geod

    from gtfs_probe_feeds import STOPS
    from vipvflow.config import TrajectoryCfg
    from vipvflow.inputs.gtfs import ingest_gtfs

    feed = write_feed(tmp_path / "vbb.zip", vbb_like_tables())
    report = ingest_gtfs(feed, tmp_path / "data", TrajectoryCfg(ground_elevation_m=GROUND_M),
                         route_types="all")
    c = report["counts"]
    assert c["shapes_built_from_stops"] == 2 and c["trips"] == 4
    assert c["route_types"] == {"3": 2, "700": 1, "900": 1}
    # buses by default: the tram (900) is dropped and counted
    bus = ingest_gtfs(feed, tmp_path / "bus", TrajectoryCfg(ground_elevation_m=GROUND_M))
    assert bus["counts"]["route_types"] == {"3": 2, "700": 1}
    assert "1 trips of route types [900] outside run.route_types (bus); dropped" in bus["problems"]
    lats, lons = [s[1] for s in STOPS], [s[2] for s in STOPS]
    geodesic = Geod(ellps="WGS84").line_length(lons, lats)
    seg = pd.read_parquet(tmp_path / "data" / "gtfs" / "segments.parquet")
    for _, g in seg.groupby("shape_id"):
        # UTM scale factor near 13.4 E in zone 33 (15 E): within 0.1 % of the geodesic
        assert g["length_m"].sum() == pytest.approx(geodesic, rel=1e-3)
        assert len(g) == int(-(-g["length_m"].sum() // 10.0))


def test_route_types_choose(tmp_path):
    """run.route_types [3, 700] keeps the two bus routes and drops the tram (900)."""
    feed = write_feed(tmp_path / "vbb.zip", vbb_like_tables())
    conf = tmp_path / "c.yaml"
    conf.write_text(yaml.safe_dump({"run": {"route_types": [3, 700]}}))
    res = vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir", tmp_path / "data", "--config", conf)
    repaired(res, "1 trips of route types [900] outside run.route_types ([3, 700]); dropped", "trips 3")
    conf.write_text(yaml.safe_dump({"run": {"route_types": [4]}}))
    one_line_error(vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir", tmp_path / "d2", "--config", conf),
                   "no trip has a route_type in run.route_types ([4]); the feed has [3, 700, 900]")
    conf.write_text(yaml.safe_dump({"run": {"route_types": [99]}}))
    one_line_error(vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir", tmp_path / "d2", "--config", conf),
                   "key 'run.route_types'", "not GTFS route types", "[99]")


def test_frequencies_exact_times(tmp_path):
    """exact_times 1: departures 08:00, 08:10, ... 08:50 (6); exact_times 0: every 20 min
    from 10:00 before 11:00 (3); the headway-based rows are named."""
    from vipvflow.config import TrajectoryCfg
    from vipvflow.inputs.gtfs import ingest_gtfs

    t = vbb_like_tables()
    t["frequencies.txt"] = ("trip_id,start_time,end_time,headway_secs,exact_times\n"
                            "T1,08:00:00,09:00:00,600,1\nT3,10:00:00,11:00:00,1200,0\n")
    report = ingest_gtfs(write_feed(tmp_path / "f.zip", t), tmp_path / "data", TrajectoryCfg(ground_elevation_m=GROUND_M))
    trips = pd.read_parquet(tmp_path / "data" / "gtfs" / "trips.parquet")
    r100 = trips[trips["route_id"] == "R100"]["start_s"].sort_values().to_numpy()
    # T1 expanded to 6 runs, T2 (first departure 09:00:30) kept
    assert list(r100) == [8 * 3600 + 600 * k for k in range(6)] + [9 * 3600 + 30]
    r200 = trips[trips["route_id"] == "R200"]["start_s"].sort_values().to_numpy()
    assert list(r200) == [10 * 3600 + 1200 * k for k in range(3)]
    assert any("1 frequencies.txt rows are headway-based" in p for p in report["problems"])


def test_corrupt_and_truncated_zip(tmp_path):
    good = write_feed(tmp_path / "good.zip", vbb_like_tables(shapes=True))
    data = good.read_bytes()
    cut = tmp_path / "truncated.zip"
    cut.write_bytes(data[: len(data) // 2])
    one_line_error(vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), cut, "--data-dir", tmp_path / "d"), str(cut))
    noise = tmp_path / "noise.zip"
    noise.write_bytes(b"PK\x03\x04" + bytes(range(256)) * 40)
    one_line_error(vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), noise, "--data-dir", tmp_path / "d"), str(noise))
    # a member whose compressed bytes are damaged (CRC / inflate error)
    bad = bytearray(data)
    with zipfile.ZipFile(good) as zf:
        info = zf.getinfo("stop_times.txt")
    start = info.header_offset + 30 + len(info.filename) + 5
    bad[start:start + 40] = b"\xff" * 40
    broken = tmp_path / "broken.zip"
    broken.write_bytes(bytes(bad))
    one_line_error(vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), broken, "--data-dir", tmp_path / "d"), str(broken))


def test_200_mb_stop_times_line(tmp_path):
    """One 200 MB line in stop_times.txt: one line naming it, memory stays low."""
    t = vbb_like_tables()
    feed = tmp_path / "huge.zip"
    with zipfile.ZipFile(feed, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, text in t.items():
            if name != "stop_times.txt":
                zf.writestr(name, text)
        with zf.open("stop_times.txt", "w", force_zip64=True) as fh:
            fh.write(t["stop_times.txt"].encode())
            block = b"9" * (1 << 20)
            for _ in range(200):
                fh.write(block)
            fh.write(b"\n")
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    res = vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir", tmp_path / "d")
    one_line_error(res, "stop_times.txt line 18 is longer than 1024 kB")
    peak_kib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    if peak_kib > before:            # this child set the maximum: it stayed well below 1 GB
        assert peak_kib < 1_000_000


# ------------------------------------------------------------------------------------ CAMS
def _cams_parts():
    lines = CAMS_1MIN.read_text().splitlines(keepends=True)
    return [x for x in lines if x.startswith("#")], [x for x in lines if not x.startswith("#")]


def _scale_rows(body, factor):
    out = []
    for r in body:
        f = r.rstrip("\n").split(";")
        f[1:6] = [f"{float(v) * factor:.4f}" for v in f[1:6]]
        out.append(";".join(f) + "\n")
    return out


def _negative_ghi(body):
    out = []
    for r in body:
        f = r.rstrip("\n").split(";")
        f[2] = f"{-abs(float(f[2])) - 1:.4f}"
        out.append(";".join(f) + "\n")
    return out


def _cams_probe(name: str, path: Path) -> None:
    head, body = _cams_parts()
    if name == "sums_15min_under_1min_header":
        path.write_text("".join(head) + "".join(_scale_rows(body, 15)))
    elif name == "header_15min_over_1min_rows":
        path.write_text("".join(h.replace("0 h 1 min 0 s", "0 h 15 min 0 s") for h in head)
                        + "".join(body))
    elif name == "every_ghi_negative":
        path.write_text("".join(head) + "".join(_negative_ghi(body)))
    elif name == "rows_out_of_order":
        path.write_text("".join(head) + "".join([body[1], body[0]] + body[2:]))
    elif name == "gzip_truncated":
        blob = gzip.compress(("".join(head) + "".join(body)).encode())
        path.write_bytes(blob[: len(blob) // 2])
    elif name == "cut_mid_line":
        text = "".join(head) + "".join(body)
        path.write_text(text[: len(text) - 40])


CAMS_ERRORS = {
    "sums_15min_under_1min_header": ["extraterrestrial", "sums over a longer period"],
    "header_15min_over_1min_rows": ["observation period lasts 1 min", "15 min"],
    "every_ghi_negative": ["negative irradiance"],
    "rows_out_of_order": ["before the previous row"],
    "gzip_truncated": ["not a CAMS"],
    "cut_mid_line": ["last line", "fields", "truncated"],
}


@pytest.mark.parametrize("name", sorted(CAMS_ERRORS))
def test_cams_probe(name, tmp_path):
    f = tmp_path / f"{name}.csv"
    _cams_probe(name, f)
    res = vipvflow("ingest", "cams", f, "--data-dir", tmp_path / "data")
    one_line_error(res, str(f), *CAMS_ERRORS[name])
    assert not (tmp_path / "data" / "radiation" / "radiation.parquet").exists()


def test_cams_short_gap_interpolated_and_counted(tmp_path):
    head, body = _cams_parts()
    f = tmp_path / "gap.csv"
    f.write_text("".join(head) + "".join(body[:10] + body[13:]))      # 12:10..12:12 missing
    out = repaired(vipvflow("ingest", "cams", f, "--data-dir", tmp_path / "data"),
                   "gaps 3", "1 gaps", "gap 2020-06-01 12:10 to 2020-06-01 12:13 UTC (3 min)")
    assert "declared end" in out      # the pvlib sample holds one hour of a declared day
    report = json.loads((tmp_path / "data" / "radiation" / "ingest_report.json").read_text())
    assert report["locations"][0]["gaps"] == [{"start_utc": 1591013400, "end_utc": 1591013580,
                                               "minutes": 3}]


# ------------------------------------------------------------------------------------ runs
def test_year_and_config_refused_in_one_line(tmp_path):
    conf = tmp_path / "c.yaml"
    conf.write_text(yaml.safe_dump({"scenario": "x", "data_dir": str(tmp_path / "d"),
                                    "out_dir": str(tmp_path / "o")}))
    for year in ("99999", "-5"):
        one_line_error(vipvflow("simulate", "--config", conf, "--year", year), f"--year {year}")
        one_line_error(vipvflow("demo-data", "--out", tmp_path / "demo", "--year", year),
                       f"--year {year}")
    conf.write_text(yaml.safe_dump({"city": {"tile_size_m": 0.001}}))
    one_line_error(vipvflow("simulate", "--config", conf, "--year", "2024"),
                   str(conf), "city.tile_size_m", "greater than or equal to 50")
    conf.write_text(yaml.safe_dump({"trajectory": {"segment_length_m": 0.001}}))
    one_line_error(vipvflow("config", "--config", conf), "trajectory.segment_length_m")


@pytest.fixture(scope="module")
def ingested(tmp_path_factory, demo_small):
    """The small demo (2024) ingested into a data dir of its own; a scenario YAML for June
    with demo generation off (the session's demo inputs are never rewritten)."""
    from conftest import write_small_config
    from vipvflow.config import load_config
    from vipvflow.simulation.prepare import ensure_ingested

    root = tmp_path_factory.mktemp("probe_runs")
    path = write_small_config(root, demo_small, months=(6,), name="probe")
    conf = yaml.safe_load(path.read_text())
    conf["demo"]["enabled"] = False
    path.write_text(yaml.safe_dump(conf))
    ensure_ingested(load_config(path), say=lambda *a: None)
    return root, conf


def _variant(ingested, tmp_path, cams=None, **changes) -> Path:
    """A copy of the ingested scenario (data dir copied, so only changed inputs re-ingest)."""
    import shutil

    root, conf = ingested
    conf = json.loads(json.dumps(conf))
    shutil.copytree(root / "data", tmp_path / "data")
    conf["data_dir"], conf["out_dir"] = str(tmp_path / "data"), str(tmp_path / "out")
    if cams is not None:
        conf["inputs"]["cams"] = [str(cams)]
    for key, value in changes.items():
        conf.setdefault(key, {}).update(value)
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(conf))
    return path


def _no_cluster(res) -> None:
    assert "dask dashboard" not in res.stdout and "partitions" not in res.stdout, res.stdout


def test_year_without_service_stops_before_the_cluster(ingested, tmp_path):
    path = _variant(ingested, tmp_path)
    res = vipvflow("simulate", "--config", path, "--year", "2023")
    one_line_error(res, "the GTFS calendar has no service in 2023 (months [6])",
                   "it runs from 2024-01-01 to 2024-12-31")
    _no_cluster(res)
    assert not (tmp_path / "out").exists()


def test_unknown_routes_and_city_elsewhere_stop(ingested, tmp_path):
    path = _variant(ingested, tmp_path, run={"routes": ["R-does-not-exist"]})
    res = vipvflow("simulate", "--config", path, "--year", "2024")
    one_line_error(res, "run.routes", "R-does-not-exist")
    _no_cluster(res)
    # a city model elsewhere: no segment in the area it covers (the real case, a feed and a
    # city model of different places, is test_real_city_e2e.test_lines_that_miss_the_city_model)
    conf = yaml.safe_load(path.read_text())
    conf["run"].pop("routes")
    path.write_text(yaml.safe_dump(conf))
    segs = tmp_path / "data" / "gtfs" / "segments.parquet"
    import geopandas as gpd

    gpd.read_parquet(segs).assign(in_city_model=False).to_parquet(segs)
    res = vipvflow("simulate", "--config", path, "--year", "2024")
    one_line_error(res, "the routes miss the city model", "route-km")
    _no_cluster(res)


def _cams_lines_without(src: Path, dest: Path, drop) -> None:
    """Copy a CAMS CSV leaving out the data rows whose period start satisfies *drop*."""
    with open(src) as fin, open(dest, "w") as fout:
        for line in fin:
            if line.startswith("#") or not drop(line[:10]):
                fout.write(line)


def test_truncated_cams_stops_before_the_cluster(ingested, demo_small, tmp_path):
    """A CAMS file ending 15 June: the June run stops naming the days without radiation."""
    cams = tmp_path / "cams_until_15_june.csv"
    _cams_lines_without(demo_small / "cams_radiation_demo.csv", cams, lambda d: d >= "2024-06-15")
    res = vipvflow("simulate", "--config", _variant(ingested, tmp_path, cams=cams),
                   "--year", "2024")
    err = one_line_error(res, "covers 2024-01-01 00:00 to 2024-06-15 00:00 UTC",
                         "2024-06-15 .. 2024-06-30", "without it")
    _no_cluster(res)
    assert "truncated" in err
    # the ingest said so too: rows end ~200 days before the declared end
    assert "days before the declared end" in res.stdout


def test_day_missing_from_cams_stops_naming_the_gap(ingested, demo_small, tmp_path):
    cams = tmp_path / "cams_without_10_june.csv"
    _cams_lines_without(demo_small / "cams_radiation_demo.csv", cams, lambda d: d == "2024-06-10")
    path = _variant(ingested, tmp_path, cams=cams)
    res = vipvflow("simulate", "--config", path, "--year", "2024")
    one_line_error(res, "gap of 1440 min from 2024-06-10 00:00 to 2024-06-11 00:00 UTC",
                   "radiation.max_gap_minutes = 60")
    _no_cluster(res)


def test_totals_zero_or_undefined_stop(tmp_path):
    """The reduce's last check: no PV energy or a NaN figure stops; strict JSON otherwise."""
    from vipvflow.errors import InputError
    from vipvflow.simulation.reduce import _check_totals

    ok = {"passes": 10, "pv_kwh_driving": 5.0, "fleet_demand_in_service_mwh": 1.0, "coverage": 0.1,
          "irradiation_kwh_m2": {"total_unshaded": 3.0}}
    _check_totals(ok, tmp_path)
    with pytest.raises(InputError, match="pv_kwh_driving is 0.0: no PV energy over 10 passes"):
        _check_totals({**ok, "pv_kwh_driving": 0.0}, tmp_path)
    with pytest.raises(InputError, match="pv_kwh_driving is nan"):
        _check_totals({**ok, "pv_kwh_driving": float("nan")}, tmp_path)
    with pytest.raises(InputError, match=r"undefined figures in the summary: coverage, "
                                         r"irradiation_kwh_m2.total_unshaded"):
        _check_totals({**ok, "coverage": float("inf"),
                       "irradiation_kwh_m2": {"total_unshaded": float("nan")}}, tmp_path)


def test_short_radiation_gap_interpolated_and_counted(ingested, demo_small, tmp_path):
    """30 minutes missing on 12 June at 10:00 UTC (buses run): under the 60 min limit, so
    the run goes on with the gap interpolated and counted (preflight and summary)."""
    from vipvflow.config import load_config
    from vipvflow.simulation.prepare import ensure_ingested, preflight
    from vipvflow.simulation.reduce import _radiation_gaps

    cams = tmp_path / "cams_gap.csv"
    _cams_lines_without(demo_small / "cams_radiation_demo.csv", cams, lambda d: False)
    text = cams.read_text()
    a = text.index("2024-06-12T10:00:00.0/")
    b = text.index("2024-06-12T10:30:00.0/")
    cams.write_text(text[:a] + text[b:])
    cfg = load_config(_variant(ingested, tmp_path, cams=cams))
    said = []
    ensure_ingested(cfg, say=said.append)
    assert any("1 gaps" in s for s in said)
    check = preflight(cfg, 2024, say=said.append)
    assert check["radiation_gaps_interpolated"] == 1
    assert check["radiation_gap_minutes_interpolated"] == 30
    assert check["service_days"] == 30
    assert _radiation_gaps(Path(cfg.data_dir), 2024, [6]) == {
        "radiation_gaps_interpolated": 1, "radiation_gap_minutes_interpolated": 30}
    assert _radiation_gaps(Path(cfg.data_dir), 2024, [7])["radiation_gaps_interpolated"] == 0
