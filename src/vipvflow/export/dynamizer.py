"""Simulation results as CityGML 3.0 Dynamizers (a "digital twin" file) and their reader.

Modelling (see ``docs/dynamizer.md`` for the content model of every element):

- one ``tran:Road`` per route shape (route and direction), holding one ``tran:TrafficSpace``
  per 10 m segment with its ``lod0MultiCurve`` (a 3D ``gml:LineString`` at roof height in
  the city CRS); each TrafficSpace carries ``gen:DoubleAttribute`` values for the run's
  total (``h_direct``, ``h_diffuse``, ``h_reflected``, ``h_total`` in Wh/m2 and ``pv_kwh``
  in kWh) and one ``dyn:Dynamizer`` per attribute driving it with the monthly series;
- one ``gen:GenericLogicalSpace`` for the whole network with the mean roof irradiance by
  hour of the day of each month (W/m2, ``g_*``): the run stores the hourly pattern for the
  network only, not per segment;
- one ``gen:GenericThematicSurface`` per building surface that reflects light onto a
  route, ``core:relatedTo`` its building, with the reflected PV energy attributed to it
  per month (kWh, ``pv_kwh_reflected``; an approximation, see :func:`reflector_contributions`).

Values are written with ``repr`` precision so that reading them back gives the exact
float64 of the run's GeoParquet.
"""
from __future__ import annotations

import csv
import json
import logging
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Iterator

import numpy as np
import pandas as pd
from lxml import etree

from ..errors import InputError

log = logging.getLogger(__name__)

CORE = "http://www.opengis.net/citygml/3.0"
DYN = "http://www.opengis.net/citygml/dynamizer/3.0"
GEN = "http://www.opengis.net/citygml/generics/3.0"
TRAN = "http://www.opengis.net/citygml/transportation/3.0"
GML = "http://www.opengis.net/gml/3.2"
XLINK = "http://www.w3.org/1999/xlink"
NSMAP = {"core": CORE, "dyn": DYN, "gen": GEN, "tran": TRAN, "gml": GML, "xlink": XLINK}
GML_ID = f"{{{GML}}}id"

#: per-segment monthly series: attribute -> (observed property, unit)
SEGMENT_SERIES = {
    "h_direct": ("direct irradiation on the bus roof per month", "Wh/m2"),
    "h_diffuse": ("diffuse irradiation on the bus roof per month", "Wh/m2"),
    "h_reflected": ("irradiation reflected by the city onto the bus roof per month", "Wh/m2"),
    "h_total": ("total irradiation on the bus roof per month", "Wh/m2"),
    "pv_kwh": ("PV energy harvested on the segment per month (all passes)", "kWh"),
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
CITY_OBJECT = {"segment": "tran:TrafficSpace", "network": "gen:GenericLogicalSpace",
               "surface": "gen:GenericThematicSurface"}
ENCODINGS = ("inline", "tabulated")
_REF = re.compile(r"\[@gml:id='(?P<id>[^']+)'\].*\[gen:name='(?P<attr>[^']+)'\]")


def _q(prefix_name: str) -> str:
    prefix, name = prefix_name.split(":")
    return f"{{{NSMAP[prefix]}}}{name}"


def _sub(parent, tag: str, text=None, **attrib):
    el = etree.SubElement(parent, _q(tag), {(_q(k) if ":" in k else k): v for k, v in attrib.items()})
    if text is not None:
        el.text = text
    return el


def _num(v: float) -> str:
    """Shortest text that parses back to the same float64 (``repr``)."""
    return repr(float(v))


def _srs_name(crs) -> str:
    epsg = crs.to_epsg() if crs is not None else None
    return f"http://www.opengis.net/def/crs/EPSG/0/{epsg}" if epsg else (crs.to_string() if crs else "")


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


def _iso(ts: pd.Timestamp) -> str:
    return ts.isoformat()


def _month_bounds(months: Iterable[str], tz: str) -> tuple[list[str], str]:
    starts = [pd.Timestamp(f"{m}-01", tz=tz) for m in months]
    end = (pd.Timestamp(f"{max(months)}-01") + pd.offsets.MonthBegin(1)).tz_localize(tz)
    return [_iso(s) for s in starts], _iso(end)


# ----------------------------------------------------------------------------- run inputs
@dataclass
class RunData:
    run_dir: Path
    segments: "pd.DataFrame"          # GeoDataFrame: segment_id, shape_id, geometry, ...
    segment_month: pd.DataFrame
    hourly: pd.DataFrame
    manifest: dict
    timezone: str
    crs: object


def load_run(run_dir: str | Path) -> RunData:
    """The outputs of a finished run that the export needs (InputError names what is missing)."""
    import geopandas as gpd

    run_dir = Path(run_dir)
    if not run_dir.is_dir():
        raise InputError(f"run directory not found: {run_dir}")
    need = ["segments.parquet", "segment_month.parquet", "hourly_pattern.parquet", "manifest.json"]
    missing = [n for n in need if not (run_dir / n).exists()]
    if missing:
        raise InputError(f"{run_dir}: not a finished run (missing {', '.join(missing)})")
    from ..simulation.rundir import open_run

    manifest = open_run(run_dir).manifest       # with its data dir found from anywhere
    segments = gpd.read_parquet(run_dir / "segments.parquet")
    sm = pd.read_parquet(run_dir / "segment_month.parquet",
                         columns=["segment_id", "month", *SEGMENT_SERIES, "pv_kwh_reflected"])
    hourly = pd.read_parquet(run_dir / "hourly_pattern.parquet")
    tz = "UTC"
    feed = Path(manifest.get("config", {}).get("data_dir", "")) / "gtfs" / "feed.json"
    if feed.exists():
        tz = json.loads(feed.read_text()).get("timezone", "UTC")
    return RunData(run_dir, segments, sm, hourly, manifest, tz, segments.crs)


# ----------------------------------------------------------------------------- reflectors
def reflector_contributions(run: RunData, segment_ids=None) -> pd.DataFrame:
    """Reflected PV energy attributed to the building surfaces that reflect onto the routes.

    Each segment's reflector groups (``parts/geometry``: weight ``r{g}_w`` = albedo x view
    factor, representative hit point ``r{g}_x, r{g}_y, r{g}_z``) are attributed to the
    surface hit by a ray from the segment's roof point to the group's representative point
    (the tile mesh of the ingested city, ``data_dir/city/meshes``).  A segment's monthly
    ``pv_kwh_reflected`` is shared among its groups in proportion to their weights; a group
    merges every surface of one orientation class seen from the segment, so the whole group
    is credited to the surface of its representative point.  Groups on terrain, or whose
    ray does not come back to the representative point, stay unattributed.

    Returns
    -------
    DataFrame ``surface_id, building_id, surface_type, month, pv_kwh_reflected`` (kWh),
    ``segments`` (number of segments the surface reflects onto; only *segment_ids* when
    given); empty when the run's
    geometry parts or the city meshes are absent.
    """
    from ..mesh import SURFACE_TYPES, TileMesh
    from ..shading import Scene

    cols = ["surface_id", "building_id", "surface_type", "month", "pv_kwh_reflected", "segments"]
    data_dir = Path(run.manifest.get("config", {}).get("data_dir", ""))
    files = sorted((run.run_dir / "parts" / "geometry").glob("tile=*.parquet"))
    seg_tile = run.segments.set_index("segment_id")["tile"]
    if segment_ids is not None:
        seg_tile = seg_tile[seg_tile.index.isin(np.asarray(segment_ids))]
    pieces = []
    for f in files:
        tile = f.stem.split("=", 1)[1]
        mesh_path = data_dir / "city" / "meshes" / f"{tile}.npz"
        if not mesh_path.exists():
            log.warning("no city mesh for tile %s (%s): its reflectors are not attributed", tile, mesh_path)
            continue
        geo = pd.read_parquet(f)
        geo = geo[geo["segment_id"].isin(seg_tile.index)]
        groups = sorted(int(c[1:-2]) for c in geo.columns if re.fullmatch(r"r\d+_w", c))
        if geo.empty or not groups:
            continue
        w = np.stack([geo[f"r{g}_w"].to_numpy(np.float64) for g in groups], 1)          # (n, G)
        rep = np.stack([geo[[f"r{g}_x", f"r{g}_y", f"r{g}_z"]].to_numpy(np.float64) for g in groups], 1)
        origin = geo[["px", "py", "pz"]].to_numpy(np.float64)
        share = w / np.where(w.sum(1, keepdims=True) > 0, w.sum(1, keepdims=True), 1.0)
        seg_idx, g_idx = np.nonzero(w > 0)
        if not len(seg_idx):
            continue
        o = origin[seg_idx]
        vec = rep[seg_idx, g_idx] - o
        dist = np.linalg.norm(vec, axis=1)
        ok = dist > 1e-6
        mesh = TileMesh.load(mesh_path)
        tri, t = Scene(mesh).first_hit(o[ok], vec[ok] / dist[ok, None], dist[ok] + 0.5)
        tri_all = np.full(len(seg_idx), -1)
        tri_all[np.flatnonzero(ok)] = np.where(np.abs(t - dist[ok]) < 0.25, tri, -1)
        hit = tri_all >= 0
        sid = mesh.surface_ids[mesh.surface_index[tri_all[hit]]]
        stype = np.asarray(SURFACE_TYPES)[mesh.surface_type[tri_all[hit]]]
        pieces.append(pd.DataFrame({"segment_id": geo["segment_id"].to_numpy()[seg_idx[hit]],
                                    "surface_id": sid, "surface_type": stype,
                                    "share": share[seg_idx[hit], g_idx[hit]]}))
    if not pieces:
        return pd.DataFrame(columns=cols)
    att = pd.concat(pieces, ignore_index=True)
    att = att[~att["surface_type"].isin(["terrain", "ground", "vegetation"])]
    if att.empty:
        return pd.DataFrame(columns=cols)
    att = att.groupby(["segment_id", "surface_id", "surface_type"], as_index=False)["share"].sum()
    bid = _building_ids(data_dir, set(att["surface_id"]))
    att["building_id"] = att["surface_id"].map(bid)
    sm = run.segment_month[["segment_id", "month", "pv_kwh_reflected"]]
    per = att.merge(sm, on="segment_id")
    per["pv_kwh_reflected"] = per["pv_kwh_reflected"] * per["share"]
    out = (per.groupby(["surface_id", "building_id", "surface_type", "month"], as_index=False, dropna=False)
           .agg(pv_kwh_reflected=("pv_kwh_reflected", "sum"), segments=("segment_id", "nunique")))
    return out[cols]


def _building_ids(data_dir: Path, wanted: set) -> dict:
    out = {}
    for f in sorted((data_dir / "city" / "surfaces").glob("tile=*/*.parquet")):
        s = pd.read_parquet(f, columns=["surface_id", "building_id"])
        s = s[s["surface_id"].isin(wanted)]
        out.update(zip(s["surface_id"], s["building_id"]))
    return out


# ----------------------------------------------------------------------------- XML building
def _generic(parent, kind: str, name: str, value: str) -> None:
    prop = _sub(parent, "core:genericAttribute")
    attr = _sub(prop, f"gen:{kind}")
    _sub(attr, "gen:name", name)
    _sub(attr, "gen:value", value)


class _Tabulated:
    """The CSV beside the GML holding every tabulated series (one row per value)."""

    HEADER = ["series", "timestamp", "value"]

    def __init__(self, path: Path):
        self.path = path
        self._fh = path.open("w", newline="", encoding="utf-8")
        self._w = csv.writer(self._fh, lineterminator="\n")
        self._w.writerow(self.HEADER)

    def add(self, s: Series) -> str:
        key = f"{s.object_id}/{s.attribute}"
        for t, v in zip(s.timestamps, s.values):
            self._w.writerow([key, t, _num(v)])
        return key

    def close(self) -> None:
        self._fh.close()


def _dynamizer(parent, s: Series, encoding: str, table: _Tabulated | None) -> None:
    prop = _sub(parent, "core:dynamizer")
    dyn = _sub(prop, "dyn:Dynamizer", **{"gml:id": s.dynamizer_id})
    _sub(dyn, "gml:name", f"{s.attribute} of {s.object_id}")
    _sub(dyn, "dyn:attributeRef", attribute_ref(s.object_tag, s.object_id, s.attribute))
    _sub(dyn, "dyn:startTime", s.start)
    _sub(dyn, "dyn:endTime", s.end)
    data = _sub(dyn, "dyn:dynamicData")
    if encoding == "inline":
        ts = _sub(data, "dyn:GenericTimeseries", **{"gml:id": s.dynamizer_id + "_ts"})
    else:
        ts = _sub(data, "dyn:TabulatedFileTimeseries", **{"gml:id": s.dynamizer_id + "_ts"})
    _sub(ts, "dyn:firstTimestamp", s.timestamps[0])
    _sub(ts, "dyn:lastTimestamp", s.timestamps[-1])
    _sub(ts, "dyn:observationProperty", s.observation)
    _sub(ts, "dyn:uom", s.uom)
    _sub(ts, "dyn:valueType", "double")
    if encoding == "inline":
        for t, v in zip(s.timestamps, s.values):
            tvp = _sub(_sub(ts, "dyn:contents"), "dyn:TimeValuePair")
            _sub(tvp, "dyn:timestamp", t)
            _sub(tvp, "dyn:doubleValue", _num(v))
        return
    key = table.add(s)
    _sub(ts, "dyn:fileLocation", table.path.name)
    _sub(ts, "dyn:fileType", "csv")
    _sub(ts, "dyn:mimeType", "text/csv")
    _sub(ts, "dyn:numberOfHeaderLines", "1")
    _sub(ts, "dyn:fieldSeparator", ",")
    _sub(ts, "dyn:decimalSymbol", ".")
    _sub(ts, "dyn:idColumnName", "series")
    _sub(ts, "dyn:idValue", key)
    _sub(ts, "dyn:timeColumnName", "timestamp")
    _sub(ts, "dyn:valueColumnName", "value")


def _line_string(parent, geom, srs: str, gid: str) -> None:
    mc = _sub(_sub(parent, "core:lod0MultiCurve"), "gml:MultiCurve", **{"gml:id": gid + "_mc"})
    ls = _sub(_sub(mc, "gml:curveMember"), "gml:LineString", **{"gml:id": gid + "_ls"})
    ls.set("srsName", srs)
    ls.set("srsDimension", "3")
    coords = np.asarray(geom.coords, dtype=np.float64)
    if coords.shape[1] == 2:
        coords = np.column_stack([coords, np.zeros(len(coords))])
    _sub(ls, "gml:posList", " ".join(_num(v) for v in coords.ravel()))


def _segment_series(run: RunData, seg_ids: np.ndarray, prefix: str) -> dict[int, list[Series]]:
    sm = run.segment_month[run.segment_month["segment_id"].isin(seg_ids)].sort_values(["segment_id", "month"])
    out: dict[int, list[Series]] = {}
    for sid, g in sm.groupby("segment_id", sort=True):
        stamps, end = _month_bounds(g["month"], run.timezone)
        oid = f"{prefix}seg_{sid}"
        out[int(sid)] = [Series(oid, CITY_OBJECT["segment"], a, obs, uom, stamps,
                                g[a].to_numpy(np.float64), stamps[0], end)
                         for a, (obs, uom) in SEGMENT_SERIES.items()]
    return out


def _members(run: RunData, encoding: str, table: _Tabulated | None, prefix: str,
             max_segments: int | None, counts: dict) -> Iterator[etree._Element]:
    """``core:cityObjectMember`` elements, one shape (Road) at a time."""
    srs = _srs_name(run.crs)
    segs = run.segments.sort_values(["shape_id", "segment_id"])
    if max_segments is not None:
        segs = segs.iloc[:max_segments]
    for shape_id, block in segs.groupby("shape_id", sort=True):
        series = _segment_series(run, block["segment_id"].to_numpy(), prefix)
        member = etree.Element(_q("core:cityObjectMember"), nsmap=NSMAP)
        road = _sub(member, "tran:Road", **{"gml:id": f"{prefix}road_{shape_id}"})
        _sub(road, "gml:name", f"bus roof path of shape {shape_id}")
        _generic(road, "StringAttribute", "shape_id", str(shape_id))
        for _, row in block.iterrows():
            sid = int(row["segment_id"])
            if sid not in series:          # segment without passes in the run's months
                continue
            ts = _sub(_sub(road, "tran:trafficSpace"), "tran:TrafficSpace",
                      **{"gml:id": f"{prefix}seg_{sid}"})
            _generic(ts, "IntAttribute", "segment_id", str(sid))
            for s in series[sid]:
                _generic(ts, "DoubleAttribute", s.attribute, _num(s.values.sum()))
            for s in series[sid]:
                _dynamizer(ts, s, encoding, table)
                counts["dynamizers"] += 1
            _line_string(ts, row.geometry, srs, f"{prefix}seg_{sid}")
            _sub(ts, "tran:granularity", "lane")
            counts["segments"] += 1
        yield member
    # network-level hourly pattern
    hp = run.hourly.sort_values(["month", "hour"])
    if len(hp):
        member = etree.Element(_q("core:cityObjectMember"), nsmap=NSMAP)
        oid = f"{prefix}network"
        net = _sub(member, "gen:GenericLogicalSpace", **{"gml:id": oid})
        _sub(net, "gml:name", "bus network of the run (hourly pattern, all segments)")
        stamps = [_iso(pd.Timestamp(f"{m}-01", tz=run.timezone) + pd.Timedelta(hours=int(h)))
                  for m, h in zip(hp["month"], hp["hour"])]
        _, end = _month_bounds(hp["month"], run.timezone)
        net_series = [Series(oid, CITY_OBJECT["network"], a, obs, uom, stamps,
                             hp[a].to_numpy(np.float64), _month_bounds(hp["month"], run.timezone)[0][0], end)
                      for a, (obs, uom) in NETWORK_SERIES.items() if a in hp]
        for s in net_series:
            _generic(net, "DoubleAttribute", s.attribute, _num(np.nanmean(s.values)))
        for s in net_series:
            _dynamizer(net, s, encoding, table)
            counts["dynamizers"] += 1
        counts["network"] += 1
        yield member
    # reflecting building surfaces
    refl = reflector_contributions(run, segs["segment_id"].to_numpy())
    for (surface_id, building_id, stype), g in refl.groupby(["surface_id", "building_id", "surface_type"],
                                                            sort=True, dropna=False):
        g = g.sort_values("month")
        oid = f"{prefix}refl_{surface_id}"
        member = etree.Element(_q("core:cityObjectMember"), nsmap=NSMAP)
        surf = _sub(member, "gen:GenericThematicSurface", **{"gml:id": oid})
        _sub(surf, "gml:name", f"reflection onto the routes by {stype} surface {surface_id}")
        if isinstance(building_id, str):
            _sub(surf, "core:relatedTo", **{"xlink:href": f"#{building_id}"})
        stamps, end = _month_bounds(g["month"], run.timezone)
        obs, uom = SURFACE_SERIES["pv_kwh_reflected"]
        s = Series(oid, CITY_OBJECT["surface"], "pv_kwh_reflected", obs, uom, stamps,
                   g["pv_kwh_reflected"].to_numpy(np.float64), stamps[0], end)
        _generic(surf, "StringAttribute", "surface_id", str(surface_id))
        if isinstance(building_id, str):
            _generic(surf, "StringAttribute", "building_id", building_id)
        _generic(surf, "StringAttribute", "surface_type", str(stype))
        _generic(surf, "IntAttribute", "segments", str(int(g["segments"].max())))
        _generic(surf, "DoubleAttribute", s.attribute, _num(s.values.sum()))
        _dynamizer(surf, s, encoding, table)
        counts["dynamizers"] += 1
        counts["surfaces"] += 1
        yield member


# ----------------------------------------------------------------------------- writer
def write_dynamizers(run_dir: str | Path, out: str | Path, encoding: str = "inline",
                     embed: str | Path | None = None, max_segments: int | None = None) -> dict:
    """Write the run's results as a CityGML 3.0 file with Dynamizers.

    Parameters
    ----------
    run_dir : a finished run directory (``out/<scenario>/<year>``)
    out : the ``.gml`` to write
    encoding : ``"inline"`` (``dyn:GenericTimeseries``) or ``"tabulated"``
        (``dyn:TabulatedFileTimeseries`` pointing at ``<out stem>.csv`` beside *out*)
    embed : a CityGML 3.0 file: *out* is then a streamed copy of it with the results added
        as further ``cityObjectMember`` elements
    max_segments : export only the first N segments (ordered by shape, segment id)

    Returns
    -------
    dict: ``files`` (paths written), ``segments``, ``surfaces``, ``network``, ``dynamizers``
    """
    if encoding not in ENCODINGS:
        raise InputError(f"unknown encoding {encoding!r} (choose {' or '.join(ENCODINGS)})")
    run = load_run(run_dir)
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    counts = {"segments": 0, "surfaces": 0, "network": 0, "dynamizers": 0}
    table = _Tabulated(out.with_suffix(".csv")) if encoding == "tabulated" else None
    prefix = "vipv_"
    tmp = out.with_name(out.name + ".tmp")
    try:
        members = _members(run, encoding, table, prefix, max_segments, counts)
        if embed is None:
            _write_standalone(tmp, run, members)
        else:
            _write_embedded(tmp, Path(embed), members)
    finally:
        if table is not None:
            table.close()
    tmp.replace(out)
    files = [out] + ([table.path] if table is not None else [])
    return {"files": files, **counts}


def _write_standalone(path: Path, run: RunData, members: Iterator[etree._Element]) -> None:
    with etree.xmlfile(str(path), encoding="utf-8") as xf:
        xf.write_declaration()
        with xf.element(_q("core:CityModel"), {GML_ID: "vipv_results"}, nsmap=NSMAP):
            xf.write(etree.fromstring(
                f'<gml:name xmlns:gml="{GML}">vipvflow results of '
                f'{run.manifest.get("scenario", "?")} {run.manifest.get("year", "?")}</gml:name>'))
            for m in members:
                xf.write("\n")
                xf.write(m)
            xf.write("\n")


#: CityModel children that must follow every cityObjectMember (CityGML 3.0 core.xsd order)
_AFTER_MEMBERS = {"appearanceMember", "featureMember", "versionMember", "versionTransitionMember"}


def _insertion_point(src: Path) -> tuple[str, int | None]:
    """Stream *src*: check it is CityGML 3.0; return the root's qualified tag name and the
    line of the first CityModel child that must come after the city objects (None: insert
    before the closing root tag)."""
    depth, root_qname, line = 0, None, None
    try:
        ctx = etree.iterparse(str(src), events=("start", "end"), huge_tree=True)
        for event, el in ctx:
            if event == "start":
                depth += 1
                if depth == 1:
                    q = etree.QName(el)
                    if q.namespace != CORE or q.localname != "CityModel":
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


def _write_embedded(path: Path, src: Path, members: Iterator[etree._Element]) -> None:
    """Copy *src* line by line, inserting the members where CityGML 3.0 allows them."""
    if not src.exists():
        raise InputError(f"--embed: file not found: {src}")
    root_qname, line = _insertion_point(src)
    close = f"</{root_qname}".encode()

    def emit(fh):
        for m in members:
            fh.write(etree.tostring(m, encoding="utf-8"))
            fh.write(b"\n")

    with src.open("rb") as fin, path.open("wb") as fout:
        if line is not None:
            for no, raw in enumerate(fin, start=1):
                if no == line:
                    head = raw[:len(raw) - len(raw.lstrip())]
                    if raw[len(head):len(head) + 1] != b"<":
                        raise InputError(f"{src}:{line}: cannot insert before a member sharing its line")
                    emit(fout)
                fout.write(raw)
            return
        # insert before the closing root tag: copy everything up to it, in chunks
        size = src.stat().st_size
        tail_len = min(size, 1 << 16)
        fin.seek(size - tail_len)
        tail = fin.read()
        pos = tail.rfind(close)
        if pos < 0:
            raise InputError(f"{src}: closing {root_qname} tag not found")
        cut = size - tail_len + pos
        fin.seek(0)
        left = cut
        while left:
            chunk = fin.read(min(left, 1 << 20))
            fout.write(chunk)
            left -= len(chunk)
        fout.write(b"\n")
        emit(fout)
        fout.write(fin.read())


# ----------------------------------------------------------------------------- reader
def read_dynamizers(path: str | Path) -> pd.DataFrame:
    """Every Dynamizer's values in a CityGML 3.0 file, inline or tabulated.

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
    for _, el in etree.iterparse(str(path), events=("end",), tag=f"{{{DYN}}}Dynamizer", huge_tree=True):
        ref = el.findtext(f"{{{DYN}}}attributeRef") or ""
        m = _REF.search(ref)
        if not m:
            raise InputError(f"{path}: Dynamizer {el.get(GML_ID)}: attributeRef not understood: {ref!r}")
        oid, attr = m["id"], m["attr"]
        ts = el.find(f"{{{DYN}}}dynamicData/*")
        uom = ts.findtext(f"{{{DYN}}}uom")
        if ts.tag == f"{{{DYN}}}GenericTimeseries":
            for tvp in ts.iterfind(f"{{{DYN}}}contents/{{{DYN}}}TimeValuePair"):
                rows.append((oid, attr, tvp.findtext(f"{{{DYN}}}timestamp"),
                             float(tvp.findtext(f"{{{DYN}}}doubleValue")), uom))
        elif ts.tag == f"{{{DYN}}}TabulatedFileTimeseries":
            loc = path.parent / ts.findtext(f"{{{DYN}}}fileLocation")
            if loc not in tables:
                if not loc.exists():
                    raise InputError(f"{path}: tabulated time series file not found: {loc}")
                sep = ts.findtext(f"{{{DYN}}}fieldSeparator") or ","
                skip = int(ts.findtext(f"{{{DYN}}}numberOfHeaderLines") or 0)
                tables[loc] = pd.read_csv(loc, sep=sep, skiprows=max(skip - 1, 0), header=0 if skip else None,
                                          dtype=str, keep_default_na=False)
            tab = tables[loc]
            idc, idv = ts.findtext(f"{{{DYN}}}idColumnName"), ts.findtext(f"{{{DYN}}}idValue")
            sel = tab[tab[idc] == idv] if idc else tab
            tcol, vcol = ts.findtext(f"{{{DYN}}}timeColumnName"), ts.findtext(f"{{{DYN}}}valueColumnName")
            rows.extend((oid, attr, t, float(v), uom) for t, v in zip(sel[tcol], sel[vcol]))
        else:
            raise InputError(f"{path}: Dynamizer {el.get(GML_ID)}: unsupported time series {ts.tag}")
        el.clear()
    df = pd.DataFrame(rows, columns=["object_id", "attribute", "timestamp", "value", "uom"])
    df["timestamp"] = pd.to_datetime(df["timestamp"], utc=True)
    df["value"] = df["value"].astype(np.float64)
    return df
