"""Horizon profiles of roof points: how high the city rises around a segment, per azimuth.

A segment's horizon profile ``h(a)`` is the elevation angle (degrees) above which the sky
is free of buildings in azimuth ``a`` (clockwise from north), seen from the roof point.
It is found once per segment at simulation time by bisection on the elevation with
occlusion rays (:meth:`vipvflow.models.shading.Scene.occluded`), vectorised over every segment and
azimuth bin at once, and stored per tile in ``parts/horizon/tile=<TILE>.parquet``
(``segment_id`` and ``h000 .. h355``, degrees).  With it, direct sunlight on the roof can
be decided without ray casting: the sun is visible when its elevation exceeds the horizon
interpolated at its azimuth (:func:`sun_visible`).  This is what the web app uses to
recompute a trip for any departure time and date in well under a second.

The profile is exact for a horizon that rises monotonically with elevation in each
azimuth (LoD2 buildings seen from the street: walls and roofs, no overhangs); between the
sampled azimuths it is interpolated linearly.

The same description of terrain shading is used by GRASS GIS ``r.horizon`` / ``r.sun``
(horizon angle per azimuth direction; the sun shines when above it).

The run's kernel uses a bound instead of the profile: :func:`building_masks` gives per roof
point and 1 deg sector a slope above which no triangle can be met (conservative, so a sun
ray above it is clear exactly, without a ray; :mod:`vipvflow.models.passkernel`).
"""
from __future__ import annotations


import numpy as np
import pandas as pd
from numba import njit

from ..store import RunDir

#: azimuth bins of a stored profile (degrees from north, clockwise)
N_AZIMUTH = 72


def horizon_columns(n_azimuth: int = N_AZIMUTH) -> list[str]:
    """Column names ``h000 .. h355`` of the stored profile (azimuth in whole degrees)."""
    return [f"h{int(round(a)):03d}" for a in np.arange(n_azimuth) * 360.0 / n_azimuth]


def horizon_profile(scene, origins, n_azimuth: int = N_AZIMUTH, tol_deg: float = 0.25,
                    max_distance_m: float = np.inf) -> np.ndarray:
    """Horizon elevation angle per azimuth bin of every origin, by ray bisection.

    Parameters
    ----------
    scene : vipvflow.models.shading.Scene
    origins : (n, 3) float, m, projected CRS (the roof points, lifted off the roof)
    n_azimuth : int, number of azimuth directions ``k * 360 / n_azimuth`` (deg from north)
    tol_deg : float, the bisection stops when the bracket is narrower than this (deg)
    max_distance_m : float, rays end here (m); farther buildings do not count

    Returns
    -------
    (n, n_azimuth) float32, degrees in [0, 90]: 0 where a horizontal ray escapes, else
    the middle of the last bracket ``[blocked, free]`` (error below ``tol_deg / 2``).

    References
    ----------
    The horizon-angle method of urban sky-view studies (Oke, "Canyon geometry and the
    nocturnal urban heat island", J. Climatol. 1, 1981: the canyon's horizon
    ``atan(H / D)``, which tests/test_app.py checks against this function).
    """
    o = np.asarray(origins, np.float64).reshape(-1, 3)
    n = len(o)
    if n == 0:
        return np.zeros((0, n_azimuth), np.float32)
    az = np.radians(np.arange(n_azimuth) * 360.0 / n_azimuth)
    sin_a, cos_a = np.sin(az)[None], np.cos(az)[None]
    oo = np.repeat(o, n_azimuth, axis=0)

    def blocked(el_deg: np.ndarray) -> np.ndarray:
        e = np.radians(el_deg)
        ce = np.cos(e)
        d = np.stack([np.broadcast_to(ce * sin_a, e.shape), np.broadcast_to(ce * cos_a, e.shape),
                      np.sin(e)], axis=-1).reshape(-1, 3)
        return scene.occluded(oo, d, max_distance_m).reshape(n, n_azimuth)

    lo = np.zeros((n, n_azimuth))
    hi = np.full((n, n_azimuth), 90.0)
    open_ = ~blocked(lo)                      # horizontal ray escapes: horizon 0
    hi[open_] = 0.0
    steps = int(np.ceil(np.log2(90.0 / max(tol_deg, 1e-6))))
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        b = blocked(mid)
        lo = np.where(b, mid, lo)
        hi = np.where(b, hi, mid)
    return np.where(open_, 0.0, 0.5 * (lo + hi)).astype(np.float32)


def horizon_frame(segment_ids, profile: np.ndarray) -> pd.DataFrame:
    """The stored table: ``segment_id`` (int64) and one float32 column per azimuth bin."""
    profile = np.asarray(profile, np.float32)
    out = {"segment_id": np.asarray(segment_ids, np.int64)}
    for j, c in enumerate(horizon_columns(profile.shape[1])):
        out[c] = profile[:, j]
    return pd.DataFrame(out)


def load_horizons(run_dir) -> pd.DataFrame:
    """All tiles' horizon tables of a run, concatenated (empty frame when none)."""
    files = RunDir(run_dir).part_files("horizon")
    if not files:
        return pd.DataFrame({"segment_id": np.zeros(0, np.int64)})
    return pd.concat([pd.read_parquet(f) for f in files], ignore_index=True)


def horizon_at(profile: np.ndarray, azimuth_deg) -> np.ndarray:
    """Horizon elevation (deg) interpolated linearly (periodic) at an azimuth per row.

    Parameters
    ----------
    profile : (n, k) horizon angles at azimuths ``j * 360 / k``
    azimuth_deg : (n,) azimuth (deg from north, clockwise)
    """
    profile = np.asarray(profile, np.float32)
    k = profile.shape[1]
    f = (np.asarray(azimuth_deg, np.float64) % 360.0) * k / 360.0
    j = np.floor(f).astype(np.int64) % k
    w = (f - np.floor(f)).astype(np.float32)
    rows = np.arange(len(profile))
    return (1 - w) * profile[rows, j] + w * profile[rows, (j + 1) % k]


def sun_visible(profile: np.ndarray, sun_elevation_deg, sun_azimuth_deg) -> np.ndarray:
    """Whether the sun clears the horizon: elevation above the interpolated profile.

    Parameters
    ----------
    profile : (n, k) horizon angles (deg), one row per pass
    sun_elevation_deg, sun_azimuth_deg : (n,) degrees
    """
    el = np.asarray(sun_elevation_deg, np.float64)
    return (el > 0) & (el > horizon_at(profile, sun_azimuth_deg))


#: azimuth sectors of the sun masks among the buildings (:func:`building_masks`): 1 deg
BUILDING_SECTORS = 360
#: slope (tan of elevation) up to which every ray is left to Embree: buildings that rise no
#: higher than this from a roof point are not walked through at all (tan 3 deg)
MASK_FLOOR = float(np.tan(np.radians(3.0)))
#: a mesh triangle seen across more sectors than this is split in four for a tighter bound
_SPLIT_SECTORS = 4
_MAX_DEPTH = 3


@njit(cache=True, nogil=True)
def pseudo_azimuth(dx, dy):
    """A stand-in for the azimuth of direction (*dx*, *dy*) from +y clockwise, without a
    trigonometric call: in [0, 4), rising with the azimuth, a quarter turn per unit and
    the opposite direction 2 further on (the "diamond angle")."""
    s = abs(dx) + abs(dy)
    if not s > 0.0:
        return 0.0
    if dx >= 0.0:
        return dx / s if dy >= 0.0 else 1.0 - dy / s
    return 2.0 - dx / s if dy <= 0.0 else 3.0 + dy / s


@njit(cache=True, nogil=True)
def building_sector(dx, dy, S):
    """The sector of :func:`building_masks` (of *S*) direction (*dx*, *dy*) falls in."""
    return np.int64(np.floor(pseudo_azimuth(dx, dy) * (S / 4.0))) % S


@njit(cache=True, nogil=True)
def _dist_segment(px, py, ax, ay, bx, by):
    ex, ey = bx - ax, by - ay
    ll = ex * ex + ey * ey
    t = 0.0 if ll <= 0.0 else min(max(((px - ax) * ex + (py - ay) * ey) / ll, 0.0), 1.0)
    qx, qy = ax + t * ex - px, ay + t * ey - py
    return np.sqrt(qx * qx + qy * qy)


@njit(cache=True, nogil=True)
def _mark(out, i, v, ox, oy, oz, S, floor_, force):
    """One triangle *v* (3, 3) into ``out[i]``; returns False (and marks nothing) where it
    is seen across too many sectors and not *force*: it is to be split."""
    dz = max(v[0, 2], v[1, 2], v[2, 2]) - oz
    if dz <= 0.0:
        return True
    d = min(_dist_segment(ox, oy, v[0, 0], v[0, 1], v[1, 0], v[1, 1]),
            _dist_segment(ox, oy, v[1, 0], v[1, 1], v[2, 0], v[2, 1]),
            _dist_segment(ox, oy, v[2, 0], v[2, 1], v[0, 0], v[0, 1])) - 1e-3
    # the origin under the triangle (inside its outline on the ground, or within 1 mm)
    c0 = (v[1, 0] - v[0, 0]) * (oy - v[0, 1]) - (v[1, 1] - v[0, 1]) * (ox - v[0, 0])
    c1 = (v[2, 0] - v[1, 0]) * (oy - v[1, 1]) - (v[2, 1] - v[1, 1]) * (ox - v[1, 0])
    c2 = (v[0, 0] - v[2, 0]) * (oy - v[2, 1]) - (v[0, 1] - v[2, 1]) * (ox - v[2, 0])
    inside = (c0 >= 0 and c1 >= 0 and c2 >= 0) or (c0 <= 0 and c1 <= 0 and c2 <= 0)
    if inside or d <= 0.0:
        for k in range(S):
            out[i, k] = np.inf
        return True
    bound = dz / d * 1.001 + 1e-4
    if bound <= floor_:
        return True
    # the azimuths the triangle covers: the shortest arc through its corners' (it does not
    # surround the origin), padded by a sector each side
    w = 4.0 / S
    a0 = pseudo_azimuth(v[0, 0] - ox, v[0, 1] - oy)
    a1 = pseudo_azimuth(v[1, 0] - ox, v[1, 1] - oy)
    a2 = pseudo_azimuth(v[2, 0] - ox, v[2, 1] - oy)
    lo, hi = min(a0, a1, a2), max(a0, a1, a2)
    if hi - lo > 2.0:            # the arc crosses the azimuth 0: measure from there
        a0 = a0 + 4.0 if a0 < 2.0 else a0
        a1 = a1 + 4.0 if a1 < 2.0 else a1
        a2 = a2 + 4.0 if a2 < 2.0 else a2
        lo, hi = min(a0, a1, a2), max(a0, a1, a2)
    k0 = np.int64(np.floor(lo / w)) - 1
    k1 = np.int64(np.floor(hi / w)) + 1
    if k1 - k0 > _SPLIT_SECTORS + 2 and not force:
        for k in range(k0, k1 + 1):
            if bound > out[i, k % S]:
                return False
        return True              # no higher than the bound already there: nothing to add
    for k in range(k0, k1 + 1):
        kk = k % S
        if bound > out[i, kk]:
            out[i, kk] = bound
    return True


@njit(cache=True, nogil=True)
def building_masks(tri, top, box, o, reach, floor_, out):
    """For each origin ``o[i]`` and azimuth sector ``k`` (of ``S = out.shape[1]``, from +y
    clockwise, :func:`building_sector`: sectors of equal :func:`pseudo_azimuth`, 0.8-1.3
    deg for 360), into ``out[i, k]``: a bound on
    the slope (tan of the elevation) above which a ray from the origin in that sector meets
    none of the triangles *tri* (m, 3, 3; *top* their highest corners' z, *box* their
    ``xmin, ymin, xmax, ymax``, float64) within *reach* (m, horizontally); at least
    *floor_*; inf where a triangle is above the origin.

    A triangle's bound is its highest corner over its least horizontal distance from the
    origin, over the azimuths it covers (its corners' shortest arc and a sector more each
    side); one seen across more than a few sectors is split in four (to a depth of 3), so a
    long wall or roof counts its near part high and its far parts lower.  The margins (1 mm,
    0.1 % and 1e-4) keep the bound safe for float32 rays: where a ray's slope exceeds it,
    neither an exact test nor Embree finds a hit."""
    S = out.shape[1]
    cap = 3 * _MAX_DEPTH + 4
    stack = np.empty((cap, 3, 3))
    depth = np.empty(cap, np.int64)
    v = np.empty((3, 3))
    for i in range(o.shape[0]):
        for k in range(S):
            out[i, k] = floor_
        ox, oy, oz = np.float64(o[i, 0]), np.float64(o[i, 1]), np.float64(o[i, 2])
        for j in range(tri.shape[0]):
            dz = top[j] - oz
            if dz <= 0.0:
                continue                        # wholly below the origin: no rising ray meets it
            gx = max(box[j, 0] - ox, 0.0, ox - box[j, 2])
            gy = max(box[j, 1] - oy, 0.0, oy - box[j, 3])
            gap = np.sqrt(gx * gx + gy * gy)
            if gap > reach or (gap > 1e-3 and dz / (gap - 1e-3) * 1.001 + 1e-4 <= floor_):
                continue                        # beyond the rays' length, or below the floor
            for a in range(3):
                for b in range(3):
                    stack[0, a, b] = tri[j, a, b]
            depth[0] = 0
            n = 1
            while n:
                n -= 1
                for a in range(3):
                    for b in range(3):
                        v[a, b] = stack[n, a, b]
                dd = depth[n]
                if _mark(out, i, v, ox, oy, oz, S, floor_, dd >= _MAX_DEPTH):
                    continue
                # four halves-of-edges triangles (corners and edge midpoints)
                for q in range(4):
                    for a in range(3):
                        # child q < 3 keeps corner q, its other corners the midpoints of
                        # q's edges; child 3 the three midpoints
                        u, e = (a, (a + 1) % 3) if q == 3 else (q, a)
                        for b in range(3):
                            stack[n, a, b] = 0.5 * (v[u, b] + v[e, b])
                    depth[n] = dd + 1
                    n += 1
