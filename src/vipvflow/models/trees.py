"""Tree crowns as shading objects: spheroids that transmit a share of the light by season.

A tree is a trunk base (x, y, z on the ground), a height, a crown diameter and a crown base
(the height of the crown's lowest leaves); its crown is the spheroid filling that box::

    centre (x, y, z + crown_base + c),  horizontal semi-axis a = crown_diameter / 2,
    vertical semi-axis c = (height - crown_base) / 2

(:class:`TreeTable` holds the trees of a tile as the city ingest writes them,
``city/trees/<TILE>.npz``).  A ray that crosses a crown keeps the crown's transmittance
``tau`` of its light; a ray through several crowns the product of theirs.  ``tau`` is the
crown's whole transmittance as measured under single urban trees (the light below a crown
over the light beside it), leaf-on or, for a deciduous tree in its leaf-off months,
leaf-off (:class:`vipvflow.models.params.TreeCfg`).  A constant per crown rather than a
Beer-Lambert law ``exp(-k L)`` of the path length ``L``: the measurements give a crown's
transmittance, not its leaf area density, and a grazing ray through a crown's edge is then
taken as dark as one through its middle (an upper bound of the shade at crown edges).  A
crown absorbs what it does not transmit: the light its leaves scatter (an albedo of about
0.2 on the sunlit side) is not counted.

The months a tree is leafless differ between trees (a table may give them per tree), so
the twelve months fall into *classes* of months in which every crown of the scene has the
same transmittance (two for trees that follow the default calendar: leaf-on, leaf-off):
:meth:`Crowns.class_of_month` and ``Crowns.tau`` (crowns x classes).  Everything the
per-segment geometry derives from rays through crowns (sky view, the reflectors' weights)
is stored per class; a pass takes its month's class.

Rays are traced through a uniform grid of the crowns' horizontal extents (each crown in
every cell its bounding square meets), cell by cell along the ray's horizontal projection
(Amanatides and Woo 1987) and only within the height band the crowns occupy, with the
analytic ray-ellipsoid test in each cell: compiled with numba (:func:`_walk`).
:func:`transmittance_reference` is the plain-numpy check (every ray against every crown).

References
----------
J. Konarska, F. Lindberg, A. Larsson, S. Thorsson, B. Holmer (2014), Transmissivity of
solar radiation through crowns of single urban trees - application for outdoor thermal
comfort modelling, Theoretical and Applied Climatology 117, 363-376 (in leaf 8.8 % to
27.5 % for the deciduous trees measured, as cited by Sustainability 11(24), 7019, 2019).
G. M. Heisler (1986), Effects of individual trees on the solar radiation climate of small
buildings, Urban Ecology 9, 337-359 (a sugar maple's shade: irradiance 80 % lower in leaf,
nearly 40 % lower leafless).
J. Amanatides, A. Woo (1987), A fast voxel traversal algorithm for ray tracing,
Eurographics 87, 3-10.
"""
from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np
from numba import njit

from .params import TreeCfg
# the table of trees, without numba (the ingest's), re-exported here
from .tree_table import (LEAF_OFF_NORTH, LEAF_OFF_SOUTH, LEAF_TYPES, TREE_SOURCES,  # noqa: F401
                         TREES_FORMAT, TreeTable, default_leaf_off, month_mask)

#: crowns a ray can cross before its light is taken as gone (its product below 1e-6)
_MAX_HITS = 64


def month_classes(trees: TreeTable, cfg: TreeCfg) -> tuple[np.ndarray, np.ndarray]:
    """The classes of months in which every crown keeps its transmittance, and each
    crown's transmittance per class.

    Returns
    -------
    class_of_month : (12,) int64, January first
    tau : (n, C) float32, dimensionless (C >= 1; 1 without deciduous trees)
    """
    n = len(trees)
    default = month_mask(default_leaf_off(cfg, trees.latitude))
    decid = (trees.leaf_type == 0) | ((trees.leaf_type < 0) & (cfg.unknown_leaf_type == "deciduous"))
    mask = np.where(trees.leaf_off >= 0, trees.leaf_off.astype(np.int64), default)
    off = decid[:, None] & (((mask[:, None] >> np.arange(12)[None, :]) & 1) == 1)   # (n, 12)
    if n == 0:
        return np.zeros(12, np.int64), np.ones((0, 1), np.float32)
    patterns, inverse = np.unique(off.T, axis=0, return_inverse=True)              # (C, n)
    tau = np.where(patterns.T, np.float32(cfg.transmittance_leaf_off),
                   np.float32(cfg.transmittance_leaf_on)).astype(np.float32)
    return np.asarray(inverse, np.int64).reshape(12), np.ascontiguousarray(tau)


def month_of(t_utc) -> np.ndarray:
    """The month (1..12, UTC calendar) of Unix times *t_utc* (s)."""
    t = np.asarray(t_utc, np.float64)
    days = np.floor(np.nan_to_num(t) / 86400.0).astype("datetime64[D]")
    return (days.astype("datetime64[M]").astype(np.int64) % 12 + 1).astype(np.int64)


@njit(cache=True, nogil=True, inline="always")
def month0(t_utc):
    """The month 0..11 (UTC calendar) of a Unix time in s: the civil calendar from days since
    1970 (H. Hinnant's algorithm), as :func:`month_of` - 1."""
    z = np.int64(np.floor(t_utc / 86400.0)) + 719468
    era = (z if z >= 0 else z - 146096) // 146097
    doe = z - era * 146097
    yoe = (doe - doe // 1460 + doe // 36524 - doe // 146096) // 365
    doy = doe - (365 * yoe + yoe // 4 - yoe // 100)
    mp = (5 * doy + 2) // 153
    return mp + 2 if mp < 10 else mp - 10


# ---------------------------------------------------------------------------- ray walking
@njit(cache=True, nogil=True)
def _walk(ox, oy, oz, dx, dy, dz, tmax, cx, cy, cz, ia2, ic2, meta, start, items, hits):
    """The crowns a ray ``o + t d``, ``0 < t < tmax``, crosses: their indices into *hits*,
    ascending; returns how many (at most ``len(hits)``).

    *meta*: the grid (float64: x0, y0, cell size, nx, ny, lowest crown bottom, highest crown
    top), *start* / *items*: each cell's crowns (cell ``ix * ny + iy``).  Coordinates in the
    scene's local frame (m); *d* need not be unit length (t in its units).
    """
    n = 0
    if items.shape[0] == 0:
        return 0
    x0, y0, h = meta[0], meta[1], meta[2]
    nx, ny = np.int64(meta[3]), np.int64(meta[4])
    t0, t1 = 0.0, tmax
    # the height band of the crowns, then the grid's extent
    if abs(dz) < 1e-12:
        if oz < meta[5] or oz > meta[6]:
            return 0
    else:
        ta, tb = (meta[5] - oz) / dz, (meta[6] - oz) / dz
        if ta > tb:
            ta, tb = tb, ta
        t0, t1 = max(t0, ta), min(t1, tb)
    for o, dd, lo, hi in ((ox, dx, x0, x0 + nx * h), (oy, dy, y0, y0 + ny * h)):
        if abs(dd) < 1e-12:
            if o < lo or o > hi:
                return 0
        else:
            ta, tb = (lo - o) / dd, (hi - o) / dd
            if ta > tb:
                ta, tb = tb, ta
            t0, t1 = max(t0, ta), min(t1, tb)
    if not t0 < t1:
        return 0
    tm = 0.5 * (t0 + min(t1, t0 + 1e-3))
    ix = min(max(np.int64(np.floor((ox + tm * dx - x0) / h)), 0), nx - 1)
    iy = min(max(np.int64(np.floor((oy + tm * dy - y0) / h)), 0), ny - 1)
    sx = 1 if dx > 0 else -1
    sy = 1 if dy > 0 else -1
    big = 1e300
    ddx = h / abs(dx) if abs(dx) > 1e-12 else big
    ddy = h / abs(dy) if abs(dy) > 1e-12 else big
    nxx = (x0 + (ix + (1 if dx > 0 else 0)) * h - ox) / dx if abs(dx) > 1e-12 else big
    nyy = (y0 + (iy + (1 if dy > 0 else 0)) * h - oy) / dy if abs(dy) > 1e-12 else big
    A_h = dx * dx + dy * dy
    while True:
        cell = ix * ny + iy
        for k in range(start[cell], start[cell + 1]):
            j = items[k]
            seen = False
            for q in range(n):
                if hits[q] == j:
                    seen = True
                    break
            if seen:
                continue
            px, py, pz = ox - cx[j], oy - cy[j], oz - cz[j]
            a = A_h * ia2[j] + dz * dz * ic2[j]
            b = 2.0 * ((px * dx + py * dy) * ia2[j] + pz * dz * ic2[j])
            c = (px * px + py * py) * ia2[j] + pz * pz * ic2[j] - 1.0
            disc = b * b - 4.0 * a * c
            if disc <= 0.0 or a <= 0.0:
                continue
            s = np.sqrt(disc)
            t_out = (-b + s) / (2.0 * a)
            t_in = (-b - s) / (2.0 * a)
            if t_out > 0.0 and t_in < tmax:
                hits[n] = j
                n += 1
                if n == hits.shape[0]:
                    break
        if n == hits.shape[0]:
            break
        if nxx < nyy:
            if nxx > t1:
                break
            ix += sx
            nxx += ddx
            if ix < 0 or ix >= nx:
                break
        else:
            if nyy > t1:
                break
            iy += sy
            nyy += ddy
            if iy < 0 or iy >= ny:
                break
    # ascending crown order: the product is then the reference's, to the last bit
    for i in range(1, n):
        v = hits[i]
        k = i - 1
        while k >= 0 and hits[k] > v:
            hits[k + 1] = hits[k]
            k -= 1
        hits[k + 1] = v
    return n


@njit(cache=True, nogil=True)
def transmit_one(ox, oy, oz, dx, dy, dz, tmax, cls, cx, cy, cz, ia2, ic2, meta, start, items,
                 tau, hits):
    """The transmittance (float32) of the crowns along one ray for month class *cls*."""
    n = _walk(ox, oy, oz, dx, dy, dz, tmax, cx, cy, cz, ia2, ic2, meta, start, items, hits)
    t = np.float32(1.0)
    for q in range(n):
        t *= tau[hits[q], cls]
    return t


#: azimuth sectors of :func:`sun_masks` (10 deg)
MASK_SECTORS = 36


@njit(cache=True, nogil=True, inline="always")
def mask_sector(dx, dy):
    """The sector of :func:`sun_masks` a direction's azimuth (from +y, clockwise) falls in."""
    k = np.int64(np.floor(np.arctan2(dx, dy) * (MASK_SECTORS / (2.0 * np.pi))))
    return k % MASK_SECTORS


@njit(cache=True, nogil=True)
def sun_masks(o, cx, cy, cz, ia2, ic2, out):
    """For each origin ``o[i]`` and azimuth sector ``k``, into ``out[i, k]``: a bound on
    the slope (tan of the elevation) above which a ray from the origin towards the sky in
    that sector passes over every crown (-inf: none lies there; inf: the origin is under a
    crown).  A crown (centre, semi-axes ``a`` across, ``c`` up) lies within the upright
    cylinder of radius ``a`` up to its top; from horizontal distance ``d > a`` it covers the
    azimuths within ``asin(a / d)`` of its centre's, and a ray rising at slope ``s`` is
    above its top beyond ``d - a`` if ``s > (top - o_z) / (d - a)``; with heights scaled by
    ``a / c`` it is a ball that rises nowhere above its centre's elevation plus
    ``asin(a / D)`` (``D`` the scaled distance): the lower bound counts.  The margins make
    the bound safe in float32 rays: where a ray's slope exceeds it, :func:`_walk` finds no
    crown."""
    w = 2.0 * np.pi / MASK_SECTORS
    for i in range(o.shape[0]):
        for k in range(MASK_SECTORS):
            out[i, k] = -np.inf
        ox, oy, oz = np.float64(o[i, 0]), np.float64(o[i, 1]), np.float64(o[i, 2])
        for j in range(cx.shape[0]):
            a = 1.0 / np.sqrt(ia2[j])
            top = cz[j] + 1.0 / np.sqrt(ic2[j]) - oz
            if top <= 0.0:
                continue                        # wholly below the origin: no rising ray meets it
            dx, dy = cx[j] - ox, cy[j] - oy
            d = np.sqrt(dx * dx + dy * dy)
            if d <= a * 1.001 + 0.01:
                for k in range(MASK_SECTORS):
                    out[i, k] = np.inf
                break
            # the lower of two bounds: over the cylinder's near edge; over the crown's
            # silhouette (heights scaled by a / c make it a ball of radius a, no point of
            # which rises above its centre's elevation plus asin(a / D))
            scale = a * np.sqrt(ic2[j])
            hz = (cz[j] - oz) * scale
            D = np.sqrt(d * d + hz * hz)
            el = np.arctan2(hz, d) + np.arcsin(min(a / D, 1.0))
            silhouette = np.tan(el) / scale if el < 0.5 * np.pi - 1e-6 else np.inf
            bound = min(top / (d - a), silhouette) * 1.001 + 1e-4
            half = np.arcsin(min(a / d, 1.0)) + 1e-3
            phi = np.arctan2(dx, dy)
            k0 = np.int64(np.floor((phi - half) / w))
            k1 = np.int64(np.floor((phi + half) / w))
            for k in range(k0, k1 + 1):
                kk = k % MASK_SECTORS
                if bound > out[i, kk]:
                    out[i, kk] = bound


@njit(cache=True, nogil=True)
def _transmit_many(o, d, tmax, cls, cx, cy, cz, ia2, ic2, meta, start, items, tau, out):
    """Rays ``o[i] + t d[i]``, ``0 < t < tmax[i]``: ``out[i, c]`` the product of the crossed
    crowns' ``tau[:, c]`` for every class, or (``cls[i] >= 0``) ``out[i, 0]`` for that class."""
    hits = np.empty(_MAX_HITS, np.int64)
    C = tau.shape[1]
    for i in range(o.shape[0]):
        n = _walk(o[i, 0], o[i, 1], o[i, 2], d[i, 0], d[i, 1], d[i, 2], tmax[i], cx, cy, cz,
                  ia2, ic2, meta, start, items, hits)
        if cls.shape[0]:
            t = np.float32(1.0)
            for q in range(n):
                t *= tau[hits[q], cls[i]]
            out[i, 0] = t
        else:
            for c in range(C):
                t = np.float32(1.0)
                for q in range(n):
                    t *= tau[hits[q], c]
                out[i, c] = t


class Crowns:
    """The crowns of a scene (:class:`vipvflow.models.shading.Scene`) with their
    transmittance per class of months, in the scene's local frame, indexed for rays.

    Parameters
    ----------
    trees : TreeTable
    cfg : TreeCfg
    origin : (3,) float, m, the scene's origin (rays are given relative to it)
    """

    def __init__(self, trees: TreeTable, cfg: TreeCfg, origin=(0.0, 0.0, 0.0)):
        self.trees = trees
        self.cfg = cfg
        self.origin = np.asarray(origin, np.float64).reshape(3)
        centre, a, c = trees.crown_extent()
        self.centre = centre - self.origin                      # local frame, float64
        self.a, self.c = a, c
        self.class_of_month, self.tau = month_classes(trees, cfg)
        self._build_grid()

    @property
    def n(self) -> int:
        return len(self.a)

    @property
    def n_classes(self) -> int:
        return int(self.tau.shape[1])

    def classes(self, months) -> np.ndarray:
        """The class (int64) of each month 1..12 of *months*."""
        return self.class_of_month[np.asarray(months, np.int64) - 1]

    def _build_grid(self) -> None:
        n = self.n
        f = np.ascontiguousarray
        self.cx, self.cy, self.cz = (f(self.centre[:, k]) for k in range(3))
        self.ia2 = f(1.0 / np.maximum(self.a, 1e-6) ** 2)
        self.ic2 = f(1.0 / np.maximum(self.c, 1e-6) ** 2)
        if n == 0:
            self.meta = np.array([0.0, 0.0, 1.0, 1.0, 1.0, 0.0, 0.0])
            self.start, self.items = np.zeros(2, np.int64), np.zeros(0, np.int64)
            return
        lo = np.column_stack([self.cx - self.a, self.cy - self.a])
        hi = np.column_stack([self.cx + self.a, self.cy + self.a])
        x0, y0 = lo.min(0) - 1.0
        span = hi.max(0) + 1.0 - (x0, y0)
        # cells of about two crown diameters (5..50 m), at most 2e6 of them
        h = float(np.clip(4.0 * np.median(self.a), 5.0, 50.0))
        h = max(h, float(np.sqrt(span[0] * span[1] / 2e6)))
        nx, ny = (np.floor(span / h).astype(np.int64) + 1)
        i0 = np.floor((lo - (x0, y0)) / h).astype(np.int64)
        i1 = np.floor((hi - (x0, y0)) / h).astype(np.int64)
        cnt = (i1[:, 0] - i0[:, 0] + 1) * (i1[:, 1] - i0[:, 1] + 1)
        owner = np.repeat(np.arange(n), cnt)
        k = np.arange(int(cnt.sum())) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        span_y = (i1[:, 1] - i0[:, 1] + 1)[owner]
        cxi = i0[owner, 0] + k // span_y
        cyi = i0[owner, 1] + k % span_y
        cell = cxi * ny + cyi
        order = np.argsort(cell, kind="stable")
        self.items = f(owner[order].astype(np.int64))
        self.start = np.zeros(nx * ny + 1, np.int64)
        np.cumsum(np.bincount(cell, minlength=nx * ny), out=self.start[1:])
        zlo = float((self.cz - self.c).min()) - 1e-6
        zhi = float((self.cz + self.c).max()) + 1e-6
        self.meta = np.array([x0, y0, h, nx, ny, zlo, zhi], np.float64)

    def arrays(self) -> tuple:
        """The compiled functions' arguments after the ray's: ``cx, cy, cz, ia2, ic2, meta,
        start, items, tau``."""
        return (self.cx, self.cy, self.cz, self.ia2, self.ic2, self.meta, self.start, self.items,
                self.tau)

    def sun_masks(self, origins_local) -> np.ndarray:
        """:func:`sun_masks` of *origins_local* (n, 3), m, in the scene's local frame:
        (n, :data:`MASK_SECTORS`) float64."""
        o = np.ascontiguousarray(np.asarray(origins_local, np.float64).reshape(-1, 3))
        out = np.empty((len(o), MASK_SECTORS))
        sun_masks(o, self.cx, self.cy, self.cz, self.ia2, self.ic2, out)
        return out

    def transmittance(self, origins, dirs, tmax, classes=None) -> np.ndarray:
        """The crowns' transmittance along rays (float32).

        Parameters
        ----------
        origins : (n, 3) float, m, in the scene's local frame (``world - origin``)
        dirs : (n, 3) float, directions (unit: *tmax* in m)
        tmax : float or (n,) float, m, the rays' ends (a surface they hit, or their length)
        classes : (n,) int, optional, each ray's class of months

        Returns
        -------
        (n,) with *classes*, else (n, C): every class
        """
        o = np.ascontiguousarray(np.asarray(origins, np.float64).reshape(-1, 3))
        d = np.ascontiguousarray(np.asarray(dirs, np.float64).reshape(-1, 3))
        t = np.ascontiguousarray(np.broadcast_to(np.asarray(tmax, np.float64), (len(o),)))
        cls = (np.zeros(0, np.int64) if classes is None
               else np.ascontiguousarray(np.broadcast_to(np.asarray(classes, np.int64), (len(o),))))
        out = np.ones((len(o), 1 if classes is not None else self.n_classes), np.float32)
        if len(o) and self.n:
            _transmit_many(o, d, t, cls, *self.arrays(), out)
        return out[:, 0] if classes is not None else out


def transmittance_reference(crowns: Crowns, origins, dirs, tmax, classes=None) -> np.ndarray:
    """Plain-numpy check of :meth:`Crowns.transmittance` (same arguments and result): every
    ray against every crown (the quadratic of the ray and the spheroid in float64), the
    crossed crowns' transmittances multiplied in crown order (float32)."""
    o = np.asarray(origins, np.float64).reshape(-1, 3)
    d = np.asarray(dirs, np.float64).reshape(-1, 3)
    tm = np.broadcast_to(np.asarray(tmax, np.float64), (len(o),))
    C = crowns.n_classes
    out = np.ones((len(o), C), np.float32)
    ia2, ic2 = 1.0 / np.maximum(crowns.a, 1e-6) ** 2, 1.0 / np.maximum(crowns.c, 1e-6) ** 2
    step = max(1, 2_000_000 // max(crowns.n, 1))
    for lo in range(0, len(o), step):
        sl = slice(lo, lo + step)
        p = o[sl, None, :] - crowns.centre[None]
        dd = d[sl, None, :]
        a = (dd[..., 0] ** 2 + dd[..., 1] ** 2) * ia2 + dd[..., 2] ** 2 * ic2
        b = 2.0 * ((p[..., 0] * dd[..., 0] + p[..., 1] * dd[..., 1]) * ia2 + p[..., 2] * dd[..., 2] * ic2)
        c = (p[..., 0] ** 2 + p[..., 1] ** 2) * ia2 + p[..., 2] ** 2 * ic2 - 1.0
        disc = b * b - 4.0 * a * c
        ok = (disc > 0) & (a > 0)
        s = np.sqrt(np.where(ok, disc, 0.0))
        with np.errstate(divide="ignore", invalid="ignore"):
            t_out = (-b + s) / (2.0 * a)
            t_in = (-b - s) / (2.0 * a)
        hit = ok & (t_out > 0) & (t_in < tm[sl, None])
        for j in range(crowns.n):
            h = hit[:, j]
            if h.any():
                out[sl][h] *= crowns.tau[j][None, :]
    if classes is not None:
        cls = np.broadcast_to(np.asarray(classes, np.int64), (len(o),))
        return out[np.arange(len(o)), cls]
    return out


# ---------------------------------------------------------------------------- the sky
#: samples per sky cell (per azimuth and per elevation) for the crowns' share of a cell
SKY_CELL_SAMPLES = 4
#: directions (points x cells x samples) :func:`sky_cell_loss` tests at a time (~2 MB of flags)
SKY_LOSS_BLOCK = 1 << 21


def sky_cell_loss(crowns: Crowns, origins_local, sky_x, tmax: float) -> np.ndarray:
    """The share of each sky cell's light the crowns take from each point: (m, C, 36 x 9)
    float32, cell ``10 k + j`` (sector ``k`` of 10 deg azimuth, band ``j`` from ``10 j`` to
    ``10 (j + 1)`` deg elevation; the flat index of :func:`vipvflow.models.sky.sky_table`'s
    rows without their last level).

    In each cell ``SKY_CELL_SAMPLES``\\ :sup:`2` directions, weighted by ``sin(el) cos(el)``
    (the light of a uniform patch on a level plane): the cell's loss is the weighted sum of
    ``1 - T`` (the crowns' transmittance, per class) over the directions above the point's
    horizon in that sector (``sky_x``: 10 x its level), over the cell's whole weight.  The
    roof then receives ``sum_cells loss x (n_z dG + t_k dH)`` less (the cell's light of the
    Perez sky, :func:`vipvflow.models.passkernel._sky_grid`), the sky taken as uniform within a
    cell.

    Parameters
    ----------
    crowns : Crowns
    origins_local : (m, 3) the roof points in the scene's frame, m
    sky_x : (m, 36) the points' horizon level per sector (:func:`vipvflow.models.sky.sky_levels`)
    tmax : float, m, ray length
    """
    from .sky import SKY_AZIMUTH_BINS, SKY_LEVEL_DEG, SKY_LEVELS

    o = np.asarray(origins_local, np.float64).reshape(-1, 3)
    m, C = len(o), crowns.n_classes
    K, L, S = SKY_AZIMUTH_BINS, SKY_LEVELS, SKY_CELL_SAMPLES
    out = np.zeros((m, C, K * L), np.float32)
    if m == 0 or crowns.n == 0:
        return out
    sub = (np.arange(S) + 0.5) / S
    az = np.radians((np.arange(K)[:, None] + sub[None, :]) * 360.0 / K)          # (K, S)
    el = np.radians((np.arange(L)[:, None] + sub[None, :]) * SKY_LEVEL_DEG)       # (L, S)
    AZ = az[:, None, :, None]                                                     # (K, L, S_az, S_el)
    EL = el[None, :, None, :]
    d = np.stack(np.broadcast_arrays(np.cos(EL) * np.sin(AZ), np.cos(EL) * np.cos(AZ), np.sin(EL)), -1)
    d = np.ascontiguousarray(d.reshape(K * L * S * S, 3))
    w = np.broadcast_to(np.sin(EL) * np.cos(EL), (K, L, S, S)).reshape(K * L, S * S)
    w_cell = w.sum(1)
    el_deg = np.broadcast_to(np.degrees(EL), (K, L, S, S)).reshape(K * L, S * S)
    sector = np.repeat(np.arange(K), L)
    horizon = np.asarray(sky_x, np.float64).reshape(m, K) * SKY_LEVEL_DEG
    # a direction rising above every crown of its sector (the point's sun mask, the same 10 deg
    # sectors) crosses none: no walk for it
    masks = crowns.sun_masks(o)
    slope = np.broadcast_to(np.tan(EL), (K, L, S, S)).reshape(K * L, S * S)
    # the points a block at a time, and of each point only the cells with a direction the
    # crowns could take (about a quarter of them in a street with trees): one walk call per
    # block, and the cells' weighted means over those cells' own directions
    D = S * S
    block = max(1, SKY_LOSS_BLOCK // (K * L * D))
    for lo in range(0, m, block):
        hi = min(m, lo + block)
        keep = ((el_deg[None] > horizon[lo:hi, sector][:, :, None])
                & ~(slope[None] > masks[lo:hi, sector][:, :, None]))         # (points, cells, D)
        pt, cl = np.nonzero(keep.any(2))
        if not len(pt):
            continue                       # no direction the crowns could take: no loss
        sub = keep[pt, cl]                                                # (cells kept, D)
        k, j = np.nonzero(sub)
        loss = np.zeros((len(pt), D, C))
        loss[k, j] = 1.0 - crowns.transmittance(o[lo + pt[k]], d[cl[k] * D + j], tmax)
        out[lo + pt, :, cl] = (loss * w[cl][:, :, None]).sum(1) / w_cell[cl][:, None]
    return out


def sky_cells() -> np.ndarray:
    """Flat indices ``10 k + j`` (j < 9) into a row of the sky tables
    (:func:`vipvflow.models.sky.sky_table`) of :func:`sky_cell_loss`'s cells, in its order."""
    from .sky import SKY_AZIMUTH_BINS, SKY_LEVELS

    return (np.arange(SKY_AZIMUTH_BINS)[:, None] * (SKY_LEVELS + 1)
            + np.arange(SKY_LEVELS)[None, :]).reshape(-1)


def tree_table_fields() -> list[str]:
    """The per-tree columns of :class:`TreeTable` (for writers and readers)."""
    return [f.name for f in fields(TreeTable) if f.name != "latitude"]


def load_tile_trees(data_dir, tile: str) -> TreeTable | None:
    """The trees of *tile* (its own and its buffer's) the city ingest wrote, None without."""
    from ..store import DataDir

    path = DataDir(data_dir).city.trees_file(tile)
    return TreeTable.load(path) if Path(path).exists() else None
