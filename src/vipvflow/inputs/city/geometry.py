"""Planar polygons in 3D: cleaning, normals, areas, validity and triangulation.

A CityGML polygon is an exterior ring and optional interior rings (holes), each a
sequence of 3D points.  :func:`prepare_polygon` turns one into what the ray tracer and
the irradiance model need -- unit normal (Newell's method), 3D area with the holes
subtracted, and triangles (mapbox earcut after projecting onto the polygon's own
plane) -- or says why it cannot, so the caller can count the skip.

Earcut is called directly, not through ``trimesh.creation.triangulate_polygon(engine="earcut")``
(the same library): on the demo city's 66,574 polygons (2026-11-26, three alternated runs in
one process) :func:`prepare_polygon` took 1.72x as long through trimesh (best 10.6 s against
6.2 s: a shapely polygon for every ring set, its coordinates read back, each ring closed
again), and trimesh hands earcut closed rings, so earcut starts from another vertex: the
triangles of all 41,982 three-point polygons came out rotated and the 24,592 larger polygons
were cut along other diagonals, which would move every mesh's triangles (and the runs'
figures in their last digits) for nothing gained.  The meshes themselves are trimesh's
(:mod:`vipvflow.models.mesh`).

References
----------
M. E. Newell's method for plane equations, in F. Tampieri, "Newell's method for computing
the plane equation of a polygon", Graphics Gems III, 1992.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import mapbox_earcut
import numpy as np
import shapely

#: points closer than this (m) are the same point
POINT_EPS_M = 1e-4

#: |nz| above which an unclassified polygon is a roof (up) or ground (down);
#: about 80 degrees of tilt
ROOF_NZ = 0.17


class Skip(Exception):
    """A polygon that cannot be used; ``reason`` is the key counted in the report."""

    def __init__(self, reason: str, detail: str = ""):
        super().__init__(detail or reason)
        self.reason = reason


@dataclass
class PreparedPolygon:
    """One cleaned polygon.

    Attributes
    ----------
    vertices : (k, 3) float64, m -- exterior then holes, rings not closed
    ring_sizes : (r,) int64 -- vertices per ring, exterior first
    normal : (3,) float64 -- outward unit normal (from the exterior ring's winding)
    area : float, m2 -- exterior area minus holes, on the polygon's plane
    triangles : (t, 3) int32 -- indices into ``vertices``, counter-clockwise seen from ``normal``
    repairs : list of str -- repairs applied (counted in the report)
    """

    vertices: np.ndarray
    ring_sizes: np.ndarray
    normal: np.ndarray
    area: float
    triangles: np.ndarray
    repairs: list = field(default_factory=list)


def newell_vector(ring: np.ndarray) -> np.ndarray:
    """Newell's vector of a ring (n, 3): direction = normal, length = 2 x area (m2).

    The ring may be open or closed; the closing edge is implied.
    """
    p = ring - ring[0]                      # better conditioned for large coordinates
    q = np.empty_like(p)
    q[:-1], q[-1] = p[1:], p[0]
    x, y, z = p[:, 0], p[:, 1], p[:, 2]
    qx, qy, qz = q[:, 0], q[:, 1], q[:, 2]
    return np.array([np.dot(y, qz) - np.dot(z, qy),
                     np.dot(z, qx) - np.dot(x, qz),
                     np.dot(x, qy) - np.dot(y, qx)])


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def plane_basis(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Orthonormal (u, v) spanning the plane of unit *normal*, with u x v = normal."""
    n = (float(normal[0]), float(normal[1]), float(normal[2]))
    helper = (0.0, 0.0, 1.0) if abs(n[2]) < 0.9 else (1.0, 0.0, 0.0)
    u = _cross(helper, n)
    norm = (u[0] ** 2 + u[1] ** 2 + u[2] ** 2) ** 0.5
    u = (u[0] / norm, u[1] / norm, u[2] / norm)
    return np.array(u), np.array(_cross(n, u))


def classify_normal(nz) -> np.ndarray:
    """Surface type of polygons without a thematic class, from the normal's z: roof, wall, ground."""
    nz = np.asarray(nz, dtype=float)
    return np.where(nz > ROOF_NZ, "roof", np.where(nz < -ROOF_NZ, "ground", "wall"))


def clean_ring(ring: np.ndarray, repairs: list) -> np.ndarray:
    """Open ring without repeated consecutive points; notes an unclosed input ring as repaired."""
    if len(ring) >= 2:
        if np.all(np.abs(ring[0] - ring[-1]) <= POINT_EPS_M):
            ring = ring[:-1]
        else:
            repairs.append("closed_ring")
    if len(ring) >= 2:
        step = np.abs(np.diff(ring, axis=0)).max(axis=1) > POINT_EPS_M
        keep = np.concatenate([[True], step])
        if not keep.all():
            repairs.append("duplicate_points")
            ring = ring[keep]
        while len(ring) >= 2 and np.all(np.abs(ring[0] - ring[-1]) <= POINT_EPS_M):
            ring = ring[:-1]
    return ring


def prepare_polygon(rings: list[np.ndarray], planarity_tolerance_m: float = 0.1,
                    min_area_m2: float = 0.0) -> PreparedPolygon:
    """Clean, check and triangulate one polygon with holes.

    Parameters
    ----------
    rings : list of (n, 3) float arrays, m
        Exterior ring first, then the holes; closed or not.
    planarity_tolerance_m : float, m
        Largest distance of a vertex from the polygon's plane.
    min_area_m2 : float, m2
        Polygons smaller than this are degenerate.

    Raises
    ------
    Skip
        ``reason`` one of ``degenerate`` (fewer than 3 distinct points or no area),
        ``too_small`` (below *min_area_m2*), ``non_planar``, ``self_intersecting``, ``invalid_rings``, ``triangulation_failed``.
    """
    repairs: list = []
    exterior = clean_ring(np.asarray(rings[0], dtype=np.float64), repairs)
    if len(exterior) < 3:
        raise Skip("degenerate", "fewer than 3 distinct points")
    nvec = newell_vector(exterior)
    twice_area = float(np.linalg.norm(nvec))
    if twice_area <= 1e-9:
        raise Skip("degenerate", "zero area")
    if twice_area / 2 < min_area_m2:
        raise Skip("too_small", f"area {twice_area / 2:.4f} m2 below min_area_m2")
    normal = nvec / twice_area
    holes = []
    hole_area = 0.0
    for ring in rings[1:]:
        ring = clean_ring(np.asarray(ring, dtype=np.float64), repairs)
        h = float(np.linalg.norm(newell_vector(ring))) / 2 if len(ring) >= 3 else 0.0
        if h <= 1e-9:
            repairs.append("dropped_degenerate_hole")
            continue
        holes.append(ring)
        hole_area += h
    vertices = np.concatenate([exterior] + holes) if holes else exterior
    origin = vertices.mean(axis=0)
    local = vertices - origin
    dist = local @ normal
    if np.abs(dist).max() > planarity_tolerance_m:
        raise Skip("non_planar", f"{np.abs(dist).max():.3f} m off the plane")
    u, v = plane_basis(normal)
    xy = local @ np.column_stack([u, v])
    sizes = np.array([len(exterior)] + [len(h) for h in holes], dtype=np.int64)
    ends = np.cumsum(sizes)
    if holes:
        shell = xy[:ends[0]]
        hole_xy = [xy[a:b] for a, b in zip(ends[:-1], ends[1:])]
        poly2d = shapely.Polygon(shell, hole_xy)
    else:
        poly2d = shapely.Polygon(xy) if len(xy) > 3 else None   # a triangle is simple
    if poly2d is not None and not shapely.is_valid(poly2d):
        why = shapely.is_valid_reason(poly2d)
        reason = "self_intersecting" if "Self-intersection" in why else "invalid_rings"
        raise Skip(reason, why)
    area = twice_area / 2 - hole_area
    if area <= max(min_area_m2, 1e-9):
        raise Skip("degenerate", "holes cover the polygon")
    tri = np.asarray(mapbox_earcut.triangulate_float64(xy, ends.astype(np.uint32)),
                     dtype=np.int32).reshape(-1, 3)
    if len(tri) == 0:
        raise Skip("triangulation_failed")
    a, b, c = xy[tri[:, 0]], xy[tri[:, 1]], xy[tri[:, 2]]
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    flip = cross < 0
    if flip.any():
        tri[flip] = tri[flip][:, [0, 2, 1]]
    return PreparedPolygon(vertices=vertices, ring_sizes=sizes, normal=normal, area=area,
                           triangles=tri[cross != 0], repairs=repairs)
