"""The Bokeh document of the web app: controls, views, and the callbacks that recompute them.

Every view is fed from :class:`vipvflow.app.model.TripModel`; nothing is computed here but
formatting.  The trip's numbers are in a ``Div`` with stable ids (``#trip-numbers`` holding
``data-*`` attributes of the settings they belong to, ``#pv-kwh``, ``#consumption-kwh``,
``#pv-share``) so a browser test can read them.
"""
from __future__ import annotations

import contextlib
import html
import json
import logging
import threading
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache, partial
from types import SimpleNamespace

import numpy as np
import pandas as pd
from bokeh.layouts import column, row
from bokeh.models import (ColorBar, ColumnDataSource, CustomJS, CustomJSTickFormatter, DataRange1d,
                          DatePicker, Div, FactorRange, HoverTool, Legend, LinearColorMapper,
                          RadioButtonGroup, Select, Slider, Span, Spinner, Toggle)
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


def _pct(value: float, decimals: int = 1) -> str:
    return f"{100 * value:.{decimals}f} %"


def numbers_html(res, fleet: dict | None = None) -> str:
    """The trip's numbers as HTML (ids and classes are the app's stable test interface).

    ``#trip-numbers`` carries the settings the numbers belong to as ``data-*`` attributes,
    and ``data-t0``: the trip's departure in the time axis of the plots (ms after the epoch
    of local time, as Bokeh's datetime axes hold it), so a page can check that the trip,
    the irradiance plot and the driving cycle show the same departure.  A trip with the sun
    below the horizon says so where the shading loss would be (no light: nothing to lose)."""
    n = res.numbers
    share = 100.0 * n["share"]
    t0 = int(round(pd.Timestamp(res.departure).value / 1e6))
    attrs = {"route": res.route_id, "direction": res.direction_id,
             "date": res.date.strftime("%Y-%m-%d"), "requested": res.requested,
             "trip": res.trip_id, "departure": res.departure.strftime("%H:%M"), "t0": t0}
    data = " ".join(f'data-{k}="{html.escape(str(v))}"' for k, v in attrs.items())
    if n.get("sun_up", True) and np.isfinite(n["shading_loss"]):
        light = (f'unshaded {n["pv_kwh_unshaded"]:.3f} kWh; shading loss '
                 f'<span class="shading-loss">{_pct(n["shading_loss"])}</span> of the light on the roof '
                 f'({n["h_direct"] + n["h_diffuse"]:.0f} of {n["h_unshaded"]:.0f} Wh/m2 direct and diffuse)')
    else:
        light = '<span class="shading-loss sun-down">sun below the horizon</span>: no light on the roof'
    stops = ""
    if n.get("stops"):
        stops = (f'<tr><td>At stops</td><td>{1000 * n["stop_pv_kwh"]:.0f} Wh</td>'
                 f'<td>{n["stops"]} stops, {n["stop_s"] / 60:.1f} min standing (circles on the map)</td></tr>')
    fleet_html = ""
    if fleet:
        run = fleet.get("run") or {}
        headline = ""
        if run.get("coverage") is not None:
            headline = (f'the run: PV the batteries take covers <b><span class="fleet-coverage">'
                        f'{100 * run["coverage"]:.2f}</span> %</b> of the fleet\'s demand in service '
                        f'(trips and layovers; summary.json coverage); ')
        loss = fleet["shading_loss"]
        loss_text = f"shading loss {_pct(loss)}" if np.isfinite(loss) else "no light"
        fleet_html = (f'<div class="fleet">Fleet: {headline}driving, simulated months (rescaled): '
                      f'<b>{fleet["allsky"]:,.0f}</b> kWh PV all-sky, {fleet["clearsky"]:,.0f} clear-sky, '
                      f'{loss_text}, '
                      f'{100 * fleet["share"]:.2f} % of the trips\' {fleet["consumption"]:,.0f} kWh '
                      f'(coverage_driving)</div>')
    return (
        f'<div id="trip-numbers" class="trip-numbers" {data}>'
        f'<div class="trip-head">Trip <b>{html.escape(res.trip_id)}</b> on {res.date:%a %d %b %Y}, '
        f'departs <b>{res.departure:%H:%M}</b> (asked {res.requested}: {html.escape(res.note)})</div>'
        f'<table class="trip-table">'
        f'<tr><td>PV energy</td><td><span id="pv-kwh" class="pv-kwh">'
        f'{n["pv_kwh"]:.{DECIMALS["pv_kwh"]}f}</span> kWh</td><td>{light}</td></tr>'
        f'{stops}'
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


def route_label(r, ambiguous: bool = False) -> str:
    """How the route picker names a route-direction: its public name and where it goes
    (``S5 to Ostheim``), its long name where it says more, the trips; the route_id when
    two routes share a public name."""
    short, long_name = str(r.route_short_name), str(r.route_long_name or "")
    head = f"to {r.trip_headsign}" if r.trip_headsign else f"direction {r.direction_id}"
    extra = [long_name] if long_name and long_name != short else []
    if ambiguous:
        extra.append(f"route_id {r.route_id}")
    extra.append(f"{r.trips} trips")
    return f"{short} {head} ({'; '.join(extra)})"


#: the app's look: a column of controls beside the views on a wide screen, above them on a
#: narrow one; the views side by side as the width allows (each at least MIN_VIEW_PX)
MIN_VIEW_PX = 340
CONTROLS_PX = 300
_WRAP = {"flex-wrap": "wrap", "align-items": "flex-start"}


def build_document(model: TripModel, doc) -> None:
    """Fill a Bokeh document with the app for *model* (a FunctionHandler target).

    Every view fits the window from a phone's 400 px to a wide monitor: the figures stretch
    to the width they get (at least :data:`MIN_VIEW_PX`) and wrap below each other, the
    controls are a column that moves above the views on a narrow screen and folds away
    ("Hide controls").  A change of any control asks :class:`Recompute` for the views:
    requests coalesce, a result computed for values changed meanwhile is dropped, so the
    trip, the irradiance, the driving cycle and the SoC always show one departure."""
    start = default_view(model)
    c = _controls(model, start)
    v = _views(model)
    v.f_mon = _monthly_figure(v.src_mon)
    compute, apply = _wire(model, c, v)
    recompute = Recompute(doc, compute, apply)
    for widget in (c.tech, c.mode, c.route, c.date, c.aux, c.kwp, c.area, c.pr, c.losses, c.depart, c.soc):
        widget.on_change("value", recompute.request)
    c.size_by.on_change("active", recompute.request)
    apply(compute())                          # the first view, before the page shows
    controls = column(c.tech, c.mode, c.size_by, c.kwp, c.area, c.pr, c.losses, c.route, c.date,
                      c.depart, c.aux, c.soc, width=CONTROLS_PX, css_classes=["app-controls"],
                      name="controls", styles={"max-width": "100%"})
    toggle = Toggle(label="Hide controls", active=True, width=130, css_classes=["controls-toggle"],
                    name="controls-toggle")
    toggle.js_on_change("active", CustomJS(args={"panel": controls, "button": toggle}, code=(
        "panel.visible = button.active; "
        "button.label = button.active ? 'Hide controls' : 'Show controls';")))
    for f in (v.f_irr, v.f_map, v.f_cyc, v.f_soc, v.f_mon):
        f.sizing_mode = "stretch_width"
        f.min_width = MIN_VIEW_PX
    # each figure in a box of its own: the row would otherwise align the figures as one
    # line of plots (each as tall as the tallest) however they wrap
    boxes = [column(f, sizing_mode="stretch_width", min_width=MIN_VIEW_PX)
             for f in (v.f_irr, v.f_map, v.f_cyc, v.f_soc, v.f_mon)]
    views = row(*boxes, sizing_mode="stretch_width", styles=_WRAP, name="views")
    content = column(c.numbers, c.error, views, sizing_mode="stretch_width", min_width=MIN_VIEW_PX)
    main = row(controls, content, sizing_mode="stretch_width", styles=_WRAP)
    doc.add_root(column(_header(model), toggle, main, sizing_mode="stretch_width",
                        styles={"padding": "0 6px", "box-sizing": "border-box"}))
    doc.title = "vipvflow app"


def _controls(model: TripModel, start: dict) -> SimpleNamespace:
    """The PV, route, date and vehicle controls and the text panes, opened on *start*."""
    routes = model.routes()
    shared = routes.groupby("route_short_name")["route_id"].transform("nunique") > 1
    route_opts = [(f"{r.route_id}|{r.direction_id}", route_label(r, bool(a)))
                  for r, a in zip(routes.itertuples(), shared)]
    run_pv = model.run_pv_choice
    wide = {"sizing_mode": "stretch_width"}
    tech = Select(title="PV technology", value=run_pv.technology, options=list(TECHNOLOGIES),
                  css_classes=["pv-tech"], name="pv-tech", **wide)
    mode = Select(title="PV model", value=run_pv.mode, css_classes=["pv-mode"], name="pv-mode",
                  options=[("paper", "paper: kWp x POA x PR"), ("pvlib", "pvlib: PVWatts + cell temperature")],
                  **wide)
    size_by = RadioButtonGroup(labels=["size by kWp", "size by area"], active=0, name="size-by", **wide)
    kwp = Spinner(title="peak power (kWp)", value=run_pv.kwp, low=0.1, high=20, step=0.1,
                  css_classes=["pv-kwp"], name="pv-kwp", **wide)
    area = Spinner(title="module area (m2)", value=round(run_pv.kwp / TECHNOLOGIES[run_pv.technology]["efficiency"], 1),
                   low=1, high=60, step=0.5, disabled=True, css_classes=["pv-area"], name="pv-area", **wide)
    pr = Slider(title="performance ratio (paper model)", value=run_pv.performance_ratio, start=0.5,
                end=0.95, step=0.01, css_classes=["pv-pr"], name="pv-pr", **wide)
    losses = Slider(title="DC system losses % (pvlib model)", value=run_pv.losses_percent, start=0,
                    end=40, step=0.5, css_classes=["pv-losses"], name="pv-losses", **wide)
    route = Select(title="route and direction", value=f"{start['route_id']}|{start['direction_id']}",
                   options=route_opts, css_classes=["route-select"], name="route", **wide)
    date = DatePicker(title="date", value=start["date"],
                      min_date=f"{model.year}-01-01", max_date=f"{model.year}-12-31",
                      css_classes=["date-picker"], name="date", **wide)
    depart = Slider(title="departure: next scheduled trip at or after", value=start["depart"], start=0,
                    end=24 * 60 - 5, step=5, css_classes=["depart-slider"], name="depart",
                    format=CustomJSTickFormatter(code=_HHMM), **wide)
    aux = Spinner(title="auxiliary base load (kW; HVAC on top)", value=model.vehicle.aux_base_kw,
                  low=0, high=40, step=0.5, css_classes=["aux-kw"], name="aux", **wide)
    soc = Slider(title="SoC limit (min)", value=model.vehicle.soc_min, start=0, end=0.9, step=0.01,
                 css_classes=["soc-min"], name="soc-min", **wide)
    numbers = Div(text="", css_classes=["numbers-div"], name="numbers", sizing_mode="stretch_width",
                  stylesheets=[":host .trip-table td { padding: 2px 10px 2px 0; vertical-align: top; }"
                               ":host .pv-kwh, :host .pv-share { font-size: 1.4em; font-weight: bold; color: #b35900; }"
                               ":host .sun-down { font-weight: bold; }"
                               ":host .compute, :host .fleet { color: #555; margin-top: 4px; }"])
    error = Div(text="", css_classes=["app-error"], sizing_mode="stretch_width")
    c = SimpleNamespace(tech=tech, mode=mode, size_by=size_by, kwp=kwp, area=area, pr=pr, losses=losses,
                        route=route, date=date, depart=depart, aux=aux, soc=soc, numbers=numbers, error=error)
    applicable(c)
    return c


def applicable(c: SimpleNamespace) -> None:
    """Disable the controls that do not apply to the chosen PV model and sizing: the
    performance ratio is the paper model's, the DC losses pvlib's; kWp or area; the
    technology matters to pvlib (temperature coefficient) and to sizing by area (efficiency)."""
    paper = c.mode.value == "paper"
    by_area = c.size_by.active == 1
    c.pr.disabled = not paper
    c.losses.disabled = paper
    c.kwp.disabled = by_area
    c.area.disabled = not by_area
    c.tech.disabled = paper and not by_area


def _views(model: TripModel) -> SimpleNamespace:
    """The data sources and the irradiance, map, driving-cycle and SoC figures."""
    src_seg = ColumnDataSource(data={k: [] for k in ("time", "direct", "diffuse", "reflected",
                                                     "total", "unshaded", "x", "y", "x_end",
                                                     "y_end", "energy_wh")}, name="trip-segments")
    src_stop = ColumnDataSource(data={k: [] for k in ("x", "y", "time", "total", "dwell_s",
                                                      "energy_wh", "size")}, name="trip-stops")
    src_cyc = ColumnDataSource(data={"time": [], "speed_kmh": [], "soc": [], "soc_pv": []},
                               name="trip-cycle")
    src_mon = ColumnDataSource(data={k: [] for k in ("month", "allsky", "clearsky", "allsky_unshaded",
                                                     "clearsky_unshaded", "shading_loss")})
    g = model.geometry
    src_bg = ColumnDataSource(data={"x": g["x"], "y": g["y"], "x_end": g["x_end"], "y_end": g["y_end"]})
    tools = "pan,wheel_zoom,box_zoom,reset,save"

    # irradiance along the trip: the legend inside, in the headroom the y range keeps for it
    f_irr = figure(title="Light on the roof along the trip (W/m2)", x_axis_type="datetime",
                   height=320, y_axis_label="W/m2", tools=tools, name="irradiance",
                   y_range=DataRange1d(start=0, range_padding=0.8, only_visible=True))
    items = []
    for name, color in zip(("total", "direct", "diffuse", "reflected"), Category10_5):
        items.append((name, [f_irr.line("time", name, source=src_seg, color=color, line_width=1.6)]))
    items.append(("without buildings", [f_irr.line("time", "unshaded", source=src_seg, color="black",
                                                   line_dash="dashed", line_width=1.2)]))
    f_irr.add_layout(Legend(items=items, click_policy="hide", location="top_left", ncols=3,
                            label_text_font_size="8.5pt", background_fill_alpha=0.75,
                            padding=4, spacing=2, margin=4))

    # the route: each segment coloured by the irradiance while the bus passes (W/m2, on the
    # scale of the light without buildings), the stops' dwells as circles apart
    mapper = LinearColorMapper(palette=Viridis256, low=0, high=1000)
    f_map = figure(title="Route: light on the roof (W/m2)", match_aspect=True,
                   height=440, x_axis_label=f"easting (m), {_crs_name(model)}", y_axis_label="northing (m)",
                   tools=tools, name="route-map")
    bx, by = _footprint_patches(model)
    f_map.patches(bx, by, fill_color="#dedede", line_color="#b4b4b4", line_width=0.5)
    bg = f_map.segment("x", "y", "x_end", "y_end", source=src_bg, color="#9e9e9e", line_width=2)
    seg_r = f_map.segment("x", "y", "x_end", "y_end", source=src_seg, line_width=6,
                          color={"field": "total", "transform": mapper})
    stop_r = f_map.scatter("x", "y", source=src_stop, size="size", fill_color={"field": "total", "transform": mapper},
                           line_color="#d62728", line_width=1.2, fill_alpha=0.8)
    f_map.add_layout(ColorBar(color_mapper=mapper, orientation="horizontal", height=10,
                              title="W/m2 while passing, with the buildings",
                              title_text_font_size="8pt", major_label_text_font_size="8pt"), "below")
    f_map.add_layout(Legend(items=[("this trip's segments (colour: W/m2)", [seg_r]),
                                   ("stops: dwell, circle area ~ time standing", [stop_r]),
                                   ("the run's other roads", [bg])],
                            location="top_left", label_text_font_size="8.5pt", background_fill_alpha=0.75,
                            padding=4, spacing=1, margin=4))
    f_map.add_tools(HoverTool(renderers=[seg_r], tooltips=[("time", "@time{%H:%M:%S}"),
                                                           ("light", "@total{0} W/m2"),
                                                           ("PV", "@energy_wh{0.00} Wh")],
                              formatters={"@time": "datetime"}))
    f_map.add_tools(HoverTool(renderers=[stop_r], tooltips=[("stop at", "@time{%H:%M:%S}"),
                                                            ("standing", "@dwell_s{0} s"),
                                                            ("light", "@total{0} W/m2"),
                                                            ("PV", "@energy_wh{0.00} Wh")],
                              formatters={"@time": "datetime"}))

    f_cyc = figure(title="Driving cycle", x_axis_type="datetime", height=240,
                   y_axis_label="speed (km/h)", tools=tools, name="driving-cycle")
    f_cyc.line("time", "speed_kmh", source=src_cyc, color="#1f77b4")

    f_soc = figure(title="Battery state of charge", x_axis_type="datetime", height=240,
                   y_axis_label="SoC", tools=tools, name="soc")
    f_soc.line("time", "soc", source=src_cyc, color="#7f7f7f", line_width=2, legend_label="without PV")
    f_soc.line("time", "soc_pv", source=src_cyc, color="#ff7f0e", line_width=2, legend_label="with PV")
    soc_min_line = Span(location=model.vehicle.soc_min, dimension="width", line_color="red",
                        line_dash="dotted")
    f_soc.add_layout(soc_min_line)
    f_soc.legend.location = "bottom_left"
    f_soc.legend.background_fill_alpha = 0.75
    f_soc.legend.label_text_font_size = "8.5pt"

    return SimpleNamespace(src_seg=src_seg, src_stop=src_stop, src_cyc=src_cyc, src_mon=src_mon,
                           f_irr=f_irr, f_map=f_map, mapper=mapper, f_cyc=f_cyc, f_soc=f_soc,
                           soc_min_line=soc_min_line)


def _monthly_figure(src_mon: ColumnDataSource):
    """Monthly PV energy of the route-direction: all-sky and clear-sky bars, unshaded marks;
    the legend inside, above the bars (the y range keeps room for it)."""
    f_mon = figure(title="Monthly PV of the route (run, this PV)",
                   x_range=FactorRange(), height=330, y_axis_label="kWh", tools="save,reset",
                   y_range=DataRange1d(start=0, range_padding=0.4), name="monthly")
    f_mon.vbar(x=dodge("month", -0.18, range=f_mon.x_range), top="allsky", width=0.34, source=src_mon,
               color="#ff7f0e", legend_label="all-sky")
    f_mon.vbar(x=dodge("month", 0.18, range=f_mon.x_range), top="clearsky", width=0.34, source=src_mon,
               color="#1f77b4", legend_label="clear-sky")
    # the energy without buildings: a mark as wide as its bar, whatever the plot's width
    for offset, column_name, label in ((-0.18, "allsky_unshaded", {"legend_label": "without buildings"}),
                                       (0.18, "clearsky_unshaded", {})):
        f_mon.segment(x0=dodge("month", offset - 0.17, range=f_mon.x_range), y0=column_name,
                      x1=dodge("month", offset + 0.17, range=f_mon.x_range), y1=column_name,
                      source=src_mon, color="black", line_width=2, **label)
    f_mon.add_tools(HoverTool(tooltips=[("month", "@month"), ("all-sky", "@allsky{0,0} kWh"),
                                        ("clear-sky", "@clearsky{0,0} kWh"),
                                        ("shading loss", "@shading_loss{0.0%}")]))
    f_mon.legend.orientation = "horizontal"
    f_mon.legend.location = "top_left"
    f_mon.legend.background_fill_alpha = 0.75
    f_mon.legend.label_text_font_size = "8.5pt"
    f_mon.xaxis.major_label_text_font_size = "10pt"
    # month names slanted when the plot is too narrow for them side by side (a phone)
    f_mon.js_on_change("inner_width", CustomJS(args={"axis": f_mon.xaxis[0]}, code=(
        "const slant = cb_obj.inner_width < 60 * cb_obj.x_range.factors.length; "
        "axis.major_label_orientation = slant ? 0.9 : 'horizontal';")))
    return f_mon


#: one thread computes the trips of every session in turn (the model's caches are not shared
#: between threads); the page's event loop stays free to take the next control change
_EXECUTOR = ThreadPoolExecutor(max_workers=1, thread_name_prefix="vipvflow-app")

async def _written() -> None:
    """An awaitable for the session's pending writes: the events were sent in one message."""


@contextlib.contextmanager
def _one_message(doc):
    """Every change of the document made in the block reaches each page as ONE ``PATCH-DOC``
    message, so the page never shows a state between two of them (Bokeh's ``hold`` collects
    the events but still sends each in a message of its own).  Outside a server session
    (a test's document, ``bokeh.io``) it is a plain ``hold("combine")``."""
    session = getattr(getattr(doc, "session_context", None), "_session", None) if doc else None
    connections = list(getattr(session, "_subscribed_connections", None) or [])
    if doc is not None:
        doc.hold("combine")
    sent: dict = {}
    originals = {}
    try:
        yield
    finally:
        if doc is not None:
            for conn in connections:           # collect what unhold would send, per page
                originals[conn] = conn.send_patch_document
                conn.send_patch_document = (lambda event, conn=conn:
                                            sent.setdefault(conn, []).append(event) or _written())
            try:
                doc.unhold()
            finally:
                for conn, send in originals.items():
                    conn.send_patch_document = send
            pending = getattr(session, "_pending_writes", None)
            for conn, events in sent.items():
                write = conn._socket.send_message(conn.protocol.create("PATCH-DOC", events))
                if pending is not None:
                    pending.append(write)

_MODEL_LOCK = threading.Lock()


class Recompute:
    """The views' recomputation for one page, without a queue.

    :meth:`request` (a control's change) asks for it; requests that come while one waits
    (:data:`COALESCE_MS`) or computes are one request.  The computation reads the controls'
    values when it starts and runs in the app's computing thread; when it is done, its result
    is shown only if no control changed meanwhile: otherwise it is dropped and the latest
    values are computed at once.  Each result is shown as one document change, so the
    trip's numbers, the irradiance, the map, the driving cycle and the SoC always belong to
    the same settings.
    """

    #: ms a first request waits for the ones that follow it (a key held down, a drag)
    COALESCE_MS = 40

    def __init__(self, doc, compute, apply):
        self.doc, self.compute, self.apply = doc, compute, apply
        self.asked = 0            # requests so far
        self.busy = False         # a computation is running
        self.waiting = False      # a start is scheduled
        self.shown = 0            # results shown
        self.dropped = 0          # results dropped as stale

    def request(self, attr, old, new) -> None:
        """Ask for the views of the controls' current values (a Bokeh ``on_change`` callback)."""
        self.asked += 1
        if not self.busy and not self.waiting:
            self.waiting = True
            self.doc.add_timeout_callback(self._start, self.COALESCE_MS)

    def _start(self) -> None:
        self.waiting = False
        if self.busy:
            return
        self.busy = True
        ticket = self.asked
        job = self.compute(prepare_only=True)          # the controls' values, read now
        future = _EXECUTOR.submit(job)
        future.add_done_callback(lambda f: self._back(ticket, f))

    def _back(self, ticket: int, future) -> None:       # in the computing thread
        try:
            self.doc.add_next_tick_callback(partial(self._done, ticket, future))
        except Exception:  # noqa: BLE001 - the page was closed meanwhile
            pass

    def _done(self, ticket: int, future) -> None:
        self.busy = False
        if ticket != self.asked:                        # stale: the controls moved on
            self.dropped += 1
            self._start()
            return
        self.shown += 1
        self.apply(future.result())


def _wire(model: TripModel, c: SimpleNamespace, v: SimpleNamespace):
    """The computation of the views and how its result is shown: ``compute()`` reads the
    controls and computes (``compute(prepare_only=True)``: reads them and returns the job,
    to run in another thread); ``apply(result)`` shows a result as one document change."""
    run_pv = model.run_pv_choice

    def settings() -> dict:
        rid, d = c.route.value.rsplit("|", 1)
        return {"pv": PVChoice(technology=c.tech.value, mode=c.mode.value, kwp=float(c.kwp.value),
                               area_m2=float(c.area.value) if c.size_by.active == 1 else None,
                               performance_ratio=float(c.pr.value), losses_percent=float(c.losses.value),
                               inverter_efficiency=run_pv.inverter_efficiency),
                "route_id": rid, "direction_id": int(d), "date": c.date.value,
                "depart": int(c.depart.value), "aux_kw": float(c.aux.value), "soc_min": float(c.soc.value)}

    def job(p: dict):
        try:
            with _MODEL_LOCK:
                res = model.trip(p["route_id"], p["direction_id"], p["date"], depart=p["depart"],
                                 pv=p["pv"], aux_kw=p["aux_kw"], soc_min=p["soc_min"])
                mon = model.monthly(p["route_id"], p["direction_id"], p["pv"])
                fleet = model.monthly(None, None, p["pv"])
            return {"settings": p, "trip": res, "monthly": mon, "fleet": fleet}
        except Exception as exc:  # noqa: BLE001 - shown in the page; the session stays usable
            log.exception("recompute failed")
            return {"settings": p, "error": exc}

    def compute(prepare_only: bool = False):
        p = settings()
        return partial(job, p) if prepare_only else job(p)

    def apply(result: dict) -> None:
        with _one_message(c.numbers.document):    # every change below: one message to the page
            applicable(c)
            if "error" in result:
                c.error.text = f'<div id="app-error" style="color:#b00">{html.escape(str(result["error"]))}</div>'
                return
            res = result["trip"]
            s = res.segments
            v.src_seg.data = {"time": s["time"].to_numpy(), "direct": s["direct"].to_numpy(),
                              "diffuse": s["diffuse"].to_numpy(), "reflected": s["reflected"].to_numpy(),
                              "total": s["total"].to_numpy(), "unshaded": s["unshaded"].to_numpy(),
                              "x": s["x"].to_numpy(), "y": s["y"].to_numpy(),
                              "x_end": s["x_end"].to_numpy(), "y_end": s["y_end"].to_numpy(),
                              "energy_wh": 1000.0 * s["energy_kwh"].to_numpy()}
            st = s[s["stop"]]
            v.src_stop.data = {"x": (0.5 * (st["x"] + st["x_end"])).to_numpy(),
                               "y": (0.5 * (st["y"] + st["y_end"])).to_numpy(),
                               "time": st["time"].to_numpy(), "total": st["total"].to_numpy(),
                               "dwell_s": st["dwell_s"].to_numpy(),
                               "energy_wh": 1000.0 * st["energy_kwh"].to_numpy(),
                               "size": 4.0 + np.sqrt(st["dwell_s"].to_numpy())}
            # one scale for the light with and without buildings: the shade shows as dark
            v.mapper.high = max(float(s["unshaded"].max()) if len(s) else 0.0, 1.0)
            cyc = res.cycle
            v.src_cyc.data = {"time": cyc["time"].to_numpy(), "speed_kmh": cyc["speed_kmh"].to_numpy(),
                              "soc": cyc["soc"].to_numpy(), "soc_pv": cyc["soc_pv"].to_numpy()}
            v.soc_min_line.location = float(result["settings"]["soc_min"])
            mon = result["monthly"].copy()
            mon["month"] = month_labels(mon["month"])
            v.f_mon.x_range.factors = list(mon["month"])
            v.src_mon.data = {k: list(mon[k]) for k in v.src_mon.data}
            c.numbers.text = numbers_html(res, _fleet_line(model, result["fleet"]))
            c.error.text = ""

    return compute, apply


def _fleet_line(model: TripModel, fleet: pd.DataFrame) -> dict | None:
    """The fleet's figures of the run rescaled to the chosen PV (:meth:`TripModel.monthly`)."""
    if not len(fleet):
        return None
    tot = fleet[["allsky", "clearsky", "allsky_unshaded", "consumption"]].sum()
    loss = fleet["shading_loss"] * fleet["allsky_unshaded"]
    return {"run": model.summary, "allsky": tot["allsky"], "clearsky": tot["clearsky"],
            "shading_loss": (float(loss.sum() / tot["allsky_unshaded"]) if tot["allsky_unshaded"] > 0
                             else float("nan")),
            "share": tot["allsky"] / tot["consumption"] if tot["consumption"] else np.nan,
            "consumption": tot["consumption"]}


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
                     f"diffuse model {model.cfg.irradiance.diffuse_model}</div>{yields}"),
               sizing_mode="stretch_width", name="header",
               stylesheets=[":host code { overflow-wrap: anywhere; }"])
