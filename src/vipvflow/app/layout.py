"""The Bokeh document of the web app: controls, views, and the callbacks that recompute them.

Every view is fed from :class:`vipvflow.app.model.TripModel`; nothing is computed here but
formatting.  The trip's numbers are in a ``Div`` with stable ids (``#trip-numbers`` holding
``data-*`` attributes of the settings they belong to, ``#pv-kwh``, ``#consumption-kwh``,
``#pv-share``) so a browser test can read them.
"""
from __future__ import annotations

import html
import json
import logging
from functools import lru_cache
from types import SimpleNamespace

import numpy as np
import pandas as pd
from bokeh.layouts import column, row
from bokeh.models import (ColorBar, ColumnDataSource, CustomJSTickFormatter, DatePicker, Div,
                          FactorRange, HoverTool, Legend, LinearColorMapper, RadioButtonGroup,
                          Select, Slider, Span, Spinner)
from bokeh.palettes import Category10_5, Viridis256
from bokeh.plotting import figure
from bokeh.transform import dodge

from ..store import DataDir, RunDir
from .model import TECHNOLOGIES, PVChoice, TripModel

log = logging.getLogger(__name__)

#: display rounding of the numbers Div (decimals), shared with the tests
DECIMALS = {"pv_kwh": 3, "consumption_kwh": 2, "share_percent": 2}

_HHMM = "const m = Math.round(tick); return String(Math.floor(m / 60)).padStart(2, '0') + ':' + String(m % 60).padStart(2, '0');"


SUMMER = (6, 7, 5, 8)            # months a first look prefers, best first
NOON_MIN = 12 * 60


def default_view(model: TripModel) -> dict:
    """The trip the app opens on, one worth looking at: the busiest route-direction, on the
    clearest day (highest GHI / clear-sky GHI over the day) of the simulated summer months
    (of the simulated months when none is in summer) on which it runs, at noon.

    Returns ``route_id, direction_id, date ('YYYY-MM-DD'), depart (minutes)``.
    """
    routes = model.routes()
    best = routes.loc[routes["trips"].idxmax()]
    route_id, direction_id = best["route_id"], int(best["direction_id"])
    months = list(model.cfg.run.months or range(1, 13))
    summer = [m for m in SUMMER if m in months] or months
    rad = model.radiation
    times = pd.to_datetime(rad.t0 + rad.step_s * np.arange(rad.data["ghi"].shape[1]), unit="s",
                           utc=True).tz_convert(model.timezone)
    day = pd.DataFrame({"date": times.tz_localize(None).normalize(),
                        "ghi": rad.data["ghi"].mean(axis=0), "clear": rad.data["ghi_clear"].mean(axis=0)})
    daily = day.groupby("date")[["ghi", "clear"]].sum()
    clearness = (daily["ghi"] / daily["clear"].where(daily["clear"] > 0)).dropna()
    sd = model.service_dates
    sd = sd[(sd["date"].dt.year == model.year) & sd["date"].dt.month.isin(summer)]
    candidates = [d for d in clearness.index.intersection(pd.DatetimeIndex(sd["date"].unique()))
                  if len(model.departures(route_id, direction_id, d))]
    if candidates:
        date = max(candidates, key=lambda d: (clearness[d], -abs(d.day_of_year - 172)))
    else:                                    # no radiation or no service day found: mid-month
        date = pd.Timestamp(model.year, summer[0], 15)
    return {"route_id": route_id, "direction_id": direction_id,
            "date": date.strftime("%Y-%m-%d"), "depart": NOON_MIN}


def month_labels(months) -> list[str]:
    """Axis labels of months (``'2024-06'`` or a date): ``'Jun'``, with the year when the
    months span more than one."""
    when = pd.to_datetime(pd.Series(months, dtype=object).astype(str))
    fmt = "%b" if when.dt.year.nunique() <= 1 else "%b %Y"
    return list(when.dt.strftime(fmt))


@lru_cache(maxsize=4)
def _footprints(data_dir: str, tiles: tuple, bounds: tuple) -> tuple[list, list]:
    from ..inputs.city.footprints import building_footprints

    rings = building_footprints(data_dir, tiles=tiles, bounds=bounds)
    return [r[:, 0].tolist() for r in rings], [r[:, 1].tolist() for r in rings]


def _crs_name(model: TripModel) -> str:
    """The city's CRS as the ingest recorded it (``EPSG:2169``), or 'projected'."""
    import json

    try:
        return str(json.loads(DataDir(model.data_dir).city.tiles_json.read_text())["crs"])
    except (OSError, KeyError, ValueError):
        return "projected"


def _footprint_patches(model: TripModel, margin_m: float = 200.0) -> tuple[list, list]:
    """x and y lists of the building footprints around the run's routes (the map's
    background, from the city model of the run's data directory: no map service)."""
    g = model.geometry
    x = np.concatenate([g["x"].to_numpy(), g["x_end"].to_numpy()])
    y = np.concatenate([g["y"].to_numpy(), g["y_end"].to_numpy()])
    bounds = (float(x.min()) - margin_m, float(y.min()) - margin_m,
              float(x.max()) + margin_m, float(y.max()) + margin_m)
    return _footprints(str(model.data_dir), tuple(sorted(g["tile"].dropna().unique())), bounds)


def numbers_html(res, fleet: dict | None = None) -> str:
    """The trip's numbers as HTML (ids and classes are the app's stable test interface)."""
    n = res.numbers
    share = 100.0 * n["share"]
    attrs = {"route": res.route_id, "direction": res.direction_id,
             "date": res.date.strftime("%Y-%m-%d"), "requested": res.requested,
             "trip": res.trip_id, "departure": res.departure.strftime("%H:%M")}
    data = " ".join(f'data-{k}="{html.escape(str(v))}"' for k, v in attrs.items())
    fleet_html = ""
    if fleet:
        run = fleet.get("run") or {}
        headline = ""
        if run.get("coverage") is not None:
            headline = (f'the run: PV the batteries take covers <b><span class="fleet-coverage">'
                        f'{100 * run["coverage"]:.2f}</span> %</b> of the fleet\'s demand in service '
                        f'(trips and layovers; summary.json coverage); ')
        fleet_html = (f'<div class="fleet">Fleet: {headline}driving, simulated months (rescaled): '
                      f'<b>{fleet["allsky"]:,.0f}</b> kWh PV all-sky, {fleet["clearsky"]:,.0f} clear-sky, '
                      f'shading loss {100 * fleet["shading_loss"]:.1f} %, '
                      f'{100 * fleet["share"]:.2f} % of the trips\' {fleet["consumption"]:,.0f} kWh '
                      f'(coverage_driving)</div>')
    return (
        f'<div id="trip-numbers" class="trip-numbers" {data}>'
        f'<div class="trip-head">Trip <b>{html.escape(res.trip_id)}</b> on {res.date:%a %d %b %Y}, '
        f'departs <b>{res.departure:%H:%M}</b> (asked {res.requested}: {html.escape(res.note)})</div>'
        f'<table class="trip-table">'
        f'<tr><td>PV energy</td><td><span id="pv-kwh" class="pv-kwh">'
        f'{n["pv_kwh"]:.{DECIMALS["pv_kwh"]}f}</span> kWh</td>'
        f'<td>unshaded {n["pv_kwh_unshaded"]:.3f} kWh, shading loss {100 * n["shading_loss"]:.1f} %</td></tr>'
        f'<tr><td>Consumed</td><td><span id="consumption-kwh" class="consumption-kwh">'
        f'{n["consumption_kwh"]:.{DECIMALS["consumption_kwh"]}f}</span> kWh</td>'
        f'<td>{n["distance_km"]:.2f} km in {n["duration_min"]:.0f} min</td></tr>'
        f'<tr><td>PV share</td><td><span id="pv-share" class="pv-share">'
        f'{share:.{DECIMALS["share_percent"]}f}</span> %</td>'
        f'<td>SoC at departure <span class="soc-start">{100 * n["soc_start"]:.1f}</span> % '
        f'({html.escape(n["soc_start_from"])}); at the end {100 * n["soc_end"]:.1f} % without PV, '
        f'{100 * n["soc_end_pv"]:.1f} % with</td></tr>'
        f'</table>{fleet_html}'
        f'<div class="compute">recomputed in {1000 * n["compute_s"]:.0f} ms with the run\'s physics '
        f'(diffuse model {n.get("diffuse_model", "")}; stored horizons and geometry factors, '
        f'occlusion rays for the reflectors)</div></div>')


def build_document(model: TripModel, doc) -> None:
    """Fill a Bokeh document with the app for *model* (a FunctionHandler target)."""
    start = default_view(model)
    c = _controls(model, start)
    v = _views(model)
    v.f_mon = _monthly_figure(v.src_mon)
    refresh = _wire(model, c, v)
    refresh()
    w = _WIDTH
    controls = column(c.tech, c.mode, c.size_by, c.kwp, c.area, c.pr, c.losses, c.route, c.date,
                      c.depart, c.aux, c.soc, width=w + 20)
    doc.add_root(column(_header(model), row(controls, column(c.numbers, c.error, v.f_map),
                                            column(v.f_irr, v.f_cyc, v.f_soc)),
                        row(Div(width=w + 20), v.f_mon)))
    doc.title = "vipvflow app"


#: width of the control column (px)
_WIDTH = 300


def _controls(model: TripModel, start: dict) -> SimpleNamespace:
    """The PV, route, date and vehicle controls and the text panes, opened on *start*."""
    routes = model.routes()
    route_opts = [(f"{r.route_id}|{r.direction_id}",
                   f"{r.route_short_name} " + (f"to {r.trip_headsign}" if r.trip_headsign
                                               else f"direction {r.direction_id}")
                   + f" ({r.trips} trips)")
                  for r in routes.itertuples()]
    run_pv = model.run_pv_choice
    w = _WIDTH
    tech = Select(title="PV technology", value=run_pv.technology, options=list(TECHNOLOGIES),
                  width=w, css_classes=["pv-tech"])
    mode = Select(title="PV model", value=run_pv.mode, width=w, css_classes=["pv-mode"],
                  options=[("paper", "paper: kWp x POA x PR"), ("pvlib", "pvlib: PVWatts + cell temperature")])
    size_by = RadioButtonGroup(labels=["size by kWp", "size by area"], active=0, width=w)
    kwp = Spinner(title="peak power (kWp)", value=run_pv.kwp, low=0.1, high=20, step=0.1, width=w,
                  css_classes=["pv-kwp"])
    area = Spinner(title="module area (m2)", value=round(run_pv.kwp / TECHNOLOGIES[run_pv.technology]["efficiency"], 1),
                   low=1, high=60, step=0.5, width=w, disabled=True, css_classes=["pv-area"])
    pr = Slider(title="performance ratio (paper model)", value=run_pv.performance_ratio, start=0.5,
                end=0.95, step=0.01, width=w, css_classes=["pv-pr"])
    losses = Slider(title="DC system losses % (pvlib model)", value=run_pv.losses_percent, start=0,
                    end=40, step=0.5, width=w, css_classes=["pv-losses"])
    route = Select(title="route and direction", value=f"{start['route_id']}|{start['direction_id']}",
                   options=route_opts, width=w, css_classes=["route-select"])
    date = DatePicker(title="date", value=start["date"],
                      min_date=f"{model.year}-01-01", max_date=f"{model.year}-12-31", width=w,
                      css_classes=["date-picker"])
    depart = Slider(title="departure: next scheduled trip at or after", value=start["depart"], start=0,
                    end=24 * 60 - 5, step=5, width=w, css_classes=["depart-slider"],
                    format=CustomJSTickFormatter(code=_HHMM))
    aux = Spinner(title="auxiliary base load (kW; HVAC on top)", value=model.vehicle.aux_base_kw,
                  low=0, high=40, step=0.5, width=w, css_classes=["aux-kw"])
    soc = Slider(title="SoC limit (min); the trip departs at its SoC in the run's balance",
                 value=model.vehicle.soc_min, start=0, end=0.9, step=0.01, width=w,
                 css_classes=["soc-min"])
    numbers = Div(text="", width=560, css_classes=["numbers-div"],
                  stylesheets=[":host .trip-table td { padding: 2px 10px 2px 0; }"
                               ":host .pv-kwh, :host .pv-share { font-size: 1.4em; font-weight: bold; color: #b35900; }"
                               ":host .compute, :host .fleet { color: #555; margin-top: 4px; }"])
    error = Div(text="", width=560, css_classes=["app-error"])

    return SimpleNamespace(tech=tech, mode=mode, size_by=size_by, kwp=kwp, area=area, pr=pr, losses=losses, route=route, date=date, depart=depart, aux=aux, soc=soc, numbers=numbers, error=error)


def _views(model: TripModel) -> SimpleNamespace:
    """The data sources and the irradiance, map, driving-cycle and SoC figures."""
    src_seg = ColumnDataSource(data={k: [] for k in ("time", "direct", "diffuse", "reflected",
                                                     "total", "unshaded", "x", "y", "x_end",
                                                     "y_end", "energy_wh")})
    src_cyc = ColumnDataSource(data={"time": [], "speed_kmh": [], "soc": [], "soc_pv": []})
    src_mon = ColumnDataSource(data={k: [] for k in ("month", "allsky", "clearsky", "allsky_unshaded",
                                                     "clearsky_unshaded", "shading_loss")})
    g = model.geometry
    src_bg = ColumnDataSource(data={"x": g["x"], "y": g["y"], "x_end": g["x_end"], "y_end": g["y_end"]})

    f_irr = figure(title="Irradiance on the roof along the trip", x_axis_type="datetime",
                   height=300, width=620, y_axis_label="W/m2", tools="pan,wheel_zoom,box_zoom,reset,save")
    items = []
    for name, color in zip(("total", "direct", "diffuse", "reflected"), Category10_5):
        items.append((name, [f_irr.line("time", name, source=src_seg, color=color, line_width=1.6)]))
    items.append(("unshaded", [f_irr.line("time", "unshaded", source=src_seg, color="black",
                                          line_dash="dashed", line_width=1.2)]))
    f_irr.add_layout(Legend(items=items, click_policy="hide", location="top_left"), "right")

    mapper = LinearColorMapper(palette=Viridis256, low=0, high=1)
    f_map = figure(title="Route, coloured by PV energy per segment (Wh)", match_aspect=True,
                   height=420, width=560, x_axis_label=f"easting (m), {_crs_name(model)}", y_axis_label="northing (m)",
                   tools="pan,wheel_zoom,box_zoom,reset,save")
    bx, by = _footprint_patches(model)
    f_map.patches(bx, by, fill_color="#dedede", line_color="#b4b4b4", line_width=0.5)
    f_map.segment("x", "y", "x_end", "y_end", source=src_bg, color="#9e9e9e", line_width=2)
    seg_r = f_map.segment("x", "y", "x_end", "y_end", source=src_seg, line_width=6,
                          color={"field": "energy_wh", "transform": mapper})
    f_map.add_layout(ColorBar(color_mapper=mapper, title="Wh"), "right")
    f_map.add_tools(HoverTool(renderers=[seg_r], tooltips=[("time", "@time{%H:%M:%S}"),
                                                           ("PV", "@energy_wh{0.00} Wh"),
                                                           ("total", "@total{0} W/m2")],
                              formatters={"@time": "datetime"}))

    f_cyc = figure(title="Driving cycle", x_axis_type="datetime", height=250, width=620,
                   y_axis_label="speed (km/h)", tools="pan,wheel_zoom,box_zoom,reset,save")
    f_cyc.line("time", "speed_kmh", source=src_cyc, color="#1f77b4")

    f_soc = figure(title="Battery state of charge", x_axis_type="datetime", height=250, width=620,
                   y_axis_label="SoC", tools="pan,wheel_zoom,box_zoom,reset,save")
    f_soc.line("time", "soc", source=src_cyc, color="#7f7f7f", line_width=2, legend_label="without PV")
    f_soc.line("time", "soc_pv", source=src_cyc, color="#ff7f0e", line_width=2, legend_label="with PV")
    soc_min_line = Span(location=model.vehicle.soc_min, dimension="width", line_color="red",
                        line_dash="dotted")
    f_soc.add_layout(soc_min_line)
    f_soc.legend.location = "bottom_left"

    return SimpleNamespace(src_seg=src_seg, src_cyc=src_cyc, src_mon=src_mon, f_irr=f_irr, f_map=f_map, mapper=mapper, f_cyc=f_cyc, f_soc=f_soc, soc_min_line=soc_min_line)


def _monthly_figure(src_mon: ColumnDataSource):
    """Monthly PV energy of the route-direction: all-sky and clear-sky bars, unshaded marks."""
    f_mon = figure(title="Monthly PV energy of the route-direction (run, rescaled to this PV)",
                   x_range=FactorRange(), height=330, width=560, y_axis_label="kWh",
                   tools="save,reset")
    f_mon.vbar(x=dodge("month", -0.18, range=f_mon.x_range), top="allsky", width=0.34, source=src_mon,
               color="#ff7f0e", legend_label="all-sky")
    f_mon.vbar(x=dodge("month", 0.18, range=f_mon.x_range), top="clearsky", width=0.34, source=src_mon,
               color="#1f77b4", legend_label="clear-sky")
    f_mon.scatter(x=dodge("month", -0.18, range=f_mon.x_range), y="allsky_unshaded", source=src_mon,
                  marker="dash", size=30, color="black", legend_label="without buildings")
    f_mon.scatter(x=dodge("month", 0.18, range=f_mon.x_range), y="clearsky_unshaded", source=src_mon,
                  marker="dash", size=30, color="black")
    f_mon.add_tools(HoverTool(tooltips=[("month", "@month"), ("all-sky", "@allsky{0,0} kWh"),
                                        ("clear-sky", "@clearsky{0,0} kWh"),
                                        ("shading loss", "@shading_loss{0.0%}")]))
    # the legend in one row above the plot, never over the bars; month names on the axis
    f_mon.legend.orientation = "horizontal"
    f_mon.add_layout(f_mon.legend[0], "above")
    f_mon.xaxis.major_label_text_font_size = "11pt"
    f_mon.y_range.start = 0

    return f_mon


def _wire(model: TripModel, c: SimpleNamespace, v: SimpleNamespace):
    """Connect the controls to the model; returns the function that recomputes the views."""
    run_pv = model.run_pv_choice
    tech, mode, size_by, kwp, area, pr, losses = c.tech, c.mode, c.size_by, c.kwp, c.area, c.pr, c.losses
    route, date, depart, aux, soc, numbers, error = c.route, c.date, c.depart, c.aux, c.soc, c.numbers, c.error
    src_seg, src_cyc, src_mon, mapper, soc_min_line = v.src_seg, v.src_cyc, v.src_mon, v.mapper, v.soc_min_line
    f_mon = v.f_mon

    def pv_choice() -> PVChoice:
        return PVChoice(technology=tech.value, mode=mode.value, kwp=float(kwp.value),
                        area_m2=float(area.value) if size_by.active == 1 else None,
                        performance_ratio=float(pr.value), losses_percent=float(losses.value),
                        inverter_efficiency=run_pv.inverter_efficiency)

    def selected():
        rid, d = route.value.rsplit("|", 1)
        return rid, int(d)

    def update_monthly(pv: PVChoice):
        rid, d = selected()
        mon = model.monthly(rid, d, pv)
        mon["month"] = month_labels(mon["month"])
        f_mon.x_range.factors = list(mon["month"])
        src_mon.data = {k: list(mon[k]) for k in src_mon.data}
        fleet = model.monthly(None, None, pv)
        if len(fleet):
            tot = fleet[["allsky", "clearsky", "allsky_unshaded", "consumption"]].sum()
            return {"run": model.summary, "allsky": tot["allsky"], "clearsky": tot["clearsky"],
                    "shading_loss": float((fleet["shading_loss"] * fleet["allsky_unshaded"]).sum()
                                          / max(tot["allsky_unshaded"], 1e-12)),
                    "share": tot["allsky"] / tot["consumption"] if tot["consumption"] else np.nan,
                    "consumption": tot["consumption"]}
        return None

    def recompute(attr, old, new):
        refresh()

    def refresh():
        try:
            pv = pv_choice()
            rid, d = selected()
            lo = float(soc.value)
            res = model.trip(rid, d, date.value, depart=int(depart.value), pv=pv,
                             aux_kw=float(aux.value), soc_min=lo)
            s = res.segments
            src_seg.data = {"time": s["time"].to_numpy(), "direct": s["direct"].to_numpy(),
                            "diffuse": s["diffuse"].to_numpy(), "reflected": s["reflected"].to_numpy(),
                            "total": s["total"].to_numpy(), "unshaded": s["unshaded"].to_numpy(),
                            "x": s["x"].to_numpy(), "y": s["y"].to_numpy(),
                            "x_end": s["x_end"].to_numpy(), "y_end": s["y_end"].to_numpy(),
                            "energy_wh": 1000.0 * s["energy_kwh"].to_numpy()}
            # colour scale to the 98th percentile: segments with a stop inside (long dwell)
            # would otherwise flatten the rest
            mapper.high = max(float(np.quantile(1000.0 * s["energy_kwh"], 0.98)), 1e-3)
            c = res.cycle
            src_cyc.data = {"time": c["time"].to_numpy(), "speed_kmh": c["speed_kmh"].to_numpy(),
                            "soc": c["soc"].to_numpy(), "soc_pv": c["soc_pv"].to_numpy()}
            soc_min_line.location = float(lo)
            fleet = update_monthly(pv)
            numbers.text = numbers_html(res, fleet)
            error.text = ""
        except Exception as exc:  # show it in the page; the session stays usable
            log.exception("recompute failed")
            error.text = f'<div id="app-error" style="color:#b00">{html.escape(str(exc))}</div>'

    def on_size(attr, old, new):
        kwp.disabled = size_by.active == 1
        area.disabled = size_by.active == 0
        refresh()

    for widget in (tech, mode, route, date, aux):
        widget.on_change("value", recompute)
    for widget in (kwp, area, pr, losses, depart, soc):
        widget.on_change("value_throttled", recompute)
    size_by.on_change("active", on_size)
    return refresh


def _header(model: TripModel) -> Div:
    """Title, run, diffuse model and the run's three yields (driving, in service, whole day)."""
    yields = ""
    summary_path = RunDir(model.run_dir).output("summary.json")
    if summary_path.exists():
        sm = json.loads(summary_path.read_text())
        parts = [(label, sm.get(key)) for label, key in (("the batteries take", "kwh_per_kwp_usable"),
                                                         ("driving", "kwh_per_kwp_driving"),
                                                         ("in service", "kwh_per_kwp_in_service"),
                                                         ("whole day", "kwh_per_kwp_whole_day"))]
        shown = [f"{label} {value:,.0f}" for label, value in parts if isinstance(value, (int, float))]
        if shown:
            yields = (f"<div class='run-yields' style='color:#555'>the run's fleet yield, kWh/kWp per year: "
                      f"{', '.join(shown)}</div>")
    return Div(text=(f"<h2 style='margin:4px 0'>vipvflow: bus-roof PV along a trip</h2>"
                     f"<div style='color:#555'>run <code>{html.escape(str(model.run_dir))}</code>, "
                     f"scenario {html.escape(model.cfg.scenario)} {model.year}, "
                     f"diffuse model {model.cfg.irradiance.diffuse_model}</div>{yields}"), width=1200)
