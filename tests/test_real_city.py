"""A real city end to end: PLATEAU Osaka (EPSG:6697, lat/lon) + a GTFS line + CAMS, `vipvflow simulate`.

The city is the PLATEAU LoD2 tile of Maishima, Osaka (../shared/data, geographic JGD2011 +
height).  Without ``--crs`` the ingest puts it into its local UTM zone (EPSG:6690), and every
later stage must follow: the GTFS line written here in WGS 84 lat/lon must land on the same
ground as the buildings.  The line runs 240 m west to east, first over open ground, then 5 m
past the north side of the tile's tallest building (a round hall, 30 m across, eaves 7.5 m and
a conical roof 13.6 m above its ground).  No street map comes with the tile: the line follows
the open strip along the hall's north side.  December midday trips: the sun stands 27-32
degrees above the southern horizon, so the hall must take the direct sun from the segments
beside it, and nothing can shade the segments more than 60 m from every building (no roof of
the tile rises more than 12.6 m above the bus roof: atan(12.6 / 60) = 12 degrees, below the sun).
"""
from __future__ import annotations

import io
import json
import subprocess
import sys
import zipfile
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pvlib
import pytest
import shapely
import yaml
from pyproj import Transformer

from vipvflow.demo.cams import _HEADER, COLUMNS

PLATEAU = ("citygml", "plateau_osaka", "52350301_bldg_6697_op.gml")
UTM = "EPSG:6690"                                   # JGD2011 / UTM zone 53N
LAT, LON = 34.669, 135.394                          # Maishima
LINE = [(536100.0, 3836607.0), (536340.0, 3836607.0)]   # in EPSG:6690; the hall: y 3836580-3836602
YEAR, MONTH = 2024, 12
DEPARTURES = [f"{h:02d}:{m:02d}:00" for h in (11, 12) for m in (0, 20, 40)] + ["13:00:00"]


def write_gtfs(path: Path) -> None:
    """One route, one direction, 7 trips a day at 11:00-13:00 JST, every day of December."""
    to_ll = Transformer.from_crs(UTM, "EPSG:4326", always_xy=True)
    x = np.linspace(LINE[0][0], LINE[1][0], 25)
    lon, lat = to_ll.transform(x, np.full_like(x, LINE[0][1]))
    shapes = pd.DataFrame({"shape_id": "S1", "shape_pt_lat": lat, "shape_pt_lon": lon,
                           "shape_pt_sequence": np.arange(len(x))})
    stops = pd.DataFrame({"stop_id": ["W", "E"], "stop_name": ["Maishima west", "Maishima east"],
                          "stop_lat": [lat[0], lat[-1]], "stop_lon": [lon[0], lon[-1]]})
    trips = pd.DataFrame({"route_id": "R1", "service_id": "DAILY", "trip_id": [f"T{i}" for i in range(len(DEPARTURES))],
                          "direction_id": 0, "shape_id": "S1", "block_id": "B1"})
    rows = []
    for trip, dep in zip(trips.trip_id, DEPARTURES):
        h, m, _ = map(int, dep.split(":"))
        arr = f"{h:02d}:{m + 1:02d}:00"                  # 240 m in 60 s
        rows += [(trip, dep, dep, "W", 1), (trip, arr, arr, "E", 2)]
    stop_times = pd.DataFrame(rows, columns=["trip_id", "arrival_time", "departure_time", "stop_id",
                                             "stop_sequence"])
    tables = {
        "agency.txt": pd.DataFrame({"agency_id": ["A"], "agency_name": ["test"], "agency_url": ["https://example.org"],
                                    "agency_timezone": ["Asia/Tokyo"]}),
        "routes.txt": pd.DataFrame({"route_id": ["R1"], "agency_id": ["A"], "route_short_name": ["M1"],
                                    "route_long_name": ["Maishima"], "route_type": [3]}),
        "calendar.txt": pd.DataFrame({"service_id": ["DAILY"], **{d: [1] for d in (
            "monday", "tuesday", "wednesday", "thursday", "friday", "saturday", "sunday")},
            "start_date": [f"{YEAR}1201"], "end_date": [f"{YEAR}1231"]}),
        "stops.txt": stops, "trips.txt": trips, "stop_times.txt": stop_times, "shapes.txt": shapes,
    }
    with zipfile.ZipFile(path, "w") as zf:
        for name, df in tables.items():
            buf = io.StringIO()
            df.to_csv(buf, index=False, float_format="%.9f")
            zf.writestr(name, buf.getvalue())


def write_cams(path: Path) -> None:
    """December in the CAMS radiation-service CSV layout: pvlib's Ineichen clear sky at Maishima
    (all-sky = clear-sky), Wh/m2 per minute."""
    minutes = pd.date_range(f"{YEAR}-{MONTH}-01", f"{YEAR + 1}-01-01", freq="min", inclusive="left", tz="UTC")
    loc = pvlib.location.Location(LAT, LON, altitude=5.0)
    mid = minutes + pd.Timedelta(seconds=30)
    cs = loc.get_clearsky(mid, model="ineichen")
    zen = loc.get_solarposition(mid)["zenith"].to_numpy()
    cosz = np.cos(np.radians(zen))
    day = cosz > 1e-4
    dni = np.where(day, cs["dni"].to_numpy(), 0.0)
    ghi = np.where(day, cs["ghi"].to_numpy(), 0.0)
    bhi = dni * np.where(day, cosz, 0.0)
    dhi = np.clip(ghi - bhi, 0.0, None)
    toa = np.where(day, pvlib.irradiance.get_extra_radiation(mid).to_numpy() * cosz, 0.0)
    wh = 1.0 / 60.0
    data = pd.DataFrame({"TOA": toa, "Clear sky GHI": ghi, "Clear sky BHI": bhi, "Clear sky DHI": dhi,
                         "Clear sky BNI": dni, "GHI": ghi, "BHI": bhi, "DHI": dhi, "BNI": dni}) * wh
    data["Reliability"] = 1.0
    t0 = minutes.strftime("%Y-%m-%dT%H:%M:%S.0").to_numpy().astype(str)
    t1 = (minutes + pd.Timedelta(minutes=1)).strftime("%Y-%m-%dT%H:%M:%S.0").to_numpy().astype(str)
    data.insert(0, "Observation period", np.char.add(np.char.add(t0, "/"), t1))
    header = _HEADER.format(seed=0, begin=f"{YEAR}-{MONTH}-01T00:00:00.0", end=f"{YEAR + 1}-01-01T00:00:00.0",
                            lat=LAT, lon=LON, alt=5.0, year=YEAR, columns=";".join(COLUMNS))
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(header)
        data.to_csv(fh, sep=";", header=False, index=False, float_format="%.4f", lineterminator="\n")


@pytest.fixture(scope="module")
def osaka_run(shared_data, tmp_path_factory):
    root = tmp_path_factory.mktemp("osaka")
    write_gtfs(root / "maishima_gtfs.zip")
    write_cams(root / "cams_maishima_dec.csv")
    conf = {
        "scenario": "osaka", "data_dir": str(root / "data"), "out_dir": str(root / "out"),
        "inputs": {"citygml": [str(shared_data.joinpath(*PLATEAU))], "gtfs": str(root / "maishima_gtfs.zip"),
                   "cams": [str(root / "cams_maishima_dec.csv")]},
        # ground heights of PLATEAU are metres above Tokyo Bay mean sea level (0-13 m here)
        "trajectory": {"ground_elevation_m": 2.0},
        "irradiance": {"diffuse_model": "isotropic", "reflection_rays": 16, "svf_rays": 32},
        "run": {"months": [MONTH]},
        "dask": {"n_workers": 1, "threads_per_worker": 1},
    }
    cfg = root / "osaka.yaml"
    cfg.write_text(yaml.safe_dump(conf))
    res = subprocess.run([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(cfg),
                          "--year", str(YEAR)], capture_output=True, text=True, timeout=300, cwd=root)
    assert res.returncode == 0, res.stderr[-3000:]
    return root, res.stdout


@pytest.mark.shared
def test_city_crs_is_the_local_utm_zone_for_every_stage(osaka_run):
    root, stdout = osaka_run
    data = root / "data"
    assert "EPSG:6690 (local UTM zone for geographic EPSG:6668)" in stdout
    assert json.loads((data / "city" / "tiles.json").read_text())["crs"] == UTM
    assert json.loads((data / "gtfs" / "feed.json").read_text())["crs"] in (UTM, "EPSG:6690")
    segs = gpd.read_parquet(data / "gtfs" / "segments.parquet")
    assert segs.crs.to_epsg() == 6690
    # the line lies where it was drawn in EPSG:6690 (to the centimetre), so in the city's frame
    assert np.allclose(segs.y, LINE[0][1], atol=0.01)
    assert segs.x.min() == pytest.approx(LINE[0][0], abs=0.01)
    sm = gpd.read_parquet(root / "out" / "osaka" / str(YEAR) / "segment_month.parquet")
    assert sm.crs.to_epsg() == 6690


@pytest.mark.shared
def test_shading_where_the_buildings_are_and_nowhere_else(osaka_run):
    root, _ = osaka_run
    data = root / "data"
    surfaces = gpd.GeoDataFrame(pd.concat([gpd.read_parquet(p) for p in
                                           sorted((data / "city" / "surfaces").glob("tile=*/*.parquet"))]))
    footprints = shapely.union_all([shapely.force_2d(g) for g in surfaces[surfaces.surface_type == "ground"].geometry])
    top = max(np.asarray(g.exterior.coords)[:, 2].max() for g in surfaces.geometry)
    sm = gpd.read_parquet(root / "out" / "osaka" / str(YEAR) / "segment_month.parquet")
    segs = gpd.read_parquet(data / "gtfs" / "segments.parquet").set_index("segment_id")
    sm = sm.join(segs[["x", "y", "z", "x_end", "y_end"]], on="segment_id")
    assert (pd.to_datetime(sm.month) == pd.Timestamp(f"{YEAR}-{MONTH}-01")).all() and len(sm) == len(segs)
    start = shapely.points(sm.x, sm.y)                 # a segment is evaluated at its start
    dist = shapely.distance(start, footprints)
    loss = 1 - (sm.h_direct + sm.h_diffuse) / sm.h_total_unshaded
    # the premise of "nothing can shade": the lowest sun of any pass clears every roof 60 m away
    times = pd.DatetimeIndex([pd.Timestamp(f"{YEAR}-12-{d:02d} {t}", tz="Asia/Tokyo")
                              for d in range(1, 32) for t in DEPARTURES])
    elevation = pvlib.solarposition.get_solarposition(times, LAT, LON)["apparent_elevation"]
    assert elevation.min() > np.degrees(np.arctan((top - sm.z.min()) / 60.0))
    open_ = loss[dist > 60]
    assert len(open_) >= 10
    assert np.abs(open_).max() < 1e-5                  # open ground: no loss (float32 sums)
    # beside the hall the direct sun (the larger part of a clear December midday) is taken
    assert (loss > 0.5).sum() >= 2
    assert (dist[loss > 1e-5] < 10).all()              # and only there
    assert (loss > -1e-5).all() and (sm.h_total_unshaded > 0).all()
