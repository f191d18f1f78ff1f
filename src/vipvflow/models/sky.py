"""The sky's brightness distribution: the Perez model's circumsolar and horizon coefficients.

The diffuse horizontal irradiance (DHI) of an anisotropic sky is split, after Perez et al.
(1990), into three parts: an isotropic dome, a circumsolar disc seen like the sun, and a
band at the horizon.  On a plane of tilt ``beta`` with the sun at angle of incidence
``theta`` and zenith ``Z``::

    E_sky = DHI [ (1 - F1) (1 + cos beta) / 2  +  F1 a / b  +  F2 sin beta ]
    a = max(0, cos theta),  b = max(cos 85 deg, cos Z)

``F1`` (circumsolar brightening, >= 0) and ``F2`` (horizon brightening, may be negative)
depend on the sky's clearness ``epsilon``, brightness ``Delta`` and the solar zenith only,
so they are computed once per time step of the radiation table
(:class:`vipvflow.models.sun_sky.RadiationTable`) and looked up per pass like DNI and DHI.
The roof model (:mod:`vipvflow.models.irradiance`) then replaces the open-sky view factors by
what the roof point sees: the isotropic part by its sky view factor, the circumsolar part by
the sun ray's visibility and the horizon part by its view of the band near the horizon.

References
----------
R. Perez, P. Ineichen, R. Seals, J. Michalsky, R. Stewart (1990), Modeling daylight
availability and irradiance components from direct and global irradiance, Solar Energy
44(5), 271-289.
R. Perez, R. Seals, P. Ineichen, R. Stewart, D. Menicucci (1987), A new simplified version
of the Perez diffuse irradiance model for tilted surfaces, Solar Energy 39(3), 221-231
(the horizon band, 6.5 deg wide, and the circumsolar region).
pvlib-python ``irradiance.perez`` (the coefficient set ``allsitescomposite1990`` and the
equations above), ``irradiance.get_extra_radiation``, ``atmosphere.get_relative_airmass``.
"""
from __future__ import annotations

import numpy as np

#: the model's clearness bin edges (Perez et al. 1990, table 1)
_EPS_EDGES = (0.0, 1.065, 1.23, 1.5, 1.95, 2.8, 4.5, 6.2)
#: kappa of the clearness formula, for a zenith in radians
_KAPPA = 1.041
#: the lower bound of b = cos Z in the circumsolar term (pvlib: cos 85 deg)
COS_85 = float(np.cos(np.radians(85.0)))
#: width of the band of sky near the horizon the horizon term stands for (Perez et al. 1987)
HORIZON_BAND_DEG = 6.5


def perez_coefficients(dhi_wm2, dni_wm2, dni_extra_wm2, zenith_deg, airmass,
                       model: str = "allsitescomposite1990"):
    """Circumsolar and horizon brightening coefficients ``F1``, ``F2`` of the Perez sky.

    The same arithmetic as pvlib's ``irradiance.perez`` (its coefficient table), without
    the plane: ``F1 = max(0, f11 + f12 Delta + f13 Z)``, ``F2 = f21 + f22 Delta + f23 Z``
    with the clearness bin of ``epsilon = ((DHI + DNI) / DHI + kappa Z^3) / (1 + kappa
    Z^3)`` and ``Delta = DHI m / E0``.  Where there is no diffuse light (DHI <= 0), no
    valid airmass (sun down) or a value is missing, both are 0: the sky is isotropic there
    (and holds nothing where DHI is 0).

    Parameters
    ----------
    dhi_wm2, dni_wm2 : array, diffuse horizontal and direct normal irradiance, W/m2
    dni_extra_wm2 : array, extraterrestrial normal irradiance, W/m2
    zenith_deg : array, solar zenith, degrees
    airmass : array, relative airmass (not pressure corrected), dimensionless
    model : str, pvlib's name of the coefficient set

    Returns
    -------
    F1, F2 : float64 arrays, dimensionless

    References
    ----------
    R. Perez et al. (1990), Solar Energy 44(5), 271-289; pvlib ``irradiance.perez``.
    """
    from pvlib.irradiance import _get_perez_coefficients

    dhi = np.asarray(dhi_wm2, np.float64)
    dni = np.asarray(dni_wm2, np.float64)
    z = np.radians(np.asarray(zenith_deg, np.float64))
    am = np.asarray(airmass, np.float64)
    ok = (dhi > 0) & np.isfinite(dhi) & np.isfinite(dni) & np.isfinite(am) & np.isfinite(z)
    with np.errstate(invalid="ignore", divide="ignore"):
        delta = np.where(ok, dhi * am / np.asarray(dni_extra_wm2, np.float64), 0.0)
        eps = np.where(ok, ((dhi + np.maximum(dni, 0)) / np.where(ok, dhi, 1.0) + _KAPPA * z ** 3)
                       / (1 + _KAPPA * z ** 3), 1.0)
    ebin = np.clip(np.digitize(eps, _EPS_EDGES) - 1, 0, len(_EPS_EDGES) - 1)
    f1c, f2c = (np.asarray(c, np.float64) for c in _get_perez_coefficients(model))
    zz = np.where(ok, z, 0.0)
    f1 = np.maximum(f1c[ebin, 0] + f1c[ebin, 1] * delta + f1c[ebin, 2] * zz, 0.0)
    f2 = f2c[ebin, 0] + f2c[ebin, 1] * delta + f2c[ebin, 2] * zz
    return np.where(ok, f1, 0.0), np.where(ok, f2, 0.0)


def perez_table(t_utc, dhi_wm2, dni_wm2, sun_z) -> tuple[np.ndarray, np.ndarray]:
    """``F1``, ``F2`` (float32, same shape as *dhi_wm2*) on a radiation table's time grid.

    Parameters
    ----------
    t_utc : (N,) float, Unix s
    dhi_wm2, dni_wm2 : (K, N) float, W/m2 (K locations)
    sun_z : (K, N) float, up component of the unit vector towards the sun (cos of the
        apparent zenith)

    References
    ----------
    pvlib ``irradiance.get_extra_radiation`` (Spencer 1971), ``atmosphere.get_relative_airmass``
    (Kasten and Young 1989), as ``irradiance.get_total_irradiance`` uses them for ``perez``.
    """
    import pandas as pd
    import pvlib

    t = np.asarray(t_utc, np.float64)
    times = pd.DatetimeIndex(pd.to_datetime(np.round(t * 1e3).astype(np.int64), unit="ms", utc=True))
    e0 = np.asarray(pvlib.irradiance.get_extra_radiation(times.day_of_year.to_numpy()), np.float64)
    cz = np.clip(np.asarray(sun_z, np.float64), -1.0, 1.0)
    zen = np.degrees(np.arccos(cz))
    with np.errstate(invalid="ignore"):
        am = np.asarray(pvlib.atmosphere.get_relative_airmass(zen), np.float64)
    f1, f2 = perez_coefficients(dhi_wm2, dni_wm2, np.broadcast_to(e0, np.shape(cz)), zen, am)
    return f1.astype(np.float32), f2.astype(np.float32)
