"""The whole day of a bus: layovers and parking through the irradiance kernel, and the
block-day timeline (driving + layover + parked = the day, once)."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pvlib
import pytest

from vipvflow.config import IrradianceCfg, TrajectoryCfg
from vipvflow.inputs.cams import COLUMNS
from vipvflow.inputs.gtfs import ingest_gtfs, passes_for_trip
from vipvflow.inputs.gtfs.schedule import block_timeline, service_day_origin_utc
from vipvflow.models.shading import Scene, box_mesh
from vipvflow.models.sun_sky import RadiationTable
from vipvflow.simulation.standing import interval_integrals, open_scene, point_geometry

#: the ground height (m) of feeds ingested without a city model or radiation file
GROUND_M = 0.0

LAT, LON, ALT = 49.61, 6.13, 300.0
LONG = 3000.0        # half length of an "infinite" wall (m)


def _clear_day_table(day: str, cloud: float = 0.0):
    """One day (and its neighbours) of pvlib's Ineichen clear sky at Luxembourg on the
    radiation table's grid (minute centres), all-sky scaled by (1 - cloud) in DNI."""
    t = pd.date_range(pd.Timestamp(day, tz="UTC") - pd.Timedelta("1D"), periods=3 * 1440, freq="1min") \
        + pd.Timedelta("30s")
    loc = pvlib.location.Location(LAT, LON, altitude=ALT)
    cs = loc.get_clearsky(t, model="ineichen")
    vals = {"ghi_clear": cs["ghi"], "dni_clear": cs["dni"], "dhi_clear": cs["dhi"],
            "dni": cs["dni"] * (1 - cloud), "dhi": cs["dhi"] * (1 + cloud)}
    sp = loc.get_solarposition(t)
    zen = sp["apparent_zenith"].to_numpy()
    vals["azimuth"] = sp["azimuth"].to_numpy()
    vals["ghi"] = vals["dni"] * np.maximum(np.cos(np.radians(zen)), 0) + vals["dhi"]
    grid = (t - pd.Timestamp(0, tz="UTC")) / pd.Timedelta(seconds=1)
    return RadiationTable.from_grid(grid.to_numpy(float), {c: np.asarray(vals[c], float) for c in COLUMNS},
                                    LAT, LON, ALT), t, zen, vals


def _energy(poa, dt):          # 1 kWp, PR 1: kWh = POA x dt
    return poa * dt / 3.6e6


def _point(x=0.0, y=0.0, z=3.2):
    return pd.DataFrame({"point_id": [0], "x": [x], "y": [y], "z": [z]})


def test_parked_whole_day_open_field_equals_pvlib_poa():
    day = "2024-06-21"
    table, t, zen, vals = _clear_day_table(day, cloud=0.3)
    cfg = IrradianceCfg(diffuse_model="sky_view_factor", svf_rays=256)
    t0 = pd.Timestamp(day, tz="Europe/Luxembourg").timestamp()
    t1 = (pd.Timestamp(day, tz="Europe/Luxembourg") + pd.Timedelta("1D")).timestamp()
    # a parked morning, a layover, a parked evening: the pieces of one day
    cuts = [t0, t0 + 6 * 3600 + 17.5, t0 + 6.5 * 3600 + 3.0, t1]
    iv = pd.DataFrame({"point_id": 0, "t0_utc": cuts[:-1], "t1_utc": cuts[1:]})
    for scene in (open_scene(), Scene(box_mesh([[500, 500, 0, 510, 510, 10]]))):   # far house
        geom = point_geometry(scene, _point(), cfg)
        res = interval_integrals(iv, geom, table, scene, cfg, _energy)
        # pvlib's POA of a flat roof over the same local day, minute by minute
        poa = pvlib.irradiance.get_total_irradiance(0, 180, zen, vals["azimuth"], vals["dni"], vals["ghi"],
                                                    vals["dhi"], model="isotropic")["poa_global"].to_numpy()
        secs = ((t - pd.Timestamp(0, tz="UTC")) / pd.Timedelta(seconds=1)).to_numpy()
        inside = (secs >= t0) & (secs < t1)
        expected_wh = float(np.sum(np.nan_to_num(poa[inside])) / 60.0)
        assert res["h_total"].sum() == pytest.approx(expected_wh, rel=0.005)
        assert res["pv_kwh"].sum() == pytest.approx(expected_wh / 1000.0, rel=0.005)
        assert res["seconds"].sum() == t1 - t0
    # a split of the day never changes its sum: one interval gives the same energy
    whole = interval_integrals(pd.DataFrame({"point_id": [0], "t0_utc": [t0], "t1_utc": [t1]}),
                               geom, table, scene, cfg, _energy)
    assert whole["pv_kwh"].sum() == pytest.approx(res["pv_kwh"].sum(), rel=1e-12)


def test_layover_beside_tall_wall_analytic_shadow_and_sky_view_factor():
    """A wall east of the bus (along y, from x = D to D + 1, height H): the morning sun is
    hidden while the ray from the roof point to it passes the wall's plane x = D below its top."""
    day = "2024-06-10"
    table, *_ = _clear_day_table(day)
    D, H, z = 12.0, 20.0, 3.2
    scene = Scene(box_mesh([[D, -LONG, 0.0, D + 1.0, LONG, H]]))
    cfg = IrradianceCfg(diffuse_model="sky_view_factor", svf_rays=4096)
    geom = point_geometry(scene, _point(z=z), cfg)
    t0 = pd.Timestamp(f"{day} 03:00", tz="UTC").timestamp()
    minutes = np.arange(t0, t0 + 17 * 3600, 60.0)
    iv = pd.DataFrame({"point_id": 0, "t0_utc": minutes, "t1_utc": minutes + 60.0})
    res = interval_integrals(iv, geom, table, scene, cfg, _energy)
    rad = table.lookup(minutes + 30.0)
    sx, sy, sz = rad["sun_x"], rad["sun_y"], rad["sun_z"]
    # height of the sun ray where it crosses the wall's face (sun in the east only)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(sx > 0, D / sx, np.inf)
    height = z + cfg.ray_offset_m + s * sz
    blocked = (sx > 0) & (sz > 0) & (height < H) & (np.abs(s * sy) < LONG)
    clear_margin = np.abs(height - H) > 0.05
    direct = rad["dni"] * np.maximum(sz, 0) * ~blocked * 60.0 / 3600.0
    assert blocked.sum() > 100 and (~blocked & (sz > 0)).sum() > 0       # the day has both
    np.testing.assert_allclose(res["h_direct"].to_numpy()[clear_margin], direct[clear_margin],
                               rtol=1e-4, atol=1e-6)
    # diffuse: DHI x the analytic sky view factor of a horizontal point beside an infinite wall
    h = H - (z + cfg.ray_offset_m)
    svf = 0.5 * (1.0 + D / np.hypot(D, h))
    dhi_wh = rad["dhi"] * 60.0 / 3600.0
    assert res["h_diffuse"].sum() == pytest.approx(svf * dhi_wh.sum(), rel=0.02)


def test_layovers_apart_take_only_their_own_minutes():
    """Intervals hours apart at one point (only the minutes they cover go through the
    kernel) give each what it gives alone; pieces that touch (at a minute's end or inside
    one) add up to the whole; the minutes between take nothing."""
    day = "2024-06-10"
    table, *_ = _clear_day_table(day, cloud=0.2)
    scene = Scene(box_mesh([[12.0, -LONG, 0.0, 13.0, LONG, 20.0]]))       # a wall east
    cfg = IrradianceCfg(diffuse_model="sky_view_factor", svf_rays=256)
    geom = point_geometry(scene, _point(), cfg)
    base = pd.Timestamp(f"{day} 04:00", tz="UTC").timestamp()
    pieces = [(base + 17.5, base + 600.0), (base + 600.0, base + 905.25),      # touching
              (base + 4 * 3600 + 30.0, base + 4 * 3600 + 1230.0),              # hours later
              (base + 9 * 3600 - 12.0, base + 9 * 3600 + 48.0)]                # within a minute or two
    iv = pd.DataFrame({"point_id": 0, "t0_utc": [a for a, _ in pieces], "t1_utc": [b for _, b in pieces]})
    together = interval_integrals(iv, geom, table, scene, cfg, _energy)
    for i, (a, b) in enumerate(pieces):
        alone = interval_integrals(pd.DataFrame({"point_id": [0], "t0_utc": [a], "t1_utc": [b]}),
                                   geom, table, scene, cfg, _energy)
        for c in ("pv_kwh", "h_total", "h_direct", "h_diffuse", "seconds"):
            assert together[c].iloc[i] == pytest.approx(alone[c].iloc[0], rel=1e-12, abs=1e-15), (i, c)
    assert (together["h_total"] > 0).all()
    # an empty interval on a minute's edge takes nothing, alone (no minute to evaluate) or not
    edge = base + 2 * 3600.0
    empty = pd.DataFrame({"point_id": [0, 1, 1], "t0_utc": [edge, edge, pieces[0][0]],
                          "t1_utc": [edge, edge, pieces[0][1]]})
    res = interval_integrals(empty, pd.concat([geom, geom.assign(segment_id=1)], ignore_index=True),
                             table, scene, cfg, _energy)
    assert res["pv_kwh"].iloc[0] == 0.0 and res["pv_kwh"].iloc[1] == 0.0
    assert res["pv_kwh"].iloc[2] == pytest.approx(together["pv_kwh"].iloc[0], rel=1e-12)
    whole = interval_integrals(pd.DataFrame({"point_id": [0], "t0_utc": [pieces[0][0]],
                                             "t1_utc": [pieces[1][1]]}), geom, table, scene, cfg, _energy)
    assert together["pv_kwh"].iloc[:2].sum() == pytest.approx(whole["pv_kwh"].iloc[0], rel=1e-12)
    # the same pieces by hand, minute by minute: each minute's value times its covered share
    minutes = np.arange(base, base + 9 * 3600 + 60.0, 60.0)
    from vipvflow.models.irradiance import evaluate_passes

    irr = evaluate_passes(pd.DataFrame({"segment_id": 0, "t_utc": minutes, "dt_s": np.float32(60.0)}),
                          None, geom, table, scene, cfg, time_at="mid")["total"].to_numpy(np.float64)
    for i, (a, b) in enumerate(pieces):
        share = np.clip(np.minimum(minutes + 60.0, b) - np.maximum(minutes, a), 0.0, None)
        assert together["h_total"].iloc[i] == pytest.approx(float((irr * share).sum() / 3600.0), rel=1e-9)


def test_points_packed_once_give_what_each_point_packed_alone_gives():
    """The standing work packs a tile's points once (with their sun masks among the
    buildings) for all its points and months: the sums are those of interval_integrals
    packing for each point on its own, bit for bit, with the default physics (Perez sky,
    reflectors, sun masks) in a street between two walls."""
    from vipvflow.models.view_factors import pack_geometry

    day = "2024-06-10"
    table, *_ = _clear_day_table(day, cloud=0.3)
    scene = Scene(box_mesh([[12.0, -60.0, 0.0, 13.0, 60.0, 20.0],
                            [-14.0, -60.0, 0.0, -13.0, 60.0, 15.0]]))
    cfg = IrradianceCfg(svf_rays=128, reflection_rays=64, reflector_points=4, horizon_band_rays=16)
    points = pd.DataFrame({"point_id": [0, 1, 2], "x": [0.0, 8.0, -9.0], "y": [0.0, 20.0, -30.0],
                           "z": [3.2, 3.2, 3.2]})
    geom = point_geometry(scene, points, cfg)
    base = pd.Timestamp(f"{day} 04:00", tz="UTC").timestamp()
    iv = pd.DataFrame({"point_id": [0, 1, 2, 0, 2],
                       "t0_utc": [base + 10.0, base + 3600.0, base + 5 * 3600 + 7.0,
                                  base + 8 * 3600.0, base + 12 * 3600.0],
                       "t1_utc": [base + 1800.0, base + 3 * 3600.0, base + 6 * 3600.0,
                                  base + 8 * 3600 + 905.0, base + 15 * 3600.0]})
    packed = pack_geometry(geom, cfg, 0.2, scene)
    once = interval_integrals(iv, geom, table, scene, cfg, _energy, packed=packed)
    each = interval_integrals(iv, geom, table, scene, cfg, _energy)
    assert (once["h_direct"] > 0).any() and (once["h_reflected"] > 0).all()
    pd.testing.assert_frame_equal(once, each, check_exact=True)
    # the packing kept the points' sun masks among the buildings, made once
    assert packed["_building_masks"][0] is scene


def _gtfs(folder):
    """A small feed in Luxembourg: one line A - B - C, block B1 of three trips, the last one
    past midnight (24:10 - 24:40), every day of 2024."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "agency.txt").write_text("agency_id,agency_name,agency_url,agency_timezone\n"
                                       "a,A,http://example.org,Europe/Luxembourg\n")
    (folder / "routes.txt").write_text("route_id,agency_id,route_short_name,route_type\nR,a,1,3\n")
    (folder / "stops.txt").write_text("stop_id,stop_name,stop_lat,stop_lon\n"
                                      "A,A,49.6000,6.1000\nB,B,49.6050,6.1100\nC,C,49.6100,6.1200\n")
    (folder / "calendar.txt").write_text(
        "service_id,monday,tuesday,wednesday,thursday,friday,saturday,sunday,start_date,end_date\n"
        "S,1,1,1,1,1,1,1,20240101,20241231\n")
    (folder / "trips.txt").write_text("route_id,service_id,trip_id,direction_id,block_id\n"
                                      "R,S,t1,0,B1\nR,S,t2,1,B1\nR,S,t3,0,B1\nR,S,u1,0,B2\n")
    rows = ["trip_id,arrival_time,departure_time,stop_id,stop_sequence"]
    times = {"t1": ("06:00:00", "06:10:00", "06:20:00", "A", "B", "C"),
             "t2": ("06:30:00", "06:40:00", "06:50:00", "C", "B", "A"),
             "t3": ("24:10:00", "24:25:00", "24:40:00", "A", "B", "C"),
             "u1": ("12:00:00", "12:10:00", "12:20:00", "A", "B", "C")}
    for trip, (a, b, c, s1, s2, s3) in times.items():
        rows += [f"{trip},{a},{a},{s1},1", f"{trip},{b},{b},{s2},2", f"{trip},{c},{c},{s3},3"]
    (folder / "stop_times.txt").write_text("\n".join(rows) + "\n")
    return folder


@pytest.fixture(scope="module")
def small_feed(tmp_path_factory):
    d = tmp_path_factory.mktemp("whole_day")
    ingest_gtfs(_gtfs(d / "feed"), d, TrajectoryCfg(ground_elevation_m=GROUND_M), crs="EPSG:2169")
    return d


def test_timeline_partitions_every_block_day(small_feed):
    tl = block_timeline(small_feed, 2024, months=[3, 10])
    bd, iv = tl["block_days"], tl["intervals"]
    tz = "Europe/Luxembourg"
    # every block-day: its intervals and its trips tile its window, without overlap
    for (block, date), g in iv.groupby(["block_id", "service_date"]):
        row = bd[(bd["block_id"] == block) & (bd["service_date"] == date)].iloc[0]
        g = g.sort_values("t0_utc")
        assert (g["t1_utc"] > g["t0_utc"]).all()
        assert (g["t0_utc"].to_numpy()[1:] >= g["t1_utc"].to_numpy()[:-1]).all()
        total = (g["t1_utc"] - g["t0_utc"]).sum() + row["driving_s"]
        assert total == row["window_end_utc"] - row["window_start_utc"]
        assert row["overlap_s"] == 0
    # the driving time is the passes' time on the road (t1 06:00-06:20, t2 06:30-06:50,
    # t3 24:10-24:40)
    b1 = bd[bd["block_id"] == "B1"].set_index("service_date")
    assert (b1["driving_s"] == 3 * 20 * 60 + 10 * 60).all()
    p = passes_for_trip(small_feed, "t3", "2024-03-30")
    assert float(p["dt_s"].sum()) == pytest.approx(30 * 60)
    # one block's days follow each other without a gap or a second count: the small hours
    # after a trip past midnight belong to the day before
    for block, g in bd.groupby("block_id"):
        g = g.sort_values("service_date")
        consecutive = g["service_date"].diff().dt.days.to_numpy()[1:] == 1
        gap = g["window_start_utc"].to_numpy()[1:] - g["window_end_utc"].to_numpy()[:-1]
        assert (gap[consecutive] == 0).all()
    # daylight-saving months: B1's block-days of March hold the month's 743 h (the clocks
    # go forward) and October's 745 h, from the arrival of the trip past midnight of the
    # day before the month (24:40) to that of the month's last day; a block-day starts at
    # its GTFS day's origin or, later, at the arrival of the day before's trip past
    # midnight (on the days the clocks change the origin moves)
    for month, hours in ((3, 31 * 24 - 1), (10, 31 * 24 + 1)):
        g = b1[b1.index.month == month]
        assert (g["window_end_utc"] - g["window_start_utc"]).sum() == hours * 3600
        first = g.index[0]
        assert g["window_start_utc"].iloc[0] == service_day_origin_utc(
            pd.to_datetime([first - pd.Timedelta(days=1)]), tz)[0] + (24 * 60 + 40) * 60
        origin = service_day_origin_utc(g.index, tz)
        assert (g["window_start_utc"].to_numpy()[1:]
                == np.maximum(origin[1:], g["last_arrival_utc"].to_numpy()[:-1])).all()
        assert (g["window_start_utc"].to_numpy()[1:] > origin[1:]).sum() >= 28
        assert (g["last_arrival_utc"] == service_day_origin_utc(g.index, tz) + (24 * 60 + 40) * 60).all()
    # B1's layovers: at C after t1 (06:20 - 06:30), at A after t2 (06:50 - 24:10); parked at A
    pts = tl["points"].set_index("point_id")
    lay = iv[(iv["block_id"] == "B1") & (iv["kind"] == "layover")]
    for after, stop, seconds in ((0, "C", 600.0), (1, "A", (24 * 60 + 10 - 6 * 60 - 50) * 60.0)):
        one = lay[lay["after_trip"] == after]
        assert set(pts.loc[one["point_id"], "stop_id"]) == {stop}
        assert ((one["t1_utc"] - one["t0_utc"]) == seconds).all()
    parked = iv[(iv["block_id"] == "B1") & (iv["kind"] == "parked")]
    assert set(pts.loc[parked["point_id"], "stop_id"]) == {"A"}
    # a run of some months cuts their days as a run of the whole year does
    year = block_timeline(small_feed, 2024)["block_days"]
    year = year[year["service_date"].dt.month.isin([3, 10])].reset_index(drop=True)
    pd.testing.assert_frame_equal(bd.reset_index(drop=True), year)
    # the ids are strings (held as categories inside), each table in the order of its strings
    for name, keys in (("block_days", ["block_id", "service_date"]),
                       ("intervals", ["block_id", "service_date", "t0_utc"]),
                       ("trip_runs", ["block_id", "service_date", "position"])):
        t = tl[name]
        for c in ("block_id", "trip_id"):
            if c in t:
                assert pd.api.types.is_string_dtype(t[c].dtype), (name, c, t[c].dtype)
                assert not isinstance(t[c].dtype, pd.CategoricalDtype), (name, c)
        pd.testing.assert_frame_equal(t.reset_index(drop=True),
                                      t.sort_values(keys, kind="stable").reset_index(drop=True))


def test_small_run_splits_every_block_day(small_run, small_config):
    import json

    from vipvflow.config import load_config

    cfg = load_config(small_config)
    bd = pd.read_parquet(small_run / "block_day.parquet")
    s = json.loads((small_run / "summary.json").read_text())
    # driving + layover + parked = the block-day's window, in time and in energy
    assert (bd["seconds_driving"] + bd["seconds_layover"] + bd["seconds_parked"] == bd["window_s"]).all()
    assert (bd["pv_kwh_driving"] + bd["pv_kwh_layover"] + bd["pv_kwh_parked"] == bd["pv_kwh_whole_day"]).all()
    np.testing.assert_allclose(bd["pv_kwh_usable"] + bd["pv_kwh_curtailed"], bd["pv_kwh_whole_day"],
                               rtol=1e-12)
    assert (bd["pv_kwh_layover"] > 0).all() and (bd["seconds_layover"] > 0).all()
    # the driving time is the trips' time on the segments (their passes)
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    # (each pass keeps its time in float32)
    np.testing.assert_allclose(bd["seconds_driving"].sum(), trips["seconds"].sum(), rtol=1e-7)
    # the layovers' auxiliaries: base load and HVAC at June's mean temperature, per hour stood
    v = cfg.vehicle_params()
    aux_kw = float(v.aux_kw(cfg.monthly_temperature_c()[5]))
    np.testing.assert_allclose(bd["layover_aux_kwh"], aux_kw * bd["seconds_layover"] / 3600.0
                               / v.discharge_efficiency, rtol=1e-9)
    assert bd["demand_kwh"].sum() == pytest.approx(bd["consumption_kwh"].sum() + bd["layover_aux_kwh"].sum())
    # the fleet: both yields, the whole day includes the idle buses parked at the depot
    assert s["harvest"] == "whole_day"
    assert s["kwh_per_kwp_driving"] < s["kwh_per_kwp_in_service"] < s["kwh_per_kwp_whole_day"]
    parts = s["pv_kwh_driving"] + s["pv_kwh_layover"] + s["pv_kwh_parked"]
    assert s["pv_kwh_whole_day"] == pytest.approx(parts)
    assert s["pv_kwh_usable"] + s["pv_kwh_curtailed"] == pytest.approx(s["pv_kwh_whole_day"])
    assert s["pv_kwh_usable"] == pytest.approx(bd["pv_kwh_usable"].sum())
    days = bd.groupby(pd.to_datetime(bd["service_date"])).size()      # dates (date32) as days
    assert s["idle_bus_days"] == int((s["buses"] - days.reindex(pd.date_range("2024-06-01", "2024-06-30"),
                                                                   fill_value=0)).sum())
    # one month run: the annual figures are the month's x 12, coverage on what the battery takes
    assert s["coverage"] == pytest.approx(s["pv_kwh_usable"] * 12 / (s["fleet_demand_in_service_mwh"] * 1000.0))
    monthly = pd.read_parquet(small_run / "monthly.parquet")
    assert monthly["pv_kwh_whole_day"].sum() == pytest.approx(s["pv_kwh_whole_day"])


def test_depot_options_are_checked(tmp_path):
    from vipvflow.config import load_config
    from vipvflow.errors import ConfigError

    bad = tmp_path / "bad.yaml"
    bad.write_text("fleet:\n  depot_shading: garage\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: key 'fleet.depot_shading'"):
        load_config(bad)
    bad.write_text("fleet:\n  depot: {lat: 95.0, lon: 6.1}\n")
    with pytest.raises(ConfigError, match=r"key 'fleet.depot.lat'"):
        load_config(bad)


def test_paper_scenario_is_the_papers_accounting():
    from pathlib import Path

    from vipvflow.config import load_config

    cfg = load_config("paper")
    assert (cfg.fleet.harvest, cfg.irradiance.diffuse_model, cfg.pv.mode) == ("driving", "isotropic", "paper")


def test_driving_only_run_keeps_the_papers_figures(small_run, small_config, tmp_path):
    import json

    from vipvflow.config import load_config
    from vipvflow.simulation import run_simulation

    cfg = load_config(small_config, overrides={"out_dir": str(tmp_path), "fleet": {"harvest": "driving"},
                                               "dask": {"n_workers": 1}})
    run = run_simulation(cfg, 2024, say=lambda *a: None)
    s = json.loads((run / "summary.json").read_text())
    full = json.loads((small_run / "summary.json").read_text())
    assert not (run / "parts" / "standing").exists()
    assert s["kwh_per_kwp_in_service"] is None and s["kwh_per_kwp_whole_day"] is None
    assert s["pv_kwh_layover"] is None and s["pv_kwh_parked"] is None
    assert s["kwh_per_kwp_driving"] == pytest.approx(full["kwh_per_kwp_driving"], rel=1e-12)
    # the driving PV is what is harvested; a full battery curtails (almost) none of it
    assert s["pv_kwh_harvested"] == pytest.approx(s["pv_kwh_driving"])
    assert s["pv_kwh_usable"] + s["pv_kwh_curtailed"] == pytest.approx(s["pv_kwh_driving"])
    # the paper's coverage: the driving PV against the trips' demand alone
    trips = pd.read_parquet(run / "trip_energy.parquet")
    assert s["coverage_driving"] == pytest.approx(trips["pv_kwh"].sum() / trips["consumption_kwh"].sum())


def test_depot_outside_the_city_model_stands_in_the_open(small_run, small_config):
    """A depot where the city model has no building within its buffer (no mesh for its
    tile) stands in the open with depot_shading: city, as with open: its roof sees the
    whole sky (sky view factor 1, nothing to reflect), never a missing mesh."""
    from vipvflow.config import load_config
    from vipvflow.models.shading import get_scene, modelled_tiles
    from vipvflow.simulation.standing import depot_point

    far = {"fleet": {"depot": {"lat": 49.9, "lon": 5.8}}}
    cfg = load_config(small_config, overrides=far)
    x, y, z, tile = depot_point(cfg, cfg.data_dir)
    assert 40000 < x < 110000 and 50000 < y < 140000 and z > 0      # LUREF, Luxembourg
    assert tile not in modelled_tiles(cfg.data_dir)
    scene = get_scene(cfg.data_dir, tile)
    assert scene.n_triangles == 0
    geom = point_geometry(scene, pd.DataFrame({"point_id": [0], "x": [x], "y": [y], "z": [z]}),
                          cfg.irradiance)
    assert geom["svf"].iloc[0] == pytest.approx(1.0) and geom["refl_vf"].iloc[0] == 0.0


def test_timeline_of_a_real_feed_without_blocks(shared_data, tmp_path):
    """Cairns (gtfs-kit's sample feed, no block_id: blocks inferred): every block-day of 2014
    is cut into driving, layover and parked time that add up to its window exactly."""
    ingest_gtfs(shared_data / "gtfs" / "cairns_gtfs_kit" / "cairns_gtfs.zip", tmp_path, TrajectoryCfg(ground_elevation_m=GROUND_M))
    tl = block_timeline(tmp_path, 2014)
    bd, iv = tl["block_days"], tl["intervals"]
    assert bd["trips"].sum() == len(tl["trip_runs"]) and (bd["overlap_s"] == 0).all()
    window = bd["window_end_utc"] - bd["window_start_utc"]
    assert (window == bd["driving_s"] + bd["layover_s"] + bd["parked_s"]).all()
    own = iv[iv["block_id"] != "(idle)"]
    assert (own["t1_utc"] - own["t0_utc"]).sum() == (bd["layover_s"] + bd["parked_s"]).sum()
    # a block's consecutive days meet without a gap or an overlap
    for _, g in bd.groupby("block_id"):
        nxt = g["service_date"].diff().dt.days.to_numpy()[1:] == 1
        assert (g["window_start_utc"].to_numpy()[1:][nxt] == g["window_end_utc"].to_numpy()[:-1][nxt]).all()


def test_open_depot_run_parks_under_the_open_sky(small_run, small_config, tmp_path):
    """A configured depot in the open: every parked interval of the run holds the flat roof's
    open-sky irradiation, DNI cos(zenith) + DHI, of the radiation table minute by minute."""
    from vipvflow.config import load_config
    from vipvflow.models.sun_sky import RadiationTable
    from vipvflow.simulation import run_simulation

    cfg = load_config(small_config, overrides={
        "out_dir": str(tmp_path), "dask": {"n_workers": 1},
        "fleet": {"depot": {"lat": 49.61, "lon": 6.13}, "depot_shading": "open"}})
    run = run_simulation(cfg, 2024, say=lambda *a: None)
    st = pd.read_parquet(run / "parts" / "standing" / "tile=open" / "month=all.parquet")
    assert set(st["kind"]) == {"parked"} and (st["block_id"] == "(idle)").any()
    table = RadiationTable.load(cfg.data_dir, 2024)
    sample = st.sort_values("pv_kwh").iloc[-40:]          # the sunniest intervals
    expected = []
    for t0, t1, buses in sample[["t0_utc", "t1_utc", "buses"]].to_numpy():
        edges = np.arange(np.floor(t0 / 60) * 60, t1 + 60, 60.0)
        rad = table.lookup(edges[:-1] + 30.0, angles=False)
        e = np.nan_to_num(rad["dni"] * np.maximum(rad["sun_z"], 0) + rad["dhi"]).astype(float)
        seconds = np.clip(np.minimum(edges[1:], t1) - np.maximum(edges[:-1], t0), 0, None)
        expected.append(buses * float(np.sum(e * seconds)) / 3600.0)
    np.testing.assert_allclose(sample["h_total"], expected, rtol=1e-5)
    system = cfg.pv_system()
    np.testing.assert_allclose(sample["pv_kwh"], system.kwp * system.performance_ratio
                               * np.asarray(expected) / 1000.0, rtol=1e-5)
    bd = pd.read_parquet(run / "block_day.parquet")
    assert (bd["seconds_driving"] + bd["seconds_layover"] + bd["seconds_parked"] == bd["window_s"]).all()


@pytest.mark.parametrize("harvest, kinds", [("driving", set()), ("in_service", {"layover"}),
                                            ("whole_day", {"layover", "parked"})])
def test_harvest_chooses_the_standing_work(small_run, small_config, tmp_path, harvest, kinds):
    from vipvflow.config import load_config
    from vipvflow.simulation.standing import timeline_dir, write_timeline

    cfg = load_config(small_config, overrides={"fleet": {"harvest": harvest}})
    tiles = write_timeline(cfg, 2024, tmp_path)
    iv = pd.read_parquet(timeline_dir(tmp_path) / "intervals.parquet")
    # every interval is in the timeline (the battery's balance needs them); the light is
    # evaluated for those fleet.harvest counts
    assert set(iv["kind"]) == {"layover", "parked"}
    assert set(iv.loc[iv["harvested"], "kind"]) == kinds and (len(tiles) > 0) == bool(kinds)
    assert (iv["month"] == "2024-06").all()
    # the block-days' time is cut the same whatever is evaluated
    bd = pd.read_parquet(timeline_dir(tmp_path) / "block_days.parquet")
    assert (bd["window_end_utc"] - bd["window_start_utc"]
            == bd["driving_s"] + bd["layover_s"] + bd["parked_s"]).all()


def test_a_large_timeline_is_cut_in_a_process_of_its_own(small_run, small_config, tmp_path, monkeypatch):
    """Above TIMELINE_PROCESS_TRIP_DAYS the timeline is written by a spawned child (its
    memory leaves with it): the same tables and tiles as in the command's own process, and
    an error in the child is the command's error, message and type."""
    import multiprocessing
    import shutil
    from pathlib import Path

    from vipvflow.config import load_config
    from vipvflow.simulation import standing

    cfg = load_config(small_config)
    here = standing.write_timeline(cfg, 2024, tmp_path / "here")
    contexts = []
    get_context = multiprocessing.get_context

    def recording(method=None):
        contexts.append(method)
        return get_context(method)

    monkeypatch.setattr(multiprocessing, "get_context", recording)
    monkeypatch.setattr(standing, "TIMELINE_PROCESS_TRIP_DAYS", 0)
    there = standing.write_timeline(cfg, 2024, tmp_path / "child")
    assert contexts == ["spawn"]
    assert here == there and here
    for name in ("block_days", "intervals", "points", "trip_runs"):
        pd.testing.assert_frame_equal(pd.read_parquet(standing.timeline_dir(tmp_path / "here") / f"{name}.parquet"),
                                      pd.read_parquet(standing.timeline_dir(tmp_path / "child") / f"{name}.parquet"))
    # a data dir whose feed lacks its pattern stops: the child's error, raised here
    broken = tmp_path / "data" / "gtfs"
    broken.mkdir(parents=True)
    shutil.copy(Path(cfg.data_dir) / "gtfs" / "trips.parquet", broken / "trips.parquet")
    bad = load_config(small_config, overrides={"data_dir": str(tmp_path / "data")})
    with pytest.raises(FileNotFoundError, match="pattern_stops"):
        standing.write_timeline(bad, 2024, tmp_path / "bad")


def test_a_tiles_intervals_read_in_batches_are_those_of_the_whole_table(small_run, monkeypatch):
    """The intervals at some points, read a few rows at a time (a standing task's), are the
    harvested intervals of the whole table at those points, in order and renumbered."""
    from vipvflow.simulation import standing
    from vipvflow.store import RunDir

    run = RunDir(small_run)
    whole = standing.harvested_intervals(run)
    points = np.unique(whole["point_id"].to_numpy())[::2]
    expect = whole[whole["point_id"].isin(points)].reset_index(drop=True)
    assert 0 < len(expect) < len(whole)
    monkeypatch.setattr(standing, "INTERVAL_BATCH", 7)
    got = standing.harvested_intervals(run, points=points)
    pd.testing.assert_frame_equal(got, expect, check_exact=True)
    some = standing.harvested_intervals(run, columns=["t0_utc", "t1_utc"], points=points)
    pd.testing.assert_frame_equal(some, expect[["t0_utc", "t1_utc"]], check_exact=True)
