"""Ground elevation from the city model: the TIN relief, else building ground surfaces.

``city/terrain.npz`` (written by :func:`vipvflow.inputs.city.ingest_city`) holds

- ``tin_vertices`` (n, 3) float64 and ``tin_triangles`` (m, 3) int32: the
  ``dem:TINRelief`` triangles (and any relief polygons, triangulated);
- ``ground_points`` (k, 3) float64: area centroid (x, y) and mean z of every building
  ground surface, used where the file has no relief;
- ``crs``.

:meth:`TerrainModel.elevation` interpolates linearly (barycentric) in the TIN triangle
containing each point, found through a uniform grid index; outside the TIN it takes the
inverse-distance mean (modified Shepard weights, falling to 0 at the radius) of the nearest
ground surfaces within ``max_distance_m``, and NaN where there is nothing.  :meth:`TerrainModel.ground` also says where each height comes from
and blends a fallback height (the radiation file's altitude, or a configured one) into the
buildings' mean with the weight of a ground point at ``max_distance_m``, so the road's
profile stays continuous where it leaves the buildings.
"""
from __future__ import annotations


import numpy as np

from ...errors import InputError
from ...store import DataDir


#: where a ground height comes from (``segments.parquet`` ``ground_source``)
GROUND_SOURCES = ("relief", "buildings", "radiation_header", "configured")


class TerrainModel:
    """Elevation (m) at points in the city's projected CRS."""

    def __init__(self, tin_vertices: np.ndarray, tin_triangles: np.ndarray,
                 ground_points: np.ndarray, crs: str = "", max_distance_m: float = 100.0):
        self.vertices = np.asarray(tin_vertices, dtype=np.float64).reshape(-1, 3)
        self.triangles = np.asarray(tin_triangles, dtype=np.int64).reshape(-1, 3)
        self.ground_points = np.asarray(ground_points, dtype=np.float64).reshape(-1, 3)
        self.crs = crs
        self.max_distance_m = float(max_distance_m)
        self._grid = None
        self._tree = None

    @classmethod
    def load(cls, data_dir, max_distance_m: float = 100.0) -> "TerrainModel":
        """Read ``<data_dir>/city/terrain.npz``."""
        path = DataDir(data_dir).city.terrain
        if not path.exists():
            raise InputError(f"{path}: no terrain model (run `vipvflow ingest city` first)")
        with np.load(path, allow_pickle=False) as z:
            return cls(z["tin_vertices"], z["tin_triangles"], z["ground_points"],
                       str(z["crs"]), max_distance_m)

    # -- TIN ------------------------------------------------------------------------
    def _build_grid(self):
        tri = self.vertices[self.triangles][:, :, :2]          # (m, 3, 2)
        lo, hi = tri.min(axis=1), tri.max(axis=1)
        origin = lo.min(axis=0)
        extent = np.maximum(hi.max(axis=0) - origin, 1e-6)
        cell = max(float(np.sqrt(extent[0] * extent[1] / max(len(tri), 1))) * 2.0,
                   float(np.median(np.max(hi - lo, axis=1))), 1e-3)
        shape = np.floor(extent / cell).astype(np.int64) + 1
        c0 = np.floor((lo - origin) / cell).astype(np.int64)
        c1 = np.floor((hi - origin) / cell).astype(np.int64)
        nx, ny = c1[:, 0] - c0[:, 0] + 1, c1[:, 1] - c0[:, 1] + 1
        rep = nx * ny
        t = np.repeat(np.arange(len(tri)), rep)
        k = np.arange(int(rep.sum())) - np.repeat(np.cumsum(rep) - rep, rep)
        cx = c0[t, 0] + k // ny[t]
        cy = c0[t, 1] + k % ny[t]
        cell_id = cx * shape[1] + cy
        order = np.argsort(cell_id, kind="stable")
        cell_id, t = cell_id[order], t[order]
        cells, starts = np.unique(cell_id, return_index=True)
        ends = np.append(starts[1:], len(cell_id))
        self._grid = (origin, cell, shape, cells, starts, ends, t)

    def _tin(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        z = np.full(len(x), np.nan)
        if len(self.triangles) == 0 or len(x) == 0:
            return z
        if self._grid is None:
            self._build_grid()
        origin, cell, shape, cells, starts, ends, tri_of = self._grid
        ix = np.floor((x - origin[0]) / cell).astype(np.int64)
        iy = np.floor((y - origin[1]) / cell).astype(np.int64)
        inside = (ix >= 0) & (iy >= 0) & (ix < shape[0]) & (iy < shape[1])
        cid = ix * shape[1] + iy
        pos = np.searchsorted(cells, cid)
        pos_c = np.minimum(pos, len(cells) - 1)
        hit = inside & (cells[pos_c] == cid)
        pts = np.flatnonzero(hit)
        n = ends[pos_c[pts]] - starts[pos_c[pts]]
        p = np.repeat(pts, n)                                           # point of each pair
        k = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        t = tri_of[np.repeat(starts[pos_c[pts]], n) + k]               # candidate triangle
        a, b, c = (self.vertices[self.triangles[t, j]] for j in range(3))
        v0x, v0y = b[:, 0] - a[:, 0], b[:, 1] - a[:, 1]
        v1x, v1y = c[:, 0] - a[:, 0], c[:, 1] - a[:, 1]
        v2x, v2y = x[p] - a[:, 0], y[p] - a[:, 1]
        den = v0x * v1y - v1x * v0y
        ok = np.abs(den) > 1e-12
        den = np.where(ok, den, 1.0)
        l1 = (v2x * v1y - v1x * v2y) / den
        l2 = (v0x * v2y - v2x * v0y) / den
        l0 = 1.0 - l1 - l2
        eps = 1e-9
        good = ok & (l0 >= -eps) & (l1 >= -eps) & (l2 >= -eps)
        zz = l0 * a[:, 2] + l1 * b[:, 2] + l2 * c[:, 2]
        # first containing triangle per point (later pairs overwrite earlier: reverse order)
        sel = np.flatnonzero(good)[::-1]
        z[p[sel]] = zz[sel]
        return z

    # -- fallback ---------------------------------------------------------------------
    def _ground(self, x: np.ndarray, y: np.ndarray, fallback_m: float | None = None) -> np.ndarray:
        z = np.full(len(x), np.nan)
        if len(self.ground_points) == 0 or len(x) == 0:
            return z
        if self._tree is None:
            from scipy.spatial import cKDTree

            self._tree = cKDTree(self.ground_points[:, :2])
        k = min(4, len(self.ground_points))
        d, i = self._tree.query(np.column_stack([x, y]), k=k,
                                distance_upper_bound=self.max_distance_m)
        d, i = d.reshape(len(x), k), i.reshape(len(x), k)
        valid = np.isfinite(d)
        # Franke and Nielson's modified Shepard weights ((R - d) / (R d))^2: a point's weight
        # falls to 0 at the search radius R, so the mean has no step where a point leaves it
        r = max(self.max_distance_m, 1e-3)
        dd = np.maximum(np.where(valid, d, r), 1e-3)
        w = np.where(valid, ((r - np.minimum(dd, r)) / (r * dd)) ** 2, 0.0)
        zi = np.where(valid, self.ground_points[np.minimum(i, len(self.ground_points) - 1), 2], 0.0)
        wsum = w.sum(axis=1)
        has = wsum > 0
        num = (w * zi).sum(axis=1)
        if fallback_m is not None:
            # the fallback weighs as a ground point at the search radius would in plain
            # inverse-distance weighting: it takes over smoothly where the buildings end
            w0 = 1.0 / r ** 2
            num, wsum = num + w0 * float(fallback_m), wsum + w0
            has = has | valid.any(axis=1)
        z[has] = num[has] / wsum[has]
        return z

    def ground(self, x, y, fallback_m: float | None = None,
               fallback_source: str = "configured") -> tuple[np.ndarray, np.ndarray]:
        """Ground elevation (m) and its source at points (x, y) in m.

        The TIN relief where it covers a point; else the inverse-distance mean of the
        building ground surfaces within ``max_distance_m``, blended with *fallback_m*;
        else *fallback_m*; else NaN.

        Returns
        -------
        z : ndarray of float64, m (NaN where nothing is known and there is no fallback)
        source : ndarray of int8, index into :data:`GROUND_SOURCES` (-1: unknown);
            *fallback_source* (``radiation_header`` or ``configured``) names the fallback
        """
        x = np.asarray(x, dtype=np.float64).ravel()
        y = np.asarray(y, dtype=np.float64).ravel()
        z = np.full(len(x), np.nan)
        src = np.full(len(x), -1, np.int8)
        step = 200_000
        for s in range(0, len(x), step):
            xs, ys = x[s:s + step], y[s:s + step]
            zs = self._tin(xs, ys)
            ss = np.where(np.isfinite(zs), GROUND_SOURCES.index("relief"), -1).astype(np.int8)
            miss = np.isnan(zs)
            if miss.any():
                zb = self._ground(xs[miss], ys[miss], fallback_m)
                sb = np.where(np.isfinite(zb), GROUND_SOURCES.index("buildings"), -1)
                if fallback_m is not None:
                    sb = np.where(np.isfinite(zb), sb, GROUND_SOURCES.index(fallback_source))
                    zb = np.where(np.isfinite(zb), zb, float(fallback_m))
                zs[miss], ss[miss] = zb, sb
            z[s:s + step], src[s:s + step] = zs, ss
        return z, src

    def elevation(self, x, y) -> np.ndarray:
        """Ground elevation (m) at points (x, y) in m; NaN where the model knows nothing.

        Parameters
        ----------
        x, y : array_like, m, the city's projected CRS

        Returns
        -------
        ndarray of float64, m, same shape as ``x``
        """
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        shape = np.broadcast(x, y).shape
        x, y = np.broadcast_to(x, shape).ravel(), np.broadcast_to(y, shape).ravel()
        z = np.full(len(x), np.nan)
        step = 200_000
        for s in range(0, len(x), step):
            xs, ys = x[s:s + step], y[s:s + step]
            zs = self._tin(xs, ys)
            miss = np.isnan(zs)
            if miss.any():
                zs[miss] = self._ground(xs[miss], ys[miss])
            z[s:s + step] = zs
        return z.reshape(shape)
