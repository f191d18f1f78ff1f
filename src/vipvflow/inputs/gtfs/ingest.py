"""``ingest_gtfs``: a GTFS feed to the trajectory stage files under ``<data_dir>/gtfs/``.

Files written (see docs/contracts.md, "Trajectories"):

- ``segments.parquet``  GeoParquet LineString Z, one row per hyper-segment.
- ``trips.parquet``     one row per trip (frequencies expanded), with its pattern and start.
- ``patterns.parquet``  per pattern and segment: ``t_offset_s``, ``dt_s``, ``speed_mps``.
- ``pattern_stops.parquet``  per pattern and stop: ``stop_index, stop_id, dist_m, arr_s,
  dep_s`` (s after the first departure): the input of the driving-cycle generator.
- ``calendar.parquet``, ``calendar_dates.parquet``  the feed's service calendars.
- ``feed.json``         timezone, CRS, tile size, counts and problems.
"""
from __future__ import annotations

import json
import logging
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from ...errors import InputError, accept_hint
from ...store import TILE_SIZE_M, DataDir, GtfsDir, staging_dir, swap_dir, write_parquet, write_text
from .feed import read_feed
from .schedule import pattern_segment_times, project_stops_monotone
from ..city.terrain import GROUND_SOURCES as _GROUND_SOURCES
from .segments import build_segments, cumulative_distance, project_shapes

log = logging.getLogger(__name__)

_UNIT_M = {"m": 1.0, "km": 1000.0, "mi": 1609.344, "ft": 0.3048}


def _city_grid(data_dir: Path):
    """(crs, tile_size_m) from ``city/tiles.json`` or (None, None)."""
    path = DataDir(data_dir).city.tiles_json
    if not path.exists():
        return None, None
    try:
        meta = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise InputError(f"{path}: not valid JSON: {exc}") from None
    return meta.get("crs"), meta.get("tile_size_m")


def _terrain(data_dir: Path):
    """The city's terrain model (relief and building ground surfaces), or None without a
    city model."""
    path = DataDir(data_dir).city.terrain
    if not path.exists():
        return None
    from ..city import TerrainModel

    try:
        return TerrainModel.load(data_dir)
    except (OSError, ValueError, KeyError) as exc:
        raise InputError(f"{path}: unreadable ({exc}); run `vipvflow ingest city` again") from None


def ground_fallback(data_dir: Path, traj_cfg) -> tuple[float, str] | None:
    """The ground height (m) where the city model knows none, and its source:
    ``trajectory.ground_elevation_m`` when set (``configured``), else the altitude declared
    by the ingested radiation files' headers (``radiation_header``, their mean), else None."""
    height = getattr(traj_cfg, "ground_elevation_m", None)
    if height is not None:
        return float(height), "configured"
    path = DataDir(data_dir).radiation.report
    try:
        locations = json.loads(path.read_text()).get("locations", [])
    except (OSError, ValueError):
        return None
    alts = [float(loc["altitude"]) for loc in locations
            if loc.get("altitude_declared", True) and loc.get("altitude") is not None]
    return (float(np.mean(alts)), "radiation_header") if alts else None


def _ground_findings(segs: pd.DataFrame, fallback, feed_path, data_dir: Path,
                     problems: list[str]) -> dict:
    """Segments by the source of their ground height (counted, the fallback said in a
    problem line); segments with none are an :class:`InputError`."""
    from ..city.terrain import GROUND_SOURCES

    src = segs["ground_source"].to_numpy()
    unknown = int((src < 0).sum())
    if unknown:
        city = DataDir(data_dir).city
        where = ("no city model is ingested" if not city.terrain.exists() else
                 "they lie outside the city model's relief and more than 100 m from its buildings")
        raise InputError(f"{feed_path}: no ground height for {unknown} of {len(segs)} road "
                         f"segments ({where}): ingest the CAMS radiation first (its header's "
                         "altitude is used) or set trajectory.ground_elevation_m (m above sea level)")
    counts = {name: int((src == i).sum()) for i, name in enumerate(GROUND_SOURCES)}
    far = counts["radiation_header"] + counts["configured"]
    if far and fallback is not None:
        what = ("the radiation file's altitude" if fallback[1] == "radiation_header"
                else "trajectory.ground_elevation_m")
        if not DataDir(data_dir).city.terrain.exists():
            problems.append(f"no city model: the ground of all {len(segs)} segments is {what} "
                            f"({fallback[0]:.1f} m)")
        else:
            problems.append(f"{far} of {len(segs)} segments ({100 * far / len(segs):.0f} %) are "
                            f"beyond the city model's relief and more than 100 m from its "
                            f"buildings: their ground is {what} ({fallback[0]:.1f} m), blended into "
                            "the buildings' ground where it meets them")
    return counts


def _city_fit(segs: pd.DataFrame, data_dir: Path, problems: list[str]) -> dict:
    """``in_city_model`` (the segment's midpoint inside the model's coverage area) and
    ``in_building`` with the offset of the point its light is taken from (the midpoint inside
    a building footprint: a straight line between stops crossing a block), added to *segs*;
    counts for the report."""
    import shapely

    from ..city.coverage import STREET_M, footprint_polygons, inside_footprints, read_coverage

    city = DataDir(data_dir).city
    mx = 0.5 * (segs["x"].to_numpy() + segs["x_end"].to_numpy())
    my = 0.5 * (segs["y"].to_numpy() + segs["y_end"].to_numpy())
    area = read_coverage(city)
    if shapely.is_empty(area):
        segs["in_city_model"] = np.zeros(len(segs), bool)
    else:
        shapely.prepare(area)
        segs["in_city_model"] = shapely.contains_xy(area, mx, my)
    segs["in_building"] = np.zeros(len(segs), bool)
    segs["light_dx_m"] = np.zeros(len(segs))
    segs["light_dy_m"] = np.zeros(len(segs))
    length = segs["length_m"].to_numpy()
    out = {"route_km": round(float(length.sum()) / 1000.0, 3),
           "route_km_in_city_model": round(float(length[segs["in_city_model"].to_numpy()].sum())
                                           / 1000.0, 3),
           "segments_in_buildings": 0}
    if len(segs) and city.tiles_json.exists():
        pad = 100.0
        prints = footprint_polygons(city, bounds=(mx.min() - pad, my.min() - pad,
                                                  mx.max() + pad, my.max() + pad))
        inside, dx, dy = inside_footprints(mx, my, prints)
        segs["in_building"], segs["light_dx_m"], segs["light_dy_m"] = inside, dx, dy
        n = int(inside.sum())
        out["segments_in_buildings"] = n
        if n:
            km = float(length[inside].sum()) / 1000.0
            problems.append(
                f"{n} of {len(segs)} segments ({km:.2f} km, {100 * km / max(out['route_km'], 1e-9):.1f} "
                f"% of the route-km) lie inside building footprints (straight lines between stops "
                f"where the feed has no shapes cross blocks and halls): each takes its light "
                f"{STREET_M:g} m outside the block, at the nearest point of its outline, and "
                "they are left out of the shading statistics (in_building)")
    return out


def _choose_crs(feed, data_dir: Path, crs):
    import geopandas as gpd
    from pyproj import CRS
    from pyproj.exceptions import CRSError

    city_crs, tile_size = _city_grid(data_dir)
    if city_crs:
        return CRS.from_user_input(city_crs), tile_size, "city/tiles.json"
    if crs:
        try:
            return CRS.from_user_input(crs), None, "argument"
        except CRSError:
            raise InputError(f"--crs {crs}: not a CRS PROJ knows (give one such as EPSG:2169 "
                             "or EPSG:25832)") from None
    pts = gpd.GeoSeries(gpd.points_from_xy(feed.stops["stop_lon"], feed.stops["stop_lat"]),
                        crs="EPSG:4326")
    return pts.estimate_utm_crs(), None, "local UTM zone"


def _stops_in_crs_area(feed, crs_obj, crs_source: str, problems: list[str], accept=()) -> None:
    """The stops the trips serve must lie in the area of use of the CRS they are projected
    into (widened by :data:`vipvflow.inputs.city.crs.AREA_MARGIN_DEG`): a feed of another
    place than the city model (Cairns' stops in Hamburg's EPSG:25832) is an
    :class:`InputError` naming both, unless ``crs_area`` is in *accept*; some stops outside
    are counted."""
    from ..city.crs import describe_area, in_area_of_use

    used = feed.stops[feed.stops["stop_id"].isin(set(feed.stop_times["stop_id"]))]
    lon, lat = used["stop_lon"].to_numpy(float), used["stop_lat"].to_numpy(float)
    ok = in_area_of_use(lon, lat, crs_obj)
    if ok.all() or not len(used):
        return
    where = ("the city model's CRS, city/tiles.json" if crs_source == "city/tiles.json"
             else "--crs" if crs_source == "argument" else crs_source)
    what = (f"{int((~ok).sum())} of the {len(used)} stops the trips serve (around "
            f"{np.median(lat[~ok]):.2f}, {np.median(lon[~ok]):.2f}) lie outside the area of use of "
            f"{describe_area(crs_obj)} ({where})")
    if not ok.any() and "crs_area" not in accept:
        raise InputError(f"{feed.path}: {what}: is the city model of the place this feed "
                         f"serves? {accept_hint('crs_area')}")
    problems.append(f"{what}: projected there anyway, with that CRS's distortion")


def _dist_factor(st: pd.DataFrame, shape_len: dict, feed_units: str | None, problems):
    """Metres per unit of the feed's ``shape_dist_traveled``, checked against the geometry.

    gtfs-kit infers units from magnitudes and can be wrong (a 5 km line in metres looks
    like km); the ratio of each shape's projected length to the largest stop distance of
    its trips decides, among m, km, mi and ft. Returns None when no unit fits.
    """
    if "shape_dist_traveled" not in st or st["shape_dist_traveled"].isna().all():
        return None
    last = st.groupby("trip_id", sort=False).agg(shape_id=("shape_id", "first"),
                                                  dmax=("shape_dist_traveled", "max"))
    last = last[last["dmax"] > 0]
    ratio = last["shape_id"].map(shape_len).astype(float) / last["dmax"].astype(float)
    ratio = ratio[np.isfinite(ratio)]
    if ratio.empty:
        return None
    r = float(np.median(ratio))
    name, factor = min(_UNIT_M.items(), key=lambda kv: abs(np.log(r / kv[1])))
    if abs(np.log(r / factor)) > np.log(1.15):
        problems.append(f"shape_dist_traveled fits no unit (shape length / distance = {r:.3g}); "
                        "stops projected onto shapes instead")
        return None
    if feed_units and name != feed_units:
        problems.append(f"shape_dist_traveled is in {name}, not {feed_units} as inferred; "
                        f"read as {name}")
    return factor


def _fill_times(dist, t):
    """Missing stop times interpolated along distance between timepoints (s)."""
    bad = np.isnan(t)
    if bad.any() and (~bad).sum() >= 2:
        t = t.copy()
        t[bad] = np.interp(dist[bad], dist[~bad], t[~bad])
    return t


def spread_repeated_times(d, arr, dep):
    """Stop times truncated to the minute, spread along distance (s).

    Timetables often give several consecutive stops the same time; taken literally the bus
    would cover the distance between them in no time. Stops whose time repeats the previous
    stop's departure are re-timed by linear interpolation along distance between the
    surrounding stops whose times do change (the first departure and last arrival are kept).

    Returns
    -------
    arr, dep : ndarray
        New times (s); dwell kept at the stops still used as time points.
    changed : int
        Number of stops re-timed.
    """
    m = len(d)
    anchors = [0] + [i for i in range(1, m - 1) if arr[i] > dep[i - 1]] + [m - 1]
    changed = True
    while changed and len(anchors) > 2:
        changed = False
        for n in range(len(anchors) - 1):
            i, j = anchors[n], anchors[n + 1]
            if dep[i] >= arr[j] and d[j] > d[i]:
                if i != 0:
                    anchors.pop(n)
                elif j != m - 1:
                    anchors.pop(n + 1)
                else:
                    continue
                changed = True
                break
    a_idx = np.asarray(anchors)
    inner = np.setdiff1d(np.arange(m), a_idx)
    if len(inner) == 0:
        return arr, dep, 0
    prev = np.searchsorted(a_idx, inner) - 1              # anchor before each re-timed stop
    i0, i1 = a_idx[prev], a_idx[prev + 1]
    span = d[i1] - d[i0]
    f = np.where(span > 0, (d[inner] - d[i0]) / np.where(span > 0, span, 1.0), 0.0)
    t = dep[i0] + (arr[i1] - dep[i0]) * f
    arr, dep = arr.copy(), dep.copy()
    arr[inner] = t
    dep[inner] = t
    return arr, dep, len(inner)


def _route_type_counts(routes: pd.DataFrame, trips: pd.DataFrame) -> dict:
    """Trips kept per GTFS route_type (as a string key: JSON)."""
    if "route_type" not in routes:
        return {}
    rt = routes[["route_id", "route_type"]].astype({"route_id": str})
    n = trips[["route_id"]].merge(rt, on="route_id", how="left")["route_type"]
    return {str(k): int(v) for k, v in n.value_counts(dropna=False).sort_index().items()}


def ingest_gtfs(feed_path, data_dir, traj_cfg, crs=None, dist_units: str | None = None,
                timezone: str | None = None, route_types="bus", accept=()) -> dict:
    """Read a GTFS feed and write the trajectory stage files under ``data_dir/gtfs/``.

    Parameters
    ----------
    feed_path : str or Path
        GTFS zip or folder.
    data_dir : str or Path
        Scenario data directory; ``city/tiles.json`` there, when present, fixes the CRS and
        tile size, and ``city/terrain.npz`` the ground height.
    traj_cfg : vipvflow.config.TrajectoryCfg
        Segment length (m), roof height (m), default elevation (m), timing mode, cycle.
    crs : str, optional
        Projected CRS when the city has not been ingested (e.g. ``EPSG:2169``); else the
        local UTM zone.
    dist_units : str, optional
        Units of ``shape_dist_traveled`` when known (checked against the geometry anyway).
    timezone : str, optional
        IANA zone of the timetable for a feed without agency.txt (see :func:`read_feed`).
    route_types : "bus", "all" or list of int
        GTFS route types to keep (``run.route_types``): buses by default
        (:data:`vipvflow.inputs.gtfs.feed.BUS_ROUTE_TYPES`).
    accept : iterable of str
        Plausibility findings accepted (``checks.accept``): with ``crs_area``, stops that all
        lie outside the CRS's area of use are a problem line instead of an error.

    Returns
    -------
    dict
        The content of ``feed.json``: timezone, crs, tile_size_m, counts, problems, seconds.
    """
    from pyproj import Transformer

    t_start = time.perf_counter()
    data_dir = Path(data_dir)
    out = DataDir(data_dir).gtfs.root
    feed = read_feed(feed_path, dist_units=dist_units, timezone=timezone, route_types=route_types)
    problems = list(feed.problems)
    crs_obj, tile_size, crs_source = _choose_crs(feed, data_dir, crs)
    if not crs_obj.is_projected:
        raise InputError(f"{crs_obj.to_string()}: the trajectory CRS must be projected (metres)")
    _stops_in_crs_area(feed, crs_obj, crs_source, problems, accept)
    tile_size = float(tile_size or TILE_SIZE_M)
    to_xy = Transformer.from_crs("EPSG:4326", crs_obj, always_xy=True)

    shape_xy = _used_shapes(feed, to_xy, problems)
    shape_len = {s: float(cumulative_distance(p)[-1]) for s, p in shape_xy.items()}
    terrain = _terrain(data_dir)
    fallback = ground_fallback(data_dir, traj_cfg)
    segs, geom = build_segments(shape_xy, traj_cfg.segment_length_m, traj_cfg.roof_height_m,
                                tile_size, terrain, fallback)
    ground_sources = _ground_findings(segs, fallback, feed.path, data_dir, problems)
    fit = _city_fit(segs, data_dir, problems)
    segs["ground_source"] = pd.Categorical.from_codes(
        segs["ground_source"].to_numpy(), categories=list(_GROUND_SOURCES))
    trips, st, st_xy = _stops_along_shapes(feed, shape_xy, to_xy)
    feed_d = _feed_distances(st, shape_len, feed.dist_units, problems)
    pats = _group_trips(st, st_xy, feed_d, shape_xy, shape_len)
    _trip_findings(pats.found, len(pats), feed.path, problems)
    pstops = pats.stops_frame()
    timing = getattr(traj_cfg, "timing", "stop_times")
    patterns = _segment_timing(pstops, pats.shape, segs, timing, traj_cfg, problems)
    trips_out = _trips_table(trips, feed.routes, pats)

    report = {
        "feed": str(Path(feed_path)),
        "timezone": feed.timezone,
        "crs": crs_obj.to_string(),
        "crs_source": crs_source,
        "tile_size_m": tile_size,
        "segment_length_m": float(traj_cfg.segment_length_m),
        "timing": timing,
        "terrain": terrain is not None,
        "ground_sources": ground_sources,
        "ground_fallback_m": None if fallback is None else round(fallback[0], 2),
        "ground_fallback_source": None if fallback is None else fallback[1],
        **fit,
        "counts": {
            "routes": int(trips_out["route_id"].nunique()),
            "shapes": len(shape_xy),
            "segments": len(segs),
            "tiles": int(segs["tile"].nunique()) if len(segs) else 0,
            "trips": len(trips_out),
            "patterns": len(pats),
            "stops": int(st["stop_id"].nunique()),
            "frequency_trips": int(feed.frequency_trips),
            "shapes_built_from_stops": int(feed.shapes_built_from_stops),
            "route_types": _route_type_counts(feed.routes, trips_out),
            "trips_with_feed_distances": pats.found["feed_distances"],
            "trips_with_projected_stops": pats.found["projected"],
        },
        "total_shape_length_km": round(sum(shape_len.values()) / 1000.0, 3),
        "problems": problems,
    }
    _write_stage(out, feed, segs, geom, crs_obj, trips_out, patterns, pstops, report, t_start)
    return report


def _used_shapes(feed, to_xy, problems: list[str]) -> dict:
    """The feed's shapes that trips use, projected (m); shapes without two distinct points
    are dropped (counted)."""
    used = set(feed.trips["shape_id"].astype(str))
    shape_xy = project_shapes(feed.shapes[feed.shapes["shape_id"].astype(str).isin(used)], to_xy)
    degenerate = [s for s, p in shape_xy.items() if len(p) < 2 or not np.isfinite(p).all()]
    if degenerate:
        problems.append(f"{len(degenerate)} shapes have fewer than two distinct points; their "
                        "trips are dropped")
        for s in degenerate:
            shape_xy.pop(s)
    return shape_xy


def _stops_along_shapes(feed, shape_xy: dict, to_xy):
    """Trips on a usable shape, their stop times in stop order and the stops' points (m)."""
    trips = feed.trips.copy()
    trips["shape_id"] = trips["shape_id"].astype(str)
    trips = trips[trips["shape_id"].isin(shape_xy.keys())]
    st = feed.stop_times.merge(trips[["trip_id", "shape_id"]], on="trip_id")
    st = st.sort_values(["trip_id", "stop_sequence"], kind="stable").reset_index(drop=True)
    sx, sy = to_xy.transform(feed.stops["stop_lon"].to_numpy(float),
                             feed.stops["stop_lat"].to_numpy(float))
    stop_pos = pd.DataFrame({"x": sx, "y": sy}, index=feed.stops["stop_id"].astype(str))
    st_xy = stop_pos.loc[st["stop_id"].astype(str)].to_numpy()
    return trips, st, st_xy


def _feed_distances(st: pd.DataFrame, shape_len: dict, feed_units: str | None,
                    problems: list[str]) -> np.ndarray:
    """The feed's ``shape_dist_traveled`` of each stop time in metres (NaN when unusable)."""
    factor = _dist_factor(st, shape_len, feed_units, problems)
    if factor is None:
        return np.full(len(st), np.nan)
    return st["shape_dist_traveled"].to_numpy(float) * factor


@dataclass
class _Patterns:
    """Trips grouped into patterns: same shape, stops, stop distances and time offsets."""

    shape: list = field(default_factory=list)          # shape id, by pattern id
    stops: list = field(default_factory=list)          # pattern_stops rows, by pattern id
    trip_pattern: dict = field(default_factory=dict)   # trip id -> pattern id
    trip_start: dict = field(default_factory=dict)     # trip id -> first departure (s)
    found: Counter = field(default_factory=Counter)    # trips by finding (dropped, repaired...)
    _ids: dict = field(default_factory=dict)           # pattern key -> pattern id

    def __len__(self) -> int:
        return len(self._ids)

    def add(self, trip, shape, stop_ids, d, arr, dep, start: float) -> None:
        """File *trip* under its pattern (a new one when no trip before had the same)."""
        key = (shape, tuple(stop_ids), tuple(np.round(d, 1)), tuple(arr), tuple(dep))
        pid = self._ids.get(key)
        if pid is None:
            pid = self._ids[key] = len(self._ids)
            self.shape.append(shape)
            self.stops.append(pd.DataFrame({
                "pattern_id": np.int64(pid), "stop_index": np.arange(len(stop_ids), dtype=np.int32),
                "stop_id": stop_ids, "dist_m": d, "arr_s": arr, "dep_s": dep}))
        self.trip_pattern[trip] = pid
        self.trip_start[trip] = start

    def stops_frame(self) -> pd.DataFrame:
        """``pattern_stops.parquet``: per pattern and stop, distance and times."""
        if not self.stops:
            return pd.DataFrame(columns=["pattern_id", "stop_index", "stop_id", "dist_m",
                                         "arr_s", "dep_s"])
        return pd.concat(self.stops, ignore_index=True)


def _group_trips(st: pd.DataFrame, st_xy: np.ndarray, feed_d: np.ndarray, shape_xy: dict,
                 shape_len: dict) -> _Patterns:
    """Each trip's stop distances and times, grouped into patterns (findings counted)."""
    tid = st["trip_id"].astype(str).to_numpy()
    bounds = np.flatnonzero(np.r_[True, tid[1:] != tid[:-1], True])
    shape_of = st["shape_id"].to_numpy()
    stop_ids = st["stop_id"].astype(str).to_numpy()
    arr_all, dep_all = st["arr_s"].to_numpy(float), st["dep_s"].to_numpy(float)
    projected: dict = {}
    pats = _Patterns()
    for a, b in zip(bounds[:-1], bounds[1:]):
        trip, shape = tid[a], shape_of[a]
        if b - a < 2:
            pats.found["short"] += 1
            continue
        d = _stop_distances(feed_d[a:b], shape_len[shape], (shape, tuple(stop_ids[a:b])),
                            shape_xy[shape], st_xy[a:b], projected, pats.found)
        timed = _trip_times(d, arr_all[a:b], dep_all[a:b], pats.found)
        if timed is not None:
            pats.add(trip, shape, stop_ids[a:b], d, *timed)
    return pats


def _stop_distances(d, length: float, key, shape_line, stop_xy, projected: dict,
                    found: Counter) -> np.ndarray:
    """A trip's stop distances along its shape (m): the feed's when usable, else the stops
    projected onto the shape (once per shape and stop sequence, in *projected*)."""
    if np.isnan(d).any() or np.any(np.diff(d) < 0) or d[-1] > 1.05 * length:
        if not np.isnan(d).all():
            found["nonmonotone"] += 1
        if key not in projected:
            projected[key] = project_stops_monotone(shape_line, stop_xy)
        found["projected"] += 1
        return projected[key]
    found["feed_distances"] += 1
    return np.clip(d, 0.0, length)


def _trip_times(d, arr, dep, found: Counter):
    """A trip's stop times repaired: (arr, dep) in s after its first departure and that
    departure (s); None when no timing can be made of it."""
    arr, dep = _fill_times(d, arr), _fill_times(d, dep)
    if np.isnan(arr).any() or np.isnan(dep).any():
        found["untimed"] += 1
        return None
    start = dep[0]
    arr, dep = arr - start, dep - start
    arr[0] = 0.0                      # the trip begins at its first departure
    if d[-1] > d[0] and arr[-1] <= 0:
        # it ends no later than it starts: no timing can be made of it
        found["still"] += 1
        return None
    if np.any(np.diff(np.column_stack([arr, dep]).ravel()) < 0):
        # times going backwards inside the trip: keep it, make times non-decreasing
        seq = np.maximum.accumulate(np.column_stack([arr, dep]).ravel())
        arr, dep = seq[0::2], seq[1::2]
        found["backwards"] += 1
    arr2, dep2, _ = spread_repeated_times(d, arr, dep)
    if not (np.array_equal(arr2, arr) and np.array_equal(dep2, dep)):
        found["spread"] += 1
        arr, dep = arr2, dep2
    return arr, dep, start


#: problem lines of the trips dropped or repaired, by finding: those an unusable feed's
#: error names, then those found in a usable one
_TRIP_FINDINGS = (
    ("short", "{} trips have fewer than two stop times; dropped"),
    ("untimed", "{} trips have too few timed stops; dropped"),
    ("still", "{} trips arrive at their last stop no later than they leave the first (stop "
              "times backwards or all equal); dropped"),
    ("backwards", "{} trips have stop times that decrease along the trip; made non-decreasing"))
_TRIP_REPAIRS = (
    ("spread", "{} trips give consecutive stops the same time; those stops were re-timed "
               "along distance between the stops whose times change"),
    ("nonmonotone", "{} trips have shape_dist_traveled missing, decreasing or beyond the "
                    "shape; their stops were projected onto the shape"))


def _trip_findings(found: Counter, n_patterns: int, feed_path, problems: list[str]) -> None:
    """The trips dropped or repaired, as problem lines; a feed without any usable trip is
    an :class:`InputError`."""
    problems.extend(line.format(found[key]) for key, line in _TRIP_FINDINGS if found[key])
    if not n_patterns:
        raise InputError(f"{feed_path}: no usable trip in the feed ("
                         + "; ".join(problems or ["no trip with two stops on a shape"]) + ")")
    problems.extend(line.format(found[key]) for key, line in _TRIP_REPAIRS if found[key])


def _segment_timing(pstops: pd.DataFrame, pattern_shape: list, segs: pd.DataFrame,
                    timing: str, traj_cfg, problems: list[str]) -> pd.DataFrame:
    """``patterns.parquet``: per pattern and segment, start offset, running time and speed
    (from the stop times, or from a driving cycle through them)."""
    seg_by_shape = {s: g for s, g in segs.groupby("shape_id", sort=False)}
    frames, n_zero, cycle_delays = [], 0, []
    for pid, g in pstops.groupby("pattern_id", sort=True):
        sg = seg_by_shape[pattern_shape[pid]]
        d, arr, dep = g["dist_m"].to_numpy(), g["arr_s"].to_numpy(), g["dep_s"].to_numpy()
        seg_start, seg_len = sg["cum_dist_m"].to_numpy(), sg["length_m"].to_numpy()
        if timing == "driving_cycle":
            from ...models.driving_cycle import cycle_reach_times
            idx, t0, dtt, cov, rep = cycle_reach_times(d, arr, dep, seg_start, seg_len,
                                                       traj_cfg.cycle)
            if rep["max_delay_s"] > 0:
                cycle_delays.append(rep["max_delay_s"])
        else:
            idx, t0, dtt, cov = pattern_segment_times(d, arr, dep, seg_start, seg_len)
        moving = cov > 0
        n_zero += int(np.sum(moving & (dtt <= 0)))
        frames.append(pd.DataFrame({
            "pattern_id": np.int64(pid),
            "segment_id": sg["segment_id"].to_numpy(np.int64)[idx],
            "t_offset_s": t0.astype(np.float64),
            "dt_s": dtt.astype(np.float32),
            "speed_mps": np.where(dtt > 0, cov / np.where(dtt > 0, dtt, 1), 0).astype(np.float32),
        }))
    if n_zero:
        problems.append(f"{n_zero} pattern segments are scheduled with zero running time "
                        "(stop times repeat between distinct stops); their dt_s is 0")
    if cycle_delays:
        problems.append(f"driving cycles: {len(cycle_delays)} patterns cannot keep their "
                        f"schedule within the limits (max delay {max(cycle_delays):.0f} s)")
    if not frames:
        return pd.DataFrame(columns=["pattern_id", "segment_id", "t_offset_s", "dt_s",
                                     "speed_mps"])
    return pd.concat(frames, ignore_index=True)


def _trips_table(trips: pd.DataFrame, routes: pd.DataFrame, pats: _Patterns) -> pd.DataFrame:
    """``trips.parquet``: the trips kept, with the route's names and type, the trip's
    headsign, pattern and start (s).  A route without a short name is named by its long
    name, else its route_id (``route_short_name`` is what outputs, console and app show)."""
    trips = trips[trips["trip_id"].astype(str).isin(pats.trip_pattern.keys())].copy()
    trips["trip_id"] = trips["trip_id"].astype(str)
    keep = [c for c in ("route_id", "route_short_name", "route_long_name", "route_type")
            if c in routes]
    trips = trips.drop(columns=[c for c in keep if c != "route_id" and c in trips])
    trips = trips.merge(routes[keep], on="route_id", how="left")
    for col in ("direction_id", "block_id", "trip_headsign", "route_short_name",
                "route_long_name", "route_type"):
        if col not in trips:
            trips[col] = pd.NA

    def text(col):
        v = trips[col].astype("string").str.strip()
        return v.mask(v == "")

    short = text("route_short_name").fillna(text("route_long_name")).fillna(
        trips["route_id"].astype("string"))
    trips["pattern_id"] = trips["trip_id"].map(pats.trip_pattern).astype(np.int64)
    trips["start_s"] = trips["trip_id"].map(pats.trip_start).astype(np.float64)
    return pd.DataFrame({
        "trip_id": trips["trip_id"].astype(str),
        "route_id": trips["route_id"].astype(str),
        "route_short_name": short.astype("string"),
        "route_long_name": text("route_long_name"),
        "route_type": pd.to_numeric(trips["route_type"], errors="coerce").astype("Int32"),
        "trip_headsign": text("trip_headsign"),
        "direction_id": trips["direction_id"].astype("Int32"),
        "shape_id": trips["shape_id"].astype(str),
        "service_id": trips["service_id"].astype(str),
        "block_id": trips["block_id"].astype("string"),
        "pattern_id": trips["pattern_id"],
        "start_s": trips["start_s"],
    }).sort_values(["route_id", "start_s", "trip_id"], kind="stable", ignore_index=True)


def _calendar_tables(feed):
    """``calendar`` and ``calendar_dates`` with text ids and dates (empty when absent)."""
    cal_cols = ["service_id", "monday", "tuesday", "wednesday", "thursday", "friday",
                "saturday", "sunday", "start_date", "end_date"]
    cal = (feed.calendar[cal_cols] if feed.calendar is not None
           else pd.DataFrame(columns=cal_cols)).astype({"service_id": str, "start_date": str,
                                                        "end_date": str})
    cd_cols = ["service_id", "date", "exception_type"]
    cd = (feed.calendar_dates[cd_cols] if feed.calendar_dates is not None
          else pd.DataFrame(columns=cd_cols)).astype({"service_id": str, "date": str})
    return cal, cd


def _write_stage(out: Path, feed, segs, geom, crs_obj, trips_out, patterns, pstops,
                 report: dict, t_start: float) -> None:
    """Write the stage files into a new folder, swapped in for gtfs/ as a whole at the end."""
    import geopandas as gpd

    # (a folder a failed write leaves is removed by the next ingest, once its process is gone)
    final, out = out, GtfsDir(staging_dir(out))
    gseg = gpd.GeoDataFrame(segs, geometry=geom, crs=crs_obj)
    write_parquet(gseg, out.table("segments"), pandas_dtypes=True)
    write_parquet(trips_out, out.table("trips"), pandas_dtypes=True)
    write_parquet(patterns, out.table("patterns"), pandas_dtypes=True)
    write_parquet(pstops, out.table("pattern_stops"), pandas_dtypes=True)
    cal, cd = _calendar_tables(feed)
    write_parquet(cal, out.table("calendar"), pandas_dtypes=True)
    write_parquet(cd, out.table("calendar_dates"), pandas_dtypes=True)
    report["seconds"] = round(time.perf_counter() - t_start, 2)
    write_text(json.dumps(report, indent=2), out.feed_json)
    swap_dir(out.root, final)
