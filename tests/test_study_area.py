"""A real study area: lines that leave the city model, feeds as they come, the ground from the
data, straight lines through blocks, names, partial years (issue: a real city end to end).

Each test here fails on the code before it: a traceback from gtfs-kit on trips without stop
times, a missing mesh read for a tile outside the model, roads at a default 300 m, segments
inside footprints counted as shaded road, rail simulated as buses by default, a shared shape
labelled with one route, a one-month console line mixing June's PV with the year's demand.
"""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import shapely

from gtfs_probe_feeds import vbb_like_tables, write_feed
from vipvflow.config import TrajectoryCfg
from vipvflow.inputs.gtfs import ingest_gtfs


def _feed_with_untimed_trips(path):
    """The VBB-like feed as the real VBB sample comes: trips naming shape_ids without a
    shapes.txt, most trips without stop_times, stop_times of a trip trips.txt lacks."""
    t = vbb_like_tables()
    t["trips.txt"] += "".join(f"R100,WD,U{i},SH9,0\n" for i in range(5))
    t["stop_times.txt"] += "TX,13:00:00,13:00:30,S1,1\nTX,13:02:00,13:02:30,S2,2\n"
    return write_feed(path, t)


def test_trips_without_stop_times_and_shapes_are_dropped_and_counted(tmp_path):
    report = ingest_gtfs(_feed_with_untimed_trips(tmp_path / "f.zip"), tmp_path / "d",
                         TrajectoryCfg(ground_elevation_m=34.0))
    text = "\n".join(report["problems"])
    assert "5 of 8 trips have no stop_times; dropped" in text
    assert "2 stop_times name a trip_id that trips.txt does not list; dropped" in text
    assert "trips name a shape_id but the feed has no shapes.txt" in text
    assert report["counts"]["trips"] == 3           # the bus trips with times (tram dropped)


def test_library_errors_become_one_line(tmp_path):
    from vipvflow.errors import InputError
    from vipvflow.inputs.gtfs.feed import library_call

    def boom(feed):
        raise KeyError("107928371")

    with pytest.raises(InputError, match=r"f.zip: building shapes \(gtfs-kit\) failed "
                                         r"\(KeyError: no entry '107928371'\)"):
        library_call(tmp_path / "f.zip", "building shapes (gtfs-kit)", boom, None)


def test_route_types_default_to_buses():
    from vipvflow.config import RunCfg
    from vipvflow.inputs.gtfs.feed import BUS_ROUTE_TYPES, route_type_set

    assert RunCfg().route_types == "bus"
    assert route_type_set("bus") == BUS_ROUTE_TYPES == {3, 11, 800, *range(700, 717)}
    assert route_type_set("all") is None and route_type_set([109]) == {109}


def test_rail_named_explicitly_is_kept_with_a_warning(tmp_path):
    t = vbb_like_tables()
    report = ingest_gtfs(write_feed(tmp_path / "f.zip", t), tmp_path / "d",
                         TrajectoryCfg(ground_elevation_m=34.0), route_types=[900])
    assert report["counts"]["route_types"] == {"900": 1}
    assert any("route types [900] that are not buses" in p and "tunnels" in p
               for p in report["problems"])


# ---- the ground from the data ----------------------------------------------------------------

def test_ground_from_the_radiation_header_without_a_city(demo_small, tmp_path):
    """No city model, no configured height: the ground is the CAMS header's altitude, said per
    segment; with neither, the ingest refuses in one line."""
    from vipvflow.errors import InputError
    from vipvflow.inputs.cams import ingest_cams

    feed = write_feed(tmp_path / "f.zip", vbb_like_tables())
    with pytest.raises(InputError, match="no ground height for .* segments .* set "
                                         "trajectory.ground_elevation_m"):
        ingest_gtfs(feed, tmp_path / "d", TrajectoryCfg())
    ingest_cams([demo_small / "cams_radiation_demo.csv"], tmp_path / "d")
    alt = json.loads((tmp_path / "d" / "radiation" / "ingest_report.json").read_text())["locations"][0]
    report = ingest_gtfs(feed, tmp_path / "d", TrajectoryCfg())
    seg = pd.read_parquet(tmp_path / "d" / "gtfs" / "segments.parquet")
    assert np.allclose(seg["ground_z"], alt["altitude"]) and alt["altitude_declared"]
    assert set(seg["ground_source"].astype(str)) == {"radiation_header"}
    assert report["ground_sources"]["radiation_header"] == len(seg)
    assert report["ground_fallback_source"] == "radiation_header"


def test_ground_between_buildings_and_fallback_is_continuous():
    """Building ground points at 40 m, the fallback 30 m: near the buildings their height,
    far away the fallback's, and in between no step (a road leaving the model)."""
    from vipvflow.inputs.city.terrain import GROUND_SOURCES, TerrainModel

    pts = np.array([[0.0, 10.0, 40.0], [20.0, 10.0, 40.0], [40.0, 10.0, 40.0]])
    t = TerrainModel(np.zeros((0, 3)), np.zeros((0, 3)), pts, max_distance_m=100.0)
    x = np.arange(0.0, 400.0, 1.0)
    z, src = t.ground(x, np.zeros_like(x), fallback_m=30.0, fallback_source="radiation_header")
    assert z[0] == pytest.approx(40.0, abs=0.2) and (z[x > 141] == 30.0).all()
    assert np.abs(np.diff(z)).max() < 0.5                 # no step where the buildings end
    assert src[0] == GROUND_SOURCES.index("buildings")
    assert src[-1] == GROUND_SOURCES.index("radiation_header")


def test_road_profile_from_building_ground_is_smoothed():
    """Building ground heights scattered by +-1.5 m along a flat street: the road keeps
    their mean, without 20 % bumps."""
    from vipvflow.inputs.gtfs.segments import smooth_profile

    s = np.arange(0.0, 500.0, 10.0)
    rng = np.random.default_rng(1)
    z = 34.0 + rng.uniform(-1.5, 1.5, len(s))
    out = smooth_profile(s, z, np.zeros(len(s), bool))
    assert np.abs(np.diff(out) / 10.0).max() < 0.05
    assert abs(out.mean() - 34.0) < 0.5
    keep = np.ones(len(s), bool)                          # the relief is followed as it is
    assert np.array_equal(smooth_profile(s, z, keep), z)


# ---- the city model's extent -----------------------------------------------------------------

def _block(x0, y0, w, h):
    return shapely.box(x0, y0, x0 + w, y0 + h)


def test_coverage_area_closes_streets_but_not_the_outside():
    from vipvflow.inputs.city.coverage import coverage_area

    # two rows of blocks with a 20 m street between them
    prints = np.array([_block(i * 40.0, 0.0, 30.0, 30.0) for i in range(5)]
                      + [_block(i * 40.0, 50.0, 30.0, 30.0) for i in range(5)])
    area = coverage_area(prints)
    assert shapely.contains_xy(area, 100.0, 40.0)          # the street between the rows
    assert shapely.contains_xy(area, 100.0, -15.0)         # in front of the outer buildings
    assert not shapely.contains_xy(area, 100.0, -60.0)     # beyond the model
    assert not shapely.contains_xy(area, 500.0, 40.0)


def test_points_inside_a_block_take_the_street_light():
    """A straight line through a block: its points inside are flagged and get the nearest
    point outside the block (two touching footprints are one block)."""
    from vipvflow.inputs.city.coverage import STREET_M, inside_footprints

    prints = np.array([_block(0.0, 0.0, 30.0, 40.0), _block(30.0, 0.0, 30.0, 40.0),
                       _block(100.0, 0.0, 20.0, 20.0)])
    x = np.array([10.0, 31.0, 80.0, 110.0])
    y = np.array([20.0, 35.0, 20.0, 10.0])
    inside, dx, dy = inside_footprints(x, y, prints)
    assert inside.tolist() == [True, True, False, True]
    lx, ly = x + dx, y + dy
    # the block's nearest outline: x = 0 for the first, y = 40 for the second (the shared
    # wall at x = 30 is inside the block), x = 100 or 120 for the last
    assert lx[0] == pytest.approx(-STREET_M) and ly[0] == pytest.approx(20.0)
    assert ly[1] == pytest.approx(40.0 + STREET_M) and lx[1] == pytest.approx(31.0)
    assert dx[2] == dy[2] == 0.0
    assert not shapely.contains_xy(shapely.union_all(prints), lx, ly).any()


def test_a_tile_without_a_mesh_is_open_sky(tmp_path):
    """get_scene: a tile the city model has no mesh for (no building within the buffer) is an
    open field; one that tiles.json lists but whose mesh is gone is an error."""
    from vipvflow.errors import InputError
    from vipvflow.models.shading import box_mesh, get_scene

    city = tmp_path / "city"
    (city / "meshes").mkdir(parents=True)
    (city / "tiles.json").write_text(json.dumps({"crs": "EPSG:2169", "tile_size_m": 500,
                                                 "tiles": {"E0010N0010": {}, "E0015N0010": {}}}))
    box_mesh([[0, 0, 0, 10, 10, 10]]).save(city / "meshes" / "E0010N0010.npz")
    assert get_scene(tmp_path, "E0010N0010").n_triangles == 10
    assert get_scene(tmp_path, "E0050N0050").n_triangles == 0
    with pytest.raises(InputError, match="E0015N0010.npz: missing, though .*tiles.json lists"):
        get_scene(tmp_path, "E0015N0010")


def test_tiles_within_the_buffer_get_meshes(tmp_path):
    """A building shades roads up to city.buffer_m away, across its tile's edge: every tile
    within the buffer gets a mesh (of the buffer's surfaces, none of its own), and the
    model's coverage area is written (one real LoD2 house, KIT's FZK-Haus)."""
    from pathlib import Path

    from vipvflow.inputs.city import ingest_city

    gml = Path(__file__).parent / "data" / "citygml" / "fzk_haus_lod2_v2.gml"
    ingest_city([gml], tmp_path / "d")
    tiles = json.loads((tmp_path / "d" / "city" / "tiles.json").read_text())["tiles"]
    own = [t for t, v in tiles.items() if v["n_surfaces"]]
    buffer_only = [t for t, v in tiles.items() if not v["n_surfaces"]]
    assert len(own) == 1 and len(buffer_only) >= 3      # the house is one tile; 300 m around
    assert all(v["n_triangles"] > 0 for v in tiles.values())
    assert all((tmp_path / "d" / "city" / "meshes" / f"{t}.npz").exists() for t in tiles)
    assert (tmp_path / "d" / "city" / "coverage.parquet").exists()


# ---- names and partial years ------------------------------------------------------------------

def test_a_shared_shape_carries_every_route():
    from vipvflow.simulation.reduce import shape_routes

    trips = pd.DataFrame({"shape_id": ["A", "A", "B", "A"], "route_id": ["r3", "r7", "r7", "r7"],
                          "route_short_name": ["S3", "S7", "S7", "S7"],
                          "direction_id": pd.array([0, 0, 1, 0], dtype="Int32")})
    out = shape_routes(trips).set_index("shape_id")
    assert out.loc["A", "route_short_name"] == "S3, S7" and out.loc["B", "route_short_name"] == "S7"
    assert out.loc["A", "direction_id"] == 0


def test_console_line_of_a_partial_year_compares_like_with_like():
    """A June run: the battery's energy and the demand are June's, the yields annualised and
    said so (it printed June's PV against the year's demand)."""
    from vipvflow.simulation.run import _summary_line

    s = {"months": [6], "kwh_per_kwp_usable": 1000.0, "kwh_per_kwp_driving": 600.0,
         "kwh_per_kwp_driving_clearsky": 700.0,
         "kwh_per_kwp_in_service": 900.0, "kwh_per_kwp_whole_day": 1200.0,
         "shading_loss_allsky": 0.1, "pv_kwh_usable": 3000.0, "pv_kwh_curtailed": 100.0,
         "coverage": 0.04, "fleet_demand_in_service_mwh": 900.0, "grid_kwh_avoided": 3100.0,
         "grid_kwh_avoided_depot": 100.0, "grid_kwh_avoided_opportunity": 3000.0,
         "block_days": 20, "block_days_infeasible": 0, "avoided_charging_cycles_per_bus": 20.0,
         "payback_years": 8.0, "route_km_in_city_model_share": 0.25, "route_km": 40.0,
         "pv_kwh_driving_in_city_model_share": 0.2, "kwh_per_kwp_driving_in_city_model": 500.0,
         "shading_loss_allsky_in_city_model": 0.2, "segments_in_buildings": 3,
         "route_km_in_buildings_share": 0.001}
    line = _summary_line(s)
    assert "annualised from June" in line
    assert "in June the batteries take 3.0 MWh" in line and "of the 75.0 MWh" in line
    assert "In the city model: 25 % of 40.0 route-km" in line
    assert "3 segments" in line and "inside building footprints" in line


def test_own_city_docs_name_the_right_utm_zone():
    """docs/own_city.md walks through Berlin (UTM zone 33: EPSG:25833), not zone 32."""
    from pathlib import Path

    text = (Path(__file__).resolve().parents[1] / "docs" / "own_city.md").read_text()
    assert "--crs EPSG:25833" in text and "--crs EPSG:25832" not in text
