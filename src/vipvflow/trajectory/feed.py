"""Reading a GTFS feed with gtfs-kit and checking what the later stages rely on.

:func:`read_feed` returns a :class:`Feed` holding gtfs-kit's tables prepared for the
trajectory stage: frequencies expanded into trips, a shape built from the stop sequence
for every trip without one, times parsed to seconds after the service day's reference
("noon minus 12 h", which may exceed 86 400 s), and a list of problems found on the way.
Problems are reported, never hidden, and only an unusable feed is fatal
(:class:`vipvflow.errors.InputError`).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError

log = logging.getLogger(__name__)


def time_to_seconds(values) -> np.ndarray:
    """GTFS ``H:MM:SS`` strings to seconds (float, NaN where empty); hours may exceed 23.

    Parameters
    ----------
    values : array-like of str
        GTFS times such as ``"05:10:00"`` or ``"24:40:00"``.

    Returns
    -------
    ndarray of float64
        Seconds after the service day's reference time (s).
    """
    s = pd.Series(values, dtype="string").str.strip()
    parts = s.str.split(":", expand=True)
    if parts.shape[1] < 3:
        return np.full(len(s), np.nan)
    num = parts.iloc[:, :3].apply(pd.to_numeric, errors="coerce").to_numpy(dtype=float)
    return num[:, 0] * 3600.0 + num[:, 1] * 60.0 + num[:, 2]


@dataclass
class Feed:
    """A GTFS feed prepared for the trajectory stage (tables are gtfs-kit's, cleaned)."""

    path: Path
    timezone: str
    routes: pd.DataFrame
    trips: pd.DataFrame
    stops: pd.DataFrame
    stop_times: pd.DataFrame      # + arr_s, dep_s (float seconds)
    shapes: pd.DataFrame          # shape_id, shape_pt_sequence, shape_pt_lat, shape_pt_lon
    calendar: pd.DataFrame | None
    calendar_dates: pd.DataFrame | None
    dist_units: str | None
    shapes_built_from_stops: int = 0
    frequency_trips: int = 0
    problems: list[str] = field(default_factory=list)
    gk_feed: object = None        # the gtfs-kit Feed after expansion, for cross-checks


def read_feed(feed_path, dist_units: str | None = None) -> Feed:
    """Read a GTFS zip or folder with gtfs-kit and prepare it.

    Parameters
    ----------
    feed_path : str or Path
        GTFS zip file or folder of ``.txt`` files.
    dist_units : str, optional
        Units of ``shape_dist_traveled`` (``m``, ``km``, ``mi``, ``ft``); inferred by
        gtfs-kit when omitted (the trajectory stage checks them against the geometry).

    Raises
    ------
    InputError
        When the path is missing or the feed lacks trips, stop times, stops or calendars.
    """
    import gtfs_kit as gk

    path = Path(feed_path)
    if not path.exists():
        raise InputError(f"{path}: GTFS feed not found")
    try:
        gfeed = gk.read_feed(path, dist_units=dist_units) if dist_units else _read_infer(gk, path)
    except InputError:
        raise
    except Exception as exc:  # gtfs-kit raises many kinds on a broken zip
        raise InputError(f"{path}: not a readable GTFS feed: {exc}") from None
    for name in ("trips", "stop_times", "stops"):
        if getattr(gfeed, name) is None or getattr(gfeed, name).empty:
            raise InputError(f"{path}: {name}.txt missing or empty")
    if (gfeed.calendar is None or gfeed.calendar.empty) and (
            gfeed.calendar_dates is None or gfeed.calendar_dates.empty):
        raise InputError(f"{path}: neither calendar.txt nor calendar_dates.txt has service dates")
    problems: list[str] = []

    tz = None
    if gfeed.agency is not None and "agency_timezone" in gfeed.agency:
        zones = gfeed.agency["agency_timezone"].dropna().unique()
        if len(zones) > 1:
            problems.append(f"agency.txt has several timezones {list(zones)}; using {zones[0]}")
        tz = str(zones[0]) if len(zones) else None
    if tz is None:
        raise InputError(f"{path}: agency.txt has no agency_timezone")

    n_freq = 0
    if gfeed.frequencies is not None and not gfeed.frequencies.empty:
        n_before = len(gfeed.trips)
        gfeed = gk.expand_frequencies(gfeed)
        n_freq = len(gfeed.trips) - n_before
    trips = gfeed.trips
    if "shape_id" not in trips:
        trips = trips.assign(shape_id=pd.Series(pd.NA, index=trips.index, dtype="string"))
        gfeed.trips = trips
    if gfeed.shapes is not None and not gfeed.shapes.empty:
        known = set(gfeed.shapes["shape_id"])
        unknown = trips["shape_id"].notna() & ~trips["shape_id"].isin(known)
        if unknown.any():
            problems.append(f"{int(unknown.sum())} trips reference a shape_id missing from "
                            "shapes.txt; shapes built from their stops")
            gfeed.trips.loc[unknown, "shape_id"] = pd.NA
    else:
        gfeed.shapes = None
    n_missing = int(gfeed.trips["shape_id"].isna().sum())
    n_built = 0
    if n_missing:
        before = set() if gfeed.shapes is None else set(gfeed.shapes["shape_id"])
        gfeed = gk.create_shapes(gfeed)
        n_built = len(set(gfeed.shapes["shape_id"]) - before)
        problems.append(f"{n_missing} trips without a shape: {n_built} shapes built from the "
                        "stop sequence (straight lines between stops)")

    st = gfeed.stop_times.copy()
    st["arr_s"] = time_to_seconds(st["arrival_time"])
    st["dep_s"] = time_to_seconds(st["departure_time"])
    # a stop with only one of the two times: use it for both
    st["arr_s"] = st["arr_s"].fillna(st["dep_s"])
    st["dep_s"] = st["dep_s"].fillna(st["arr_s"])
    bad = st["dep_s"] < st["arr_s"]
    if bad.any():
        problems.append(f"{int(bad.sum())} stop_times depart before they arrive; departure set "
                        "to arrival")
        st.loc[bad, "dep_s"] = st.loc[bad, "arr_s"]
    st = st.sort_values(["trip_id", "stop_sequence"], kind="stable").reset_index(drop=True)

    trips = gfeed.trips
    no_times = ~trips["trip_id"].isin(st["trip_id"])
    if no_times.any():
        problems.append(f"{int(no_times.sum())} trips have no stop_times; dropped")
        trips = trips[~no_times]
    stops = gfeed.stops
    missing_stop = ~st["stop_id"].isin(stops["stop_id"])
    if missing_stop.any():
        problems.append(f"{int(missing_stop.sum())} stop_times reference unknown stops; dropped")
        st = st[~missing_stop]

    return Feed(path=path, timezone=tz, routes=gfeed.routes, trips=trips.reset_index(drop=True),
                stops=stops, stop_times=st, shapes=gfeed.shapes, calendar=gfeed.calendar,
                calendar_dates=gfeed.calendar_dates, dist_units=gfeed.dist_units,
                shapes_built_from_stops=n_built, frequency_trips=n_freq, problems=problems,
                gk_feed=gfeed)


def _read_infer(gk, path: Path):
    """gtfs-kit's read with inferred units; a feed without any distance gets metres."""
    try:
        return gk.read_feed(path)
    except ValueError:
        return gk.read_feed(path, dist_units="m")
