"""The demo town as CityGML 2.0 LoD2: terrain (TIN relief), buildings and street trees.

Buildings are rectangular footprints placed in rows along the street stretches of the
:mod:`~vipvflow.demo.layout` (continuous perimeter-block rows in canyons, detached houses
with gaps in suburban stretches, none in open stretches), standing on the terrain, with
flat, gabled or hipped roofs.  Every building is a closed shell of planar polygons whose
vertices run counter-clockwise seen from outside (outward normals).

Street trees line the canyon and suburban stretches (:func:`place_trees`): small-crowned
limes, maples and planes on the canyons' pavements, larger crowns of several genera (a few
pines among them) on the suburban verges, their crowns 4 m or more above the road (as
trees over bus routes are pruned), none in a building or over another street's carriageway.
Each is a ``veg:SolitaryVegetationObject`` with its species, height, crown and trunk diameter
and crown base (a generic attribute), and an implicit geometry (a unit tree of trunk and
low-poly crown, defined once per crown shape and referred to by xlink, scaled by its
transformation matrix and placed at its reference point), as tree cadastres and LiDAR
tree models write them.

The file is written element by element (lxml, one
``core:cityObjectMember`` per building, tree and ``dem:ReliefFeature`` per 1 km terrain tile),
so a reader can stream it.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import shapely
from lxml import etree

from .layout import EAVES_RANGE, Layout

SRS_NAME = "urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774"
NS = {
    "core": "http://www.opengis.net/citygml/2.0",
    "bldg": "http://www.opengis.net/citygml/building/2.0",
    "dem": "http://www.opengis.net/citygml/relief/2.0",
    "veg": "http://www.opengis.net/citygml/vegetation/2.0",
    "gen": "http://www.opengis.net/citygml/generics/2.0",
    "gml": "http://www.opengis.net/gml",
    "xlink": "http://www.w3.org/1999/xlink",
    "xsi": "http://www.w3.org/2001/XMLSchema-instance",
}
SCHEMA_LOCATION = (
    "http://www.opengis.net/citygml/building/2.0 "
    "http://schemas.opengis.net/citygml/building/2.0/building.xsd "
    "http://www.opengis.net/citygml/relief/2.0 "
    "http://schemas.opengis.net/citygml/relief/2.0/relief.xsd "
    "http://www.opengis.net/citygml/vegetation/2.0 "
    "http://schemas.opengis.net/citygml/vegetation/2.0/vegetation.xsd "
    "http://www.opengis.net/citygml/generics/2.0 "
    "http://schemas.opengis.net/citygml/generics/2.0/generics.xsd")
# roof type codes of the SIG3D/AdV code list used by German and Luxembourg LoD2 data
ROOF_TYPE_CODE = {"flat": "1000", "gabled": "1030", "hipped": "1040"}
_ROOF_MIX = {"canyon": {"flat": 0.35, "gabled": 0.5, "hipped": 0.15},
             "suburban": {"flat": 0.15, "gabled": 0.55, "hipped": 0.30},
             "terminus": {"flat": 0.5, "gabled": 0.4, "hipped": 0.1}}

#: line ends with a terminus among buildings (line, end: 0 first stop, 1 last stop), per demo
#: size: a bus turns at a village square or a station forecourt, not only in an open field
#: (the other ends stay in the open: a park-and-ride at the edge of town)
TERMINUS_ENDS = {"full": (("1", 0), ("2", 0)), "small": (("1", 1),)}
#: a terminus square: building rows along the last TERMINUS_BACK_M of the line and
#: TERMINUS_AHEAD_M beyond its end (the turning loop), TERMINUS_OFFSET_M beyond the road edge
TERMINUS_BACK_M, TERMINUS_AHEAD_M, TERMINUS_OFFSET_M = 110.0, 40.0, 6.0
TERRAIN_SPACING_M = 50.0
TERRAIN_TILE_M = 1000.0


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


# --------------------------------------------------------------------------- terrain
class Terrain:
    """Gentle relief on a regular grid, triangulated into a TIN.

    Elevations (m, NG-L) of a plateau at about 335 m cut by a north-south valley (floor near
    285 m) east of the centre, with a small undulation whose phases come from the seed.
    Each grid cell is split along its south-west to north-east diagonal; :meth:`z` is the
    piecewise-linear surface of exactly those triangles.
    """

    def __init__(self, bounds, seed: int, spacing: float = TERRAIN_SPACING_M):
        self.spacing = float(spacing)
        x0 = np.floor(bounds[0] / spacing) * spacing
        y0 = np.floor(bounds[1] / spacing) * spacing
        self.nx = int(np.ceil((bounds[2] - x0) / spacing))
        self.ny = int(np.ceil((bounds[3] - y0) / spacing))
        self.x0, self.y0 = float(x0), float(y0)
        gx = x0 + spacing * np.arange(self.nx + 1)
        gy = y0 + spacing * np.arange(self.ny + 1)
        X, Y = np.meshgrid(gx, gy)  # (ny+1, nx+1)
        self.grid = np.round(self.height_function(X, Y, seed), 3)

    @staticmethod
    def height_function(x, y, seed: int):
        """Smooth elevation model (m) at EPSG:2169 points."""
        ph = np.random.default_rng([seed, 4]).uniform(0, 2 * np.pi, 3)
        x_valley = 78600.0 + 250.0 * np.sin(2 * np.pi * (y - 75000.0) / 3000.0 + ph[0])
        z = 336.0 - 48.0 * np.exp(-(((x - x_valley) / 750.0) ** 2))
        z += 4.0 * np.sin(2 * np.pi * x / 2300.0 + ph[1]) * np.cos(2 * np.pi * y / 1900.0 + ph[2])
        return np.clip(z, 281.0, 339.0)

    @property
    def bounds(self):
        return (self.x0, self.y0, self.x0 + self.nx * self.spacing, self.y0 + self.ny * self.spacing)

    def z(self, x, y):
        """Elevation of the TIN at points (m)."""
        fx = (np.asarray(x, dtype=float) - self.x0) / self.spacing
        fy = (np.asarray(y, dtype=float) - self.y0) / self.spacing
        i = np.clip(np.floor(fx).astype(int), 0, self.nx - 1)
        j = np.clip(np.floor(fy).astype(int), 0, self.ny - 1)
        u, v = fx - i, fy - j
        g = self.grid
        z00, z10, z01, z11 = g[j, i], g[j, i + 1], g[j + 1, i], g[j + 1, i + 1]
        lower = u >= v  # triangle (00, 10, 11)
        return np.where(lower, z00 + u * (z10 - z00) + v * (z11 - z10),
                        z00 + v * (z01 - z00) + u * (z11 - z01))

    def triangles(self, i0: int, i1: int, j0: int, j1: int) -> np.ndarray:
        """Triangles (m, 3, 3) of cells [i0, i1) x [j0, j1), counter-clockwise from above."""
        I, J = np.meshgrid(np.arange(i0, i1), np.arange(j0, j1))
        I, J = I.ravel(), J.ravel()

        def vert(di, dj):
            return np.stack([self.x0 + (I + di) * self.spacing, self.y0 + (J + dj) * self.spacing,
                             self.grid[J + dj, I + di]], axis=-1)

        v00, v10, v01, v11 = vert(0, 0), vert(1, 0), vert(0, 1), vert(1, 1)
        lower = np.stack([v00, v10, v11], axis=1)
        upper = np.stack([v00, v11, v01], axis=1)
        return np.stack([lower, upper], axis=1).reshape(-1, 3, 3)


# --------------------------------------------------------------------------- buildings
@dataclass
class Building:
    gml_id: str
    stretch_id: str
    kind: str
    footprint: np.ndarray   # (4, 2) counter-clockwise from above; ridge along edge 0->1
    roof_type: str          # flat | gabled | hipped
    base_z: float           # m
    eaves_z: float          # m
    ridge_z: float          # m
    storeys: int

    def surfaces(self) -> list[tuple[str, np.ndarray]]:
        """(type, ring (n, 3)) of every polygon of the closed shell, ring not repeated."""
        return shell_polygons(self.footprint, self.base_z, self.eaves_z, self.ridge_z, self.roof_type)


def shell_polygons(fp, base, eaves, ridge, roof_type):
    """Polygons of a rectangular building, counter-clockwise seen from outside.

    Parameters
    ----------
    fp : (4, 2) array
        Footprint corners counter-clockwise seen from above; a gabled or hipped roof has
        its ridge parallel to edge 0->1.
    base, eaves, ridge : float
        Ground, eaves and ridge elevations (m).
    roof_type : {"flat", "gabled", "hipped"}
    """
    B = [np.array([p[0], p[1], base]) for p in fp]
    E = [np.array([p[0], p[1], eaves]) for p in fp]
    ground = [("ground", np.array([B[0], B[3], B[2], B[1]]))]
    rect_walls = [("wall", np.array([B[i], B[(i + 1) % 4], E[(i + 1) % 4], E[i]])) for i in range(4)]
    if roof_type == "flat":
        return [("roof", np.array(E))] + rect_walls + ground
    m03 = 0.5 * (fp[0] + fp[3])
    m12 = 0.5 * (fp[1] + fp[2])
    if roof_type == "gabled":
        r0, r1 = np.r_[m03, ridge], np.r_[m12, ridge]
        roofs = [("roof", np.array([E[0], E[1], r1, r0])), ("roof", np.array([E[2], E[3], r0, r1]))]
        walls = [rect_walls[0],
                 ("wall", np.array([B[1], B[2], E[2], r1, E[1]])),
                 rect_walls[2],
                 ("wall", np.array([B[3], B[0], E[0], r0, E[3]]))]
        return roofs + walls + ground
    if roof_type == "hipped":
        u = (fp[1] - fp[0]) / np.hypot(*(fp[1] - fp[0]))
        d = 0.5 * np.hypot(*(fp[3] - fp[0]))
        r0, r1 = np.r_[m03 + d * u, ridge], np.r_[m12 - d * u, ridge]
        roofs = [("roof", np.array([E[0], E[1], r1, r0])), ("roof", np.array([E[2], E[3], r0, r1])),
                 ("roof", np.array([E[1], E[2], r1])), ("roof", np.array([E[3], E[0], r0]))]
        return roofs + rect_walls + ground
    raise ValueError(f"unknown roof type {roof_type!r}")


def _row(a, b, offset, side, depth_fn, width_fn, gap_fn, skip_p, rng):
    """Rectangles along street piece a->b at *offset* m on *side* (+1 left, -1 right).

    Each footprint is counter-clockwise from above with its first edge on the street side.
    """
    L = np.hypot(*(b - a))
    u = (b - a) / L
    n = np.array([-u[1], u[0]])  # left normal
    out = []
    s = 0.0
    while True:
        w = width_fn()
        if s + w > L:
            w = L - s
            if w < 8.0:
                break
        depth = depth_fn()
        if rng.random() >= skip_p:
            near0 = a + s * u + side * offset * n
            near1 = near0 + w * u
            far0, far1 = near0 + side * depth * n, near1 + side * depth * n
            fp = np.array([near0, near1, far1, far0]) if side > 0 else np.array([near1, near0, far0, far1])
            out.append(fp)
        s += w + gap_fn()
    return out


@dataclass(frozen=True)
class Terminus:
    """A line end among buildings (``kind`` and ``stretch_id`` as a street stretch's)."""

    line: str
    end: int
    xy: tuple
    kind: str = "terminus"

    @property
    def stretch_id(self) -> str:
        return f"L{self.line}_terminus_{self.end}"


def terminus_ends(layout: Layout) -> list[Terminus]:
    """The line ends of :data:`TERMINUS_ENDS` (where the buses lay over among buildings)."""
    out = []
    for line in layout.lines:
        for name, end in TERMINUS_ENDS.get(layout.size, ()):
            if name == line.name:
                p = line.xy[0] if end == 0 else line.xy[-1]
                out.append(Terminus(line.name, end, (float(p[0]), float(p[1]))))
    return out


def _terminus_candidates(layout: Layout, rng) -> list:
    """Building rows on both sides of the last street piece at each terminus, running
    :data:`TERMINUS_AHEAD_M` past the line's end (the square the buses turn in)."""
    out = []
    by_name = {line.name: line for line in layout.lines}
    for t in terminus_ends(layout):
        line = by_name[t.line]
        xy = line.xy if t.end == 1 else line.xy[::-1]
        end, prev = xy[-1], xy[-2]
        u = (end - prev) / np.hypot(*(end - prev))
        a, b = end - TERMINUS_BACK_M * u, end + TERMINUS_AHEAD_M * u
        width = next(st.width_m for st in (line.stretches if t.end == 1 else line.stretches[::-1]))
        off = width / 2 + TERMINUS_OFFSET_M
        for side in (1, -1):
            for fp in _row(a, b, off, side, lambda: rng.uniform(12.0, 15.0),
                           lambda: rng.uniform(12.0, 20.0), lambda: rng.uniform(0.0, 4.0), 0.0, rng):
                out.append((t, np.round(fp, 3)))
    return out


def place_buildings(layout: Layout, terrain: Terrain, seed: int) -> list[Building]:
    """Buildings along the canyon and suburban stretches and around the termini among
    buildings (:data:`TERMINUS_ENDS`), none overlapping a street.

    Candidates are laid out in rows along every straight street piece; any candidate that
    reaches into a street (of any line) or overlaps an earlier one is dropped.
    """
    rng = np.random.default_rng([seed, 2])
    cands = []  # (stretch, footprint)
    for st in layout.stretches():
        if st.kind == "open":
            continue
        for a, b in zip(st.xy[:-1], st.xy[1:]):
            for side in (1, -1):
                if st.kind == "canyon":
                    o1 = st.width_m / 2
                    d1 = rng.uniform(11.0, 14.0)
                    o2 = o1 + d1 + rng.uniform(14.0, 22.0)
                    rows = [(o1, lambda: d1, lambda: rng.uniform(10.0, 20.0), lambda: 0.0, 0.0),
                            (o2, lambda: rng.uniform(10.0, 13.0), lambda: rng.uniform(10.0, 20.0),
                             lambda: 0.0, 0.0)]
                else:
                    o1 = st.width_m / 2 + st.setback_m
                    rows = [(o1 + k * rng.uniform(30.0, 38.0), lambda: rng.uniform(8.0, 11.0),
                             lambda: rng.uniform(9.0, 14.0), lambda: rng.uniform(5.0, 12.0), 0.15)
                            for k in range(2 if layout.size == "small" else 3)]
                for off, dfn, wfn, gfn, skip in rows:
                    for fp in _row(a, b, off, side, dfn, wfn, gfn, skip, rng):
                        cands.append((st, np.round(fp, 3)))

    cands += _terminus_candidates(layout, rng)
    polys = shapely.polygons([fp for _, fp in cands])
    shrunk = shapely.buffer(polys, -0.05, join_style="mitre")
    # streets: the road (and the front gardens of suburban stretches) of every stretch
    streets = [shapely.buffer(shapely.linestrings(st.xy),
                              st.width_m / 2 + st.setback_m + (3.0 if st.kind == "open" else 0.0),
                              cap_style="flat", join_style="round")
               for st in layout.stretches()]
    hits = shapely.STRtree(streets).query(shrunk, predicate="intersects")
    ok = np.ones(len(cands), dtype=bool)
    ok[np.unique(hits[0])] = False
    pairs = shapely.STRtree(shrunk).query(shrunk, predicate="intersects")
    earlier = [[] for _ in cands]
    for i, j in pairs.T:
        if j < i:
            earlier[i].append(j)
    for i in range(len(cands)):
        if ok[i] and any(ok[j] for j in earlier[i]):
            ok[i] = False

    buildings = []
    for (st, fp), keep in zip(cands, ok):
        if not keep:
            continue
        mix = _ROOF_MIX[st.kind]
        roof = str(rng.choice(list(mix), p=list(mix.values())))
        if st.kind == "canyon":
            storeys = int(rng.integers(4, 7))
            eaves_h = 3.0 * storeys + 2.0
        elif st.kind == "terminus":
            storeys = int(rng.integers(3, 5))
            eaves_h = 3.0 * storeys + 1.5
        else:
            eaves_h = float(rng.uniform(*EAVES_RANGE["suburban"]))
            storeys = 2 if eaves_h < 8.5 else 3
        along, across = np.hypot(*(fp[1] - fp[0])), np.hypot(*(fp[2] - fp[1]))
        if roof == "hipped":
            if along < across:  # ridge along the long side
                fp = np.roll(fp, -1, axis=0)
                along, across = across, along
            if along < across + 1.0:
                roof = "gabled"
        if roof == "gabled" and st.kind == "suburban" and rng.random() < 0.3:
            fp = np.roll(fp, -1, axis=0)  # gable end to the street
            across = along
        pitch = rng.uniform(25.0, 35.0) if roof == "hipped" else rng.uniform(30.0, 45.0)
        base = float(np.round(terrain.z(fp[:, 0], fp[:, 1]).min(), 3))
        eaves = round(base + eaves_h, 3)
        ridge = eaves if roof == "flat" else round(eaves + 0.5 * across * np.tan(np.radians(pitch)), 3)
        buildings.append(Building(f"bldg_{len(buildings):05d}", st.stretch_id, st.kind, fp,
                                  roof, base, eaves, ridge, storeys))
    return buildings


# --------------------------------------------------------------------------- writing
def _pos_list(ring: np.ndarray) -> str:
    closed = np.concatenate([ring, ring[:1]])
    return " ".join(f"{v:.3f}" for v in closed.ravel())


def _polygon(parent, gml_id: str | None, ring: np.ndarray, tag: str = "Polygon"):
    attrib = {_q("gml", "id"): gml_id} if gml_id else {}
    poly = etree.SubElement(parent, _q("gml", tag), attrib)
    lr = etree.SubElement(etree.SubElement(poly, _q("gml", "exterior")), _q("gml", "LinearRing"))
    etree.SubElement(lr, _q("gml", "posList"), srsDimension="3").text = _pos_list(ring)
    return poly


_BOUNDARY_TAG = {"roof": "RoofSurface", "wall": "WallSurface", "ground": "GroundSurface"}
_XMLNS = re.compile(rb' xmlns:\w+="[^"]*"')


def _member() -> etree._Element:
    return etree.Element(_q("core", "cityObjectMember"), nsmap=NS)


def building_member(b: Building) -> etree._Element:
    """``core:cityObjectMember`` holding the ``bldg:Building`` of *b*.

    The building has a ``lod2Solid`` referencing (xlink) the polygons of its boundary
    surfaces, which carry the geometry.
    """
    member = _member()
    el = etree.SubElement(member, _q("bldg", "Building"), {_q("gml", "id"): b.gml_id})
    etree.SubElement(el, _q("gml", "name")).text = f"{b.kind} building {b.gml_id}"
    etree.SubElement(el, _q("bldg", "function")).text = "1000" if b.kind == "suburban" else "1010"
    etree.SubElement(el, _q("bldg", "roofType")).text = ROOF_TYPE_CODE[b.roof_type]
    etree.SubElement(el, _q("bldg", "measuredHeight"), uom="m").text = f"{b.ridge_z - b.base_z:.3f}"
    etree.SubElement(el, _q("bldg", "storeysAboveGround")).text = str(b.storeys)
    surfaces = b.surfaces()
    counts = {"roof": 0, "wall": 0, "ground": 0}
    ids = []
    for kind, _ in surfaces:
        ids.append(f"{b.gml_id}_{kind}_{counts[kind]}")
        counts[kind] += 1
    solid = etree.SubElement(etree.SubElement(el, _q("bldg", "lod2Solid")), _q("gml", "Solid"))
    comp = etree.SubElement(etree.SubElement(solid, _q("gml", "exterior")), _q("gml", "CompositeSurface"))
    for sid in ids:
        etree.SubElement(comp, _q("gml", "surfaceMember"), {_q("xlink", "href"): f"#{sid}_poly"})
    for (kind, ring), sid in zip(surfaces, ids):
        bounded = etree.SubElement(el, _q("bldg", "boundedBy"))
        surf = etree.SubElement(bounded, _q("bldg", _BOUNDARY_TAG[kind]), {_q("gml", "id"): sid})
        ms = etree.SubElement(etree.SubElement(surf, _q("bldg", "lod2MultiSurface")), _q("gml", "MultiSurface"))
        _polygon(etree.SubElement(ms, _q("gml", "surfaceMember")), f"{sid}_poly", ring)
    return member


def relief_members(terrain: Terrain, near=None):
    """``core:cityObjectMember`` with one ``dem:ReliefFeature`` (TIN) per terrain tile.

    Tiles are :data:`TERRAIN_TILE_M` squares; with *near* (a shapely geometry), only those
    that intersect it.  Yields (member, number of triangles).
    """
    step = int(round(TERRAIN_TILE_M / terrain.spacing))
    sp = terrain.spacing
    for j0 in range(0, terrain.ny, step):
        for i0 in range(0, terrain.nx, step):
            i1, j1 = min(i0 + step, terrain.nx), min(j0 + step, terrain.ny)
            x0, y0 = terrain.x0 + i0 * sp, terrain.y0 + j0 * sp
            if near is not None and not shapely.box(x0, y0, terrain.x0 + i1 * sp,
                                                    terrain.y0 + j1 * sp).intersects(near):
                continue
            name = f"E{int(x0 // 100):04d}N{int(y0 // 100):04d}"
            member = _member()
            rf = etree.SubElement(member, _q("dem", "ReliefFeature"), {_q("gml", "id"): f"relief_{name}"})
            etree.SubElement(rf, _q("gml", "name")).text = f"terrain {name}"
            etree.SubElement(rf, _q("dem", "lod")).text = "2"
            tin = etree.SubElement(etree.SubElement(rf, _q("dem", "reliefComponent")), _q("dem", "TINRelief"),
                                   {_q("gml", "id"): f"tin_{name}"})
            etree.SubElement(tin, _q("dem", "lod")).text = "2"
            ts = etree.SubElement(etree.SubElement(tin, _q("dem", "tin")), _q("gml", "TriangulatedSurface"),
                                  {_q("gml", "id"): f"tin_{name}_surface"})
            patches = etree.SubElement(ts, _q("gml", "trianglePatches"))
            tris = terrain.triangles(i0, i1, j0, j1)
            for tri in tris:
                _polygon(patches, None, tri, tag="Triangle")
            yield member, len(tris)


def _fragment(el: etree._Element) -> bytes:
    """*el* serialised without the namespace declarations the root element already makes."""
    text = etree.tostring(el, encoding="UTF-8", pretty_print=True, xml_declaration=False)
    end = text.index(b">")
    return _XMLNS.sub(b"", text[:end]) + text[end:]


def write_citygml(path: Path, buildings: list[Building], terrain: Terrain, near=None,
                  trees: list | None = None) -> dict:
    """Write the CityGML 2.0 file; return counts of what it holds.

    One ``core:cityObjectMember`` per building, per tree (*trees*, :func:`place_trees`) and per
    terrain tile, written one after the other (the file is never held in memory).  *near*
    (shapely geometry, optional) limits the terrain to the 1 km tiles it touches.
    """
    counts = {"buildings": 0, "roof_surfaces": 0, "wall_surfaces": 0, "ground_surfaces": 0,
              "terrain_triangles": 0, "relief_features": 0, "trees": 0}
    top = max([b.ridge_z for b in buildings], default=float(terrain.grid.max()))
    lo = (*terrain.bounds[:2], float(terrain.grid.min()))
    hi = (*terrain.bounds[2:], max(top, float(terrain.grid.max())))
    root = etree.Element(_q("core", "CityModel"), {_q("xsi", "schemaLocation"): SCHEMA_LOCATION}, nsmap=NS)
    name = etree.SubElement(root, _q("gml", "name"))
    name.text = "vipvflow demo town (synthetic, Luxembourg-like)"
    bb = etree.SubElement(root, _q("gml", "boundedBy"))
    env = etree.SubElement(bb, _q("gml", "Envelope"), srsName=SRS_NAME, srsDimension="3")
    etree.SubElement(env, _q("gml", "lowerCorner")).text = " ".join(f"{v:.3f}" for v in lo)
    etree.SubElement(env, _q("gml", "upperCorner")).text = " ".join(f"{v:.3f}" for v in hi)
    with open(path, "wb") as fh:
        fh.write(b"<?xml version='1.0' encoding='UTF-8'?>\n")
        head = etree.tostring(root, encoding="UTF-8", pretty_print=True)
        fh.write(head[: head.rindex(b"</")])  # everything but the closing tag
        for member, ntri in relief_members(terrain, near):
            fh.write(_fragment(member))
            counts["terrain_triangles"] += ntri
            counts["relief_features"] += 1
        for b in buildings:
            fh.write(_fragment(building_member(b)))
            counts["buildings"] += 1
            for kind, _ in b.surfaces():
                counts[f"{kind}_surfaces"] += 1
        defined: set = set()
        for tree in trees or ():
            fh.write(_fragment(tree_member(tree, defined)))
            counts["trees"] += 1
        fh.write(head[head.rindex(b"</"):])
    return counts


# --------------------------------------------------------------------------- street trees
@dataclass
class Tree:
    gml_id: str
    stretch_id: str
    species: str
    x: float
    y: float
    z: float                # ground at the trunk (m)
    height: float           # m above the ground
    crown_diameter: float   # m
    crown_base: float       # m above the ground
    trunk_diameter: float   # m


#: species of the street trees (botanical names), per stretch kind
_SPECIES = {"canyon": ("Tilia cordata", "Acer platanoides", "Platanus x hispanica"),
            "suburban": ("Acer platanoides", "Tilia cordata", "Betula pendula", "Quercus robur",
                         "Prunus avium", "Pinus nigra")}
_SPECIES_P = {"canyon": (0.45, 0.35, 0.20), "suburban": (0.25, 0.22, 0.17, 0.15, 0.13, 0.08)}
#: unit trees (trunk to crown base share of the height) the implicit geometries refer to
CROWN_SHAPES = (0.3, 0.4, 0.5)


def place_trees(layout: Layout, terrain: Terrain, buildings: list[Building], seed: int) -> list[Tree]:
    """Street trees along the canyon and suburban stretches (none in the open).

    Canyons: a tree every 10-14 m on each pavement, 3 m from the facades, crowns of
    4.5-5.2 m (clear of the facades), 9-13 m high, crown base 4.0-5.0 m.  Suburban
    stretches: a tree every 12-18 m on each verge 1.5 m beyond the road edge, crowns of 6-10
    m, 10-18 m high, crown base 4.0-5.5 m.  A quarter of the places stay empty (driveways,
    crossings); a tree whose trunk stands on another street's carriageway or whose crown
    meets a building is dropped.  Drawn from their own stream of *seed* (the buildings are
    those of the generator without trees).
    """
    rng = np.random.default_rng([seed, 5])
    footprints = shapely.STRtree(shapely.polygons([b.footprint for b in buildings])) if buildings else None
    roads = []
    for st in layout.stretches():
        half = st.width_m / 2 - (3.0 if st.kind == "canyon" else 0.0)
        roads.append((st.stretch_id, shapely.buffer(shapely.linestrings(st.xy), half, cap_style="flat")))
    road_tree = shapely.STRtree([r for _, r in roads])
    trees = []
    for st in layout.stretches():
        if st.kind not in _SPECIES:
            continue
        canyon = st.kind == "canyon"
        offset = st.width_m / 2 - 3.0 if canyon else st.width_m / 2 + 1.5
        for a, b in zip(st.xy[:-1], st.xy[1:]):
            L = float(np.hypot(*(b - a)))
            u = (b - a) / L
            n = np.array([-u[1], u[0]])
            for side in (1, -1):
                s = float(rng.uniform(2.0, 8.0))
                while s < L - 2.0:
                    step = rng.uniform(10.0, 14.0) if canyon else rng.uniform(12.0, 18.0)
                    keep = rng.random() >= 0.25
                    if canyon:
                        crown, height, base = rng.uniform(4.5, 5.2), rng.uniform(9.0, 13.0), rng.uniform(4.0, 5.0)
                    else:
                        crown, height, base = rng.uniform(6.0, 10.0), rng.uniform(10.0, 18.0), rng.uniform(4.0, 5.5)
                    species = str(rng.choice(_SPECIES[st.kind], p=_SPECIES_P[st.kind]))
                    p = a + s * u + side * offset * n
                    s += step
                    if not keep:
                        continue
                    trunk = shapely.Point(*p)
                    hits = road_tree.query(trunk, predicate="intersects")
                    if any(roads[i][0] != st.stretch_id for i in hits):
                        continue
                    if footprints is not None and len(footprints.query(
                            shapely.buffer(trunk, crown / 2 + 0.3), predicate="intersects")):
                        continue
                    z = float(np.round(terrain.z(p[0], p[1]), 3))
                    trees.append(Tree(f"tree_{len(trees):05d}", st.stretch_id, species,
                                      float(np.round(p[0], 3)), float(np.round(p[1], 3)), z,
                                      round(float(height), 2), round(float(crown), 2),
                                      round(float(base), 2), round(float(0.025 * height + 0.1), 2)))
    return trees


def unit_tree(shape: float, n_az: int = 8) -> list[np.ndarray]:
    """Polygons (rings, counter-clockwise from outside) of a unit tree: an octagonal trunk of
    radius 0.03 from 0 to *shape* and a low-poly spheroid crown of radius 0.5 from *shape*
    to 1 (rings at 30, 60, 90, 120 and 150 deg from its bottom)."""
    az = 2 * np.pi * np.arange(n_az) / n_az
    c = (1.0 - shape) / 2
    zc = shape + c
    polar = np.radians([30.0, 60.0, 90.0, 120.0, 150.0])
    rings = [np.stack([0.5 * np.sin(t) * np.sin(az), 0.5 * np.sin(t) * np.cos(az),
                       np.full(n_az, zc - c * np.cos(t))], 1) for t in polar]
    bottom, top = np.array([0.0, 0.0, shape]), np.array([0.0, 0.0, 1.0])
    polys = []
    for k in range(n_az):
        j = (k + 1) % n_az
        polys.append(np.array([bottom, rings[0][j], rings[0][k]]))
        for lo, hi in zip(rings[:-1], rings[1:]):
            polys.append(np.array([lo[k], lo[j], hi[j], hi[k]]))
        polys.append(np.array([rings[-1][k], rings[-1][j], top]))
    tr = 0.03
    b = [np.array([tr * np.sin(a), tr * np.cos(a), 0.0]) for a in az]
    t = [np.array([tr * np.sin(a), tr * np.cos(a), shape]) for a in az]
    for k in range(n_az):
        j = (k + 1) % n_az
        polys.append(np.array([b[k], b[j], t[j], t[k]]))
    return polys


def tree_member(tree: Tree, defined: set) -> etree._Element:
    """``core:cityObjectMember`` holding the ``veg:SolitaryVegetationObject`` of *tree*: its
    attributes and its ``lod2ImplicitRepresentation`` (the unit tree of the crown shape
    nearest its own, inline the first time (*defined* remembers it), else by xlink)."""
    member = _member()
    el = etree.SubElement(member, _q("veg", "SolitaryVegetationObject"), {_q("gml", "id"): tree.gml_id})
    etree.SubElement(el, _q("gml", "name")).text = f"street tree {tree.gml_id}"
    att = etree.SubElement(el, _q("gen", "doubleAttribute"), name="crown_base")
    etree.SubElement(att, _q("gen", "value")).text = f"{tree.crown_base:.2f}"
    etree.SubElement(el, _q("veg", "species")).text = tree.species
    etree.SubElement(el, _q("veg", "height"), uom="m").text = f"{tree.height:.2f}"
    etree.SubElement(el, _q("veg", "trunkDiameter"), uom="m").text = f"{tree.trunk_diameter:.2f}"
    etree.SubElement(el, _q("veg", "crownDiameter"), uom="m").text = f"{tree.crown_diameter:.2f}"
    shape = min(CROWN_SHAPES, key=lambda f: abs(f - tree.crown_base / tree.height))
    tid = f"unit_tree_{int(round(shape * 100)):02d}"
    rep = etree.SubElement(el, _q("veg", "lod2ImplicitRepresentation"))
    ig = etree.SubElement(rep, _q("core", "ImplicitGeometry"))
    m = np.diag([tree.crown_diameter, tree.crown_diameter, tree.height, 1.0])
    etree.SubElement(ig, _q("core", "transformationMatrix")).text = " ".join(f"{v:g}" for v in m.ravel())
    rel = etree.SubElement(ig, _q("core", "relativeGMLGeometry"))
    if tid in defined:
        rel.set(_q("xlink", "href"), f"#{tid}")
    else:
        defined.add(tid)
        ms = etree.SubElement(rel, _q("gml", "MultiSurface"), {_q("gml", "id"): tid})
        for ring in unit_tree(shape):
            _polygon(etree.SubElement(ms, _q("gml", "surfaceMember")), None, ring)
    pt = etree.SubElement(etree.SubElement(ig, _q("core", "referencePoint")), _q("gml", "Point"))
    etree.SubElement(pt, _q("gml", "pos"), srsDimension="3").text = f"{tree.x:.3f} {tree.y:.3f} {tree.z:.3f}"
    return member
