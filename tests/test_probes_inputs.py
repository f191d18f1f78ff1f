"""Issue 37: inputs a careless user gives, tried through the CLI as the user would.

Each probe ends in one line on stderr naming the file and what is wrong (exit code 2, no
traceback) or in a repair the command's output counts; numbers refer to the issue's list:
duplicated GTFS rows (8 and the MergeError), stop times beyond a service day (4, the 89 GiB
ArrayMemoryError), a city model forced into a CRS of another place (5) and a feed of another
place than the city model's CRS, a radiation file located elsewhere (2), GHI and DHI swapped
(3), encodings and unreadable values in GTFS and CAMS files.
"""
from __future__ import annotations

import zipfile
from pathlib import Path

import pandas as pd
import pytest
import yaml

from gtfs_probe_feeds import vbb_like_tables, write_feed
from test_feed_probes import (CAMS_1MIN, GROUND_M, ingested, one_line_error,  # noqa: F401
                              repaired, vipvflow, _variant)

pytestmark = pytest.mark.filterwarnings("ignore::pandas.errors.PerformanceWarning")


def _ingest_gtfs(feed: Path, tmp_path: Path, *args) -> object:
    return vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M), feed, "--data-dir",
                    tmp_path / "data", *args)


def _with_row(tables: dict, name: str, row: int) -> dict:
    """*tables* with data row *row* (1 = the first after the header) of *name* repeated at
    the end of the table."""
    lines = tables[name].splitlines()
    return {**tables, name: "\n".join(lines + [lines[row]]) + "\n"}


# ------------------------------------------------------------------------------ GTFS
@pytest.mark.parametrize("table,row,words", [
    ("routes.txt", 1, "routes.txt: 1 rows repeat the route_id of an earlier row (1 of them "
                      "identical to it; first: route_id R100 at line 5)"),
    ("trips.txt", 2, "trips.txt: 1 rows repeat the trip_id of an earlier row (1 of them identical "
                     "to it; first: trip_id T2 at line 6)"),
    ("stop_times.txt", 3, "stop_times.txt: 1 rows repeat the trip_id and stop_sequence of an "
                          "earlier row (1 of them identical to it; first: trip_id T1, "
                          "stop_sequence 3 at line 18)"),
])
def test_duplicated_rows_first_kept_and_counted(table, row, words, tmp_path):
    """Issue items 8 and the MergeError: a repeated route, trip or stop time is dropped (the
    first row kept), counted, and the ingested timetable equals the clean feed's (before, a
    repeated route doubled its trips and the reduce failed on their merge; a repeated stop
    time changed the demand)."""
    clean = vbb_like_tables()
    out = repaired(_ingest_gtfs(write_feed(tmp_path / "dup.zip", _with_row(clean, table, row)),
                                tmp_path, "--config", _all_types(tmp_path)), words, "trips 4")
    assert "the first row kept, the others dropped" in out
    vipvflow("ingest", "gtfs", "--ground-elevation", str(GROUND_M),
             write_feed(tmp_path / "clean.zip", clean), "--data-dir", tmp_path / "clean",
             "--config", _all_types(tmp_path))
    for name in ("trips", "patterns", "pattern_stops"):
        got = pd.read_parquet(tmp_path / "data" / "gtfs" / f"{name}.parquet")
        want = pd.read_parquet(tmp_path / "clean" / "gtfs" / f"{name}.parquet")
        pd.testing.assert_frame_equal(got, want)
    assert pd.read_parquet(tmp_path / "data" / "gtfs" / "trips.parquet")["trip_id"].is_unique


def _all_types(tmp_path: Path) -> Path:
    conf = tmp_path / "all_types.yaml"
    conf.write_text("run:\n  route_types: all\n")
    return conf


def _retimed(tables: dict, trip: str | None, hours: int = 0, text: str | None = None) -> dict:
    """stop_times.txt with the times of *trip* (every trip: None) shifted by *hours*, or the
    first stop time of *trip* set to *text*."""
    rows = tables["stop_times.txt"].splitlines()
    out, done = [rows[0]], False
    for r in rows[1:]:
        f = r.split(",")
        if trip is None or f[0] == trip:
            if text is not None and not done:
                f[1] = f[2] = text
                done = True
            elif text is None:
                for i in (1, 2):
                    h, m, s = f[i].split(":")
                    f[i] = f"{int(h) + hours:02d}:{m}:{s}"
        out.append(",".join(f))
    return {**tables, "stop_times.txt": "\n".join(out) + "\n"}


def test_stop_time_far_beyond_a_service_day_drops_its_trip(tmp_path):
    """A stop time of 999999999:00:00 (the 89 GiB ArrayMemoryError of the preflight): its
    trip is dropped and counted at ingest, the others kept."""
    feed = write_feed(tmp_path / "f.zip", _retimed(vbb_like_tables(), "T2", text="999999999:00:00"))
    repaired(_ingest_gtfs(feed, tmp_path, "--config", _all_types(tmp_path)),
             "stop_times.txt: 1 of 4 trips have stop times beyond a service day (before 0:00:00 "
             "or after 30:00:00: from 999999999:00:00; first: trip T2 at stop_sequence 1); "
             "dropped", "trips 3")
    trips = pd.read_parquet(tmp_path / "data" / "gtfs" / "trips.parquet")
    assert sorted(trips["trip_id"]) == ["T1", "T3", "T4"]


def test_timetable_shifted_by_two_days_is_refused(tmp_path):
    """Issue item 4: every time +48 h ("problems: none" before, a wrong whole-day yield)."""
    feed = write_feed(tmp_path / "f.zip", _retimed(vbb_like_tables(), None, hours=48))
    one_line_error(_ingest_gtfs(feed, tmp_path, "--config", _all_types(tmp_path)), str(feed),
                   "stop_times.txt: 4 of 4 trips have stop times beyond a service day",
                   "from 56:00:00 to 60:06:30", "no trip left")
    assert not (tmp_path / "data" / "gtfs" / "feed.json").exists()


def test_huge_stop_time_never_reaches_the_preflight(ingested, tmp_path):
    """The small demo's feed with one stop time at 999999999:00:00, through the run's own
    ingest and preflight (where the old code asked numpy for 89 GiB): the trip is dropped."""
    from vipvflow.config import load_config
    from vipvflow.simulation.prepare import ensure_ingested, preflight

    feed = _demo_feed_with(ingested, tmp_path, "stop_times.txt",
                           lambda text: text.replace("05:01:00,05:01:20", "999999999:00:00,"
                                                     "999999999:00:00", 1))
    cfg = load_config(_variant(ingested, tmp_path, inputs={"gtfs": str(feed)}))
    said = []
    ensure_ingested(cfg, say=said.append)
    assert any("1 of 292 trips have stop times beyond a service day" in s for s in said), said
    assert preflight(cfg, 2024, say=said.append)["service_days"] == 30


@pytest.mark.parametrize("encoding,name", [("latin-1", "Windows-1252 (cp1252"),
                                           ("cp1252", "Windows-1252 (cp1252"),
                                           ("utf-16", "UTF-16 (with a byte order mark)")])
def test_gtfs_in_another_encoding_is_read_and_named(encoding, name, tmp_path):
    """latin-1, cp1252 and UTF-16 (with its byte order mark) tables are read in their
    encoding, said in a problem line, and the names come out right (gtfs-kit failed with a
    UnicodeDecodeError naming no file before)."""
    t = vbb_like_tables()
    t["stops.txt"] = t["stops.txt"].replace("S1,S1,", "S1,Brandenburger Tor – Straße,")
    if encoding == "latin-1":
        t["stops.txt"] = t["stops.txt"].replace(" – ", " ")
    feed = tmp_path / "f.zip"
    with zipfile.ZipFile(feed, "w") as zf:
        for member, text in t.items():
            zf.writestr(member, text.encode(encoding if member == "stops.txt" else "utf-8"))
    out = repaired(_ingest_gtfs(feed, tmp_path, "--config", _all_types(tmp_path)), "trips 4")
    assert f"stops.txt is encoded in {name}" in out and f"read as {encoding if encoding != 'latin-1' else 'cp1252'}" in out


@pytest.mark.parametrize("change,words", [
    (("stops.txt", "52.5163,13.3777", "north,13.3777"), "stops.txt line 2: stop_lat 'north' is not a number"),
    (("stop_times.txt", "T1,08:02:00,08:02:30,S2,2", "T1,08:02:00,08:02:30,S2,two"),
     "stop_times.txt line 3: stop_sequence 'two' is not an integer"),
    (("routes.txt", "R100,1,100,3", "R100,1,100,bus"), "routes.txt line 2: route_type 'bus' is not an integer"),
])
def test_text_in_a_numeric_gtfs_column_names_file_line_and_column(change, words, tmp_path):
    name, old, new = change
    t = vbb_like_tables()
    assert old in t[name]
    feed = write_feed(tmp_path / "f.zip", {**t, name: t[name].replace(old, new)})
    one_line_error(_ingest_gtfs(feed, tmp_path), str(feed), words)


def test_calendar_with_start_after_end(tmp_path):
    """Every service of calendar.txt ending before it starts: refused naming the row (it
    said "problems: none" and then that the calendar had no service in the year); one of
    two such services: dropped and counted."""
    t = vbb_like_tables()
    swapped = t["calendar.txt"].replace("20240101,20241231", "20241231,20240101")
    feed = write_feed(tmp_path / "f.zip", {**t, "calendar.txt": swapped})
    one_line_error(_ingest_gtfs(feed, tmp_path), "calendar.txt: 1 of 1 services have a start_date "
                   "after their end_date (first: service WD at line 2, 20241231 > 20240101)",
                   "no service date")
    two = swapped + "WE,0,0,0,0,0,1,1,20240101,20241231\n"
    feed = write_feed(tmp_path / "g.zip", {**t, "calendar.txt": two})
    repaired(_ingest_gtfs(feed, tmp_path), "calendar.txt: 1 of 2 services have a start_date after "
             "their end_date (first: service WD at line 2, 20241231 > 20240101), so no dates; dropped")
    # left with two dates of calendar_dates.txt: the run's refusal says so
    from vipvflow.errors import InputError
    from vipvflow.simulation.prepare import _run_service_dates

    dates = "service_id,date,exception_type\nWD,20240304,1\nWD,20241104,1\n"
    feed = write_feed(tmp_path / "h.zip", {**t, "calendar.txt": swapped, "calendar_dates.txt": dates})
    repaired(_ingest_gtfs(feed, tmp_path), "calendar.txt: 1 of 1 services")
    trips = pd.read_parquet(tmp_path / "data" / "gtfs" / "trips.parquet")
    with pytest.raises(InputError, match=r"no service in 2024 \(months \[6\]\); it runs from "
                                        r"2024-03-04 to 2024-11-04, on 2 dates in 2024"):
        _run_service_dates(tmp_path / "data", trips, 2024, {6})


def test_stops_outside_the_area_of_the_crs(tmp_path):
    """Berlin's stops put into Luxembourg's EPSG:2169 (as a Hamburg city model's EPSG:25832
    took Cairns' stops): one line naming the CRS, its area and where the stops are;
    accepted with --accept crs_area."""
    feed = write_feed(tmp_path / "f.zip", vbb_like_tables())
    one_line_error(_ingest_gtfs(feed, tmp_path, "--crs", "EPSG:2169"),
                   "4 of the 4 stops the trips serve (around 52.52, 13.38) lie outside the area "
                   "of use of EPSG:2169 (LUREF / Luxembourg TM", "--accept crs_area")
    repaired(_ingest_gtfs(feed, tmp_path, "--crs", "EPSG:2169", "--accept", "crs_area"),
             "lie outside the area of use of EPSG:2169")
    one_line_error(_ingest_gtfs(feed, tmp_path, "--crs", "NOTACRS"),
                   "--crs NOTACRS: not a CRS PROJ knows")


# ------------------------------------------------------------------------------ city
def test_city_forced_into_a_crs_of_another_place(demo_small, tmp_path):
    """Issue item 5: ``inputs.citygml_crs: EPSG:32618`` (UTM 18N, New York) on the demo's
    EPSG:2169 file: refused on its first building (782 instead of 602 segments before)."""
    conf = tmp_path / "c.yaml"
    conf.write_text(yaml.safe_dump({"inputs": {"citygml_crs": "EPSG:32618"}}))
    gml = demo_small / "demo_city.gml"
    res = vipvflow("ingest", "city", gml, "--data-dir", tmp_path / "data", "--config", conf, "-q")
    one_line_error(res, str(gml), "(EPSG:2169, the first", "at 49.6", "lie outside the area of "
                   "use of EPSG:32618 (WGS 84 / UTM zone 18N", "--accept crs_area")
    assert not (tmp_path / "data" / "city").exists()
    one_line_error(vipvflow("ingest", "city", gml, "--data-dir", tmp_path / "data", "--crs",
                            "NOTACRS"), "--crs NOTACRS (or inputs.citygml_crs): not a CRS name")


# ------------------------------------------------------------------------------ CAMS
def _cams_text() -> str:
    return CAMS_1MIN.read_text()


def _data_row(text: str, i: int, fn) -> str:
    """*text* with data row *i* (0-based) replaced by ``fn(row)``."""
    lines = text.splitlines(keepends=True)
    rows = [k for k, line in enumerate(lines) if not line.startswith("#")]
    lines[rows[i]] = fn(lines[rows[i]])
    return "".join(lines)


@pytest.mark.parametrize("how", ["utf-8-sig", "utf-16", "latin-1"])
def test_cams_with_a_byte_order_mark_or_latin1_is_read(how, tmp_path):
    """A UTF-8 byte order mark ("no header line" before, although it is there), UTF-16 with
    its mark, latin-1 text in the header: read, the same rows as the plain file."""
    text = _cams_text()
    if how == "latin-1":
        text = text.replace("# Provider:", "# Provider (Météo):") if "# Provider:" in text else \
            text.replace("# Title:", "# Title (é):", 1)
    f = tmp_path / "cams.csv"
    f.write_bytes(text.encode(how))
    out = repaired(vipvflow("ingest", "cams", f, "--data-dir", tmp_path / "data"), "60 rows")
    if how != "utf-8-sig":
        assert f"encoded in {'cp1252' if how == 'latin-1' else how}" in out
    plain = tmp_path / "plain.csv"
    plain.write_text(_cams_text())
    repaired(vipvflow("ingest", "cams", plain, "--data-dir", tmp_path / "plain"), "60 rows")
    got = pd.read_parquet(tmp_path / "data" / "radiation" / "radiation.parquet")
    pd.testing.assert_frame_equal(got, pd.read_parquet(tmp_path / "plain" / "radiation" / "radiation.parquet"))


@pytest.mark.parametrize("fn,words", [
    (lambda r: r.replace(r.split(";")[2], "abc", 1), "line 62: Clear sky GHI 'abc' is not a number"),
    (lambda r: r.replace("2020-06-01T12:05", "2020-06-31T12:05", 1),
     "line 62: observation period '2020-06-31T12:05:00.0/2020-06-01T12:06:00.0': its start is "
     "not an ISO 8601 date and time"),
])
def test_cams_bad_value_names_its_line(fn, words, tmp_path):
    f = tmp_path / "cams.csv"
    f.write_text(_data_row(_cams_text(), 5, fn))
    assert words.split(":")[0].split()[1] == str(_line_of_row(f, 5))
    one_line_error(vipvflow("ingest", "cams", f, "--data-dir", tmp_path / "data"), str(f), words)


def _line_of_row(path: Path, i: int) -> int:
    lines = path.read_text().splitlines()
    return [k + 1 for k, line in enumerate(lines) if not line.startswith("#")][i]


@pytest.mark.parametrize("key,value", [("Latitude", "999"), ("Longitude", "-200.5")])
def test_cams_location_out_of_range(key, value, tmp_path):
    """Issue item 2: a latitude of 999 was accepted."""
    text = _cams_text()
    line = next(x for x in text.splitlines() if x.startswith(f"# {key} "))
    f = tmp_path / "cams.csv"
    f.write_text(text.replace(line, line.split(": ")[0] + ": " + value))
    one_line_error(vipvflow("ingest", "cams", f, "--data-dir", tmp_path / "data"), str(f),
                   f"{key} {value} is not a {key.lower()}")


def _cams_day(demo: Path, dest: Path, swap=None) -> Path:
    """The demo's CAMS file cut to 12 June 2024, with the columns *swap* exchanged in each
    row (0 is the period; 6 GHI, 8 DHI; 2..5 the clear-sky columns, 6..9 the all-sky ones)."""
    with open(demo / "cams_radiation_demo.csv") as fin, open(dest, "w") as fout:
        for line in fin:
            if line.startswith("#"):
                fout.write(line)
            elif line.startswith("2024-06-12"):
                v = line.rstrip("\n").split(";")
                for a, b in swap or ():
                    v[a], v[b] = v[b], v[a]
                fout.write(";".join(v) + "\n")
    return dest


def test_ghi_and_dhi_swapped_are_refused(demo_small, tmp_path):
    """Issue item 3: GHI and DHI swapped gave 482 kWh/kWp above the clear-sky 464; all-sky and
    clear-sky columns swapped put GHI far above the clear sky. Refused naming the first
    minute and its values; the untouched day passes; --accept radiation_components reads it."""
    day = _cams_day(demo_small, tmp_path / "day.csv")
    repaired(vipvflow("ingest", "cams", day, "--data-dir", tmp_path / "ok"), "1440 rows")
    swapped = _cams_day(demo_small, tmp_path / "swapped.csv", swap=[(6, 8)])
    err = one_line_error(vipvflow("ingest", "cams", swapped, "--data-dir", tmp_path / "d"),
                         str(swapped), "GHI below DHI for", "are the GHI and DHI columns swapped?",
                         "--accept radiation_components")
    assert "first at 2024-06-12 0" in err
    clear = _cams_day(demo_small, tmp_path / "clear.csv", swap=[(2, 6), (3, 7), (4, 8), (5, 9)])
    one_line_error(vipvflow("ingest", "cams", clear, "--data-dir", tmp_path / "d"), str(clear),
                   "GHI above 1.5 x the clear-sky GHI + 50 W/m2 for", "all-sky and clear-sky "
                   "columns swapped")
    assert not (tmp_path / "d" / "radiation").exists()
    repaired(vipvflow("ingest", "cams", swapped, "--data-dir", tmp_path / "d", "--accept",
                      "radiation_components"), "1440 rows")


# ------------------------------------------------------------------------------ runs
def _demo_feed_with(ingested, tmp_path: Path, member: str, fn) -> Path:
    """The small demo's GTFS zip with *member* rewritten by *fn*."""
    _, conf = ingested
    src = Path(conf["inputs"]["gtfs"])
    dest = tmp_path / "feed.zip"
    with zipfile.ZipFile(src) as zin, zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zout:
        for info in zin.infolist():
            data = zin.read(info)
            zout.writestr(info.filename, fn(data.decode()) if info.filename == member else data)
    return dest


def _relocated_cams(ingested, dest: Path, lat: float, lon: float) -> Path:
    """The small demo's CAMS file with its header's location moved to *lat*, *lon*."""
    _, conf = ingested
    with open(conf["inputs"]["cams"][0]) as fin, open(dest, "w") as fout:
        for line in fin:
            if line.startswith("# Latitude"):
                line = f"# Latitude (positive North, ISO 19115): {lat}\n"
            elif line.startswith("# Longitude"):
                line = f"# Longitude (positive East, ISO 19115): {lon}\n"
            fout.write(line)
    return dest


def test_radiation_of_another_place_stops_before_the_cluster(ingested, tmp_path):
    """Issue item 2: a CAMS header located in Sydney for the Luxembourg-like city (116
    instead of 314 kWh/kWp before): one line naming the file, its location and the
    distance, before any cluster; accepted with --accept radiation_far (the preflight then
    passes)."""
    from vipvflow.config import load_config
    from vipvflow.simulation.prepare import ensure_ingested, preflight

    cams = _relocated_cams(ingested, tmp_path / "cams_sydney.csv", -33.8688, 151.2093)
    path = _variant(ingested, tmp_path, cams=cams)
    res = vipvflow("simulate", "--config", path, "--year", "2024", "--quiet")
    err = one_line_error(res, str(cams), "the radiation's location -33.8688, 151.2093 lies",
                         "km from the city model (49.", "more than 50 km", "--accept radiation_far")
    assert "16,6" in err or "16,5" in err or "16,7" in err       # ~16,600 km from Luxembourg
    assert "dask dashboard" not in res.stdout
    cfg = load_config(path)
    cfg.checks.accept = ["radiation_far"]
    ensure_ingested(cfg, say=lambda *a: None)
    assert preflight(cfg, 2024, say=lambda *a: None)["service_days"] == 30
    # a location 20 km away passes
    near = _relocated_cams(ingested, tmp_path / "cams_near.csv", 49.61 + 0.18, 6.13)
    (tmp_path / "near").mkdir()
    cfg = load_config(_variant(ingested, tmp_path / "near", cams=near))
    ensure_ingested(cfg, say=lambda *a: None)
    preflight(cfg, 2024, say=lambda *a: None)


def test_dark_span_is_bounded():
    """The preflight's night test samples at most two days (999999999:00:00 asked for
    89 GiB of sample times)."""
    from vipvflow.simulation.prepare import _dark

    loc = {"lat": 49.61, "lon": 6.13}
    assert list(_dark([0.0], [3.6e12], loc)) == [False]
    assert list(_dark([1718150400.0 - 3600], [1718150400.0], loc)) == [True]   # 12 June, 23-24 UTC
