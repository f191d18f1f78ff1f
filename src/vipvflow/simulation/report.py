"""``report.html``: the run's figures (PNG, also in ``figures/``) and its summary table."""
from __future__ import annotations

import base64
import html
import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from ..irradiance import shading_loss  # noqa: E402


def _save(fig, run_dir: Path, name: str) -> str:
    out = run_dir / "figures"
    out.mkdir(parents=True, exist_ok=True)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    data = buf.getvalue()
    (out / f"{name}.png").write_bytes(data)
    return base64.b64encode(data).decode()


def fig_monthly(monthly: pd.DataFrame, summary: dict):
    fig, ax = plt.subplots(figsize=(8, 4))
    x = np.arange(len(monthly))
    kwp_bus = summary["kwp_per_bus"] * summary["buses"]
    ax.bar(x - 0.2, monthly["pv_kwh_clear"] / kwp_bus, 0.4, label="clear-sky", color="#f4b400")
    ax.bar(x + 0.2, monthly["pv_kwh"] / kwp_bus, 0.4, label="all-sky", color="#4285f4")
    ax.plot(x - 0.2, monthly["pv_kwh_clear_unshaded"] / kwp_bus, "k_", ms=14, label="without buildings")
    ax.plot(x + 0.2, monthly["pv_kwh_unshaded"] / kwp_bus, "k_", ms=14)
    ax.set_xticks(x, [m[5:] for m in monthly["month"]])
    ax.set_xlabel("month")
    ax.set_ylabel("kWh per kWp per bus")
    ax.set_title("Monthly PV yield; the gap to the black marks is the shading loss")
    ax.legend()
    return fig


def fig_map(smg, column: str, label: str, cmap: str):
    annual = smg.groupby("segment_id").agg(
        geometry=("geometry", "first"), h_total=("h_total", "sum"),
        h_direct=("h_direct", "sum"), h_diffuse=("h_diffuse", "sum"),
        h_total_unshaded=("h_total_unshaded", "sum"), n_passes=("n_passes", "sum"),
        pv_kwh=("pv_kwh", "sum"))
    annual["shading_loss"] = shading_loss(annual["h_direct"], annual["h_diffuse"],
                                          annual["h_total_unshaded"])
    annual["yield_wh_per_pass"] = 1000 * annual["pv_kwh"] / annual["n_passes"].where(annual["n_passes"] > 0)
    lines = [np.asarray(g.coords)[:, :2] for g in annual["geometry"]]
    fig, ax = plt.subplots(figsize=(7, 6))
    lc = LineCollection(lines, array=annual[column].to_numpy(), cmap=cmap, linewidths=2.5)
    ax.add_collection(lc)
    ax.autoscale()
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    fig.colorbar(lc, ax=ax, label=label)
    return fig


def fig_cycles(monthly: pd.DataFrame):
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.bar([m[5:] for m in monthly["month"]], monthly["avoided_charging_cycles"], color="#0f9d58")
    ax.set_xlabel("month")
    ax.set_ylabel("avoided charging cycles (fleet)")
    ax.set_title("Charging cycles avoided by PV (usable SoC window)")
    return fig


def fig_hourly(hp: pd.DataFrame):
    grid = hp.pivot_table(index="hour", columns="month", values="g_total", aggfunc="sum")
    fig, ax = plt.subplots(figsize=(8, 4.5))
    im = ax.imshow(grid.to_numpy(), aspect="auto", origin="lower", cmap="inferno",
                   extent=[0.5, grid.shape[1] + 0.5, grid.index.min() - 0.5, grid.index.max() + 0.5])
    ax.set_xticks(range(1, grid.shape[1] + 1), [m[5:] for m in grid.columns])
    ax.set_xlabel("month")
    ax.set_ylabel("local hour")
    fig.colorbar(im, ax=ax, label="mean roof irradiance in service (W/m²)")
    ax.set_title("Daily irradiance pattern by hour and month (all-sky)")
    return fig


def fig_routes(rm: pd.DataFrame):
    r = rm.groupby(["route_short_name", "direction_id"]).agg(
        trips=("trips", "sum"), pv_kwh=("pv_kwh", "sum"), consumption_kwh=("consumption_kwh", "sum"),
        pv_kwh_unshaded=("pv_kwh_unshaded", "sum"), pv_kwh_direct=("pv_kwh_direct", "sum"),
        pv_kwh_diffuse=("pv_kwh_diffuse", "sum")).reset_index()
    labels = [f"{a} / dir {b}" for a, b in zip(r["route_short_name"], r["direction_id"])]
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    ax[0].bar(labels, 100 * r["pv_kwh"] / r["consumption_kwh"], color="#4285f4")
    ax[0].set_ylabel("PV share of consumption (%)")
    ax[1].bar(labels, 100 * shading_loss(r["pv_kwh_direct"], r["pv_kwh_diffuse"], r["pv_kwh_unshaded"]),
              color="#db4437")
    ax[1].set_ylabel("shading loss (%)")
    for a in ax:
        a.tick_params(axis="x", rotation=30)
    fig.suptitle("Route comparison")
    return fig


def write_report(run_dir: Path, summary: dict, monthly, smg, hp, rm) -> Path:
    figs = [
        ("monthly_yield", "Monthly yield, clear-sky vs all-sky, with shading losses", fig_monthly(monthly, summary)),
        ("map_yield", "Segment-level yield (Wh per pass)",
         fig_map(smg, "yield_wh_per_pass", "PV energy per pass (Wh)", "viridis")),
        ("map_shading", "Segment-level shading loss", fig_map(smg, "shading_loss", "shading loss (all-sky)", "magma_r")),
        ("avoided_cycles", "Avoided charging cycles per month", fig_cycles(monthly)),
        ("hourly_pattern", "Daily irradiance pattern by hour and month", fig_hourly(hp)),
        ("routes", "Route comparison", fig_routes(rm)),
    ]
    parts = []
    for name, title, fig in figs:
        parts.append(f"<h2>{html.escape(title)}</h2><img alt='{name}' src='data:image/png;base64,{_save(fig, run_dir, name)}'>")
    rows = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(_fmt(v))}</td></tr>"
                   for k, v in summary.items() if not isinstance(v, dict))
    doc = f"""<!doctype html><html><head><meta charset="utf-8">
<title>vipvflow: {html.escape(summary['scenario'])} {summary['year']}</title>
<style>body{{font-family:sans-serif;max-width:1000px;margin:2em auto}}img{{max-width:100%}}
td,th{{text-align:left;padding:2px 8px}}</style></head><body>
<h1>VIPV fleet-year: {html.escape(summary['scenario'])} {summary['year']}</h1>
<p>{html.escape(_model_note(summary))}</p>
<table>{rows}</table>{''.join(parts)}</body></html>"""
    path = run_dir / "report.html"
    path.write_text(doc, encoding="utf-8")
    return path


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


def _fmt(v) -> str:
    if isinstance(v, float):
        return f"{v:,.4g}"
    return str(v)
