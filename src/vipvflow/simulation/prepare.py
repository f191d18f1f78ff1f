"""Inputs of a run: generate the demo when asked, ingest each input once (cached by the
content digests of its files and the settings), check them before a cluster starts."""
from __future__ import annotations

import json
import logging
from pathlib import Path

from ..config import Config
from ..errors import InputError
from ..store import DataDir, GtfsDir, sha256, write_text

log = logging.getLogger(__name__)


def _cached(stamp: Path, fp: dict) -> bool:
    try:
        return json.loads(stamp.read_text()) == fp
    except (OSError, ValueError):
        return False


#: written beside the demo inputs: the year, seed and size they were generated for
DEMO_MARKER = "demo_generated.json"
#: the demo generator's version: inputs of an older generator are made again (2: termini
#: among buildings; 3: street trees)
DEMO_VERSION = 3


def mark_demo(folder, year: int, seed: int, size: str) -> None:
    """Record what the demo inputs in *folder* were generated for (see :func:`ensure_demo`)."""
    _stamp(Path(folder) / DEMO_MARKER, {"year": year, "seed": seed, "size": size,
                                        "generator": DEMO_VERSION})


def _read_marker(path: Path) -> dict | None:
    try:
        return json.loads(path.read_text())
    except (OSError, ValueError):
        return None


def _stamp(stamp: Path, fp: dict) -> None:
    write_text(json.dumps(fp, indent=1), stamp)


def ensure_demo(cfg: Config, year: int, say=print) -> None:
    """Generate the demo inputs when the scenario is the demo and they are missing or were
    made with another seed or size. Inputs made for another year are kept (said in one
    line): the run then stops before its cluster naming the calendar's range, instead of
    rewriting the demo under a finished run of that other year."""
    if not cfg.demo.enabled:
        return
    inputs = [*cfg.inputs.citygml, cfg.inputs.gtfs, *cfg.inputs.cams]
    folder = Path(cfg.inputs.gtfs).parent
    marker = folder / DEMO_MARKER
    want = {"year": year, "seed": cfg.demo.seed, "size": cfg.demo.size, "generator": DEMO_VERSION}
    if all(Path(p).exists() for p in inputs):
        if _cached(marker, want):
            return
        made = _read_marker(marker)
        if made and made.get("year") != year and {k: made.get(k) for k in ("seed", "size", "generator")} == {
                "seed": cfg.demo.seed, "size": cfg.demo.size, "generator": DEMO_VERSION}:
            # the demo of another year is kept: a run for a year its timetable does not
            # serve stops with the calendar's range (make a new one with `demo-data --year`)
            say(f"the demo inputs in {folder} are for {made['year']} (new ones: vipvflow "
                f"demo-data --out {folder} --year {year})")
            return
    from ..demo import generate_demo        # pvlib, scipy, shapely: only when the demo is made

    say(f"generating the demo scenario ({cfg.demo.size}, seed {cfg.demo.seed}) for {year} in {folder}")
    generate_demo(folder, year=year, seed=cfg.demo.seed, size=cfg.demo.size)
    _stamp(marker, want)


def input_digests(cfg: Config) -> "InputDigests":
    """The content digests (SHA-256) of the scenario's input files, which must exist; the
    timetable and the radiation are required (tree tables, ``inputs.trees``, are optional)."""
    from .manifest import InputDigests

    city_files = [Path(p) for p in cfg.inputs.citygml]
    tree_files = [Path(p) for p in cfg.inputs.trees]
    cams_files = [Path(p) for p in cfg.inputs.cams]
    gtfs = Path(cfg.inputs.gtfs) if cfg.inputs.gtfs else None
    missing = [str(p) for p in [*city_files, *tree_files, *cams_files, *([gtfs] if gtfs else [])]
               if not p.exists()]
    if missing:
        raise InputError("input file(s) not found: " + ", ".join(missing)
                         + " (see data_manifest.yaml and `make data`)")
    if gtfs is None or not cams_files:
        raise InputError(f"{cfg._source}: inputs.gtfs and inputs.cams are required")
    not_files = [str(p) for p in [*city_files, *tree_files, *cams_files] if not p.is_file()]
    if not_files:
        raise InputError(f"{cfg._source}: inputs name folders, not files: {', '.join(not_files)}")
    files = {"inputs.citygml": {str(p): sha256(p) for p in city_files},
             "inputs.gtfs": {str(gtfs): sha256(gtfs)},
             "inputs.cams": {str(p): sha256(p) for p in cams_files}}
    if tree_files:
        files["inputs.trees"] = {str(p): sha256(p) for p in tree_files}
    return InputDigests(files)


#: the ingests' format versions: a data dir ingested before (city: no meshes for the tiles
#: within the buffer, no coverage area, no check of --crs's area, an older mesh file (the
#: mesh format is part of it too); GTFS: no ground sources, no
#: duplicate rows or service-day checks; radiation: no gaps listed, no check of GHI against
#: DHI and the clear sky) is ingested again
_FORMATS = {"city": 3, "radiation": 4, "gtfs": 3}


def _fingerprints(cfg: Config, inputs) -> dict:
    """What each ingested folder of the data dir must have been made from: the contents
    (SHA-256) of its input files and the settings that shape it."""
    def shas(role):
        return sorted(inputs.files[role].values())

    from ..models.mesh import MESH_FORMAT
    from ..models.tree_table import TREES_FORMAT

    # the trees (vegetation as crowns, never mesh surfaces, and the tree tables) shape the city
    city = {"files": shas("inputs.citygml") + (shas("inputs.trees") if "inputs.trees" in inputs.files
                                              else []),
            "config": {"city": cfg.city.model_dump(mode="json"), "crs": cfg.inputs.citygml_crs,
                       "format": _FORMATS["city"], "mesh_format": MESH_FORMAT,
                       "trees_format": TREES_FORMAT, "trees_crs": cfg.inputs.trees_crs}}
    radiation = {"files": shas("inputs.cams"), "config": {"checks": _FORMATS["radiation"]}}
    gtfs = {"files": shas("inputs.gtfs"), "config": {
        "trajectory": cfg.trajectory.model_dump(mode="json"), "city": city,
        "radiation": radiation, "timezone": cfg.inputs.gtfs_timezone,
        "route_types": cfg.run.route_types, "format": _FORMATS["gtfs"]}}
    return {"city": city, "radiation": radiation, "gtfs": gtfs}


def ingest_needed(cfg: Config, inputs) -> list[str]:
    """The folders of the data dir (``city``, ``radiation``, ``gtfs``) that
    :func:`ensure_ingested` would ingest again for these inputs and settings."""
    data = DataDir(cfg.data_dir)
    fps = _fingerprints(cfg, inputs)
    return [name for name in ("city", "radiation", "gtfs")
            if (name != "city" or cfg.inputs.citygml)
            and not _cached(getattr(data, name).stamp, fps[name])]


def ensure_ingested(cfg: Config, say=print, inputs=None):
    """Ingest city, GTFS and CAMS inputs into ``cfg.data_dir`` unless already done from the
    same file contents and settings (each folder's ``.inputs.json`` records the SHA-256 of
    its files). Returns the inputs' :class:`~vipvflow.simulation.manifest.InputDigests`
    (computed when *inputs* is not given).  Each reader is loaded only when its folder is
    ingested: the city's loads trimesh and Embree, which a run's own process needs not."""
    if inputs is None:
        inputs = input_digests(cfg)
    data_dir = Path(cfg.data_dir)
    city_files = [Path(p) for p in cfg.inputs.citygml]
    tree_files = [Path(p) for p in cfg.inputs.trees]
    cams_files = [Path(p) for p in cfg.inputs.cams]
    gtfs = Path(cfg.inputs.gtfs)
    fps = _fingerprints(cfg, inputs)
    data = DataDir(data_dir)
    stamp = data.city.stamp
    if city_files and not _cached(stamp, fps["city"]):
        from ..inputs.city import ingest_city

        say(f"ingesting {len(city_files)} CityGML file(s)"
            + (f" and {len(tree_files)} tree table(s)" if tree_files else ""))
        report = ingest_city(city_files, data_dir, cfg.city, crs=cfg.inputs.citygml_crs,
                             accept=cfg.checks.accept, trees=tree_files,
                             trees_crs=cfg.inputs.trees_crs)
        say("  " + report.summary())
        _stamp(stamp, fps["city"])
    # the radiation before the timetable: its header's altitude is the ground where the
    # city model has none
    stamp = data.radiation.stamp
    if not _cached(stamp, fps["radiation"]):
        say(f"ingesting {len(cams_files)} CAMS file(s)")
        from ..commands.ingest_cams import findings
        from ..inputs.cams import ingest_cams

        report = ingest_cams(cams_files, data_dir, accept=cfg.checks.accept)
        for line in findings(report):
            say("  " + line)
        _stamp(stamp, fps["radiation"])
    else:
        _earlier(data.radiation.report, "gaps", say)
    stamp = data.gtfs.stamp
    if not _cached(stamp, fps["gtfs"]):
        from ..commands.ingest_gtfs import findings, summary_lines
        from ..inputs.gtfs import ingest_gtfs

        say(f"ingesting GTFS feed {gtfs}")
        report = ingest_gtfs(gtfs, data_dir, cfg.trajectory, crs=cfg.inputs.citygml_crs,
                             timezone=cfg.inputs.gtfs_timezone, route_types=cfg.run.route_types,
                             accept=cfg.checks.accept)
        for line in summary_lines(report):
            say("  " + line)
        for line in findings(report):
            say("  " + line)
        _stamp(stamp, fps["gtfs"])
    else:
        _earlier(data.gtfs.feed_json, "problems", say)
    return inputs


def _earlier(report_path: Path, what: str, say) -> None:
    """One line naming the findings of an ingest done by an earlier run (nothing if none)."""
    try:
        report = json.loads(report_path.read_text())
    except (OSError, ValueError):
        return
    if what == "problems":
        n = len(report.get("problems", []))
    else:
        n = sum(len(loc.get("gaps", [])) for loc in report.get("locations", []))
    if n:
        say(f"{report_path}: {n} {what} found when it was ingested (listed there)")


#: the years a run may ask for: GTFS dates are YYYYMMDD and CAMS starts in 2004
YEAR_RANGE = (1900, 2100)


def check_year(year) -> int:
    """The run's year, or :class:`InputError` when it is not a plausible calendar year."""
    lo, hi = YEAR_RANGE
    if isinstance(year, bool) or not isinstance(year, int) or not lo <= year <= hi:
        raise InputError(f"--year {year}: not a year a timetable and radiation data can cover "
                         f"({lo}..{hi})")
    return year


def _day(t: float) -> str:
    import pandas as pd

    return pd.Timestamp(t, unit="s", tz="UTC").strftime("%Y-%m-%d %H:%M")


def _date_list(dates) -> str:
    """'2024-06-16 .. 2024-12-31 (199 days)' or the dates themselves when few."""
    import pandas as pd

    d = pd.DatetimeIndex(sorted(set(dates)))
    if len(d) <= 3:
        return ", ".join(x.strftime("%Y-%m-%d") for x in d)
    return f"{d[0]:%Y-%m-%d} .. {d[-1]:%Y-%m-%d} ({len(d)} service days)"


def preflight(cfg: Config, year: int, say=print) -> dict:
    """Checks made on the ingested inputs before a cluster starts; each failure is one line.

    - ``run.routes`` name routes of the feed;
    - the GTFS calendar has service in the run's months of *year* (else its range is named);
    - the city model covers at least part of the routes (same tiles);
    - every radiation location lies within :data:`vipvflow.config.RADIATION_MAX_KM` of the
      city model (without one: of the routes), unless ``radiation_far`` is accepted;
    - the radiation data cover every service day's trips (first departure to last arrival,
      UTC) without a gap longer than ``radiation.max_gap_minutes``; shorter gaps within
      those hours are counted (they were interpolated at ingest).

    Returns
    -------
    dict
        ``service_days``, ``radiation_gaps_interpolated``, ``radiation_gap_minutes_interpolated``.
    """
    import pandas as pd

    check_year(year)
    data_dir = Path(cfg.data_dir)
    data = DataDir(data_dir)
    gdir = data.gtfs.root
    feed = json.loads(data.gtfs.feed_json.read_text())
    trips = pd.read_parquet(data.gtfs.trips,
                            columns=["trip_id", "route_id", "shape_id", "service_id", "pattern_id",
                                     "start_s"])
    trips = _run_trips(cfg, trips)
    sd = _run_service_dates(data_dir, trips, year, set(cfg.run.months))
    # the shapes the run drives: of the trips with service in its months
    _check_city_covers(data_dir, trips[trips["service_id"].isin(set(sd["service_id"]))], say)
    if "radiation_far" not in cfg.checks.accept:
        check_radiation_place(data_dir)
    days, lo, hi = _hours_on_the_road(gdir, trips, sd, feed["timezone"])
    n_short, short_min = _check_radiation(data_dir, days, lo, hi, cfg.radiation.max_gap_minutes)
    if n_short:
        say(f"  radiation: {n_short} gaps ({short_min} min) within the buses' hours were "
            "interpolated")
    return {"service_days": int(len(days)), "radiation_gaps_interpolated": n_short,
            "radiation_gap_minutes_interpolated": int(short_min)}


def _run_trips(cfg: Config, trips):
    """The trips of ``run.routes`` (all when not set); a route not in the feed is an error."""
    routes = cfg.run.routes
    if routes is None:
        return trips
    unknown = sorted(set(routes) - set(trips["route_id"].astype(str)))
    if unknown:
        known = sorted(trips["route_id"].astype(str).unique())
        types = cfg.run.route_types
        kept = "" if types == "all" else (
            f"; ingest kept only route types {'bus' if types == 'bus' else types} "
            "(run.route_types)")
        raise InputError(f"{cfg._source}: run.routes: route_id(s) not in the feed: "
                         f"{', '.join(unknown)} (the feed has {', '.join(known[:10])}"
                         f"{' ...' if len(known) > 10 else ''}{kept})")
    return trips[trips["route_id"].astype(str).isin(routes)]


def _run_service_dates(data_dir: Path, trips, year: int, months: set):
    """The service dates of *trips* in the run's months; none is an error naming the
    calendar's range."""
    from ..inputs.gtfs.schedule import service_dates

    gdir = DataDir(data_dir).gtfs.root
    year_sd = service_dates(data_dir, year)
    year_sd = year_sd[year_sd["service_id"].isin(set(trips["service_id"]))]
    sd = year_sd[year_sd["date"].dt.month.isin(months)]
    if sd.empty:
        lo, hi = _calendar_range(gdir)
        which = "" if len(months) == 12 else f" (months {sorted(months)})"
        # a calendar of a few dates (its services dropped at ingest, say) is said so
        n = year_sd["date"].nunique()
        few = f", on {n} dates in {year}" if n else ""
        raise InputError(f"{gdir / 'calendar.parquet'}: the GTFS calendar has no service in "
                         f"{year}{which}; it runs from {lo} to {hi}{few}")
    return sd


def _check_city_covers(data_dir: Path, trips, say) -> None:
    """The city model, when ingested, must cover some of the routes (else the run is
    refused: a city model of another place, or in another CRS); the share of the route-km
    outside it, computed under the open sky, is said."""
    import pandas as pd

    data = DataDir(data_dir)
    tiles_json = data.city.tiles_json
    if not tiles_json.exists():
        return
    city = json.loads(tiles_json.read_text())
    seg = pd.read_parquet(data.gtfs.segments)
    seg = seg[seg["shape_id"].isin(set(trips["shape_id"]))]
    if not len(seg):
        return
    if "in_city_model" in seg:
        inside = seg["in_city_model"].to_numpy(bool)
    else:                          # segments ingested before the coverage area existed
        inside = seg["tile"].isin(set(city.get("tiles", {}))).to_numpy()
    km = seg["length_m"].to_numpy(float)
    if not inside.any():
        raise InputError(f"{tiles_json}: the routes miss the city model: none of their "
                         f"{km.sum() / 1000:.1f} route-km ({len(seg)} segments, tiles "
                         f"{', '.join(sorted(seg['tile'].unique())[:3])} ...) lies in the area its "
                         f"buildings cover ({len(city.get('tiles', {}))} tiles in {city.get('crs')}); "
                         "is the city the one the feed serves, in the same CRS? (Without "
                         "inputs.citygml every road is computed under the open sky.)")
    if not inside.all():
        share = km[~inside].sum() / km.sum()
        say(f"  {100 * share:.0f} % of the route-km ({km[~inside].sum() / 1000:.1f} of "
            f"{km.sum() / 1000:.1f} km) lie outside the city model: computed under the open "
            "sky there (no building known to shade them); summary.json gives the figures "
            "inside and outside it")


def _lonlat_box(crs: str, xmin: float, ymin: float, xmax: float, ymax: float):
    """(west, south, east, north) in degrees of a box in projected *crs* (edges densified)."""
    from pyproj import Transformer

    t = Transformer.from_crs(crs, "EPSG:4326", always_xy=True)
    return tuple(float(v) for v in t.transform_bounds(xmin, ymin, xmax, ymax, densify_pts=21))


def _km_to_box(lat: float, lon: float, box) -> float:
    """Great-circle distance (km) from a point to the nearest point of a lon/lat box (0
    inside it; the box's nearest corner or edge by clamping, exact enough at these scales)."""
    import numpy as np

    w, s, e, n = box
    la, lo = min(max(lat, s), n), min(max(lon, w), e)
    p1, p2, l1, l2 = map(np.radians, (lat, la, lon, lo))
    h = np.sin((p2 - p1) / 2) ** 2 + np.cos(p1) * np.cos(p2) * np.sin((l2 - l1) / 2) ** 2
    return float(2 * 6371.0 * np.arcsin(np.sqrt(min(1.0, h))))


def _place(data: DataDir):
    """(what, lon/lat box) of the place the run is about: the city model's buildings (the
    tiles holding its own surfaces), else the routes' segments; None when neither is there."""
    import pandas as pd

    if data.city.tiles_json.is_file():
        city = json.loads(data.city.tiles_json.read_text())
        bounds = [t["bounds"] for t in city.get("tiles", {}).values() if t.get("n_surfaces", 1)]
        if bounds and city.get("crs"):
            b = list(zip(*bounds))
            return "the city model", _lonlat_box(city["crs"], min(b[0]), min(b[1]), max(b[2]),
                                                 max(b[3]))
    if data.gtfs.segments.is_file() and data.gtfs.feed_json.is_file():
        crs = json.loads(data.gtfs.feed_json.read_text()).get("crs")
        seg = pd.read_parquet(data.gtfs.segments, columns=["x", "y"])
        if crs and len(seg):
            return "the routes", _lonlat_box(crs, seg["x"].min(), seg["y"].min(), seg["x"].max(),
                                             seg["y"].max())
    return None


def check_radiation_place(data_dir: Path) -> None:
    """Every radiation location must lie within :data:`vipvflow.config.RADIATION_MAX_KM` of
    the city model (without one: of the routes): a CAMS file of another place (Sydney's for
    Luxembourg gave 116 instead of 314 kWh/kWp) is an :class:`InputError` naming the file,
    its location and the distance."""
    from ..config import RADIATION_MAX_KM
    from ..errors import accept_hint

    data = DataDir(data_dir)
    place = _place(data)
    try:
        rad = json.loads(data.radiation.report.read_text())
    except (OSError, ValueError):
        return                          # _check_radiation names the missing report
    if place is None:
        return
    what, box = place
    for loc in rad.get("locations", []):
        km = _km_to_box(loc["lat"], loc["lon"], box)
        if km <= RADIATION_MAX_KM:
            continue
        files = [f["file"] for f in rad.get("files", [])
                 if round(f["latitude"], 4) == loc["lat"] and round(f["longitude"], 4) == loc["lon"]]
        w, s, e, n = box
        raise InputError(f"{', '.join(files) or data.radiation.table}: the radiation's location "
                         f"{loc['lat']:.4f}, {loc['lon']:.4f} lies {km:,.0f} km from {what} "
                         f"({s:.2f}..{n:.2f} N, {w:.2f}..{e:.2f} E), more than "
                         f"{RADIATION_MAX_KM:g} km: a CAMS file of another place? "
                         f"{accept_hint('radiation_far')}")


def _hours_on_the_road(gdir: Path, trips, sd, timezone: str):
    """(service days, their first departure and last arrival in Unix s UTC)."""
    import pandas as pd

    from ..inputs.gtfs.schedule import service_day_origin_utc

    pat = pd.read_parquet(GtfsDir(gdir).patterns, columns=["pattern_id", "t_offset_s", "dt_s"])
    dur = (pat["t_offset_s"] + pat["dt_s"]).groupby(pat["pattern_id"]).max()
    tr = trips.assign(end_s=trips["start_s"] + trips["pattern_id"].map(dur).fillna(0.0))
    span = tr.groupby("service_id").agg(lo=("start_s", "min"), hi=("end_s", "max"))
    days = sd.join(span, on="service_id").groupby("date").agg(lo=("lo", "min"), hi=("hi", "max"))
    origin = service_day_origin_utc(days.index.to_numpy(), timezone)
    return days, origin + days["lo"].to_numpy(), origin + days["hi"].to_numpy()


def _check_radiation(data_dir: Path, days, lo, hi, limit_min: float) -> tuple[int, float]:
    """Radiation must cover the buses' hours (*lo* to *hi*, Unix s) of every service day at
    every location, without a gap over *limit_min*; (shorter gaps hit, their minutes)."""
    import numpy as np

    report_path = DataDir(data_dir).radiation.report
    try:
        rad = json.loads(report_path.read_text())
    except (OSError, ValueError):
        raise InputError(f"{report_path}: missing or unreadable; run 'vipvflow ingest cams'") from None
    n_short = short_min = 0
    for loc in rad["locations"]:
        # lookups interpolate between minute centres: the data hold from the first centre to
        # the last
        first, last = loc["start_utc"] + 30, loc["end_utc"] - 30
        missing = (lo < first) | (hi > last)
        if missing.any():
            # hours outside the data at night need none (every radiation value is 0 then):
            # a service day running past the end of a calendar-year file, say
            missing[missing] = ~_dark(np.maximum(lo[missing], last), hi[missing], loc) | \
                ~_dark(lo[missing], np.minimum(hi[missing], first), loc)
        if missing.any():
            raise InputError(
                f"{report_path.parent / 'radiation.parquet'}: radiation at "
                f"{loc['lat']:.4f}, {loc['lon']:.4f} covers {_day(loc['start_utc'])} to "
                f"{_day(loc['end_utc'])} UTC; the buses run on "
                f"{_date_list(days.index[missing])} without it (CAMS file truncated or for "
                "another year?)")
        for g in loc.get("gaps", []):
            hit = (lo < g["end_utc"]) & (hi > g["start_utc"])
            if not hit.any():
                continue
            if g["minutes"] > limit_min:
                raise InputError(
                    f"{report_path.parent / 'radiation.parquet'}: radiation at "
                    f"{loc['lat']:.4f}, {loc['lon']:.4f} has a gap of {g['minutes']} min from "
                    f"{_day(g['start_utc'])} to {_day(g['end_utc'])} UTC while buses run "
                    f"(limit radiation.max_gap_minutes = {limit_min:g})")
            n_short += 1
            short_min += g["minutes"]
    return n_short, short_min


#: the longest span :func:`_dark` samples (s): two days
MAX_DARK_SPAN_S = 2 * 86400.0


def _dark(t0, t1, loc: dict, step_s: float = 300.0):
    """Whether the sun stays below the horizon (apparent elevation < -1 deg) at the radiation
    location from *t0* to *t1* (Unix s, arrays; an empty span is dark)."""
    import numpy as np
    import pandas as pd
    import pvlib

    out = np.ones(len(t0), bool)
    for i, (a, b) in enumerate(zip(np.asarray(t0, float), np.asarray(t1, float))):
        if b <= a:
            continue
        if b - a > MAX_DARK_SPAN_S:
            # longer than any service day: not a night (and not sampled every 5 min: a
            # stop time at 999999999:00:00 asked for 89 GiB here)
            out[i] = False
            continue
        times = pd.to_datetime(np.append(np.arange(a, b, step_s), b), unit="s", utc=True)
        sun = pvlib.solarposition.get_solarposition(times, loc["lat"], loc["lon"])
        out[i] = bool((sun["apparent_elevation"] < -1.0).all())
    return out


def _calendar_range(gdir: Path) -> tuple[str, str]:
    """First and last date of the feed's calendar.txt and calendar_dates.txt (ISO)."""
    import pandas as pd

    dates = []
    cal = pd.read_parquet(gdir / "calendar.parquet")
    if len(cal):
        dates += [cal["start_date"].astype(str).min(), cal["end_date"].astype(str).max()]
    cd = pd.read_parquet(gdir / "calendar_dates.parquet")
    if len(cd):
        added = cd[cd["exception_type"].astype(int) == 1]["date"].astype(str)
        if len(added):
            dates += [added.min(), added.max()]
    if not dates:
        return "(no dates)", "(no dates)"
    iso = [f"{d[:4]}-{d[4:6]}-{d[6:8]}" for d in (min(dates), max(dates))]
    return iso[0], iso[1]
