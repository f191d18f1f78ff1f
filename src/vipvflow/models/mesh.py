"""The triangle mesh of one tile (its own surfaces plus the shading buffer), as a trimesh.Trimesh.

City ingest builds it (:meth:`TileMesh.build`, :meth:`TileMesh.merge`), checks it
(:meth:`TileMesh.check`) and writes it as ``city/meshes/<TILE>.npz``; workers load it to build
the Embree BVH (:mod:`vipvflow.models.shading`).  The geometry and every per-face value live in
one ``trimesh.Trimesh`` (:attr:`TileMesh.trimesh`): vertices, faces, and the face attributes of
:data:`FACE_ATTRIBUTES` in ``face_attributes``; the tile's name, extent, buffer and the ids of
the source surfaces in its ``metadata``.  :class:`TileMesh` is a thin view with the names the
models use (``mesh.triangles``, ``mesh.albedo``, ``mesh.surface_index``...).

The file is written from the Trimesh's arrays as it holds them (float64 vertices), not by
one of trimesh's exporters: PLY and glTF store float32 vertices (steps of 7.8 mm at the
10^5 m coordinates of a national CRS, which moves shadow edges), and trimesh's dict export
drops face attributes and metadata.  Its ``format`` (:data:`MESH_FORMAT`) is checked on load:
a mesh of another format is refused in one line, never read wrongly.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import InputError
from ..store import write_npz

if TYPE_CHECKING:
    import trimesh

#: surface type codes used in ``TileMesh.surface_type``
SURFACE_TYPES = ("roof", "wall", "ground", "closure", "terrain", "vegetation", "other")
SURFACE_CODE = {name: i for i, name in enumerate(SURFACE_TYPES)}

#: the per-face attributes of a tile mesh (``Trimesh.face_attributes``, and ``TileMesh.<name>``):
#: name -> (dtype, values per face, value for a mesh built or stored without it, ``None``:
#: required).  One line adds one, e.g. ``"transmittance": (np.float32, 1, 0.0)``.
FACE_ATTRIBUTES = {
    "surface_index": (np.int32, 1, None),   # the face's source surface: index into surface_ids
    "surface_type": (np.int8, 1, None),     # code of SURFACE_TYPES
    "albedo": (np.float32, 1, None),        # broadband albedo of the face's surface
    "normals": (np.float32, 3, None),       # unit outward normal of the face's *surface* (Newell)
}

#: version of ``city/meshes/<TILE>.npz``: 3 = vegetation no longer in the mesh (trees are
#: crowns of their own, :mod:`vipvflow.models.trees`); 2 = written from a Trimesh (``faces``,
#: ``face_<name>`` per face attribute, ``format``); 1 (no ``format`` key) = the arrays of
#: vipvflow before it
MESH_FORMAT = 3


def _face_values(name: str, value, m: int) -> np.ndarray:
    dtype, cols, default = FACE_ATTRIBUTES[name]
    shape = (m,) if cols == 1 else (m, cols)
    if value is None:
        if default is None:
            raise TypeError(f"TileMesh: face attribute {name!r} missing")
        return np.full(shape, default, dtype)
    value = np.asarray(value, dtype)
    if value.shape != shape:
        raise ValueError(f"TileMesh: face attribute {name!r} of shape {value.shape}, not {shape}")
    return value


class TileMesh:
    """Triangles of a tile's mesh, held by a ``trimesh.Trimesh`` (:attr:`trimesh`).

    Parameters / attributes
    -----------------------
    vertices : (n, 3) float64, m, projected CRS
    triangles : (m, 3) int, vertex indices (counter-clockwise seen from the normal side);
        the Trimesh's ``faces``
    surface_ids : (k,) str, id of each source surface (``metadata["surface_ids"]``)
    bounds : (4,) float64, the tile's own extent (xmin, ymin, xmax, ymax)
    buffer_m : float, width of the buffer around ``bounds`` included in the mesh
    name : str, the tile
    **face attributes : the arrays of :data:`FACE_ATTRIBUTES`, one row per triangle:
        ``surface_index`` (m,) int32, ``surface_type`` (m,) int8, ``albedo`` (m,) float32,
        ``normals`` (m, 3) float32 (the surface's unit normal, outward)
    """

    def __init__(self, vertices, triangles, surface_ids=(), bounds=None, buffer_m: float = 0.0,
                 name: str = "", **face_attributes):
        unknown = set(face_attributes) - set(FACE_ATTRIBUTES)
        if unknown:
            raise TypeError(f"TileMesh: unknown face attribute(s) {sorted(unknown)}")
        faces = np.asarray(triangles).reshape(-1, 3)
        m = len(faces)
        values = {k: _face_values(k, face_attributes.get(k), m) for k in FACE_ATTRIBUTES}
        import trimesh      # here: a process that reads this module's constants never loads it

        self.trimesh = trimesh.Trimesh(
            vertices=np.asarray(vertices, np.float64).reshape(-1, 3), faces=faces,
            face_attributes=values, process=False, validate=False,
            metadata={"tile": str(name), "buffer_m": float(buffer_m),
                      "bounds": np.asarray(np.full(4, np.nan) if bounds is None else bounds,
                                           np.float64),
                      "surface_ids": np.asarray(surface_ids, dtype=str)})

    @classmethod
    def from_trimesh(cls, mesh: trimesh.Trimesh) -> "TileMesh":
        """A view of *mesh* (its face attributes and metadata as :class:`TileMesh` writes them)."""
        out = cls.__new__(cls)
        out.trimesh = mesh
        return out

    # ------------------------------------------------------------------ the models' names
    @property
    def vertices(self) -> np.ndarray:
        return self.trimesh.vertices.view(np.ndarray)

    @property
    def triangles(self) -> np.ndarray:
        return self.trimesh.faces.view(np.ndarray)

    @property
    def surface_ids(self) -> np.ndarray:
        return self.trimesh.metadata["surface_ids"]

    @property
    def bounds(self) -> np.ndarray:
        return self.trimesh.metadata["bounds"]

    @property
    def buffer_m(self) -> float:
        return float(self.trimesh.metadata["buffer_m"])

    @property
    def name(self) -> str:
        return str(self.trimesh.metadata["tile"])

    @property
    def n_triangles(self) -> int:
        return int(len(self.trimesh.faces))

    def __repr__(self) -> str:
        return (f"TileMesh({self.name!r}, {len(self.vertices)} vertices, {self.n_triangles} "
                f"triangles, {len(self.surface_ids)} surfaces)")

    # ------------------------------------------------------------------ build, merge, check
    @classmethod
    def build(cls, vertices, rings_triangles, sizes, surface_ids, bounds=None, buffer_m=0.0,
              name="", **per_surface) -> "TileMesh":
        """The mesh of surfaces given as ragged arrays: *vertices* (all surfaces' vertices in
        order), *rings_triangles* (each surface's triangles, indices into its own vertices,
        concatenated), *sizes* = (vertices per surface, triangles per surface); the face
        attributes other than ``surface_index`` given per surface (*per_surface*, one row per
        surface) and spread to the surface's triangles."""
        vsz, tsz = (np.asarray(s, np.int64) for s in sizes)
        starts = np.zeros(len(vsz), np.int64)
        np.cumsum(vsz[:-1], out=starts[1:])
        owner = np.repeat(np.arange(len(tsz), dtype=np.int32), tsz)
        faces = np.asarray(rings_triangles, np.int64).reshape(-1, 3) + starts[owner][:, None]
        face = {k: np.asarray(v)[owner] for k, v in per_surface.items()}
        return cls(vertices, faces, surface_ids, bounds=bounds, buffer_m=buffer_m, name=name,
                   surface_index=owner, **face)

    @classmethod
    def merge(cls, meshes, name: str | None = None, bounds=None,
              buffer_m: float | None = None) -> "TileMesh":
        """One mesh of *meshes* in order (trimesh's concatenate: vertices, faces and face
        attributes); their surfaces are numbered on (``surface_index`` shifted, ``surface_ids``
        joined).  Name, extent and buffer are the first mesh's unless given."""
        import trimesh

        meshes = list(meshes)
        if not meshes:
            raise ValueError("TileMesh.merge: no mesh")
        parts, shift = [], 0
        for m in meshes:
            face = dict(m.trimesh.face_attributes)
            face["surface_index"] = (m.surface_index + shift).astype(np.int32)
            parts.append(trimesh.Trimesh(vertices=m.vertices, faces=m.triangles, face_attributes=face,
                                         process=False, validate=False))
            shift += len(m.surface_ids)
        first = meshes[0]
        if sum(len(p.faces) for p in parts) == 0:
            merged_v = np.concatenate([m.vertices for m in meshes])
            out = cls(merged_v, np.zeros((0, 3), np.int64), surface_ids=())
        else:
            out = cls.from_trimesh(trimesh.util.concatenate([p for p in parts if len(p.faces)]))
            out.trimesh.face_attributes = {k: out.trimesh.face_attributes[k] for k in FACE_ATTRIBUTES}
        out.trimesh.metadata = {
            "tile": first.name if name is None else str(name),
            "buffer_m": first.buffer_m if buffer_m is None else float(buffer_m),
            "bounds": np.asarray(first.bounds if bounds is None else bounds, np.float64),
            "surface_ids": np.concatenate([np.asarray(m.surface_ids, dtype=str) for m in meshes]),
        }
        return out

    def check(self, label: str = "") -> dict:
        """Check the mesh through trimesh; return its counts.

        Raises ``ValueError`` (a bug upstream, not bad input: ingest skips bad polygons) when
        a face names a vertex that does not exist, a vertex is not finite, or a face attribute
        or ``surface_index`` does not fit.  Returns ``{"triangles", "degenerate_triangles"}``:
        faces trimesh finds degenerate (an edge of their 2D oriented box under 1e-8 m), which
        no ray hits; they are kept (removing them would renumber the faces)."""
        mesh = self.trimesh
        where = label or self.name
        faces = self.triangles
        if len(faces) and (faces.min() < 0 or faces.max() >= len(mesh.vertices)):
            raise ValueError(f"{where}: a face names a vertex the mesh does not have")
        if not np.isfinite(self.vertices).all():
            raise ValueError(f"{where}: non-finite vertex coordinates")
        for key, (_, cols, _) in FACE_ATTRIBUTES.items():
            value = mesh.face_attributes.get(key)
            if value is None or len(value) != len(faces):
                raise ValueError(f"{where}: face attribute {key!r} does not have one row per face")
        sidx = self.surface_index
        if len(sidx) and (sidx.min() < 0 or sidx.max() >= len(self.surface_ids)):
            raise ValueError(f"{where}: a face's surface_index names no surface")
        degenerate = int((~mesh.nondegenerate_faces()).sum()) if len(faces) else 0
        return {"triangles": int(len(faces)), "degenerate_triangles": degenerate}

    # ------------------------------------------------------------------ file
    def save(self, path: str | Path) -> None:
        """Write atomically as ``.npz`` (temporary name, then rename): the Trimesh's vertices
        (float64) and faces, each face attribute as ``face_<name>``, the metadata."""
        mesh = self.trimesh
        write_npz(path, format=np.int64(MESH_FORMAT), vertices=self.vertices.astype(np.float64),
                  faces=self.triangles.astype(np.int32),
                  **{f"face_{k}": np.asarray(mesh.face_attributes[k]) for k in FACE_ATTRIBUTES},
                  surface_ids=np.asarray(self.surface_ids, dtype=str),
                  bounds=np.asarray(self.bounds, dtype=np.float64),
                  buffer_m=np.float64(self.buffer_m), name=np.str_(self.name),
                  face_attribute_names=np.str_(json.dumps(sorted(FACE_ATTRIBUTES))))

    @classmethod
    def load(cls, path: str | Path) -> "TileMesh":
        """The mesh written by :meth:`save`; a file of another format (an older vipvflow's)
        raises :class:`~vipvflow.errors.InputError` saying to ingest the city again."""
        with np.load(path, allow_pickle=False) as z:
            fmt = int(z["format"]) if "format" in z.files else 1
            if fmt != MESH_FORMAT:
                raise InputError(
                    f"{path}: a tile mesh of format {fmt}, this vipvflow reads format "
                    f"{MESH_FORMAT}: ingest the city again (vipvflow ingest city FILE... "
                    f"--data-dir DIR; vipvflow simulate does it by itself)")
            face = {k: z[f"face_{k}"] for k in FACE_ATTRIBUTES if f"face_{k}" in z.files}
            return cls(z["vertices"], z["faces"], z["surface_ids"], bounds=z["bounds"],
                       buffer_m=float(z["buffer_m"]), name=str(z["name"]), **face)

    @classmethod
    def from_triangles(cls, tris: np.ndarray, albedo=0.2, surface_type="wall",
                       name: str = "") -> "TileMesh":
        """A mesh from a (m, 3, 3) array of triangle corners (tests, synthetic scenes)."""
        tris = np.asarray(tris, dtype=np.float64).reshape(-1, 3, 3)
        m = len(tris)
        n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        lo, hi = tris.reshape(-1, 3).min(0), tris.reshape(-1, 3).max(0)
        return cls(tris.reshape(-1, 3), np.arange(3 * m).reshape(m, 3),
                   np.array([f"t{i}" for i in range(m)], dtype=str),
                   bounds=np.array([lo[0], lo[1], hi[0], hi[1]]), name=name,
                   surface_index=np.arange(m, dtype=np.int32),
                   albedo=np.broadcast_to(np.asarray(albedo, np.float32), (m,)).copy(),
                   normals=n.astype(np.float32),
                   surface_type=np.full(m, SURFACE_CODE[surface_type], np.int8))


def _face_attribute(name: str) -> property:
    return property(lambda self: self.trimesh.face_attributes[name],
                    doc=f"Face attribute ``{name}`` (:data:`FACE_ATTRIBUTES`).")


for _name in FACE_ATTRIBUTES:
    setattr(TileMesh, _name, _face_attribute(_name))
