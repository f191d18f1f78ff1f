"""A real city as its open data comes: Berlin Mitte LoD2 tiles + the real VBB feed, end to end.

The seven LoD2 tiles of Berlin Mitte (../shared/data/citygml/berlin_mitte, EPSG:25833, no
terrain) cover a few km2; the VBB sample (../shared/data/gtfs/berlin_vbb_rail_sample) is the
real feed with its quirks: no agency.txt, trips.txt naming shape_ids without a shapes.txt,
most trips without stop_times (only departures 12:00-13:00 were kept), U-Bahn and S-Bahn
route types.  Every line leaves the city model.  The feed is zipped as it is and ingested
with ``--timezone Europe/Berlin``; two S-Bahn lines (route_type 109, named explicitly) are
simulated for June 2019 with the default whole-day harvest, under a CAMS-format radiation
file of Berlin's coordinates written by the demo's generator (no CAMS file of Berlin can be
shipped).

Then a feed and a city model of different places (Cairns, Hamburg): one clear line naming
the stops outside the city model's CRS, no traceback.
"""
from __future__ import annotations

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pytest
import shapely
import yaml

pytestmark = pytest.mark.shared

BERLIN_GROUND_M = 34.0          # Berlin Mitte lies 32-37 m above sea level (DHHN2016)
S5, S7 = ["10157_109", "10158_109"], ["10162_109", "10163_109"]
YEAR, MONTH = 2019, 6


def _cli(*args, cwd, timeout=900) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "vipvflow.cli", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


def _ok(res: subprocess.CompletedProcess) -> str:
    out = res.stdout + res.stderr
    assert "Traceback" not in out, out[-3000:]
    assert res.returncode == 0, out[-3000:]
    return out


def _zip(folder: Path, dest: Path) -> Path:
    with zipfile.ZipFile(dest, "w", zipfile.ZIP_DEFLATED) as zf:
        for f in sorted(folder.glob("*.txt")):
            zf.write(f, f.name)
    return dest


@pytest.fixture(scope="module")
def berlin(shared_data, tmp_path_factory):
    """The Berlin scenario simulated: (root, stdout, seconds of each step)."""
    import time

    from vipvflow.demo.cams import write_cams_csv

    root = tmp_path_factory.mktemp("berlin")
    feed = _zip(shared_data / "gtfs" / "berlin_vbb_rail_sample", root / "vbb.zip")
    cams = root / "cams_berlin_2019_06.csv"
    write_cams_csv(cams, YEAR, 52.52, 13.40, BERLIN_GROUND_M, seed=7, months=[MONTH])
    tiles = sorted((shared_data / "citygml" / "berlin_mitte").glob("*.gml"))
    conf = {"scenario": "berlin", "data_dir": str(root / "data"), "out_dir": str(root / "out"),
            "inputs": {"citygml": [str(t) for t in tiles], "gtfs": str(feed),
                       "gtfs_timezone": "Europe/Berlin", "cams": [str(cams)]},
            "run": {"route_types": [109], "routes": S5 + S7, "months": [MONTH]},
            "irradiance": {"svf_rays": 128, "reflection_rays": 32, "reflector_points": 16},
            "dask": {"n_workers": 1, "threads_per_worker": 2}}
    path = root / "berlin.yaml"
    path.write_text(yaml.safe_dump(conf))
    times = {}
    t = time.perf_counter()
    out = _ok(_cli("simulate", "--config", path, "--year", YEAR, "--quiet", cwd=root))
    times["simulate_s"] = time.perf_counter() - t
    return root, out, times


def test_berlin_end_to_end(berlin):
    """Exit 0, no traceback; the in-model share stated; roads on Berlin's ground; no
    segment inside a footprint counted as shaded road; shading loss inside the model 3-40 %."""
    root, out, _ = berlin
    run = root / "out" / "berlin" / str(YEAR)
    s = json.loads((run / "summary.json").read_text())
    assert 0 < s["route_km_in_city_model_share"] < 0.5                 # most of each line is outside
    assert "In the city model:" in out and "of the route-km" in out and "outside the city model" in out
    assert 0.03 <= s["shading_loss_allsky_in_city_model"] <= 0.40
    assert s["shading_loss_allsky_outside_city_model"] < 0.01         # open sky
    assert s["kwh_per_kwp_driving_in_city_model"] < s["kwh_per_kwp_driving_outside_city_model"]
    # the ground: the buildings' ground surfaces near them, the radiation file's altitude beyond
    segs = gpd.read_parquet(run / "segments.parquet")
    z = shapely.get_coordinates(segs.geometry.to_numpy(), include_z=True)[:, 2] - 3.2
    assert np.abs(z - BERLIN_GROUND_M).max() < 20.0
    assert set(segs["ground_source"].astype(str)) == {"buildings", "radiation_header"}
    assert s["ground_sources"]["buildings"] > 0
    assert np.abs(segs["gradient"]).max() < 0.12                      # no bumps between buildings
    # straight lines between stops cross blocks: flagged, lit as the street next to them,
    # left out of the shading statistics
    inside = segs[segs["in_building"]]
    assert len(inside) == s["segments_in_buildings"] > 0
    assert (inside["svf"] > 0.05).all() and (inside["shading_loss"] < 0.99).all()
    street = segs[~segs["in_building"] & segs["in_city_model"]]
    sm = pd.read_parquet(run / "segment_month.parquet")
    sm = sm[sm["segment_id"].isin(street["segment_id"])]
    loss = 1 - (sm["h_direct"].sum() + sm["h_diffuse"].sum()) / sm["h_total_unshaded"].sum()
    assert loss == pytest.approx(s["shading_loss_allsky_in_city_model"], rel=1e-9)


def test_berlin_names_and_routes(berlin):
    """Segments carry every simulated route that drives them (never a route that was not
    simulated); the outputs carry the feed's names; the app offers the simulated routes only."""
    from vipvflow.app.model import TripModel

    root, out, _ = berlin
    run = root / "out" / "berlin" / str(YEAR)
    segs = gpd.read_parquet(run / "segments.parquet")
    names = {n for v in segs["route_short_name"].dropna() for n in v.split(", ")}
    assert names <= {"S5", "S7"} and names
    trips = pd.read_parquet(run / "trip_energy.parquet")
    assert set(trips["route_id"]) <= set(S5 + S7)
    assert trips["trip_headsign"].notna().all()
    rm = pd.read_parquet(run / "route_month.parquet")
    assert {"route_long_name", "trip_headsign"} <= set(rm.columns)
    model = TripModel(run)
    assert set(model.routes()["route_id"]) <= set(S5 + S7)


def test_berlin_feed_ingest_counts_what_it_dropped(berlin):
    """The VBB sample as it comes: the ingest report counts each kind of trip dropped."""
    root, out, _ = berlin
    feed = json.loads((root / "data" / "gtfs" / "feed.json").read_text())
    text = "\n".join(feed["problems"])
    for what in ("agency.txt is missing", "trips have no stop_times; dropped",
                 "feed has no shapes.txt; shapes built from their stops",
                 "outside run.route_types ([109]); dropped",
                 "that are not buses are simulated as buses"):
        assert what in text, text


def test_berlin_ingest_alone_by_the_docs(shared_data, tmp_path):
    """docs/own_city.md's first steps on the Berlin data: city, radiation, then the feed as it
    comes (buses by default: the VBB sample has 11 bus routes), each one command, exit 0."""
    from vipvflow.demo.cams import write_cams_csv

    feed = _zip(shared_data / "gtfs" / "berlin_vbb_rail_sample", tmp_path / "vbb.zip")
    cams = tmp_path / "cams.csv"
    write_cams_csv(cams, YEAR, 52.52, 13.40, BERLIN_GROUND_M, seed=7, months=[MONTH])
    tiles = sorted((shared_data / "citygml" / "berlin_mitte").glob("*.gml"))
    data = tmp_path / "data"
    out = _ok(_cli("ingest", "city", *tiles, "--data-dir", data, cwd=tmp_path))
    assert "EPSG:25833" in out
    _ok(_cli("ingest", "cams", cams, "--data-dir", data, cwd=tmp_path))
    out = _ok(_cli("ingest", "gtfs", feed, "--data-dir", data, "--timezone", "Europe/Berlin",
                   cwd=tmp_path))
    assert "trips of route types [109, 400] outside run.route_types (bus); dropped" in out
    assert "ground height of the segments from:" in out


def test_lines_that_miss_the_city_model(shared_data, tmp_path):
    """Cairns' feed with Hamburg's tile: no overlap at all: one line saying that the feed's
    stops lie outside the area of use of the city model's CRS (EPSG:25832, where the GTFS
    ingest would project them), before any cluster starts; never a traceback."""
    from vipvflow.demo.cams import write_cams_csv

    cams = tmp_path / "cams_cairns.csv"
    write_cams_csv(cams, 2014, -16.92, 145.77, 5.0, seed=3, months=[6])
    conf = {"scenario": "mismatch", "data_dir": str(tmp_path / "data"), "out_dir": str(tmp_path / "out"),
            "inputs": {"citygml": [str(shared_data / "citygml" / "hamburg" / "LoD2_576_5950_1_HH_2022.xml")],
                       "gtfs": str(shared_data / "gtfs" / "cairns_gtfs_kit" / "cairns_gtfs.zip"),
                       "cams": [str(cams)]},
            "run": {"months": [6]}}
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(conf))
    res = _cli("simulate", "--config", path, "--year", 2014, "--quiet", cwd=tmp_path)
    err = res.stderr.strip()
    assert res.returncode == 2 and "Traceback" not in res.stderr + res.stdout, res.stderr[-3000:]
    assert len(err.splitlines()) == 1, err
    assert "cairns_gtfs.zip" in err and "lie outside the area of use of EPSG:25832" in err, err
    assert "(the city model's CRS, city/tiles.json)" in err and "around -16.9" in err, err
    assert "dask dashboard" not in res.stdout
