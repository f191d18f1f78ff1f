"""Service dates, trip patterns and passes.

Timing along a shape
--------------------
A trip's stop times are placed on its shape at the stops' distances (metres in the projected
CRS). The time at which the bus *reaches* distance ``s`` is piecewise linear: between the
departure from stop i and the arrival at stop i+1 it grows linearly with distance; at a stop
it jumps from the arrival to the departure (the bus dwells there). Before the first stop the
time is the first departure, past the last stop the last arrival. A segment's time
``dt_s`` is the reach time at its end minus the reach time at its start, so a dwell falls on
the segment in which the stop lies (on the following one when the stop is exactly on a
boundary). Only the segments overlapping [first stop, last stop] belong to a pattern.

Trips that share a shape, stops, stop distances and stop-time offsets from the first
departure share a *pattern*; the per-segment times are stored once per pattern
(``patterns.parquet``) and a pass (trip, service date) adds its start time.

Local time to UTC
-----------------
GTFS times count from "noon minus 12 h" of the service date in the agency's timezone: local
midnight, except on the days the clocks change, when it is 23:00 or 01:00. The UTC time of a
stop time t on service date D is therefore ``UTC(D 12:00 local) - 12 h + t``, computed exactly
so here.

Months
------
A pass belongs to the month of its *service date*: a trip of 31 May leaving at 24:30 is in
May although it runs on 1 June. Every pass is thus in exactly one (tile, month) partition.
"""
from __future__ import annotations

import functools
import json
from pathlib import Path

import numpy as np
import pandas as pd

from ...store import DataDir, GtfsDir
import pyarrow.parquet as pq

WEEKDAYS = ["monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday"]


# ---------------------------------------------------------------------------------------------
# stops on shapes

def project_stops_monotone(pts: np.ndarray, stop_xy: np.ndarray) -> np.ndarray:
    """Distances along a polyline of stops visited in order, never decreasing (m).

    Each stop may project onto any piece of the polyline; the set of projections with
    non-decreasing distance that minimises the sum of stop-to-shape distances is chosen
    (dynamic programming over the pieces, O(stops x pieces)), so a shape that passes the
    same place twice (loops, out-and-back) gets each stop on the right pass.

    Parameters
    ----------
    pts : ndarray (n, 2)
        Shape vertices (m), n >= 2.
    stop_xy : ndarray (m, 2)
        Stops in visiting order (m).
    """
    a, b = pts[:-1], pts[1:]
    d = b - a
    seg_len2 = np.einsum("ij,ij->i", d, d)
    cum = np.r_[0.0, np.cumsum(np.sqrt(seg_len2))]
    rel = stop_xy[:, None, :] - a[None, :, :]                       # (m, k, 2)
    u = np.where(seg_len2 > 0, np.einsum("mkj,kj->mk", rel, d) / np.where(seg_len2 > 0,
                                                                          seg_len2, 1), 0)
    u = np.clip(u, 0.0, 1.0)
    foot = a[None] + u[..., None] * d[None]
    dist = np.hypot(*(stop_xy[:, None, :] - foot).transpose(2, 0, 1))  # (m, k)
    pos = cum[:-1][None] + u * np.sqrt(seg_len2)[None]               # (m, k), rows sorted
    m, k = dist.shape
    cost = dist[0].copy()
    back = np.zeros((m, k), dtype=np.int64)
    for i in range(1, m):
        order_min = np.minimum.accumulate(cost)
        arg = _prefix_argmin(cost)
        j = np.searchsorted(pos[i - 1], pos[i], side="right") - 1
        ok = j >= 0
        new = np.full(k, np.inf)
        new[ok] = dist[i, ok] + order_min[j[ok]]
        back[i, ok] = arg[j[ok]]
        cost = new
    out = np.empty(m)
    jj = int(np.argmin(cost))
    for i in range(m - 1, -1, -1):
        out[i] = pos[i, jj]
        jj = back[i, jj]
    return np.maximum.accumulate(out)


def _prefix_argmin(v: np.ndarray) -> np.ndarray:
    """Index of the minimum of v[:j+1] for every j."""
    idx = np.arange(len(v))
    running = np.minimum.accumulate(v)
    is_new = v <= running
    return np.maximum.accumulate(np.where(is_new, idx, 0))


def reach_time(s, stop_d, arr, dep) -> np.ndarray:
    """Time the bus reaches distance *s* (s after the first departure; see module doc).

    Parameters
    ----------
    s : array of float
        Distances along the shape (m).
    stop_d, arr, dep : array of float
        Stop distances (m, non-decreasing), arrival and departure times (s).
    """
    s = np.asarray(s, float)
    stop_d, arr, dep = (np.asarray(v, float) for v in (stop_d, arr, dep))
    i = np.searchsorted(stop_d, s, side="left")          # stop_d[i-1] < s <= stop_d[i]
    i_c = np.clip(i, 1, len(stop_d) - 1)
    d0, d1 = stop_d[i_c - 1], stop_d[i_c]
    gap = d1 - d0
    frac = np.where(gap > 0, (s - d0) / np.where(gap > 0, gap, 1.0), 1.0)
    t = dep[i_c - 1] + (arr[i_c] - dep[i_c - 1]) * np.clip(frac, 0.0, 1.0)
    t = np.where(s <= stop_d[0], dep[0], t)
    return np.where(s >= stop_d[-1], arr[-1], t)


def pattern_segment_times(stop_d, arr, dep, seg_start, seg_len):
    """Per-segment timing of one pattern.

    Returns
    -------
    index : ndarray of int
        Positions (into seg_start) of the segments the pattern covers.
    t_offset : ndarray
        Reach time of each segment's start (s after the first departure).
    dt : ndarray
        Time on the segment (s), dwell included.
    covered : ndarray
        Length of the segment the trip actually drives (m; less than the segment's length
        only where the first or last stop lies inside it).
    """
    stop_d = np.asarray(stop_d, float)
    seg_end = seg_start + seg_len
    first, last = stop_d[0], stop_d[-1]
    if last > first:
        idx = np.flatnonzero((seg_end > first) & (seg_start < last))
    else:  # degenerate trip standing still: the segment holding the stop
        idx = np.flatnonzero((seg_start <= first) & (seg_end >= first))[:1]
    a = np.maximum(seg_start[idx], first)
    b = np.minimum(seg_end[idx], last)
    t0 = reach_time(a, stop_d, arr, dep)
    t1 = reach_time(b, stop_d, arr, dep)
    return idx, t0, t1 - t0, b - a


# ---------------------------------------------------------------------------------------------
# service dates

def _read(data_dir, name: str, **kw) -> pd.DataFrame:
    """The GTFS table *name* (``trips``, ``patterns``, ...) of *data_dir*."""
    path = DataDir(data_dir).gtfs.table(name)
    return pq.read_table(path, **kw).to_pandas()


def service_dates_from_tables(calendar: pd.DataFrame | None, calendar_dates: pd.DataFrame | None,
                              year: int) -> pd.DataFrame:
    """Active (service_id, date) pairs of *year* from calendar + calendar_dates tables."""
    start, end = pd.Timestamp(year, 1, 1), pd.Timestamp(year, 12, 31)
    days = pd.date_range(start, end, freq="D")
    parts = []
    if calendar is not None and len(calendar):
        cal = calendar.reset_index(drop=True)
        c0 = pd.to_datetime(cal["start_date"].astype(str), format="%Y%m%d").to_numpy()
        c1 = pd.to_datetime(cal["end_date"].astype(str), format="%Y%m%d").to_numpy()
        flags = cal[WEEKDAYS].fillna(0).astype(int).to_numpy()             # (s, 7)
        dv = days.to_numpy()
        wd = days.day_of_week.to_numpy()
        active = ((dv[None, :] >= c0[:, None]) & (dv[None, :] <= c1[:, None])
                  & (flags[:, wd] == 1))
        si, di = np.nonzero(active)
        parts.append(pd.DataFrame({"service_id": cal["service_id"].to_numpy()[si],
                                   "date": days[di]}))
    base = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(
        {"service_id": pd.Series(dtype=object), "date": pd.Series(dtype="datetime64[ns]")})
    if calendar_dates is not None and len(calendar_dates):
        cd = calendar_dates.copy()
        cd["date"] = pd.to_datetime(cd["date"].astype(str), format="%Y%m%d")
        cd = cd[(cd["date"] >= start) & (cd["date"] <= end)]
        removed = cd[cd["exception_type"].astype(int) == 2][["service_id", "date"]]
        added = cd[cd["exception_type"].astype(int) == 1][["service_id", "date"]]
        if len(removed):
            key = pd.MultiIndex.from_frame(base[["service_id", "date"]].astype(
                {"service_id": str}))
            rkey = pd.MultiIndex.from_frame(removed.astype({"service_id": str}))
            base = base[~key.isin(rkey)]
        base = pd.concat([base, added], ignore_index=True)
    out = base.astype({"service_id": str}).drop_duplicates()
    out["date"] = pd.to_datetime(out["date"]).astype("datetime64[ns]")
    return out.sort_values(["date", "service_id"]).reset_index(drop=True)


@functools.lru_cache(maxsize=16)
def _service_dates_cached(gdir: str, year: int, stamp: tuple) -> pd.DataFrame:
    gtfs = GtfsDir(Path(gdir))
    cal_path, cd_path = gtfs.table("calendar"), gtfs.table("calendar_dates")
    cal = pq.read_table(cal_path).to_pandas() if cal_path.exists() else None
    cd = pq.read_table(cd_path).to_pandas() if cd_path.exists() else None
    return service_dates_from_tables(cal, cd, year)


def _stamp(gdir: Path, names) -> tuple:
    """Modification times of files, so caches see a re-ingest."""
    return tuple((gdir / n).stat().st_mtime_ns if (gdir / n).exists() else 0 for n in names)


def service_dates(data_dir, year: int) -> pd.DataFrame:
    """Every (service_id, date) on which a service runs in *year* (dates as local days).

    Parameters
    ----------
    data_dir : path
        Scenario data directory holding ``gtfs/`` (from :func:`ingest_gtfs`).
    year : int

    Returns
    -------
    DataFrame[service_id (str), date (datetime64[ns], midnight)]
    """
    gdir = DataDir(data_dir).gtfs.root.resolve()
    stamp = _stamp(gdir, ("calendar.parquet", "calendar_dates.parquet"))
    return _service_dates_cached(str(gdir), int(year), stamp).copy()


def service_day_origin_utc(dates, timezone: str) -> np.ndarray:
    """Unix seconds of the GTFS time origin ("noon minus 12 h", local) of each service date.

    Parameters
    ----------
    dates : array-like of datetime64 (days)
    timezone : str
        IANA zone of the agency, e.g. ``Europe/Luxembourg``.
    """
    d = pd.DatetimeIndex(pd.to_datetime(dates)).normalize()
    noon = (d + pd.Timedelta(hours=12)).tz_localize(timezone, ambiguous=False,
                                                    nonexistent="shift_forward")
    origin = noon.tz_convert("UTC") - pd.Timedelta(hours=12)
    return ((origin - pd.Timestamp(0, tz="UTC")) / pd.Timedelta(seconds=1)).to_numpy(float)


# ---------------------------------------------------------------------------------------------
# passes

def _feed_info(data_dir) -> dict:
    return json.loads(DataDir(data_dir).gtfs.feed_json.read_text())


def _parse_month(month, year):
    if isinstance(month, str):
        period = pd.Period(month, freq="M")
        if year is not None and int(year) != period.year:
            raise ValueError(f"month {month!r} is not in year {year}")
    else:
        if year is None:
            raise ValueError("an integer month needs a year")
        period = pd.Period(year=int(year), month=int(month), freq="M")
    return period


_PASS_COLUMNS = ["segment_id", "trip_id", "service_date", "t_utc", "dt_s", "speed_mps"]


def _expand(runs: pd.DataFrame, pat: pd.DataFrame) -> pd.DataFrame:
    """Outer product of runs (trip, date, origin + start) with their pattern's segments."""
    if runs.empty or pat.empty:
        return _empty_passes()
    if not pat.attrs.get("sorted_by_pattern_time"):
        pat = pat.sort_values(["pattern_id", "t_offset_s"], kind="stable").reset_index(drop=True)
    pids = pat["pattern_id"].to_numpy()
    uniq, first = np.unique(pids, return_index=True)
    count = np.diff(np.r_[first, len(pids)])
    runs = runs[runs["pattern_id"].isin(uniq)]
    loc = np.searchsorted(uniq, runs["pattern_id"].to_numpy())
    n = count[loc]
    # pattern row of each pass: its run's first row plus its place in the run; a run's
    # values are repeated (faster than gathering them by run index)
    row = np.arange(n.sum()) + np.repeat(first[loc] - (np.cumsum(n) - n), n)
    if isinstance(runs["trip_id"].dtype, pd.CategoricalDtype):
        trip_code = runs["trip_id"].cat.codes.to_numpy()
        trip_names = runs["trip_id"].cat.categories
    else:
        trip_code, trip_names = pd.factorize(runs["trip_id"].astype(str), sort=True)
    return pd.DataFrame({
        "segment_id": pat["segment_id"].to_numpy(np.int64)[row],
        "trip_id": pd.Categorical.from_codes(np.repeat(trip_code, n), trip_names),
        "service_date": np.repeat(runs["service_date"].to_numpy(), n),
        "t_utc": np.repeat(runs["t0_utc"].to_numpy(float), n) + pat["t_offset_s"].to_numpy(float)[row],
        "dt_s": pat["dt_s"].to_numpy(np.float32)[row],
        "speed_mps": pat["speed_mps"].to_numpy(np.float32)[row],
    }, copy=False)          # the columns are new arrays: pandas' copy into blocks cost 2-3 ms


def _empty_passes() -> pd.DataFrame:
    return pd.DataFrame({
        "segment_id": pd.Series(dtype=np.int64), "trip_id": pd.Series(dtype="category"),
        "service_date": pd.Series(dtype="datetime64[ns]"), "t_utc": pd.Series(dtype=float),
        "dt_s": pd.Series(dtype=np.float32), "speed_mps": pd.Series(dtype=np.float32)})


def iter_passes(data_dir, tile: str, month, year: int | None = None,
                routes=None) -> pd.DataFrame:
    """Every pass of every trip through the segments of *tile* in *month*.

    Parameters
    ----------
    data_dir : path
        Scenario data directory (``gtfs/`` from :func:`ingest_gtfs`).
    tile : str
        Tile name (:mod:`vipvflow.inputs.tiles`).
    month : str or int
        ``"2024-06"``, or 6 together with *year*.
    year : int, optional
        Checked against *month* when both are given.
    routes : list of str, optional
        Only trips of these route ids (default: all).

    Returns
    -------
    DataFrame
        ``segment_id`` int64, ``trip_id`` (categorical: millions of rows share a few
        thousand names), ``service_date`` (datetime64[ns], the local
        service day), ``t_utc`` float64 (Unix s at segment start), ``dt_s`` float32 (s on
        the segment), ``speed_mps`` float32 (mean speed on the segment, dwell included),
        sorted by service date, trip and time. A pass belongs to the month of its service
        date (see module doc). Only this month and this tile are ever held in memory.
    """
    return PassChunks(data_dir, tile, month, year, routes).all()


#: passes of one :class:`PassChunks` chunk at most, unless one service day has more (a
#: chunk's passes take ~160 bytes each at the irradiance kernel's peak; 1 M rather than 2 M
#: took ~0.1 GB off a worker's peak on the 200-line network's largest tile)
PASS_CHUNK = 1 << 20


class PassChunks:
    """The passes of :func:`iter_passes` in chunks of whole service days, in order.

    Iterating gives DataFrames (columns and order as :func:`iter_passes`) of consecutive
    service days, each of at most *max_passes* passes unless one day alone has more; their
    concatenation is :func:`iter_passes`'s frame.  ``n`` is the number of passes of all
    chunks, known before any is made.  A (trip, service date) is never split over two chunks.
    """

    def __init__(self, data_dir, tile: str, month, year: int | None = None, routes=None,
                 max_passes: int = PASS_CHUNK):
        period = _parse_month(month, year)
        self.max_passes = int(max_passes)
        gdir = DataDir(data_dir).gtfs.root.resolve()
        stamp = _stamp(gdir, _GTFS_TABLES)
        self._pat = _tile_patterns(str(gdir), tile, stamp)
        self._runs = None
        if not self._pat.empty:
            runs = _month_runs(str(gdir), str(period), None if routes is None else
                               tuple(sorted(str(r) for r in routes)), stamp)
            runs = runs[runs["pattern_id"].isin(self._pat.attrs["pattern_ids"])]
            if not runs.empty:
                self._runs = runs
        self._per_run = np.zeros(0, np.int64)
        if self._runs is not None:
            uniq, count = np.unique(self._pat["pattern_id"].to_numpy(), return_counts=True)
            self._per_run = count[np.searchsorted(uniq, self._runs["pattern_id"].to_numpy())]
        self.n = int(self._per_run.sum())

    def all(self) -> pd.DataFrame:
        """Every pass in one frame (:func:`iter_passes`)."""
        return _empty_passes() if self._runs is None else _expand(self._runs, self._pat)

    def bounds(self) -> list[tuple[int, int]]:
        """The chunks' run ranges ``[a, b)`` (rows of the month's runs, sorted by date)."""
        if self._runs is None:
            return []
        dates = self._runs["service_date"].to_numpy()
        day0 = np.flatnonzero(np.r_[True, dates[1:] != dates[:-1]])
        per_day = np.add.reduceat(self._per_run, day0)
        out, a, held = [], 0, 0
        for k, n in enumerate(per_day.tolist()):
            if held and held + n > self.max_passes:
                out.append((a, int(day0[k])))
                a, held = int(day0[k]), 0
            held += n
        out.append((a, len(self._runs)))
        return out

    def __iter__(self):
        for a, b in self.bounds():
            yield _expand(self._runs.iloc[a:b], self._pat)


def clear_caches() -> None:
    """Drop this process's cached GTFS tables (service dates, a tile's patterns, a month's
    runs)."""
    for cached in (_service_dates_cached, _tile_patterns, _month_runs):
        cached.cache_clear()


_GTFS_TABLES = ("trips.parquet", "patterns.parquet", "segments.parquet", "calendar.parquet",
                "calendar_dates.parquet", "feed.json")


@functools.lru_cache(maxsize=8)
def _tile_patterns(gdir: str, tile: str, stamp: tuple) -> pd.DataFrame:
    """The pattern rows of the segments of *tile*, sorted by pattern and time (cached per
    process: a worker evaluates a tile for every month)."""
    data_dir = Path(gdir).parent
    segs = _read(data_dir, "segments", columns=["segment_id", "tile"],
                 filters=[("tile", "==", tile)])
    if segs.empty:
        return pd.DataFrame()
    pat = _read(data_dir, "patterns",
                filters=[("segment_id", "in", segs["segment_id"].to_numpy().tolist())])
    if pat.empty:
        return pd.DataFrame()
    pat = pat.sort_values(["pattern_id", "t_offset_s"], kind="stable").reset_index(drop=True)
    pat.attrs["sorted_by_pattern_time"] = True
    pat.attrs["pattern_ids"] = np.unique(pat["pattern_id"].to_numpy())
    return pat


@functools.lru_cache(maxsize=13)
def _month_runs(gdir: str, month: str, routes: tuple | None, stamp: tuple) -> pd.DataFrame:
    """Every run (trip x service date) of *month* with its pattern and UTC start, sorted by
    service date and trip; ``trip_id`` categorical over all the feed's trips (cached per
    process: the tiles of a worker share a month's runs)."""
    period = pd.Period(month, freq="M")
    trips = _read(Path(gdir).parent, "trips",
                  columns=["trip_id", "route_id", "service_id", "pattern_id", "start_s"])
    names = np.unique(trips["trip_id"].astype(str).to_numpy())
    if routes is not None:
        trips = trips[trips["route_id"].astype(str).isin(routes)]
    trips = trips.drop(columns="route_id")
    sd = _service_dates_cached(gdir, period.year, _stamp(Path(gdir), ("calendar.parquet",
                                                                       "calendar_dates.parquet")))
    sd = sd[(sd["date"] >= period.start_time) & (sd["date"] <= period.end_time)]
    runs = _runs(Path(gdir).parent, trips, sd)
    if runs.empty:
        return runs
    runs["trip_id"] = pd.Categorical(runs["trip_id"].astype(str), categories=names)
    return runs[["trip_id", "pattern_id", "service_date", "t0_utc"]]


def _runs(data_dir, trips, sd) -> pd.DataFrame:
    """Trips joined with their service dates: ``t0_utc`` (Unix s of the first departure),
    sorted by service date and trip."""
    runs = trips.merge(sd, on="service_id")
    if runs.empty:
        return runs
    tz = _feed_info(data_dir)["timezone"]
    udates = np.unique(runs["date"].to_numpy())
    origin = service_day_origin_utc(udates, tz)
    runs = runs.assign(
        t0_utc=origin[np.searchsorted(udates, runs["date"].to_numpy())] + runs["start_s"],
        service_date=runs["date"])
    return runs.sort_values(["service_date", "trip_id"], kind="stable").reset_index(drop=True)


def _passes(data_dir, trips, sd, pat) -> pd.DataFrame:
    runs = _runs(data_dir, trips, sd)
    if runs.empty:
        return _empty_passes()
    # runs are in (date, trip) order and each pattern's segments in time order, so the
    # passes come out sorted by service date, trip and time
    return _expand(runs, pat)


def passes_for_trip(data_dir, trip_id: str, service_date) -> pd.DataFrame:
    """All segment passes of one trip on one service date (columns as :func:`iter_passes`).

    The date need not be a day the trip's service runs (the app may ask "what if"); the
    timing is the trip's pattern placed on that date.
    """
    trips = _read(data_dir, "trips", columns=["trip_id", "service_id", "pattern_id",
                                                      "start_s"])
    trips = trips[trips["trip_id"] == str(trip_id)]
    if trips.empty:
        raise KeyError(f"trip {trip_id!r} not in {DataDir(data_dir).gtfs.trips}")
    pid = int(trips["pattern_id"].iloc[0])
    pat = _read(data_dir, "patterns", filters=[("pattern_id", "==", pid)])
    date = pd.Timestamp(service_date).normalize()
    sd = pd.DataFrame({"service_id": trips["service_id"].astype(str).to_numpy(),
                       "date": pd.DatetimeIndex([date]).astype("datetime64[ns]")})
    return _passes(data_dir, trips.astype({"service_id": str}), sd, pat)


# ---------------------------------------------------------------------------------------------
# the whole day of a vehicle block: trips, layovers, parked

TIMELINE_KINDS = ("layover", "parked")
#: block id of the buses without a block on a day (parked all day at the depot)
IDLE_BLOCK = "(idle)"


def stop_positions(data_dir, shape_dist: pd.DataFrame) -> pd.DataFrame:
    """Roof points (m, projected CRS) of stops at distances along their shapes.

    Parameters
    ----------
    data_dir : path with ``gtfs/segments.parquet``
    shape_dist : DataFrame with ``shape_id`` and ``dist_m`` (m along the shape)

    Returns
    -------
    DataFrame indexed like *shape_dist*: ``x, y, z`` (the roof point on the road, as the
    segments' points: the road's height plus the roof height) and ``tile`` (the segment's).
    """
    seg = _read(data_dir, "segments", columns=["shape_id", "cum_dist_m", "length_m", "x", "y",
                                                       "z", "x_end", "y_end", "z_end", "tile"])
    seg = seg.sort_values(["shape_id", "cum_dist_m"], kind="stable").reset_index(drop=True)
    out = pd.DataFrame(index=shape_dist.index, columns=["x", "y", "z"], dtype=float)
    out["tile"] = ""
    for shape, group in shape_dist.groupby("shape_id", sort=False):
        s = seg[seg["shape_id"].astype(str) == str(shape)]
        if s.empty:
            raise KeyError(f"shape {shape!r} has no segments")
        cum = s["cum_dist_m"].to_numpy(float)
        d = group["dist_m"].to_numpy(float)
        i = np.clip(np.searchsorted(cum, d, side="right") - 1, 0, len(s) - 1)
        length = s["length_m"].to_numpy(float)[i]
        frac = np.clip((d - cum[i]) / np.where(length > 0, length, 1.0), 0.0, 1.0)
        for c in "xyz":
            a, b = s[c].to_numpy(float)[i], s[f"{c}_end"].to_numpy(float)[i]
            out.loc[group.index, c] = a + frac * (b - a)
        out.loc[group.index, "tile"] = s["tile"].to_numpy()[i]
    return out


def block_timeline(data_dir, year: int, months=None, routes=None, depot=None,
                   depot_shading: str = "city") -> dict:
    """Every block-day of *year* cut into driving, layover and parked time (UTC).

    A block-day (vehicle block x service date) owns the service day from the GTFS time origin
    of its date to that of the next date (24 h; 23 h or 25 h when the clocks change),
    stretched to its last arrival when the block runs past it and starting no earlier than
    the end of the same block's previous block-day (a block past midnight owns its small
    hours, the next day's block-day starts after them).  In it: the trips (driving, from
    first departure to last arrival; the passes cover exactly this time); between two trips
    the *layover* at the terminal where the first one arrived (its last stop); before the
    first departure and after the last arrival the bus is *parked* at the depot.  So
    ``driving + layover + parked`` is the block-day's window, with no instant counted twice
    (trips of a block that overlap in the timetable are reported as ``overlap_s``).

    Parameters
    ----------
    data_dir : path, scenario data directory (``gtfs/`` from :func:`ingest_gtfs`)
    year : int
    months : list of int, optional; block-days whose service date is in these months
    routes : list of str, optional; only trips of these route ids
    depot : (x, y, z, tile) of the depot in the projected CRS, optional; default the first
        stop of each block-day's first trip
    depot_shading : ``city`` (the depot's place in the city model), ``open`` or ``covered``

    Returns
    -------
    dict of DataFrames
        ``block_days``: ``block_id, service_date, month, trips, window_start_utc,
        window_end_utc, first_departure_utc, last_arrival_utc, driving_s, overlap_s,
        layover_s, parked_s``;
        ``intervals``: ``block_id, service_date, month, kind`` (layover | parked), ``after_trip``
        (position of the trip before it in the block-day; -1 before the first),
        ``point_id, t0_utc, t1_utc, buses`` (1; for the idle rows, block id
        :data:`IDLE_BLOCK`, the number of buses without a block that day: the fleet has as
        many buses as the busiest day has blocks, the others stand at the depot, the
        configured one or the commonest first stop, from the day's origin to the next);
        ``points``: ``point_id, stop_id, x, y, z, tile, shading`` (tile ``open`` /
        ``covered`` for a depot not in the city model); ``trip_runs``: ``trip_id,
        service_date, block_id, position`` (the trip's place in its block-day); ``buses``.
    """
    trips, ends = _block_trips(data_dir, routes)
    pts, stop_point, depot_point = _timeline_points(data_dir, trips, ends, depot, depot_shading)
    runs, tz = _block_runs(data_dir, trips, year, months)
    bd, runs = _block_days(runs)
    lay, over, pos = _layovers(runs, stop_point)
    dp = bd["first_stop_id"].astype(str).map(depot_point) if depot is None else pd.Series(
        depot_point["depot"], index=bd.index)
    am = pd.DataFrame({"block_id": bd["block_id"], "date": bd["date"], "kind": "parked", "after_trip": -1,
                       "point_id": dp, "t0_utc": bd["window_start_utc"], "t1_utc": bd["first_departure_utc"]})
    pm = pd.DataFrame({"block_id": bd["block_id"], "date": bd["date"], "kind": "parked",
                       "after_trip": bd["trips"] - 1, "point_id": dp, "t0_utc": bd["last_arrival_utc"],
                       "t1_utc": bd["window_end_utc"]})
    fleet_depot = (depot_point["depot"] if depot is not None
                   else int(dp.mode().iloc[0]) if len(dp) else -1)
    idle, n_buses = _idle_buses(bd, year, months, fleet_depot, tz)
    # the blocks as one set of sorted categories (the idle buses' too): the intervals sort
    # as by the strings, which they are given once sorted
    blocks = pd.CategoricalDtype(pd.Index(sorted({*bd["block_id"].cat.categories, IDLE_BLOCK}), dtype=str))
    iv = pd.concat([f.astype({"block_id": blocks}) for f in (am.assign(buses=1), lay.assign(buses=1),
                                                             pm.assign(buses=1), idle)], ignore_index=True)
    del am, lay, pm, idle
    iv = iv[iv["t1_utc"] > iv["t0_utc"]]
    iv = iv.sort_values(_BLOCK_DAY + ["t0_utc"], kind="stable").reset_index(drop=True)
    iv = iv.rename(columns={"date": "service_date"}).astype({"point_id": np.int64, "after_trip": np.int64,
                                                             "buses": np.int64})
    iv["month"] = month_labels(iv["service_date"])
    bd = _block_day_totals(bd, runs, over, iv)
    iv["block_id"] = _strings(iv["block_id"])
    trip_runs = pd.DataFrame({"trip_id": _strings(runs["trip_id"]), "service_date": runs["date"],
                              "block_id": _strings(runs["block_id"]), "position": pos})
    return {"block_days": bd, "intervals": iv, "points": pts, "trip_runs": trip_runs, "buses": n_buses}


#: the columns that name a block-day
_BLOCK_DAY = ["block_id", "date"]


def _strings(values: pd.Series) -> pd.Series:
    """A categorical Series of strings as the strings, taken from its categories by their
    codes (in Arrow: no Python string per row, where ``astype(str)`` made one for each of a
    network's millions of rows)."""
    codes = values.cat.codes.to_numpy()
    if (codes < 0).any() or not pd.api.types.is_string_dtype(values.cat.categories.dtype):
        return values.astype(str)
    return pd.Series(values.cat.categories.take(codes), index=values.index, name=values.name)


def month_labels(dates):
    """``YYYY-MM`` of each of *dates*, as ``Series.dt.strftime("%Y-%m")`` gives it (a string
    array, missing where a date is), formatted once per distinct date: a network's millions
    of rows share a few hundred dates, and a string object each cost ~0.3 GB."""
    codes, uniq = pd.factorize(pd.DatetimeIndex(pd.to_datetime(dates)))
    labels = pd.Series(uniq).dt.strftime("%Y-%m").array
    return labels.take(codes, allow_fill=True)


def _block_trips(data_dir, routes):
    """(trips with their pattern's end stops, end time and block, the patterns' ends)."""
    from ...models.vehicle import infer_blocks

    trips = _read(data_dir, "trips", columns=["trip_id", "route_id", "service_id", "block_id",
                                                      "shape_id", "pattern_id", "start_s"])
    if routes is not None:
        trips = trips[trips["route_id"].astype(str).isin([str(r) for r in routes])]
    ps = _read(data_dir, "pattern_stops").sort_values(["pattern_id", "stop_index"], kind="stable")
    ends = ps.groupby("pattern_id", sort=True).agg(
        first_stop_id=("stop_id", "first"), last_stop_id=("stop_id", "last"),
        first_dist_m=("dist_m", "first"), last_dist_m=("dist_m", "last"), duration_s=("arr_s", "last"))
    trips = trips.merge(ends, left_on="pattern_id", right_index=True, how="inner")
    trips["end_s"] = trips["start_s"] + trips["duration_s"]
    trips["block_id"] = infer_blocks(trips).to_numpy()
    return trips, ends


def _timeline_points(data_dir, trips, ends, depot, depot_shading: str):
    """The points a bus stands at: the trips' first and last stops (by stop id) and the
    depot; (points, stop id -> city point id, stop id -> depot point id)."""
    shape_of = trips.drop_duplicates("pattern_id").set_index("pattern_id")["shape_id"]
    stops = pd.concat([
        pd.DataFrame({"stop_id": ends["first_stop_id"], "dist_m": ends["first_dist_m"]}),
        pd.DataFrame({"stop_id": ends["last_stop_id"], "dist_m": ends["last_dist_m"]})])
    stops = stops[stops.index.isin(shape_of.index)]
    stops["shape_id"] = shape_of.loc[stops.index].to_numpy()
    stops = stops.drop_duplicates("stop_id").reset_index(drop=True)
    pts = pd.concat([stops[["stop_id"]], stop_positions(data_dir, stops)], axis=1)
    pts["shading"] = "city"
    if depot is not None:
        pts = pd.concat([pts, pd.DataFrame({"stop_id": ["depot"], "x": [depot[0]], "y": [depot[1]],
                                            "z": [depot[2]], "tile": [depot[3]],
                                            "shading": ["city"]})], ignore_index=True)
    if depot_shading != "city":
        depots = pts[pts["stop_id"].isin(["depot"] if depot is not None else ends["first_stop_id"])].copy()
        depots["shading"] = depot_shading
        depots["tile"] = depot_shading
        pts = pd.concat([pts, depots], ignore_index=True)
    pts = pts.reset_index(drop=True)
    pts.insert(0, "point_id", np.arange(len(pts), dtype=np.int64))
    city = pts[pts["shading"] == "city"]
    stop_point = dict(zip(city["stop_id"], city["point_id"]))
    depot_point = dict(zip(pts.loc[pts["shading"] == depot_shading, "stop_id"],
                           pts.loc[pts["shading"] == depot_shading, "point_id"]))
    return pts, stop_point, depot_point


#: the trips' columns of the timeline's runs (:func:`_block_runs`)
_RUN_COLUMNS = ["trip_id", "service_id", "block_id", "first_stop_id", "last_stop_id", "start_s",
                "end_s"]
#: the runs' columns held as categories
_RUN_STRINGS = ["trip_id", "block_id", "first_stop_id", "last_stop_id"]


def _block_runs(data_dir, trips, year: int, months):
    """(runs of the year's months and of the day before each, in block, date and time order,
    with UTC times ``t0, t1`` and the service day ``day0, day1``; the feed's time zone)."""
    # the run's months, and the day before each (its block past midnight moves the first
    # day's start, as in a run of the whole year); the days before are dropped later
    sd = service_dates(data_dir, year)
    in_run = sd["date"].dt.month.isin(list(months)) if months is not None else pd.Series(True, sd.index)
    before = (sd["date"] + pd.Timedelta(days=1)).dt.month.isin(list(months)) if months is not None else in_run
    sd = sd.assign(in_run=in_run)[in_run | (before & (sd["date"] + pd.Timedelta(days=1)).dt.year.eq(year))]
    # a trip's columns repeat on each of its days: only those the timeline uses, its strings
    # as categories (sorted: the runs sort as by the strings; a network's 4.7 M trip-days
    # held four strings each, 0.9 GB)
    runs = (trips[_RUN_COLUMNS].astype({c: "category" for c in _RUN_STRINGS})
            .merge(sd, on="service_id").drop(columns="service_id"))
    tz = _feed_info(data_dir)["timezone"]
    udates = np.unique(runs["date"].to_numpy()) if len(runs) else np.zeros(0, "datetime64[ns]")
    origin = service_day_origin_utc(udates, tz)
    next_origin = service_day_origin_utc(udates + np.timedelta64(1, "D"), tz)
    k = np.searchsorted(udates, runs["date"].to_numpy())
    runs = runs.assign(t0=origin[k] + runs.pop("start_s").to_numpy(float),
                       t1=origin[k] + runs.pop("end_s").to_numpy(float),
                       day0=origin[k], day1=next_origin[k])
    runs = runs.sort_values(["block_id", "date", "t0", "trip_id"], kind="stable").reset_index(drop=True)
    return runs, tz


def _block_days(runs):
    """(block-days of the run's months with their windows, the runs of those months)."""
    key = _BLOCK_DAY
    bd = runs.groupby(key, sort=True).agg(
        trips=("trip_id", "size"), first_departure_utc=("t0", "min"), last_arrival_utc=("t1", "max"),
        day0=("day0", "first"), day1=("day1", "first"),
        first_stop_id=("first_stop_id", "first")).reset_index()
    bd["window_end_utc"] = np.maximum(bd["day1"], bd["last_arrival_utc"])
    prev_end = bd.groupby("block_id", sort=False)["window_end_utc"].shift(1)
    start = np.maximum(bd["day0"], prev_end.fillna(-np.inf))
    bd["window_start_utc"] = np.minimum(start, bd["first_departure_utc"])
    keep = bd.set_index(key).index.isin(pd.MultiIndex.from_frame(runs.loc[runs["in_run"], key]))
    bd = bd[keep].reset_index(drop=True)
    runs = runs[runs["in_run"].to_numpy()].reset_index(drop=True)
    return bd, runs


def _layovers(runs, stop_point: dict):
    """Layovers from a trip's arrival to the next trip's departure of the same block-day;
    (layovers, overlaps of trips that run into the next, trip positions in the block-day)."""
    # the runs come sorted by block-day: a block-day's runs are consecutive (the blocks'
    # codes compared, not their strings as Python objects: millions of them at network scale)
    block = pd.factorize(runs["block_id"])[0]
    date = runs["date"].to_numpy()
    same = (block[1:] == block[:-1]) & (date[1:] == date[:-1])
    del block
    a = np.flatnonzero(same)
    idx = np.arange(len(runs))
    pos = idx - np.maximum.accumulate(np.where(np.r_[True, ~same], idx, 0)) if len(runs) else idx
    del idx
    gap = runs["t0"].to_numpy()[a + 1] - runs["t1"].to_numpy()[a]
    stop, stops = pd.factorize(runs["last_stop_id"].array[a], use_na_sentinel=False)
    stops = pd.Index(np.asarray(stops, dtype=object))
    lay = pd.DataFrame({"block_id": runs["block_id"].array[a], "date": date[a],
                        "kind": "layover", "after_trip": pos[a],
                        "point_id": stops.map(stop_point).to_numpy()[stop],
                        "t0_utc": runs["t1"].to_numpy()[a], "t1_utc": runs["t0"].to_numpy()[a + 1]})
    over = pd.DataFrame({"block_id": lay["block_id"], "date": lay["date"],
                         "overlap_s": np.maximum(-gap, 0.0)})
    return lay[gap > 0], over, pos


def _idle_buses(bd, year: int, months, fleet_depot: int, tz: str):
    """Idle buses: on a day with fewer blocks than the fleet has buses (the most blocks of
    any day), the others stand parked at the depot from the day's origin to the next;
    (their parked rows, the fleet's size)."""
    per_day = bd.groupby("date").size()
    n_buses = int(per_day.max()) if len(per_day) else 0
    days = pd.DatetimeIndex(sorted({d for d in pd.date_range(f"{year}-01-01", f"{year}-12-31", freq="D")
                                    if months is None or d.month in set(months)})).astype("datetime64[ns]")
    idle_n = n_buses - per_day.reindex(days, fill_value=0).to_numpy()
    d0, d1 = service_day_origin_utc(days, tz), service_day_origin_utc(days + pd.Timedelta(days=1), tz)
    idle = pd.DataFrame({"block_id": IDLE_BLOCK, "date": days, "kind": "parked", "after_trip": -1,
                         "point_id": fleet_depot, "t0_utc": d0, "t1_utc": d1, "buses": idle_n})
    return idle[idle["buses"] > 0], n_buses


def _block_day_totals(bd, runs, over, iv):
    """The block-days with their driving, overlap, layover and parked seconds and month."""
    key = _BLOCK_DAY
    driving = runs.assign(s=runs["t1"] - runs["t0"]).groupby(key, sort=True)["s"].sum()
    bd["driving_s"] = driving.to_numpy()
    bd["overlap_s"] = over.groupby(key, sort=True)["overlap_s"].sum().reindex(
        pd.MultiIndex.from_frame(bd[key]), fill_value=0.0).to_numpy() if len(over) else 0.0
    # per kind the rows of the buses in service, each interval's block-day as its row of
    # *bd* (-1: none; not a copy of the intervals' strings per kind)
    at = pd.MultiIndex.from_frame(bd[key].astype({"block_id": iv["block_id"].dtype})).get_indexer(
        pd.MultiIndex.from_arrays([iv["block_id"], iv["service_date"]]))
    own = (iv["block_id"] != IDLE_BLOCK).to_numpy(bool) & (at >= 0)
    s = (iv["t1_utc"] - iv["t0_utc"]).to_numpy()
    for kind in TIMELINE_KINDS:
        m = own & (iv["kind"] == kind).to_numpy(bool)
        bd[f"{kind}_s"] = pd.Series(s[m]).groupby(at[m]).sum().reindex(
            np.arange(len(bd)), fill_value=0.0).to_numpy()
    bd = bd.rename(columns={"date": "service_date"}).drop(columns=["day0", "day1", "first_stop_id"])
    bd["block_id"] = _strings(bd["block_id"])
    bd["month"] = month_labels(bd["service_date"])
    return bd
