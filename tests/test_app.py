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


@pytest.mark.parametrize("mode", ["paper", "pvlib"])
def test_trip_shading_loss_is_the_runs_definition_in_both_pv_models(trip_model, small_run, mode):
    """The app's shading loss of a trip is the run's: 1 - (direct + diffuse) / unshaded light
    on the roof (models.loss.shading_loss on irradiation), whatever the PV model; the
    run (paper mode, linear) gives the same from its trip's energies."""
    from vipvflow.app.model import PVChoice
    from vipvflow.models.loss import shading_loss

    res, date = _midday_trip(trip_model)
    r = trip_model.routes().iloc[0]
    got = trip_model.trip(r.route_id, int(r.direction_id), date, "12:00",
                          pv=PVChoice(technology="c-Si", mode=mode, kwp=3.5)).numbers
    s = res.segments
    light = {c: float((s[c] * s["dt_s"]).sum()) / 3600.0 for c in ("direct", "diffuse", "unshaded")}
    expected = float(shading_loss(light["direct"], light["diffuse"], light["unshaded"]))
    assert got["shading_loss"] == pytest.approx(expected, rel=1e-9)
    assert got["h_unshaded"] == pytest.approx(light["unshaded"], rel=1e-9)
    assert 0.01 < expected < 0.9
    te = pd.read_parquet(Path(small_run) / "trip_energy.parquet")
    ref = te[(te["trip_id"] == res.trip_id) & (pd.to_datetime(te["service_date"]) == date)].iloc[0]
    assert trip_model.cfg.pv.mode == "paper"
    run = float(shading_loss(ref["pv_kwh_direct"], ref["pv_kwh_diffuse"], ref["pv_kwh_unshaded"]))
    assert got["shading_loss"] == pytest.approx(run, abs=0.01)


def test_a_trip_in_the_dark_says_the_sun_is_below_the_horizon(trip_model):
    """A December trip at 06:00 in Luxembourg (sunrise after 08:00): no light, no 'nan'."""
    from vipvflow.app.layout import numbers_html

    r = trip_model.routes().iloc[0]
    res = trip_model.trip(r.route_id, int(r.direction_id), "2024-12-16", "06:00")
    n = res.numbers
    assert res.departure.hour < 8 and not n["sun_up"] and n["h_unshaded"] == 0 and n["pv_kwh"] == 0
    text = numbers_html(res)
    assert "sun below the horizon" in text and "nan" not in text.lower()


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


#: the app's controls (their css classes) and figures (their names)
CONTROLS = ["pv-tech", "pv-mode", "pv-kwp", "pv-area", "pv-pr", "pv-losses", "route-select",
            "date-picker", "depart-slider", "aux-kw", "soc-min", "controls-toggle"]
FIGURES = ["irradiance", "route-map", "driving-cycle", "soc", "monthly"]

#: page boxes of every figure's canvas and frame, and of the legends and colour bars in it
_BOXES_JS = """() => {
  const doc = Bokeh.documents[0];
  const out = {};
  for (const name of %s) {
    const fig = doc.get_model_by_name(name);
    const view = Bokeh.index.find_one(fig);
    const c = view.canvas_view.el.getBoundingClientRect();
    const f = view.frame.bbox;
    const legends = [];
    for (const m of [...fig.center, ...fig.below, ...fig.above, ...fig.right, ...fig.left]) {
      if (m.type != "Legend" && m.type != "ColorBar") continue;
      const b = Bokeh.index.find_one(m).bbox;
      legends.push({type: m.type, left: c.left + b.left, right: c.left + b.right,
                    top: c.top + b.top, bottom: c.top + b.bottom});
    }
    out[name] = {canvas: {left: c.left, right: c.right, top: c.top, bottom: c.bottom},
                 frame: {left: c.left + f.left, right: c.left + f.right, top: c.top + f.top,
                         bottom: c.top + f.bottom}, legends};
  }
  return out;
}""" % json.dumps(FIGURES)

#: what the page shows of the trip: the settings of the numbers, the first time of the
#: irradiance and the driving cycle (ms, Bokeh's datetime axis), the slider's value
_SHOWN_JS = """() => {
  const doc = Bokeh.documents[0];
  const text = doc.get_model_by_name("numbers").text;
  const attr = (k) => { const m = text.match(new RegExp('data-' + k + '="([^"]*)"')); return m ? m[1] : null; };
  const seg = doc.get_model_by_name("trip-segments").data.time;
  const cyc = doc.get_model_by_name("trip-cycle").data.time;
  return {slider: doc.get_model_by_name("depart").value, requested: attr("requested"),
          departure: attr("departure"), t0: Number(attr("t0")),
          irradiance_t0: seg.length ? Number(seg[0]) : null, cycle_t0: cyc.length ? Number(cyc[0]) : null};
}"""


def _hhmm(minutes: int) -> str:
    return f"{minutes // 60:02d}:{minutes % 60:02d}"


def _inside(box, left, right, what, slack=0.5):
    assert box["left"] >= left - slack and box["right"] <= right + slack, (what, box, left, right)


def test_app_fits_400_1280_and_1920_px(chromium, app_url, artifacts):
    """At a phone's 400 px, a laptop's 1,280 and a monitor's 1,920: nothing wider than the
    window, every control and every figure inside it, every legend and colour bar inside
    its figure (legends inside the plotting frame); the controls fold away and come back."""
    playwright = pytest.importorskip("playwright.sync_api")
    errors = []
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(chromium), args=CHROMIUM_ARGS)
        try:
            for width in (400, 1280, 1920):
                page = browser.new_page(viewport={"width": width, "height": 900})
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto(app_url)
                page.wait_for_selector("#pv-kwh", timeout=60_000)
                page.wait_for_timeout(500)
                scroll, inner = page.evaluate("() => [document.documentElement.scrollWidth, window.innerWidth]")
                assert scroll <= inner == width, (width, scroll, inner)
                for name in CONTROLS:
                    box = page.locator(f".{name}").bounding_box()
                    assert box is not None and box["width"] > 50, (width, name, box)
                    _inside({"left": box["x"], "right": box["x"] + box["width"]}, 0, width, (width, name))
                boxes = page.evaluate(_BOXES_JS)
                for name, b in boxes.items():
                    _inside(b["canvas"], 0, width, (width, name))
                    for lg in b["legends"]:
                        _inside(lg, b["canvas"]["left"], b["canvas"]["right"], (width, name, lg["type"]))
                        assert b["canvas"]["top"] - 0.5 <= lg["top"] and lg["bottom"] <= b["canvas"]["bottom"] + 0.5
                        if lg["type"] == "Legend":
                            _inside(lg, b["frame"]["left"], b["frame"]["right"], (width, name, "frame"))
                            assert b["frame"]["top"] - 0.5 <= lg["top"] and lg["bottom"] <= b["frame"]["bottom"] + 0.5
                    assert len([lg for lg in b["legends"] if lg["type"] == "Legend"]) == (
                        0 if name == "driving-cycle" else 1), (name, b["legends"])
                page.screenshot(path=str(artifacts / f"app_{width}.png"), full_page=True)
                # the controls fold away: the views take the width, and come back
                toggle = page.locator(".controls-toggle button")
                toggle.click()
                expect_hidden = page.locator(".app-controls")
                expect_hidden.wait_for(state="hidden", timeout=10_000)
                assert toggle.inner_text() == "Show controls"
                toggle.click()
                page.locator(".app-controls").wait_for(state="visible", timeout=10_000)
                page.close()
        finally:
            browser.close()
    assert not errors, errors


def test_72_departure_keys_end_consistent_at_the_sliders_time(chromium, app_url, trip_model):
    """72 presses of the arrow key on the departure slider (12:00 -> 18:00): within 2 s of
    the last, the numbers, the irradiance plot and the driving cycle all show the trip of
    the slider's time; on the way, every frame shown is one departure (never the irradiance
    of one trip beside the cycle of another)."""
    playwright = pytest.importorskip("playwright.sync_api")
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(chromium), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(app_url)
            page.wait_for_selector("#pv-kwh", timeout=60_000)
            first = page.evaluate(_SHOWN_JS)
            assert first["slider"] == 12 * 60 and first["requested"] == "12:00"
            handle = page.locator(".depart-slider .noUi-handle")
            handle.focus()
            frames = []
            for i in range(72):
                page.keyboard.press("ArrowRight")
                if i % 6 == 5:
                    frames.append(page.evaluate(_SHOWN_JS))
            want = 18 * 60
            page.wait_for_function(
                """([js, want]) => { const s = eval(js)();
                     return s.slider == want && s.requested == want_hhmm(want)
                         && Math.abs(s.irradiance_t0 - s.t0) < 1 && Math.abs(s.cycle_t0 - s.t0) < 1; }"""
                .replace("want_hhmm(want)", f"'{_hhmm(want)}'"),
                arg=[_SHOWN_JS, want], timeout=2_000)
            last = page.evaluate(_SHOWN_JS)
        finally:
            browser.close()
    for f in frames + [last]:
        assert abs(f["irradiance_t0"] - f["t0"]) < 1 and abs(f["cycle_t0"] - f["t0"]) < 1, f
    # the trip shown is the model's: the next scheduled departure at or after 18:00
    r = last
    start = default_start(trip_model)
    res = trip_model.trip(start["route_id"], start["direction_id"], start["date"], want)
    assert r["departure"] == res.departure.strftime("%H:%M") and res.departure.strftime("%H:%M") >= "18:00"


def default_start(model):
    from vipvflow.app.layout import default_view

    return default_view(model)


def test_controls_that_do_not_apply_are_disabled_and_the_shading_loss_stays(chromium, app_url):
    """In pvlib mode the performance ratio (the paper model's) is disabled and the DC losses
    enabled, and the other way round; the trip's shading loss (on light) is the same."""
    playwright = pytest.importorskip("playwright.sync_api")
    from playwright.sync_api import expect

    state_js = """() => { const d = Bokeh.documents[0];
        return {pr: d.get_model_by_name("pv-pr").disabled, losses: d.get_model_by_name("pv-losses").disabled,
                tech: d.get_model_by_name("pv-tech").disabled}; }"""
    with playwright.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(chromium), args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.goto(app_url)
            page.wait_for_selector("#pv-kwh", timeout=60_000)
            assert page.evaluate(state_js) == {"pr": False, "losses": True, "tech": True}
            loss = page.locator(".shading-loss").inner_text()
            kwh = page.locator("#pv-kwh").inner_text()
            page.locator(".pv-mode select").select_option(label="pvlib: PVWatts + cell temperature")
            expect(page.locator("#pv-kwh")).not_to_have_text(kwh, timeout=30_000)
            assert page.evaluate(state_js) == {"pr": True, "losses": False, "tech": False}
            assert page.locator(".shading-loss").inner_text() == loss
        finally:
            browser.close()
