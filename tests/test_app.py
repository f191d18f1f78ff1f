"""The web app: horizon profiles, the trip model against pvlib and the ray-cast run, and the
Bokeh app driven in a real headless Chromium."""
from __future__ import annotations

import json

import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from vipvflow.models.horizon import horizon_at, horizon_profile
from vipvflow.models.shading import Scene, box_mesh

X0, Y0 = 77_000.0, 75_000.0        # LUREF-like coordinates: float32 precision must hold
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
ROOT = Path(__file__).resolve().parents[1]


# ----------------------------------------------------------------------------- horizon
@pytest.mark.parametrize("H,D", [(15.0, 8.0), (30.0, 5.0), (6.0, 20.0)])
def test_horizon_of_long_wall_is_atan_height_over_distance(H, D):
    """A wall of height H (above the roof point) at distance D east: horizon atan(H / D)
    facing it, atan(H sin(a) / D) at azimuth a, 0 away from it."""
    zr, long = 3.2, 5000.0
    scene = Scene(box_mesh([[X0 + D, Y0 - long, 0.0, X0 + D + 1.0, Y0 + long, zr + H]]))
    tol = 0.25
    prof = horizon_profile(scene, [[X0, Y0, zr]], n_azimuth=72, tol_deg=tol)
    assert prof.shape == (1, 72) and prof.dtype == np.float32
    az = np.arange(72) * 5.0
    expect = np.degrees(np.arctan(H * np.clip(np.sin(np.radians(az)), 0, None) / D))
    assert abs(prof[0, 18] - np.degrees(np.arctan(H / D))) <= tol           # due east
    np.testing.assert_allclose(prof[0], expect, atol=tol)
    assert (prof[0, 37:72] == 0).all()                                      # west: open
    # interpolation between bins
    assert abs(horizon_at(prof, [92.5])[0] - np.degrees(np.arctan(H / D))) < 0.5


# ----------------------------------------------------------------------------- model
@pytest.fixture(scope="module")
def trip_model(small_run):
    from vipvflow.app.model import TripModel

    return TripModel(small_run)


def _midday_trip(model):
    r = model.routes().iloc[0]
    date = pd.Timestamp("2024-06-12")
    return model.trip(r.route_id, int(r.direction_id), date, "12:00"), date


def test_unshaded_total_equals_pvlib_isotropic_poa(trip_model):
    import pvlib

    res, _ = _midday_trip(trip_model)
    s = res.segments
    t_mid = pd.to_datetime(s["t_utc"] + 0.5 * s["dt_s"], unit="s", utc=True)
    rad = trip_model.radiation.lookup(s["t_utc"].to_numpy() + 0.5 * s["dt_s"].to_numpy(), angles=False)
    sp = pvlib.solarposition.get_solarposition(t_mid, trip_model.radiation.lat[0],
                                               trip_model.radiation.lon[0])
    geo = trip_model.geometry.set_index("segment_id").loc[s["segment_id"]]
    poa = pvlib.irradiance.get_total_irradiance(
        geo["tilt_deg"].to_numpy(float), geo["azimuth_deg"].to_numpy(float),
        sp["apparent_zenith"].to_numpy(), sp["azimuth"].to_numpy(),
        rad["dni"].astype(float), rad["ghi"].astype(float), rad["dhi"].astype(float),
        albedo=0.0, model="isotropic")["poa_global"]
    poa = np.asarray(poa, float)
    dt = s["dt_s"].to_numpy()
    assert (poa > 100).all()
    ours, ref = float((s["unshaded"] * dt).sum()), float((poa * dt).sum())
    assert abs(ours / ref - 1) < 0.005
    np.testing.assert_allclose(s["unshaded"], poa, rtol=0.01)


def test_trip_model_components_equal_the_runs(trip_model, small_run):
    """One physics: for one trip the app's direct and diffuse equal the run's
    ``trip_energy`` (same sky view factor, radiation and PV dispatcher; the horizon profile
    decides the sun's visibility where it can, the run's own ray where it cannot), and its
    reflected (every sample point traced) equals the run's (one point per reflector and pass,
    in turn) within three of the stated standard errors."""
    res, date = _midday_trip(trip_model)
    te = pd.read_parquet(Path(small_run) / "trip_energy.parquet")
    ref = te[(te["trip_id"] == res.trip_id) & (pd.to_datetime(te["service_date"]) == date)].iloc[0]
    n = res.numbers
    assert trip_model.cfg.irradiance.diffuse_model == "perez_svf"       # the default
    assert n["pv_kwh_diffuse"] == pytest.approx(ref["pv_kwh_diffuse"], rel=1e-5)
    assert n["pv_kwh_direct"] == pytest.approx(ref["pv_kwh_direct"], rel=1e-5)
    se = n["pv_kwh_reflected_se"]
    assert 0 < se < 0.2 * n["pv_kwh_reflected"]
    assert abs(n["pv_kwh_reflected"] - ref["pv_kwh_reflected"]) <= 3 * se
    assert n["shading_loss"] == pytest.approx(
        1 - (ref["pv_kwh_direct"] + ref["pv_kwh_diffuse"]) / ref["pv_kwh_unshaded"], abs=0.01)


def test_trip_model_agrees_with_ray_cast_run(trip_model, small_run):
    """The same scheduled trip, recomputed from horizons (rays where they cannot tell), against the
    simulation's result: unshaded energy equal, sun visibility from horizons equal to
    Embree's (but at the sampled azimuths' interpolation), total PV close."""
    from vipvflow.models.shading import get_scene

    res, date = _midday_trip(trip_model)
    te = pd.read_parquet(Path(small_run) / "trip_energy.parquet")
    ref = te[(te["trip_id"] == res.trip_id) & (pd.to_datetime(te["service_date"]) == date)]
    assert len(ref) == 1
    ref = ref.iloc[0]
    n = res.numbers
    assert n["pv_kwh_unshaded"] == pytest.approx(ref["pv_kwh_unshaded"], rel=0.005)
    assert n["pv_kwh"] == pytest.approx(ref["pv_kwh"], rel=0.03)
    assert n["consumption_kwh"] == pytest.approx(ref["consumption_kwh"], rel=1e-6)

    # sun visibility: horizon test vs. one occlusion ray per pass
    s = res.segments
    geo = trip_model.geometry.set_index("segment_id").loc[s["segment_id"]]
    t = s["t_utc"].to_numpy() + 0.5 * s["dt_s"].to_numpy()
    rad = trip_model.radiation.lookup(t)
    sun = np.stack([rad["sun_x"], rad["sun_y"], rad["sun_z"]], 1)
    ray_visible = np.zeros(len(s), bool)
    for tile, idx in geo.reset_index().groupby("tile").indices.items():
        scene = get_scene(trip_model.data_dir, tile)
        ray_visible[idx] = ~scene.occluded(geo[["px", "py", "pz"]].to_numpy()[idx], sun[idx],
                                           trip_model.cfg.irradiance.ray_length_m)
    agree = (ray_visible == s["sun_visible"].to_numpy()).mean()
    assert agree > 0.98


def test_departure_rule_and_pv_scaling(trip_model):
    from vipvflow.app.model import PVChoice

    r = trip_model.routes().iloc[0]
    deps = trip_model.departures(r.route_id, int(r.direction_id), "2024-06-12")
    first = deps.iloc[3]
    want = first["start_s"] / 60.0 - 1.0          # a minute before the 4th departure
    res = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", want)
    assert res.trip_id == first["trip_id"]
    base = PVChoice(kwp=3.5, performance_ratio=0.75)
    a = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", "11:00", pv=base)
    b = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", "11:00",
                        pv=PVChoice(kwp=7.0, performance_ratio=0.75))
    assert b.numbers["pv_kwh"] == pytest.approx(2 * a.numbers["pv_kwh"], rel=1e-9)
    # 5 kW more auxiliary load costs 5 kW x duration at the battery, through its discharge
    # efficiency, or through the charge efficiency while it replaces recuperated power
    c = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", "11:00", aux_kw=12.0)
    d = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", "11:00", aux_kw=7.0)
    veh = trip_model.vehicle
    extra = 5.0 * c.numbers["duration_min"] / 60.0
    diff = c.numbers["consumption_kwh"] - d.numbers["consumption_kwh"]
    assert extra * veh.charge_efficiency - 1e-9 <= diff <= extra / veh.discharge_efficiency + 1e-9
    # pvlib mode gives a plausible fraction of paper mode at the same POA
    p = trip_model.trip(r.route_id, int(r.direction_id), "2024-06-12", "11:00",
                        pv=PVChoice(technology="CdTe", mode="pvlib", kwp=3.5))
    assert 0.5 < p.numbers["pv_kwh"] / a.numbers["pv_kwh"] < 1.3
    # SoC: without PV it falls by consumption / capacity
    cyc = a.cycle
    assert cyc["soc"].iloc[0] - cyc["soc"].iloc[-1] == pytest.approx(
        a.numbers["consumption_kwh"] / trip_model.vehicle.battery_kwh, rel=1e-9)
    assert (cyc["soc_pv"] >= cyc["soc"] - 1e-12).all()
    mon = trip_model.monthly(r.route_id, int(r.direction_id), PVChoice(kwp=7.0, performance_ratio=0.75))
    mon1 = trip_model.monthly(r.route_id, int(r.direction_id), PVChoice(kwp=3.5, performance_ratio=0.75))
    np.testing.assert_allclose(mon["allsky"], 2 * mon1["allsky"])


def test_app_opens_on_a_clear_summer_noon_of_the_busiest_route(trip_model):
    """Not 1 January at 08:00: the busiest route-direction, the clearest service day of the
    run's summer months by GHI / clear-sky GHI, departing at noon."""
    from vipvflow.app.layout import default_view

    start = default_view(trip_model)
    routes = trip_model.routes()
    busiest = routes[routes["trips"] == routes["trips"].max()]
    assert (start["route_id"], start["direction_id"]) in set(
        zip(busiest["route_id"], busiest["direction_id"].astype(int)))
    assert start["depart"] == 12 * 60
    date = pd.Timestamp(start["date"])
    assert date.month == 6                                      # the run's only month
    # clearness of every June day from the radiation table, computed here per day
    rad = trip_model.radiation
    t = pd.to_datetime(rad.t0 + rad.step_s * np.arange(rad.data["ghi"].shape[1]), unit="s", utc=True)
    local = t.tz_convert(trip_model.timezone).tz_localize(None)
    ratio = {}
    for day in pd.date_range(f"{trip_model.year}-06-01", f"{trip_model.year}-06-30"):
        m = (local >= day) & (local < day + pd.Timedelta(days=1))
        if len(trip_model.departures(start["route_id"], start["direction_id"], day)):
            ratio[day] = rad.data["ghi"][0, m].sum() / rad.data["ghi_clear"][0, m].sum()
    assert ratio[date] == pytest.approx(max(ratio.values()), rel=1e-6)
    res = trip_model.trip(start["route_id"], start["direction_id"], start["date"], start["depart"])
    assert res.numbers["pv_kwh"] > 0 and res.departure.hour in (12, 13)


# ----------------------------------------------------------------------------- browser
def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def app_url(small_run, tmp_path_factory):
    """``vipvflow app RUN --port P`` in a subprocess, until the module's tests are done."""
    port = _free_port()
    log = tmp_path_factory.mktemp("app") / "app.log"
    with open(log, "w") as fh:
        proc = subprocess.Popen([sys.executable, "-m", "vipvflow.cli", "app", str(small_run),
                                 "--port", str(port), "--host", "127.0.0.1"],
                                stdout=fh, stderr=subprocess.STDOUT, cwd=ROOT)
    url = f"http://127.0.0.1:{port}/"
    try:
        deadline = time.time() + 120
        while True:
            if proc.poll() is not None:
                pytest.fail(f"app exited with {proc.returncode}:\n{log.read_text()}")
            try:
                with urllib.request.urlopen(url, timeout=5) as r:
                    if r.status == 200:
                        break
            except OSError:
                pass
            if time.time() > deadline:
                pytest.fail(f"app did not answer on {url}:\n{log.read_text()}")
            time.sleep(0.5)
        yield url
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
    assert "Traceback" not in log.read_text(), log.read_text()


def _displayed(page) -> dict:
    box = page.locator("#trip-numbers")
    out = {k: box.get_attribute(f"data-{k}") for k in ("route", "direction", "date", "requested", "trip")}
    out["pv_kwh"] = page.locator("#pv-kwh").inner_text()
    out["consumption_kwh"] = page.locator("#consumption-kwh").inner_text()
    out["share"] = page.locator("#pv-share").inner_text()
    return out


def _expected(model, shown) -> dict:
    from vipvflow.app.layout import DECIMALS

    hh, mm = shown["requested"].split(":")
    res = model.trip(shown["route"], int(shown["direction"]), shown["date"], int(hh) * 60 + int(mm))
    n = res.numbers
    return {"trip": res.trip_id, "pv_kwh": f"{n['pv_kwh']:.{DECIMALS['pv_kwh']}f}",
            "consumption_kwh": f"{n['consumption_kwh']:.{DECIMALS['consumption_kwh']}f}",
            "share": f"{100 * n['share']:.{DECIMALS['share_percent']}f}"}


def test_app_in_browser(chromium, app_url, trip_model, tmp_path):
    playwright = pytest.importorskip("playwright.sync_api")
    from playwright.sync_api import expect

    from vipvflow.app.layout import default_view

    errors, requests = [], []
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(chromium), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1500, "height": 1250})
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.on("request", lambda r: requests.append(r.url))
            page.goto(app_url)
            page.wait_for_selector("#pv-kwh", timeout=60_000)
            first = _displayed(page)
            # opens on the busiest route, the clearest simulated summer day, at noon
            start = default_view(trip_model)
            assert (first["route"], int(first["direction"]), first["date"], first["requested"]) == \
                (start["route_id"], start["direction_id"], start["date"], "12:00")
            assert float(first["pv_kwh"]) > 0
            # the run's three fleet yields in the header, as summary.json has them
            sm = json.loads((Path(trip_model.run_dir) / "summary.json").read_text())
            yields = page.locator(".run-yields").inner_text()
            for label, key in (("driving", "kwh_per_kwp_driving"), ("in service", "kwh_per_kwp_in_service"),
                               ("whole day", "kwh_per_kwp_whole_day")):
                assert f"{label} {sm[key]:,.0f}" in yields, yields
            exp = _expected(trip_model, first)
            assert {k: first[k] for k in exp} == exp

            # departure slider: 48 steps of 5 min with the keyboard -> 16:00
            handle = page.locator(".depart-slider .noUi-handle")
            handle.focus()
            for _ in range(48):
                page.keyboard.press("ArrowRight")
            numbers = page.locator("#trip-numbers")
            expect(numbers).to_have_attribute("data-requested", "16:00", timeout=30_000)
            page.wait_for_timeout(500)
            later = _displayed(page)
            assert later["pv_kwh"] != first["pv_kwh"]
            exp = _expected(trip_model, later)
            assert {k: later[k] for k in exp} == exp

            # route and direction: the other direction of the line
            select = page.locator(".route-select select")
            routes = trip_model.routes()
            assert (routes.iloc[0]["route_id"], int(routes.iloc[0]["direction_id"])) == \
                (start["route_id"], start["direction_id"])       # both directions: as many trips
            select.select_option(index=1)
            expect(numbers).to_have_attribute("data-direction", str(int(routes.iloc[1]["direction_id"])),
                                              timeout=30_000)
            expect(numbers).to_have_attribute("data-route", str(routes.iloc[1]["route_id"]))
            page.wait_for_timeout(500)
            back = _displayed(page)
            # the small demo's line is open and runs both ways at the same times: its PV is
            # the same to 1e-4 kWh, its consumption is not (one direction climbs)
            assert (back["pv_kwh"], back["consumption_kwh"]) != (later["pv_kwh"], later["consumption_kwh"])
            exp = _expected(trip_model, back)
            assert {k: back[k] for k in exp} == exp

            shot = tmp_path / "app.png"
            page.screenshot(path=str(shot), full_page=True)
        finally:
            browser.close()
    assert not errors, errors
    host = app_url.rstrip("/")
    outside = [u for u in requests if not (u.startswith(host + "/") or u.startswith("ws://127.0.0.1"))]
    assert not outside, outside
    assert shot.stat().st_size > 10_000
