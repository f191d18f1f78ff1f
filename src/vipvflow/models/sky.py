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


# ---------------------------------------------------------------------------- the luminance
#: Perez et al. (1993), Table 1: per clearness bin (rows, the bins of :data:`_EPS_EDGES`) the
#: coefficients of the luminance parameters a, b, c, d, e, four each:
#: ``x = x1 + x2 Z + Delta (x3 + x4 Z)`` (Z the solar zenith in radians; in the first bin c
#: and d take the forms of :func:`perez_1993_parameters`)
PEREZ_1993 = np.array([
    [1.3525, -0.2576, -0.2690, -1.4366, -0.7670, 0.0007, 1.2734, -0.1233, 2.8000, 0.6004,
     1.2375, 1.0000, 1.8734, 0.6297, 0.9738, 0.2809, 0.0356, -0.1246, -0.5718, 0.9938],
    [-1.2219, -0.7730, 1.4148, 1.1016, -0.2054, 0.0367, -3.9128, 0.9156, 6.9750, 0.1774,
     6.4477, -0.1239, -1.5798, -0.5081, -1.7812, 0.1080, 0.2624, 0.0672, -0.2190, -0.4285],
    [-1.1000, -0.2515, 0.8952, 0.0156, 0.2782, -0.1812, -4.5000, 1.1766, 24.7219, -13.0812,
     -37.7000, 34.8438, -5.0000, 1.5218, 3.9229, -2.6204, -0.0156, 0.1597, 0.4199, -0.5562],
    [-0.5484, -0.6654, -0.2672, 0.7117, 0.7234, -0.6219, -5.6812, 2.6297, 33.3389, -18.3000,
     -62.2500, 52.0781, -3.5000, 0.0016, 1.1477, 0.1062, 0.4659, -0.3296, -0.0876, -0.0329],
    [-0.6000, -0.3566, -2.5000, 2.3250, 0.2937, 0.0496, -5.6812, 1.8415, 21.0000, -4.7656,
     -21.5906, 7.2492, -3.5000, -0.1554, 1.4062, 0.3988, 0.0032, 0.0766, -0.0656, -0.1294],
    [-1.0156, -0.3670, 1.0078, 1.4051, 0.2875, -0.5328, -3.8500, 3.3750, 14.0000, -0.9999,
     -7.1406, 7.5469, -3.4000, -0.1078, -1.0750, 1.5702, -0.0672, 0.4016, 0.3017, -0.4844],
    [-1.0000, 0.0211, 0.5025, -0.5119, -0.3000, 0.1922, 0.7023, -1.6317, 19.0000, -5.0000,
     1.2438, -1.9094, -4.0000, 0.0250, 0.3844, 0.2656, 1.0468, -0.3788, -2.4517, 1.4656],
    [-1.0500, 0.0289, 0.4260, 0.3590, -0.3250, 0.1156, 0.7781, 0.0025, 31.0625, -14.5000,
     -46.1148, 55.3750, -7.2312, 0.4050, 13.3500, 0.6234, 1.5000, -0.6426, 1.8564, 0.5636]])

#: azimuth sectors (36 of 10 deg, the first from 0 to 10 deg) and elevation levels (0, 10,
#: .. 80 deg; none above 90) of the visible-sky tables (:func:`sky_table`, :func:`sky_levels`)
SKY_AZIMUTH_BINS = 36
SKY_LEVEL_DEG = 10.0
SKY_LEVELS = 9
#: time step of the sky tables (s): the luminance's shape moves with the sun (3.75 deg in
#: 15 min) and is interpolated linearly in between
SKY_STEP_S = 900.0
_SUB = 2          # directions per sector and per level band in each direction (quadrature)


def perez_1993_parameters(zenith_rad, epsilon, delta):
    """The Perez all-weather sky's luminance parameters ``a, b, c, d, e`` (arrays).

    Parameters
    ----------
    zenith_rad : array, solar zenith (radians, at most pi / 2)
    epsilon : array, the sky's clearness (Perez et al. 1990), >= 1
    delta : array, the sky's brightness ``DHI m / E0`` (clipped to 0.01..0.6, the model's
        range, as gendaylit clips it)

    References
    ----------
    R. Perez, R. Seals, J. Michalsky (1993), All-weather model for sky luminance
    distribution - preliminary configuration and validation, Solar Energy 50(3), 235-245,
    table 1 and eqs. 1-2.
    """
    z = np.asarray(zenith_rad, np.float64)
    dl = np.clip(np.asarray(delta, np.float64), 0.01, 0.6)
    k = PEREZ_1993[np.clip(np.digitize(np.asarray(epsilon, np.float64), _EPS_EDGES[1:]), 0, 7)]
    col = lambda j: k[..., j]                                           # noqa: E731
    a = col(0) + col(1) * z + dl * (col(2) + col(3) * z)
    b = col(4) + col(5) * z + dl * (col(6) + col(7) * z)
    c = col(8) + col(9) * z + dl * (col(10) + col(11) * z)
    d = col(12) + col(13) * z + dl * (col(14) + col(15) * z)
    e = col(16) + col(17) * z + dl * (col(18) + col(19) * z)
    first = np.asarray(epsilon) < _EPS_EDGES[1]
    if np.any(first):
        with np.errstate(invalid="ignore", over="ignore"):
            c1 = np.exp(np.power(dl * (col(8) + col(9) * z), col(10))) - col(11)
            d1 = -np.exp(dl * (col(12) + col(13) * z)) + col(14) + dl * col(15)
        c, d = np.where(first, c1, c), np.where(first, d1, d)
    return a, b, c, d, e


def _sky_directions():
    """Unit vectors (levels x SUB, sectors x SUB, 3) of the quadrature grid, their
    elevation (rad) and the solid angle ``cos(el) d(el) d(az)`` of each."""
    n_el, n_az = SKY_LEVELS * _SUB, SKY_AZIMUTH_BINS * _SUB
    el = np.radians((np.arange(n_el) + 0.5) * 90.0 / n_el)
    az = np.radians((np.arange(n_az) + 0.5) * 360.0 / n_az)
    EL, AZ = np.meshgrid(el, az, indexing="ij")
    d = np.stack([np.cos(EL) * np.sin(AZ), np.cos(EL) * np.cos(AZ), np.sin(EL)], -1)
    w = np.cos(EL) * (np.pi / 2 / n_el) * (2 * np.pi / n_az)
    return d, EL, w


#: the sky sectors' central azimuths' sine and cosine (east and north components)
SECTOR_SIN = np.sin(np.radians((np.arange(SKY_AZIMUTH_BINS) + 0.5) * 360.0 / SKY_AZIMUTH_BINS))
SECTOR_COS = np.cos(np.radians((np.arange(SKY_AZIMUTH_BINS) + 0.5) * 360.0 / SKY_AZIMUTH_BINS))


def sky_table(dhi_wm2, dni_wm2, dni_extra_wm2, sun_xyz) -> tuple[np.ndarray, np.ndarray]:
    """The light of the sky above each elevation level in each azimuth sector, as shares
    of the diffuse horizontal irradiance, per time: two (n, 36, 10) float32 tables (levels
    0, 10, .. 90 deg; at 90 deg 0).

    ``G[i, k, j]`` = the Perez (1993) sky's light on a horizontal plane from sector ``k``
    above elevation ``10 j`` deg, over its light from the whole sky (``G[i, :, 0].sum()``
    is 1); ``H[i, k, j]`` the same integral with ``cos(el)`` in place of ``sin(el)``, the
    part a tilted plane adds: a plane of unit normal ``n`` whose horizon in sector ``k``
    stands at ``h_k`` receives ``DHI sum_k (n_z G[k, h_k / 10] + (n_x sin a_k + n_y cos a_k)
    H[k, h_k / 10])`` (``a_k`` the sector's central azimuth; interpolated between levels,
    :func:`sky_share`).  Where DHI is 0 or the sun is down the sky is taken as uniform.

    Parameters
    ----------
    dhi_wm2, dni_wm2 : (n,) W/m2
    dni_extra_wm2 : (n,) extraterrestrial normal irradiance, W/m2
    sun_xyz : (n, 3) unit vectors towards the sun (east, north, up)

    References
    ----------
    R. Perez, R. Seals, J. Michalsky (1993), Solar Energy 50(3), 235-245 (the luminance
    ``(1 + a exp(b / cos zeta)) (1 + c exp(d gamma) + e cos^2 gamma)``); R. Perez et al.
    (1990), Solar Energy 44(5), 271-289 (clearness and brightness); pvlib
    ``atmosphere.get_relative_airmass``.
    """
    import pvlib

    dhi = np.nan_to_num(np.asarray(dhi_wm2, np.float64))
    dni = np.maximum(np.nan_to_num(np.asarray(dni_wm2, np.float64)), 0.0)
    s = np.asarray(sun_xyz, np.float64).reshape(-1, 3)
    n = len(s)
    cz = np.clip(s[:, 2], 0.0, 1.0)
    z = np.arccos(cz)
    with np.errstate(invalid="ignore"):
        am = np.nan_to_num(np.asarray(pvlib.atmosphere.get_relative_airmass(np.degrees(z)), np.float64),
                           nan=38.0)
    ok = (dhi > 0) & (s[:, 2] > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        eps = np.where(ok, ((dhi + dni) / np.where(ok, dhi, 1.0) + _KAPPA * z ** 3)
                       / (1 + _KAPPA * z ** 3), 1.0)
    eps = np.clip(eps, 1.0, 12.0)                     # the model's range (gendaylit: 1..12.1)
    delta = np.where(ok, dhi * am / np.asarray(dni_extra_wm2, np.float64), 0.01)
    a, b, c, d, e = perez_1993_parameters(z, eps, delta)
    dirs, EL, w = _sky_directions()
    flat = dirs.reshape(-1, 3)
    grad_den = np.maximum(np.sin(EL).reshape(-1), 0.01)
    w_v = (w * np.sin(EL)).reshape(-1)                # horizontal plane: cos of incidence
    w_h = (w * np.cos(EL)).reshape(-1)                # the horizontal part, for tilt
    out_g = np.zeros((n, SKY_AZIMUTH_BINS, SKY_LEVELS + 1), np.float32)
    out_h = np.zeros((n, SKY_AZIMUTH_BINS, SKY_LEVELS + 1), np.float32)
    shape = (SKY_LEVELS, _SUB, SKY_AZIMUTH_BINS, _SUB)
    for lo in range(0, n, 2048):
        hi = min(n, lo + 2048)
        g = np.arccos(np.clip(s[lo:hi] @ flat.T, -1.0, 1.0))
        with np.errstate(over="ignore", invalid="ignore"):
            lv = ((1 + a[lo:hi, None] * np.exp(b[lo:hi, None] / grad_den[None]))
                  * (1 + c[lo:hi, None] * np.exp(d[lo:hi, None] * g) + e[lo:hi, None] * np.cos(g) ** 2))
        lv = np.maximum(np.nan_to_num(lv, nan=0.0, posinf=0.0), 0.0)
        bad = ~ok[lo:hi] | ~((lv * w_v).sum(1) > 0)
        lv[bad] = 1.0                                 # no sky model (night, no DHI): uniform
        for wt, out in ((w_v, out_g), (w_h, out_h)):
            cell = (lv * wt).reshape((hi - lo,) + shape).sum((2, 4))
            cum = np.cumsum(cell[:, ::-1], axis=1)[:, ::-1]        # above level j, per sector
            if out is out_g:
                total = cum[:, 0].sum(1)
                norm = np.where(total > 0, total, 1.0)[:, None, None]
            out[lo:hi, :, :SKY_LEVELS] = (cum / norm).transpose(0, 2, 1)
    return out_g, out_h


def sky_levels(profile_deg) -> np.ndarray:
    """A roof point's horizon per sky sector as a fractional level index: (m, 36) float32.

    Parameters
    ----------
    profile_deg : (m, 72) horizon elevation per 5 deg azimuth bin (deg;
        :func:`vipvflow.models.horizon.horizon_profile`), the sector's two bins averaged
    """
    p = np.asarray(profile_deg, np.float64).reshape(len(profile_deg), SKY_AZIMUTH_BINS, -1).mean(2)
    return np.clip(p / SKY_LEVEL_DEG, 0.0, SKY_LEVELS - 1 + 0.999999).astype(np.float32)


def _interp(table, levels):
    n = len(levels)
    x = np.asarray(levels, np.float32)
    i = x.astype(np.int64)
    f = x - i.astype(np.float32)
    r = np.arange(n)[:, None]
    k = np.arange(SKY_AZIMUTH_BINS)[None, :]
    lo = table[r, k, i]
    return lo + f * (table[r, k, i + 1] - lo)


#: values per cell of the packed sky tables (:func:`pack_sky`)
SKY_PACK = 4


def pack_sky(tables: dict) -> np.ndarray:
    """The four tables of :meth:`vipvflow.models.sun_sky.RadiationTable.sky` (``all``,
    ``all_h``, ``clear``, ``clear_h``, (rows, 36, 10) float32) as one array of cells x time:
    (360 x 4, rows) float32, row ``4 cell + q`` the values of table ``q`` (in that order) at
    every time step.  The compiled kernel sums a segment's sky over many time steps at once,
    each sum a run over contiguous memory (:func:`vipvflow.models.passkernel._sky_grid`)."""
    names = ("all", "all_h", "clear", "clear_h")
    n = len(tables["all"])
    cells = tables["all"][0].size
    out = np.empty((cells, SKY_PACK, n), np.float32)
    for q, name in enumerate(names):
        out[:, q, :] = np.asarray(tables[name], np.float32).reshape(n, cells).T
    return out.reshape(cells * SKY_PACK, n)


def unpack_sky(packed: np.ndarray, shape) -> dict:
    """The four tables of :func:`pack_sky`'s *packed* as views into it (no copy), each of
    *shape* (rows, 36, 10)."""
    n = packed.shape[1]
    p = packed.reshape(-1, SKY_PACK, n)
    return {name: p[:, q, :].T.reshape(shape) for q, name in enumerate(("all", "all_h", "clear", "clear_h"))}


def sky_share(table_g, table_h, levels, normal) -> np.ndarray:
    """The share of DHI a roof point receives from the sky above its horizon, for rows of
    the two sky tables (:func:`sky_table`, (n, 36, 10)), its *levels* (n, 36)
    (:func:`sky_levels`) and its unit *normal* (n, 3): float32 (n,), 1 for a level roof in
    the open.  Beyond the last level the sky above 90 deg is none."""
    nrm = np.asarray(normal, np.float32)
    tilt = (nrm[:, 0:1] * SECTOR_SIN.astype(np.float32) + nrm[:, 1:2] * SECTOR_COS.astype(np.float32))
    v = nrm[:, 2:3] * _interp(table_g, levels) + tilt * _interp(table_h, levels)
    out = np.zeros(len(v), np.float32)
    for k in range(v.shape[1]):          # in sector order, as the compiled kernel sums them
        out += v[:, k]
    return out


def open_terms(table_h) -> np.ndarray:
    """Per row of a tilt table (:func:`sky_table`'s ``H``, (n, 36, 10)): ``sum_k sin a_k
    H[k, 0]`` and ``sum_k cos a_k H[k, 0]``, (n, 2) float32: an open roof of unit normal
    ``n`` receives the share ``n_z + n_x A + n_y B`` (:func:`open_share`)."""
    h0 = np.asarray(table_h, np.float64)[:, :, 0]
    return np.stack([h0 @ SECTOR_SIN, h0 @ SECTOR_COS], 1).astype(np.float32)


def open_share(terms, normal) -> np.ndarray:
    """The share of DHI an open roof of unit *normal* (n, 3) receives, from rows of
    :func:`open_terms` (n, 2): float32 (n,)."""
    nrm = np.asarray(normal, np.float32)
    t = np.asarray(terms, np.float32)
    return nrm[:, 2] + (nrm[:, 0] * t[:, 0] + nrm[:, 1] * t[:, 1])


def tree_share(table_g, table_h, loss, normal) -> np.ndarray:
    """The share of DHI the tree crowns take from a roof point: for rows of the two sky
    tables (:func:`sky_table`, (n, 36, 10)), the crowns' loss per sky cell (n, 324)
    (:func:`vipvflow.models.trees.sky_cell_loss`, the cell's light taken as uniform within
    it) and the roof's unit *normal* (n, 3): ``sum_cells loss (n_z dG + t_k dH)`` with
    ``dG``, ``dH`` the cell's light (the tables' difference between its two levels) and
    ``t_k = n_x sin a_k + n_y cos a_k``; float32 (n,), summed cell by cell as the compiled
    kernel sums them."""
    from .trees import sky_cells

    cells = sky_cells()
    n = len(loss)
    g = np.asarray(table_g, np.float32).reshape(n, -1)
    h = np.asarray(table_h, np.float32).reshape(n, -1)
    nrm = np.asarray(normal, np.float32)
    tilt = (nrm[:, 0:1] * SECTOR_SIN.astype(np.float32) + nrm[:, 1:2] * SECTOR_COS.astype(np.float32))
    nz = nrm[:, 2]
    loss = np.asarray(loss, np.float32)
    out = np.zeros(n, np.float32)
    for j, cell in enumerate(cells):
        k = j // SKY_LEVELS
        out += loss[:, j] * (nz * (g[:, cell] - g[:, cell + 1]) + tilt[:, k] * (h[:, cell] - h[:, cell + 1]))
    return out
