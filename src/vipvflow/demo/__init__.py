"""The embedded demo scenario: a Luxembourg-like town, its bus lines and a year of sun.

:func:`generate_demo` writes, in the real input formats, everything a run needs:

``demo_city.gml``
    CityGML 2.0 LoD2 in LUREF + NG-L heights (EPSG:2169 + EPSG:5774): terrain as TIN relief,
    buildings and street trees along the lines (:mod:`.city`);
``demo_gtfs.zip``
    GTFS feed of the lines and a year of service (:mod:`.gtfs`);
``cams_radiation_demo.csv``
    1-minute clear-sky and all-sky irradiation for the year in the CAMS radiation service
    format (:mod:`.cams`);
``demo_layout.json``
    the ground truth: lines, lengths, stops, trips per year and street stretches
    (:mod:`.layout`).

Everything random is drawn from numpy Generators seeded by ``seed``: the same seed, year and
size give byte-identical files.
"""
from __future__ import annotations

import json
import re
import time
from pathlib import Path

import numpy as np
import shapely
from pyproj import Transformer

from ..progress import Progress
from ..store import atomic_path, write_text
from .cams import write_cams_csv
from .city import SRS_NAME, Terrain, place_buildings, place_trees, terminus_ends, write_citygml
from .gtfs import AVERAGE_SPEED_KMH, AGENCY_TZ, stop_positions, stop_offsets, trips_per_year, write_gtfs
from .layout import CENTRE_XY, CRS, Layout, build_layout

__all__ = ["generate_demo", "build_layout", "FILES"]

FILES = {"citygml": "demo_city.gml", "gtfs": "demo_gtfs.zip", "cams": "cams_radiation_demo.csv",
         "layout": "demo_layout.json"}
TERRAIN_MARGIN_M = 400.0   # terrain grid beyond the lines' bounding box
TERRAIN_NEAR_M = 500.0     # terrain tiles written within this distance of a line


# a JSON list of numbers only, spread over lines by indent: printed on one line instead
_NUMBER_LIST = re.compile(r"\[\s*((?:-?[\d.e+-]+,\s*)*-?[\d.e+-]+)\s*\]")


def _rounded(xy, nd: int = 2) -> list:
    return np.round(np.asarray(xy, dtype=float), nd).tolist()


def layout_document(layout: Layout, year: int, buildings, terrain: Terrain, trees=()) -> dict:
    """The ground truth of the demo as a JSON-ready dict (coordinates in EPSG:2169)."""
    to_wgs84 = Transformer.from_crs(CRS, "EPSG:4326", always_xy=True)
    lon, lat = to_wgs84.transform(*CENTRE_XY)
    lines = []
    for line in layout.lines:
        length = round(line.length_m, 2)
        stops = stop_positions(line.length_m)
        arr, _ = stop_offsets(stops)
        tpy = trips_per_year(line.name, year)
        lines.append({
            "route_id": line.route_id, "route_short_name": line.name,
            "route_long_name": line.long_name,
            "shape_ids": {"0": f"{line.route_id}_d0", "1": f"{line.route_id}_d1"},
            "length_m": {"0": length, "1": length},
            "n_stops": int(len(stops)), "stop_spacing_m": round(float(stops[1] - stops[0]), 2),
            "trip_duration_s": int(arr[-1]), "average_speed_kmh": AVERAGE_SPEED_KMH,
            "trips_per_service_day": tpy["per_service_day"], "service_days": tpy["service_days"],
            "trips_per_year": tpy["per_direction"],
            "centerline": _rounded(line.xy, 3),
        })
    by_stretch: dict[str, list] = {}
    for b in buildings:
        by_stretch.setdefault(b.stretch_id, []).append(b)
    trees_of: dict[str, int] = {}
    for t in trees:
        trees_of[t.stretch_id] = trees_of.get(t.stretch_id, 0) + 1
    stretches = []
    for st in layout.stretches():
        own = by_stretch.get(st.stretch_id, [])
        eaves = np.array([b.eaves_z - b.base_z for b in own]) if own else np.zeros(1)
        poly = shapely.buffer(shapely.linestrings(st.xy), st.width_m / 2, cap_style="flat")
        stretches.append({
            "id": st.stretch_id, "line": st.line, "kind": st.kind,
            "s_start_m": round(st.s_start_m, 2), "s_end_m": round(st.s_end_m, 2),
            "length_m": round(st.length_m, 2), "width_m": st.width_m, "setback_m": st.setback_m,
            "building_height_m": round(float(eaves.mean()), 2),
            "building_height_range_m": [round(float(eaves.min()), 2), round(float(eaves.max()), 2)],
            "n_buildings": len(own), "n_trees": trees_of.get(st.stretch_id, 0),
            "centerline": _rounded(st.xy, 3),
            "polygon": _rounded(shapely.get_coordinates(shapely.get_exterior_ring(poly)), 2),
        })
    termini = [{"line": t.line, "end": "first stop" if t.end == 0 else "last stop",
                "xy": [round(t.xy[0], 2), round(t.xy[1], 2)],
                "n_buildings": len(by_stretch.get(t.stretch_id, []))} for t in terminus_ends(layout)]
    return {
        "crs": CRS, "srs_name": SRS_NAME, "size": layout.size, "seed": layout.seed, "year": year,
        "termini_among_buildings": termini,
        "agency_timezone": AGENCY_TZ,
        "centre": {"x": CENTRE_XY[0], "y": CENTRE_XY[1], "lon": round(lon, 6), "lat": round(lat, 6)},
        "terrain": {"spacing_m": terrain.spacing, "bounds": _rounded(terrain.bounds, 2),
                    "z_min": round(float(terrain.grid.min()), 3),
                    "z_max": round(float(terrain.grid.max()), 3)},
        "lines": lines,
        "stretches": stretches,
    }


def generate_demo(out_dir, year: int, seed: int = 42, size: str = "full") -> dict:
    """Write the demo scenario's input files into *out_dir*.

    Parameters
    ----------
    out_dir : str or Path
        Directory (created when missing).
    year : int
        Year of the timetable (public holidays) and of the radiation series.
    seed : int
        Seed of every random choice.
    size : {"full", "small"}
        ``full``: an 18 km line 1 and a 6.5 km line 2 with about 3,600 buildings;
        ``small``: a 3 km line through canyon, suburban and open stretches with a few hundred
        buildings (the radiation file is a whole year in both).

    Returns
    -------
    dict
        ``paths`` (file name per kind), ``counts`` (buildings, surfaces, terrain triangles,
        trips, stops, trips per year per line and direction, CAMS rows),
        ``annual_kwh_m2`` (radiation sums) and ``seconds`` (time per file).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = {k: out / v for k, v in FILES.items()}
    seconds = {}
    bar = Progress("demo generation", len(FILES), unit="files")
    bar.update(0, "town and CityGML")
    try:
        return _generate(paths, seconds, year, seed, size, bar)
    finally:
        bar.close()


def _generate(paths: dict, seconds: dict, year: int, seed: int, size: str, bar) -> dict:
    """The files of :func:`generate_demo`, one after the other, counted on *bar*."""
    t = time.perf_counter()
    layout = build_layout(seed, size)
    terrain = Terrain(layout.bounds(TERRAIN_MARGIN_M), seed)
    buildings = place_buildings(layout, terrain, seed)
    trees = place_trees(layout, terrain, buildings, seed)
    near = shapely.union_all([shapely.buffer(shapely.linestrings(line.xy), TERRAIN_NEAR_M)
                              for line in layout.lines])
    with atomic_path(paths["citygml"]) as tmp:
        city = write_citygml(tmp, buildings, terrain, near, trees)
    seconds["citygml"] = time.perf_counter() - t
    bar.update(1, "GTFS")

    t = time.perf_counter()
    with atomic_path(paths["gtfs"]) as tmp:
        gtfs = write_gtfs(tmp, layout, year)
    seconds["gtfs"] = time.perf_counter() - t
    bar.update(1, "layout")

    t = time.perf_counter()
    doc = layout_document(layout, year, buildings, terrain, trees)
    write_text(_NUMBER_LIST.sub(lambda m: "[" + " ".join(m.group(1).split()) + "]",
                                json.dumps(doc, indent=1)) + "\n", paths["layout"])
    seconds["layout"] = time.perf_counter() - t
    bar.update(1, "CAMS radiation year")

    t = time.perf_counter()
    alt = round(float(terrain.z(*CENTRE_XY)), 2)
    with atomic_path(paths["cams"]) as tmp:
        cams = write_cams_csv(tmp, year, round(doc["centre"]["lat"], 4),
                              round(doc["centre"]["lon"], 4), alt, seed)
    seconds["cams"] = time.perf_counter() - t
    bar.update(1, "done")

    counts = dict(city)
    counts.update({
        "trips": gtfs["trips"], "stop_times": gtfs["stop_times"], "stops": gtfs["stops"],
        "shape_points": gtfs["shape_points"], "blocks": gtfs["blocks"],
        "trips_per_year": {line["route_short_name"]: line["trips_per_year"] for line in doc["lines"]},
        "line_length_m": {line["route_short_name"]: line["length_m"]["0"] for line in doc["lines"]},
        "cams_rows": cams["rows"],
    })
    return {"paths": paths, "counts": counts, "annual_kwh_m2": cams["annual_kwh_m2"],
            "seconds": {k: round(v, 2) for k, v in seconds.items()}}
