"""Hyper-segments: each shape cut into equal pieces of at most the nominal length.

A shape of length L (m, in the projected CRS) is cut into ``n = ceil(L / nominal)`` pieces
of length ``L / n``, so that every piece is at most the nominal length and the pieces add up
to L exactly. A piece is described by its start and end points (x, y, z with z = ground +
roof height), its heading (degrees clockwise from north, start to end), the road gradient
(dz/ds of the ground), its length along the shape and the distance of its start from the
shape's start. Its geometry keeps the shape's own vertices between the two ends.
"""
from __future__ import annotations

import logging

import numpy as np
import pandas as pd
import shapely

from ..city.terrain import GROUND_SOURCES
from ..tiles import tile_names

_RELIEF = GROUND_SOURCES.index("relief")

log = logging.getLogger(__name__)


def project_shapes(shapes: pd.DataFrame, transformer) -> dict[str, np.ndarray]:
    """Projected vertex coordinates of every shape (m), consecutive duplicates removed.

    Parameters
    ----------
    shapes : DataFrame
        GTFS shapes (``shape_id, shape_pt_sequence, shape_pt_lat, shape_pt_lon``).
    transformer : pyproj.Transformer
        WGS84 (lon, lat order) to the projected CRS.

    Returns
    -------
    dict of shape_id -> ndarray (n, 2)
    """
    sh = shapes.sort_values(["shape_id", "shape_pt_sequence"], kind="stable")
    x, y = transformer.transform(sh["shape_pt_lon"].to_numpy(float),
                                 sh["shape_pt_lat"].to_numpy(float))
    ids = sh["shape_id"].astype(str).to_numpy()
    xy = np.column_stack([x, y])
    out = {}
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    ends = np.r_[starts[1:], len(ids)]
    for a, b in zip(starts, ends):
        pts = xy[a:b]
        keep = np.r_[True, np.any(np.diff(pts, axis=0) != 0, axis=1)]
        out[ids[a]] = pts[keep]
    return out


def cumulative_distance(pts: np.ndarray) -> np.ndarray:
    """Distance of each vertex from the first along the polyline (m)."""
    return np.r_[0.0, np.cumsum(np.hypot(*np.diff(pts, axis=0).T))]


def cut_shape(pts: np.ndarray, nominal_m: float):
    """Break points of one shape cut into equal pieces of at most *nominal_m*.

    Returns
    -------
    breaks_xy : ndarray (n+1, 2)
        Points at the piece boundaries (m).
    breaks_s : ndarray (n+1,)
        Their distances along the shape (m); ``breaks_s[-1]`` is the shape length.
    """
    cum = cumulative_distance(pts)
    length = cum[-1]
    # pieces may exceed the nominal length by at most 1 um: a shape that is a whole number
    # of nominal lengths up to coordinate round-trip noise is not given an extra piece
    n = max(1, int(np.ceil(length / (nominal_m + 1e-6))))
    s = np.linspace(0.0, length, n + 1)
    return np.column_stack([np.interp(s, cum, pts[:, 0]), np.interp(s, cum, pts[:, 1])]), s


def ground_elevation(x, y, terrain, fallback=None) -> tuple[np.ndarray, np.ndarray]:
    """Ground height at points (m) and its source.

    Parameters
    ----------
    x, y : array_like, m
    terrain : :class:`vipvflow.inputs.city.TerrainModel` (or an object with
        ``ground(x, y, fallback_m, fallback_source)``, or only ``elevation(x, y)``), or None
    fallback : (height_m, source) or None
        The height where the city model knows none (``radiation_header``: the radiation
        file's altitude, ``configured``: ``trajectory.ground_elevation_m``).

    Returns
    -------
    z : ndarray, m (NaN where unknown)
    source : ndarray of int8, index into
        :data:`vipvflow.inputs.city.terrain.GROUND_SOURCES` (-1 unknown)
    """
    from ..city.terrain import GROUND_SOURCES

    x = np.asarray(x, float).ravel()
    y = np.asarray(y, float).ravel()
    height, source = fallback if fallback is not None else (None, "configured")
    if terrain is None:
        if height is None:
            return np.full(x.shape, np.nan), np.full(x.shape, -1, np.int8)
        return (np.full(x.shape, float(height)),
                np.full(x.shape, GROUND_SOURCES.index(source), np.int8))
    if hasattr(terrain, "ground"):
        z, src = terrain.ground(x, y, height, source)
        return np.asarray(z, float), np.asarray(src, np.int8)
    z = np.asarray(terrain.elevation(x, y), dtype=float)
    src = np.where(np.isfinite(z), GROUND_SOURCES.index("relief"), -1).astype(np.int8)
    if height is not None:
        src = np.where(np.isfinite(z), src, GROUND_SOURCES.index(source)).astype(np.int8)
        z = np.where(np.isfinite(z), z, float(height))
    return z, src


#: a road's ground profile from scattered heights (building ground surfaces, a fallback) is
#: smoothed along the road over this length (m): a running median, then a running mean of
#: half of it; the relief (a TIN) is followed as it is
SMOOTH_M = 100.0


def smooth_profile(s: np.ndarray, z: np.ndarray, keep: np.ndarray, window_m: float = SMOOTH_M) -> np.ndarray:
    """Heights *z* at evenly spaced distances *s* (m) along a road, smoothed where not *keep*.

    The building ground surfaces around a street differ by a metre or two (entrances,
    courtyards, slopes along a block); their inverse-distance mean then makes bumps that a
    road does not have (gradients of 20 % over 10 m).  A running median over *window_m* and a
    running mean over half of it keep the road's trend and drop the bumps (the ends are
    extended by their nearest value).

    Returns
    -------
    ndarray, m
    """
    from scipy.ndimage import median_filter, uniform_filter1d

    z = np.asarray(z, float)
    if len(z) < 3 or keep.all():
        return z.copy()
    step = float(s[1] - s[0]) if len(s) > 1 else window_m
    k = max(1, int(round(window_m / max(step, 1e-6))) | 1)
    med = median_filter(z, size=k, mode="nearest")
    mean = uniform_filter1d(med, size=max(1, (k // 2) | 1), mode="nearest")
    return np.where(keep, z, mean)


def build_segments(shape_xy: dict[str, np.ndarray], nominal_m: float, roof_height_m: float,
                   tile_size_m: float, terrain=None, fallback=None):
    """Hyper-segments of every shape.

    Parameters
    ----------
    shape_xy : dict of shape_id -> ndarray (n, 2)
        Projected shape vertices (m).
    nominal_m : float
        Nominal (maximum) segment length (m).
    roof_height_m : float
        PV plane above the road (m).
    tile_size_m : float
        Tile size for the ``tile`` column (m).
    terrain : TerrainModel, optional
        Ground model (:func:`ground_elevation`).
    fallback : (height_m, source), optional
        Ground height where the model knows none (:func:`ground_elevation`).

    Returns
    -------
    segments : DataFrame
        One row per segment, columns of ``gtfs/segments.parquet`` without geometry, ordered
        by shape then ``seg_index``; ``segment_id`` numbers them 0..N-1; ``ground_z`` is NaN
        and ``ground_source`` -1 where no height is known (the caller refuses those).
    geometry : ndarray of shapely LineString Z
    """
    frames, lines = [], []
    next_id = 0
    for shape_id in sorted(shape_xy):
        pts = shape_xy[shape_id]
        if len(pts) < 2:
            continue
        bxy, bs = cut_shape(pts, nominal_m)
        n = len(bs) - 1
        gz, gsrc = ground_elevation(bxy[:, 0], bxy[:, 1], terrain, fallback)
        if np.isfinite(gz).all():
            gz = smooth_profile(bs, gz, gsrc == _RELIEF)
        length = np.diff(bs)
        dx, dy = np.diff(bxy[:, 0]), np.diff(bxy[:, 1])
        heading = np.degrees(np.arctan2(dx, dy)) % 360.0
        frames.append(pd.DataFrame({
            "segment_id": np.arange(next_id, next_id + n, dtype=np.int64),
            "shape_id": shape_id,
            "seg_index": np.arange(n, dtype=np.int32),
            "x": bxy[:-1, 0], "y": bxy[:-1, 1], "z": gz[:-1] + roof_height_m,
            "x_end": bxy[1:, 0], "y_end": bxy[1:, 1], "z_end": gz[1:] + roof_height_m,
            "ground_z": gz[:-1],
            "ground_source": gsrc[:-1],
            "heading_deg": heading,
            "gradient": np.diff(gz) / length,
            "length_m": length,
            "cum_dist_m": bs[:-1],
            "tile": tile_names(bxy[:-1, 0], bxy[:-1, 1], tile_size_m),
        }))
        lines.append(_segment_lines(pts, bxy, bs, gz, roof_height_m, terrain, fallback,
                                    relief=gsrc == _RELIEF))
        next_id += n
    if not frames:
        cols = ["segment_id", "shape_id", "seg_index", "x", "y", "z", "x_end", "y_end", "z_end",
                "ground_z", "ground_source", "heading_deg", "gradient", "length_m", "cum_dist_m", "tile"]
        return pd.DataFrame(columns=cols), np.array([], dtype=object)
    return pd.concat(frames, ignore_index=True), np.concatenate(lines)


def _segment_lines(pts, bxy, bs, gz, roof, terrain, fallback, relief=None):
    """LineString Z per piece: its two ends plus the shape vertices strictly inside it."""
    cum = cumulative_distance(pts)
    n = len(bs) - 1
    inner = (cum > 0) & (cum < bs[-1])
    v_s = cum[inner]
    v_seg = np.clip(np.searchsorted(bs, v_s, side="right") - 1, 0, n - 1)
    v_xy = pts[inner]
    # drop vertices that coincide with a break point
    keep = (v_s > bs[v_seg] + 1e-9) & (v_s < bs[v_seg + 1] - 1e-9)
    v_s, v_seg, v_xy = v_s[keep], v_seg[keep], v_xy[keep]
    # the shape's own vertices: on the relief, its height; elsewhere the smoothed profile of
    # the break points
    v_z = np.interp(v_s, bs, gz)
    if relief is not None and relief.any():
        z_rel, src = ground_elevation(v_xy[:, 0], v_xy[:, 1], terrain, fallback)
        on = (src == _RELIEF) & np.isfinite(z_rel)
        v_z = np.where(on, z_rel, v_z)
    v_z = v_z + roof
    k = np.arange(n)
    seg = np.concatenate([k, v_seg, k])
    order = np.concatenate([np.full(n, -1.0), v_s, np.full(n, np.inf)])
    xyz = np.vstack([
        np.column_stack([bxy[:-1], gz[:-1] + roof]),
        np.column_stack([v_xy, v_z]),
        np.column_stack([bxy[1:], gz[1:] + roof]),
    ])
    idx = np.lexsort((order, seg))
    return shapely.linestrings(xyz[idx], indices=seg[idx])
