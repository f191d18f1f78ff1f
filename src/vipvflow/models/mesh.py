"""The compact triangle mesh of one tile (its own surfaces plus the shading buffer).

Written by city ingest as ``city/meshes/<TILE>.npz``; loaded by workers to build the
Embree BVH.  Plain numpy arrays so a load is a few milliseconds.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..store import write_npz

#: surface type codes used in ``TileMesh.surface_type``
SURFACE_TYPES = ("roof", "wall", "ground", "closure", "terrain", "vegetation", "other")
SURFACE_CODE = {name: i for i, name in enumerate(SURFACE_TYPES)}


@dataclass
class TileMesh:
    """Triangles of a tile's mesh.

    Attributes
    ----------
    vertices : (n, 3) float64, m, projected CRS
    triangles : (m, 3) int32, vertex indices (counter-clockwise seen from the normal side)
    surface_index : (m,) int32, index into ``surface_ids``
    surface_ids : (k,) str, id of each surface the triangles belong to
    albedo : (m,) float32, broadband albedo of the triangle's surface
    normals : (m, 3) float32, unit normal of the triangle's surface (outward)
    surface_type : (m,) int8, codes of :data:`SURFACE_TYPES`
    bounds : (4,) float64, the tile's own extent (xmin, ymin, xmax, ymax)
    buffer_m : float, width of the buffer around ``bounds`` included in the mesh
    """

    vertices: np.ndarray
    triangles: np.ndarray
    surface_index: np.ndarray
    surface_ids: np.ndarray
    albedo: np.ndarray
    normals: np.ndarray
    surface_type: np.ndarray
    bounds: np.ndarray = field(default_factory=lambda: np.full(4, np.nan))
    buffer_m: float = 0.0
    name: str = ""

    @property
    def n_triangles(self) -> int:
        return int(len(self.triangles))

    def save(self, path: str | Path) -> None:
        """Write atomically as ``.npz`` (temporary name, then rename)."""
        write_npz(path, vertices=self.vertices.astype(np.float64),
                 triangles=self.triangles.astype(np.int32),
                 surface_index=self.surface_index.astype(np.int32),
                 surface_ids=np.asarray(self.surface_ids, dtype=str),
                 albedo=self.albedo.astype(np.float32), normals=self.normals.astype(np.float32),
                 surface_type=self.surface_type.astype(np.int8),
                 bounds=np.asarray(self.bounds, dtype=np.float64),
                 buffer_m=np.float64(self.buffer_m), name=np.str_(self.name))

    @classmethod
    def load(cls, path: str | Path) -> "TileMesh":
        with np.load(path, allow_pickle=False) as z:
            return cls(vertices=z["vertices"], triangles=z["triangles"],
                       surface_index=z["surface_index"], surface_ids=z["surface_ids"],
                       albedo=z["albedo"], normals=z["normals"], surface_type=z["surface_type"],
                       bounds=z["bounds"], buffer_m=float(z["buffer_m"]), name=str(z["name"]))

    @classmethod
    def from_triangles(cls, tris: np.ndarray, albedo=0.2, surface_type="wall",
                       name: str = "") -> "TileMesh":
        """A mesh from a (m, 3, 3) array of triangle corners (tests, synthetic scenes)."""
        tris = np.asarray(tris, dtype=np.float64).reshape(-1, 3, 3)
        m = len(tris)
        n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
        return cls(vertices=tris.reshape(-1, 3), triangles=np.arange(3 * m, dtype=np.int32).reshape(m, 3),
                   surface_index=np.arange(m, dtype=np.int32),
                   surface_ids=np.array([f"t{i}" for i in range(m)]),
                   albedo=np.broadcast_to(np.asarray(albedo, np.float32), (m,)).copy(),
                   normals=n.astype(np.float32),
                   surface_type=np.full(m, SURFACE_CODE[surface_type], np.int8),
                   bounds=np.array([lo[0], lo[1], hi[0], hi[1]]), name=name)
