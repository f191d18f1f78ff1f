"""Air temperature where the city is: a monthly climatology chosen by the city's coordinates.

The package ships the NCEP-NCAR Reanalysis 1 long-term monthly means of the 2 m air
temperature, 1991-2020, on its T62 Gaussian grid (192 x 94 points, ~1.9 deg), as published
by NOAA PSL (``air.2m.mon.ltm.1991-2020.nc``), stored in tenths of a degree
(``vipvflow/data/ncep_air2m_ltm_1991_2020.npz``, 230 kB).  :func:`monthly_air_temperature`
interpolates it bilinearly to a latitude and longitude.  A grid cell is ~200 km wide and
the reanalysis surface is smooth: within ~1 K of a city's own station normals where the
land around is flat (Luxembourg-Findel 1991-2020: 0.4..18.6 here against 0.8..18.1 deg C),
a few kelvin off on a coast or in mountains; a scenario that has its city's normals names
them (``climate.monthly_mean_temperature_c``).  The CAMS radiation files carry no air
temperature.

Licence: NOAA PSL data, a work of the US government, with no restriction on use or
redistribution; PSL asks for the acknowledgement "NCEP Reanalysis data provided by the
NOAA PSL, Boulder, Colorado, USA, from their website at https://psl.noaa.gov".

References
----------
E. Kalnay et al. (1996), The NCEP/NCAR 40-year reanalysis project, Bulletin of the American
Meteorological Society 77(3), 437-471.
"""
from __future__ import annotations

from functools import lru_cache
from importlib import resources

import numpy as np

#: what :func:`monthly_air_temperature` reads, for the run's manifest
SOURCE = ("NCEP-NCAR Reanalysis 1, 2 m air temperature, long-term monthly means 1991-2020 "
          "(NOAA PSL), at the city's coordinates")


@lru_cache(maxsize=1)
def _grid():
    with resources.files("vipvflow").joinpath("data/ncep_air2m_ltm_1991_2020.npz").open("rb") as fh:
        with np.load(fh) as z:
            return z["lat"].astype(np.float64), z["lon"].astype(np.float64), z["t_dc"] / 10.0


def monthly_air_temperature(lat_deg: float, lon_deg: float) -> list[float]:
    """Mean air temperature of each month (Jan..Dec, deg C, 0.1 deg) at a place.

    Parameters
    ----------
    lat_deg, lon_deg : float, WGS84 degrees (longitude east positive)

    Returns
    -------
    list of 12 floats, deg C: the climatology interpolated bilinearly between the four
    grid points around the place (longitude periodic).

    References
    ----------
    E. Kalnay et al. (1996), BAMS 77(3), 437-471; NOAA PSL ``air.2m.mon.ltm.1991-2020.nc``.
    """
    if not (np.isfinite(lat_deg) and np.isfinite(lon_deg) and -90 <= lat_deg <= 90):
        raise ValueError(f"not a place: latitude {lat_deg}, longitude {lon_deg}")
    lat, lon, t = _grid()                      # lat descending, lon 0..358.125
    la = lat[::-1]
    tt = t[:, ::-1, :]
    x = float(lon_deg) % 360.0
    y = float(np.clip(lat_deg, la[0], la[-1]))
    i = int(np.clip(np.searchsorted(la, y) - 1, 0, len(la) - 2))
    fy = (y - la[i]) / (la[i + 1] - la[i])
    step = lon[1] - lon[0]
    j = int(x // step) % len(lon)
    j1 = (j + 1) % len(lon)
    fx = (x - lon[j]) / step if x >= lon[j] else (x + 360.0 - lon[j]) / step
    v = ((1 - fy) * ((1 - fx) * tt[:, i, j] + fx * tt[:, i, j1])
         + fy * ((1 - fx) * tt[:, i + 1, j] + fx * tt[:, i + 1, j1]))
    return [round(float(a), 1) for a in v]
