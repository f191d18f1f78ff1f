"""Streaming CityGML 1.0 / 2.0 / 3.0 reader.

``lxml.etree.iterparse`` delivers one ``cityObjectMember`` at a time; the member is turned
into a :class:`Feature` (raw rings as numpy arrays, no per-vertex Python objects) and then
cleared together with everything parsed before it, so memory stays bounded for files of
gigabytes.  Elements are matched by local name, so the same code reads every CityGML
version and both GML 3.1.1 (``http://www.opengis.net/gml``) and GML 3.2
(``http://www.opengis.net/gml/3.2``).

What is read
------------
- ``Building`` and its ``BuildingPart`` s (any depth; building id = the top Building's
  ``gml:id``): thematic boundary surfaces (``boundedBy`` in 1.0/2.0, ``boundary`` in 3.0)
  with their lod2 (else lod3/lod4/lod1) multi-surfaces; without thematic surfaces the
  object's lod2Solid / lod2MultiSurface / lod1Solid / lod1MultiSurface, typed later
  from the normal. ``xlink:href`` surface members are resolved within the feature.
- ``ReliefFeature`` / ``TINRelief``: triangles and polygons (``gml:Triangle`` in
  ``trianglePatches`` / ``patches``) as terrain.
- ``SolitaryVegetationObject`` / ``PlantCover``: trees and plant covers, never surfaces of
  the mesh (:mod:`vipvflow.inputs.city.trees` makes crowns of them): their attributes
  (``height``, ``crownDiameter``, ``averageHeight``, ``class``, ``species``, generic attributes
  naming a crown base or leaf type), explicit geometry (any LoD: its vertices), and implicit
  geometry (``ImplicitGeometry``: the transformation matrix and reference point, the relative
  geometry inline, by xlink within the feature or to a template an earlier feature of the
  file defined; an external ``libraryObject`` is not read, its attributes serve).
"""
from __future__ import annotations

import gzip
import re
import zipfile
import zlib
from collections import Counter
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterator

import numpy as np
from lxml import etree

from ...errors import InputError

XLINK_HREF = "{http://www.w3.org/1999/xlink}href"
GML_IDS = ("{http://www.opengis.net/gml}id", "{http://www.opengis.net/gml/3.2}id")

#: thematic surface class -> surface type of the contract
THEMATIC = {
    "RoofSurface": "roof",
    "WallSurface": "wall",
    "GroundSurface": "ground",
    "ClosureSurface": "closure",
    "OuterFloorSurface": "roof",     # up-facing, open to the sky (terraces)
    "OuterCeilingSurface": "other",  # down-facing overhangs
}
#: interior (LoD4) surfaces: not part of the outer shell
INTERIOR = {"InteriorWallSurface", "CeilingSurface", "FloorSurface"}

_MEMBERS = ("{*}cityObjectMember", "{*}featureMember", "{*}Envelope")
#: CityGML versions read; a namespace naming another version is refused
VERSIONS = ("1.0", "2.0", "3.0")
_CITYGML_NS = re.compile(r"opengis\.net/citygml/(?:[A-Za-z]+/)?(\d+\.\d+)")
_LOD_SURF = re.compile(r"^lod([0-4])(MultiSurface|Solid|Geometry|CompositeSurface|MultiSolid)$")
_POLYGONAL = {"Polygon", "Triangle", "PolygonPatch", "Rectangle"}


def local(el) -> str:
    tag = el.tag
    if not isinstance(tag, str):
        return ""
    return tag.rpartition("}")[2]


def gml_id(el) -> str | None:
    for key in GML_IDS:
        v = el.get(key)
        if v is not None:
            return v
    return None


@dataclass
class RawSurface:
    """One polygon as read: rings (n, 3) in the file's CRS, exterior first."""

    rings: list
    surface_type: str | None      # None: classify from the normal
    citygml_class: str
    surface_id: str | None        # None: generate
    reversed: bool = False


@dataclass
class Vegetation:
    """What a vegetation object says about its shape (file CRS; None where it says nothing).

    ``cls``: ``SolitaryVegetationObject`` or ``PlantCover``; ``attributes``: name -> value
    (``height``, ``crownDiameter``, ``trunkDiameter``, ``averageHeight`` in m, ``class``,
    ``species``, ``function``, and generic attributes by name); ``vertices`` (n, 3) of its
    explicit geometry; ``ref`` (3,) the implicit geometry's reference point, ``offsets``
    (k, 3) its relative geometry through the transformation matrix (m, added to ``ref``),
    ``matrix`` the 4 x 4 matrix; ``polygons`` the explicit polygons' exterior rings (plant
    covers: their footprint)."""

    cls: str
    attributes: dict = field(default_factory=dict)
    vertices: np.ndarray | None = None
    ref: np.ndarray | None = None
    offsets: np.ndarray | None = None
    matrix: np.ndarray | None = None
    polygons: list = field(default_factory=list)
    implicit: str = ""          # "", "inline", "template", "library", "unresolved"

    def sample(self) -> np.ndarray:
        """Some of its coordinates (file CRS), for settling the file's axis order."""
        parts = [a for a in (self.vertices, None if self.ref is None else self.ref[None]) if a is not None]
        return np.concatenate(parts) if parts else np.zeros((0, 3))


@dataclass
class Feature:
    """A city object: its id, kind (building, terrain, vegetation) and polygons (a
    vegetation object's shape in ``vegetation``)."""

    kind: str
    feature_id: str
    surfaces: list = field(default_factory=list)
    n_parts: int = 0
    thematic: Counter = field(default_factory=Counter)   # thematic surfaces per type
    problems: Counter = field(default_factory=Counter)   # unreadable bits, per reason
    skips: list = field(default_factory=list)            # (surface type or None, reason) per unreadable polygon
    lods: set = field(default_factory=set)               # LoDs the geometry was taken from
    vegetation: Vegetation | None = None

    @property
    def lod_used(self) -> str:
        """``"lod2"``, ``"lod1"``, ``"lod1+lod2"`` (parts of different LoDs) or ``"none"``."""
        return "+".join(f"lod{k}" for k in sorted(self.lods)) or "none"


class CityGMLReader:
    """Iterate the features of one CityGML file (or file object).

    Parameters
    ----------
    source : path or binary file object
    label : str
        Name used in error messages (file path, ``zip!member``).

    Attributes (after iteration has started)
    ----------------------------------------
    srs_name : str or None -- first ``srsName`` met (envelope or geometry)
    version : str or None -- ``"1.0"``, ``"2.0"`` or ``"3.0"``
    ignored : Counter -- features not read, per class name
    """

    def __init__(self, source, label: str):
        self.source = source
        self.label = label
        self.srs_name: str | None = None
        self.version: str | None = None
        self.gml: str | None = None
        self.ignored: Counter = Counter()
        self._anon = 0
        self._seen_ns: set = set()
        #: implicit geometries' relative geometries by gml:id, for later features' xlinks
        self.templates: dict = {}

    def __iter__(self) -> Iterator[Feature]:
        ctx = etree.iterparse(self.source, events=("end",), tag=_MEMBERS, huge_tree=True,
                              remove_comments=True, remove_pis=True)
        try:
            for _, elem in ctx:
                name = local(elem)
                if name == "Envelope":
                    if self.srs_name is None and elem.get("srsName"):
                        self.srs_name = elem.get("srsName")
                    continue
                self._check_version(elem)
                for child in elem:
                    if not isinstance(child.tag, str):
                        continue
                    self._check_version(child)
                    feature = self._feature(child)
                    if feature is not None:
                        yield feature
                # free what has been read: the member and all earlier siblings
                elem.clear()
                parent = elem.getparent()
                if parent is not None:
                    while elem.getprevious() is not None:
                        del parent[0]
        except etree.XMLSyntaxError as exc:
            line = exc.lineno if exc.lineno else "?"
            raise InputError(f"{self.label}: line {line}: not well-formed XML: {exc.msg}") from None
        except (EOFError, zlib.error, zipfile.BadZipFile, OSError) as exc:
            # raised while reading a .gz / .zip member: corrupt or truncated archive
            kind = "zlib.error" if isinstance(exc, zlib.error) else type(exc).__name__
            raise InputError(f"{self.label}: corrupt or truncated file ({kind}: {exc})") from None
        finally:
            del ctx

    def _check_version(self, el) -> None:
        """Note the CityGML version of *el*'s namespace; refuse versions not read."""
        ns = etree.QName(el).namespace or ""
        if ns in self._seen_ns:
            return
        self._seen_ns.add(ns)
        m = _CITYGML_NS.search(ns)
        if not m:
            return
        if m.group(1) not in VERSIONS:
            raise InputError(f"{self.label}: line {el.sourceline}: CityGML version {m.group(1)} "
                             f"(namespace {ns}) is not supported; vipvflow reads CityGML "
                             f"{', '.join(VERSIONS)}")
        if self.version is None:
            self.version = m.group(1)

    # -- features -----------------------------------------------------------------
    def _feature(self, el) -> Feature | None:
        name = local(el)
        if self.gml is None:
            self.gml = "3.2" if el.get(GML_IDS[1]) is not None else (
                "3.1.1" if el.get(GML_IDS[0]) is not None else None)
        if self.srs_name is None:
            found = el.xpath(".//@srsName")
            if found:
                self.srs_name = str(found[0])
        if name == "Building":
            return self._building(el)
        if name == "ReliefFeature":
            return self._generic(el, "terrain", "terrain", "ReliefFeature")
        if name in ("SolitaryVegetationObject", "PlantCover"):
            return self._vegetation(el, name)
        self.ignored[name] += 1
        return None

    def _new_id(self, kind: str) -> str:
        self._anon += 1
        return f"{Path(self.label).stem}_{kind}_{self._anon}"

    def _building(self, el) -> Feature:
        bid = gml_id(el) or self._new_id("building")
        feature = Feature("building", bid)
        index = _LazyIndex(el)
        objects = [el] + [p for p in el.iter("{*}BuildingPart")]
        feature.n_parts = len(objects) - 1
        for obj in objects:
            n_thematic = 0
            for holder in obj:
                if local(holder) not in ("boundedBy", "boundary"):
                    continue
                for surf in holder:
                    cls = local(surf)
                    if cls in INTERIOR:
                        feature.problems["interior_surface_ignored"] += 1
                        continue
                    stype = THEMATIC.get(cls)
                    if stype is None:
                        continue
                    n_thematic += 1
                    feature.thematic[stype] += 1
                    geom = _best_lod(surf)
                    if geom is None:
                        feature.problems["surface_without_geometry"] += 1
                        continue
                    feature.lods.add(_lod_of(geom))
                    sid = gml_id(surf)
                    polys = list(_polygons(geom, index, feature.problems))
                    for k, (poly, rev) in enumerate(polys):
                        rings, why = _rings(poly)
                        if rings is None:
                            feature.skips.append((stype, why))
                            continue
                        this_id = None if sid is None else (sid if len(polys) == 1 else f"{sid}_{k}")
                        feature.surfaces.append(RawSurface(rings, stype, cls, this_id, rev))
            if n_thematic == 0:
                geom = _fallback_geometry(obj)
                if geom is not None:
                    feature.lods.add(_lod_of(geom))
                    for poly, rev in _polygons(geom, index, feature.problems):
                        rings, why = _rings(poly)
                        if rings is None:
                            feature.skips.append((None, why))
                        else:
                            feature.surfaces.append(
                                RawSurface(rings, None, local(geom), gml_id(poly), rev))
        return feature

    def _generic(self, el, kind: str, stype: str, cls: str) -> Feature:
        fid = gml_id(el) or self._new_id(kind)
        feature = Feature(kind, fid)
        index = _LazyIndex(el)
        for poly, rev in _polygons(el, index, feature.problems, skip_implicit=True):
            rings, why = _rings(poly)
            if rings is None:
                feature.skips.append((stype, why))
            else:
                feature.surfaces.append(RawSurface(rings, stype, cls, None, rev))
        return feature


    def _vegetation(self, el, cls: str) -> Feature:
        """A tree or plant cover: attributes, explicit vertices, implicit geometry."""
        fid = gml_id(el) or self._new_id("vegetation")
        feature = Feature("vegetation", fid)
        veg = feature.vegetation = Vegetation(cls)
        index = _LazyIndex(el)
        for child in el:
            if not isinstance(child.tag, str):
                continue
            name = local(child)
            if name in _VEG_NUMBERS:
                try:
                    veg.attributes[name] = float(child.text)
                except (TypeError, ValueError):
                    feature.problems[f"unreadable_{name}"] += 1
            elif name in ("class", "species", "function", "usage"):
                veg.attributes[name] = (child.text or "").strip()
            elif name.endswith("Attribute") and child.get("name"):      # CityGML 1.0 / 2.0
                value = next((v.text for v in child if local(v) == "value"), None)
                if value is not None:
                    veg.attributes[child.get("name")] = value.strip()
            elif name == "genericAttribute":                              # CityGML 3.0
                for att in child:
                    parts = {local(v): (v.text or "").strip() for v in att if isinstance(v.tag, str)}
                    if parts.get("name") and "value" in parts:
                        veg.attributes[parts["name"]] = parts["value"]
            elif "ImplicitRepresentation" in name and veg.ref is None:
                self._implicit(child, veg, index, feature.problems)
            elif _LOD_SURF.match(name):
                rings = []
                for poly, _ in _polygons(child, index, feature.problems, skip_implicit=True):
                    r, why = _rings(poly)
                    if r is None:
                        feature.skips.append(("vegetation", why))
                    else:
                        rings.append(r[0])
                if rings:
                    feature.lods.add(_lod_of(child))
                    veg.polygons += rings
        if veg.polygons:
            veg.vertices = np.concatenate(veg.polygons)
        return feature

    def _implicit(self, holder, veg: "Vegetation", index, problems: Counter) -> None:
        """An ``ImplicitGeometry``: matrix, reference point, relative geometry's vertices."""
        ig = next((c for c in holder.iter() if local(c) == "ImplicitGeometry"), None)
        if ig is None:
            return
        matrix, ref, rel = np.eye(4), None, None
        for child in ig:
            name = local(child)
            if name == "transformationMatrix":
                try:
                    matrix = np.array((child.text or "").split(), np.float64).reshape(4, 4)
                except ValueError:
                    problems["unreadable_transformation_matrix"] += 1
            elif name == "referencePoint":
                pos = next((p for p in child.iter() if local(p) in ("pos", "coordinates")), None)
                if pos is not None:
                    try:
                        v = np.array((pos.text or "").replace(",", " ").split(), np.float64)
                        ref = np.r_[v, np.zeros(3)][:3] if len(v) in (2, 3) else None
                    except ValueError:
                        ref = None
            elif name in ("relativeGMLGeometry", "relativeGeometry"):
                rel = child
            elif name == "libraryObject":
                veg.implicit = "library"
        if ref is None:
            problems["implicit_geometry_without_reference_point"] += 1
            return
        veg.ref, veg.matrix = ref, matrix
        if rel is None:
            veg.implicit = veg.implicit or "unresolved"
            return
        href = rel.get(XLINK_HREF)
        if href is not None and len(rel) == 0:
            target = index.get(href)
            verts = _vertices(target, index, problems) if target is not None else \
                self.templates.get(href.lstrip("#"))
            veg.implicit = "template"
        else:
            verts = _vertices(rel, index, problems)
            veg.implicit = "inline"
            for g in rel:
                if isinstance(g.tag, str) and gml_id(g) is not None and verts is not None:
                    self.templates[gml_id(g)] = verts
        if verts is None or not len(verts):
            problems["unresolved_implicit_geometry"] += 1
            veg.implicit = "unresolved"
            return
        local_xyz = np.column_stack([verts, np.ones(len(verts))]) @ matrix.T
        if np.linalg.norm(ref) > 0 and np.allclose(matrix[:3, 3], ref, rtol=0, atol=1e-3):
            # a writer that put the position both in the matrix and in the reference point:
            # placed once (the standard adds the reference point to the transformed geometry)
            local_xyz[:, :3] -= ref
            problems["implicit_position_in_matrix_and_reference_point"] += 1
        veg.offsets = local_xyz[:, :3]


#: vegetation attributes read as numbers (m)
_VEG_NUMBERS = ("height", "crownDiameter", "trunkDiameter", "averageHeight")


def _vertices(el, index, problems: Counter) -> np.ndarray | None:
    """Every polygon vertex under *el* (xlinks within the feature followed), (n, 3)."""
    out = []
    if local(el) in _POLYGONAL:
        polys = [(el, False)]
    else:
        polys = list(_polygons(el, index, problems))
    for poly, _ in polys:
        rings, _ = _rings(poly)
        if rings is not None:
            out += rings
    return np.concatenate(out) if out else None


class _LazyIndex:
    """``gml:id`` -> element within one feature, built on the first xlink."""

    def __init__(self, root):
        self.root = root
        self._map = None

    def get(self, ref: str):
        if self._map is None:
            self._map = {}
            for e in self.root.iter():
                i = gml_id(e) if isinstance(e.tag, str) else None
                if i is not None:
                    self._map[i] = e
        return self._map.get(ref.lstrip("#"))


def _best_lod(surf):
    """The geometry property of a thematic surface: lod2 first, else the lowest other LoD."""
    found = {}
    for child in surf:
        m = _LOD_SURF.match(local(child))
        if m:
            found.setdefault(int(m.group(1)), child)
    for lod in (2, 3, 4, 1, 0):
        if lod in found:
            return found[lod]
    return None


def _lod_of(geom) -> int:
    """The LoD digit of a geometry property (``lod1Solid`` -> 1)."""
    return int(_LOD_SURF.match(local(geom)).group(1))


def _fallback_geometry(obj):
    """Solid / multi-surface of a building object without thematic surfaces."""
    by_name = {}
    for child in obj:
        by_name.setdefault(local(child), child)
    for name in ("lod2Solid", "lod2MultiSurface", "lod3Solid", "lod3MultiSurface",
                 "lod1Solid", "lod1MultiSurface"):
        if name in by_name:
            return by_name[name]
    return None


def _polygons(el, index: _LazyIndex, problems: Counter, skip_implicit: bool = False,
              reverse: bool = False, depth: int = 0):
    """Yield (polygon element, reversed) under *el*, following xlinks within the feature."""
    if depth > 50:
        problems["xlink_cycle"] += 1
        return
    for child in el:
        if not isinstance(child.tag, str):
            continue
        name = local(child)
        if name in _POLYGONAL:
            yield child, reverse
            continue
        if skip_implicit and "ImplicitRepresentation" in name:
            problems["implicit_geometry_ignored"] += 1
            continue
        if name == "Envelope":
            continue
        href = child.get(XLINK_HREF)
        if href is not None and len(child) == 0:
            target = index.get(href)
            if target is None:
                problems["unresolved_xlink"] += 1
                continue
            if local(target) in _POLYGONAL:
                yield target, reverse
            else:
                yield from _polygons(target, index, problems, skip_implicit, reverse, depth + 1)
            continue
        flip = reverse
        if name == "OrientableSurface" and child.get("orientation") == "-":
            flip = not reverse
        yield from _polygons(child, index, problems, skip_implicit, flip, depth + 1)


def _srs_dimension(el) -> int | None:
    for _ in range(8):
        if el is None:
            return None
        d = el.get("srsDimension")
        if d is not None:
            return int(d)
        el = el.getparent()
    return None


def _ring_coords(ring) -> np.ndarray | None:
    """(n, 3) coordinates of a LinearRing (posList, pos sequence or GML 2 coordinates)."""
    values = None
    dim = None
    pos_texts = []
    for child in ring:
        name = local(child)
        if name == "posList":
            values = child.text.split() if child.text else []
            dim = _srs_dimension(child)
        elif name == "pos":
            parts = child.text.split() if child.text else []
            pos_texts.append(parts)
            if dim is None:
                dim = _srs_dimension(child) or len(parts)
        elif name == "coordinates":
            values = (child.text or "").replace(",", " ").split()
            dim = 3
    if pos_texts:
        if any(len(p) != len(pos_texts[0]) for p in pos_texts):
            return None
        values = [v for p in pos_texts for v in p]
    if not values:
        return None
    arr = np.array(values, dtype=np.float64)
    if dim is None:
        dim = 3 if len(arr) % 3 == 0 else 2
    if dim not in (2, 3) or len(arr) % dim:
        return None
    arr = arr.reshape(-1, dim)
    if dim == 2:
        arr = np.column_stack([arr, np.zeros(len(arr))])
    return arr


def _rings(poly) -> tuple[list | None, str | None]:
    """(exterior and interior rings of a polygon element as (n, 3) arrays, None) or
    (None, the reason it cannot be read)."""
    rings = []
    for child in poly:
        name = local(child)
        if name in ("exterior", "outerBoundaryIs", "interior", "innerBoundaryIs"):
            ring_el = next((r for r in child if local(r) == "LinearRing"), None)
            if ring_el is None:
                return None, "unsupported_ring"
            try:
                coords = _ring_coords(ring_el)
            except ValueError:
                coords = None
            if coords is None:
                return None, "unreadable_coordinates"
            if name in ("exterior", "outerBoundaryIs"):
                rings.insert(0, coords)
            else:
                rings.append(coords)
    if not rings:
        return None, "polygon_without_exterior"
    return rings, None


@contextmanager
def open_sources(path: Path):
    """Yield (label, binary file object) for a .gml/.xml, .gml.gz or every GML in a .zip."""
    path = Path(path)
    if not path.exists():
        raise InputError(f"{path}: file not found")
    if path.is_dir():
        raise InputError(f"{path}: is a directory, not a CityGML file")
    if path.stat().st_size == 0:
        raise InputError(f"{path}: empty file")
    if path.suffix.lower() == ".zip":
        try:
            zf = zipfile.ZipFile(path)
        except (zipfile.BadZipFile, OSError, EOFError) as exc:
            raise InputError(f"{path}: corrupt or truncated zip file ({exc})") from None
        with zf:
            names = [n for n in zf.namelist()
                     if n.lower().endswith((".gml", ".xml", ".citygml")) and not n.endswith("/")]
            if not names:
                raise InputError(f"{path}: zip holds no .gml or .xml file")
            yield [(f"{path}!{n}", (lambda n=n: zf.open(n))) for n in names]
    elif path.suffix.lower() == ".gz":
        yield [(str(path), lambda: _readable(path, gzip.open))]
    else:
        yield [(str(path), lambda: _readable(path, open))]


def _readable(path: Path, opener):
    try:
        return opener(path, "rb")
    except OSError as exc:
        raise InputError(f"{path}: cannot be read ({exc.strerror or exc})") from None
