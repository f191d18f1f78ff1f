"""Ray queries against a tile's mesh: Embree (embreex) behind one small interface.

:class:`Scene` builds the BVH once per tile mesh.  Vertices and ray origins are shifted by
the mesh centre before they become float32, so a ray in a national CRS (coordinates of
10^5 to 10^6 m) keeps millimetre precision.  Large batches are split over a small thread
pool: embreex releases the GIL while it traces.

:func:`occluded_reference` is a plain-numpy Moeller-Trumbore test used to check the fast
path on small scenes.
"""
from __future__ import annotations

import collections
import os
import threading
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from ..store import DataDir
from .mesh import SURFACE_CODE, TileMesh

#: number of BVH builds by :func:`get_scene`, per (data_dir, tile)
BVH_BUILDS: collections.Counter = collections.Counter()

_FAR = np.float32(1e30)
_MIN_SPLIT = 65_536        # rays per thread below which a batch is not split
_pool: ThreadPoolExecutor | None = None
_pool_lock = threading.Lock()


def available_cores() -> int:
    """CPU cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not Linux
        return max(1, os.cpu_count() or 1)


def _get_pool(n: int) -> ThreadPoolExecutor:
    global _pool
    with _pool_lock:
        if _pool is None or _pool._max_workers < n:
            _pool = ThreadPoolExecutor(max_workers=n, thread_name_prefix="vipv-rays")
        return _pool


class Scene:
    """An Embree scene of one tile mesh, built once.

    Parameters
    ----------
    mesh : TileMesh
    n_threads : int, optional
        Threads for large ray batches (default: the cores available to the process).
    trees : vipvflow.models.trees.TreeTable, optional
        The trees whose crowns the scene's rays meet (:meth:`crowns`).

    Notes
    -----
    Coordinates are metres in the projected CRS.  Internally everything is relative to
    ``self.origin`` (the centre of the mesh's bounding box) in float32.
    """

    def __init__(self, mesh: TileMesh, n_threads: int | None = None, trees=None):
        self.mesh = mesh
        self.trees = trees if trees is not None and len(trees) else None
        self._crowns: dict = {}
        self.n_threads = n_threads or available_cores()
        v = np.asarray(mesh.vertices, np.float64)
        if not len(v) and self.trees is not None:        # a tile of trees alone: their frame
            v = np.column_stack([self.trees.x, self.trees.y, self.trees.z])
        self.origin = (v.min(0) + v.max(0)) / 2 if len(v) else np.zeros(3)
        self.n_triangles = int(len(mesh.triangles))
        self._scene = None
        if self.n_triangles:
            tris = np.ascontiguousarray((v[mesh.triangles] - self.origin).astype(np.float32))
            self._scene = rtcore_scene.EmbreeScene()
            self._mesh = TriangleMesh(self._scene, tris)

    def crowns(self, cfg):
        """The scene's tree crowns for the tree parameters *cfg*
        (:class:`vipvflow.models.params.TreeCfg`, or an ``IrradianceCfg`` holding them) in
        the scene's frame (:class:`vipvflow.models.trees.Crowns`, built once per *cfg*), or
        None: no trees, or ``cfg.enabled`` false."""
        cfg = getattr(cfg, "trees", cfg)
        if self.trees is None or cfg is None or not cfg.enabled:
            return None
        key = cfg.model_dump_json()
        crowns = self._crowns.get(key)
        if crowns is None:
            from .trees import Crowns

            crowns = self._crowns[key] = Crowns(self.trees, cfg, self.origin)
        return crowns

    def sun_masks(self, origins_local, reach: float) -> np.ndarray:
        """Per origin (n, 3; the scene's frame, :meth:`to_local`) and 1 deg azimuth sector
        a slope above which a ray of length *reach* (m) meets no triangle of the scene
        (:func:`vipvflow.models.horizon.building_masks`): (n,
        :data:`~vipvflow.models.horizon.BUILDING_SECTORS`) float64."""
        from .horizon import BUILDING_SECTORS, MASK_FLOOR, building_masks

        o = np.ascontiguousarray(np.asarray(origins_local, np.float32).reshape(-1, 3))
        out = np.empty((len(o), BUILDING_SECTORS))
        v = np.asarray(self.mesh.vertices, np.float64)
        tris = (np.ascontiguousarray((v[self.mesh.triangles] - self.origin).astype(np.float32))
                if self.n_triangles else np.zeros((0, 3, 3), np.float32))
        t64 = tris.astype(np.float64)
        box = np.ascontiguousarray(np.concatenate([t64[:, :, :2].min(1), t64[:, :, :2].max(1)], axis=1))
        building_masks(tris, np.ascontiguousarray(t64[:, :, 2].max(1)), box, o,
                       float(reach) * 1.001 + 1.0, MASK_FLOOR, out)
        return out

    # ------------------------------------------------------------------ helpers
    def _prepare(self, origins, dirs, tfar):
        o = np.ascontiguousarray((np.asarray(origins, np.float64) - self.origin).astype(np.float32))
        d = np.ascontiguousarray(np.asarray(dirs, np.float32))
        n = len(o)
        if np.ndim(tfar) == 0:
            t = np.full(n, min(float(tfar), float(_FAR)), np.float32)
        else:
            t = np.ascontiguousarray(np.minimum(np.asarray(tfar, np.float32), _FAR))
        return o.reshape(-1, 3), d.reshape(-1, 3), t

    def _run(self, o, d, t, query, output):
        n = len(o)
        k = min(self.n_threads, max(1, n // _MIN_SPLIT))
        if k <= 1:
            return self._scene.run(o, d, dists=t, query=query, output=output)
        bounds = np.linspace(0, n, k + 1).astype(np.int64)
        sl = [slice(bounds[i], bounds[i + 1]) for i in range(k)]
        parts = list(_get_pool(k).map(
            lambda s: self._scene.run(o[s], d[s], dists=t[s].copy(), query=query, output=output), sl))
        if output:
            return {key: np.concatenate([p[key] for p in parts]) for key in ("primID", "tfar")}
        return np.concatenate(parts)

    # ------------------------------------------------------------------ queries
    def occluded(self, origins, dirs, tfar=np.inf) -> np.ndarray:
        """Whether each ray hits any triangle within distance *tfar*.

        Parameters
        ----------
        origins : (n, 3) float, m, projected CRS
        dirs : (n, 3) float, unit vectors
        tfar : float or (n,) float, m

        Returns
        -------
        (n,) bool
        """
        o, d, t = self._prepare(origins, dirs, tfar)
        if self._scene is None or len(o) == 0:
            return np.zeros(len(o), bool)
        return self._run(o, d, t, "OCCLUDED", None) != -1

    def to_local(self, points) -> np.ndarray:
        """Points (m, projected CRS) as float32 relative to :attr:`origin`, the form
        :meth:`occluded_local` takes (millimetre precision within a tile)."""
        p = np.asarray(points, np.float64)
        return np.ascontiguousarray((p - self.origin).astype(np.float32))

    def occluded_local(self, origins, dirs, tfar) -> np.ndarray:
        """:meth:`occluded` for ray origins already in the scene's frame (:meth:`to_local`):
        float32 (n, 3) origins and unit directions and a scalar *tfar* (m), no conversion."""
        o = np.ascontiguousarray(origins, np.float32).reshape(-1, 3)
        d = np.ascontiguousarray(dirs, np.float32).reshape(-1, 3)
        if self._scene is None or len(o) == 0:
            return np.zeros(len(o), bool)
        t = np.full(len(o), min(float(tfar), float(_FAR)), np.float32)
        return self._run(o, d, t, "OCCLUDED", None) != -1

    def first_hit(self, origins, dirs, tfar=np.inf) -> tuple[np.ndarray, np.ndarray]:
        """The closest triangle hit by each ray within *tfar*.

        Returns
        -------
        tri : (n,) int32, triangle index into the mesh, -1 for no hit
        t : (n,) float32, distance along the ray (m; ``inf`` for no hit, with unit *dirs*)
        """
        o, d, t = self._prepare(origins, dirs, tfar)
        if self._scene is None or len(o) == 0:
            return np.full(len(o), -1, np.int32), np.full(len(o), np.inf, np.float32)
        res = self._run(o, d, t, "INTERSECT", 1)
        tri = res["primID"].astype(np.int32)
        dist = np.where(tri >= 0, res["tfar"], np.float32(np.inf)).astype(np.float32)
        return tri, dist


def occluded_reference(mesh: TileMesh, origins, dirs, tfar=np.inf, eps: float = 1e-9) -> np.ndarray:
    """Plain-numpy Moeller-Trumbore occlusion test (for tests on small scenes).

    Same arguments and result as :meth:`Scene.occluded`; O(rays x triangles) memory per
    chunk, float64 throughout.

    References
    ----------
    T. Moeller, B. Trumbore (1997), Fast, minimum storage ray-triangle intersection,
    Journal of Graphics Tools 2(1), 21-28.
    """
    o = np.asarray(origins, np.float64).reshape(-1, 3)
    d = np.asarray(dirs, np.float64).reshape(-1, 3)
    tf = np.broadcast_to(np.asarray(tfar, np.float64), (len(o),))
    tri = np.asarray(mesh.vertices, np.float64)[mesh.triangles]
    v0, e1, e2 = tri[:, 0], tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]
    out = np.zeros(len(o), bool)
    step = max(1, 2_000_000 // max(1, len(tri)))
    for a in range(0, len(o), step):
        oo, dd, tt = o[a:a + step, None], d[a:a + step, None], tf[a:a + step, None]
        p = np.cross(dd, e2[None])
        det = (e1[None] * p).sum(-1)
        ok = np.abs(det) > eps
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        s = oo - v0[None]
        u = (s * p).sum(-1) * inv
        q = np.cross(s, e1[None])
        v = (dd * q).sum(-1) * inv
        t = (e2[None] * q).sum(-1) * inv
        hit = ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > eps) & (t <= tt)
        out[a:a + step] = hit.any(axis=1)
    return out


# ---------------------------------------------------------------------- per-process cache
_cache: "collections.OrderedDict[tuple, Scene]" = collections.OrderedDict()
_cache_lock = threading.Lock()


def modelled_tiles(data_dir) -> frozenset:
    """The tiles the city model of *data_dir* has a mesh for (``city/tiles.json``): every
    tile within ``city.buffer_m`` of a modelled surface; empty without a city model."""
    import json

    path = DataDir(data_dir).city.tiles_json
    if not path.exists():
        return frozenset()
    return frozenset(json.loads(path.read_text()).get("tiles", {}))


def get_scene(data_dir, tile: str, cache_size: int = 8, n_threads: int | None = None) -> Scene:
    """The :class:`Scene` of a tile, from a bounded LRU cache of this process.

    Loads ``city/meshes/<tile>.npz`` (and the tile's trees, ``city/trees/<tile>.npz``)
    and builds the BVH on a miss; each build is counted in
    :data:`BVH_BUILDS` under the key ``(data_dir, tile)``.  *n_threads* sets the ray-casting
    threads of a new scene (default: the cores available).  A tile the city model has no
    mesh for (no modelled surface within the buffer: a line that leaves the model) is an
    open field: a scene without surfaces, the sky unobstructed.

    Raises
    ------
    InputError
        When ``city/tiles.json`` lists the tile but its mesh file is missing (a damaged
        data dir: ingest the city again).
    """
    key = (str(Path(data_dir).resolve()), tile)
    with _cache_lock:
        scene = _cache.get(key)
        if scene is not None:
            _cache.move_to_end(key)
            return scene
    from .trees import load_tile_trees

    path = DataDir(data_dir).city.mesh(tile)
    trees = load_tile_trees(data_dir, tile)
    if path.exists():
        mesh = TileMesh.load(path)
    elif tile in modelled_tiles(data_dir):
        from ..errors import InputError

        raise InputError(f"{path}: missing, though {DataDir(data_dir).city.tiles_json} lists tile "
                         f"{tile}; run `vipvflow ingest city` again")
    else:
        mesh = box_mesh([], name=tile)
    scene = Scene(mesh, n_threads=n_threads, trees=trees)
    with _cache_lock:
        BVH_BUILDS[key] += 1
        _cache[key] = scene
        _cache.move_to_end(key)
        while len(_cache) > max(1, cache_size):
            _cache.popitem(last=False)
    return scene


def clear_scene_cache() -> None:
    """Drop every cached scene (the build counter is kept)."""
    with _cache_lock:
        _cache.clear()


# ---------------------------------------------------------------------- synthetic scenes
_BOX_FACES = np.array([[0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5], [2, 3, 7], [2, 7, 6],
                       [3, 0, 4], [3, 4, 7], [4, 5, 6], [4, 6, 7]])


def box_mesh(boxes, albedo_wall: float = 0.3, albedo_roof: float = 0.15, name: str = "") -> TileMesh:
    """A mesh of axis-aligned boxes (walls and flat roofs, outward normals; no floor).

    Parameters
    ----------
    boxes : (n, 6) array of ``xmin, ymin, zmin, xmax, ymax, zmax`` (m)
    """
    b = np.asarray(boxes, np.float64).reshape(-1, 6)
    if len(b) == 0:
        return TileMesh(np.zeros((0, 3)), np.zeros((0, 3), np.int64), name=name,
                        surface_index=np.zeros(0, np.int32), albedo=np.zeros(0, np.float32),
                        normals=np.zeros((0, 3), np.float32), surface_type=np.zeros(0, np.int8))
    x0, y0, z0, x1, y1, z1 = b.T
    corners = np.stack([np.stack([x0, y0, z0], 1), np.stack([x1, y0, z0], 1),
                        np.stack([x1, y1, z0], 1), np.stack([x0, y1, z0], 1),
                        np.stack([x0, y0, z1], 1), np.stack([x1, y0, z1], 1),
                        np.stack([x1, y1, z1], 1), np.stack([x0, y1, z1], 1)], axis=1)
    tris = corners[:, _BOX_FACES].reshape(-1, 3, 3)
    mesh = TileMesh.from_triangles(tris, albedo=albedo_wall, surface_type="wall", name=name)
    roof = np.tile(np.arange(10) >= 8, len(b))
    mesh.albedo[roof] = albedo_roof
    mesh.surface_type[roof] = SURFACE_CODE["roof"]
    return mesh
