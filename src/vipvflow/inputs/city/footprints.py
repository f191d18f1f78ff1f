"""Building footprints of the ingested city, for map backgrounds (report figures, web app).

The footprints are the CityGML ground surfaces (``GroundSurface``) of the tiles
``city/surfaces/tile=<T>/part-0.parquet``; a city model without ground surfaces (LoD1
solids, some LoD2 exports) gives its roof surfaces instead, which cover the same outline
seen from above. Everything is read from the data directory: no map service, no network.
"""
from __future__ import annotations


import numpy as np

from ...store import DataDir


def building_footprints(data_dir, tiles=None, bounds=None) -> list[np.ndarray]:
    """Outer rings of the buildings' footprints, as (n, 2) arrays of x, y in the city CRS (m).

    Parameters
    ----------
    data_dir : the data directory of a run (``city/surfaces`` inside)
    tiles : tile names to read (``None``: every tile)
    bounds : (xmin, ymin, xmax, ymax) in m: only footprints that reach into it

    Returns
    -------
    list of arrays; empty when the city has no surfaces (a map is then drawn without them).
    """
    import pyarrow.dataset as ds
    import shapely

    root = DataDir(data_dir).city.surfaces
    files = sorted(root.glob("tile=*/*.parquet"))
    if tiles is not None:
        wanted = {f"tile={t}" for t in tiles}
        files = [f for f in files if f.parent.name in wanted]
    if not files:
        return []
    data = ds.dataset([str(f) for f in files], format="parquet")
    geoms = np.empty(0, object)
    for kind in ("ground", "roof"):
        table = data.to_table(columns=["geometry"], filter=ds.field("surface_type") == kind)
        if table.num_rows:
            geoms = shapely.from_wkb(table["geometry"].to_numpy(zero_copy_only=False))
            break
    if bounds is not None and len(geoms):
        geoms = geoms[shapely.intersects(geoms, shapely.box(*bounds))]
    rings = []
    for g in geoms:
        for part in getattr(g, "geoms", [g]):
            if part.geom_type == "Polygon" and not part.is_empty:
                rings.append(np.asarray(part.exterior.coords)[:, :2])
    return rings
