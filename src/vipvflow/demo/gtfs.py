"""The demo timetable as a GTFS feed.

Every line runs both ways (direction 1 on the reversed shape) with weekday (``WD``),
Saturday (``SA``) and Sunday (``SU``) services of different headways; on Luxembourg's
public holidays the weekday (or Saturday) service is removed and the Sunday service added
through ``calendar_dates.txt``.  Trips take the line length at a scheduled average speed of
20 km/h including a 20 s dwell at each intermediate stop; the last trips of a service day
run past midnight (times such as ``24:50:00``).  Each service's trips are chained into
vehicle blocks: a bus shuttles between the two termini with a layover of at least 5 min.
"""
from __future__ import annotations

import datetime as dt
import io
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd
from dateutil.easter import easter
from pyproj import Transformer

from .layout import Layout, Line, cumulative_length, densify, point_at

AGENCY_TZ = "Europe/Luxembourg"
AVERAGE_SPEED_KMH = 20.0
DWELL_S = 20
MIN_LAYOVER_S = 300
STOP_SPACING_M = 400.0
SHAPE_STEP_M = 20.0
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
SERVICE_DAYS = {"WD": (1, 1, 1, 1, 1, 0, 0), "SA": (0, 0, 0, 0, 0, 1, 0), "SU": (0, 0, 0, 0, 0, 0, 1)}

# departures from each terminus: (first "HH:MM", end "HH:MM" exclusive, headway min) per
# service; times after 24:00 belong to the same service day
HEADWAYS = {
    "1": {
        "WD": [("05:00", "06:00", 30), ("06:00", "09:00", 10), ("09:00", "15:00", 20),
               ("15:00", "18:30", 15), ("18:30", "21:00", 30), ("21:00", "24:40", 40)],
        "SA": [("06:00", "08:00", 30), ("08:00", "19:00", 20), ("19:00", "24:01", 30)],
        "SU": [("07:30", "24:31", 30)],
    },
    "2": {
        "WD": [("06:00", "22:00", 20), ("22:00", "24:31", 30)],
        "SA": [("07:00", "24:01", 30)],
        "SU": [("08:00", "23:31", 30)],
    },
}


def _hm(text: str) -> int:
    h, m = text.split(":")
    return int(h) * 3600 + int(m) * 60


def departures(line: str, service: str) -> np.ndarray:
    """First-stop departure times (s after local midnight of the service day)."""
    out = []
    for start, end, headway in HEADWAYS[line][service]:
        out.extend(range(_hm(start), _hm(end), headway * 60))
    return np.array(out, dtype=np.int64)


def gtfs_time(seconds) -> list[str]:
    """GTFS ``HH:MM:SS`` strings (hours may exceed 23)."""
    return [f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}" for s in np.asarray(seconds, dtype=np.int64)]


def luxembourg_holidays(year: int) -> dict[dt.date, str]:
    """Legal public holidays of Luxembourg in *year* (Europe Day since 2019)."""
    e = easter(year)
    days = {
        dt.date(year, 1, 1): "New Year's Day",
        e + dt.timedelta(days=1): "Easter Monday",
        dt.date(year, 5, 1): "Labour Day",
        e + dt.timedelta(days=39): "Ascension Day",
        e + dt.timedelta(days=50): "Whit Monday",
        dt.date(year, 6, 23): "National Day",
        dt.date(year, 8, 15): "Assumption Day",
        dt.date(year, 11, 1): "All Saints' Day",
        dt.date(year, 12, 25): "Christmas Day",
        dt.date(year, 12, 26): "St Stephen's Day",
    }
    if year >= 2019:
        days.setdefault(dt.date(year, 5, 9), "Europe Day")
    return dict(sorted(days.items()))


def calendar_exceptions(year: int) -> list[tuple[str, dt.date, int]]:
    """(service_id, date, exception_type) rows: holidays run the Sunday service."""
    rows = []
    for day in luxembourg_holidays(year):
        wd = day.weekday()
        if wd == 6:
            continue
        rows.append(("WD" if wd < 5 else "SA", day, 2))
        rows.append(("SU", day, 1))
    return rows


def service_day_counts(year: int) -> dict[str, int]:
    """Days in *year* on which each service runs (calendar + calendar_dates)."""
    days = pd.date_range(f"{year}-01-01", f"{year}-12-31", freq="D")
    counts = {sid: int(sum(mask[d.weekday()] for d in days)) for sid, mask in SERVICE_DAYS.items()}
    for sid, _, kind in calendar_exceptions(year):
        counts[sid] += 1 if kind == 1 else -1
    return counts


def stop_positions(length_m: float) -> np.ndarray:
    """Distances of the stops along the line (m), evenly spaced about every 400 m."""
    n = max(2, int(round(length_m / STOP_SPACING_M)) + 1)
    return np.linspace(0.0, length_m, n)


def stop_offsets(stop_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Arrival and departure offsets (s) from the first departure at each stop.

    Running at a constant speed between stops, chosen so that the whole trip, dwell
    included, averages :data:`AVERAGE_SPEED_KMH`.
    """
    total = stop_s[-1] / (AVERAGE_SPEED_KMH / 3.6)
    n_dwell = len(stop_s) - 2
    v_run = stop_s[-1] / (total - DWELL_S * n_dwell)
    k = np.arange(len(stop_s))
    arr = stop_s / v_run + DWELL_S * np.clip(k - 1, 0, None)
    dep = arr + np.where((k > 0) & (k < len(stop_s) - 1), DWELL_S, 0)
    return np.round(arr).astype(np.int64), np.round(dep).astype(np.int64)


def trips_per_year(line: str, year: int) -> dict:
    """Trips of *line* per direction in *year* implied by the calendar (same both ways)."""
    days = service_day_counts(year)
    per_service = {sid: int(len(departures(line, sid))) for sid in SERVICE_DAYS}
    total = sum(days[sid] * n for sid, n in per_service.items())
    return {"per_service_day": per_service, "service_days": days, "per_direction": {"0": total, "1": total}}


def _blocks(dep0: np.ndarray, dep1: np.ndarray, duration: int) -> tuple[np.ndarray, np.ndarray]:
    """Vehicle numbers of the trips leaving terminus A (*dep0*) and B (*dep1*).

    Trips in order of departure take the bus that has waited longest at their terminus
    (arrived at least :data:`MIN_LAYOVER_S` before), or a new bus.
    """
    events = sorted([(t, 0, i) for i, t in enumerate(dep0)] + [(t, 1, i) for i, t in enumerate(dep1)])
    waiting: list[list[tuple[int, int]]] = [[], []]  # per terminus: (ready time, bus)
    out = [np.zeros(len(dep0), dtype=np.int64), np.zeros(len(dep1), dtype=np.int64)]
    n_bus = 0
    for t, d, i in events:
        ready = [k for k, (r, _) in enumerate(waiting[d]) if r <= t]
        if ready:
            k = min(ready, key=lambda k: waiting[d][k])
            bus = waiting[d].pop(k)[1]
        else:
            bus, n_bus = n_bus, n_bus + 1
        out[d][i] = bus
        waiting[1 - d].append((t + duration + MIN_LAYOVER_S, bus))
    return out[0], out[1]


def _line_tables(line: Line, to_wgs84: Transformer):
    """stops, shapes, trips and stop_times rows of one line."""
    rid = line.route_id
    length = line.length_m
    # shapes: every street vertex and at most SHAPE_STEP_M apart
    pts = densify(line.xy, SHAPE_STEP_M)
    cum = cumulative_length(pts)
    lon, lat = to_wgs84.transform(pts[:, 0], pts[:, 1])
    shapes = []
    for d in (0, 1):
        order = slice(None) if d == 0 else slice(None, None, -1)
        dist = cum if d == 0 else (cum[-1] - cum)[::-1]
        shapes.append(pd.DataFrame({
            "shape_id": f"{rid}_d{d}",
            "shape_pt_lat": [f"{v:.7f}" for v in lat[order]],
            "shape_pt_lon": [f"{v:.7f}" for v in lon[order]],
            "shape_pt_sequence": np.arange(len(pts)),
            "shape_dist_traveled": [f"{v:.2f}" for v in dist]}))
    # stops: one platform per direction at each stop position
    stop_s = stop_positions(length)
    sxy = point_at(line.xy, stop_s)
    slon, slat = to_wgs84.transform(sxy[:, 0], sxy[:, 1])
    kinds = [next(st.kind for st in line.stretches if s <= st.s_end_m + 1e-6) for s in stop_s]
    stops = []
    for d in (0, 1):
        stops.append(pd.DataFrame({
            "stop_id": [f"{rid}_S{k:02d}_d{d}" for k in range(len(stop_s))],
            "stop_name": [f"Line {line.name} {kind} {k:02d}" for k, kind in enumerate(kinds)],
            "stop_lat": [f"{v:.7f}" for v in slat], "stop_lon": [f"{v:.7f}" for v in slon]}))
    arr, dep = stop_offsets(stop_s)
    duration = int(arr[-1])
    trips, stop_times = [], []
    for sid in SERVICE_DAYS:
        t0 = departures(line.name, sid)
        buses = _blocks(t0, t0, duration)
        for d in (0, 1):
            t, st = direction_trips(rid, sid, d, t0, buses[d], stop_s, length, arr, dep)
            t.insert(3, "trip_headsign", line.long_name.split(" - ")[-1 if d == 0 else 0])
            trips.append(t)
            stop_times.append(st)
    return (pd.concat(stops), pd.concat(shapes), pd.concat(trips), pd.concat(stop_times),
            {"stops": len(stop_s), "trip_duration_s": duration})


def write_gtfs(path: Path, layout: Layout, year: int) -> dict:
    """Write the GTFS zip of all lines of *layout* for *year*; return counts."""
    to_wgs84 = Transformer.from_crs("EPSG:2169", "EPSG:4326", always_xy=True)
    parts = [_line_tables(line, to_wgs84) for line in layout.lines]
    start, end = f"{year}0101", f"{year}1231"
    tables = {
        "agency.txt": pd.DataFrame([{
            "agency_id": "VIPV", "agency_name": "vipvflow demo transit",
            "agency_url": "https://example.org/vipvflow-demo", "agency_timezone": AGENCY_TZ,
            "agency_lang": "fr"}]),
        "stops.txt": pd.concat([p[0] for p in parts]),
        "routes.txt": pd.DataFrame([{
            "route_id": line.route_id, "agency_id": "VIPV", "route_short_name": line.name,
            "route_long_name": line.long_name, "route_type": 3} for line in layout.lines]),
        "trips.txt": pd.concat([p[2] for p in parts]),
        "stop_times.txt": pd.concat([p[3] for p in parts]),
        "calendar.txt": pd.DataFrame([{
            "service_id": sid, **dict(zip(["monday", "tuesday", "wednesday", "thursday", "friday",
                                           "saturday", "sunday"], mask)),
            "start_date": start, "end_date": end} for sid, mask in SERVICE_DAYS.items()]),
        "calendar_dates.txt": pd.DataFrame(
            [{"service_id": sid, "date": day.strftime("%Y%m%d"), "exception_type": kind}
             for sid, day, kind in calendar_exceptions(year)]),
        "shapes.txt": pd.concat([p[1] for p in parts]),
        "feed_info.txt": pd.DataFrame([{
            "feed_publisher_name": "vipvflow demo generator (synthetic)",
            "feed_publisher_url": "https://example.org/vipvflow-demo", "feed_lang": "fr",
            "feed_start_date": start, "feed_end_date": end, "feed_version": f"demo-{year}"}]),
    }
    with zipfile.ZipFile(path, "w") as zf:
        for name, df in tables.items():
            buf = io.StringIO()
            df.to_csv(buf, index=False, lineterminator="\n")
            info = zipfile.ZipInfo(name, date_time=ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            zf.writestr(info, buf.getvalue().encode("utf-8"))
    return {
        "trips": int(len(tables["trips.txt"])), "stop_times": int(len(tables["stop_times.txt"])),
        "stops": int(len(tables["stops.txt"])), "shape_points": int(len(tables["shapes.txt"])),
        "blocks": int(tables["trips.txt"]["block_id"].nunique()),
        "per_line": {line.name: p[4] for line, p in zip(layout.lines, parts)},
    }


def direction_trips(rid: str, sid: str, d: int, t0, buses, stop_s, length: float, arr, dep):
    """trips.txt and stop_times.txt rows of one route, service and direction.

    Parameters
    ----------
    rid, sid : route and service ids
    d : direction (0 along the shape, 1 back)
    t0 : departures (s after local midnight)
    buses : the block number of each departure
    stop_s : stop positions along direction 0's shape (m); *length* the shape's length (m)
    arr, dep : arrival and departure offsets at each stop from the first departure (s)

    Returns
    -------
    (trips, stop_times) DataFrames (times as GTFS ``HH:MM:SS``, distances in m as text)
    """
    ids = [f"{rid}_{sid}_d{d}_{k:03d}" for k in range(len(t0))]
    trips = pd.DataFrame({"route_id": rid, "service_id": sid, "trip_id": ids, "direction_id": d,
                          "block_id": [f"{rid}_{sid}_B{b:02d}" for b in buses],
                          "shape_id": f"{rid}_d{d}"})
    stop_idx = np.arange(len(stop_s)) if d == 0 else np.arange(len(stop_s))[::-1]
    dist = stop_s if d == 0 else length - stop_s[::-1]
    n = len(stop_s)
    stop_times = pd.DataFrame({
        "trip_id": np.repeat(ids, n),
        "arrival_time": gtfs_time((t0[:, None] + arr[None, :]).ravel()),
        "departure_time": gtfs_time((t0[:, None] + dep[None, :]).ravel()),
        "stop_id": np.tile([f"{rid}_S{k:02d}_d{d}" for k in stop_idx], len(t0)),
        "stop_sequence": np.tile(np.arange(1, n + 1), len(t0)),
        "shape_dist_traveled": np.tile([f"{v:.2f}" for v in np.abs(dist)], len(t0)),
        "timepoint": 1})
    return trips, stop_times
