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

from ...errors import InputError

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


#: longest line accepted in a GTFS table (bytes); real feeds stay far below 10 kB a line
MAX_LINE_BYTES = 1 << 20

#: GTFS route types: the basic ones and the extended (Google "Extended GTFS Route Types")
#: range 100..1799
BASIC_ROUTE_TYPES = {0: "tram", 1: "subway", 2: "rail", 3: "bus", 4: "ferry", 5: "cable tram",
                     6: "aerial lift", 7: "funicular", 11: "trolleybus", 12: "monorail"}

#: the route types of buses: basic bus (3) and trolleybus (11), the extended bus services
#: 700..716 and trolleybus 800 (the default of ``run.route_types``)
BUS_ROUTE_TYPES = frozenset({3, 11, *range(700, 717), 800})


def route_type_set(route_types) -> frozenset | None:
    """The GTFS route types ``run.route_types`` stands for: ``"bus"`` (the default:
    :data:`BUS_ROUTE_TYPES`), ``"all"`` (None: every type) or a list of types."""
    if route_types is None or route_types == "all":
        return None
    if route_types == "bus":
        return BUS_ROUTE_TYPES
    return frozenset(int(t) for t in route_types)


#: encodings a GTFS table is read in when it is not UTF-8 (GTFS requires UTF-8): a byte order
#: mark names UTF-16 or UTF-32; otherwise Windows-1252 (a superset of latin-1's printable
#: characters), or latin-1 where a byte is undefined in Windows-1252
_BOMS = ((b"\xff\xfe\x00\x00", "utf-32"), (b"\x00\x00\xfe\xff", "utf-32"),
         (b"\xef\xbb\xbf", "utf-8-sig"), (b"\xff\xfe", "utf-16"), (b"\xfe\xff", "utf-16"))
_NOT_CP1252 = (b"\x81", b"\x8d", b"\x8f", b"\x90", b"\x9d")
_ENCODING_NAMES = {"utf-16": "UTF-16 (with a byte order mark)",
                   "utf-32": "UTF-32 (with a byte order mark)",
                   "cp1252": "Windows-1252 (cp1252, latin-1 with more letters)", "latin-1": "latin-1 (ISO 8859-1)"}


def check_tables(path: Path, max_line: int = MAX_LINE_BYTES) -> dict[str, str]:
    """Stream every ``.txt`` table of a GTFS zip or folder once, before pandas reads it.

    A corrupt or truncated zip, a member that does not inflate, or a line longer than
    *max_line* bytes (a table that is not CSV, which pandas would try to hold whole) raises
    :class:`InputError` naming the file, member and line; memory stays at one chunk.

    Returns
    -------
    dict
        The tables that are not UTF-8, by name, with the encoding to read them in
        (``utf-16``, ``utf-32``, ``cp1252`` or ``latin-1``; see :data:`_BOMS`).
    """
    import codecs
    import zipfile
    import zlib

    chunk = min(1 << 20, max_line)
    found: dict[str, str] = {}

    def scan(fh, name: str) -> None:
        since_nl, lines = 0, 0          # bytes since the last newline, newlines seen
        utf8 = codecs.getincrementaldecoder("utf-8")()
        encoding, cp1252 = None, True
        first = True
        while block := fh.read(chunk):
            if first:
                encoding = next((enc for bom, enc in _BOMS if block.startswith(bom)), None)
                first = False
            if encoding is None:
                try:
                    utf8.decode(block)
                except UnicodeDecodeError:
                    encoding = "8bit"
            cp1252 = cp1252 and not any(b in block for b in _NOT_CP1252)
            last = block.rfind(b"\n")
            if last < 0:
                since_nl += len(block)
            else:
                # lines inside a chunk are shorter than the chunk (<= the limit); only the
                # line running across chunk boundaries can grow past it
                since_nl += block.find(b"\n")
                if since_nl <= max_line:
                    lines += block.count(b"\n")
                    since_nl = len(block) - last - 1
            if since_nl > max_line:
                raise InputError(f"{path}: {name} line {lines + 1} is longer than "
                                 f"{max_line // 1024} kB: not a GTFS table")
        if encoding == "8bit":
            encoding = "cp1252" if cp1252 else "latin-1"
        if encoding not in (None, "utf-8-sig"):
            found[name] = encoding

    if path.is_dir():
        for member in sorted(path.glob("*.txt")):
            with open(member, "rb") as fh:
                scan(fh, member.name)
        return found
    try:
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                if info.is_dir() or not info.filename.endswith(".txt"):
                    continue
                with zf.open(info) as fh:
                    scan(fh, info.filename)
    except (zipfile.BadZipFile, zlib.error, EOFError, OSError, NotImplementedError) as exc:
        raise InputError(f"{path}: not a readable GTFS zip ({type(exc).__name__}: {exc})") from None
    return found


def _as_utf8(path: Path, encodings: dict[str, str], folder: Path) -> Path:
    """The ``.txt`` tables of the feed at *path* written to *folder* in UTF-8, those named in
    *encodings* decoded from theirs (streamed, a line at a time); returns *folder*."""
    import io
    import shutil
    import zipfile

    def copy(fh, name: str) -> None:
        dest = folder / Path(name).name
        enc = encodings.get(name)
        if enc is None:
            with open(dest, "wb") as out:
                shutil.copyfileobj(fh, out)
            return
        text = io.TextIOWrapper(fh, encoding=enc, newline="")
        with open(dest, "w", encoding="utf-8", newline="") as out:
            shutil.copyfileobj(text, out)

    if path.is_dir():
        for member in sorted(path.glob("*.txt")):
            with open(member, "rb") as fh:
                copy(fh, member.name)
    else:
        with zipfile.ZipFile(path) as zf:
            for info in zf.infolist():
                if not info.is_dir() and info.filename.endswith(".txt"):
                    with zf.open(info) as fh:
                        copy(fh, info.filename)
    return folder


def _check_timezone(name: str, where: str) -> str:
    from zoneinfo import ZoneInfo, ZoneInfoNotFoundError

    try:
        ZoneInfo(str(name))
    except (ZoneInfoNotFoundError, ValueError):
        raise InputError(f"{where}: {name!r} is not an IANA time zone (e.g. Europe/Berlin)") from None
    return str(name)


def read_feed(feed_path, dist_units: str | None = None, timezone: str | None = None,
              route_types="bus") -> Feed:
    """Read a GTFS zip or folder with gtfs-kit and prepare it.

    Parameters
    ----------
    feed_path : str or Path
        GTFS zip file or folder of ``.txt`` files.
    dist_units : str, optional
        Units of ``shape_dist_traveled`` (``m``, ``km``, ``mi``, ``ft``); inferred by
        gtfs-kit when omitted (the trajectory stage checks them against the geometry).
    timezone : str, optional
        IANA zone of the timetable when the feed has no agency.txt (or no timezone in
        it); the feed's own ``agency_timezone`` wins when present.
    route_types : "bus", "all" or iterable of int, optional
        GTFS ``route_type`` values to keep (basic 0..12 or extended 100..1799; ``"bus"``:
        :data:`BUS_ROUTE_TYPES`; ``"all"`` or None: every type). Trips of other types are
        dropped and counted; kept trips of types that are not buses are named in a problem
        line (a building model knows no tunnels or viaducts). Buses by default.

    Raises
    ------
    InputError
        When the path is missing or the feed lacks trips, stop times, stops or calendars.
    """
    import gtfs_kit as gk

    path = Path(feed_path)
    problems: list[str] = []
    gfeed = _read_tables(gk, path, dist_units, problems)
    _drop_duplicates(gfeed, path, problems)
    _check_dates(gfeed, path)
    _check_calendar_spans(gfeed, path, problems)
    _clean_coordinates(gfeed, path, problems)
    tz = _feed_timezone(gfeed, path, timezone, problems)
    gfeed = _select_routes(gfeed, path, route_types, problems)
    _fill_single_times(gfeed, path, problems)
    _frequencies_within_service_day(gfeed, path, problems)
    gfeed, n_freq = _expand_frequencies(gk, gfeed, path, problems)
    # trips without stop times and stop times of unknown trips or stops go before any shape
    # is built from the stops (gtfs-kit's create_shapes fails on a trip without stop times)
    gfeed.trips, gfeed.stop_times = _drop_unmatched(gfeed.trips, gfeed.stop_times, gfeed.stops,
                                                    path, problems)
    _drop_unusable_shapes(gfeed, problems)
    gfeed, n_built = _build_missing_shapes(gk, gfeed, path, problems)
    st = _stop_times_in_seconds(gfeed.stop_times, problems)
    st, trips = _within_service_day(st, gfeed.trips, path, problems)
    return Feed(path=path, timezone=tz, routes=gfeed.routes, trips=trips.reset_index(drop=True),
                stops=gfeed.stops, stop_times=st, shapes=gfeed.shapes, calendar=gfeed.calendar,
                calendar_dates=gfeed.calendar_dates, dist_units=gfeed.dist_units,
                shapes_built_from_stops=n_built, frequency_trips=n_freq, problems=problems,
                gk_feed=gfeed)


def library_call(path: Path, what: str, fn, *args, **kwargs):
    """``fn(*args, **kwargs)``, a call into gtfs-kit (or pandas) on the feed at *path*: any
    error it raises becomes one :class:`InputError` line naming the feed, the step (*what*:
    the table and field it works on) and the library's own message, never a traceback."""
    try:
        return fn(*args, **kwargs)
    except InputError:
        raise
    except Exception as exc:  # noqa: BLE001 - a library's many error kinds, said in one line
        msg = str(exc).strip().splitlines()[0][:200] if str(exc).strip() else ""
        kind = type(exc).__name__
        if isinstance(exc, KeyError):
            msg = f"no entry {msg}"
        raise InputError(f"{path}: {what} failed ({kind}: {msg})") from None


def _read_tables(gk, path: Path, dist_units: str | None, problems: list[str]):
    """gtfs-kit's feed of *path*, with the trips, stop times, stops and a calendar it needs.

    Tables that are not UTF-8 (a byte order mark of UTF-16 or UTF-32, or Windows-1252 /
    latin-1 text) are read in their encoding, each named in a problem line; a value that is
    not a number in a numeric column is named with its table, line and column."""
    import tempfile

    if not path.exists():
        raise InputError(f"{path}: GTFS feed not found")
    encodings = check_tables(path)
    for enc in sorted(set(encodings.values())):
        names = sorted(Path(n).name for n, e in encodings.items() if e == enc)
        problems.append(f"{', '.join(names)} {'is' if len(names) == 1 else 'are'} encoded in "
                        f"{_ENCODING_NAMES[enc]}, not UTF-8 as GTFS requires: read as {enc}")
    with tempfile.TemporaryDirectory(prefix="vipvflow-gtfs-") as tmp:
        source = _as_utf8(path, encodings, Path(tmp)) if encodings else path
        try:
            gfeed = library_call(path, "reading the feed (gtfs-kit read_feed)",
                                 (lambda: gk.read_feed(source, dist_units=dist_units)) if dist_units
                                 else (lambda: _read_infer(gk, source)))
        except InputError:
            bad = _bad_value(source)
            if bad:
                raise InputError(f"{path}: {bad}") from None
            raise
    for name in ("trips", "stop_times", "stops"):
        if getattr(gfeed, name) is None or getattr(gfeed, name).empty:
            raise InputError(f"{path}: {name}.txt missing or empty")
    if (gfeed.calendar is None or gfeed.calendar.empty) and (
            gfeed.calendar_dates is None or gfeed.calendar_dates.empty):
        raise InputError(f"{path}: neither calendar.txt nor calendar_dates.txt has service dates")
    return gfeed


def _bad_value(source: Path) -> str | None:
    """The first value of a GTFS table at *source* (zip or folder of UTF-8 tables) that
    gtfs-kit cannot read as the number its column holds: ``"stops.txt line 3: stop_lat
    'north' is not a number"``; None when there is none."""
    import zipfile

    from gtfs_kit.constants import DTYPES

    def check(fh, name: str) -> str | None:
        table = Path(name).stem
        kinds = {c: t for c, t in DTYPES.get(table, {}).items() if t != "string"}
        if not kinds:
            return None
        try:
            df = pd.read_csv(fh, dtype=str, keep_default_na=False, encoding="utf-8-sig")
        except (ValueError, UnicodeDecodeError):
            return None
        df.columns = [str(c).strip() for c in df.columns]
        for col, kind in kinds.items():
            if col not in df:
                continue
            text = df[col].str.strip()
            empty = text.isin(["", "nan", "NaN", "null"])
            num = pd.to_numeric(text.where(~empty), errors="coerce")
            bad = ~empty & num.isna()
            if kind != "float":
                bad |= ~empty & num.notna() & (num % 1 != 0)
            if bad.any():
                i = int(np.flatnonzero(bad.to_numpy())[0])
                what = "a number" if kind == "float" else "an integer"
                return f"{Path(name).name} line {i + 2}: {col} {df[col].iloc[i]!r} is not {what}"
        return None

    if source.is_dir():
        for member in sorted(source.glob("*.txt")):
            with open(member, "rb") as fh:
                if found := check(fh, member.name):
                    return found
        return None
    with zipfile.ZipFile(source) as zf:
        for info in zf.infolist():
            if not info.is_dir() and info.filename.endswith(".txt"):
                with zf.open(info) as fh:
                    if found := check(fh, info.filename):
                        return found
    return None


#: the columns that identify a row of each GTFS table (GTFS reference: "Primary key");
#: a later row repeating them is dropped, the first kept (:func:`_drop_duplicates`)
PRIMARY_KEYS = {"routes": ("route_id",), "trips": ("trip_id",), "stops": ("stop_id",),
                "stop_times": ("trip_id", "stop_sequence"), "calendar": ("service_id",),
                "calendar_dates": ("service_id", "date"),
                "shapes": ("shape_id", "shape_pt_sequence"),
                "frequencies": ("trip_id", "start_time")}


def _drop_duplicates(gfeed, path: Path, problems: list[str]) -> None:
    """Rows repeating the primary key of an earlier row of their table are dropped, the
    first kept, and counted per table with the first one's line (a repeated route or trip
    doubled every trip of it; a repeated stop time made a trip stop twice)."""
    for table, key in PRIMARY_KEYS.items():
        frame = getattr(gfeed, table, None)
        if frame is None or frame.empty or not set(key) <= set(frame.columns):
            continue
        ids = frame[list(key)].astype("string").apply(lambda c: c.str.strip())
        dup = ids.duplicated(keep="first").to_numpy()
        if not dup.any():
            continue
        first = int(np.flatnonzero(dup)[0])
        same = frame.astype("string").duplicated(keep="first").to_numpy()
        example = ", ".join(f"{k} {ids[k].iloc[first]}" for k in key)
        problems.append(f"{table}.txt: {int(dup.sum())} rows repeat the {' and '.join(key)} of an "
                        f"earlier row ({int(same.sum())} of them identical to it; first: {example} "
                        f"at line {int(frame.index[first]) + 2}): the first row kept, the others "
                        "dropped")
        setattr(gfeed, table, frame[~dup])


def _feed_timezone(gfeed, path: Path, timezone: str | None, problems: list[str]) -> str:
    """The timetable's IANA zone: agency.txt's, else *timezone* as given, else an error."""
    tz = None
    if gfeed.agency is not None and "agency_timezone" in gfeed.agency:
        zones = gfeed.agency["agency_timezone"].dropna().unique()
        if len(zones) > 1:
            problems.append(f"agency.txt has several timezones {list(zones)}; using {zones[0]}")
        tz = str(zones[0]) if len(zones) else None
    if tz is not None:
        return _check_timezone(tz, f"{path}: agency.txt agency_timezone")
    if timezone:
        tz = _check_timezone(timezone, "--timezone")
        what = "agency.txt is missing" if gfeed.agency is None else "agency.txt has no agency_timezone"
        problems.append(f"{what}; timezone {tz} as given")
        return tz
    if gfeed.agency is None:
        raise InputError(f"{path}: agency.txt is missing, so the timetable's time zone is unknown; "
                         "pass --timezone (or inputs.gtfs_timezone), e.g. Europe/Berlin")
    raise InputError(f"{path}: agency.txt has no agency_timezone; pass --timezone "
                     "(or inputs.gtfs_timezone), e.g. Europe/Berlin")


def _expand_frequencies(gk, gfeed, path: Path, problems: list[str]):
    """frequencies.txt expanded into trips: (feed, number of trips added)."""
    if gfeed.frequencies is None or gfeed.frequencies.empty:
        return gfeed, 0
    n_before = len(gfeed.trips)
    fr = gfeed.frequencies
    exact = (pd.to_numeric(fr["exact_times"], errors="coerce").fillna(0).astype(int)
             if "exact_times" in fr else pd.Series(0, index=fr.index))
    gfeed = library_call(path, "frequencies.txt: expanding trip_id, start_time, end_time, "
                         "headway_secs into trips (gtfs-kit)", gk.expand_frequencies, gfeed)
    n_freq = len(gfeed.trips) - n_before
    if (exact == 0).any():
        problems.append(f"{int((exact == 0).sum())} frequencies.txt rows are headway-based "
                        "(exact_times 0): departures placed at start_time + n x headway")
    return gfeed, n_freq


def _drop_unusable_shapes(gfeed, problems: list[str]) -> None:
    """Trips naming a shape missing from shapes.txt (or with fewer than two distinct
    points) lose their shape_id, to get one built from their stops."""
    trips = gfeed.trips
    if "shape_id" not in trips:
        trips = trips.assign(shape_id=pd.Series(pd.NA, index=trips.index, dtype="string"))
        gfeed.trips = trips
    named = trips["shape_id"].notna()
    if gfeed.shapes is not None and not gfeed.shapes.empty:
        good = _usable_shapes(gfeed.shapes)
        unknown = named & ~trips["shape_id"].isin(good)
        n_single = int((named & trips["shape_id"].isin(set(gfeed.shapes["shape_id"]) - good)).sum())
        if unknown.any():
            problems.append(f"{int(unknown.sum())} trips reference a shape_id missing from "
                            f"shapes.txt or with fewer than two distinct points ({n_single}); "
                            "shapes built from their stops")
            gfeed.trips.loc[unknown, "shape_id"] = pd.NA
            gfeed.shapes = gfeed.shapes[gfeed.shapes["shape_id"].isin(good)]
            if gfeed.shapes.empty:
                gfeed.shapes = None
    else:
        gfeed.shapes = None
        if named.any():
            problems.append(f"{int(named.sum())} trips name a shape_id but the feed has no "
                            "shapes.txt; shapes built from their stops")
            gfeed.trips.loc[named, "shape_id"] = pd.NA


def _build_missing_shapes(gk, gfeed, path: Path, problems: list[str]):
    """A shape from the stop sequence for every trip without one: (feed, shapes built)."""
    n_missing = int(gfeed.trips["shape_id"].isna().sum())
    if not n_missing:
        return gfeed, 0
    before = set() if gfeed.shapes is None else set(gfeed.shapes["shape_id"])
    gfeed = library_call(path, "building shapes from stop_times.txt stop sequences and "
                         "stops.txt stop_lat/stop_lon (gtfs-kit create_shapes)",
                         gk.create_shapes, gfeed)
    n_built = len(set(gfeed.shapes["shape_id"]) - before)
    problems.append(f"{n_missing} trips without a shape: {n_built} shapes built from the "
                    "stop sequence (straight lines between stops)")
    return gfeed, n_built


def _stop_times_in_seconds(stop_times: pd.DataFrame, problems: list[str]) -> pd.DataFrame:
    """Stop times with ``arr_s`` and ``dep_s`` (s), repaired where one is missing or the
    departure precedes the arrival, in trip and stop order."""
    st = stop_times.copy()
    st["arr_s"] = time_to_seconds(st["arrival_time"])
    st["dep_s"] = time_to_seconds(st["departure_time"])
    unreadable = ((st["arrival_time"].notna() & st["arr_s"].isna())
                  | (st["departure_time"].notna() & st["dep_s"].isna()))
    if unreadable.any():
        first = st.loc[unreadable].iloc[0]
        problems.append(f"{int(unreadable.sum())} stop_times have times that are not H:MM:SS "
                        f"(e.g. trip {first['trip_id']}: {first['arrival_time']!r}); "
                        "interpolated along the trip like untimed stops")
    # a stop with only one of the two times: use it for both
    st["arr_s"] = st["arr_s"].fillna(st["dep_s"])
    st["dep_s"] = st["dep_s"].fillna(st["arr_s"])
    bad = st["dep_s"] < st["arr_s"]
    if bad.any():
        problems.append(f"{int(bad.sum())} stop_times depart before they arrive; departure set "
                        "to arrival")
        st.loc[bad, "dep_s"] = st.loc[bad, "arr_s"]
    return st.sort_values(["trip_id", "stop_sequence"], kind="stable").reset_index(drop=True)


#: the longest plausible service day (h): GTFS times count from noon minus 12 h of the
#: service date and pass 24:00:00 for trips after midnight, but a bus timetable's day ends
#: by 30:00:00 (06:00 the next morning); a later (or negative) time is a shifted or broken
#: timetable (:func:`_within_service_day`)
SERVICE_DAY_H = 30.0


def _fmt_hms(seconds: float) -> str:
    sign, seconds = ("-" if seconds < 0 else ""), abs(seconds)
    return f"{sign}{int(seconds // 3600)}:{int(seconds % 3600 // 60):02d}:{int(seconds % 60):02d}"


def _within_service_day(st: pd.DataFrame, trips: pd.DataFrame, path: Path,
                        problems: list[str]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(stop times, trips) without the trips that have a time before 0:00:00 or after
    :data:`SERVICE_DAY_H` (counted, the first named); none left is an :class:`InputError`."""
    limit = SERVICE_DAY_H * 3600.0
    t = st[["arr_s", "dep_s"]].to_numpy(float)
    out = ((t < 0) | (t > limit)).any(axis=1)
    if not out.any():
        return st, trips
    bad_trips = set(st.loc[out, "trip_id"])
    first = st.loc[out].iloc[0]
    worst = t[(t < 0) | (t > limit)]
    span = (f"from {_fmt_hms(worst.min())}" if worst.min() == worst.max() else
            f"from {_fmt_hms(worst.min())} to {_fmt_hms(worst.max())}")
    what = (f"{len(bad_trips)} of {trips['trip_id'].nunique()} trips have stop times beyond a "
            f"service day (before 0:00:00 or after {SERVICE_DAY_H:g}:00:00: {span}; first: trip "
            f"{first['trip_id']} at stop_sequence {first['stop_sequence']})")
    if len(bad_trips) >= trips["trip_id"].nunique():
        raise InputError(f"{path}: stop_times.txt: {what}: no trip left (a timetable shifted "
                         "by days, or times in another unit?)")
    problems.append(f"stop_times.txt: {what}; dropped")
    st = st[~st["trip_id"].isin(bad_trips)].reset_index(drop=True)
    return st, trips[~trips["trip_id"].isin(bad_trips)].reset_index(drop=True)


def _frequencies_within_service_day(gfeed, path: Path, problems: list[str]) -> None:
    """frequencies.txt rows whose start or end time lies beyond a service day (see
    :data:`SERVICE_DAY_H`), or whose headway is not a positive number of seconds, are dropped
    and counted before they are expanded into trips (an end time at 999999:00:00 would make
    billions)."""
    fr = gfeed.frequencies
    if fr is None or fr.empty:
        return
    limit = SERVICE_DAY_H * 3600.0
    start, end = time_to_seconds(fr["start_time"]), time_to_seconds(fr["end_time"])
    headway = pd.to_numeric(fr["headway_secs"], errors="coerce").to_numpy(float)
    bad = ~(np.isfinite(start) & np.isfinite(end) & (start >= 0) & (end <= limit)
            & (end >= start) & np.isfinite(headway) & (headway > 0))
    if not bad.any():
        return
    i = int(np.flatnonzero(bad)[0])
    problems.append(f"frequencies.txt: {int(bad.sum())} rows with a start_time, end_time or "
                    f"headway_secs outside a service day of {SERVICE_DAY_H:g} h (first: line "
                    f"{int(fr.index[i]) + 2}, {fr['start_time'].iloc[i]}-{fr['end_time'].iloc[i]} "
                    f"every {fr['headway_secs'].iloc[i]} s); dropped")
    gfeed.frequencies = fr[~bad]


def _check_calendar_spans(gfeed, path: Path, problems: list[str]) -> None:
    """calendar.txt rows whose start_date is after their end_date have no dates: dropped and
    counted; when no service date is left in calendar.txt and calendar_dates.txt, the feed
    is refused naming the first such row."""
    cal = gfeed.calendar
    if cal is None or cal.empty:
        return
    start, end = cal["start_date"].astype(str).str.strip(), cal["end_date"].astype(str).str.strip()
    reversed_ = (start > end).to_numpy()       # YYYYMMDD: text order is date order
    if not reversed_.any():
        return
    i = int(np.flatnonzero(reversed_)[0])
    what = (f"calendar.txt: {int(reversed_.sum())} of {len(cal)} services have a start_date after "
            f"their end_date (first: service {cal['service_id'].iloc[i]} at line "
            f"{int(cal.index[i]) + 2}, {start.iloc[i]} > {end.iloc[i]}), so no dates")
    cd = gfeed.calendar_dates
    added = (cd is not None and not cd.empty and
             (pd.to_numeric(cd["exception_type"], errors="coerce") == 1).any())
    if reversed_.all() and not added:
        raise InputError(f"{path}: {what}: the feed has no service date (start_date and "
                         "end_date swapped?)")
    problems.append(f"{what}; dropped")
    gfeed.calendar = cal[~reversed_]


def _drop_unmatched(trips: pd.DataFrame, st: pd.DataFrame, stops: pd.DataFrame, path: Path,
                    problems: list[str]):
    """(trips, stop times) without the stop times at unknown stops and the trips left with
    no stop times (each counted)."""
    missing_stop = ~st["stop_id"].isin(stops["stop_id"])
    if missing_stop.any():
        problems.append(f"{int(missing_stop.sum())} stop_times reference unknown stops; dropped")
        st = st[~missing_stop]
    no_times = ~trips["trip_id"].isin(st["trip_id"])
    if no_times.any():
        problems.append(f"{int(no_times.sum())} of {len(trips)} trips have no stop_times; dropped")
        trips = trips[~no_times]
    if trips.empty:
        raise InputError(f"{path}: no trip has stop_times (stop_times.txt names none of the "
                         "trips.txt trips at known stops)")
    return trips.reset_index(drop=True), st.reset_index(drop=True)


def _check_dates(gfeed, path: Path) -> None:
    """calendar.txt and calendar_dates.txt dates must be GTFS dates (YYYYMMDD)."""
    for table, cols in (("calendar", ("start_date", "end_date")), ("calendar_dates", ("date",))):
        frame = getattr(gfeed, table)
        if frame is None or frame.empty:
            continue
        for col in cols:
            if col not in frame:
                raise InputError(f"{path}: {table}.txt has no {col} column")
            text = frame[col].astype("string").str.strip()
            bad = ~text.str.fullmatch(r"\d{8}").fillna(False)
            if not bad.any():
                parsed = pd.to_datetime(text, format="%Y%m%d", errors="coerce")
                bad = parsed.isna()
            if bad.any():
                i = int(np.flatnonzero(bad.to_numpy())[0])
                raise InputError(f"{path}: {table}.txt line {i + 2}: {col} {frame[col].iloc[i]!r} "
                                 "is not a date YYYYMMDD")


def _clean_coordinates(gfeed, path: Path, problems: list[str]) -> None:
    """Stops and shape points with missing or impossible WGS84 coordinates are removed
    (counted); stop_times at such stops go with them."""
    def valid(lat, lon):
        lat = pd.to_numeric(lat, errors="coerce").astype(float)
        lon = pd.to_numeric(lon, errors="coerce").astype(float)
        return (np.isfinite(lat) & np.isfinite(lon) & (lat.abs() <= 90) & (lon.abs() <= 180)
                & ~((lat == 0) & (lon == 0)))

    stops = gfeed.stops
    ok = valid(stops["stop_lat"], stops["stop_lon"])
    if not ok.all():
        # stations and nodes without coordinates that no trip stops at go unremarked
        used = gfeed.stop_times["stop_id"].isin(stops.loc[~ok, "stop_id"])
        if used.any():
            bad = sorted(set(gfeed.stop_times.loc[used, "stop_id"].astype(str)))
            problems.append(f"{len(bad)} stops served by trips have missing or impossible "
                            f"coordinates (e.g. {bad[0]}); their {int(used.sum())} stop_times "
                            "dropped")
        if not ok.any():
            raise InputError(f"{path}: stops.txt: no stop has valid stop_lat/stop_lon")
        gfeed.stops = stops[ok].reset_index(drop=True)
        gfeed.stop_times = gfeed.stop_times[~used]
    shapes = gfeed.shapes
    if shapes is not None and not shapes.empty:
        ok = valid(shapes["shape_pt_lat"], shapes["shape_pt_lon"])
        if not ok.all():
            problems.append(f"{int((~ok).sum())} shape points have missing or impossible "
                            "coordinates; dropped")
            gfeed.shapes = shapes[ok].reset_index(drop=True)


def _usable_shapes(shapes: pd.DataFrame) -> set:
    """shape_ids with at least two distinct points."""
    pts = shapes.dropna(subset=["shape_pt_lat", "shape_pt_lon"]).drop_duplicates(
        ["shape_id", "shape_pt_lat", "shape_pt_lon"])
    n = pts.groupby("shape_id").size()
    return set(n.index[n >= 2])


def _select_routes(gfeed, path: Path, route_types, problems: list[str]):
    """Drop trips of unknown routes and, when *route_types* is given, of other route types."""
    routes, trips = gfeed.routes, gfeed.trips
    if routes is None or routes.empty:
        raise InputError(f"{path}: routes.txt missing or empty")
    orphan = ~gfeed.stop_times["trip_id"].isin(trips["trip_id"])
    if orphan.any():
        problems.append(f"{int(orphan.sum())} stop_times name a trip_id that trips.txt does not "
                        "list; dropped")
    unknown = ~trips["route_id"].isin(routes["route_id"])
    if unknown.any():
        names = sorted(trips.loc[unknown, "route_id"].astype(str).unique())
        problems.append(f"{int(unknown.sum())} trips name a route_id missing from routes.txt "
                        f"({', '.join(names[:5])}{' ...' if len(names) > 5 else ''}); dropped")
        trips = trips[~unknown]
    wanted = route_type_set(route_types)
    rtype = pd.to_numeric(routes["route_type"], errors="coerce")
    if wanted is not None:
        keep_routes = set(routes.loc[rtype.isin(wanted), "route_id"])
        other = ~trips["route_id"].isin(keep_routes)
        label = "bus" if wanted == BUS_ROUTE_TYPES else sorted(wanted)
        if other.all():
            present = sorted(int(t) for t in rtype.dropna().unique())
            raise InputError(f"{path}: no trip has a route_type in run.route_types "
                             f"({label}); the feed has {present}"
                             + ("; name the types to simulate in run.route_types (a list) "
                                "or 'all'" if wanted == BUS_ROUTE_TYPES else ""))
        if other.any():
            dropped = sorted(int(t) for t in rtype[routes["route_id"].isin(
                set(trips.loc[other, "route_id"]))].dropna().unique())
            problems.append(f"{int(other.sum())} trips of route types {dropped} outside "
                            f"run.route_types ({label}); dropped")
            trips = trips[~other]
    kept_types = rtype[routes["route_id"].isin(set(trips["route_id"]))].dropna().astype(int)
    not_bus = sorted(set(kept_types) - BUS_ROUTE_TYPES)
    if not_bus:
        n = int(trips["route_id"].isin(set(routes.loc[rtype.isin(not_bus), "route_id"])).sum())
        problems.append(f"{n} trips of route types {not_bus} that are not buses are simulated "
                        "as buses on the street: a building model knows no tunnels, cuttings "
                        "or viaducts, so where such a line runs underground or elevated its "
                        "light is wrong")
    if trips.empty:
        raise InputError(f"{path}: no trip left: every trip names a route_id missing from "
                         "routes.txt")
    gfeed.trips = trips.reset_index(drop=True)
    gfeed.stop_times = gfeed.stop_times[gfeed.stop_times["trip_id"].isin(gfeed.trips["trip_id"])]
    if gfeed.frequencies is not None and not gfeed.frequencies.empty:
        gfeed.frequencies = gfeed.frequencies[
            gfeed.frequencies["trip_id"].isin(gfeed.trips["trip_id"])]
    return gfeed


def _fill_single_times(gfeed, path: Path, problems: list[str]) -> None:
    """stop_times with only an arrival or only a departure time (a column or a value
    missing): the one given is used for both."""
    st = gfeed.stop_times.copy()
    for col in ("arrival_time", "departure_time"):
        if col not in st:
            st[col] = pd.Series(pd.NA, index=st.index, dtype="string")
    if st["arrival_time"].isna().all() and st["departure_time"].isna().all():
        raise InputError(f"{path}: stop_times.txt has no arrival_time or "
                         "departure_time values")
    one = st["arrival_time"].isna() ^ st["departure_time"].isna()
    if one.any():
        problems.append(f"{int(one.sum())} stop_times give only an arrival or only a departure "
                        "time; used for both")
        st["arrival_time"] = st["arrival_time"].fillna(st["departure_time"])
        st["departure_time"] = st["departure_time"].fillna(st["arrival_time"])
    gfeed.stop_times = st


def _read_infer(gk, path: Path):
    """gtfs-kit's read with inferred units; a feed without any distance gets metres."""
    try:
        return gk.read_feed(path)
    except ValueError:
        return gk.read_feed(path, dist_units="m")
