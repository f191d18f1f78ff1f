"""The city's trees: CityGML vegetation objects and tree tables, as crowns.

Every tree becomes a row of a :class:`vipvflow.models.trees.TreeTable`: its trunk's base on
the ground, height, crown diameter, crown base, leaf type and own leaf-off months, whatever
the source says:

* ``SolitaryVegetationObject`` (CityGML 1.0-3.0): ``height`` and ``crownDiameter`` where it
  has them; its geometry (explicit polygons of any LoD, or an implicit geometry placed by its
  transformation matrix at its reference point) gives what the attributes leave out: the
  trunk's position (the reference point, else the middle of the vertices), the ground (the
  reference point's height, else the lowest vertex), the height (the highest vertex), the
  crown diameter (as tree surveys record it: the mean of the crown's two widths along the
  principal axes of its horizontal outline) and the crown base (the lowest vertex at least
  half the crown's radius from the trunk).  A generic attribute ``crown_base`` (``crownBase``, ``h_trunk``, ``kronenansatz``)
  gives the crown base.
* ``PlantCover`` (hedges, shrubs, woods): its outline filled with crowns from the ground to
  ``averageHeight`` (else the geometry's top), one every ``max(2, min(height, 10))`` m.
* A tree table (``inputs.trees``): CSV or GeoParquet points, one tree per row, columns
  ``height`` and ``crown_diameter`` (m; the names of common tree cadastres are read too,
  :data:`ALIASES`), optional ``crown_base`` (m), ``leaf_type`` (deciduous / evergreen),
  ``genus`` or ``species``, ``leaf_off_months`` (``11-4`` or ``11,12,1,2,3,4``), ``z`` (the
  ground, m); positions from the GeoParquet's geometry (its CRS), from ``lon``/``lat``
  columns (WGS84) or ``x``/``y`` in ``inputs.trees_crs`` (default: the city's CRS).

Without a crown base the tree's is ``city.trees.crown_base_fraction`` of its height; without
a ground height the city model's (its relief, else its buildings' ground surfaces within
100 m); a tree without either is skipped.  The leaf type comes from the data (``leaf_type``,
a CityGML ``class`` or ``function`` naming it) or the genus (:data:`GENERA`), else it is
unknown (``irradiance.trees.unknown_leaf_type`` decides at run time).  Rows and objects that
cannot be a tree (no position, height or crown diameter, a crown base above the top, sizes
beyond any tree's) are skipped and counted by reason, the first lines named.
"""
from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ...errors import InputError
from ...models.tree_table import LEAF_TYPES, TREE_SOURCES, TreeTable, month_mask
from .crs import inside, transform_xyz

#: genera of urban trees by leaf type (lower case; the first word of a botanical name)
GENERA = {
    "deciduous": ("acer aesculus ailanthus alnus betula carpinus castanea catalpa celtis "
                  "cercis corylus crataegus fagus fraxinus ginkgo gleditsia juglans larix "
                  "liquidambar liriodendron malus metasequoia morus ostrya paulownia platanus "
                  "populus prunus pterocarya pyrus quercus robinia salix sophora sorbus "
                  "styphnolobium tilia ulmus zelkova amelanchier koelreuteria taxodium").split(),
    "evergreen": ("abies cedrus chamaecyparis cupressus ilex juniperus picea pinus "
                  "pseudotsuga sequoia sequoiadendron taxus thuja tsuga olea eucalyptus "
                  "quercus_ilex").split(),
}
_GENUS = {g: i for i, t in enumerate(LEAF_TYPES) for g in GENERA[t]}
_WORDS = {"deciduous": 0, "broadleaf": 0, "broad-leaved": 0, "laubbaum": 0, "laub": 0,
          "evergreen": 1, "conifer": 1, "coniferous": 1, "nadelbaum": 1, "nadel": 1}

#: column names a tree table's fields are read from (lower case, the first present wins)
ALIASES = {
    "height": ("height", "height_m", "tree_height", "baumhoehe", "hoehe"),
    "crown_diameter": ("crown_diameter", "crown_diameter_m", "crowndiameter", "crown_d",
                       "kronedurch", "kronendurchmesser"),
    "crown_base": ("crown_base", "crown_base_m", "crown_base_height", "crownbase", "kronenansatz"),
    "leaf_type": ("leaf_type", "leaftype"),
    "genus": ("genus", "species", "gattung", "art_bot", "botanical_name"),
    "leaf_off_months": ("leaf_off_months",),
    "z": ("z", "ground_z", "elevation", "ground_m"),
    "id": ("tree_id", "id", "gisid", "baumid"),
    "lon": ("lon", "longitude", "lng"),
    "lat": ("lat", "latitude"),
    "x": ("x", "easting"),
    "y": ("y", "northing"),
}
#: generic attributes of a CityGML tree naming its crown base (m above the ground) or leaf type
_CROWN_BASE_ATTRIBUTES = ("crown_base", "crownBase", "crown_base_height", "h_trunk", "kronenansatz")
_LEAF_ATTRIBUTES = ("leaf_type", "leafType", "laubart")
#: beyond any tree: a crown wider or a tree higher than this (m) is a unit or data error
MAX_CROWN_M, MAX_HEIGHT_M = 60.0, 150.0


def leaf_type_of(*texts) -> int:
    """0 deciduous, 1 evergreen, -1 unknown, from texts that may name it: a leaf type, a
    class, a genus or a botanical name (its first word, :data:`GENERA`)."""
    for text in texts:
        if text is None or (isinstance(text, float) and not np.isfinite(text)):
            continue
        t = str(text).strip().lower()
        if not t:
            continue
        for word, code in _WORDS.items():
            if word in t:
                return code
        first = re.split(r"[\s_(,.'\"]+", t)[0]
        if " ".join(t.split()[:2]) == "quercus ilex":
            return 1
        if first in _GENUS:
            return _GENUS[first]
    return -1


def parse_months(text) -> int:
    """A leaf-off month list (``11-4``, ``11,12,1``, ``Nov-Apr`` not read) as a 12-bit mask;
    -1 when empty (the default calendar); ValueError when it is not months."""
    if text is None or (isinstance(text, float) and not np.isfinite(text)):
        return -1
    t = str(text).strip()
    if not t:
        return -1
    months = []
    for part in re.split(r"[,;\s]+", t):
        if not part:
            continue
        if "-" in part:
            a, b = (int(v) for v in part.split("-", 1))
            if not (1 <= a <= 12 and 1 <= b <= 12):
                raise ValueError(part)
            months += [((a - 1 + k) % 12) + 1 for k in range((b - a) % 12 + 1)]
        else:
            m = int(part)
            if not 1 <= m <= 12:
                raise ValueError(part)
            months.append(m)
    return month_mask(months)


@dataclass
class TreeReport:
    """What the trees of an ingest came to (``ingest_report.json``'s ``trees``)."""

    kept: int = 0
    by_source: dict = field(default_factory=dict)
    by_leaf_type: dict = field(default_factory=dict)
    crown_base_from: dict = field(default_factory=dict)     # attribute, geometry, default
    ground_from: dict = field(default_factory=dict)         # data, city_model
    skipped: dict = field(default_factory=dict)             # per reason
    skipped_examples: dict = field(default_factory=dict)    # per reason: the first few places
    implicit_geometry: dict = field(default_factory=dict)   # inline, template, library, unresolved
    plant_covers: int = 0
    tables: list = field(default_factory=list)

    def line(self) -> str:
        """One line for the console."""
        if not self.kept and not self.skipped:
            return "no trees"
        src = ", ".join(f"{k} {v}" for k, v in sorted(self.by_source.items()))
        leaf = ", ".join(f"{k} {v}" for k, v in sorted(self.by_leaf_type.items()))
        skip = ", ".join(f"{k} {v}" for k, v in sorted(self.skipped.items())) or "none"
        return f"{self.kept:,} trees ({src}; {leaf}), skipped {sum(self.skipped.values())} ({skip})"


class TreeCollector:
    """Collects trees (one row each, the city's CRS) from vegetation objects and tables.

    Parameters
    ----------
    crown_base_fraction : float, the crown base of a tree whose data gives none, as a share
        of its height
    """

    def __init__(self, crown_base_fraction: float = 0.35):
        self.fraction = float(crown_base_fraction)
        self.rows: dict[str, list] = {k: [] for k in ("x", "y", "z", "height", "crown_diameter",
                                                      "crown_base", "leaf_type", "leaf_off",
                                                      "source", "tree_id")}
        self.report = TreeReport()
        self._skipped = Counter()
        self._examples: dict[str, list] = {}
        self._base_from = Counter()
        self._implicit = Counter()

    # ------------------------------------------------------------------ rows
    def _skip(self, reason: str, where: str) -> None:
        self._skipped[reason] += 1
        ex = self._examples.setdefault(reason, [])
        if len(ex) < 5:
            ex.append(where)

    def _add(self, x, y, z, height, crown, base, leaf, leaf_off, source, tid, where,
             base_from: str = "data") -> bool:
        """One tree, checked; *base* None: the default fraction (*base_from*: where a given
        one came from)."""
        if not (np.isfinite(x) and np.isfinite(y)):
            self._skip("no_position", where)
            return False
        if height is None or not np.isfinite(height) or height <= 0:
            self._skip("no_height", where)
            return False
        if crown is None or not np.isfinite(crown) or crown <= 0:
            self._skip("no_crown_diameter", where)
            return False
        if height > MAX_HEIGHT_M or crown > MAX_CROWN_M:
            self._skip("size_beyond_a_tree", where)
            return False
        if base is None or not np.isfinite(base):
            base, how = self.fraction * height, "default"
        else:
            how = base_from
        if base < 0 or base >= height:
            self._skip("crown_base_not_below_top", where)
            return False
        self._base_from[how] += 1
        for k, v in (("x", x), ("y", y), ("z", z), ("height", height), ("crown_diameter", crown),
                     ("crown_base", base), ("leaf_type", leaf), ("leaf_off", leaf_off),
                     ("source", source), ("tree_id", tid)):
            self.rows[k].append(v)
        return True

    # ------------------------------------------------------------------ CityGML
    def add_vegetation(self, feature, src, target: str, label: str) -> None:
        """A CityGML vegetation object (:class:`vipvflow.inputs.city.citygml.Feature` with
        its ``vegetation``), its coordinates read by *src* (the file's
        :class:`~vipvflow.inputs.city.crs.SourceCRS`) into *target*."""
        veg = feature.vegetation
        where = f"{label}: {veg.cls} {feature.feature_id}"
        if veg.implicit:
            self._implicit[veg.implicit] += 1
        ref = None if veg.ref is None else self._to_target(veg.ref[None], src, target)
        verts = None
        if veg.vertices is not None:
            verts = self._to_target(veg.vertices, src, target)
        if veg.offsets is not None and ref is not None and np.isfinite(ref).all():
            off = src.read(veg.offsets) if src is not None else veg.offsets
            placed = ref + off
            verts = placed if verts is None else np.concatenate([verts, placed])
        if verts is not None:
            verts = verts[np.isfinite(verts).all(1)]
            if not len(verts):
                verts = None
        att = veg.attributes
        if veg.cls == "PlantCover":
            self._plant_cover(feature, veg, verts, att, where)
            return
        leaf = leaf_type_of(*(att.get(k) for k in _LEAF_ATTRIBUTES), att.get("class"),
                            att.get("function"), att.get("species"))
        height = _num(att.get("height"))
        crown = _num(att.get("crownDiameter"))
        base = next((_num(att[k]) for k in _CROWN_BASE_ATTRIBUTES if k in att), None)
        if ref is not None and np.isfinite(ref).all():
            x, y, z = ref[0]
        elif verts is not None:
            x, y = (verts[:, 0].min() + verts[:, 0].max()) / 2, (verts[:, 1].min() + verts[:, 1].max()) / 2
            z = verts[:, 2].min()
        else:
            self._skip("no_position", where)
            return
        base_from = "data"
        if verts is not None:
            g_height, g_crown, g_base = crown_of(verts, x, y, z)
            if height is None:
                height = g_height
            if crown is None:
                crown = g_crown
            if base is None and g_base is not None:
                base, base_from = g_base, "geometry"
        self._add(x, y, z, height, crown, base, leaf, -1, TREE_SOURCES.index("citygml"),
                  feature.feature_id, where, base_from)

    def _plant_cover(self, feature, veg, verts, att, where) -> None:
        """A plant cover's outline filled with crowns from the ground to its height."""
        import shapely

        self.report.plant_covers += 1
        if verts is None:
            self._skip("plant_cover_without_geometry", where)
            return
        z0 = float(verts[:, 2].min())
        height = _num(att.get("averageHeight"))
        if height is None:
            height = float(verts[:, 2].max()) - z0
        if not height > 0.5:
            self._skip("plant_cover_lower_than_half_a_metre", where)
            return
        polys = [shapely.Polygon(p[:, :2]) for p in feature.vegetation.polygons] if veg.polygons else []
        polys = [p.buffer(0) for p in polys if p.is_valid or p.buffer(0).area > 0]
        outline = shapely.union_all([p for p in polys if p.area > 0.01]) if polys else None
        if outline is None or outline.is_empty:
            outline = shapely.MultiPoint(verts[:, :2]).convex_hull
        if outline.area < 1.0:
            self._skip("plant_cover_without_area", where)
            return
        step = float(np.clip(height, 2.0, 10.0))
        while outline.area / step ** 2 > 20_000:
            step *= 1.5
        x0, y0, x1, y1 = outline.bounds
        gx, gy = np.meshgrid(np.arange(x0 + step / 2, x1, step), np.arange(y0 + step / 2, y1, step))
        pts = shapely.points(gx.ravel(), gy.ravel())
        keep = shapely.contains(outline, pts)
        if not keep.any():
            c = outline.representative_point()
            gx, gy, keep = np.array([c.x]), np.array([c.y]), np.array([True])
        leaf = leaf_type_of(*(att.get(k) for k in _LEAF_ATTRIBUTES), att.get("class"),
                            att.get("function"), att.get("species"))
        for i, (x, y) in enumerate(zip(gx.ravel()[keep], gy.ravel()[keep])):
            self._add(float(x), float(y), z0, height, 1.2 * step, 0.0, leaf, -1,
                      TREE_SOURCES.index("plant_cover"), f"{feature.feature_id}_{i}", where)

    @staticmethod
    def _to_target(xyz, src, target):
        xyz = np.asarray(xyz, np.float64).reshape(-1, 3)
        if src is None:
            return xyz
        out = src.read(xyz)
        ok = np.isfinite(out).all(1) & inside(out, src.bounds)
        if src.crs != target:
            with np.errstate(all="ignore"):
                out = transform_xyz(np.where(ok[:, None], out, 0.0), src.crs, target)
        out = np.where(ok[:, None], out, np.nan)
        return out

    # ------------------------------------------------------------------ tables
    def add_table(self, path, target: str, table_crs: str | None = None) -> None:
        """A tree table (CSV or GeoParquet) into the city's CRS *target*."""
        path = Path(path)
        frame, xy_crs, line0 = read_table(path, target, table_crs)
        self.report.tables.append(str(path))
        cols = {c.lower(): c for c in frame.columns}
        pick = {k: next((cols[a] for a in names if a in cols), None) for k, names in ALIASES.items()}
        missing = [k for k in ("height", "crown_diameter") if pick[k] is None]
        if missing:
            raise InputError(f"{path}: no {' or '.join(missing)} column (found: "
                             f"{', '.join(map(str, frame.columns[:20]))}); columns read: "
                             + "; ".join(f"{k}: {', '.join(ALIASES[k])}" for k in missing))
        x, y = frame["__x"].to_numpy(np.float64), frame["__y"].to_numpy(np.float64)
        z = frame["__z"].to_numpy(np.float64) if "__z" in frame else np.full(len(frame), np.nan)
        if pick["z"] is not None:
            z = _numbers(frame[pick["z"]])
        height, crown = _numbers(frame[pick["height"]]), _numbers(frame[pick["crown_diameter"]])
        base = _numbers(frame[pick["crown_base"]]) if pick["crown_base"] else np.full(len(frame), np.nan)
        texts = [frame[pick[k]].astype(object).to_numpy() if pick[k] else None
                 for k in ("leaf_type", "genus")]
        months = frame[pick["leaf_off_months"]].to_numpy() if pick["leaf_off_months"] else None
        ids = (frame[pick["id"]].astype(str).to_numpy() if pick["id"]
               else np.array([f"{path.stem}_{i}" for i in range(len(frame))]))
        for i in range(len(frame)):
            where = f"{path}: line {i + line0}" if line0 else f"{path}: row {i}"
            try:
                off = parse_months(months[i]) if months is not None else -1
            except ValueError:
                self._skip("unreadable_leaf_off_months", where)
                continue
            leaf = leaf_type_of(*(t[i] for t in texts if t is not None))
            self._add(x[i], y[i], z[i], height[i], crown[i], None if np.isnan(base[i]) else base[i],
                      leaf, off, TREE_SOURCES.index("table"), ids[i], where)

    # ------------------------------------------------------------------ result
    def finish(self, terrain, latitude: float) -> TreeTable:
        """The collected trees, with the ground from *terrain* (a
        :class:`~vipvflow.inputs.city.terrain.TerrainModel`, or None) where they have none;
        the report filled in."""
        r = self.rows
        table = TreeTable(**{k: np.asarray(v) if v else np.zeros(0, TreeTable._DTYPES[k]
                                                                  if TreeTable._DTYPES[k] is not str else "U1")
                             for k, v in r.items()}, latitude=latitude)
        ground = Counter()
        no_z = ~np.isfinite(table.z)
        if no_z.any():
            gz = terrain.elevation(table.x[no_z], table.y[no_z]) if terrain is not None \
                else np.full(int(no_z.sum()), np.nan)
            table.z[no_z] = gz
            ground["city_model"] = int(np.isfinite(gz).sum())
            bad = np.flatnonzero(no_z)[~np.isfinite(gz)]
            for i in bad:
                self._skip("no_ground_height", f"tree {table.tree_id[i]}")
        ground["data"] = int((~no_z).sum())
        table = table.take(np.flatnonzero(np.isfinite(table.z)))
        rep = self.report
        rep.kept = len(table)
        rep.by_source = {TREE_SOURCES[k]: int(v) for k, v in zip(*np.unique(table.source, return_counts=True))}
        names = np.array(list(LEAF_TYPES) + ["unknown"])
        rep.by_leaf_type = {str(names[k]): int(v) for k, v in zip(*np.unique(table.leaf_type, return_counts=True))}
        rep.crown_base_from = {k: int(v) for k, v in self._base_from.items() if v}
        rep.ground_from = {k: v for k, v in ground.items() if v}
        rep.skipped = dict(self._skipped)
        rep.skipped_examples = {k: v for k, v in self._examples.items()}
        rep.implicit_geometry = dict(self._implicit)
        return table


def crown_of(verts: np.ndarray, x: float, y: float, z: float):
    """Height, crown diameter and crown base (m; the base None when the geometry cannot
    tell) of a tree's vertices (n, 3) around its trunk at (x, y) on the ground z: the top
    above z; the crown base the lowest vertex at least half the crown's radius from the
    trunk; the diameter, as tree surveys record it, the mean of the crown's two widths
    across each other: its extents along the principal axes of the convex outline of the
    vertices from the crown base up (an elliptic crown of axes a and b: (a + b) / 2)."""
    import shapely

    v = np.asarray(verts, np.float64)
    height = float(v[:, 2].max() - z)
    r = np.hypot(v[:, 0] - x, v[:, 1] - y)
    R = float(r.max())
    if not R > 0:
        return height, None, None
    wide = r >= 0.5 * R
    base = float(v[wide, 2].min() - z)
    crown = v[v[:, 2] >= z + base - 1e-6]
    hull = shapely.MultiPoint(crown[:, :2]).convex_hull
    if hull.area > 0:
        xy = np.asarray(hull.exterior.coords)[:-1]
        xy = xy - xy.mean(0)
        _, axes = np.linalg.eigh(xy.T @ xy)
        proj = xy @ axes
        diameter = float((proj.max(0) - proj.min(0)).mean())
    else:
        diameter = 2.0 * R
    return height, diameter, (base if base > 0.05 * height else None)


def _num(v):
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if np.isfinite(f) else None


def _numbers(col) -> np.ndarray:
    import pandas as pd

    return pd.to_numeric(col, errors="coerce").to_numpy(np.float64)


def read_table(path: Path, target: str, table_crs: str | None = None):
    """A tree table as a DataFrame with its positions in the city's CRS *target* (``__x``,
    ``__y``, and ``__z`` from 3-D points), the CRS its x/y came from and the file line of
    its first row (CSV; 0 for Parquet).  One line naming the file for what cannot be read."""
    import pandas as pd

    if not path.exists():
        raise InputError(f"{path}: file not found")
    if path.stat().st_size == 0:
        raise InputError(f"{path}: empty file")
    suffix = path.suffix.lower()
    if suffix in (".parquet", ".geoparquet"):
        import geopandas as gpd
        import pyarrow.parquet as pq

        try:
            meta = pq.read_schema(path).metadata or {}
        except Exception as exc:                                # noqa: BLE001 - any unreadable file
            raise InputError(f"{path}: not a Parquet file ({exc})") from None
        if b"geo" in meta:
            try:
                gdf = gpd.read_parquet(path)
            except Exception as exc:                            # noqa: BLE001
                raise InputError(f"{path}: unreadable GeoParquet ({exc})") from None
            if gdf.crs is None:
                raise InputError(f"{path}: the GeoParquet names no CRS")
            geom = gdf.geometry
            if not geom.geom_type.dropna().isin(["Point"]).all():
                raise InputError(f"{path}: the geometry must be points (trunk positions), "
                                 f"found {', '.join(sorted(set(geom.geom_type.dropna())))}")
            frame = pd.DataFrame(gdf.drop(columns=gdf.geometry.name))
            xy = np.column_stack([geom.x.to_numpy(), geom.y.to_numpy(),
                                  np.where(geom.has_z, geom.z if geom.has_z.any() else np.nan, np.nan)])
            crs = f"EPSG:{gdf.crs.to_epsg()}" if gdf.crs.to_epsg() else gdf.crs.to_string()
            return _place(frame, xy, crs, target, has_z=bool(geom.has_z.any())), crs, 0
        frame = pd.read_parquet(path)
        line0 = 0
    elif suffix in (".csv", ".txt", ".tsv"):
        try:
            frame = pd.read_csv(path, sep=None, engine="python", dtype=str, keep_default_na=False)
        except (pd.errors.ParserError, UnicodeDecodeError, ValueError) as exc:
            raise InputError(f"{path}: unreadable CSV ({exc})") from None
        line0 = 2
    else:
        raise InputError(f"{path}: a tree table is a .csv or a (Geo)Parquet file")
    cols = {c.lower(): c for c in frame.columns}
    lon = next((cols[a] for a in ALIASES["lon"] if a in cols), None)
    lat = next((cols[a] for a in ALIASES["lat"] if a in cols), None)
    x = next((cols[a] for a in ALIASES["x"] if a in cols), None)
    y = next((cols[a] for a in ALIASES["y"] if a in cols), None)
    if lon and lat:
        xy = np.column_stack([_numbers(frame[lon]), _numbers(frame[lat]), np.full(len(frame), np.nan)])
        return _place(frame, xy, "EPSG:4326", target), "EPSG:4326", line0
    if x and y:
        crs = table_crs or target
        xy = np.column_stack([_numbers(frame[x]), _numbers(frame[y]), np.full(len(frame), np.nan)])
        return _place(frame, xy, crs, target), crs, line0
    raise InputError(f"{path}: no tree positions: columns lon/lat (WGS84), x/y (in "
                     f"inputs.trees_crs, else the city's CRS) or a GeoParquet point geometry "
                     f"(found: {', '.join(map(str, frame.columns[:20]))})")


def _place(frame, xyz: np.ndarray, crs: str, target: str, has_z: bool = False):
    """*frame* with ``__x, __y`` (and ``__z``) in *target*."""
    from .crs import horizontal, normalise_crs

    src = horizontal(normalise_crs(crs))
    out = xyz.copy()
    ok = np.isfinite(out[:, :2]).all(1)
    if src != target:
        z = np.where(np.isfinite(out[:, 2]), out[:, 2], 0.0)
        with np.errstate(all="ignore"):
            moved = transform_xyz(np.column_stack([np.where(ok[:, None], out[:, :2], 0.0), z]), src, target)
        out[:, :2] = np.where(ok[:, None], moved[:, :2], np.nan)
    frame = frame.copy()
    frame["__x"], frame["__y"] = out[:, 0], out[:, 1]
    if has_z:
        frame["__z"] = out[:, 2]
    return frame
