"""The per-segment geometry of a roof pass, computed once per 10 m segment.

The roof plane, the sky the roof sees (sky view factor), the reflecting
surfaces around it and their exchange weights, stored with the tile's
geometry and read by the per-pass irradiance (:mod:`.irradiance`).
"""
from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
from numba import njit

from .params import IrradianceCfg
from .mesh import SURFACE_CODE
from .sky import SKY_AZIMUTH_BINS as _SKY_SECTORS

_GOLDEN = (np.sqrt(5.0) - 1.0) / 2.0


_CHUNK = 1 << 20        # passes per chunk in evaluate_passes


_MIN_REFLECTOR_LIFT = 0.02   # m: a reflector's sun ray starts off its own surface


_DENSE_SVF, _DENSE_RAYS = 0.75, 4   # below this sky view factor, 4x the reflection rays


_GROUND_CODES = [SURFACE_CODE["ground"], SURFACE_CODE["terrain"]]   # lit like open ground


# ---------------------------------------------------------------------------- roof plane
def roof_plane(heading_deg, gradient):
    """Roof tilt and azimuth from the heading and the road gradient.

    Parameters
    ----------
    heading_deg : array, direction of travel (deg from north, clockwise)
    gradient : array, dz/ds (dimensionless; > 0 climbing)

    Returns
    -------
    tilt_deg, azimuth_deg : arrays
        Tilt from horizontal and azimuth of the downhill direction the roof faces.
    """
    heading = np.asarray(heading_deg, np.float64)
    g = np.asarray(gradient, np.float64)
    tilt = np.degrees(np.arctan(np.abs(g)))
    azimuth = np.where(g > 0, heading + 180.0, heading) % 360.0
    return tilt, azimuth


def plane_normal(tilt_deg, azimuth_deg) -> np.ndarray:
    """Unit normal (east, north, up) of a plane of given tilt and azimuth, shape (n, 3)."""
    t, a = np.radians(tilt_deg), np.radians(azimuth_deg)
    return np.stack([np.sin(t) * np.sin(a), np.sin(t) * np.cos(a), np.cos(t)], axis=-1)


def sun_vector(zenith_deg, azimuth_deg) -> np.ndarray:
    """Unit vector towards the sun (east, north, up), shape (n, 3)."""
    return plane_normal(zenith_deg, azimuth_deg)


# ---------------------------------------------------------------------------- sampling
def segment_uniforms(seed: int, stream: int, keys: np.ndarray, n: int) -> np.ndarray:
    """Uniform random numbers drawn from a generator of its own per key (segment id).

    A segment's rays then do not depend on which other segments share its batch, tile or
    worker: results are deterministic for a given ``seed``, stream and segment id.

    Parameters
    ----------
    seed : int, ``IrradianceCfg.seed``
    stream : int, what the numbers are for (0 sky view, 1 roof hemisphere rays, 2 the
        reflector groups' own rays, 3 the street's own rays): independent streams
    keys : (m,) int, segment ids
    n : int, numbers per key

    Returns
    -------
    (m, n) float64 in [0, 1)

    References
    ----------
    numpy ``random.default_rng`` (PCG64 seeded by ``SeedSequence([seed, stream, key])``).
    """
    from numpy.random import PCG64, Generator, SeedSequence

    keys = np.asarray(keys, dtype=np.int64)
    out = np.empty((len(keys), n))
    for i, key in enumerate(keys):
        # default_rng([seed, stream, key]) built directly: the same numbers, half the time
        out[i] = Generator(PCG64(SeedSequence([seed, stream, int(key)]))).random(n)
    return out


def cosine_directions(normals: np.ndarray, n_rays: int, rng) -> np.ndarray:
    """Cosine-weighted hemisphere directions about each normal, stratified.

    Ray ``k`` of a normal falls in the ``k``-th of ``n_rays`` equal-area rings of the unit
    disk (jittered within it) at the golden angle from ray ``k - 1`` (a Fibonacci spiral,
    rotated at random per normal), and is lifted onto the hemisphere (Malley's method), so
    the projected solid angle is sampled evenly and each normal's rays are independent of
    the others'.  Each ray is uniform over its ring, an equal share of the projected solid
    angle, so the mean of a quantity over the rays estimates its cosine-weighted
    hemispherical mean without bias, with the variance of a stratified sample.

    Parameters
    ----------
    normals : (m, 3) float, unit normals (east, north, up)
    n_rays : int, rays per normal
    rng : numpy Generator, or (m, n_rays + 1) uniforms in [0, 1) (see
        :func:`segment_uniforms`): the radial jitter of each ray and the spiral's rotation

    Returns
    -------
    (m, n_rays, 3) float64 unit vectors

    References
    ----------
    M. Pharr, W. Jakob, G. Humphreys, Physically Based Rendering, 3rd ed. (2016), sections
    13.6.3 (Malley's method) and 7.3 (stratified sampling); R. Swinbank, R. J. Purser
    (2006), Fibonacci grids, Q. J. R. Meteorol. Soc. 132, 1769-1793.
    """
    from .hemisphere import directions

    m = len(normals)
    if isinstance(rng, np.random.Generator):
        uni = rng.random((m, n_rays + 1))
    else:
        uni = np.asarray(rng, dtype=np.float64).reshape(m, n_rays + 1)
    return directions(np.ascontiguousarray(normals, dtype=np.float64),
                      np.ascontiguousarray(uni), int(n_rays), _GOLDEN)


# ---------------------------------------------------------------------------- geometry
def _roof_points(segments: pd.DataFrame) -> np.ndarray:
    if {"x_end", "y_end", "z_end"} <= set(segments.columns):
        return np.stack([(segments["x"].to_numpy(float) + segments["x_end"].to_numpy(float)) / 2,
                         (segments["y"].to_numpy(float) + segments["y_end"].to_numpy(float)) / 2,
                         (segments["z"].to_numpy(float) + segments["z_end"].to_numpy(float)) / 2], 1)
    return segments[["x", "y", "z"]].to_numpy(np.float64)


def _orientation_class(n: np.ndarray) -> np.ndarray:
    """Orientation class of reflector normals: 0 up, 1 down, 2..9 eight azimuth sectors."""
    az = np.degrees(np.arctan2(n[:, 0], n[:, 1])) % 360.0
    sector = 2 + (((az + 22.5) % 360.0) // 45.0).astype(np.int64)
    return np.where(n[:, 2] > 0.7, 0, np.where(n[:, 2] < -0.7, 1, sector))


def _dominant_surface(gkey, surface, w, n_keys: int) -> np.ndarray:
    """The surface (index into the tile mesh's ``surface_ids``) holding most of each
    group's weight, -1 for groups without hits; shape (n_keys,)."""
    out = np.full(n_keys, -1, np.int64)
    if len(gkey):
        s = pd.Series(w).groupby([np.asarray(gkey), np.asarray(surface)]).sum()
        top = s.sort_values(ascending=False, kind="stable").groupby(level=0).head(1)
        out[top.index.get_level_values(0).to_numpy()] = top.index.get_level_values(1).to_numpy()
    return out


@njit(cache=True, nogil=True)
def _order_in_groups(group, key, n_groups):
    """``np.lexsort((key, group))`` for integer groups ``0 .. n_groups - 1`` and keys
    without NaN: the hits by group (a stable counting sort), each group's by key (stable:
    equal keys keep their order), so the same permutation, a stable sort's being unique."""
    n = group.shape[0]
    start = np.zeros(n_groups + 1, np.int64)
    for i in range(n):
        start[group[i] + 1] += 1
    for g in range(n_groups):
        start[g + 1] += start[g]
    pos = start[:-1].copy()
    out = np.empty(n, np.int64)
    for i in range(n):
        g = group[i]
        out[pos[g]] = i
        pos[g] += 1
    for g in range(n_groups):
        lo, hi = start[g], start[g + 1]
        if hi - lo < 2:
            continue
        if hi - lo <= 24:
            for a in range(lo + 1, hi):            # insertion: strictly greater moves on
                v = out[a]
                b = a - 1
                while b >= lo and key[out[b]] > key[v]:
                    out[b + 1] = out[b]
                    b -= 1
                out[b + 1] = v
        else:
            run = out[lo:hi].copy()
            out[lo:hi] = run[np.argsort(key[run], kind="mergesort")]
    return out


def _lexsort_groups(key, group, n_groups: int) -> np.ndarray:
    """:func:`_order_in_groups`, or ``np.lexsort`` where a key is NaN."""
    key = np.ascontiguousarray(key, np.float64)
    if np.isnan(key).any():
        return np.lexsort((key, group))
    return _order_in_groups(np.ascontiguousarray(group, np.int64), key, np.int64(n_groups))


@njit(cache=True, nogil=True)
def _first_reaching(cw, glo, ghi, target):
    """Per group ``g`` (hits ``glo[g] .. ghi[g]``, their cumulative weights *cw* not
    decreasing) and each of its targets ``target[g, k]``: the number of hits before the
    first whose cumulative weight reaches the target (all hits of earlier groups, and the
    group's own with a smaller weight)."""
    m, P = target.shape
    out = np.empty((m, P), np.int64)
    for g in range(m):
        lo, hi = glo[g], ghi[g] + 1
        for k in range(P):
            a, b = lo, max(lo, hi)
            t = target[g, k]
            while a < b:                          # the first index with cw >= t
                c = (a + b) >> 1
                if cw[c] < t:
                    a = c + 1
                else:
                    b = c
            out[g, k] = a
    return out


def _group_points(o, hs, gkey, w, hp, hn, w_g, n_g, P: int, lift: float, w_t=None):
    """P sample points per reflector group, each standing for an equal share of the group's
    weight (albedo x view factor), stratified over the group's surface in two dimensions.

    The hits of the roof's rays on a group (each a sample of the group's weight) are split
    into ``B = sqrt(P)`` bands of equal weight along a first key, and each band into ``B``
    cells of equal weight along a second key: ``P`` cells of ``1/P`` of the weight each.
    The point of cell ``(b, c)`` is the hit holding the weight quantile ``(s + 1/2) / B``
    of its cell ordered along the first key, ``s = (b + c) mod B`` (a Latin square), so the
    ``P`` points stand at ``P`` distinct levels of the first key and in ``B`` strata of the
    second within every band (multi-jittered sampling, without the jitter).  Walls: height,
    then position along the facade (shadows of other buildings cover a facade from the
    bottom up, and streets across let the sun in along some stretches only); roof- and
    ground-like groups: horizontal distance from the roof point, then azimuth about it.
    ``P`` not a square: ``P`` bands along the first key (one point at the middle of each).

    Parameters
    ----------
    o : (m, 3) roof points, m
    hs : (h,) int, segment (row of *o*) of each hit
    gkey : (h,) int, ``segment x G + group`` of each hit
    w : (h,) weight of each hit (albedo / rays)
    hp, hn : (h, 3) hit points (m) and unit normals facing the roof
    w_g : (m, G) group weights (``w`` summed per group), n_g : (m, G, 3) group normals
    P : int, points per group
    lift : float, m, the points are lifted off their surface by this along its normal

    With *w_t* (h, C), each hit's weight seen through the tree crowns per class of months,
    also each point's factor per class (m, G, P, C): its cell's share of the group's weight
    through the crowns over its share without (1/P), so that the mean of the points' lit
    fractions times their factors is the group's lit fraction as the roof sees it through
    the crowns (a point of an empty cell: the group's mean).

    Returns
    -------
    points (m, G, P, 3), m, and their surface normals (m, G, P, 3); groups without hits keep
    the roof point and the group normal; the factors (None without *w_t*).

    References
    ----------
    K. Chiu, P. Shirley, C. Wang (1994), Multi-jittered sampling, Graphics Gems IV, 370-374.
    """
    m, G = w_g.shape
    n_flat = n_g.reshape(-1, 3)
    vertical = np.abs(n_flat[:, 2]) < 0.7
    rel = hp - o[hs]
    along = rel[:, 0] * -n_flat[gkey, 1] + rel[:, 1] * n_flat[gkey, 0]     # along the facade
    v = vertical[gkey]
    key1 = np.where(v, hp[:, 2], np.hypot(rel[:, 0], rel[:, 1]))
    key2 = np.where(v, along, np.arctan2(rel[:, 0], rel[:, 1]))
    wflat = w_g.reshape(-1)
    # band of each hit: the weight quantile of its mid-weight along key1 within its group
    # (sums within each group only, so a group's points do not depend on the others')
    srt = _lexsort_groups(key1, gkey, m * G)
    mid = np.empty(len(w))
    mid[srt] = _group_cumsum(w[srt], gkey[srt]) - 0.5 * w[srt]
    B = math.isqrt(P)
    B = B if B * B == P else P           # P not a square: P bands along key1, as in 1D
    band = np.minimum((B * mid / np.maximum(wflat[gkey], 1e-300)).astype(np.int64), B - 1)
    # cell within the band: the weight quantile of the hit's mid-weight along key2
    bkey = gkey * B + band
    w_band = np.bincount(bkey, w, m * G * B)
    srt = _lexsort_groups(key2, bkey, m * G * B)
    mid[srt] = _group_cumsum(w[srt], bkey[srt]) - 0.5 * w[srt]
    per = P // B                                                # cells per band
    cell = np.minimum((per * mid / np.maximum(w_band[bkey], 1e-300)).astype(np.int64), per - 1)
    ckey = bkey * per + cell
    # point k = (band b, cell c) takes, within its cell ordered by key1, the weight quantile
    # (s + 1/2) / per with s = (c + b) mod per: the P points hold P distinct key1 levels
    # (a Latin square of bands and cells) and B x per strata of key2 within the bands
    srt = _lexsort_groups(key1, ckey, m * G * B * per)
    cs = ckey[srt]
    gs = gkey[srt]
    cw = _group_cumsum(w[srt], gs)                              # within each group
    n_cell = m * G * B * per
    w_cell = np.bincount(ckey, w, n_cell).reshape(m * G, B * per)
    start = np.cumsum(w_cell, axis=1) - w_cell                  # within each group
    bb, cc = np.divmod(np.arange(B * per), per)
    sub = ((cc + bb) % per + 0.5) / per
    target = start + sub[None, :] * w_cell
    cells = np.arange(n_cell).reshape(m * G, P)
    lo = np.searchsorted(cs, cells, side="left")
    hi = np.searchsorted(cs, cells, side="right") - 1
    # an empty cell (a group of few hits) takes the hit at its target in the group's order
    glo = np.searchsorted(gs, np.arange(m * G), side="left")[:, None]
    ghi = np.searchsorted(gs, np.arange(m * G), side="right")[:, None] - 1
    empty = hi < lo
    lo, hi = np.where(empty, glo, lo), np.where(empty, np.maximum(ghi, glo), hi)
    # the first hit of the group whose cumulative weight reaches the target (the hits before
    # it: the earlier groups' and the group's own below the target; the weights are not
    # negative, so a group's cumulative weights do not decrease)
    first = _first_reaching(cw, glo[:, 0], ghi[:, 0], np.ascontiguousarray(target, np.float64))
    idx = np.clip(first, lo, hi)
    idx = srt[np.minimum(idx, len(srt) - 1)]
    used = (wflat > 0)[:, None]
    pts = np.where(used[..., None], hp[idx] + lift * hn[idx],
                   np.repeat(o, G, axis=0)[:, None, :])
    nrm = np.where(used[..., None], hn[idx], n_flat[:, None, :])
    factors = None
    if w_t is not None:
        C = w_t.shape[1]
        cell_w = np.bincount(ckey, w, n_cell).reshape(m * G, P)
        ratio = np.empty((m * G, P, C))
        for c in range(C):
            cell_c = np.bincount(ckey, w_t[:, c], n_cell).reshape(m * G, P)
            group = np.bincount(gkey, w_t[:, c], m * G) / np.maximum(wflat, 1e-300)
            ratio[:, :, c] = np.where(cell_w > 0, cell_c / np.where(cell_w > 0, cell_w, 1.0),
                                      group[:, None])
        mean = ratio.mean(1, keepdims=True)
        factors = np.where(mean > 0, ratio / np.where(mean > 0, mean, 1.0), 1.0).reshape(m, G, P, C)
    return pts.reshape(m, G, P, 3), nrm.reshape(m, G, P, 3), factors


#: the surface index of the street where the city model has none (the virtual ground)
VIRTUAL_GROUND = -2


def _hits(scene, o, d, ray_length_m: float, ground_z, road_albedo: float, crowns=None) -> dict:
    """What rays from *o* (n, 3) along *d* (n, 3) hit first: a triangle of the mesh, else the
    street where the city model has none.

    A city model without terrain or road surfaces (most LoD2 building files) leaves the
    street out, and a ray that leaves a facade downwards would escape, counted as open
    ground lit like a field.  Here a ray that hits nothing and points down meets the
    level ground at *ground_z* (the road under the roof point, m) within the ray length:
    the street, with the road's albedo, lit and shaded as the buildings shade it (its
    sample points cast their own sun rays).  A mesh hit always wins (terrain, roads).

    With *crowns* (:class:`vipvflow.models.trees.Crowns` of the scene) also ``T`` (n, C):
    the crowns' transmittance per class of months along each ray up to what it hits (its
    whole length where it hits nothing); None without.

    Returns
    -------
    dict of (n,) arrays: ``tri`` (mesh triangle, :data:`VIRTUAL_GROUND` for the virtual
    street, -1 for nothing), ``dist`` (m, inf for nothing), ``albedo``, ``ground`` (bool:
    ground, terrain, road or the virtual street), ``normal`` (n, 3) the surface's normal as
    stored (up for the virtual street), ``T``
    """
    tri, dist = scene.first_hit(o, d, ray_length_m)
    tri = tri.astype(np.int64)
    dist = dist.astype(np.float64)
    mesh = scene.mesh
    n = len(tri)
    hit = tri >= 0
    t = np.where(hit, tri, 0)
    albedo = np.zeros(n)
    ground = np.zeros(n, bool)
    normal = np.zeros((n, 3))
    normal[:, 2] = 1.0
    if len(mesh.albedo):
        albedo[hit] = np.asarray(mesh.albedo, np.float64)[t[hit]]
        ground[hit] = np.isin(np.asarray(mesh.surface_type)[t[hit]], _GROUND_CODES)
        normal[hit] = np.asarray(mesh.normals, np.float64)[t[hit]]
    if ground_z is not None:
        gz = np.broadcast_to(np.asarray(ground_z, np.float64), (n,))
        down = ~hit & (d[:, 2] < 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_g = (o[:, 2] - gz) / -d[:, 2]
        virtual = down & (t_g > 0) & (t_g <= ray_length_m)
        tri[virtual], dist[virtual] = VIRTUAL_GROUND, t_g[virtual]
        albedo[virtual], ground[virtual] = road_albedo, True
    T = None
    if crowns is not None:
        T = crowns.transmittance(np.asarray(o, np.float64) - scene.origin, d,
                                 np.where(np.isfinite(dist), dist, ray_length_m))
    return {"tri": tri, "dist": dist, "albedo": albedo, "ground": ground, "normal": normal, "T": T}


def _class_mean(values: np.ndarray, T, n: int) -> np.ndarray | None:
    """Per class: the mean of *values* x the crowns' transmittance *T* (rays, C) over each
    row's *n* consecutive rays, (rows, C); None without crowns."""
    if T is None:
        return None
    v = np.asarray(values, np.float64)[:, None] * T
    return v.reshape(-1, n, T.shape[1]).mean(1)


def _group_cumsum(values: np.ndarray, groups: np.ndarray) -> np.ndarray:
    """Cumulative sums of *values* restarting at each run of equal *groups* (sorted): each
    group's sums are its own, whatever comes before it (float64)."""
    if not len(values):
        return np.zeros(0)
    return pd.Series(np.asarray(values, np.float64)).groupby(np.asarray(groups), sort=False).cumsum().to_numpy()


def _reflector_surroundings(scene, keys, pts, nrm, used, cfg: IrradianceCfg, stream: int = 2,
                            ground_z=None, road_albedo: float = 0.10, crowns=None):
    """What the sample points of each reflector group see over their own hemisphere (m, G).

    ``cfg.reflector_sky_rays`` cosine-weighted rays from every sample point: a ray that
    escapes upwards sees sky, one that hits a ground, terrain or road triangle, or the level
    street under the segment where the model has no surface (*ground_z*, m, per segment;
    :func:`_hits`), sees the street (weighted by its albedo; *road_albedo* for the virtual
    street), one that escapes downwards beyond the ray length sees open ground (lit as an
    open field, albedo applied per run), one that hits any other surface (a facade, a roof)
    sees light that surface reflects (weighted by its albedo).

    Returns
    -------
    dict of (m, G) arrays ``sky``, ``gnd`` (albedo-weighted street), ``open``, ``wall``
    (albedo-weighted facades and roofs), ``hor`` (view of the band of sky near the horizon,
    :func:`horizon_band_view`, mean over the points), and the street hits ``hits``: ``pair`` (segment x
    G + group), ``p`` (hit points, m), ``n`` (upward normals), ``w`` (albedo / rays, the
    hit's share of the group's ``gnd``).  With *crowns*, ``sky_t``, ``gnd_t``, ``open_t``,
    ``wall_t``, ``hor_t`` (m, G, C): the same seen through the crowns, per class of months.
    """
    m, G, P, _ = pts.shape
    R = cfg.reflector_sky_rays
    out = {k: np.zeros((m, G)) for k in ("sky", "gnd", "open", "wall", "hor")}
    C = crowns.n_classes if crowns is not None else 0
    if C:
        out.update({f"{k}_t": np.zeros((m, G, C)) for k in ("sky", "gnd", "open", "wall", "hor")})
    sel = np.flatnonzero(used.reshape(-1))                     # active (segment, group)
    out["hits"] = {"pair": np.zeros(0, np.int64), "p": np.zeros((0, 3)), "n": np.zeros((0, 3)),
                   "w": np.zeros(0)}
    if not len(sel):
        return out
    uni = segment_uniforms(cfg.seed, stream, keys, G * P * (R + 1)).reshape(m * G, P, R + 1)
    d = cosine_directions(nrm.reshape(m * G, P, 3)[sel].reshape(-1, 3), R,
                          uni[sel].reshape(-1, R + 1)).reshape(-1, 3)
    oo = np.repeat(pts.reshape(m * G, P, 3)[sel].reshape(-1, 3), R, axis=0)
    n = P * R
    gz = None if ground_z is None else np.repeat(np.repeat(np.asarray(ground_z, np.float64), G)[sel], n)
    h = _hits(scene, oo, d, cfg.ray_length_m, gz, road_albedo, crowns)
    tri, dist, a = h["tri"], h["dist"], h["albedo"]
    hit = tri != -1
    on_ground = h["ground"]
    seen = {"sky": ~hit & (d[:, 2] > 0), "open": ~hit & (d[:, 2] <= 0),
            "gnd": np.where(on_ground, a, 0.0), "wall": np.where(hit & ~on_ground, a, 0.0)}
    for k, v in seen.items():
        out[k].reshape(-1)[sel] = v.astype(np.float64).reshape(-1, n).mean(1)
        if C:
            out[f"{k}_t"].reshape(-1, C)[sel] = _class_mean(v, h["T"], n)
    # the view of the band of sky near the horizon (the Perez horizon term), R rays a point
    pn = nrm.reshape(m * G, P, 3)[sel].reshape(-1, 3)
    band_uni = segment_uniforms(cfg.seed, stream + 3, keys, G * P * 2 * R).reshape(m * G, P, 2 * R)
    band, band_t = _horizon_band(scene, pts.reshape(m * G, P, 3)[sel].reshape(-1, 3), pn,
                                 band_uni[sel].reshape(-1, 2 * R), R, cfg.ray_length_m, crowns)
    out["hor"].reshape(-1)[sel] = band.reshape(-1, P).mean(1)
    if C:
        out["hor_t"].reshape(-1, C)[sel] = band_t.reshape(-1, P, C).mean(1)
    g = np.flatnonzero(on_ground & (a > 0))
    if len(g):
        tn = h["normal"][g]
        tn = np.where((tn[:, 2:3] < 0), -tn, tn)
        out["hits"] = {"pair": sel[g // n], "p": oo[g] + dist[g, None].astype(np.float64) * d[g],
                       "n": tn, "w": a[g] / n}
        if C:
            out["hits"]["T"] = h["T"][g]
    return out


def _street(o, gw, surround, keys, cfg: IrradianceCfg, scene, lift: float, ground_z=None,
            road_albedo: float = 0.10, crowns=None, gw_t=None):
    """The street the reflector groups see, as one more reflector of each segment.

    Its P sample points are taken from the street hits of the groups' own rays, each hit
    weighted by its share of the light it sends to the roof (group weight x albedo / rays),
    like :func:`_group_points`; its own rays give its sky view and what facades it sees.

    Returns
    -------
    dict of arrays: ``n`` (m, 3) weighted mean normal, ``pts`` (m, P, 3), ``used`` (m,),
    and the street's own ``sky``, ``wall`` (m,) (see :func:`_reflector_surroundings`); with
    *crowns* ``sky_t``, ``wall_t`` (m, C) through them and the points' factors ``f`` (m, P,
    C) (the street seen through the crowns from the groups the roof sees through them,
    *gw_t* (m, G, C): :func:`_group_points`).
    """
    m, G = gw.shape
    P = cfg.reflector_points
    h = surround["hits"]
    seg = h["pair"] // max(G, 1)
    w = h["w"] * gw.reshape(-1)[h["pair"]]
    w_s = np.bincount(seg, w, m)[:, None]
    n_s = np.stack([np.bincount(seg, w * h["n"][:, j], m) for j in range(3)], -1)[:, None]
    used = w_s[:, 0] > 0
    n_s = np.where(used[:, None, None], n_s / np.maximum(np.linalg.norm(n_s, axis=2, keepdims=True),
                                                         1e-12), [0.0, 0.0, 1.0])
    C = crowns.n_classes if crowns is not None else 0
    if not used.any():
        pts = np.repeat(o[:, None], P, axis=1)
        z = np.zeros(m)
        out = {"n": n_s[:, 0], "pts": pts, "used": used, "sky": z, "wall": z.copy()}
        if C:
            out.update(sky_t=np.zeros((m, C)), wall_t=np.zeros((m, C)), f=np.ones((m, P, C)))
        return out
    w_t = None
    if C:
        w_t = (h["w"][:, None] * h["T"]) * gw_t.reshape(-1, C)[h["pair"]]
    pts, pn, f = _group_points(o, seg, seg, w, h["p"], h["n"], w_s, n_s, P, lift, w_t)
    own = _reflector_surroundings(scene, keys, pts, pn, used[:, None], cfg, stream=3,
                                  ground_z=ground_z, road_albedo=road_albedo, crowns=crowns)
    out = {"n": n_s[:, 0], "pts": pts[:, 0], "used": used, "sky": own["sky"][:, 0],
           "wall": own["wall"][:, 0]}
    if C:
        out.update(sky_t=own["sky_t"][:, 0], wall_t=own["wall_t"][:, 0], f=f[:, 0])
    return out


def segment_geometry(scene, segments: pd.DataFrame, cfg: IrradianceCfg | None = None,
                     chunk: int = 1024, road_albedo: float = 0.10,
                     roof_height_m: float | None = 3.2) -> pd.DataFrame:
    """Time-independent geometry of every segment: roof plane, sky view factor, reflectors.

    Parameters
    ----------
    scene : vipvflow.models.shading.Scene
    segments : DataFrame with ``segment_id, x, y, z, heading_deg, gradient`` (optional
        ``x_end, y_end, z_end``: the roof point is then the segment's midpoint), metres
    cfg : IrradianceCfg (``svf_rays``, ``reflection_rays``, ``max_reflector_groups``,
        ``reflector_points``, ``reflector_sky_rays``, ``horizon_band_rays``,
        ``ray_length_m``, ``ray_offset_m``, ``seed``)
    road_albedo : float, albedo of the street where the city model has no surface
        (``city.albedo.road``)
    roof_height_m : float or None, height of the roof point above the street, m: the level
        of the street under it where the model has no ground (:func:`_hits`; a
        ``ground_z`` column of *segments*, m, gives it instead); None: no such street, a ray
        that leaves the mesh downwards sees open ground

    Returns
    -------
    DataFrame, one row per segment (plain numeric columns):
        ``segment_id``; ``px, py, pz`` ray origin (roof point lifted by ``ray_offset_m``
        along the normal, m); ``tilt_deg, azimuth_deg``; ``nx, ny, nz`` roof normal;
        ``hbv`` the roof's view of the band of sky near the horizon (``sin tilt`` in the
        open, :func:`horizon_band_view`);
        ``svf`` cosine-weighted sky view factor (sky above the horizon and not blocked;
        (1 + cos tilt)/2 with no buildings); ``refl_vf`` albedo-weighted view factor of
        all surfaces seen, ``refl_vf_se`` its Monte Carlo standard error; for each group
        ``g < max_reflector_groups``: ``r{g}_w`` (sum albedo x view factor),
        ``r{g}_nx, r{g}_ny, r{g}_nz`` (unit normal facing the roof), ``r{g}_x, r{g}_y,
        r{g}_z`` (the group's hit point nearest its weighted mean), ``r{g}_p{k}_x,
        r{g}_p{k}_y, r{g}_p{k}_z`` for ``k < reflector_points`` (sample points for the
        group's lit fraction, each an equal share of its weight, stratified over the group
        in two dimensions, see :func:`_group_points`; m), ``r{g}_sky`` (the
        group's own cosine-weighted sky view factor), ``r{g}_gnd`` (albedo-weighted view
        factor of the modelled ground and terrain it sees), ``r{g}_open`` (view factor of
        open ground beyond the mesh, below the horizon), ``r{g}_wall`` (albedo-weighted view
        factor of facades and roofs it sees), ``r{g}_nlen`` (length of the group's
        weighted mean normal, <= 1: the beam on a group of several orientations is
        ``w x nlen x max(s . n, 0)``), ``r{g}_surface`` (index into the tile mesh's
        ``surface_ids`` of the surface holding most of the group's weight, -1 for none);
        the street the groups see: ``st_nx, st_ny, st_nz`` (normal), ``st_p{k}_x, _y, _z``
        (sample points), ``st_sky`` (its sky view), ``st_wall`` (albedo-weighted view of
        facades).  Points are lifted off their
        surface by ``max(ray_offset_m, 0.02 m)``.  Unused groups have weight 0.

    Notes
    -----
    All rays are stratified (:func:`cosine_directions`) and drawn per segment id
    (:func:`segment_uniforms`), so a segment's geometry is deterministic for a given
    ``seed`` and does not depend on its batch (*chunk* segments at a time: 1024 keeps a
    worker's rays and hits of a batch to ~0.4 GB; 4096 took a 3,000-segment tile's task to
    2.1 GB).  Segments with a sky view factor below 0.75
    (streets, where reflections matter most) get 4x ``reflection_rays``.  The error of the
    reflected part is dominated by the sample points' lit fraction (a shadow line crossing a
    facade); 64 points stratified 8 x 8 (the default) keep every point of the Radiance
    cross-checks within 20 % for every seed tried (docs/reflection_sampling.md).

    References
    ----------
    T. R. Oke (1988), Street design and urban canopy layer climate, Energy and Buildings 11,
    103-113 (sky view factor).  Cosine-weighted hemisphere sampling by Malley's method
    (concentric disk projected to the hemisphere): M. Pharr, W. Jakob, G. Humphreys,
    Physically Based Rendering, 3rd ed., section 13.6.3.  The roof model and its
    view-factor reflection: Pera et al., Dynamic 3D Solar Irradiation Modelling for
    Vehicle-Integrated Photovoltaics (CITATION.cff), sections 3.2.1 to 3.2.3.
    """
    cfg = cfg or IrradianceCfg()
    n_seg = len(segments)
    seg_ids = (segments["segment_id"].to_numpy(np.int64) if "segment_id" in segments
               else np.arange(n_seg, dtype=np.int64))
    tilt, azim = roof_plane(segments["heading_deg"].to_numpy(float),
                            segments["gradient"].to_numpy(float))
    normal = plane_normal(tilt, azim)
    roof = _roof_points(segments)
    origin = roof + cfg.ray_offset_m * normal
    if "ground_z" in segments:
        ground_z = segments["ground_z"].to_numpy(np.float64)
    elif roof_height_m is not None:
        ground_z = roof[:, 2] - float(roof_height_m)
    else:
        ground_z = None
    crowns = scene.crowns(cfg) if hasattr(scene, "crowns") else None
    C = crowns.n_classes if crowns is not None else 0
    G, P = cfg.max_reflector_groups, cfg.reflector_points
    svf = np.ones(n_seg, np.float64)
    hbv = np.zeros(n_seg, np.float64)
    trees = {"svf": np.ones((n_seg, C)), "hbv": np.zeros((n_seg, C))} if C else None
    acc = _no_reflectors(origin, G, P, C)
    H = cfg.horizon_band_rays
    for a in range(0, n_seg, chunk):
        sl = slice(a, min(n_seg, a + chunk))
        svf[sl], svf_t = _sky_view_factor(scene, origin[sl], normal[sl], seg_ids[sl], cfg, crowns)
        if C:
            trees["svf"][sl] = svf_t
        tilted = np.flatnonzero(np.hypot(normal[sl, 0], normal[sl, 1]) > 1e-6)
        if len(tilted):
            uni = segment_uniforms(cfg.seed, 4, seg_ids[sl][tilted], 2 * H)
            hbv[a + tilted], hbv_t = _horizon_band(scene, origin[sl][tilted], normal[sl][tilted],
                                                   uni, H, cfg.ray_length_m, crowns)
            if C:
                trees["hbv"][a + tilted] = hbv_t
        if not (cfg.reflection and cfg.reflection_rays > 0 and G > 0):
            continue
        # more rays where the sky view is small: reflections matter most there
        dense = svf[sl] < _DENSE_SVF
        for part, N in ((~dense, cfg.reflection_rays), (dense, _DENSE_RAYS * cfg.reflection_rays)):
            idx = np.arange(sl.start, sl.stop)[part]
            if len(idx):
                _reflectors(scene, origin[idx], normal[idx], seg_ids[idx], N, cfg, acc, idx,
                            None if ground_z is None else ground_z[idx], road_albedo, crowns)
    frame = _geometry_frame(seg_ids, origin, tilt, azim, normal, svf, acc, G, P, hbv)
    profile = None
    if cfg.diffuse_model == "perez_svf":
        # the Perez sky's luminance is integrated over the sky the roof point sees: its
        # horizon per 10 deg sector as a level index (models.sky.sky_levels)
        from .horizon import horizon_profile
        from .sky import sky_levels

        profile = np.concatenate([horizon_profile(scene, origin[a:a + chunk], max_distance_m=cfg.ray_length_m)
                                  for a in range(0, n_seg, chunk)]) if n_seg else np.zeros((0, 72), np.float32)
        frame = pd.concat([frame, pd.DataFrame(sky_levels(profile), columns=SKY_COLUMNS)], axis=1)
    if C:
        frame = pd.concat([frame, _tree_frame(crowns, scene, origin, trees, acc, G, cfg,
                                              None if profile is None else frame[SKY_COLUMNS])], axis=1)
    if profile is not None:
        frame.attrs["horizon_profile"] = profile        # the run stores it for the app, once
    return frame


def tree_columns(C: int, G: int) -> list[str]:
    """The geometry table's per-class columns of a tile with tree crowns (C classes of
    months, G reflector groups): the quantity of the column without ``_t{c}`` seen through
    the crowns in class ``c`` (:func:`segment_geometry`)."""
    names = ["svf", "hbv"] + [f"r{g}_{k}" for g in range(G)
                              for k in ("w", "sky", "gnd", "open", "wall", "hor")]
    if G:
        names += ["st_sky", "st_wall"]
    return [f"{n}_t{c}" for c in range(C) for n in names]


#: the geometry table's columns of each segment's class of months (crowns), January first
TREE_MONTH_COLUMNS = [f"tree_month_{m:02d}" for m in range(1, 13)]
#: the prefix of the crowns' loss per sky cell (``tsky_t{c}_{cell:03d}``, perez_svf)
_TSKY = re.compile(r"tsky_t(\d+)_(\d{3})")
#: a reflector's sample point's factor through the crowns (``r{g}_q{k}_t{c}``, ``st_q{k}_t{c}``)
_POINT_FACTOR = re.compile(r"(r\d+|st)_q(\d+)_t(\d+)")


def _tree_frame(crowns, scene, origin, trees: dict, acc: dict, G: int, cfg: IrradianceCfg,
                sky_x) -> pd.DataFrame:
    """The columns a tile with crowns adds to its geometry table: the class of each month
    (:data:`TREE_MONTH_COLUMNS`), :func:`tree_columns`, and with the Perez sky the crowns'
    loss per sky cell of each class (``tsky_t{c}_{cell:03d}``,
    :func:`vipvflow.models.trees.sky_cell_loss`)."""
    f32 = np.float32
    C, n = crowns.n_classes, len(origin)
    out = {m: np.full(n, k, np.int8) for m, k in zip(TREE_MONTH_COLUMNS, crowns.class_of_month)}
    for c in range(C):
        out[f"svf_t{c}"] = np.minimum(trees["svf"][:, c], 1.0).astype(f32)
        out[f"hbv_t{c}"] = trees["hbv"][:, c].astype(f32)
        for g in range(G):
            out[f"r{g}_w_t{c}"] = acc["w_t"][:, g, c].astype(f32)
            for k in ("sky", "gnd", "open", "wall", "hor"):
                out[f"r{g}_{k}_t{c}"] = acc[f"{k}_t"][:, g, c].astype(f32)
        if G:
            out[f"st_sky_t{c}"] = acc["street"]["sky_t"][:, c].astype(f32)
            out[f"st_wall_t{c}"] = acc["street"]["wall_t"][:, c].astype(f32)
    # each sample point's factor through the crowns (its cell's share of the reflector's
    # weight through them over its share without; _group_points), per class
    P = acc["f"].shape[2] if G else 0
    for c in range(C):
        for g in range(G):
            for k in range(P):
                out[f"r{g}_q{k}_t{c}"] = acc["f"][:, g, k, c].astype(f32)
        if G:
            for k in range(P):
                out[f"st_q{k}_t{c}"] = acc["street"]["f"][:, k, c].astype(f32)
    if sky_x is not None:
        from .trees import sky_cell_loss

        loss = sky_cell_loss(crowns, origin - scene.origin, np.asarray(sky_x, f32), cfg.ray_length_m)
        for c in range(C):
            for j in range(loss.shape[2]):
                out[f"tsky_t{c}_{j:03d}"] = loss[:, c, j]
    return _frame_by_dtype(out)


#: the geometry table's columns of the roof point's horizon per sky sector (perez_svf)
SKY_COLUMNS = [f"sky_x{k:02d}" for k in range(_SKY_SECTORS)]


def _no_reflectors(origin, G: int, P: int, C: int = 0) -> dict:
    """Per-segment reflector arrays of segments that see nothing (filled by :func:`_reflectors`);
    with C classes of months (crowns) also their ``w_t``, ``sky_t``.. (n, G, C)."""
    n = len(origin)
    out = {"refl_vf": np.zeros(n), "refl_se": np.zeros(n), "w": np.zeros((n, G)),
            "n": np.tile(np.array([0.0, 0.0, 1.0]), (n, G, 1)) if G else np.zeros((n, 0, 3)),
            "rep": np.repeat(origin[:, None], G, axis=1),
            "pts": np.repeat(np.repeat(origin[:, None, None], G, axis=1), P, axis=2),
            **{k: np.zeros((n, G)) for k in ("sky", "gnd", "open", "wall", "hor")},
            "nlen": np.ones((n, G)), "surface": np.full((n, G), -1, np.int64),
            "street": {"n": np.tile([0.0, 0.0, 1.0], (n, 1)),
                       "pts": np.repeat(origin[:, None], P, axis=1),
                       "sky": np.zeros(n), "wall": np.zeros(n)}}
    if C:
        out.update({f"{k}_t": np.zeros((n, G, C)) for k in ("w", "sky", "gnd", "open", "wall", "hor")})
        out["f"] = np.ones((n, G, P, C))
        out["street"].update(sky_t=np.zeros((n, C)), wall_t=np.zeros((n, C)), f=np.ones((n, P, C)))
    return out


def _sky_view_factor(scene, o, nrm, keys, cfg: IrradianceCfg, crowns=None):
    """Cosine-weighted sky view factor of roof points (m,): the share of ``cfg.svf_rays``
    stratified cosine-weighted rays that escape upwards, at most ``(1 + cos tilt) / 2``;
    and with *crowns* the same with each escaping ray weighted by the crowns' transmittance
    along it, per class of months (m, C) (None without).

    References
    ----------
    T. R. Oke (1988), Street design and urban canopy layer climate, Energy and Buildings 11,
    103-113.
    """
    R = cfg.svf_rays
    d = cosine_directions(nrm, R, segment_uniforms(cfg.seed, 0, keys, R + 1)).reshape(-1, 3)
    oo = np.repeat(o, R, axis=0)
    blocked = scene.occluded(oo, d, cfg.ray_length_m)
    escape = (~blocked) & (d[:, 2] > 0)
    free = escape.reshape(len(o), R).mean(axis=1)
    # never above the open field's (1 + cos tilt) / 2, which the rays only estimate
    cap = isotropic_sky_view(np.asarray(nrm, np.float64)[:, 2])
    if crowns is None:
        return np.minimum(free, cap), None
    T = np.zeros((len(oo), crowns.n_classes), np.float32)
    T[escape] = crowns.transmittance(oo[escape] - scene.origin, d[escape], cfg.ray_length_m)
    return np.minimum(free, cap), np.minimum(T.reshape(len(o), R, -1).mean(1), cap[:, None])


def horizon_band_directions(normals: np.ndarray, n_rays: int, uni: np.ndarray) -> np.ndarray:
    """Directions into the band of sky near the horizon in front of each plane, drawn in
    proportion to the light the band gives the plane.

    The Perez model's horizon band lies at the horizon, so it lights a plane of tilt
    ``beta`` in proportion to ``sin beta cos phi`` (``phi`` the azimuth from the plane's
    own); ray ``k`` takes its azimuth from the ``k``-th of *n_rays* equal shares of that
    weight (``phi = asin(2 u - 1)``, stratified and jittered) and its elevation uniform in
    the band's 6.5 deg, so the share of rays that escape is the weighted view of the band.

    Parameters
    ----------
    normals : (m, 3) float, unit normals (east, north, up)
    n_rays : int, rays per normal
    uni : (m, 2 n_rays) float, uniforms in [0, 1): the azimuth jitter, then the elevation

    Returns
    -------
    (m, n_rays, 3) float64 unit vectors

    References
    ----------
    R. Perez, R. Seals, P. Ineichen, R. Stewart, D. Menicucci (1987), Solar Energy 39(3),
    221-231 (the horizon band); M. Pharr, W. Jakob, G. Humphreys, Physically Based Rendering,
    3rd ed., section 13.3 (inversion method, stratified sampling).
    """
    from .sky import HORIZON_BAND_DEG

    n = np.asarray(normals, np.float64)
    m = len(n)
    uni = np.asarray(uni, np.float64).reshape(m, 2, n_rays)
    az0 = np.arctan2(n[:, 0], n[:, 1])[:, None]
    u = (np.arange(n_rays)[None, :] + uni[:, 0]) / n_rays
    az = az0 + np.arcsin(np.clip(2.0 * u - 1.0, -1.0, 1.0))
    el = np.radians(HORIZON_BAND_DEG) * uni[:, 1]
    ce = np.cos(el)
    return np.stack([ce * np.sin(az), ce * np.cos(az), np.sin(el)], -1)


def horizon_band_view(scene, o, nrm, uni, n_rays: int, ray_length_m: float) -> np.ndarray:
    """Each plane's view of the band of sky near the horizon, weighted as the Perez horizon
    term lights it: ``sin beta`` x the weighted share of the band in front of it that no
    surface hides (``sin beta`` for an open plane, 0 for a horizontal one); (m,) float64.

    Parameters
    ----------
    scene : vipvflow.models.shading.Scene
    o : (m, 3) ray origins (m), nrm : (m, 3) unit normals
    uni : (m, 2 n_rays) uniforms in [0, 1) (:func:`segment_uniforms`)
    n_rays : int, rays per plane (:func:`horizon_band_directions`)
    ray_length_m : float, m

    References
    ----------
    R. Perez et al. (1990), Solar Energy 44(5), 271-289 (the horizon term ``F2 sin beta``);
    pvlib ``irradiance.perez``.
    """
    return _horizon_band(scene, o, nrm, uni, n_rays, ray_length_m)[0]


def _horizon_band(scene, o, nrm, uni, n_rays: int, ray_length_m: float, crowns=None):
    """:func:`horizon_band_view` (m,), and with *crowns* the same with each free ray
    weighted by the crowns' transmittance along it, per class of months (m, C) (else None)."""
    nrm = np.asarray(nrm, np.float64)
    s = np.hypot(nrm[:, 0], nrm[:, 1])
    out = np.zeros(len(nrm))
    out_t = np.zeros((len(nrm), crowns.n_classes)) if crowns is not None else None
    tilted = np.flatnonzero(s > 1e-6)
    if not len(tilted):
        return out, out_t
    d = horizon_band_directions(nrm[tilted], n_rays, np.asarray(uni)[tilted]).reshape(-1, 3)
    oo = np.repeat(np.asarray(o, np.float64)[tilted], n_rays, axis=0)
    blocked = scene.occluded(oo, d, ray_length_m)
    out[tilted] = s[tilted] * (~blocked).reshape(-1, n_rays).mean(1)
    if crowns is not None:
        T = np.zeros((len(oo), crowns.n_classes), np.float32)
        T[~blocked] = crowns.transmittance(oo[~blocked] - scene.origin, d[~blocked], ray_length_m)
        out_t[tilted] = s[tilted, None] * T.reshape(-1, n_rays, crowns.n_classes).mean(1)
    return out, out_t


def _merge_groups(hs, hn, w, m: int, G: int) -> np.ndarray:
    """Reflector group (0..G-1) of each hit: the hits' orientation classes by weight, the G
    heaviest kept, every other class merged into the kept one nearest in orientation."""
    cls = _orientation_class(hn)
    C = 10
    key = hs * C + cls
    cw = np.bincount(key, w, m * C).reshape(m, C)
    cn = np.stack([np.bincount(key, w * hn[:, j], m * C) for j in range(3)], -1).reshape(m, C, 3)
    order = np.argsort(-cw, axis=1, kind="stable")
    kept = order[:, :G]
    rank = np.empty_like(order)
    np.put_along_axis(rank, order, np.arange(C)[None].repeat(m, 0), axis=1)
    kn = np.take_along_axis(cn, kept[..., None], axis=1)           # (m, G, 3)
    kn_u = kn / np.maximum(np.linalg.norm(kn, axis=2, keepdims=True), 1e-12)
    cn_u = cn / np.maximum(np.linalg.norm(cn, axis=2, keepdims=True), 1e-12)
    kw = np.take_along_axis(cw, kept, axis=1)
    sim = np.einsum("mcj,mgj->mcg", cn_u, kn_u) - 10.0 * (kw[:, None, :] <= 0)
    target = np.where(rank < G, rank, np.argmax(sim, axis=2))      # (m, C) -> group
    return target[hs, cls]


def _reflectors(scene, o, nrm, keys, N: int, cfg: IrradianceCfg, acc: dict, idx,
                ground_z=None, road_albedo: float = 0.10, crowns=None) -> None:
    """Reflector groups of the roof points *o* (m, 3) with normals *nrm*, from *N*
    cosine-weighted rays each; written into the rows *idx* of *acc* (see
    :func:`segment_geometry` for what each array holds).  *ground_z* (m,): the level of the
    street under each roof point where the model has none (:func:`_hits`).  With *crowns*
    the groups' weights and surroundings are also found through them, per class of months
    (``acc["w_t"]``...: the groups, their points and normals stay those without crowns)."""
    mesh = scene.mesh
    G, P = cfg.max_reflector_groups, cfg.reflector_points
    m = len(o)
    d = cosine_directions(nrm, N, segment_uniforms(cfg.seed, 1, keys, N + 1)).reshape(-1, 3)
    oo = np.repeat(o, N, axis=0)
    h = _hits(scene, oo, d, cfg.ray_length_m,
              None if ground_z is None else np.repeat(np.asarray(ground_z, np.float64), N), road_albedo,
              crowns)
    tri, dist = h["tri"], h["dist"]
    hit = tri != -1
    x = h["albedo"]
    xs = x.reshape(m, N)
    acc["refl_vf"][idx] = xs.mean(axis=1)
    acc["refl_se"][idx] = xs.std(axis=1, ddof=1) / np.sqrt(N) if N > 1 else 0.0
    hit &= x > 0
    if not hit.any():
        return
    hs, hd = np.repeat(np.arange(m), N)[hit], d[hit]
    hn = h["normal"][hit]
    hn = np.where(((hn * hd).sum(1) > 0)[:, None], -hn, hn)     # the face the roof sees
    hp = oo[hit] + dist[hit, None].astype(np.float64) * hd
    w = x[hit] / N
    gkey = hs * G + _merge_groups(hs, hn, w, m, G)
    w_g = np.bincount(gkey, w, m * G).reshape(m, G)
    w_t = None
    if crowns is not None:
        w_t = w[:, None] * h["T"][hit]
        acc["w_t"][idx] = np.stack([np.bincount(gkey, w_t[:, c], m * G).reshape(m, G)
                                    for c in range(w_t.shape[1])], -1)
    n_g = np.stack([np.bincount(gkey, w * hn[:, j], m * G) for j in range(3)], -1).reshape(m, G, 3)
    p_g = np.stack([np.bincount(gkey, w * hp[:, j], m * G) for j in range(3)], -1).reshape(m, G, 3)
    nz = w_g > 0
    norm = np.linalg.norm(n_g, axis=2)
    acc["nlen"][idx] = np.where(nz, norm / np.maximum(w_g, 1e-300), 1.0)
    n_g = np.where(nz[..., None], n_g / np.maximum(norm, 1e-12)[..., None], [0.0, 0.0, 1.0])
    mean_p = p_g / np.maximum(w_g, 1e-300)[..., None]
    # representative point: the group's hit point nearest its weighted mean
    dev = np.linalg.norm(hp - mean_p.reshape(-1, 3)[gkey], axis=1)
    srt = _lexsort_groups(dev, gkey, m * G)
    first = srt[np.unique(gkey[srt], return_index=True)[1]]
    rep = np.repeat(o[:, None], G, axis=1).reshape(-1, 3)
    rep[gkey[first]] = hp[first]
    # the surface holding most of each group's weight (for the export)
    surf = np.full(int(hit.sum()), -1, np.int64)
    on_mesh = tri[hit] >= 0
    surf[on_mesh] = np.asarray(mesh.surface_index, np.int64)[tri[hit][on_mesh]]
    acc["surface"][idx] = _dominant_surface(gkey, surf, w, m * G).reshape(m, G)
    # sample points (lit fraction) and the groups' own surroundings (sky, street, facades)
    lift = max(cfg.ray_offset_m, _MIN_REFLECTOR_LIFT)
    pts, pn, f = _group_points(o, hs, gkey, w, hp, hn, w_g, n_g, P, lift, w_t)
    if f is not None:
        acc["f"][idx] = f
    around = _reflector_surroundings(scene, keys, pts, pn, nz, cfg, ground_z=ground_z,
                                     road_albedo=road_albedo, crowns=crowns)
    for k in ("sky", "gnd", "open", "wall", "hor"):
        acc[k][idx] = around[k]
        if crowns is not None:
            acc[f"{k}_t"][idx] = around[f"{k}_t"]
    acc["w"][idx], acc["n"][idx], acc["rep"][idx], acc["pts"][idx] = w_g, n_g, rep.reshape(m, G, 3), pts
    st = _street(o, w_g, around, keys, cfg, scene, lift, ground_z, road_albedo, crowns,
                 acc["w_t"][idx] if crowns is not None else None)
    for k in acc["street"]:
        acc["street"][k][idx] = st[k]


def _geometry_frame(seg_ids, origin, tilt, azim, normal, svf, acc: dict, G: int, P: int,
                    hbv) -> pd.DataFrame:
    """The stored geometry table (plain numeric columns, see :func:`segment_geometry`)."""
    f32 = np.float32
    out = {"segment_id": seg_ids,
           "px": origin[:, 0], "py": origin[:, 1], "pz": origin[:, 2],
           "tilt_deg": tilt.astype(f32), "azimuth_deg": azim.astype(f32),
           "nx": normal[:, 0].astype(f32), "ny": normal[:, 1].astype(f32),
           "nz": normal[:, 2].astype(f32), "svf": svf.astype(f32), "hbv": hbv.astype(f32),
           "refl_vf": acc["refl_vf"].astype(f32), "refl_vf_se": acc["refl_se"].astype(f32)}
    for g in range(G):
        out[f"r{g}_w"] = acc["w"][:, g].astype(f32)
        for j, c in enumerate("xyz"):
            out[f"r{g}_n{c}"] = acc["n"][:, g, j].astype(f32)
        for j, c in enumerate("xyz"):
            out[f"r{g}_{c}"] = acc["rep"][:, g, j]
        for k in range(P):
            for j, c in enumerate("xyz"):
                out[f"r{g}_p{k}_{c}"] = acc["pts"][:, g, k, j]
        for k in ("sky", "gnd", "open", "wall", "hor", "nlen"):
            out[f"r{g}_{k}"] = acc[k][:, g].astype(f32)
        out[f"r{g}_surface"] = acc["surface"][:, g].astype(np.int32)
    if G:
        street = acc["street"]
        for j, c in enumerate("xyz"):
            out[f"st_n{c}"] = street["n"][:, j].astype(f32)
        for k in range(P):
            for j, c in enumerate("xyz"):
                out[f"st_p{k}_{c}"] = street["pts"][:, k, j]
        out["st_sky"] = street["sky"].astype(f32)
        out["st_wall"] = street["wall"].astype(f32)
    return _frame_by_dtype(out)


def _frame_by_dtype(columns: dict) -> pd.DataFrame:
    """``pd.DataFrame(columns)``, built from one 2-D block per dtype: the geometry table has
    about a thousand columns, and a frame built column by column cost more than the rays."""
    by_dtype: dict = {}
    for name, values in columns.items():
        by_dtype.setdefault(np.asarray(values).dtype, []).append(name)
    frames = [pd.DataFrame(np.column_stack([columns[c] for c in names]), columns=names)
              for names in by_dtype.values()]
    return pd.concat(frames, axis=1)[list(columns)]


_POINT_COLUMN = re.compile(r"(r\d+|st)_p(\d+)_([xyz])")


def geometry_table(geometry: pd.DataFrame):
    """The geometry table (:func:`segment_geometry`) as Arrow for its file: each reflector's
    P sample points (``r{g}_p{k}_{x,y,z}``, ``st_p{k}_...``) in one fixed-size list column
    ``<prefix>_points`` of its P x 3 coordinates (x, y, z of point 0, then point 1, ...),
    where the points' first column was; the other columns as they are.  A thousand scalar
    columns of a few dozen rows cost ten times more to write than the values
    (:func:`read_geometry` restores them)."""
    import pyarrow as pa

    names = [str(c) for c in geometry.columns]
    # the values as one 2-D block per dtype (a pandas lookup per column cost more than the
    # write): column i is block[i][:, where[i]]
    block, where = {}, {}
    by_dtype: dict = {}
    for i, dtype in enumerate(geometry.dtypes):
        by_dtype.setdefault(dtype, []).append(i)
    for positions in by_dtype.values():
        values = geometry.iloc[:, positions].to_numpy()
        for j, i in enumerate(positions):
            block[i], where[i] = values, j
    points: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        m = _POINT_COLUMN.fullmatch(name)
        if m:
            points.setdefault(m.group(1), []).append(i)
    first = {}
    for prefix, idx in points.items():
        P = len(idx) // 3
        if [names[i] for i in idx] != [f"{prefix}_p{k}_{c}" for k in range(P) for c in "xyz"]:
            raise ValueError(f"geometry columns of {prefix} not in point order")
        flat = np.ascontiguousarray(block[idx[0]][:, [where[i] for i in idx]], np.float64).ravel()
        first[idx[0]] = (f"{prefix}_points", pa.FixedSizeListArray.from_arrays(pa.array(flat), 3 * P))
    # the crowns' loss per sky cell of each class: one list column ``tsky_t{c}`` (float32)
    cells: dict[str, list[int]] = {}
    for i, name in enumerate(names):
        m = _TSKY.fullmatch(name)
        if m:
            cells.setdefault(f"tsky_t{m.group(1)}", []).append(i)
    for prefix, idx in cells.items():
        if [names[i] for i in idx] != [f"{prefix}_{j:03d}" for j in range(len(idx))]:
            raise ValueError(f"geometry columns of {prefix} not in cell order")
        flat = np.ascontiguousarray(block[idx[0]][:, [where[i] for i in idx]], np.float32).ravel()
        first[idx[0]] = (prefix, pa.FixedSizeListArray.from_arrays(pa.array(flat), len(idx)))
        points[prefix] = idx
    # the sample points' factors through the crowns: one list column ``<prefix>_q_t{c}``
    factors: dict[tuple, list[int]] = {}
    for i, name in enumerate(names):
        m = _POINT_FACTOR.fullmatch(name)
        if m:
            factors.setdefault((m.group(1), m.group(3)), []).append(i)
    for (prefix, c), idx in factors.items():
        if [names[i] for i in idx] != [f"{prefix}_q{k}_t{c}" for k in range(len(idx))]:
            raise ValueError(f"geometry columns of {prefix}'s point factors not in point order")
        flat = np.ascontiguousarray(block[idx[0]][:, [where[i] for i in idx]], np.float32).ravel()
        first[idx[0]] = (f"{prefix}_q_t{c}", pa.FixedSizeListArray.from_arrays(pa.array(flat), len(idx)))
        points[f"{prefix}_q_t{c}"] = idx
    in_points = {i for idx in points.values() for i in idx}
    out_names, out_arrays = [], []
    for i, name in enumerate(names):
        if i in first:
            out_names.append(first[i][0])
            out_arrays.append(first[i][1])
        elif i not in in_points:
            out_names.append(name)
            out_arrays.append(pa.array(np.ascontiguousarray(block[i][:, where[i]])))
    return pa.Table.from_arrays(out_arrays, names=out_names)


def read_geometry(path, columns: list[str] | None = None) -> pd.DataFrame:
    """A geometry file as the table :func:`segment_geometry` made (the sample points'
    list columns of :func:`geometry_table` expanded back; files written before them, with
    one column per coordinate, read as they are).  *columns*: only these scalar columns."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pq.read_table(path, columns=columns)
    out = {}
    for name, col in zip(table.column_names, table.columns):
        if pa.types.is_fixed_size_list(col.type) and name.endswith("_points"):
            prefix, size = name[:-len("_points")], col.type.list_size
            flat = col.combine_chunks().flatten().to_numpy().reshape(-1, size)
            for k in range(size // 3):
                for j, c in enumerate("xyz"):
                    out[f"{prefix}_p{k}_{c}"] = flat[:, 3 * k + j]
        elif pa.types.is_fixed_size_list(col.type) and name.startswith("tsky_t"):
            flat = col.combine_chunks().flatten().to_numpy().reshape(-1, col.type.list_size)
            for j in range(col.type.list_size):
                out[f"{name}_{j:03d}"] = flat[:, j]
        elif pa.types.is_fixed_size_list(col.type) and "_q_t" in name:
            prefix, c = name.split("_q_t")
            flat = col.combine_chunks().flatten().to_numpy().reshape(-1, col.type.list_size)
            for k in range(col.type.list_size):
                out[f"{prefix}_q{k}_t{c}"] = flat[:, k]
        else:
            out[name] = col.to_numpy()
    return _frame_by_dtype(out) if out else table.to_pandas()


COMPONENTS = ("direct", "diffuse", "reflected", "total", "direct_clear", "diffuse_clear",
              "reflected_clear", "total_clear", "total_unshaded", "total_clear_unshaded",
              "direct_no_trees", "diffuse_no_trees")


def _exchange_weights(w, f_street, f_wall, street_wall, has_street):
    """Weights of each reflector's own light at the roof, all bounces included.

    Reflectors ``j``: the segment's G groups and the street (last).  Each receives a source
    ``S_j`` (beam on its lit part, sky, open ground) and the light of the others:
    ``E = S + K E`` with ``K[g, street] = F_street,g`` (albedo-weighted view factor of the
    street from group ``g``), ``K[g, j] = F_wall,g w_j / sum_{k != g} w_k`` (the facades a
    group sees are taken at the irradiance of the segment's other groups, weighted as the
    roof sees them; at its own when it is alone) and ``K[street, j] = F_wall,street w_j /
    sum_k w_k``.  The roof receives ``sum_g w_g E_g = m . S`` with ``(I - K)^T m = w``
    (the radiosity equation of the few surfaces, solved per segment).

    Parameters
    ----------
    w : (s, G) albedo x view factor of each group from the roof
    f_street, f_wall : (s, G) albedo-weighted view factors of street and facades from each group
    street_wall : (s,) albedo-weighted view factor of facades from the street
    has_street : (s,) bool, whether the segment's groups see any street

    Returns
    -------
    (s, G + 1) weights ``m`` (the street's is 0 where it is not seen)
    """
    s, G = w.shape
    K = np.zeros((s, G + 1, G + 1))
    total = w.sum(1, keepdims=True)
    others = total - w                                           # (s, G)
    share = np.where(others[:, :, None] > 0,
                     w[:, None, :] / np.where(others > 0, others, 1.0)[:, :, None], 0.0)
    share[:, np.arange(G), np.arange(G)] = np.where(others > 0, 0.0, 1.0)
    K[:, :G, :G] = f_wall[:, :, None] * share
    K[:, :G, G] = np.where(has_street[:, None], f_street, 0.0)
    K[:, G, :G] = street_wall[:, None] * np.where(total > 0, w / np.where(total > 0, total, 1.0), 0.0)
    K[~has_street, G, :] = 0.0
    A = np.eye(G + 1)[None] - K
    rhs = np.concatenate([w, np.zeros((s, 1))], 1)
    return np.linalg.solve(np.swapaxes(A, 1, 2), rhs[..., None])[..., 0]


def pack_geometry(geometry: pd.DataFrame, cfg: IrradianceCfg, ground_albedo: float = 0.20,
                  scene=None) -> dict:
    """Per-segment arrays for :func:`roof_irradiance`, with the time-independent parts of
    eq. (3) folded in.

    Reflectors: the G groups the roof sees and the street those groups see (its sample
    points and normal ``st_*``).  Each reflector ``j`` (normal ``n_j``, own sky view factor
    ``F_s,j``, open-ground view factor ``F_o,j``) receives per pass the source
    ``S_j = DNI max(s . n_j, 0) L_j + DHI F_s,j + GHI rho_g F_o,j`` with ``L_j`` the lit
    fraction of its sample points; the light the reflectors exchange (facade to street to
    facade, facade to facade) is folded into one weight ``m_j`` per reflector
    (:func:`_exchange_weights`), so the roof receives ``sum_j m_j S_j``.  A segment needs
    ``m_j n_j`` and the points per reflector and two sums: ``refl_sky = sum m_j F_s,j`` (x DHI)
    and ``refl_ghi = sum m_j rho_g F_o,j`` (x GHI).

    A geometry table without the street and facade columns (older runs) lights the street
    a group sees by GHI, as an open field, and leaves out the exchange between facades; one
    without the per-group surroundings is read as the open field of the paper:
    ``F_s = (1 + n_z)/2``, ``F_g = 0``, ``F_o = (1 - n_z)/2``, and its single representative
    point ``r{g}_x, r{g}_y, r{g}_z``.

    With *scene*, the ray origins are also stored in that scene's float32 frame
    (:meth:`vipvflow.models.shading.Scene.to_local`), so the hot path builds its rays without
    converting them per pass.

    Parameters
    ----------
    geometry : DataFrame from :func:`segment_geometry` (lengths in m, view factors and
        weights dimensionless)
    cfg : IrradianceCfg (``reflection``, ``max_reflector_groups``)
    ground_albedo : float, albedo of the open ground beyond the city model (dimensionless)
    scene : vipvflow.models.shading.Scene, optional

    Returns
    -------
    dict of arrays per segment ``s`` and reflector ``J`` (groups, then the street): ``p``
    (s, 3) ray origins (m), ``n`` (s, 3) roof normals, ``svf`` (s,), ``hbv`` (s,) the roof's
    view of the horizon band, ``refl_sky`` and ``refl_ghi`` (s,) the weights of DHI and GHI
    in the reflected part, ``refl_hor`` (s,) the reflectors' horizon-band views so weighted
    (x DHI F2 under the Perez sky; all dimensionless), ``sky_x`` (s, 36) the roof point's
    horizon per sky sector as a level index (:func:`vipvflow.models.sky.sky_levels`; (s, 0)
    without the ``sky_x..`` columns),
    ``wn`` (s, J, 3) weight x normal of each reflector (its beam weight is ``wn . sun``),
    ``group_p`` (s J, P, 3) sample points (m); with *scene* also ``scene_origin``,
    ``p_local`` and ``group_p_local`` (float32, the scene's frame).

    References
    ----------
    C. M. Goral, K. E. Torrance, D. P. Greenberg, B. Battaile (1984), Modeling the
    interaction of light between diffuse surfaces, SIGGRAPH 84 (the radiosity equation).
    pvlib ``irradiance.get_ground_diffuse`` (open ground lit as a field: GHI x albedo).
    """
    f32 = np.float32
    cols = set(geometry.columns)
    G = cfg.max_reflector_groups if cfg.reflection else 0
    G = min(G, sum(1 for c in cols if c.startswith("r") and c.endswith("_w")))
    P = 0
    while G and f"r0_p{P}_x" in cols:
        P += 1
    s = len(geometry)
    street = bool(G and P and "st_sky" in cols)
    J = G + street
    col = lambda c, dt=np.float64: geometry[c].to_numpy(dt)         # noqa: E731
    # the classes of months of a tile with crowns (1 without): the quantities the crowns
    # change are taken per class from their ``_t{c}`` columns (a row of a tile without
    # crowns, joined with others in the app, has them missing: its own values serve)
    months = _tree_months(geometry, cols)
    C = int(months.max()) + 1 if s else 1

    def per_class(name, default=None):
        base = col(name) if name in cols else (np.zeros(s) if default is None else default)
        out = np.repeat(base[:, None], C, axis=1)
        for c in range(C):
            if f"{name}_t{c}" in cols:
                v = col(f"{name}_t{c}")
                out[:, c] = np.where(np.isfinite(v), v, base)
        return out

    w = np.stack([per_class(f"r{g}_w") for g in range(G)], 1) if G else np.zeros((s, 0, C))
    nrm = np.zeros((s, J, 3))
    pts = np.zeros((s, J, max(P, 1), 3), np.float64)
    f_s, f_g, f_o, f_w, f_h = (np.zeros((s, G, C)) for _ in range(5))
    beam_len = np.ones((s, J))
    # the sample points: one (s, P x 3) block per reflector (a thousand columns read one
    # by one cost more than the rest of the packing)
    points = lambda prefix: geometry[[f"{prefix}_p{k}_{c}" for k in range(P)  # noqa: E731
                                      for c in "xyz"]].to_numpy(np.float64).reshape(s, P, 3)
    for g in range(G):
        for j, c in enumerate("xyz"):
            nrm[:, g, j] = col(f"r{g}_n{c}")
            if not P:
                pts[:, g, 0, j] = col(f"r{g}_{c}")
        if P:
            pts[:, g] = points(f"r{g}")
        if f"r{g}_sky" in cols:
            f_s[:, g], f_g[:, g], f_o[:, g] = (per_class(f"r{g}_{k}") for k in ("sky", "gnd", "open"))
        else:
            f_s[:, g] = ((1 + nrm[:, g, 2]) / 2)[:, None]
            f_o[:, g] = ((1 - nrm[:, g, 2]) / 2)[:, None]
        f_w[:, g], f_h[:, g] = per_class(f"r{g}_wall"), per_class(f"r{g}_hor")
        if f"r{g}_nlen" in cols:
            beam_len[:, g] = col(f"r{g}_nlen")
    # one set of reflectors per (segment, class): the classes as more rows
    flat = lambda a: np.moveaxis(a, 2, 1).reshape(s * C, a.shape[1])       # noqa: E731
    w2, f_s2, f_g2, f_o2, f_w2, f_h2 = (flat(a) for a in (w, f_s, f_g, f_o, f_w, f_h))
    src_sky, src_ghi = f_s2, ground_albedo * f_o2
    if street:
        for j, c in enumerate("xyz"):
            nrm[:, G, j] = col(f"st_n{c}")
        pts[:, G] = points("st")
        # the street is a reflector of the segment where its groups see it without crowns
        has = np.repeat(((f_g * w).sum(1) > 0).any(1), C)
        m = _exchange_weights(w2, f_g2, f_w2, per_class("st_wall").reshape(-1), has)
        src_sky = np.concatenate([f_s2, per_class("st_sky").reshape(-1)[:, None]], 1)
        src_ghi = np.concatenate([src_ghi, np.zeros((s * C, 1))], 1)
        f_h2 = np.concatenate([f_h2, np.zeros((s * C, 1))], 1)   # a level street: no horizon term
    else:                     # the street lit as an open field, by GHI
        m = w2
        src_ghi = src_ghi + f_g2
    blen = np.repeat(beam_len, C, axis=0)
    nrm_c = np.repeat(nrm, C, axis=0)
    geo = {"p": np.ascontiguousarray(geometry[["px", "py", "pz"]].to_numpy(np.float64)),
           "n": np.ascontiguousarray(geometry[["nx", "ny", "nz"]].to_numpy(f32)),
           "svf": np.ascontiguousarray(per_class("svf").astype(f32)),
           "svf_no_trees": geometry["svf"].to_numpy(f32),
           "hbv": np.ascontiguousarray(per_class("hbv").astype(f32)),
           "hbv_no_trees": (geometry["hbv"].to_numpy(f32) if "hbv" in cols else np.zeros(s, f32)),
           **_sky_terms(geometry, cols),
           "tree_month": months,
           **_tree_sky(geometry, cols, C),
           "refl_sky": (m * src_sky).sum(1).astype(f32).reshape(s, C),
           "refl_ghi": (m * src_ghi).sum(1).astype(f32).reshape(s, C),
           "refl_hor": (m * f_h2).sum(1).astype(f32).reshape(s, C),
           "wn": np.ascontiguousarray(((m * blen)[..., None] * nrm_c).astype(f32).reshape(s, C, J, 3)),
           "group_p": pts.reshape(s * J, max(P, 1), 3),
           "group_f": _point_factors(geometry, cols, G, street, max(P, 1), C)}
    if scene is not None:
        geo["scene_origin"] = np.asarray(scene.origin, np.float64).copy()
        geo["p_local"] = scene.to_local(geo["p"])
        geo["group_p_local"] = scene.to_local(geo["group_p"])
        _check_tree_classes(geo, scene, cfg)
    return geo


def _point_factors(geometry: pd.DataFrame, cols: set, G: int, street: bool, P: int,
                   C: int) -> np.ndarray:
    """Each reflector sample point's factor through the crowns per class, (s J, P, C)
    float32 (:func:`_group_points`; 1 without crowns, or for a row without them)."""
    s = len(geometry)
    out = np.ones((s, G + street, P, C), np.float32)
    for j, prefix in enumerate([f"r{g}" for g in range(G)] + (["st"] if street else [])):
        for c in range(C):
            names = [f"{prefix}_q{k}_t{c}" for k in range(P)]
            if names[0] in cols:
                v = geometry[names].to_numpy(np.float32)
                out[:, j, :, c] = np.where(np.isfinite(v), v, np.float32(1))
    return np.ascontiguousarray(out.reshape(s * (G + street), P, C))


def _tree_months(geometry: pd.DataFrame, cols: set) -> np.ndarray:
    """Each segment's class of each month (s, 12) int64: the ``tree_month_..`` columns, 0
    where there are none (no crowns)."""
    s = len(geometry)
    if not set(TREE_MONTH_COLUMNS) <= cols:
        return np.zeros((s, 12), np.int64)
    v = geometry[TREE_MONTH_COLUMNS].to_numpy(np.float64)
    return np.ascontiguousarray(np.where(np.isfinite(v), v, 0).astype(np.int64))


def _tree_sky(geometry: pd.DataFrame, cols: set, C: int) -> dict:
    """The crowns' loss per sky cell (perez_svf), dense ``tsky`` (s, C, 324) float32 (s, C, 0
    without), and its nonzero entries for the compiled kernel: ``tsky_off`` (s + 1,) the
    first entry of each segment, ``tsky_cell`` (e,) the cell's flat index in a sky table row
    (:func:`vipvflow.models.trees.sky_cells`), ``tsky_sector`` (e,), ``tsky_w`` (e, C)."""
    from .trees import sky_cells

    s = len(geometry)
    names = [[f"tsky_t{c}_{j:03d}" for j in range(len(sky_cells()))] for c in range(C)]
    if not (f"tsky_t0_000" in cols):
        return {"tsky": np.zeros((s, C, 0), np.float32), "tsky_off": np.zeros(s + 1, np.int64),
                "tsky_cell": np.zeros(0, np.int64), "tsky_sector": np.zeros(0, np.int64),
                "tsky_w": np.zeros((0, C), np.float32)}
    dense = np.zeros((s, C, len(sky_cells())), np.float32)
    for c in range(C):
        if names[c][0] in cols:
            dense[:, c] = np.nan_to_num(geometry[names[c]].to_numpy(np.float32))
    any_c = (dense > 0).any(1)                                      # (s, cells)
    seg, cell = np.nonzero(any_c)
    off = np.zeros(s + 1, np.int64)
    np.cumsum(np.bincount(seg, minlength=s), out=off[1:])
    flat_cell = sky_cells()[cell]
    return {"tsky": dense, "tsky_off": off, "tsky_cell": np.ascontiguousarray(flat_cell.astype(np.int64)),
            "tsky_sector": np.ascontiguousarray((cell // 9).astype(np.int64)),
            "tsky_w": np.ascontiguousarray(dense[seg, :, cell])}


def _check_tree_classes(geo: dict, scene, cfg) -> None:
    """The geometry's classes of months must be those of the scene's crowns (the rays of a
    pass are traced through them): a geometry computed with other trees is refused."""
    crowns = scene.crowns(cfg) if hasattr(scene, "crowns") else None
    want = crowns.class_of_month if crowns is not None else np.zeros(12, np.int64)
    got = geo["tree_month"]
    if len(got) and not (got == want[None, :]).all():
        from ..errors import InputError

        raise InputError("the segment geometry was computed with other trees than the city "
                         "model's now (classes of months differ): compute the geometry again")


def _sky_terms(geometry: pd.DataFrame, cols: set) -> dict:
    """The roof points' horizon levels per sky sector (``sky_x``, (s, 36) float32, (s, 0)
    without them) and, for the compiled kernel, each sector's cell in a table row
    (``sky_cell``: ``10 k + level``, int64), its interpolation weight (``sky_f``) and the
    roof's tilt weight ``n_x sin a_k + n_y cos a_k`` (``sky_t``; ``sky_tilted`` where any)."""
    from .sky import SECTOR_COS, SECTOR_SIN, SKY_LEVELS

    f32 = np.float32
    s = len(geometry)
    if not set(SKY_COLUMNS) <= cols:
        z = np.zeros((s, 0), f32)
        return {"sky_x": z, "sky_cell": np.zeros((s, 0), np.int64), "sky_f": z, "sky_t": z,
                "sky_tilted": np.zeros(s, bool)}
    x = np.ascontiguousarray(geometry[SKY_COLUMNS].to_numpy(f32))
    i = x.astype(np.int64)
    n = geometry[["nx", "ny"]].to_numpy(f32)
    t = (n[:, 0:1] * SECTOR_SIN.astype(f32) + n[:, 1:2] * SECTOR_COS.astype(f32)).astype(f32)
    return {"sky_x": x, "sky_cell": np.arange(len(SKY_COLUMNS))[None, :] * (SKY_LEVELS + 1) + i,
            "sky_f": (x - i.astype(f32)).astype(f32), "sky_t": t,
            "sky_tilted": np.abs(n).max(1) > 0}


def isotropic_sky_view(normal_z):
    """Isotropic sky view factor of a plane, ``(1 + cos beta) / 2`` (Liu & Jordan), from the
    up component of its unit normal (dimensionless; 1 for a horizontal plane).

    References
    ----------
    B. Y. H. Liu, R. C. Jordan (1963), Solar Energy 7(2), 53-74; pvlib
    ``irradiance.isotropic``.
    """
    nz = np.asarray(normal_z)
    return (nz.dtype.type(1) + nz) * nz.dtype.type(0.5)
