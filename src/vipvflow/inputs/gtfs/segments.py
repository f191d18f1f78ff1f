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

from ..tiles import tile_names

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


def ground_elevation(x, y, terrain, default_m: float) -> np.ndarray:
    """Ground height at points (m); *terrain* has ``.elevation(x, y)`` or is None."""
    x = np.asarray(x, float)
    if terrain is None:
        return np.full(x.shape, float(default_m))
    z = np.asarray(terrain.elevation(x, np.asarray(y, float)), dtype=float)
    return np.where(np.isfinite(z), z, float(default_m))


def build_segments(shape_xy: dict[str, np.ndarray], nominal_m: float, roof_height_m: float,
                   tile_size_m: float, terrain=None, default_elevation_m: float = 300.0):
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
    terrain : object with ``elevation(x, y)``, optional
        Ground model (m, NaN where unknown); None gives *default_elevation_m* everywhere.

    Returns
    -------
    segments : DataFrame
        One row per segment, columns of ``gtfs/segments.parquet`` without geometry, ordered
        by shape then ``seg_index``; ``segment_id`` numbers them 0..N-1.
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
        gz = ground_elevation(bxy[:, 0], bxy[:, 1], terrain, default_elevation_m)
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
            "heading_deg": heading,
            "gradient": np.diff(gz) / length,
            "length_m": length,
            "cum_dist_m": bs[:-1],
            "tile": tile_names(bxy[:-1, 0], bxy[:-1, 1], tile_size_m),
        }))
        lines.append(_segment_lines(pts, bxy, bs, gz, roof_height_m, terrain,
                                    default_elevation_m))
        next_id += n
    if not frames:
        cols = ["segment_id", "shape_id", "seg_index", "x", "y", "z", "x_end", "y_end", "z_end",
                "ground_z", "heading_deg", "gradient", "length_m", "cum_dist_m", "tile"]
        return pd.DataFrame(columns=cols), np.array([], dtype=object)
    return pd.concat(frames, ignore_index=True), np.concatenate(lines)


def _segment_lines(pts, bxy, bs, gz, roof, terrain, default_m):
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
    v_z = ground_elevation(v_xy[:, 0], v_xy[:, 1], terrain, default_m) + roof
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
