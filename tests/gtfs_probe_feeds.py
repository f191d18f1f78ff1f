"""Small GTFS feeds written by tests: a VBB-like line in Berlin and its broken variants."""
from __future__ import annotations

import zipfile
from pathlib import Path

# four stops along Unter den Linden, Berlin (WGS84), about 300 m apart
STOPS = [("S1", 52.51630, 13.37770), ("S2", 52.51680, 13.38220), ("S3", 52.51730, 13.38680),
         ("S4", 52.51770, 13.39130)]


def vbb_like_tables(shapes: bool = False, agency: bool = True) -> dict[str, str]:
    """Tables of a VBB-like feed: two routes (bus 3, extended bus 700, tram 900), trips naming
    shape_ids; ``shapes`` adds shapes.txt, ``agency`` adds agency.txt."""
    t = {}
    if agency:
        t["agency.txt"] = ("agency_id,agency_name,agency_url,agency_timezone\n"
                           "1,BVG,https://www.bvg.de,Europe/Berlin\n")
    t["routes.txt"] = ("route_id,agency_id,route_short_name,route_type\n"
                       "R100,1,100,3\nR200,1,200,700\nRM1,1,M1,900\n")
    t["stops.txt"] = "stop_id,stop_name,stop_lat,stop_lon\n" + "".join(
        f"{s},{s},{lat},{lon}\n" for s, lat, lon in STOPS)
    t["calendar.txt"] = ("service_id,monday,tuesday,wednesday,thursday,friday,saturday,sunday,"
                         "start_date,end_date\nWD,1,1,1,1,1,0,0,20240101,20241231\n")
    t["trips.txt"] = ("route_id,service_id,trip_id,shape_id,direction_id\n"
                      "R100,WD,T1,SH1,0\nR100,WD,T2,SH1,0\nR200,WD,T3,SH2,1\nRM1,WD,T4,SH1,0\n")
    rows = ["trip_id,arrival_time,departure_time,stop_id,stop_sequence"]
    for trip, h in (("T1", 8), ("T2", 9), ("T4", 10)):
        for i, (s, _, _) in enumerate(STOPS):
            rows.append(f"{trip},{h:02d}:{2 * i:02d}:00,{h:02d}:{2 * i:02d}:30,{s},{i + 1}")
    for i, (s, _, _) in enumerate(reversed(STOPS)):
        rows.append(f"T3,12:{2 * i:02d}:00,12:{2 * i:02d}:30,{s},{i + 1}")
    t["stop_times.txt"] = "\n".join(rows) + "\n"
    if shapes:
        t["shapes.txt"] = "shape_id,shape_pt_lat,shape_pt_lon,shape_pt_sequence\n" + "".join(
            f"SH1,{lat},{lon},{i}\n" for i, (_, lat, lon) in enumerate(STOPS))
    return t


def write_feed(path: Path, tables: dict[str, str]) -> Path:
    """*tables* as a GTFS zip at *path*."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, text in tables.items():
            zf.writestr(name, text)
    return path
