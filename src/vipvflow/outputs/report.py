"""``report.html``: the run's summary table, how to read it, its inputs and CRS, and its figures
(PNG, also in ``figures/``).

The maps show each segment's year (:mod:`vipvflow.simulation.annual`) over the building
footprints of the city model (:func:`vipvflow.inputs.city.footprints.building_footprints`): the
whole network, and a close-up of the street canyons (where the roofs see least sky).
"""
from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import numpy as np
import pandas as pd

from ..models.loss import shading_loss
from ..simulation.dictionary import SUMMARY, render_html
from ..store import RunDir, write_bytes, write_text

#: colour limits of the maps: these percentiles of the segments' values (a few segments with
#: a stop or a tunnel-like canyon would otherwise flatten the rest)
MAP_PERCENTILES = (2.0, 98.0)

#: side of the close-up map (m)
CLOSE_UP_M = 1200.0



def _pyplot():
    """matplotlib's pyplot on its file-only backend, loaded where a figure is drawn (a run's
    workers draw them: the command's own process then never loads matplotlib, ~0.6 s of
    a core taken from the workers while they compute)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def figure_png(make, *args) -> bytes:
    """The figure ``make(*args)`` as PNG bytes (a task the run's workers can take)."""
    fig = make(*args)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    _pyplot().close(fig)
    return buf.getvalue()


def _loaded() -> bool:
    """A task that loads this module and matplotlib on a worker."""
    return _pyplot() is not None


class Figures:
    """The report's figures, drawn as they are added: on the workers of *client* while the
    reduce goes on (a figure takes a core for 0.1-0.6 s, mostly text layout and PNG
    encoding), or in this process without one.  :meth:`results` waits for them."""

    def __init__(self, client=None):
        self._client = client
        self._items: list[tuple[str, str, object]] = []
        # each worker loads matplotlib (about half a second) while it waits for the data
        # (held until the figures are in, never waited for: a worker gone meanwhile is no
        # matter)
        self._loading = [] if client is None else [
            client.submit(_loaded, workers=[w], allow_other_workers=True, pure=False,
                          key=f"figure-load-{i}")
            for i, w in enumerate(client.scheduler_info()["workers"])]

    def add(self, name: str, title: str, make, *args) -> None:
        if self._client is not None:
            from ..simulation.partition import handing_back

            job = self._client.submit(handing_back, figure_png, make, *args, pure=False,
                                      key=f"figure-{name}")
        else:
            job = figure_png(make, *args)
        self._items.append((name, title, job))

    def results(self) -> list[tuple[str, str, bytes]]:
        """(name, title, PNG bytes) of every figure, in the order added."""
        jobs = [job for _, _, job in self._items]
        data = self._client.gather(jobs) if self._client is not None else jobs
        self._loading = []
        return [(name, title, png) for (name, title, _), png in zip(self._items, data)]


def _months(values) -> pd.DatetimeIndex:
    """Months given as ``YYYY-MM`` strings or dates, as timestamps of their first day."""
    return pd.DatetimeIndex(pd.to_datetime(pd.Series(values).astype(str).str.slice(0, 7), format="%Y-%m"))


def fig_monthly(monthly: pd.DataFrame, summary: dict):
    """Monthly all-sky yield of the fleet (kWh/kWp), stacked: driving, at terminals between
    trips, parked outside the blocks; driving + terminals is the in-service yield, the top
    of each bar the whole day.  Black marks: driving without buildings (the gap to the
    driving bar is the shading loss on the road).  Runs without the split (driving only)
    show the driving bar alone."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9.5, 4))
    x = np.arange(len(monthly))
    kwp = summary["kwp_per_bus"] * summary["buses"]
    split = {"pv_kwh_driving", "pv_kwh_layover", "pv_kwh_parked"} <= set(monthly.columns)
    driving = (monthly["pv_kwh_driving"] if split else monthly["pv_kwh"]).to_numpy(float) / kwp
    ax.bar(x, driving, 0.6, label="driving", color="#4285f4")
    if split:
        layover = monthly["pv_kwh_layover"].to_numpy(float) / kwp
        parked = monthly["pv_kwh_parked"].to_numpy(float) / kwp
        ax.bar(x, layover, 0.6, bottom=driving, color="#9fc5f8",
               label="+ at terminals between trips (top: in service)")
        ax.bar(x, parked, 0.6, bottom=driving + layover, color="#c8c8c8",
               label="+ parked outside service (top: whole day)")
    ax.plot(x, monthly["pv_kwh_unshaded"].to_numpy(float) / kwp, "k_", ms=18,
            label="driving, without buildings")
    ax.set_xticks(x, _months(monthly["month"]).strftime("%b"))
    ax.set_xlabel("month")
    ax.set_ylabel("all-sky PV energy (kWh per installed kWp)")
    title = "Monthly PV yield of the fleet"
    keys = ("kwh_per_kwp_driving", "kwh_per_kwp_in_service", "kwh_per_kwp_whole_day")
    if split and all(summary.get(k) is not None for k in keys):
        title += ("\nthe year: driving {:.0f}, in service {:.0f}, whole day {:.0f} kWh/kWp"
                  .format(*(summary[k] for k in keys)))
    ax.set_title(title, fontsize=10)
    handles, labels = ax.get_legend_handles_labels()
    ax.legend(handles[::-1], labels[::-1], loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return fig


def _segment_lines(segments) -> list[np.ndarray]:
    """Each segment's vertices as an (n, 2) array of x, y."""
    import shapely

    geoms = np.asarray(segments.geometry.values)
    xy, index = shapely.get_coordinates(geoms, return_index=True)
    # one array per segment, an empty one for an empty line
    return np.split(xy, np.cumsum(np.bincount(index, minlength=len(geoms)))[:-1])


def _near(shapes: list[np.ndarray], window, margin: float) -> np.ndarray:
    """Which of *shapes* ((n, 2) arrays) have their bounding box within *margin* of *window*
    (xmin, ymin, xmax, ymax): the close-up draws only those (the others lie outside its view,
    further than a stroke reaches into it)."""
    sizes = np.array([len(a) for a in shapes], dtype=np.int64)
    near = np.zeros(len(shapes), bool)
    if not sizes.any():
        return near
    xy = np.concatenate([np.asarray(a, dtype=np.float64).reshape(-1, 2) for a in shapes])
    start = (np.cumsum(sizes) - sizes)[sizes > 0]           # shapes without points stay out
    lo, hi = np.minimum.reduceat(xy, start), np.maximum.reduceat(xy, start)
    near[sizes > 0] = ((hi[:, 0] >= window[0] - margin) & (lo[:, 0] <= window[2] + margin)
                       & (hi[:, 1] >= window[1] - margin) & (lo[:, 1] <= window[3] + margin))
    return near


def _robust_limits(values: np.ndarray) -> tuple[float, float]:
    v = values[np.isfinite(values)]
    if not len(v):
        return 0.0, 1.0
    lo, hi = np.percentile(v, MAP_PERCENTILES)
    return (float(lo), float(hi)) if hi > lo else (float(lo) - 0.5, float(lo) + 0.5)


def close_up_window(segments, side_m: float = CLOSE_UP_M) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of a square of *side_m* around the street canyons: the
    middle of the 5 % of segments whose roofs see the least sky (``svf``), or of the most
    shaded ones when the run has no sky view factors."""
    import shapely

    mid = shapely.get_coordinates(shapely.line_interpolate_point(
        np.asarray(segments.geometry.values), 0.5, normalized=True))
    key = segments["svf"] if "svf" in segments and segments["svf"].notna().any() else -segments["shading_loss"]
    key = key.fillna(key.max()).to_numpy()
    n = max(1, int(0.05 * len(key)))
    cx, cy = np.median(mid[np.argsort(key, kind="stable")[:n]], axis=0)
    h = side_m / 2
    return cx - h, cy - h, cx + h, cy + h


def fig_map(segments, column: str, label: str, cmap: str, title: str, footprints=(), crs_label: str = "",
            scale: float = 1.0):
    """The segments coloured by *column* (x *scale*) over the building footprints: the whole
    network and a close-up of the canyons, colour limits at :data:`MAP_PERCENTILES`."""
    from matplotlib.collections import LineCollection, PolyCollection
    from matplotlib.patches import Rectangle

    plt = _pyplot()
    values = segments[column].to_numpy(np.float64) * scale
    vmin, vmax = _robust_limits(values)
    lines = _segment_lines(segments)
    window = close_up_window(segments)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.2), gridspec_kw={"width_ratios": [1.6, 1]},
                             layout="constrained")
    # the close-up's shapes: those reaching within a tenth of its side of its view
    near_lines = _near(lines, window, 0.1 * (window[2] - window[0]))
    near_prints = _near(list(footprints), window, 0.1 * (window[2] - window[0]))
    for ax, zoom in zip(axes, (False, True)):
        prints = [f for f, near in zip(footprints, near_prints) if near] if zoom else footprints
        if len(prints):
            ax.add_collection(PolyCollection(prints, facecolors="#d4d4d4", edgecolors="#a8a8a8",
                                             linewidths=0.3, zorder=1))
        lc = LineCollection([a for a, near in zip(lines, near_lines) if near] if zoom else lines,
                            array=values[near_lines] if zoom else values, cmap=cmap,
                            linewidths=4.0 if zoom else 1.8, zorder=2, capstyle="butt")
        lc.set_clim(vmin, vmax)
        ax.add_collection(lc)
        ax.set_aspect("equal")
        ax.ticklabel_format(useOffset=False, style="plain")
        ax.tick_params(labelsize=8)
        if zoom:
            ax.set_xlim(window[0], window[2])
            ax.set_ylim(window[1], window[3])
            ax.set_title("close-up: the street canyons (least sky seen)", fontsize=10)
        else:
            xy = np.concatenate(lines)
            pad = 0.03 * max(np.ptp(xy[:, 0]), np.ptp(xy[:, 1]))
            ax.set_xlim(xy[:, 0].min() - pad, xy[:, 0].max() + pad)
            ax.set_ylim(xy[:, 1].min() - pad, xy[:, 1].max() + pad)
            ax.add_patch(Rectangle(window[:2], window[2] - window[0], window[3] - window[1], fill=False,
                                   edgecolor="#d62728", linewidth=1.2, zorder=3))
            ax.set_title("the simulated network (red: close-up)", fontsize=10)
        ax.set_xlabel(f"easting (m), {crs_label}" if crs_label else "easting (m)", fontsize=9)
        ax.set_ylabel("northing (m)", fontsize=9)
    fig.colorbar(lc, ax=axes, label=label, extend="both", shrink=0.8)
    fig.suptitle(title)
    return fig


def fig_cycles(monthly: pd.DataFrame):
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.bar(_months(monthly["month"]).strftime("%b"), monthly["avoided_charging_cycles"], color="#0f9d58")
    ax.set_ylabel("avoided charging cycles (fleet)")
    ax.set_title("Charging cycles PV saves the chargers (the battery's balance)")
    return fig


def fig_balance(monthly: pd.DataFrame):
    """Per month: the PV the batteries take and the PV curtailed (battery full), and the
    block-days the charging plan cannot serve."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(9.5, 3.8))
    x = np.arange(len(monthly))
    usable = monthly["pv_kwh_usable"].to_numpy(float) / 1000.0
    curtailed = monthly["pv_kwh_curtailed"].to_numpy(float) / 1000.0
    ax.bar(x, usable, 0.6, color="#4285f4", label="taken by the batteries")
    ax.bar(x, curtailed, 0.6, bottom=usable, color="#c8c8c8", label="curtailed (battery full)")
    ax.set_xticks(x, _months(monthly["month"]).strftime("%b"))
    ax.set_ylabel("PV energy (MWh)")
    bad = monthly["block_days_infeasible"].to_numpy(float)
    ax2 = ax.twinx()
    ax2.plot(x, bad, "o-", color="#d62728", label="block-days the plan cannot serve")
    ax2.set_ylabel("infeasible block-days", color="#d62728")
    ax2.set_ylim(0, max(1.0, bad.max() * 1.2))
    h1, l1 = ax.get_legend_handles_labels()
    h2, l2 = ax2.get_legend_handles_labels()
    ax.legend(h1 + h2, l1 + l2, loc="upper left", bbox_to_anchor=(1.08, 1.0), fontsize=8)
    ax.set_title(f"The batteries' month: PV taken and curtailed; block-days not served "
                 f"({int(bad.sum())} in all)", fontsize=10)
    return fig


def fig_soc(traces: pd.DataFrame, soc_min: float):
    """The SoC through a typical and the worst block-day, with PV and without, under the
    charging plan (``traces`` from the reduce: ``which, block_id, service_date, t_utc,
    soc_pv, soc_nopv``)."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 3.8), sharey=True)
    for ax, which in zip(axes, ("typical", "worst")):
        t = traces[traces["which"] == which]
        if t.empty:
            ax.set_visible(False)
            continue
        hours = (t["t_utc"].to_numpy(float) - t["t_utc"].min()) / 3600.0
        ax.plot(hours, 100 * t["soc_nopv"], color="#7f7f7f", label="without PV")
        ax.plot(hours, 100 * t["soc_pv"], color="#ff7f0e", label="with PV")
        ax.axhline(100 * soc_min, color="#d62728", ls="--", lw=1, label="SoC minimum")
        first = pd.Timestamp(t["t_utc"].min(), unit="s", tz="UTC")
        ax.set_xlabel(f"hours after the first departure ({first:%H:%M} UTC)")
        ax.set_title(f"{which} block-day: {t['block_id'].iloc[0]}, "
                     f"{pd.Timestamp(t['service_date'].iloc[0]):%Y-%m-%d}", fontsize=10)
    axes[0].set_ylabel("state of charge (%)")
    axes[0].legend(loc="lower left", fontsize=8)
    fig.suptitle("Battery state of charge through the day, under the charging plan")
    return fig


def fig_ranking(ranking: pd.DataFrame, top: int = 12):
    """The blocks and routes where PV saves the most grid energy per kWp (and their payback)."""
    plt = _pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.2))
    for ax, kind in zip(axes, ("block", "route")):
        r = ranking[ranking["kind"] == kind].sort_values("rank").head(top)
        if r.empty:
            ax.set_visible(False)
            continue
        y = np.arange(len(r))[::-1]
        ax.barh(y, r["kwh_avoided_per_kwp_year"], color="#0f9d58")
        ax.set_yticks(y, [f"{n} ({'never' if not np.isfinite(p) else f'{p:.1f} y'})"
                          for n, p in zip(r["name"], r["payback_years"])], fontsize=8)
        ax.set_xlabel("grid energy avoided (kWh per kWp and year)")
        ax.set_title(f"{kind}s: where PV pays first (payback)", fontsize=10)
    fig.suptitle("Which buses to equip: grid energy avoided per installed kWp")
    fig.tight_layout()
    return fig


def fig_hourly(hp: pd.DataFrame):
    plt = _pyplot()
    hp = hp.assign(month=_months(hp["month"]))
    grid = hp.pivot_table(index="hour", columns="month", values="g_total", aggfunc="sum")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    im = ax.imshow(grid.to_numpy(), aspect="auto", origin="lower", cmap="inferno",
                   extent=[0.5, grid.shape[1] + 0.5, grid.index.min() - 0.5, grid.index.max() + 0.5])
    ax.set_xticks(range(1, grid.shape[1] + 1), pd.DatetimeIndex(grid.columns).strftime("%b"))
    ax.set_ylabel("local hour")
    fig.colorbar(im, ax=ax, label="mean roof irradiance in service (W/m²)")
    ax.set_title("Daily irradiance pattern by hour and month (all-sky)")
    return fig


def fig_routes(rm: pd.DataFrame, coverage: float | None = None):
    """Per route and direction: the driving PV's share of the trips' consumption
    (coverage_driving) and the shading loss; the fleet's headline coverage in the title."""
    plt = _pyplot()
    rm = rm.assign(trip_headsign=rm["trip_headsign"] if "trip_headsign" in rm else "")
    r = rm.groupby(["route_short_name", "direction_id"], dropna=False).agg(
        trips=("trips", "sum"), pv_kwh=("pv_kwh", "sum"), consumption_kwh=("consumption_kwh", "sum"),
        pv_kwh_unshaded=("pv_kwh_unshaded", "sum"), pv_kwh_direct=("pv_kwh_direct", "sum"),
        pv_kwh_diffuse=("pv_kwh_diffuse", "sum"),
        headsign=("trip_headsign", lambda v: v.dropna().mode().iloc[0] if v.notna().any() else "")).reset_index()
    # the names passengers know: "S5 to Ostheim" (the direction's number without a headsign)
    labels = [f"{a} to {h}" if h else f"{a} / dir {b}"
              for a, b, h in zip(r["route_short_name"], r["direction_id"], r["headsign"])]
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    ax[0].bar(labels, 100 * r["pv_kwh"] / r["consumption_kwh"], color="#4285f4")
    ax[0].set_ylabel("driving PV / trips' consumption (%)")
    ax[1].bar(labels, 100 * shading_loss(r["pv_kwh_direct"], r["pv_kwh_diffuse"], r["pv_kwh_unshaded"]),
              color="#db4437")
    ax[1].set_ylabel("shading loss (%)")
    for a in ax:
        a.tick_params(axis="x", rotation=30)
    title = "Route comparison (driving)"
    if coverage is not None:
        title += (f"; the fleet: the PV the batteries take covers {100 * coverage:.2f} % "
                  "of the demand in service")
    fig.suptitle(title, fontsize=11)
    return fig


# ---------------------------------------------------------------------------- the table
#: the summary table: section -> key -> label, in the order shown; the unit and the meaning
#: (on hover) are the data dictionary's (:data:`SUMMARY`), fractions shown as %
_SECTIONS = {
    "Fleet and network": {
        "routes": "routes",
        "buses": "buses (most vehicle blocks on one day)",
        "trips": "trips simulated",
        "segments": "road segments",
        "passes": "segment passes evaluated",
        "service_hours_per_bus_year": "service time per bus",
    },
    "PV yield": {
        "kwp_per_bus": "PV installed per bus",
        "kwh_per_kwp_usable": "specific yield the batteries take (all-sky)",
        "kwh_per_kwp_harvested": "specific yield harvested (fleet.harvest's time)",
        "kwh_per_kwp_driving": "of which while driving, all-sky",
        "kwh_per_kwp_driving_clearsky": "while driving, clear-sky",
        "kwh_per_kwp_in_service": "in service (driving + layovers), all-sky",
        "kwh_per_kwp_whole_day": "over the whole day (+ parked), all-sky",
        "pv_kwh_usable": "PV energy the batteries take",
        "pv_kwh_curtailed": "PV energy the batteries could not take (curtailed)",
        "pv_kwh_driving": "PV energy while driving, all-sky",
        "pv_kwh_layover": "PV energy at terminals between trips",
        "pv_kwh_parked": "PV energy parked at the depot",
        "pv_kwh_driving_clearsky": "PV energy while driving, under a cloudless sky",
        "pv_kwh_driving_unshaded": "PV energy while driving, all-sky, without buildings",
    },
    "Buildings": {
        "shading_loss_allsky": "shading loss, all-sky",
        "shading_loss_clearsky": "shading loss, clear-sky",
        "shading_loss_allsky_without_trees": "shading loss by the buildings alone, all-sky",
        "tree_shading_loss_allsky": "of which the tree crowns add, all-sky",
        "trees_in_city_model": "trees in the city model",
        "reflection_gain_allsky": "gain from reflections, all-sky",
        "net_building_effect_allsky": "net effect of the buildings, all-sky",
        "route_km_in_city_model_share": "route-km inside the city model",
        "shading_loss_allsky_in_city_model": "shading loss inside the city model, all-sky",
    },
    "Light": {
        "site_ghi_kwh_m2_year": "global horizontal irradiation of the site",
        "ghi_in_service_kwh_m2_per_bus": "of which while a bus is in service",
        "roof_irradiation_unshaded_kwh_m2_per_bus": "on a bus roof, without buildings",
        "roof_irradiation_kwh_m2_per_bus": "on a bus roof, with buildings",
    },
    "Battery and charging plan": {
        "fleet_demand_in_service_mwh": "battery energy the fleet uses in service (trips and layovers)",
        "coverage": "share of it the PV the batteries take covers",
        "fleet_demand_driving_mwh": "battery energy of the trips alone",
        "coverage_driving": "share of it the driving PV covers (the paper's accounting)",
        "block_days": "block-days (a bus's day of service)",
        "block_days_infeasible": "block-days the charging plan cannot serve, with PV",
        "block_days_infeasible_without_pv": "the same without PV",
        "soc_lowest_pv": "lowest state of charge of any block-day, with PV",
        "grid_kwh_avoided": "grid energy PV avoids at the chargers",
        "grid_kwh_avoided_depot": "of which at the depot",
        "grid_kwh_avoided_opportunity": "of which at the terminals",
    },
    "Energy and cost": {
        "avoided_charging_cycles_fleet": "charging cycles avoided, fleet (the battery's balance)",
        "avoided_charging_cycles_per_bus": "charging cycles avoided per bus (the battery's balance)",
        "avoided_charging_cycles_per_bus_paper": "the same by the paper's formula (PV taken / cycle)",
        "system_cost_eur_per_bus": "PV system cost per bus",
        "payback_years": "simple payback (grid energy avoided x tariff)",
        "payback_years_paper": "the same from the PV the batteries take (the paper's)",
    },
    "Model": {
        "pv_mode": "PV model",
        "diffuse_model": "sky diffuse model",
        "annualised_from_months": "yearly figures scaled from fewer months",
    },
}
#: decimals of the table's values where the default (0; 1 for a percentage) would hide them
_DECIMALS = {"kwp_per_bus": 2, "coverage": 2, "coverage_driving": 2,
             "avoided_charging_cycles_per_bus": 1, "avoided_charging_cycles_per_bus_paper": 1,
             "payback_years": 1, "payback_years_paper": 1, "soc_lowest_pv": 1}
#: how a data-dictionary unit reads in the table (sums over the run say so)
_UNIT_SHOWN = {"count": "", "fraction": "%", "kWh": "kWh (simulated months)",
               "h": "h (simulated months)"}


def _unit(key: str) -> tuple[str, bool]:
    """The unit *key* is shown in and whether its value is shown as a percentage."""
    unit = SUMMARY[key].unit if key in SUMMARY else ""
    return _UNIT_SHOWN.get(unit, unit).replace("m2", "m²"), unit == "fraction"


def _fmt(v, decimals: int | None = None, percent: bool = False) -> str:
    """A value for people: thousands separators, % for fractions, *decimals* after the
    point (``None``: 0 from 100 up, 2 from 1, 3 below)."""
    if v is None:
        return "n/a"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if not isinstance(v, (int, float, np.integer, np.floating)):
        return str(v)
    if not np.isfinite(v):
        return "n/a"
    if decimals is None:
        size = abs(100 * v if percent else v)
        decimals = 0 if size >= 100 else 2 if size >= 1 else 3
    if percent:
        return f"{100 * v:,.{decimals}f}"
    if isinstance(v, (int, np.integer)):
        return f"{v:,d}"
    return f"{v:,.{decimals}f}"


def summary_table(summary: dict) -> str:
    """The summary as an HTML table by section (value, unit; the meaning on hover); keys
    not in the curated rows are listed under "More" with the data dictionary's unit."""
    rows, shown = [], set()
    for section, labels in _SECTIONS.items():
        keys = [k for k in labels if k in summary]
        if keys:
            rows.append(f"<tr><th colspan='3' class='sec'>{html.escape(section)}</th></tr>")
        rows += [_summary_row(summary, k, html.escape(labels[k]), _DECIMALS.get(k)) for k in keys]
        shown.update(keys)
    more = [k for k, v in summary.items() if k not in shown and not isinstance(v, (dict, list))
            and k not in ("scenario", "year")]
    if more:
        rows.append("<tr><th colspan='3' class='sec'>More (see <a href='#data-dictionary'>the data dictionary</a>)</th></tr>")
        rows += [_summary_row(summary, k, f"<code>{html.escape(k)}</code>", None, auto=True)
                 for k in more]
    return f"<table class='summary'>{''.join(rows)}</table>"


def _summary_row(summary: dict, key: str, label_html: str, decimals: int | None,
                 auto: bool = False) -> str:
    """One row of the summary table: label, value (*decimals*, else 1 for a percentage and 0
    otherwise, or as :func:`_fmt` sees fit with *auto*), unit; the meaning on hover."""
    unit, percent = _unit(key)
    if decimals is None and not auto:
        decimals = 1 if percent else 0
    meaning = SUMMARY[key].meaning if key in SUMMARY else ""
    return (f"<tr title='{html.escape(meaning)}'><td>{label_html}</td>"
            f"<td class='num'>{html.escape(_fmt(summary[key], decimals, percent))}</td>"
            f"<td>{html.escape(unit)}</td></tr>")


def _how_to_read(summary: dict) -> str:
    s = summary
    pct = lambda k: _fmt(s.get(k), 1, True)  # noqa: E731
    return (
        "<p>Every bus of the timetable carries the same PV roof. For each short road segment "
        "(10 m by default) a bus passes, vipvflow computes the sun and sky light on the roof from CAMS radiation, with the "
        "3D city model's buildings casting shadows, hiding sky and reflecting light, and turns it "
        "into PV energy. <b>Specific yield</b> is the PV energy per installed kWp in a year: "
        f"{_fmt(s.get('kwh_per_kwp_usable'), 0)} kWh/kWp is what the batteries take, the figure "
        "coverage, cycles and payback rest on. The roofs harvest "
        f"{_fmt(s.get('kwh_per_kwp_driving'), 0)} kWh/kWp under the real (all-sky) weather "
        f"({_fmt(s.get('kwh_per_kwp_driving_clearsky'), 0)} under a cloudless sky) in the minutes "
        "the buses drive their trips, and keep harvesting while a bus stands at a terminal "
        "between trips and while it is parked: "
        f"{_fmt(s.get('kwh_per_kwp_in_service'), 0)} kWh/kWp in service (driving and layovers) and "
        f"{_fmt(s.get('kwh_per_kwp_whole_day'), 0)} over the whole day (fleet.harvest: "
        f"{html.escape(str(s.get('harvest', 'driving')))}); a full battery takes nothing, so "
        "some of it is curtailed. Each bus's day is run through its battery under the charging "
        "plan (depot, terminals): the grid energy PV saves there gives the avoided charging "
        f"cycles and the payback, and {_fmt(s.get('block_days_infeasible'))} of "
        f"{_fmt(s.get('block_days'))} block-days cannot be served by the plan (the SoC would "
        "fall below its minimum). A bus roof is partly in the streets' shade, so it collects "
        "less than a fixed panel at the site would. The <b>shading loss</b> "
        f"({pct('shading_loss_allsky')} %) is the direct and sky light the buildings take away; the "
        f"light they reflect onto the roof is counted apart ({pct('reflection_gain_allsky')} %). "
        "Yearly figures are per bus or per kWp; totals marked \"simulated months\" are sums over "
        "the run. On the maps each segment shows the year of a bus that spent all its service "
        "hours in that segment's light, so a street's colour does not depend on how many buses "
        "use it or how long they stop there. Every column of the output files is explained, with "
        "its unit, in <a href='#data-dictionary'>the data dictionary</a> at the end of this report "
        "and in the files' own metadata.</p>")


def _inputs_table(cfg, crs_label: str, tiles: int | None) -> str:
    rows = []
    if cfg is not None:
        inp = cfg.inputs
        rows += [("scenario", cfg.scenario), ("configuration", getattr(cfg, "_source", "")),
                 ("CityGML", ", ".join(str(p) for p in inp.citygml) or "-"),
                 ("GTFS feed", str(inp.gtfs) if inp.gtfs else "-"),
                 ("CAMS radiation", ", ".join(str(p) for p in inp.cams) or "-"),
                 ("data directory", str(cfg.data_dir)),
                 ("routes", ", ".join(cfg.run.routes) if cfg.run.routes else "all")]
    rows.append(("coordinate reference system", crs_label or "unknown"))
    if tiles:
        rows.append(("city tiles crossed", f"{tiles:,d}"))
    body = "".join(f"<tr><td>{html.escape(k)}</td><td><code>{html.escape(str(v))}</code></td></tr>"
                   for k, v in rows)
    return f"<table class='inputs'>{body}</table>"


def crs_label(crs) -> str:
    """``EPSG:2169 (LUREF / Luxembourg TM)`` for a pyproj CRS; '' for None."""
    if crs is None:
        return ""
    epsg = crs.to_epsg()
    return f"EPSG:{epsg} ({crs.name})" if epsg else crs.name


def _mapped(segments):
    """The segments the maps show: those with passes."""
    if "n_passes" in segments:
        segments = segments[segments["n_passes"].fillna(0) > 0]
    return segments


#: the maps: name -> (title, column, colour bar label, colour map, figure title, scale)
MAPS = {
    "map_yield": ("Yield per segment", "kwh_per_kwp_year", "specific yield (kWh/kWp per year)",
                  "viridis", "PV yield of a bus in each segment's light, all-sky (kWh/kWp per year)", 1.0),
    "map_shading": ("Shading loss per segment", "shading_loss", "shading loss, all-sky (%)", "magma_r",
                    "Direct and sky light the buildings take away, all-sky (%)", 100.0),
}


def map_figure(run_dir: str, data_dir: str | None, name: str):
    """The map *name* (:data:`MAPS`) of the run's ``segments.parquet`` over the building
    footprints of the city model in *data_dir* (none without)."""
    import geopandas as gpd
    import pyarrow.parquet as pq

    from ..inputs.city.footprints import building_footprints

    # the columns drawn (a network's 39 columns read whole were twice the memory of these)
    path = RunDir(run_dir).output("segments.parquet")
    column = MAPS[name][1]
    have = set(pq.read_schema(path).names)
    segments = _mapped(gpd.read_parquet(path, columns=[c for c in dict.fromkeys(
        ["geometry", "tile", "n_passes", "svf", "shading_loss", column]) if c in have]))
    footprints = []
    if data_dir is not None:
        xmin, ymin, xmax, ymax = segments.total_bounds
        tiles = sorted(segments["tile"].unique()) if "tile" in segments else None
        footprints = building_footprints(data_dir, tiles=tiles,
                                         bounds=(xmin - 200, ymin - 200, xmax + 200, ymax + 200))
    _, column, label, cmap, title, scale = MAPS[name]
    return fig_map(segments, column, label, cmap, title, footprints, crs_label(segments.crs), scale)


def add_maps(figures: Figures, run_dir: Path, cfg=None) -> None:
    """Start the maps of the run's ``segments.parquet`` (written) over the building
    footprints of *cfg*'s city model."""
    data_dir = str(cfg.data_dir) if cfg is not None else None
    for name, (title, *_) in MAPS.items():
        figures.add(name, title, map_figure, str(run_dir), data_dir, name)


def add_hourly(figures: Figures, hp) -> None:
    """Start the chart of the irradiance per hour and month (*hp*: ``hourly_pattern``)."""
    figures.add("hourly_pattern", "Daily irradiance pattern by hour and month", fig_hourly, hp)


def add_routes(figures: Figures, rm, coverage: float | None = None) -> None:
    """Start the chart comparing the routes (*rm*: ``route_month``; *coverage*: the fleet's)."""
    figures.add("routes", "Route comparison", fig_routes, rm, coverage)


def add_battery(figures: Figures, traces, soc_min: float) -> None:
    """Start the chart of the SoC through a typical and the worst block-day."""
    figures.add("soc_day", "Battery state of charge: a typical and the worst block-day", fig_soc,
                traces, soc_min)


def add_ranking(figures: Figures, ranking) -> None:
    """Start the chart of the blocks and routes where PV pays first (``ranking.parquet``)."""
    figures.add("ranking", "Which buses to equip: grid energy avoided per kWp, and payback",
                fig_ranking, ranking)


def add_charts(figures: Figures, summary: dict, monthly) -> None:
    """Start the charts of the fleet's months (*monthly*, *summary*)."""
    figures.add("monthly_yield", ("Monthly yield: driving, in service and whole day (all-sky), "
                                  "with the shading loss on the road"), fig_monthly, monthly, summary)
    figures.add("battery_month", "PV the batteries take and curtail, and block-days not served, "
                "per month", fig_balance, monthly)
    figures.add("avoided_cycles", "Avoided charging cycles per month", fig_cycles, monthly)


#: the figures in the report's order
FIGURE_ORDER = ("monthly_yield", "battery_month", "soc_day", "ranking", "map_yield", "map_shading",
                "avoided_cycles", "hourly_pattern", "routes")


def write_report(run_dir: Path, summary: dict, figures: list[tuple[str, str, bytes]], cfg=None,
                 segments=None, model: dict | None = None, crs=None) -> Path:
    """Write ``report.html`` and ``figures/*.png``.

    *figures*: :meth:`Figures.results` (:func:`add_maps`, :func:`add_hourly`,
    :func:`add_routes`, :func:`add_charts`).  *segments*:
    the run's ``segments.parquet`` frame (each segment's year; its lines are not used);
    read from *run_dir* when not given. *crs*: the segments' CRS (that of *segments* when
    not given). *cfg*: the run's configuration (its inputs are listed). *model*: the extras
    of the run's ``city.glb`` (:func:`vipvflow.outputs.gltf.write_gltf`), linked with its
    counts."""
    import geopandas as gpd

    if segments is None:
        segments = gpd.read_parquet(run_dir / "segments.parquet")
    mapped = _mapped(segments)
    crs = crs_label(crs if crs is not None else getattr(mapped, "crs", None))
    tiles = sorted(mapped["tile"].unique()) if "tile" in mapped else None
    shown = {name: (title, png) for name, title, png in figures}
    parts = []
    for name in FIGURE_ORDER:
        title, png = shown[name]
        write_bytes(png, RunDir(run_dir).figures / f"{name}.png")
        parts.append(f"<h2>{html.escape(title)}</h2>"
                     f"<img alt='{name}' src='data:image/png;base64,{base64.b64encode(png).decode()}'>")
    title = f"{summary['scenario']} {summary['year']}"
    doc = f"""<!doctype html><html><head><meta charset="utf-8">
<title>vipvflow: {html.escape(title)}</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto;color:#222}}img{{max-width:100%}}
td,th{{text-align:left;padding:2px 10px}}td.num{{text-align:right;font-variant-numeric:tabular-nums}}
th.sec{{padding-top:10px;border-bottom:1px solid #ccc}}tr[title]:hover{{background:#f4f4f4}}
p{{line-height:1.45;max-width:900px}}details{{margin:4px 0}}summary{{cursor:pointer}}
table.dictionary td{{vertical-align:top;font-size:0.9em}}</style></head><body>
<h1>Bus-roof PV, fleet-year: {html.escape(title)}</h1>
<p>{html.escape(_model_note(summary))}</p>
<h2>How to read this</h2>{_how_to_read(summary)}
<h2>The charging plan</h2>{_plan_note(cfg, summary)}
<h2>Summary</h2>{summary_table(summary)}
<h2>Inputs</h2>{_inputs_table(cfg, crs, len(tiles) if tiles else None)}
{_model_3d(model)}
{''.join(parts)}
<h2 id="data-dictionary">Data dictionary</h2>{render_html()}</body></html>"""
    return write_text(doc, RunDir(run_dir).report)


def _plan_note(cfg, summary: dict) -> str:
    """The charging plan the battery's balance ran under, and the block-days it cannot serve."""
    parts = []
    if cfg is not None:
        d, o = cfg.charging.depot, cfg.charging.opportunity
        hours = "whenever parked" if d.hours is None else f"from {d.hours[0]:g} h to {d.hours[1]:g} h"
        parts.append(f"Depot: {d.power_kw:g} kW per bus, {hours}, efficiency {d.efficiency:g}, "
                     f"to SoC {_fmt(d.target_soc, 2) if d.target_soc is not None else 'soc_max'}.")
        if o.terminals is None:
            parts.append("No charging at terminals.")
        else:
            where = "every terminal" if o.terminals == "all" else "terminals " + ", ".join(o.terminals)
            parts.append(f"Terminals: {o.power_kw:g} kW at {where}, during layovers of at least "
                         f"{o.min_layover_min:g} min ({o.connect_min:g} min to dock), efficiency "
                         f"{o.efficiency:g}.")
    n_bad = summary.get("block_days_infeasible", 0)
    if n_bad:
        first = "; ".join(summary.get("infeasible_block_days_first") or [])
        parts.append(f"<b>{n_bad} of {summary.get('block_days')} block-days cannot be served</b> "
                     f"under this plan (first: {html.escape(first)}); block_day.parquet "
                     "(feasible, infeasible_at_utc, infeasible_soc) lists them all.")
    else:
        parts.append(f"The plan serves all {summary.get('block_days')} block-days.")
    parts.append("ranking.parquet ranks the blocks and routes by the grid energy PV avoids per "
                 "kWp, with the payback of one bus's system.")
    return "<p>" + " ".join(parts) + "</p>"


def _model_3d(model: dict | None) -> str:
    """The report's link to ``city.glb`` (nothing when the run has none)."""
    if not model:
        return ""
    scale = model.get("colour") or {}
    origin = ", ".join(f"{v:.0f}" for v in model.get("origin", []))
    return (f"<h2>3D model</h2><p><a href='city.glb'>city.glb</a> (glTF 2.0 binary; any glTF "
            f"viewer, Blender, or <code>trimesh.load</code>): the {model['buildings']:,} buildings "
            f"of the run's {len(model.get('tiles', [])):,} tiles and its {model['segments']:,} "
            f"route segments coloured by annual PV yield ({html.escape(str(scale.get('column')))}, "
            f"viridis from {scale.get('min', 0):.0f} to {scale.get('max', 0):.0f} "
            f"{html.escape(str(scale.get('unit', '')))}). Coordinates: "
            f"{html.escape(str(model.get('crs')))} minus the origin ({origin}) m, stated in the "
            "file's extras. Again or elsewhere: <code>vipvflow export gltf RUN_DIR --out "
            "city.glb</code>.</p>")


def _model_note(summary: dict) -> str:
    """What the figures mean: the diffuse model of the run and the shading-loss definition."""
    model = summary.get("diffuse_model", "sky_view_factor")
    diffuse = ("diffuse light = DHI x the sky view factor of each roof point (the sky the "
               "buildings leave open)" if model == "sky_view_factor" else
               "diffuse light = DHI (1 + cos tilt) / 2, the paper's isotropic sky: the sky the "
               "buildings hide is counted as open (an upper bound in streets)")
    return (f"Diffuse model: {model}: {diffuse}. Shading loss = 1 - (direct + diffuse) / "
            "unshaded (sun and sky the buildings take away); the light they reflect onto the "
            "roof is reported apart (reflection gain).")

