"""Where the city model is: its coverage area, and the building footprints a road crosses.

A real study area covers part of a network: the model holds the buildings of some blocks,
the lines run on into streets it does not have.  :func:`coverage_area` draws the area the
model covers from its buildings' footprints (ground surfaces, else roofs seen from above):
their union closed by ``closing_m`` (the streets, courtyards and squares between modelled
buildings, up to twice that wide, are inside) and widened by ``margin_m`` (the street in
front of the outermost buildings), together with the extent of its relief (a TIN knows the
open ground too).  A road point inside it is ``in_city_model``; outside,
the model has no building that could shade it, or does not know the buildings that do.

:func:`inside_footprints` finds road points inside a building's footprint: a shape built
from straight lines between stops (a feed without shapes.txt) crosses blocks and station
halls, where the roof would be in the dark.  Each such point gets the nearest point outside
the block it lies in (``street_m`` beyond its outline) as the place its light is taken from.
"""
from __future__ import annotations

import numpy as np

from ...store import CityDir

#: the coverage area: footprints closed by this distance (m) ...
CLOSING_M = 60.0
#: ... and widened by this one (m)
MARGIN_M = 20.0
#: a road point inside a footprint takes its light this far outside the block (m): a
#: pavement's width and half a lane, where a bus drives past a building line; nearer (3 m)
#: where that lands in the next block, further where 3 m does too
STREET_M = 6.0


def footprint_polygons(city: CityDir, bounds=None) -> np.ndarray:
    """The buildings' footprints as 2D shapely polygons (ground surfaces, else roofs), from
    the tiles' surface files of *city* (an ingested ``city/`` or an ingest's staging folder);
    only those reaching into *bounds* (xmin, ymin, xmax, ymax) when given."""
    import pyarrow.dataset as ds
    import shapely

    files = sorted(city.surfaces.glob("tile=*/*.parquet"))
    if not files:
        return np.empty(0, object)
    data = ds.dataset([str(f) for f in files], format="parquet")
    geoms = np.empty(0, object)
    for kind in ("ground", "roof"):
        table = data.to_table(columns=["geometry"], filter=ds.field("surface_type") == kind)
        if table.num_rows:
            geoms = shapely.force_2d(shapely.from_wkb(table["geometry"].to_numpy(zero_copy_only=False)))
            break
    if not len(geoms):
        return geoms
    geoms = shapely.make_valid(geoms[~shapely.is_empty(geoms)])
    polys = shapely.get_parts(geoms)
    polys = polys[shapely.get_type_id(polys) == 3]           # polygons only
    polys = polys[shapely.area(polys) > 1.0]
    if bounds is not None and len(polys):
        polys = polys[shapely.intersects(polys, shapely.box(*bounds))]
    return polys


#: footprints closer than this (m) are one block
_MERGE_M = 0.5

#: the relief's extent: cells of this size (m) that a TIN triangle's bounding box meets
RELIEF_CELL_M = 25.0


def relief_cells(city: CityDir, cell_m: float = RELIEF_CELL_M) -> np.ndarray:
    """The relief (TIN) of an ingested city as square cells (shapely boxes, *cell_m* wide)
    that its triangles' bounding boxes meet: the ground the model knows, whether or not a
    building stands on it (empty without a relief)."""
    import shapely

    if not city.terrain.exists():
        return np.empty(0, object)
    with np.load(city.terrain, allow_pickle=False) as z:
        v, t = z["tin_vertices"], z["tin_triangles"]
    if not len(t):
        return np.empty(0, object)
    tri = v[t][:, :, :2]
    lo = np.floor(tri.min(axis=1) / cell_m).astype(np.int64)
    hi = np.floor(tri.max(axis=1) / cell_m).astype(np.int64)
    nx, ny = hi[:, 0] - lo[:, 0] + 1, hi[:, 1] - lo[:, 1] + 1
    rep = nx * ny                              # the cells each triangle's bounding box meets
    owner = np.repeat(np.arange(len(tri)), rep)
    k = np.arange(int(rep.sum())) - np.repeat(np.cumsum(rep) - rep, rep)
    cells = np.unique(np.column_stack([lo[owner, 0] + k // ny[owner], lo[owner, 1] + k % ny[owner]]),
                      axis=0)
    return shapely.box(cells[:, 0] * cell_m, cells[:, 1] * cell_m,
                       (cells[:, 0] + 1) * cell_m, (cells[:, 1] + 1) * cell_m)


def grown_footprints(footprints: np.ndarray, closing_m: float = CLOSING_M):
    """The footprints' union grown by *closing_m* (m), simplified: a tile's share of the
    coverage area, small whatever the number of buildings (the ingest keeps one per tile)."""
    import shapely

    if not len(footprints):
        return shapely.Polygon()
    grown = shapely.union_all(shapely.buffer(footprints, closing_m, quad_segs=4))
    return shapely.simplify(grown, 1.0)


def coverage_area(footprints: np.ndarray, closing_m: float = CLOSING_M, margin_m: float = MARGIN_M,
                  relief: np.ndarray | None = None, grown: list | None = None):
    """The area the city model covers (a shapely (Multi)Polygon, empty without footprints
    or relief): the footprints' union closed by *closing_m* and widened by *margin_m* (m),
    together with the relief's extent (:func:`relief_cells`).  *grown*: the footprints
    already grown by *closing_m* (:func:`grown_footprints`, per tile) instead of them."""
    import shapely

    parts = []
    grown = list(grown or [])
    if len(footprints):
        grown.append(grown_footprints(footprints, closing_m))
    if grown:
        parts.append(shapely.buffer(shapely.union_all(grown), margin_m - closing_m, quad_segs=4))
    if relief is not None and len(relief):
        parts.append(shapely.union_all(relief))
    if not parts:
        return shapely.Polygon()
    return shapely.union_all(parts)


def tile_footprints(surfaces) -> np.ndarray:
    """The building footprints of one tile's surfaces (a GeoDataFrame with ``surface_type``):
    its ground surfaces in 2D, else its roofs (as :func:`footprint_polygons`)."""
    import shapely

    for kind in ("ground", "roof"):
        g = surfaces.geometry.to_numpy()[surfaces["surface_type"].to_numpy() == kind]
        if len(g):
            g = shapely.get_parts(shapely.make_valid(shapely.force_2d(g)))
            g = g[shapely.get_type_id(g) == 3]
            return g[shapely.area(g) > 1.0]
    return np.empty(0, object)


def write_coverage(city: CityDir, crs: str, grown: list) -> dict:
    """Write ``coverage.parquet`` (one row: the coverage area, GeoParquet in *crs*) into
    *city*, from the tiles' grown footprints (*grown*, :func:`grown_footprints`) and the
    relief; return its area (km2) for the ingest report."""
    import geopandas as gpd
    import shapely

    from ...store import atomic_path

    relief = relief_cells(city)
    area = coverage_area(np.empty(0, object), relief=relief, grown=grown)
    gdf = gpd.GeoDataFrame({"closing_m": [CLOSING_M], "margin_m": [MARGIN_M],
                            "relief_cells": [len(relief)]}, geometry=[area], crs=crs)
    with atomic_path(city.coverage) as tmp:
        gdf.to_parquet(tmp, index=False)
    return {"coverage_km2": round(float(shapely.area(area)) / 1e6, 4)}


def read_coverage(city: CityDir):
    """The coverage area of an ingested city (computed from its footprints when the city was
    ingested before it was written); an empty polygon without a city."""
    import geopandas as gpd
    import shapely

    if city.coverage.exists():
        return gpd.read_parquet(city.coverage).geometry.iloc[0]
    if not city.tiles_json.exists():
        return shapely.Polygon()
    return coverage_area(footprint_polygons(city), relief=relief_cells(city))


def inside_footprints(x, y, footprints: np.ndarray, street_m: float = STREET_M):
    """Which points (x, y; m) lie inside a footprint, and where their light is taken from.

    Returns
    -------
    inside : (n,) bool
    dx, dy : (n,) float64, m: from each point to the nearest point ``street_m`` outside the
        block (touching footprints merged) it lies in; 0 for points outside every footprint
    """
    import shapely

    x, y = np.asarray(x, float), np.asarray(y, float)
    n = len(x)
    inside, dx, dy = np.zeros(n, bool), np.zeros(n), np.zeros(n)
    if not n or not len(footprints):
        return inside, dx, dy
    pts = shapely.points(x, y)
    tree = shapely.STRtree(footprints)
    p_idx, f_idx = tree.query(pts, predicate="within")
    if not len(p_idx):
        return inside, dx, dy
    inside[p_idx] = True
    # the blocks: footprints that touch (within half a metre) merged, around the points
    sel = np.flatnonzero(inside)
    near = np.unique(tree.query(shapely.buffer(pts[sel], 200.0, quad_segs=2),
                                predicate="intersects")[1])
    blocks = shapely.get_parts(shapely.union_all(shapely.buffer(footprints[near], _MERGE_M,
                                                                quad_segs=2)))
    btree = shapely.STRtree(blocks)
    hit_p, hit_b = btree.query(pts[sel], predicate="within")
    block_of = np.full(len(sel), -1, np.int64)
    block_of[hit_p] = hit_b
    if (block_of < 0).any():               # on an outline: the block nearest to it
        miss = np.flatnonzero(block_of < 0)
        block_of[miss] = btree.nearest(pts[sel][miss])
    end = np.full((len(sel), 2), np.nan)
    todo = np.arange(len(sel))
    for step in (street_m, street_m / 2, 2 * street_m, 4 * street_m):
        rings = shapely.get_exterior_ring(shapely.buffer(blocks[block_of[todo]], step - _MERGE_M,
                                                         quad_segs=2))
        line = shapely.shortest_line(pts[sel][todo], rings)
        cand = shapely.get_coordinates(shapely.get_point(line, 1))
        # a point pushed out of its block into another one goes further out
        bad = np.zeros(len(todo), bool)
        bp, _ = btree.query(shapely.points(cand), predicate="within")
        bad[bp] = True
        end[todo[~bad]] = cand[~bad]
        todo = todo[bad]
        if not len(todo):
            break
    if len(todo):                          # hemmed in: the last candidate
        end[todo] = cand[bad]
    dx[sel], dy[sel] = end[:, 0] - x[sel], end[:, 1] - y[sel]
    return inside, dx, dy
