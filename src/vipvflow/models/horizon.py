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
"""
from __future__ import annotations


import numpy as np
import pandas as pd

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
