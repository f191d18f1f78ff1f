"""Simulation results as CityGML 3.0 Dynamizers (a "digital twin" file) and their reader.

Modelling (``docs/dynamizer.md`` maps every element to the official schema):

- ``--aggregate segment``: one ``tran:Road`` per route shape (route and direction) holding one
  ``tran:TrafficSpace`` per 10 m segment with its ``lod0MultiCurve`` (a 3D ``gml:LineString``
  at roof height in the run's CRS); ``--aggregate route``: one ``tran:Road`` per route holding
  one ``tran:TrafficSpace`` per direction whose MultiCurve has one LineString per shape, the
  values summed over the direction's segments.  Each TrafficSpace carries ``gen:DoubleAttribute``
  totals (``h_direct``, ``h_diffuse``, ``h_reflected``, ``h_total`` in Wh/m2, ``pv_kwh`` in kWh)
  and one ``dyn:Dynamizer`` per attribute driving it with the monthly series;
- one ``gen:GenericLogicalSpace`` for the whole network with the mean roof irradiance by
  hour of the day of each month (W/m2, ``g_*``);
- one ``gen:GenericThematicSurface`` per building surface that reflects light onto an exported
  segment, related to its building, with the reflected PV energy attributed to it per month.

The file is written as a stream (``lxml.etree.xmlfile``): one city object is built in memory at
a time and the run's tables are read in record batches, so memory does not grow with the
number of segments.  Values are written with ``repr`` precision so that reading them back gives
the exact float64 of the run's GeoParquet.
"""
from __future__ import annotations

import csv
import itertools
import json
import logging
import re
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from lxml import etree

from ..errors import InputError
from ..store import DataDir, RunDir, atomic_path
from .citygml3 import (CORE, DYN, NSMAP, SCHEMA_LOCATIONS, XSI, first_srs_name, q, schema_location,
                       srs_name, vertical_epsg)

log = logging.getLogger(__name__)

GML_ID = q("gml:id")
PREFIX = "vipv_"

#: per-segment monthly series: attribute -> (observed property, unit)
SEGMENT_SERIES = {
    "h_direct": ("direct irradiation on the bus roof per month", "Wh/m2"),
    "h_diffuse": ("diffuse irradiation on the bus roof per month", "Wh/m2"),
    "h_reflected": ("irradiation reflected by the city onto the bus roof per month", "Wh/m2"),
    "h_total": ("total irradiation on the bus roof per month", "Wh/m2"),
    "pv_kwh": ("PV energy harvested on the segment per month (all passes)", "kWh"),
}
#: the same series summed over a route direction's segments (``--aggregate route``)
ROUTE_SERIES = {
    **{name: (f"{prop}, summed over the segments", unit)
       for name, (prop, unit) in SEGMENT_SERIES.items() if name.startswith("h_")},
    "pv_kwh": ("PV energy harvested on the route direction per month (all passes)", "kWh"),
}
#: network series from hourly_pattern.parquet: attribute -> (observed property, unit)
NETWORK_SERIES = {
    "g_direct": ("mean direct irradiance on bus roofs by hour of the month's mean day", "W/m2"),
    "g_diffuse": ("mean diffuse irradiance on bus roofs by hour of the month's mean day", "W/m2"),
    "g_reflected": ("mean reflected irradiance on bus roofs by hour of the month's mean day", "W/m2"),
    "g_total": ("mean total irradiance on bus roofs by hour of the month's mean day", "W/m2"),
}
#: per reflecting building surface
SURFACE_SERIES = {
    "pv_kwh_reflected": ("PV energy from light this surface reflects onto the routes, per month "
                         "(attributed by albedo-weighted view factor)", "kWh"),
}
ENCODINGS = ("inline", "tabulated")
AGGREGATES = ("segment", "route")
#: above this many selected segments the default aggregation is per route
AUTO_ROUTE_ABOVE = 20_000
_REF = re.compile(r"\[@gml:id='(?P<id>[^']+)'\].*\[gen:name='(?P<attr>[^']+)'\]")
_BATCH_ROWS = 65_536

T = {name: q(name) for name in ("core:CityModel", "core:cityObjectMember", "tran:Road", "gml:name")}


def _num(v: float) -> str:
    """Shortest text that parses back to the same float64 (``repr``), in xs:double spelling."""
    v = float(v)
    if v != v:
        return "NaN"
    if v in (float("inf"), float("-inf")):
        return "INF" if v > 0 else "-INF"
    return repr(v)


def xml_id(text) -> str:
    """A gml:id (an XML NCName) from a GTFS id: characters outside ``[A-Za-z0-9_.-]`` become
    ``_xHHHH_`` (so distinct ids stay distinct)."""
    return re.sub(r"[^A-Za-z0-9_.-]", lambda m: f"_x{ord(m.group()):04x}_", str(text))


def attribute_ref(object_tag: str, object_id: str, attribute: str, value_kind: str = "DoubleAttribute") -> str:
    """The ``dyn:attributeRef`` XPath of a generic attribute's value of a city object."""
    return (f"//{object_tag}[@gml:id='{object_id}']/core:genericAttribute/"
            f"gen:{value_kind}[gen:name='{attribute}']/gen:value")


# ----------------------------------------------------------------------------- series
@dataclass
class Series:
    """One time series of one attribute of one city object."""

    object_id: str
    object_tag: str
    attribute: str
    observation: str
    uom: str
    timestamps: list[str]     # ISO 8601 with UTC offset, interval starts
    values: np.ndarray        # float64
    start: str                # dyn:startTime (first interval start)
    end: str                  # dyn:endTime (end of the last interval)

    @property
    def dynamizer_id(self) -> str:
        return f"{self.object_id}_dyn_{self.attribute}"


class _Months:
    """ISO timestamps of month starts in the feed's time zone (cached: few distinct months)."""

    def __init__(self, tz: str):
        self.tz = tz
        self._start: dict[str, str] = {}
        self._end: dict[str, str] = {}

    def start(self, month: str) -> str:
        if month not in self._start:
            self._start[month] = pd.Timestamp(f"{month}-01", tz=self.tz).isoformat()
        return self._start[month]

    def end(self, month: str) -> str:
        if month not in self._end:
            self._end[month] = (pd.Timestamp(f"{month}-01") + pd.offsets.MonthBegin(1)).tz_localize(
                self.tz).isoformat()
        return self._end[month]


# ----------------------------------------------------------------------------- run inputs
@dataclass
class RunData:
    """What the export reads of a finished run: paths and small metadata, no big tables."""

    run_dir: Path
    data_dir: Path
    manifest: dict
    timezone: str
    horizontal_epsg: int | None
    vertical_epsg: int | None
    months: list[str]                 # months of the run (YYYY-MM), sorted
    routes: list[str]                 # route_short_name of the run, sorted

    @property
    def srs_name(self) -> str | None:
        return srs_name(self.horizontal_epsg, self.vertical_epsg)

    @property
    def segment_month_path(self) -> Path:
        return self.run_dir / "segment_month.parquet"

    @property
    def segments_path(self) -> Path:
        return self.run_dir / "segments.parquet"


def load_run(run_dir: str | Path) -> RunData:
    """The outputs of a finished run that the export needs (InputError names what is missing)."""
    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise InputError(f"run directory not found: {run_dir}")
    need = ["segments.parquet", "segment_month.parquet", "hourly_pattern.parquet", "manifest.json"]
    missing = [n for n in need if not (run_dir / n).exists()]
    if missing:
        raise InputError(f"{run_dir}: not a finished run (missing {', '.join(missing)})")
    from ..simulation.rundir import open_run

    run = open_run(run_dir)          # the data dir found from anywhere (run folders travel)
    manifest, data_dir = run.manifest, run.data_dir
    tz = "UTC"
    feed = DataDir(data_dir).gtfs.feed_json
    if feed.exists():
        tz = json.loads(feed.read_text()).get("timezone", "UTC")
    else:
        log.warning("%s not found: timestamps are written in UTC", feed)
    meta = pq.read_schema(run_dir / "segments.parquet").metadata or {}
    epsg = _geoparquet_epsg(meta)
    vertical = None
    cfg = manifest.get("config", {})
    for f in (cfg.get("inputs", {}) or {}).get("citygml", []) or []:
        vertical = vertical_epsg(first_srs_name(Path(f))) if Path(f).is_file() else None
        break
    months, routes = set(), set()
    for b in pq.ParquetFile(run_dir / "segment_month.parquet").iter_batches(
            _BATCH_ROWS * 4, columns=["month", "route_short_name"]):
        months.update(_month_strings(b.column(0)).unique().to_pylist())
        routes.update(str(r) for r in b.column(1).unique().to_pylist() if r is not None)
    months, routes = sorted(months), sorted(routes)
    return RunData(run_dir, data_dir, manifest, tz, epsg, vertical, months, routes)


def _month_strings(col):
    """A ``month`` column as ``YYYY-MM`` strings (runs write it as a date, the first day of the
    month; older runs as ``YYYY-MM`` text)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    if pa.types.is_string(col.type) or pa.types.is_large_string(col.type):
        return pc.utf8_slice_codeunits(col, 0, 7)
    if pa.types.is_dictionary(col.type):
        return _month_strings(pc.cast(col, pa.string()))
    return pc.strftime(col, format="%Y-%m")


def _geoparquet_epsg(meta: dict) -> int | None:
    geo = meta.get(b"geo")
    if not geo:
        return None
    from pyproj import CRS

    info = json.loads(geo)
    col = info.get("columns", {}).get(info.get("primary_column", "geometry"), {})
    crs = col.get("crs")
    return CRS.from_user_input(crs).to_epsg() if crs is not None else None


# ----------------------------------------------------------------------------- selection
@dataclass
class Selection:
    """What to export: months (YYYY-MM), routes (route_short_name), the first N segments."""

    months: list[str]
    routes: list[str] | None = None
    max_segments: int | None = None
    #: the selected segment ids met while streaming, as closed ranges [first, last]
    ranges: list = field(default_factory=list)

    def note(self, segment_id: int) -> None:
        if self.ranges and self.ranges[-1][1] == segment_id - 1:
            self.ranges[-1][1] = segment_id
        else:
            self.ranges.append([segment_id, segment_id])

    def contains(self, ids: np.ndarray) -> np.ndarray:
        """Which of *ids* were exported (boolean mask)."""
        if not self.ranges:
            return np.zeros(len(ids), bool)
        r = np.asarray(self.ranges)
        k = np.searchsorted(r[:, 0], ids, side="right") - 1
        return (k >= 0) & (ids <= r[np.maximum(k, 0), 1])


def _selection(run: RunData, months, routes, max_segments) -> Selection:
    chosen = run.months
    if months:
        wanted = []
        for m in months:
            text = str(m).strip()
            if re.fullmatch(r"\d{1,2}", text):
                text = f"{run.manifest.get('year', run.months[0][:4])}-{int(text):02d}"
            if text not in run.months:
                raise InputError(f"--months: {m} is not a month of the run {run.run_dir} "
                                 f"(it has {', '.join(run.months)})")
            wanted.append(text)
        chosen = sorted(set(wanted))
    if routes:
        unknown = [r for r in routes if str(r) not in run.routes]
        if unknown:
            raise InputError(f"--routes: {', '.join(map(str, unknown))} not in the run {run.run_dir} "
                             f"(it has {', '.join(run.routes)})")
        routes = [str(r) for r in routes]
    if max_segments is not None and max_segments < 1:
        raise InputError(f"--segments must be at least 1, got {max_segments}")
    return Selection(chosen, routes or None, max_segments)


# ----------------------------------------------------------------------------- streams
@dataclass
class SegmentRecord:
    segment_id: int
    shape_id: str
    route: str
    direction: int
    coords: np.ndarray      # (n, 3) float64
    months: list[str]
    values: np.ndarray      # (len(months), len(SEGMENT_SERIES)) float64


def _wkb_coords(wkb) -> list[np.ndarray]:
    import shapely

    geoms = shapely.from_wkb(np.asarray(wkb, dtype=object))
    coords, index = shapely.get_coordinates(geoms, include_z=True, return_index=True)
    cuts = np.flatnonzero(np.diff(index)) + 1
    return np.split(coords, cuts)


class _Geometries:
    """Segment geometries from ``segments.parquet`` read forward in segment id order."""

    def __init__(self, path: Path):
        self._batches = pq.ParquetFile(path).iter_batches(_BATCH_ROWS, columns=["segment_id", "geometry"])
        if not _sorted_by_segment(path):
            log.info("%s is not in segment order: read whole", path)
            table = pq.read_table(path, columns=["segment_id", "geometry"]).sort_by("segment_id")
            self._batches = iter(table.to_batches())
        self._buf: dict[int, np.ndarray] = {}
        self._last = -1

    def take(self, segment_id: int) -> np.ndarray:
        while segment_id > self._last:
            try:
                b = next(self._batches)
            except StopIteration:
                break
            ids = b.column("segment_id").to_numpy()
            for k in [k for k in self._buf if k < segment_id]:      # not selected: drop
                del self._buf[k]
            self._buf.update(zip(ids.tolist(), _wkb_coords(b.column("geometry").to_pylist())))
            if len(ids):
                self._last = max(self._last, int(ids.max()))
        coords = self._buf.pop(segment_id, None)
        if coords is None:
            raise InputError(f"segments.parquet: segment {segment_id} of segment_month.parquet "
                             "has no geometry")
        return coords


def _segment_records(run: RunData, sel: Selection) -> Iterator[SegmentRecord]:
    """Each selected segment with its monthly values, in segment id order, streamed in record
    batches (a segment's rows may straddle two batches: the last id of a batch waits for the
    next one)."""
    import pyarrow as pa
    import pyarrow.compute as pc

    cols = ["segment_id", "shape_id", "route_short_name", "direction_id", "month", *SEGMENT_SERIES]
    geoms = _Geometries(run.segments_path)
    months = pa.array(sel.months)
    routes = pa.array(sel.routes) if sel.routes is not None else None
    if _sorted_by_segment(run.segment_month_path):
        source = (pa.Table.from_batches([b]) for b in
                  pq.ParquetFile(run.segment_month_path).iter_batches(_BATCH_ROWS, columns=cols))
    else:
        log.info("%s is not in segment order: read whole and sorted", run.segment_month_path)
        source = iter([pq.read_table(run.segment_month_path, columns=cols)
                       .sort_by([("segment_id", "ascending"), ("month", "ascending")])])
    carry, last_id, n = None, -1, 0
    for table in itertools.chain(source, [None]):
        if table is None:
            if carry is None:
                break
            done, carry = carry, None
        else:
            if carry is not None:
                table = pa.concat_tables([carry, table])
            ids = table.column("segment_id").to_numpy()
            if not len(ids):
                continue
            tail = int(np.searchsorted(ids, ids[-1]))       # ids ascending: the last id's rows
            carry, done = table.slice(tail), table.slice(0, tail)
        done = done.set_column(done.schema.get_field_index("month"), "month", _month_strings(done.column("month")))
        keep = pc.is_in(done.column("month"), value_set=months)
        if routes is not None:
            keep = pc.and_(keep, pc.is_in(pc.cast(done.column("route_short_name"), pa.string()),
                                          value_set=routes))
        done = done.filter(keep)
        if not done.num_rows:
            continue
        ids = done.column("segment_id").to_numpy()
        month_col = done.column("month").to_numpy(zero_copy_only=False).astype(str)
        order = np.lexsort((month_col, ids))
        ids, month_col = ids[order], month_col[order]
        values = np.column_stack([done.column(c).to_numpy(zero_copy_only=False) for c in SEGMENT_SERIES]
                                 ).astype(np.float64)[order]
        shape_col = done.column("shape_id").to_numpy(zero_copy_only=False)[order]
        route_col = done.column("route_short_name").to_numpy(zero_copy_only=False)[order]
        dir_col = done.column("direction_id").to_numpy(zero_copy_only=False)[order]
        starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
        ends = np.r_[starts[1:], len(ids)]
        for a, b in zip(starts.tolist(), ends.tolist()):
            sid = int(ids[a])
            if sid <= last_id:
                raise InputError(f"{run.segment_month_path}: segment {sid} appears twice")
            last_id = sid
            sel.note(sid)
            yield SegmentRecord(sid, str(shape_col[a]), str(route_col[a]), int(dir_col[a]), geoms.take(sid),
                                month_col[a:b].tolist(), values[a:b])
            n += 1
            if sel.max_segments is not None and n >= sel.max_segments:
                return


def _sorted_by_segment(path: Path) -> bool:
    """True when the segment ids of the file never decrease (checked from row group statistics
    when they exist, else from the column streamed)."""
    prev = None
    for b in pq.ParquetFile(path).iter_batches(_BATCH_ROWS * 4, columns=["segment_id"]):
        ids = b.column(0).to_numpy()
        if len(ids) and ((prev is not None and ids[0] < prev) or (np.diff(ids) < 0).any()):
            return False
        if len(ids):
            prev = ids[-1]
    return True


# ----------------------------------------------------------------------------- XML pieces
# City objects are written as text (one chunk per city object, indented, one element a line),
# parsed by libxml2 into an element and handed to the xmlfile stream: much faster than
# building each of the ~60 elements of a Dynamizer with SubElement, and the parse checks
# that every chunk is well-formed.
_DECL = {ns: " ".join(f'xmlns:{p}="{NSMAP[p]}"' for p in ns) for ns in (
    ("core", "dyn", "gen", "tran", "gml"), ("core", "dyn", "gen", "tran", "gml", "xlink"))}


def _esc(text) -> str:
    return (str(text).replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
            .replace('"', "&quot;"))


def _chunk(text: str) -> etree._Element:
    return etree.fromstring(text, _PARSER)


_PARSER = etree.XMLParser(remove_blank_text=False, huge_tree=True)


def _generic(out: list, ind: str, kind: str, name: str, value: str) -> None:
    out.append(f"{ind}<core:genericAttribute>\n{ind}  <gen:{kind}>\n{ind}    <gen:name>{_esc(name)}</gen:name>\n"
               f"{ind}    <gen:value>{_esc(value)}</gen:value>\n{ind}  </gen:{kind}>\n"
               f"{ind}</core:genericAttribute>\n")


class _Tabulated:
    """The CSV beside the GML holding every tabulated series (one row per value)."""

    HEADER = ["series", "timestamp", "value"]

    def __init__(self, path: Path):
        self.path = path
        self.tmp = path.with_name(path.name + ".tmp")
        self._fh = self.tmp.open("w", newline="", encoding="utf-8")
        self._w = csv.writer(self._fh, lineterminator="\n")
        self._w.writerow(self.HEADER)

    def add(self, s: Series) -> str:
        key = f"{s.object_id}/{s.attribute}"
        self._w.writerows([key, t, _num(v)] for t, v in zip(s.timestamps, s.values))
        return key

    def close(self, keep: bool) -> None:
        self._fh.close()
        if keep:
            self.tmp.replace(self.path)
        else:
            self.tmp.unlink(missing_ok=True)


def _dynamizer(out: list, ind: str, s: Series, table: _Tabulated | None) -> None:
    """``core:dynamizer`` / ``dyn:Dynamizer`` with its time series (schema order)."""
    i2, i3, i4, i5 = ind + "  ", ind + "    ", ind + "      ", ind + "        "
    kind = "GenericTimeseries" if table is None else "TabulatedFileTimeseries"
    out.append(
        f'{ind}<core:dynamizer>\n{i2}<dyn:Dynamizer gml:id="{s.dynamizer_id}">\n'
        f"{i3}<gml:name>{_esc(s.attribute)} of {s.object_id}</gml:name>\n"
        f"{i3}<dyn:attributeRef>{_esc(attribute_ref(s.object_tag, s.object_id, s.attribute))}</dyn:attributeRef>\n"
        f"{i3}<dyn:startTime>{s.start}</dyn:startTime>\n{i3}<dyn:endTime>{s.end}</dyn:endTime>\n"
        f'{i3}<dyn:dynamicData>\n{i4}<dyn:{kind} gml:id="{s.dynamizer_id}_ts">\n'
        f"{i5}<dyn:firstTimestamp>{s.timestamps[0]}</dyn:firstTimestamp>\n"
        f"{i5}<dyn:lastTimestamp>{s.timestamps[-1]}</dyn:lastTimestamp>\n"
        f"{i5}<dyn:observationProperty>{_esc(s.observation)}</dyn:observationProperty>\n"
        f"{i5}<dyn:uom>{_esc(s.uom)}</dyn:uom>\n")
    if table is None:
        out.append(f"{i5}<dyn:valueType>double</dyn:valueType>\n")
        out.extend(f"{i5}<dyn:timeValuePair><dyn:TimeValuePair><dyn:timestamp>{t}</dyn:timestamp>"
                   f"<dyn:doubleValue>{_num(v)}</dyn:doubleValue></dyn:TimeValuePair></dyn:timeValuePair>\n"
                   for t, v in zip(s.timestamps, s.values))
    else:
        key = table.add(s)
        out.append(
            f"{i5}<dyn:fileLocation>{_esc(table.path.name)}</dyn:fileLocation>\n"
            f"{i5}<dyn:fileType>csv</dyn:fileType>\n{i5}<dyn:mimeType>text/csv</dyn:mimeType>\n"
            f"{i5}<dyn:valueType>double</dyn:valueType>\n"
            f"{i5}<dyn:numberOfHeaderLines>1</dyn:numberOfHeaderLines>\n"
            f"{i5}<dyn:fieldSeparator>,</dyn:fieldSeparator>\n{i5}<dyn:decimalSymbol>.</dyn:decimalSymbol>\n"
            f"{i5}<dyn:idColumnName>series</dyn:idColumnName>\n{i5}<dyn:idValue>{_esc(key)}</dyn:idValue>\n"
            f"{i5}<dyn:timeColumnName>timestamp</dyn:timeColumnName>\n"
            f"{i5}<dyn:valueColumnName>value</dyn:valueColumnName>\n")
    out.append(f"{i4}</dyn:{kind}>\n{i3}</dyn:dynamicData>\n{i2}</dyn:Dynamizer>\n{ind}</core:dynamizer>\n")


def _multi_curve(out: list, ind: str, lines: list[np.ndarray], srs: str | None, gid: str) -> None:
    crs = f' srsName="{_esc(srs)}" srsDimension="3"' if srs else ""
    out.append(f'{ind}<core:lod0MultiCurve>\n{ind}  <gml:MultiCurve gml:id="{gid}_mc"{crs}>\n')
    for k, coords in enumerate(lines):
        out.append(f'{ind}    <gml:curveMember><gml:LineString gml:id="{gid}_ls{k}"><gml:posList>'
                   f'{" ".join(map(_num, coords.ravel()))}</gml:posList></gml:LineString></gml:curveMember>\n')
    out.append(f"{ind}  </gml:MultiCurve>\n{ind}</core:lod0MultiCurve>\n")


def _space_series(oid: str, months: list[str], values: np.ndarray, series: dict, clock: _Months) -> list[Series]:
    stamps = [clock.start(m) for m in months]
    return [Series(oid, "tran:TrafficSpace", a, obs, uom, stamps, values[:, j], stamps[0], clock.end(months[-1]))
            for j, (a, (obs, uom)) in enumerate(series.items())]


def _traffic_space(out: list, ind: str, oid: str, name: str, ints: dict, strings: dict,
                   series: list[Series], lines: list[np.ndarray], srs: str | None, table, counts: dict) -> None:
    """``tran:trafficSpace`` / ``tran:TrafficSpace`` (schema order: city object, space, own)."""
    i2 = ind + "  "
    out.append(f'{ind}<tran:trafficSpace>\n{i2}<tran:TrafficSpace gml:id="{oid}">\n'
               f"{i2}  <gml:name>{_esc(name)}</gml:name>\n")
    i3 = i2 + "  "
    for k, v in strings.items():
        _generic(out, i3, "StringAttribute", k, v)
    for k, v in ints.items():
        _generic(out, i3, "IntAttribute", k, str(int(v)))
    for s in series:
        _generic(out, i3, "DoubleAttribute", s.attribute, _num(s.values.sum()))
    for s in series:
        _dynamizer(out, i3, s, table)
    counts["dynamizers"] += len(series)
    _multi_curve(out, i3, lines, srs, oid)
    out.append(f"{i3}<tran:granularity>lane</tran:granularity>\n{i2}</tran:TrafficSpace>\n{ind}</tran:trafficSpace>")


def _with_decl(text: str, decl: str) -> str:
    """Declare the namespaces on the chunk's first element."""
    i = _FIRST_TAG.match(text).end()
    return text[:i] + " " + decl + text[i:]


_FIRST_TAG = re.compile(r"\s*<[^\s>/]+")


# ----------------------------------------------------------------------------- members
#: a member writer: writes one core:cityObjectMember into an open xmlfile
MemberWriter = Callable[[etree.xmlfile], None]
_CHUNK = _DECL[("core", "dyn", "gen", "tran", "gml")]
_CHUNK_X = _DECL[("core", "dyn", "gen", "tran", "gml", "xlink")]


def _member(body: list[str]) -> etree._Element:
    """A complete ``core:cityObjectMember`` chunk from the lines of its city object."""
    return _chunk(f"<core:cityObjectMember {_CHUNK_X}>\n{''.join(body)}</core:cityObjectMember>")


def _segment_members(run: RunData, sel: Selection, table, counts: dict) -> Iterator[MemberWriter]:
    """One Road per shape, its TrafficSpaces written one at a time."""
    srs, clock = run.srs_name, _Months(run.timezone)
    records = _segment_records(run, sel)
    for shape_id, group in itertools.groupby(records, key=lambda r: r.shape_id):
        def write(xf, shape_id=shape_id, group=group):
            first = next(group)
            with xf.element(T["core:cityObjectMember"], nsmap=_MEMBER_NSMAP):
                with xf.element(T["tran:Road"], {GML_ID: f"{PREFIX}road_{xml_id(shape_id)}"}):
                    xf.write("\n", _chunk(f"<gml:name {_CHUNK}>bus roof path of shape {_esc(shape_id)} "
                                           f"(route {_esc(first.route)}, direction {first.direction})</gml:name>"))
                    for k, v in (("shape_id", shape_id), ("route", first.route)):
                        out: list[str] = []
                        _generic(out, "", "StringAttribute", k, v)
                        xf.write("\n", _chunk(_with_decl("".join(out).rstrip(), _CHUNK)))
                    for rec in itertools.chain([first], group):
                        out = []
                        oid = f"{PREFIX}seg_{rec.segment_id}"
                        _traffic_space(out, "", oid, f"segment {rec.segment_id} of shape {shape_id}",
                                       {"segment_id": rec.segment_id}, {},
                                       _space_series(oid, rec.months, rec.values, SEGMENT_SERIES, clock),
                                       [rec.coords], srs, table, counts)
                        xf.write("\n", _chunk(_with_decl("".join(out), _CHUNK)))
                        counts["segments"] += 1
                    xf.write("\n")
        yield write


def _join_lines(pieces: list[np.ndarray], tol: float = 1e-6) -> list[np.ndarray]:
    """Consecutive segment polylines joined where one ends at the next's start."""
    lines, cur = [], None
    for p in pieces:
        if cur is not None and np.allclose(cur[-1][-1], p[0], atol=tol):
            cur.append(p[1:])
        else:
            if cur is not None:
                lines.append(np.concatenate(cur))
            cur = [p]
    if cur is not None:
        lines.append(np.concatenate(cur))
    return lines


def route_totals(segment_month: pd.DataFrame) -> pd.DataFrame:
    """The route aggregation: ``SEGMENT_SERIES`` summed per route, direction and month."""
    return (segment_month.groupby(["route_short_name", "direction_id", "month"], sort=True)[list(SEGMENT_SERIES)]
            .sum().reset_index())


def _route_members(run: RunData, sel: Selection, table, counts: dict) -> Iterator[MemberWriter]:
    """One Road per route, one TrafficSpace per direction (its shapes' lines, summed values)."""
    srs, clock = run.srs_name, _Months(run.timezone)
    sums: dict[tuple, dict[str, np.ndarray]] = {}
    pieces: dict[tuple, dict[str, list[np.ndarray]]] = {}
    n_seg: dict[tuple, int] = {}
    for rec in _segment_records(run, sel):
        key = (rec.route, rec.direction)
        acc = sums.setdefault(key, {})
        for m, v in zip(rec.months, rec.values):
            if m in acc:
                acc[m] = acc[m] + v
            else:
                acc[m] = v.copy()
        pieces.setdefault(key, {}).setdefault(rec.shape_id, []).append(rec.coords)
        n_seg[key] = n_seg.get(key, 0) + 1
    for route in sorted({k[0] for k in sums}):
        def write(xf, route=route):
            rid = f"{PREFIX}route_{xml_id(route)}"
            out = [f'<tran:Road gml:id="{rid}">\n  <gml:name>bus roof paths of route {_esc(route)}</gml:name>\n']
            _generic(out, "  ", "StringAttribute", "route", route)
            for (r, direction) in sorted(k for k in sums if k[0] == route):
                acc = sums[(r, direction)]
                months = sorted(acc)
                values = np.stack([acc[m] for m in months])
                oid = f"{rid}_dir{direction}"
                shapes = pieces[(r, direction)]
                lines = [line for s in sorted(shapes) for line in _join_lines(shapes[s])]
                _traffic_space(out, "  ", oid, f"route {route} direction {direction}",
                               {"direction_id": direction, "segments": n_seg[(r, direction)]},
                               {"route": route, "shapes": " ".join(sorted(shapes))},
                               _space_series(oid, months, values, ROUTE_SERIES, clock), lines, srs, table,
                               counts)
                out.append("\n")
                counts["route_directions"] += 1
                counts["segments"] += n_seg[(r, direction)]
            out.append("</tran:Road>\n")
            xf.write(_member(out))
        yield write


def _network_member(run: RunData, sel: Selection, table, counts: dict) -> MemberWriter | None:
    hp = pd.read_parquet(run.run_dir / "hourly_pattern.parquet")
    hp["month"] = hp["month"].astype(str).str.slice(0, 7)
    hp = hp[hp["month"].isin(sel.months)].sort_values(["month", "hour"])
    if hp.empty:
        return None
    clock = _Months(run.timezone)
    oid = f"{PREFIX}network"
    stamps = [(pd.Timestamp(f"{m}-01", tz=run.timezone) + pd.Timedelta(hours=int(h))).isoformat()
              for m, h in zip(hp["month"], hp["hour"])]
    months = list(hp["month"])
    series = [Series(oid, "gen:GenericLogicalSpace", a, obs, uom, stamps, hp[a].to_numpy(np.float64),
                     clock.start(months[0]), clock.end(months[-1]))
              for a, (obs, uom) in NETWORK_SERIES.items() if a in hp]

    def write(xf):
        out = [f'<gen:GenericLogicalSpace gml:id="{oid}">\n'
               "  <gml:name>bus network of the run (hourly pattern, all segments)</gml:name>\n"]
        for s in series:
            _generic(out, "  ", "DoubleAttribute", s.attribute, _num(np.nanmean(s.values)))
        for s in series:
            _dynamizer(out, "  ", s, table)
        out.append("</gen:GenericLogicalSpace>\n")
        counts["dynamizers"] += len(series)
        counts["network"] += 1
        xf.write(_member(out))
    return write


def _surface_members(run: RunData, sel: Selection, table, counts: dict) -> Iterator[MemberWriter]:
    refl = reflector_contributions(run, sel)
    clock = _Months(run.timezone)
    for (surface_id, building_id, stype), g in refl.groupby(["surface_id", "building_id", "surface_type"],
                                                            sort=True, dropna=False):
        def write(xf, surface_id=surface_id, building_id=building_id, stype=stype, g=g):
            g = g.sort_values("month")
            oid = f"{PREFIX}refl_{xml_id(surface_id)}"
            out = [f'<gen:GenericThematicSurface gml:id="{oid}">\n'
                   f"  <gml:name>reflection onto the routes by {_esc(stype)} surface {_esc(surface_id)}</gml:name>\n"]
            if isinstance(building_id, str):
                out.append(f'  <core:relatedTo>\n    <core:CityObjectRelation gml:id="{oid}_rel">\n'
                           "      <core:relationType>reflectsLightOntoRoutesFrom</core:relationType>\n"
                           f'      <core:relatedTo xlink:href="#{_esc(building_id)}"/>\n'
                           "    </core:CityObjectRelation>\n  </core:relatedTo>\n")
            months = list(g["month"])
            stamps = [clock.start(m) for m in months]
            obs, uom = SURFACE_SERIES["pv_kwh_reflected"]
            s = Series(oid, "gen:GenericThematicSurface", "pv_kwh_reflected", obs, uom, stamps,
                       g["pv_kwh_reflected"].to_numpy(np.float64), stamps[0], clock.end(months[-1]))
            _generic(out, "  ", "StringAttribute", "surface_id", str(surface_id))
            if isinstance(building_id, str):
                _generic(out, "  ", "StringAttribute", "building_id", building_id)
            _generic(out, "  ", "StringAttribute", "surface_type", str(stype))
            _generic(out, "  ", "IntAttribute", "segments", str(int(g["segments"].max())))
            _generic(out, "  ", "DoubleAttribute", s.attribute, _num(s.values.sum()))
            _dynamizer(out, "  ", s, table)
            out.append("</gen:GenericThematicSurface>\n")
            counts["dynamizers"] += 1
            counts["surfaces"] += 1
            xf.write(_member(out))
        yield write


#: namespaces declared on each element written into the stream (xmlfile does not reuse the
#: declarations of the enclosing elements it has open)
_MEMBER_NSMAP = {k: v for k, v in NSMAP.items() if k != "xsi"}
_GML_NSMAP = {"gml": NSMAP["gml"]}


# ----------------------------------------------------------------------------- reflectors
def reflector_contributions(run: RunData, sel: Selection | None = None) -> pd.DataFrame:
    """Reflected PV energy attributed to the building surfaces that reflect onto the routes.

    Each segment's reflector groups (``parts/geometry``: weight ``r{g}_w`` = albedo x view
    factor, ``r{g}_surface`` = the tile mesh's surface holding most of the group's weight, as
    the run's rays found it) are read, not traced again.  A segment's monthly
    ``pv_kwh_reflected`` (``parts/segment_month``) is shared among its groups in proportion to
    their weights; a group merges every surface of one orientation class seen from the
    segment, so the whole group is credited to its dominant surface.  Groups on terrain or the
    ground, and groups without a surface (-1), stay unattributed.  Read tile by tile; the
    tile meshes (``data_dir/city/meshes``) give the surfaces' ids and types.

    Parameters
    ----------
    run : :func:`load_run`
    sel : the export's selection (months, and the segment ids it met while streaming);
        None: the whole run

    Returns
    -------
    DataFrame ``surface_id, building_id, surface_type, month, pv_kwh_reflected`` (kWh),
    ``segments`` (number of selected segments the surface reflects onto); empty when the
    run's geometry parts or the city meshes are absent.
    """
    from ..models.mesh import SURFACE_TYPES, TileMesh

    cols = ["surface_id", "building_id", "surface_type", "month", "pv_kwh_reflected", "segments"]
    months = sel.months if sel is not None else run.months
    pieces = []
    for f in RunDir(run.run_dir).part_files("geometry"):
        tile = f.stem.split("=", 1)[1]
        mesh_path = DataDir(run.data_dir).city.mesh(tile)
        if not mesh_path.exists():
            log.warning("no city mesh for tile %s (%s): its reflectors are not attributed", tile, mesh_path)
            continue
        names = pq.read_schema(f).names
        groups = sorted(int(c[1:-2]) for c in names if re.fullmatch(r"r\d+_w", c))
        if not groups or f"r{groups[0]}_surface" not in names:
            continue
        geo = pd.read_parquet(f, columns=["segment_id", *(f"r{g}_{k}" for g in groups for k in ("w", "surface"))])
        if sel is not None:
            geo = geo[sel.contains(geo["segment_id"].to_numpy(np.int64))]
        sm = _tile_reflected(run, tile, months)
        geo = geo[geo["segment_id"].isin(sm["segment_id"])]
        if geo.empty:
            continue
        w = np.stack([geo[f"r{g}_w"].to_numpy(np.float64) for g in groups], 1)          # (n, G)
        surf = np.stack([geo[f"r{g}_surface"].to_numpy(np.int64) for g in groups], 1)   # (n, G)
        share = w / np.where(w.sum(1, keepdims=True) > 0, w.sum(1, keepdims=True), 1.0)
        seg_idx, g_idx = np.nonzero((w > 0) & (surf >= 0))
        if not len(seg_idx):
            continue
        mesh = TileMesh.load(mesh_path)
        # each surface's type: that of its triangles
        surface_type = np.full(len(mesh.surface_ids), -1, np.int64)
        surface_type[np.asarray(mesh.surface_index)] = np.asarray(mesh.surface_type)
        hit = surf[seg_idx, g_idx]
        att = pd.DataFrame({"segment_id": geo["segment_id"].to_numpy()[seg_idx],
                            "surface_id": np.asarray(mesh.surface_ids)[hit],
                            "surface_type": np.asarray(SURFACE_TYPES)[surface_type[hit]],
                            "share": share[seg_idx, g_idx]})
        att = att[~att["surface_type"].isin(["terrain", "ground", "vegetation"])]
        if att.empty:
            continue
        att = att.groupby(["segment_id", "surface_id", "surface_type"], as_index=False)["share"].sum()
        per = att.merge(sm, on="segment_id")
        per["pv_kwh_reflected"] = per["pv_kwh_reflected"] * per["share"]
        pieces.append(per[["surface_id", "surface_type", "segment_id", "month", "pv_kwh_reflected"]])
    if not pieces:
        return pd.DataFrame(columns=cols)
    per = pd.concat(pieces, ignore_index=True)
    bid = _building_ids(run.data_dir, set(per["surface_id"]))
    per["building_id"] = per["surface_id"].map(bid)
    out = (per.groupby(["surface_id", "building_id", "surface_type", "month"], as_index=False, dropna=False)
           .agg(pv_kwh_reflected=("pv_kwh_reflected", "sum"), segments=("segment_id", "nunique")))
    return out[cols]


def _tile_reflected(run: RunData, tile: str, months: list[str]) -> pd.DataFrame:
    """``segment_id, month, pv_kwh_reflected`` of one tile (its run partitions)."""
    frames = []
    for m in months:
        f = RunDir(run.run_dir).part("segment_month", tile, m)
        if f.exists():
            d = pq.read_table(f, columns=["segment_id", "pv_kwh_reflected"])
            frames.append(pd.DataFrame({"segment_id": d.column(0).to_numpy(), "month": m,
                                        "pv_kwh_reflected": d.column(1).to_numpy()}))
    if not frames:
        return pd.DataFrame({"segment_id": pd.Series(dtype=np.int64), "month": pd.Series(dtype=object),
                             "pv_kwh_reflected": pd.Series(dtype=np.float64)})
    return pd.concat(frames, ignore_index=True)


def _building_ids(data_dir: Path, wanted: set) -> dict:
    import pyarrow as pa
    import pyarrow.compute as pc

    value_set = pa.array(sorted(map(str, wanted)), pa.string())
    out = {}
    for f in sorted(DataDir(data_dir).city.surfaces.glob("tile=*/*.parquet")):
        t = pq.read_table(f, columns=["surface_id", "building_id"])
        t = t.filter(pc.is_in(pc.cast(t.column("surface_id"), pa.string()), value_set=value_set))
        out.update(zip(t.column("surface_id").to_pylist(), t.column("building_id").to_pylist()))
    return out


# ----------------------------------------------------------------------------- writer
def choose_aggregate(run: RunData, sel: Selection, aggregate: str | None) -> str:
    """*aggregate* itself, or for None ``"segment"`` up to ``AUTO_ROUTE_ABOVE`` selected segments
    and ``"route"`` above (counted from ``segments.parquet`` and the selected routes)."""
    if aggregate is not None:
        if aggregate not in AGGREGATES:
            raise InputError(f"unknown aggregation {aggregate!r} (choose {' or '.join(AGGREGATES)})")
        return aggregate
    n = pq.ParquetFile(run.segments_path).metadata.num_rows
    if sel.routes is not None:
        import pyarrow as pa
        import pyarrow.compute as pc

        ids = set()
        for b in pq.ParquetFile(run.segment_month_path).iter_batches(
                _BATCH_ROWS * 4, columns=["segment_id", "route_short_name"]):
            keep = pc.is_in(pc.cast(b.column(1), pa.string()), value_set=pa.array(sel.routes))
            ids.update(pc.unique(b.column(0).filter(keep)).to_pylist())
            if len(ids) > AUTO_ROUTE_ABOVE:
                break
        n = len(ids)
    if sel.max_segments is not None:
        n = min(n, sel.max_segments)
    return "segment" if n <= AUTO_ROUTE_ABOVE else "route"


def write_dynamizers(run_dir: str | Path, out: str | Path, encoding: str = "inline",
                     embed: str | Path | None = None, max_segments: int | None = None,
                     aggregate: str | None = "segment", routes=None, months=None,
                     reflectors: bool | None = None) -> dict:
    """Write the run's results as a CityGML 3.0 file with Dynamizers, streamed.

    Parameters
    ----------
    run_dir : a finished run directory (``out/<scenario>/<year>``)
    out : the ``.gml`` to write
    encoding : ``"inline"`` (``dyn:GenericTimeseries``) or ``"tabulated"``
        (``dyn:TabulatedFileTimeseries`` pointing at ``<out stem>.csv`` beside *out*)
    embed : a CityGML 3.0 file: *out* is then a streamed copy of it with the results added
        as further ``cityObjectMember`` elements (and the modules added to its schemaLocation)
    max_segments : export only the first N selected segments (in segment id order)
    aggregate : ``"segment"`` (a TrafficSpace per segment), ``"route"`` (per route and
        direction), or None: segment up to ``AUTO_ROUTE_ABOVE`` segments, route above
    routes : route short names to export (default all)
    months : months to export, ``6`` or ``"2024-06"`` (default all of the run)
    reflectors : write the reflecting building surfaces (default: with ``"segment"`` only; a
        network's reflecting surfaces outnumber its route directions by far)

    Returns
    -------
    dict: ``files`` (paths written), ``aggregate``, ``segments``, ``route_directions``,
    ``surfaces``, ``network``, ``dynamizers``
    """
    if encoding not in ENCODINGS:
        raise InputError(f"unknown encoding {encoding!r} (choose {' or '.join(ENCODINGS)})")
    if embed is not None and not Path(embed).exists():
        raise InputError(f"--embed: file not found: {embed}")
    run = load_run(run_dir)
    sel = _selection(run, months, routes, max_segments)
    aggregate = choose_aggregate(run, sel, aggregate)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    counts = {"segments": 0, "route_directions": 0, "surfaces": 0, "network": 0, "dynamizers": 0}
    table = _Tabulated(out.with_suffix(".csv")) if encoding == "tabulated" else None

    def members() -> Iterator[MemberWriter]:
        if aggregate == "segment":
            yield from _segment_members(run, sel, table, counts)
        else:
            yield from _route_members(run, sel, table, counts)
        net = _network_member(run, sel, table, counts)
        if net is not None:
            yield net
        if reflectors if reflectors is not None else aggregate == "segment":
            yield from _surface_members(run, sel, table, counts)

    ok = False
    try:
        with atomic_path(out) as tmp:
            if embed is None:
                _write_standalone(tmp, run, sel, members())
            else:
                _write_embedded(tmp, Path(embed), members())
        ok = True
    finally:
        if table is not None:
            table.close(keep=ok)
    files = [out] + ([table.path] if table is not None else [])
    return {"files": files, "aggregate": aggregate, **counts}


def _envelope(run: RunData) -> etree._Element | None:
    """``gml:boundedBy`` of every segment of the run (streamed min / max of the end points)."""
    lo, hi = np.full(3, np.inf), np.full(3, -np.inf)
    cols = ["x", "y", "z", "x_end", "y_end", "z_end"]
    for b in pq.ParquetFile(run.segments_path).iter_batches(_BATCH_ROWS, columns=cols):
        a = np.column_stack([b.column(c).to_numpy() for c in cols]).reshape(-1, 3)
        if len(a):
            lo, hi = np.minimum(lo, a.min(0)), np.maximum(hi, a.max(0))
    if not np.isfinite(lo).all():
        return None
    crs = f' srsName="{_esc(run.srs_name)}"' if run.srs_name else ""
    return _chunk(f'<gml:boundedBy xmlns:gml="{NSMAP["gml"]}">\n  <gml:Envelope srsDimension="3"{crs}>\n'
                  f'    <gml:lowerCorner>{" ".join(map(_num, lo))}</gml:lowerCorner>\n'
                  f'    <gml:upperCorner>{" ".join(map(_num, hi))}</gml:upperCorner>\n'
                  "  </gml:Envelope>\n</gml:boundedBy>")


def _write_standalone(path: Path, run: RunData, sel: Selection, members: Iterator[MemberWriter]) -> None:
    attrib = {GML_ID: f"{PREFIX}results", f"{{{XSI}}}schemaLocation": schema_location()}
    with etree.xmlfile(str(path), encoding="utf-8") as xf:
        xf.write_declaration()
        with xf.element(T["core:CityModel"], attrib, nsmap=NSMAP):
            name = etree.Element(T["gml:name"], nsmap=_GML_NSMAP)
            name.text = (f"vipvflow results of {run.manifest.get('scenario', '?')} "
                         f"{run.manifest.get('year', '?')} ({', '.join(sel.months)})")
            xf.write("\n", name)
            bounds = _envelope(run)
            if bounds is not None:
                xf.write("\n", bounds, pretty_print=False)
            for write in members:
                xf.write("\n")
                write(xf)
            xf.write("\n")


# ----------------------------------------------------------------------------- embedding
#: CityModel children after which no cityObjectMember may come (CityGML 3.0 core.xsd: the
#: members form one repeated choice, closed by the ADE hook adeOfCityModel); inserting before
#: the first non-cityObjectMember member keeps the input's own order of members too
_AFTER_MEMBERS = {"appearanceMember", "featureMember", "versionMember", "versionTransitionMember",
                  "adeOfCityModel"}
_START_TAG = re.compile(rb"<(?P<name>[^\s/>?!]+)(?P<attrs>(?:\s+[^\s=/>]+\s*=\s*(?:\"[^\"]*\"|'[^']*'))*)\s*(?P<end>/?>)")
_PROLOG_ITEM = re.compile(rb"\s*(<\?.*?\?>|<!--.*?-->|<!DOCTYPE[^>]*>)", re.S)
_XMLNS = re.compile(rb"\sxmlns:(?P<p>[A-Za-z_][\w.-]*)\s*=\s*([\"'])(?P<uri>[^\"']*)\2")


def _insertion_point(src: Path) -> tuple[str, int | None]:
    """Stream *src*: check it is CityGML 3.0; return the root's qualified tag name and the
    line of the first CityModel child that must come after the city objects (None: insert
    before the closing root tag)."""
    depth, root_qname, line = 0, None, None
    try:
        for event, el in etree.iterparse(str(src), events=("start", "end"), huge_tree=True):
            if event == "start":
                depth += 1
                if depth == 1:
                    name = etree.QName(el)
                    if name.namespace != CORE or name.localname != "CityModel":
                        raise InputError(f"{src}: not a CityGML 3.0 CityModel (root {el.tag}); "
                                         "--embed needs CityGML 3.0")
                    root_qname = f"{el.prefix}:CityModel" if el.prefix else "CityModel"
                elif depth == 2 and line is None and etree.QName(el).localname in _AFTER_MEMBERS \
                        and etree.QName(el).namespace == CORE:
                    line = el.sourceline
            else:
                depth -= 1
                if depth == 1:
                    el.clear()
                    while el.getprevious() is not None:
                        del el.getparent()[0]
    except etree.XMLSyntaxError as exc:
        raise InputError(f"{src}: not well-formed XML: {exc}") from exc
    return root_qname, line


def _root_start_tag(head: bytes, src: Path) -> re.Match:
    """The root start tag in the first bytes of a file (after declaration, comments, DOCTYPE)."""
    pos = 0
    while True:
        m = _PROLOG_ITEM.match(head, pos)
        if not m:
            break
        pos = m.end()
    m = _START_TAG.search(head, pos)
    if m is None:
        raise InputError(f"{src}: root start tag not found in the first {len(head):,} bytes")
    return m


def _with_schema_locations(tag: bytes) -> bytes:
    """The root start tag with the export's modules added to its ``xsi:schemaLocation``."""
    prefixes = {m["p"]: m["uri"] for m in _XMLNS.finditer(tag)}
    xsi = next((p for p, uri in prefixes.items() if uri == XSI.encode()), None)
    end = tag.rstrip()[-2:] if tag.rstrip().endswith(b"/>") else tag.rstrip()[-1:]
    body = tag.rstrip()[:-len(end)]
    if xsi is None:
        xsi = b"xsi"
        while xsi in prefixes:
            xsi += b"_"
        body += b' xmlns:' + xsi + b'="' + XSI.encode() + b'"'
    loc = re.compile(rb"(\s" + re.escape(xsi) + rb":schemaLocation\s*=\s*)([\"'])([^\"']*)\2")
    m = loc.search(body)
    present = set(m.group(3).split()[::2]) if m else set()
    extra = " ".join(f"{ns} {url}" for ns, url in SCHEMA_LOCATIONS.items() if ns.encode() not in present).encode()
    if not extra:
        return tag
    if m:
        value = (m.group(3).rstrip() + b" " + extra).strip()
        body = body[:m.start(3)] + value + body[m.end(3):]
    else:
        body += b" " + xsi + b':schemaLocation="' + extra + b'"'
    return body + end


def _write_embedded(path: Path, src: Path, members: Iterator[MemberWriter]) -> None:
    """Copy *src* as a stream, inserting the members where CityGML 3.0 allows them and adding
    the export's modules to the root's ``xsi:schemaLocation``."""
    root_qname, line = _insertion_point(src)
    close = f"</{root_qname}".encode()

    def emit(fh):
        for write in members:
            with etree.xmlfile(fh, encoding="utf-8") as xf:
                write(xf)
            fh.write(b"\n")

    with src.open("rb") as fin, path.open("wb") as fout:
        head = fin.read(1 << 20)
        m = _root_start_tag(head, src)
        fout.write(head[:m.start()])
        fout.write(_with_schema_locations(m.group(0)))
        start_lines = head[:m.end()].count(b"\n")       # lines before the rest of the copy
        rest = head[m.end():]
        if line is not None:
            # copy up to the line of the first non-cityObjectMember member, insert, copy on
            no = start_lines + 1
            buf = rest
            while True:
                nl = buf.find(b"\n")
                if nl < 0:
                    more = fin.read(1 << 20)
                    if not more:
                        raise InputError(f"{src}:{line}: insertion line not found")
                    buf += more
                    continue
                if no == line:
                    stripped = buf.lstrip(b" \t")
                    if not stripped.startswith(b"<"):
                        raise InputError(f"{src}:{line}: cannot insert before a member sharing its line")
                    emit(fout)
                    fout.write(buf)
                    break
                fout.write(buf[:nl + 1])
                buf = buf[nl + 1:]
                no += 1
            while chunk := fin.read(1 << 20):
                fout.write(chunk)
            return
        # insert before the closing root tag: copy everything up to it, in chunks
        size = src.stat().st_size
        tail_len = min(size - m.end(), 1 << 16)
        fin.seek(size - tail_len)
        tail = fin.read()
        pos = tail.rfind(close)
        if pos < 0:
            raise InputError(f"{src}: closing {root_qname} tag not found")
        cut = size - tail_len + pos
        fin.seek(m.end())
        left = cut - m.end()
        while left > 0:
            chunk = fin.read(min(left, 1 << 20))
            fout.write(chunk)
            left -= len(chunk)
        fout.write(b"\n")
        emit(fout)
        fout.write(fin.read())


# ----------------------------------------------------------------------------- reader
def read_dynamizers(path: str | Path) -> pd.DataFrame:
    """Every Dynamizer's values in a CityGML 3.0 file, inline or tabulated (streamed).

    Returns
    -------
    DataFrame ``object_id`` (gml:id of the driven city object), ``attribute`` (generic
    attribute name), ``timestamp`` (tz-aware, interval start), ``value`` (float64), ``uom``.
    """
    path = Path(path)
    if not path.exists():
        raise InputError(f"file not found: {path}")
    tables: dict[Path, pd.DataFrame] = {}
    rows: list[tuple] = []
    d = f"{{{DYN}}}"
    member = q("core:cityObjectMember")
    for _, el in etree.iterparse(str(path), events=("end",), tag=(f"{d}Dynamizer", member), huge_tree=True):
        if el.tag == member:          # a city object read: drop it and what came before
            el.clear()
            parent = el.getparent()
            if parent is not None:
                while el.getprevious() is not None:
                    del parent[0]
            continue
        ref = el.findtext(f"{d}attributeRef") or ""
        m = _REF.search(ref)
        if not m:
            raise InputError(f"{path}:{el.sourceline}: Dynamizer {el.get(GML_ID)}: attributeRef not "
                             f"understood: {ref!r}")
        oid, attr = m["id"], m["attr"]
        ts = el.find(f"{d}dynamicData/*")
        if ts is None:
            raise InputError(f"{path}:{el.sourceline}: Dynamizer {el.get(GML_ID)} has no dynamicData")
        uom = ts.findtext(f"{d}uom")
        if ts.tag == f"{d}GenericTimeseries":
            for pair in ts.iterfind(f"{d}timeValuePair/{d}TimeValuePair"):
                rows.append((oid, attr, pair.findtext(f"{d}timestamp"),
                             float(pair.findtext(f"{d}doubleValue")), uom))
        elif ts.tag == f"{d}TabulatedFileTimeseries":
            loc = path.parent / ts.findtext(f"{d}fileLocation")
            if loc not in tables:
                if not loc.exists():
                    raise InputError(f"{path}: tabulated time series file not found: {loc}")
                sep = ts.findtext(f"{d}fieldSeparator") or ","
                skip = int(ts.findtext(f"{d}numberOfHeaderLines") or 0)
                tab = pd.read_csv(loc, sep=sep, skiprows=max(skip - 1, 0), header=0 if skip else None,
                                  dtype=str, keep_default_na=False)
                idc = ts.findtext(f"{d}idColumnName")
                tables[loc] = (tab, {k: g for k, g in tab.groupby(idc, sort=False)} if idc else None)
            tab, by_id = tables[loc]
            idv = ts.findtext(f"{d}idValue")
            sel = by_id.get(idv, tab.iloc[:0]) if by_id is not None else tab
            tcol, vcol = ts.findtext(f"{d}timeColumnName"), ts.findtext(f"{d}valueColumnName")
            rows.extend((oid, attr, t, float(v), uom) for t, v in zip(sel[tcol], sel[vcol]))
        else:
            raise InputError(f"{path}:{el.sourceline}: Dynamizer {el.get(GML_ID)}: unsupported time "
                             f"series {ts.tag}")
        el.clear()
    df = pd.DataFrame(rows, columns=["object_id", "attribute", "timestamp", "value", "uom"])
    df["timestamp"] = pd.to_datetime(df["timestamp"], utc=True)
    df["value"] = df["value"].astype(np.float64)
    return df
