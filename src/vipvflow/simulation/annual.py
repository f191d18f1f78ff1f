"""Figures of a run that read as a place or a bus: each segment's year, a bus's year, the site's year.

Sums over passes add every bus that crossed a segment (a segment with a stop collects the
dwell time of every bus), so neither a segment-year sum nor the fleet's irradiation total is
a figure of one place or one bus. Here they become:

- per segment: the mean irradiance while buses are on it (W/m2) and the year of a bus that
  spent all its service hours in that light (kWh/kWp, kWh/m2 per year); the fleet's specific
  yield is their mean weighted by the time buses spend on each segment;
- per bus: the light on one roof in a year of service (kWh/m2 per year);
- for the site: the global horizontal irradiation of the calendar year from the radiation file.
"""
from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pandas as pd

from ..models.loss import shading_loss
from ..store import DataDir

#: geometry factors of ``parts/geometry`` that a map reader needs (the rest is the irradiance
#: model's internal reflector geometry and stays in parts/)
PUBLIC_FACTORS = ["tilt_deg", "azimuth_deg", "svf", "refl_vf"]

_SUMS = ["n_passes", "seconds", "pv_kwh", "pv_kwh_unshaded", "h_direct", "h_diffuse", "h_reflected",
         "h_total", "h_total_unshaded"]


def service_hours_per_bus(trip_seconds: float, n_buses: int, annualise: float = 1.0) -> float:
    """Hours a bus spends on its trips in a year (h): trip time of the fleet / buses."""
    return trip_seconds / 3600.0 * annualise / n_buses


def segment_year(segments, geometry: pd.DataFrame | None, segment_month: pd.DataFrame,
                 kwp: float, hours_per_bus: float):
    """The segments (GeoDataFrame of ``gtfs/segments.parquet``) with their public geometry
    factors and their totals and per-year figures over the run's months.

    Parameters
    ----------
    geometry : the run's ``parts/geometry`` rows (``segment_id`` and factors), or None
    segment_month : per segment and month: ``n_passes, seconds`` (s), ``pv_kwh*`` (kWh),
        ``h_*`` (Wh/m2)
    kwp : installed PV per bus (kWp)
    hours_per_bus : service hours per bus and year (h), :func:`service_hours_per_bus`

    Returns
    -------
    GeoDataFrame, one row per segment: the input columns, :data:`PUBLIC_FACTORS`, the sums
    ``n_passes, seconds, pv_kwh, pv_kwh_unshaded, h_total, h_total_unshaded``, the means
    ``g_total_in_service, g_total_unshaded_in_service`` (W/m2), ``shading_loss``,
    ``reflection_gain`` and ``kwh_per_kwp_year`` (kWh/kWp), ``irradiation_kwh_m2_year``
    (kWh/m2); NaN where no bus passed.
    """
    out = segments
    if geometry is not None:
        keep = ["segment_id"] + [c for c in PUBLIC_FACTORS if c in geometry.columns]
        out = out.merge(geometry[keep], on="segment_id", how="left")
    # column by column: the columns taken at once were a copy of them (a network's 0.27 GB)
    groups = segment_month.groupby("segment_id", sort=True)
    sums = pd.DataFrame({c: groups[c].sum() for c in _SUMS})
    out = out.merge(sums, left_on="segment_id", right_index=True, how="left")
    hours = out["seconds"].where(out["seconds"] > 0) / 3600.0
    unshaded = out["h_total_unshaded"].where(out["h_total_unshaded"] > 0)
    out["g_total_in_service"] = out["h_total"] / hours
    out["g_total_unshaded_in_service"] = out["h_total_unshaded"] / hours
    out["shading_loss"] = shading_loss(out["h_direct"], out["h_diffuse"], out["h_total_unshaded"])
    out["reflection_gain"] = out["h_reflected"] / unshaded
    out["kwh_per_kwp_year"] = out["pv_kwh"] / kwp / hours * hours_per_bus
    out["irradiation_kwh_m2_year"] = out["g_total_in_service"] * hours_per_bus / 1000.0
    return out.drop(columns=["h_direct", "h_diffuse", "h_reflected"])


def site_ghi_kwh_m2(data_dir: Path, year: int, min_coverage: float = 0.99) -> float | None:
    """Global horizontal irradiation of the calendar *year* (UTC) at the radiation file's
    locations (kWh/m2, mean of the locations); None when a location's minutes of the year
    are less than *min_coverage* present (the year is then not known, not guessed).

    Each value is the mean over its minute (CAMS), so the year is the sum of the minutes x
    60 s; the few missing minutes of a covered year are filled with the year's mean.

    Kept per file (its path, size and time) and year: a run computes it while its cluster
    starts (:func:`vipvflow.simulation.run._warm_radiation`), where reading the year's
    minutes (~0.1 GB of the process for a moment) does not add to the workers' memory as it
    did in the reduce."""
    path = DataDir(data_dir).radiation.table
    if not path.is_file():
        return None
    st = path.stat()
    return _site_ghi(str(path), st.st_size, st.st_mtime_ns, year, min_coverage)


@functools.lru_cache(maxsize=8)
def _site_ghi(path: str, size: int, mtime_ns: int, year: int, min_coverage: float) -> float | None:
    """:func:`site_ghi_kwh_m2` of the radiation file *path* (*size* and *mtime_ns* name its
    version)."""
    import pyarrow.parquet as pq

    lo = int(pd.Timestamp(f"{year}-01-01", tz="UTC").timestamp())
    hi = int(pd.Timestamp(f"{year + 1}-01-01", tz="UTC").timestamp())
    table = pq.read_table(path, columns=["t_utc", "ghi", "lat", "lon"],
                          filters=[("t_utc", ">=", lo), ("t_utc", "<", hi)]).to_pandas()
    minutes = (hi - lo) // 60
    if table.empty:
        return None
    per_loc = []
    for _, part in table.groupby(["lat", "lon"], sort=True):
        ghi = part["ghi"].to_numpy(np.float64)
        ok = np.isfinite(ghi)
        if ok.sum() < min_coverage * minutes:
            return None
        per_loc.append(ghi[ok].mean() * minutes * 60.0 / 3600.0 / 1000.0)
    return float(np.mean(per_loc))


def per_bus_figures(irradiation_wh_m2: pd.Series, n_buses: int, annualise: float, hours_per_bus: float,
                    data_dir: Path, year: int) -> dict:
    """The summary's per-bus and site figures (keys with their units in their names).

    *irradiation_wh_m2*: the fleet's light on the roofs over the run (``h_*`` sums, Wh/m2)."""
    per_bus = irradiation_wh_m2 / 1000.0 * annualise / n_buses
    site = site_ghi_kwh_m2(data_dir, year)
    return {
        "service_hours_per_bus_year": float(hours_per_bus),
        "roof_irradiation_kwh_m2_per_bus": float(per_bus["h_total"]),
        "roof_irradiation_unshaded_kwh_m2_per_bus": float(per_bus["h_total_unshaded"]),
        "ghi_in_service_kwh_m2_per_bus": float(per_bus["h_ghi"]),
        "site_ghi_kwh_m2_year": site,
    }
