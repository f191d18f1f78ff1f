"""Synthetic CityGML 2.0 cities of gabled houses (benchmarks, memory and tiling tests).

Written as a stream, so a city of any size costs no memory to produce.  Each house is a
w x d footprint, eaves height h, ridge height h + r along x: 2 roof planes, 4 walls
(2 rectangles, 2 pentagon gables), 1 ground; exterior rings counter-clockwise seen from
outside.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

HEADER = """<?xml version="1.0" encoding="UTF-8"?>
<core:CityModel xmlns:core="http://www.opengis.net/citygml/2.0" xmlns:bldg="http://www.opengis.net/citygml/building/2.0" xmlns:gml="http://www.opengis.net/gml">
<gml:boundedBy><gml:Envelope srsName="{srs}" srsDimension="3"><gml:lowerCorner>{x0} {y0} 0</gml:lowerCorner><gml:upperCorner>{x1} {y1} 50</gml:upperCorner></gml:Envelope></gml:boundedBy>
"""


def house_polygons(x: float, y: float, z: float, w: float, d: float, h: float, r: float):
    """{type: [ring, ...]} of a gabled house, rings (n, 3) open, outward counter-clockwise."""
    x1, y1, ym = x + w, y + d, y + d / 2
    zt, zr = z + h, z + h + r
    P = np.array
    return {
        "ground": [P([[x, y, z], [x, y1, z], [x1, y1, z], [x1, y, z]])],
        "wall": [P([[x, y, z], [x1, y, z], [x1, y, zt], [x, y, zt]]),              # south
                 P([[x1, y1, z], [x, y1, z], [x, y1, zt], [x1, y1, zt]]),          # north
                 P([[x1, y, z], [x1, y1, z], [x1, y1, zt], [x1, ym, zr], [x1, y, zt]]),  # east
                 P([[x, y1, z], [x, y, z], [x, y, zt], [x, ym, zr], [x, y1, zt]])],      # west
        "roof": [P([[x, y, zt], [x1, y, zt], [x1, ym, zr], [x, ym, zr]]),          # south slope
                 P([[x1, y1, zt], [x, y1, zt], [x, ym, zr], [x1, ym, zr]])],       # north slope
    }


_CLS = {"roof": "RoofSurface", "wall": "WallSurface", "ground": "GroundSurface"}


def building_xml(bid: str, polys: dict) -> str:
    parts = [f'<core:cityObjectMember><bldg:Building gml:id="{bid}">']
    k = 0
    for stype, rings in polys.items():
        for ring in rings:
            closed = np.vstack([ring, ring[:1]])
            pos = " ".join(f"{v:.3f}" for v in closed.ravel())
            parts.append(
                f'<bldg:boundedBy><bldg:{_CLS[stype]} gml:id="{bid}_s{k}"><bldg:lod2MultiSurface>'
                f'<gml:MultiSurface><gml:surfaceMember><gml:Polygon><gml:exterior><gml:LinearRing>'
                f'<gml:posList srsDimension="3">{pos}</gml:posList></gml:LinearRing></gml:exterior>'
                f'</gml:Polygon></gml:surfaceMember></gml:MultiSurface></bldg:lod2MultiSurface>'
                f'</bldg:{_CLS[stype]}></bldg:boundedBy>')
            k += 1
    parts.append("</bldg:Building></core:cityObjectMember>\n")
    return "".join(parts)


def write_synthetic_city(path, n_buildings: int, spacing_m: float = 25.0,
                         origin=(77000.0, 75000.0), srs: str = "EPSG:2169",
                         seed: int = 0) -> dict:
    """Write *n_buildings* gabled houses on a square grid; return totals for checks.

    Returns
    -------
    dict with ``buildings``, ``surfaces`` per type, ``area_m2`` per type (analytic),
    ``bounds`` (xmin, ymin, xmax, ymax).
    """
    rng = np.random.default_rng(seed)
    cols = int(np.ceil(np.sqrt(n_buildings)))
    x0, y0 = origin
    extent = cols * spacing_m
    area = {"roof": 0.0, "wall": 0.0, "ground": 0.0}
    with open(Path(path), "w", encoding="utf-8") as fh:
        fh.write(HEADER.format(srs=srs, x0=x0, y0=y0, x1=x0 + extent, y1=y0 + extent))
        for i in range(n_buildings):
            w, d = rng.uniform(8, 18), rng.uniform(8, 14)
            h, r = rng.uniform(4, 20), rng.uniform(1, 5)
            x = x0 + (i % cols) * spacing_m + rng.uniform(0, spacing_m - w - 1)
            y = y0 + (i // cols) * spacing_m + rng.uniform(0, spacing_m - d - 1)
            z = 300.0 + rng.uniform(-2, 2)
            fh.write(building_xml(f"B{i}", house_polygons(x, y, z, w, d, h, r)))
            slope = np.hypot(d / 2, r)
            area["roof"] += 2 * w * slope
            area["wall"] += 2 * w * h + 2 * (d * h + d * r / 2)
            area["ground"] += w * d
        fh.write("</core:CityModel>\n")
    n = n_buildings
    return {"buildings": n, "surfaces": {"roof": 2 * n, "wall": 4 * n, "ground": n},
            "area_m2": area, "bounds": (x0, y0, x0 + extent, y0 + extent)}
