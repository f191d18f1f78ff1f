"""A synthetic year of 1-minute radiation in the CAMS radiation service CSV format.

Clear sky is pvlib's Ineichen-Perez model with a monthly Linke turbidity typical of
central Europe; all sky is the clear sky times a clear-sky index from a seeded
stochastic cloud model; the all-sky global irradiance is split into beam and diffuse parts
with the Erbs decomposition.  Values are written as the service writes them: irradiation
integrated over each minute (Wh/m2), times in UT, ``;``-separated, after ``#`` header lines,
so :func:`pvlib.iotools.read_cams` reads the file.

Cloud model (per day *d* of month *m*):

* a cloud fraction ``c_d ~ Beta(2 mu_m, 2 (1 - mu_m))`` (U-shaped: many clear and many
  overcast days) with ``mu_m = (1 - K_m) / (1 - k_cloud)`` so that the expected
  clear-sky index equals the monthly target ``K_m``;
* a latent Gaussian AR(1) process ``g`` with a 25 min time constant; a minute is cloudy
  when ``g < Phi^-1(c_d)``, which makes ``c_d`` the expected cloudy share of the day;
* the clear-sky index is 1 in clear minutes and the day's cloud transmittance
  ``k_cloud ~ U(0.15, 0.45)`` in cloudy minutes.

References
----------
Ineichen, P. and Perez, R. (2002). A new airmass independent formulation for the Linke
turbidity coefficient. Solar Energy 73(3), 151-157.
Erbs, D. G., Klein, S. A. and Duffie, J. A. (1982). Estimation of the diffuse radiation
fraction for hourly, daily and monthly-average global radiation. Solar Energy 28(4), 293-302.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
from scipy.signal import lfilter
from scipy.special import ndtri

# Linke turbidity (air mass 2) per month, central European towns (Jan..Dec)
LINKE_TURBIDITY = np.array([3.0, 3.2, 3.5, 3.8, 3.9, 4.0, 4.1, 4.0, 3.7, 3.4, 3.1, 3.0])
# target monthly clear-sky index (all-sky GHI / clear-sky GHI), Jan..Dec
CLEAR_SKY_INDEX = np.array([0.45, 0.53, 0.63, 0.70, 0.71, 0.73, 0.75, 0.74, 0.69, 0.58, 0.47, 0.41])
CLOUD_TIME_CONSTANT_MIN = 25.0

COLUMNS = ["Observation period", "TOA", "Clear sky GHI", "Clear sky BHI", "Clear sky DHI",
           "Clear sky BNI", "GHI", "BHI", "DHI", "BNI", "Reliability"]

_HEADER = """\
# Coding: utf-8
# File format version: 2
# Title: CAMS Radiation Service v4.6 all-sky irradiation (derived from satellite data).
# Content:  A time-series of solar radiation received on horizontal plane and plane always normal to the sun rays at ground level.
#           Returns the global, beam and diffuse irradiations integrated over a selected time step,
#           for a selected location (Meteosat Second Generation satellite coverage) and a selected period.
#           SYNTHETIC DATA: written by the vipvflow demo generator (pvlib Ineichen clear sky, seeded cloud model, Erbs split), not by CAMS.
# Provider: vipvflow demo generator (seed {seed})
# More information at: http://www.soda-pro.com/web-services/radiation/cams-radiation-service
# Date begin (ISO 8601): {begin}
# Date end (ISO 8601): {end}
# Latitude (positive North, ISO 19115): {lat:.4f}
# Longitude (positive East, ISO 19115): {lon:.4f}
# Altitude (m): {alt:.2f}
# Time reference: Universal time (UT)
#
# Encoding partly from D2.8.III.13-14 INSPIRE Data Specification on Atmospheric Conditions and Meteorological Geographical Features - Technical Guidelines (2013-12-10) and CF (Climate and Forecast) metadata (2013-11-11)
# CF Standard Names registry of ObservablePropertyValue
# http://cfconventions.org/Data/cf-standard-names/27/build/cf-standard-name-table.html
# urn:x-inspire:specification:DS-AC-MF:observable-property-name:cf-standard-name:1.6
# ObservableProperty
#     basePhenomenon:"integral_of_surface_downwelling_shortwave_flux_in_air_sky_wrt_time"
#     uom:"Wh m-2" [unit]
# StatisticalMeasure
#     statisticalFunction: "sum"
# Summarization (integration) period: 0 year 0 month 0 day 0 h 1 min 0 s
# noValue: nan
# File generated on: {year}-12-31
#
# Columns:
# 1. Observation period (ISO 8601)
# 2. TOA. Irradiation on horizontal plane at the top of atmosphere (Wh/m2)
# 3. Clear sky GHI. Clear sky global irradiation on horizontal plane at ground level (Wh/m2)
# 4. Clear sky BHI. Clear sky beam irradiation on horizontal plane at ground level (Wh/m2)
# 5. Clear sky DHI. Clear sky diffuse irradiation on horizontal plane at ground level (Wh/m2)
# 6. Clear sky BNI. Clear sky beam irradiation on mobile plane following the sun at normal incidence (Wh/m2)
# 7. GHI. Global irradiation on horizontal plane at ground level (Wh/m2)
# 8. BHI. Beam irradiation on horizontal plane at ground level (Wh/m2)
# 9. DHI. Diffuse irradiation on horizontal plane at ground level (Wh/m2)
#10. BNI. Beam irradiation on mobile plane following the sun at normal incidence (Wh/m2)
#11. Reliability. Proportion of reliable data in the summarization (0-1)
#
# {columns}
"""


def clear_sky_index(minutes: pd.DatetimeIndex, seed: int) -> np.ndarray:
    """Clear-sky index (all-sky / clear-sky GHI, 0..1) of each minute from the cloud model."""
    rng = np.random.default_rng([seed, 3])
    n = len(minutes)
    day = ((minutes - minutes[0]) // pd.Timedelta(days=1)).to_numpy()
    n_days = int(day[-1]) + 1
    first = minutes[0].normalize()
    month_of_day = pd.date_range(first, periods=n_days, freq="D").month.to_numpy() - 1
    k_cloud = rng.uniform(0.15, 0.45, n_days)
    mu = np.clip((1.0 - CLEAR_SKY_INDEX[month_of_day]) / (1.0 - k_cloud), 0.02, 0.98)
    cover = rng.beta(2.0 * mu, 2.0 * (1.0 - mu))
    a = np.exp(-1.0 / CLOUD_TIME_CONSTANT_MIN)
    # stationary from the first minute: the state before it is itself a N(0, 1) draw
    g, _ = lfilter([np.sqrt(1.0 - a * a)], [1.0, -a], rng.standard_normal(n),
                   zi=[a * rng.standard_normal()])
    cloudy = g < ndtri(np.clip(cover, 1e-6, 1 - 1e-6))[day]
    return np.where(cloudy, k_cloud[day], 1.0)


def radiation_year(year: int, latitude: float, longitude: float, altitude: float,
                   seed: int) -> pd.DataFrame:
    """1-minute irradiation (Wh/m2 per minute) for *year*, columns as in the CAMS CSV.

    Parameters
    ----------
    year : int
    latitude, longitude : float
        Degrees north and east.
    altitude : float
        Metres above sea level.
    seed : int
        Seed of the cloud model.

    Returns
    -------
    DataFrame
        Indexed by the start of each minute (UTC); ``TOA``, ``Clear sky GHI/BHI/DHI/BNI``,
        ``GHI/BHI/DHI/BNI`` in Wh/m2, ``Reliability`` (1).
    """
    start = pd.Timestamp(f"{year}-01-01", tz="UTC")
    minutes = pd.date_range(start, pd.Timestamp(f"{year + 1}-01-01", tz="UTC"),
                            freq="min", inclusive="left")
    mid = minutes + pd.Timedelta(seconds=30)
    sun = pvlib.solarposition.get_solarposition(mid, latitude, longitude, altitude,
                                                method="nrel_numpy")
    zen = sun["zenith"].to_numpy()
    cosz = np.cos(np.radians(zen))
    dni_extra = np.asarray(pvlib.irradiance.get_extra_radiation(mid.day_of_year.to_numpy()))
    am_rel = pvlib.atmosphere.get_relative_airmass(sun["apparent_zenith"].to_numpy())
    am_abs = pvlib.atmosphere.get_absolute_airmass(am_rel, pvlib.atmosphere.alt2pres(altitude))
    tl = LINKE_TURBIDITY[mid.month.to_numpy() - 1]
    with np.errstate(divide="ignore", invalid="ignore"):  # night: NaN air mass
        cs = pvlib.clearsky.ineichen(sun["apparent_zenith"].to_numpy(), am_abs, tl,
                                     altitude=altitude, dni_extra=dni_extra)
    day = cosz > 1e-4  # geometric sun above the horizon: the TOA irradiation written is > 0
    ghi_cs = np.where(day, np.nan_to_num(np.asarray(cs["ghi"], dtype=float)), 0.0)
    dni_cs = np.where(day, np.nan_to_num(np.asarray(cs["dni"], dtype=float)), 0.0)
    bhi_cs = np.where(day, dni_cs * cosz, 0.0)
    dhi_cs = np.clip(ghi_cs - bhi_cs, 0.0, None)
    ghi = ghi_cs * clear_sky_index(minutes, seed)
    erbs = pvlib.irradiance.erbs(ghi, zen, mid.day_of_year.to_numpy())
    dni = np.minimum(np.nan_to_num(np.asarray(erbs["dni"], dtype=float)), dni_cs)
    bhi = np.where(day, dni * cosz, 0.0)
    dhi = np.clip(ghi - bhi, 0.0, None)
    toa = np.where(day, dni_extra * cosz, 0.0)
    wh = 1.0 / 60.0  # W/m2 over one minute -> Wh/m2
    return pd.DataFrame({
        "TOA": toa * wh, "Clear sky GHI": ghi_cs * wh, "Clear sky BHI": bhi_cs * wh,
        "Clear sky DHI": dhi_cs * wh, "Clear sky BNI": np.where(day, dni_cs, 0.0) * wh,
        "GHI": ghi * wh, "BHI": bhi * wh, "DHI": dhi * wh, "BNI": np.where(day, dni, 0.0) * wh,
        "Reliability": 1.0}, index=minutes)


def write_cams_csv(path: Path, year: int, latitude: float, longitude: float, altitude: float,
                   seed: int, months=None) -> dict:
    """Write the CAMS-format CSV for *year* (only *months*, 1..12, when given: a contiguous
    range, the header's dates follow); return rows and the written period's sums (kWh/m2)."""
    data = radiation_year(year, latitude, longitude, altitude, seed)
    begin, end = pd.Timestamp(f"{year}-01-01"), pd.Timestamp(f"{year + 1}-01-01")
    if months is not None:
        months = sorted(months)
        if months != list(range(months[0], months[-1] + 1)):
            raise ValueError(f"months must be a contiguous range, got {months}")
        begin = pd.Timestamp(year, months[0], 1)
        end = begin + pd.offsets.MonthBegin(len(months))
        data = data[(data.index >= begin.tz_localize(data.index.tz))
                    & (data.index < end.tz_localize(data.index.tz))]
    values = data.round(4)
    t0 = data.index.strftime("%Y-%m-%dT%H:%M:%S.0")
    t1 = (data.index + pd.Timedelta(minutes=1)).strftime("%Y-%m-%dT%H:%M:%S.0")
    values.insert(0, "Observation period", np.char.add(np.char.add(t0.to_numpy().astype(str), "/"),
                                                         t1.to_numpy().astype(str)))
    header = _HEADER.format(seed=seed, begin=f"{begin:%Y-%m-%dT%H:%M:%S}.0",
                            end=f"{end:%Y-%m-%dT%H:%M:%S}.0", lat=latitude, lon=longitude,
                            alt=altitude, year=year, columns=";".join(COLUMNS))
    with open(path, "w", encoding="utf-8", newline="\n") as fh:
        fh.write(header)
        values.to_csv(fh, sep=";", header=False, index=False, float_format="%.4f",
                      lineterminator="\n")
    sums = data[["TOA", "Clear sky GHI", "GHI", "BHI", "DHI"]].sum() / 1000.0
    return {"rows": int(len(data)), "annual_kwh_m2": {k: round(float(v), 1) for k, v in sums.items()}}
