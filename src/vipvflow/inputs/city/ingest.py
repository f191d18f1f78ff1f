"""City ingest: CityGML files -> tiled semantic surfaces (GeoParquet) and tile meshes.

Two passes with bounded memory:

1. Stream every file (:class:`~vipvflow.inputs.city.citygml.CityGMLReader`), clean and
   triangulate each polygon (:mod:`~vipvflow.inputs.city.geometry`), and keep the results in
   compact numpy chunks.  A full chunk is routed to spool files, one per tile it touches:
   the tile of each surface's area centroid ("own") and every tile whose buffer-expanded
   bounds its bounding box overlaps ("buffer").
2. For each tile, read its spool files and write ``city/surfaces/tile=<T>/part-0.parquet``
   (own surfaces) and ``city/meshes/<T>.npz`` (own + buffer surfaces), both atomically.

Peak memory is set by the chunk size and the largest tile, not by the size of the city.

The data dir's ``city/`` changes as a whole: everything is written into
``<data_dir>/.city-ingest-<pid>/`` and swapped in only when the ingest succeeded (an input
error, Ctrl-C or a kill leaves the previous ``city/`` as it was).  Folders left by a killed
ingest (``.city-ingest-<pid>``, the older ``city/.ingest-spool-<pid>``) are removed by the
next ingest once their process is gone.

Coordinates: each file's axis order and CRS are settled on its first building
(:class:`~vipvflow.inputs.city.crs.SourceCRS`); without ``--crs`` a projected file keeps its CRS and a
geographic one (PLATEAU's EPSG:6697) is put into its local UTM zone.  Polygons with a
non-finite coordinate, a vertex outside the CRS's area of use or an absurd area are skipped and
counted by reason.
"""
from __future__ import annotations

import json
import logging
import os
import shutil
import time
from collections import Counter
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ...config import CityCfg
from ...errors import InputError
from ...store import CityDir, DataDir, atomic_path, pid_alive, remove_stale, staging_dir, swap_dir, write_json, write_npz
from ...models.mesh import SURFACE_CODE, SURFACE_TYPES, TileMesh
from ...progress import Progress, citygml_bytes, file_position
from ..tiles import tile_bounds, tile_index, tile_name
from .citygml import CityGMLReader, open_sources
from .coverage import grown_footprints, tile_footprints, write_coverage
from .crs import (SourceCRS, horizontal, inside, is_projected, local_utm, normalise_crs,
                  parse_srs_name, transform_xyz)
from .geometry import Skip, classify_normal, prepare_polygon

log = logging.getLogger(__name__)

CHUNK_SURFACES = 20_000

#: a building polygon larger than this (m2, 2 km x 2 km) is a broken coordinate, not a roof
MAX_SURFACE_AREA_M2 = 4e6
#: reasons of skipped polygons that come from the coordinates rather than the shape
BAD_COORDINATES = ("non_finite_coordinates", "outside_crs_area", "absurd_area")


@dataclass
class IngestReport:
    """What a city ingest read, wrote and skipped."""

    files: list = field(default_factory=list)
    crs: str | None = None
    crs_source: str = ""                                   # why this CRS (file, --crs, local UTM zone)
    file_crs: dict = field(default_factory=dict)
    axis_order: dict = field(default_factory=dict)         # per file: how coordinates were read
    buildings: int = 0
    buildings_by_lod: dict = field(default_factory=dict)   # LoD the geometry was taken from
    building_parts: int = 0
    terrain_features: int = 0
    vegetation_features: int = 0
    trees: dict = field(default_factory=dict)              # the crowns kept (inputs/city/trees.py)
    surfaces: dict = field(default_factory=dict)          # polygons written, per type
    thematic_surfaces: dict = field(default_factory=dict)  # thematic elements read, per type
    area_m2: dict = field(default_factory=dict)            # per type
    skipped: dict = field(default_factory=dict)            # polygons, per reason
    skipped_by_type: dict = field(default_factory=dict)    # polygons, per thematic type
    repaired: dict = field(default_factory=dict)           # polygons, per repair
    problems: dict = field(default_factory=dict)           # unreadable parts, per reason
    ignored_features: dict = field(default_factory=dict)   # city objects not read, per class
    tiles: int = 0
    coverage: dict = field(default_factory=dict)           # the area the model covers (coverage.py)
    triangles: int = 0
    terrain_triangles: int = 0
    degenerate_triangles: int = 0                          # in the tile meshes, found by trimesh (kept)
    elapsed_s: float = 0.0
    report_path: str = ""

    @property
    def n_surfaces(self) -> int:
        return int(sum(self.surfaces.values()))

    @property
    def n_skipped(self) -> int:
        return int(sum(self.skipped.values()))

    def summary(self) -> str:
        """One line: files, CRS, buildings by LoD, surfaces per type, skips, tiles, speed."""
        types = ", ".join(f"{k} {v}" for k, v in sorted(self.surfaces.items()))
        skips = ", ".join(f"{k} {v}" for k, v in sorted(self.skipped.items())) or "none"
        lods = ", ".join(f"{k} {v}" for k, v in sorted(self.buildings_by_lod.items()))
        rate = self.n_surfaces / self.elapsed_s if self.elapsed_s > 0 else 0.0
        crs = f"{self.crs} ({self.crs_source})" if self.crs_source else f"{self.crs}"
        problems = ""
        if self.problems:
            problems = ", other problems " + ", ".join(
                f"{k} {v}" for k, v in sorted(self.problems.items()))
        trees = ""
        if self.trees.get("kept") or self.trees.get("skipped"):
            from dataclasses import fields as _fields

            from .trees import TreeReport

            names = {f.name for f in _fields(TreeReport)}
            trees = ", " + TreeReport(**{k: v for k, v in self.trees.items() if k in names}).line()
        return (f"{len(self.files)} file(s) in {crs}: {self.buildings} buildings ({lods or 'none'}), "
                f"{self.n_surfaces} surfaces ({types}), skipped {self.n_skipped} ({skips}){problems}"
                f"{trees}, {self.tiles} tiles, {self.triangles} mesh triangles, "
                f"{self.elapsed_s:.1f} s ({rate:,.0f} surfaces/s)")

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2, sort_keys=True)


def _offsets(sizes: np.ndarray) -> np.ndarray:
    out = np.zeros(len(sizes) + 1, dtype=np.int64)
    np.cumsum(sizes, out=out[1:])
    return out


def ragged_take(values: np.ndarray, offsets: np.ndarray, idx: np.ndarray):
    """Rows of the ragged array (values, offsets) selected by *idx*: (values, sizes)."""
    starts = offsets[:-1][idx]
    sizes = offsets[1:][idx] - starts
    total = int(sizes.sum())
    shift = np.repeat(starts - _offsets(sizes)[:-1], sizes)
    return values[np.arange(total, dtype=np.int64) + shift], sizes


class _Chunk:
    """Compact arrays of prepared surfaces (ragged parts with their sizes)."""

    FIELDS = ("V", "vsz", "T", "tsz", "R", "rsz", "normal", "area", "code", "albedo",
              "centroid", "sid", "bid", "cls")

    def __init__(self, **arrays):
        self.__dict__.update(arrays)

    @property
    def n(self) -> int:
        return len(self.sid)

    def take(self, idx: np.ndarray) -> "_Chunk":
        V, vsz = ragged_take(self.V, _offsets(self.vsz), idx)
        T, tsz = ragged_take(self.T, _offsets(self.tsz), idx)
        R, rsz = ragged_take(self.R, _offsets(self.rsz), idx)
        out = {k: getattr(self, k)[idx] for k in self.FIELDS if k not in ("V", "vsz", "T", "tsz", "R", "rsz")}
        return _Chunk(V=V, vsz=vsz, T=T, tsz=tsz, R=R, rsz=rsz, **out)

    def save(self, path: Path, own: np.ndarray) -> None:
        write_npz(path, own=own, **{k: getattr(self, k) for k in self.FIELDS})

    @classmethod
    def load_many(cls, paths) -> tuple["_Chunk", np.ndarray]:
        parts, owns = [], []
        for p in paths:
            with np.load(p, allow_pickle=False) as z:
                parts.append({k: z[k] for k in cls.FIELDS})
                owns.append(z["own"])
        merged = {k: np.concatenate([p[k] for p in parts]) for k in cls.FIELDS}
        return cls(**merged), np.concatenate(owns)


class _Accumulator:
    """Collects prepared polygons; routes full chunks to per-tile spool files."""

    def __init__(self, spool: Path, cfg: CityCfg, chunk_surfaces: int):
        self.spool = spool
        self.size = float(cfg.tile_size_m)
        self.buffer = float(cfg.buffer_m)
        self.chunk_surfaces = chunk_surfaces
        self.n_chunks = 0
        self.tiles_seen: set = set()
        self.own_tiles: set = set()
        self.ground_points: list = []
        self.terrain_files: list = []
        self._reset()

    def _reset(self):
        self.verts, self.tris, self.rings = [], [], []
        self.normal, self.area, self.code, self.albedo = [], [], [], []
        self.sid, self.bid, self.cls = [], [], []

    def add(self, prep, sid: str, bid: str, stype: str, cls: str, albedo: float):
        self.verts.append(prep.vertices)
        self.tris.append(prep.triangles)
        self.rings.append(prep.ring_sizes)
        self.normal.append(prep.normal)
        self.area.append(prep.area)
        self.code.append(SURFACE_CODE[stype])
        self.albedo.append(albedo)
        self.sid.append(sid)
        self.bid.append(bid)
        self.cls.append(cls)
        if len(self.sid) >= self.chunk_surfaces:
            self.flush()

    def flush(self):
        n = len(self.sid)
        if n == 0:
            return
        vsz = np.fromiter((len(v) for v in self.verts), np.int64, n)
        tsz = np.fromiter((len(t) for t in self.tris), np.int64, n)
        rsz = np.fromiter((len(r) for r in self.rings), np.int64, n)
        V = np.concatenate(self.verts)
        T = np.concatenate(self.tris).astype(np.int32)
        R = np.concatenate(self.rings).astype(np.int32)
        vo = _offsets(vsz)
        # area-weighted centroid of each surface from its triangles
        tri_glob = T + np.repeat(vo[:-1], tsz)[:, None]
        P = V[tri_glob]
        a = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
        owner = np.repeat(np.arange(n), tsz)
        wsum = np.bincount(owner, a, minlength=n)
        c = P.mean(axis=1)
        centroid = np.stack([np.bincount(owner, a * c[:, k], minlength=n) for k in range(3)], 1)
        centroid /= np.where(wsum > 0, wsum, 1)[:, None]
        chunk = _Chunk(V=V, vsz=vsz, T=T, tsz=tsz, R=R, rsz=rsz,
                       normal=np.array(self.normal), area=np.array(self.area),
                       code=np.array(self.code, np.int8), albedo=np.array(self.albedo, np.float32),
                       centroid=centroid, sid=np.array(self.sid, dtype=str),
                       bid=np.array(self.bid, dtype=str), cls=np.array(self.cls, dtype=str))
        ground = chunk.code == SURFACE_CODE["ground"]
        if ground.any():
            zmean = np.add.reduceat(V[:, 2], vo[:-1]) / vsz
            self.ground_points.append(np.column_stack([centroid[ground, :2], zmean[ground]]))
        terrain = np.flatnonzero(chunk.code == SURFACE_CODE["terrain"])
        if len(terrain):
            sub = chunk.take(terrain)
            tpath = self.spool / "_terrain" / f"{self.n_chunks:06d}.npz"
            tpath.parent.mkdir(parents=True, exist_ok=True)
            np.savez(tpath, V=sub.V, T=sub.T + np.repeat(_offsets(sub.vsz)[:-1], sub.tsz)[:, None])
            self.terrain_files.append(tpath)
        self._route(chunk, vo)
        self.n_chunks += 1
        self._reset()

    def _route(self, chunk: _Chunk, vo: np.ndarray):
        s, b = self.size, self.buffer
        x, y = chunk.V[:, 0], chunk.V[:, 1]
        minx, maxx = np.minimum.reduceat(x, vo[:-1]), np.maximum.reduceat(x, vo[:-1])
        miny, maxy = np.minimum.reduceat(y, vo[:-1]), np.maximum.reduceat(y, vo[:-1])
        ox, oy = tile_index(chunk.centroid[:, 0], chunk.centroid[:, 1], s)
        # tiles ix whose expanded extent [ix*s - b, (ix+1)*s + b] meets [minx, maxx]
        lx = np.minimum(np.ceil((minx - b) / s - 1).astype(np.int64), ox)
        hx = np.maximum(np.floor((maxx + b) / s).astype(np.int64), ox)
        ly = np.minimum(np.ceil((miny - b) / s - 1).astype(np.int64), oy)
        hy = np.maximum(np.floor((maxy + b) / s).astype(np.int64), oy)
        nx, ny = hx - lx + 1, hy - ly + 1
        rep = nx * ny
        sidx = np.repeat(np.arange(chunk.n), rep)
        k = np.arange(int(rep.sum())) - np.repeat(_offsets(rep)[:-1], rep)
        px = lx[sidx] + k // ny[sidx]
        py = ly[sidx] + k % ny[sidx]
        own = (px == ox[sidx]) & (py == oy[sidx])
        keys, inverse = np.unique(np.stack([px, py], 1), axis=0, return_inverse=True)
        order = np.argsort(inverse.ravel(), kind="stable")
        bounds = _offsets(np.bincount(inverse.ravel(), minlength=len(keys)))
        for g, (ix, iy) in enumerate(keys):
            sel = order[bounds[g]:bounds[g + 1]]
            name = tile_name(ix, iy, s)
            folder = self.spool / name
            folder.mkdir(exist_ok=True)
            self.tiles_seen.add(name)
            if own[sel].any():
                self.own_tiles.add(name)
            chunk.take(sidx[sel]).save(folder / f"{self.n_chunks:06d}.npz", own[sel])


def _write_surfaces(own_part: "_Chunk", name: str, city_dir: Path, crs: str):
    """A tile's own surfaces as ``surfaces/tile=<T>/part-0.parquet`` (GeoParquet); returns
    its footprints grown for the coverage area (:func:`.coverage.grown_footprints`)."""
    import geopandas as gpd
    import shapely

    n_own = own_part.n
    ring_of_vertex = np.repeat(np.arange(len(own_part.R)), own_part.R)
    rings = shapely.linearrings(own_part.V, indices=ring_of_vertex)
    polys = shapely.polygons(rings, indices=np.repeat(np.arange(n_own), own_part.rsz))
    types = np.asarray(SURFACE_TYPES)[own_part.code]
    gdf = gpd.GeoDataFrame({
        "surface_id": own_part.sid.astype(object), "building_id": own_part.bid.astype(object),
        "surface_type": types.astype(object), "citygml_class": own_part.cls.astype(object),
        "area_m2": own_part.area, "nx": own_part.normal[:, 0], "ny": own_part.normal[:, 1],
        "nz": own_part.normal[:, 2], "albedo": own_part.albedo.astype(np.float64),
        "tile": np.full(n_own, name, dtype=object)}, geometry=polys, crs=crs)
    with atomic_path(CityDir(city_dir).surface_part(name)) as tmp:
        gdf.to_parquet(tmp, index=False)
    return grown_footprints(tile_footprints(gdf))


def _write_tile(name: str, spool: Path, city_dir: Path, cfg: CityCfg, crs: str):
    """Write one tile's GeoParquet (own surfaces) and mesh (own + buffer); return its
    tiles.json entry and its footprints grown for the coverage area (None without)."""
    files = sorted((spool / name).glob("*.npz"))
    chunk, own = _Chunk.load_many(files)
    order = np.argsort(~own, kind="stable")      # own surfaces first
    chunk = chunk.take(order)
    n_own = int(own.sum())
    # -- surfaces (own) -> GeoParquet (a tile reached only by the buffer has none: no file)
    grown = _write_surfaces(chunk.take(np.arange(n_own)), name, city_dir, crs) if n_own else None
    # -- mesh: the tile's own surfaces, then those of its buffer, merged and checked by trimesh
    bounds = np.array(tile_bounds(name, cfg.tile_size_m))
    parts = [_surface_mesh(chunk.take(idx), name, bounds, cfg.buffer_m)
             for idx in (np.arange(n_own), np.arange(n_own, chunk.n))]
    mesh = TileMesh.merge(parts)
    counts = mesh.check(f"tile {name}")
    mesh.save(CityDir(city_dir).mesh(name))
    return {"bounds": bounds.tolist(), "n_surfaces": n_own,
            "n_buffer_surfaces": int(chunk.n - n_own), "n_triangles": counts["triangles"],
            "n_degenerate_triangles": counts["degenerate_triangles"]}, grown


def _surface_mesh(chunk: _Chunk, name: str, bounds: np.ndarray, buffer_m: float) -> TileMesh:
    """The triangles of the surfaces of *chunk* as one mesh (each surface's albedo, type and
    normal on its triangles)."""
    return TileMesh.build(chunk.V, chunk.T, (chunk.vsz, chunk.tsz), chunk.sid, bounds=bounds,
                          buffer_m=float(buffer_m), name=name, albedo=chunk.albedo,
                          normals=chunk.normal.astype(np.float32), surface_type=chunk.code)


def ingest_city(paths, data_dir, city_cfg: CityCfg | None = None, crs: str | None = None,
                chunk_surfaces: int = CHUNK_SURFACES, axis_order: str = "auto",
                accept=(), trees=(), trees_crs: str | None = None) -> IngestReport:
    """Read CityGML files into tiled surfaces, tile meshes and a terrain model.

    Parameters
    ----------
    paths : path or list of paths
        CityGML files (``.gml``, ``.xml``, ``.gml.gz``, or ``.zip`` holding GML files).
    data_dir : path
        Scenario data dir; outputs go to ``<data_dir>/city/`` (docs/contracts.md), which is
        replaced as a whole only when the ingest succeeds.
    city_cfg : CityCfg, optional
        Tile size (m), buffer (m), albedo per type, planarity tolerance (m), min area (m2).
    crs : str, optional
        Output CRS (``EPSG:xxxx``, projected) and the CRS assumed for files without
        ``srsName``.  Default: the first file's CRS when projected, else (geographic, e.g.
        PLATEAU's EPSG:6697) the local UTM zone of its first building.
    chunk_surfaces : int
        Surfaces held in memory before they are spooled to disk.
    axis_order : str
        ``auto`` (default): each file's axis order from its CRS and data (docs/city.md);
        ``epsg``: the EPSG order (latitude / northing first where EPSG says so); ``xy``:
        easting / longitude first.
    accept : iterable of str
        Plausibility findings accepted (``checks.accept``): with ``crs_area``, a *crs* whose
        area of use does not hold the city model is used anyway instead of refused.
    trees : path or list of paths
        Tree tables (CSV or GeoParquet points, :mod:`vipvflow.inputs.city.trees`); their trees
        join the CityGML vegetation objects as crowns (``city/trees/<T>.npz``,
        ``city/trees.parquet``), never as mesh surfaces.
    trees_crs : str, optional
        CRS of the x/y columns of the CSV tree tables (default: the city's).

    Returns
    -------
    IngestReport
        Also written to ``city/ingest_report.json``.

    Raises
    ------
    InputError
        Missing, broken or truncated file (with line number), unknown CityGML version,
        unknown or missing CRS, a file with no city objects or no usable polygon.  The data
        dir's ``city/`` is left as it was.
    """
    t0 = time.perf_counter()
    cfg = city_cfg or CityCfg()
    paths, target = _input_paths(paths, crs)
    data_dir = Path(data_dir)
    data_dir.mkdir(parents=True, exist_ok=True)
    remove_stale_ingests(data_dir)
    final_dir = DataDir(data_dir).city.root
    city_dir = staging_dir(final_dir)           # data_dir/.city-ingest-<pid>, swapped in at the end
    report = IngestReport(crs_source="--crs" if target else "")
    counts = _Counts()
    spool = city_dir / ".spool"
    bar = Progress("CityGML ingest", citygml_bytes(paths), unit="B")
    try:
        spool.mkdir()
        acc = _Accumulator(spool, cfg, chunk_surfaces)
        read = _CityRead(acc, cfg, target, report, counts, bar, axis_order, accept)
        read.files(paths)
        acc.flush()
        target = report.crs = read.target
        for table in _paths(trees):
            read.trees.add_table(table, target, trees_crs)
        _check_not_empty(report, counts, read.ignored, final_dir, len(read.trees.rows["x"]))
        tiles, grown = {}, []
        # every tile a surface can shade has a mesh: its own surfaces' tiles and the tiles
        # within the buffer around them (a road there is shaded by the model's buildings)
        for name in sorted(acc.tiles_seen):
            tiles[name], g = _write_tile(name, spool, city_dir, cfg, target)
            if g is not None:
                grown.append(g)
        terrain_tris = _write_terrain(city_dir, acc, target)
        report.trees = _write_trees(city_dir, read.trees, cfg, target, set(tiles))
        shutil.rmtree(spool)
        report.coverage = write_coverage(CityDir(city_dir), target, grown)
        write_json({
            "crs": target, "tile_size_m": cfg.tile_size_m, "buffer_m": cfg.buffer_m,
            "tiles": tiles}, CityDir(city_dir).tiles_json, sort_keys=True)
        _sum_up(report, counts, read.ignored, tiles, terrain_tris)
        report.elapsed_s = round(time.perf_counter() - t0, 3)
        report.report_path = str(CityDir(final_dir).report)
        write_json(json.loads(report.to_json()), CityDir(city_dir).report, sort_keys=True)
        swap_dir(city_dir, final_dir)
    except BaseException:
        bar.close(failed=True)
        raise
    finally:
        bar.close()
        shutil.rmtree(city_dir, ignore_errors=True)
    return report


def _input_paths(paths, crs: str | None) -> tuple[list[Path], str | None]:
    """(the CityGML files, each of which must exist; the output CRS *crs* when given, which
    must be projected)."""
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    paths = [Path(p) for p in paths]
    for path in paths:
        if not path.exists():
            raise InputError(f"{path}: file not found")
    try:
        name = normalise_crs(crs) if crs else None
    except InputError:
        raise InputError(f"--crs {crs} (or inputs.citygml_crs): not a CRS name (EPSG:2169, "
                         "urn:ogc:def:crs:EPSG::25832 or an OGC URL)") from None
    target = horizontal(name) if name else None
    if target and not is_projected(target):
        raise InputError(f"--crs {crs}: tiles need a projected CRS in metres, not {target}")
    return paths, target


class _CityRead:
    """One pass over the CityGML files: their city objects into the accumulator (vegetation
    into the trees), counted."""

    def __init__(self, acc: _Accumulator, cfg: CityCfg, target: str | None,
                 report: IngestReport, counts: _Counts, bar: Progress, axis_order: str,
                 accept=()):
        from .trees import TreeCollector

        self.acc, self.cfg, self.target, self.axis_order = acc, cfg, target, axis_order
        self.accept = tuple(accept)
        self.trees = TreeCollector(cfg.trees.crown_base_fraction)
        self.report, self.counts, self.bar = report, counts, bar
        self.albedo = cfg.albedo.model_dump()
        self.ignored = Counter()               # city objects not read, per class
        self.read_before = 0                   # bytes of the files read before this one

    def files(self, paths: list[Path]) -> None:
        """Read every file (each GML file of a ``.zip``)."""
        for path in paths:
            with open_sources(path) as sources:
                for label, opener in sources:
                    self.report.files.append(label)
                    with opener() as fh:
                        self._file(fh, label)
                    log.info("read %s", label)

    def _file(self, fh, label: str) -> None:
        """Read one file; its CRS is settled on its first feature with coordinates."""
        reader = CityGMLReader(fh, label)
        src = None
        for n_feature, feature in enumerate(reader):
            if n_feature % 64 == 0:
                self.bar.advance_to(self.read_before + file_position(fh))
            if src is None and _has_coordinates(feature):
                src, self.target = _resolve_crs(reader, label, feature, self.target,
                                                self.report, self.axis_order, self.accept)
            if feature.vegetation is not None:
                # trees are crowns of their own (models/trees.py), never opaque mesh surfaces
                for stype, reason in feature.skips:
                    self.counts.skip(reason, stype)
                if src is not None or not _has_coordinates(feature):
                    self.trees.add_vegetation(feature, src, self.target, label)
            else:
                _add_feature(feature, self.acc, src, self.target, self.cfg, self.albedo, self.counts)
            self._count(feature)
        self.ignored.update(reader.ignored)
        if src is None:
            self.report.file_crs[label] = None
        self.read_before += file_position(fh)
        self.bar.advance_to(self.read_before, "tiles and meshes next")

    def _count(self, feature) -> None:
        """Count a feature by kind (buildings by LoD) and its problems."""
        self.counts.problems.update(feature.problems)
        if feature.kind == "building":
            self.report.buildings += 1
            self.report.building_parts += feature.n_parts
            self.counts.lods[feature.lod_used] += 1
        elif feature.kind == "terrain":
            self.report.terrain_features += 1
        else:
            self.report.vegetation_features += 1


def _sum_up(report: IngestReport, counts: _Counts, ignored: Counter, tiles: dict,
            terrain_triangles: int) -> None:
    """Put the counts of the ingest and the tiles written into *report*."""
    report.surfaces = dict(counts.written)
    report.thematic_surfaces = dict(counts.thematic)
    report.area_m2 = {k: round(v, 3) for k, v in counts.area.items()}
    report.skipped = dict(counts.skipped)
    report.skipped_by_type = dict(counts.skipped_by_type)
    report.repaired = dict(counts.repaired)
    report.problems, report.ignored_features = dict(counts.problems), dict(ignored)
    report.buildings_by_lod = dict(counts.lods)
    report.tiles = len(tiles)
    report.triangles = int(sum(t["n_triangles"] for t in tiles.values()))
    report.degenerate_triangles = int(sum(t["n_degenerate_triangles"] for t in tiles.values()))
    report.terrain_triangles = terrain_triangles


@dataclass
class _Counts:
    written: Counter = field(default_factory=Counter)
    thematic: Counter = field(default_factory=Counter)
    area: Counter = field(default_factory=Counter)
    skipped: Counter = field(default_factory=Counter)
    skipped_by_type: Counter = field(default_factory=Counter)
    repaired: Counter = field(default_factory=Counter)
    problems: Counter = field(default_factory=Counter)
    lods: Counter = field(default_factory=Counter)

    def skip(self, reason: str, stype: str | None) -> None:
        self.skipped[reason] += 1
        if stype is not None:
            self.skipped_by_type[stype] += 1


def _coordinates(feature) -> np.ndarray:
    """Some coordinates of a feature as written (its polygons', a vegetation object's)."""
    if feature.vegetation is not None:
        return feature.vegetation.sample()
    rings = [r for s in feature.surfaces for r in s.rings if len(r)]
    return np.concatenate(rings) if rings else np.zeros((0, 3))


def _has_coordinates(feature) -> bool:
    return len(_coordinates(feature)) > 0


def _resolve_crs(reader: CityGMLReader, label: str, feature, target: str | None,
                 report: IngestReport, axis_order: str = "auto", accept=()):
    """(how this file's coordinates are read, output CRS), settled on its first feature.

    A given output CRS (``--crs``, ``inputs.citygml_crs``) whose area of use does not hold
    the file's first building is refused (the city would be tiled in a projection's far
    distortion: EPSG:32618, New York's UTM zone, for Luxembourg), unless ``crs_area`` is in
    *accept*."""
    if reader.srs_name:
        name = parse_srs_name(reader.srs_name)
    elif target:
        name = target
    else:
        raise InputError(f"{label}: the file names no CRS (no srsName); pass --crs EPSG:xxxx")
    sample = _coordinates(feature)[:, :2]
    src = SourceCRS.decide(name, sample, axis_order)
    report.file_crs[label] = src.crs
    report.axis_order[label] = src.axis_order
    if target is None:
        if is_projected(src.crs):
            target, why = src.crs, "the file's CRS"
        else:
            lonlat = src.read(np.column_stack([sample, np.zeros(len(sample))]))[:, :2]
            lonlat = lonlat[inside(lonlat, src.bounds)]
            if not len(lonlat):
                raise InputError(f"{label}: feature {feature.feature_id}: no coordinate inside "
                                 f"the area of use of {src.crs}; pass --crs EPSG:xxxx")
            lon, lat = np.median(lonlat, axis=0)
            target = local_utm(src.crs, float(lon), float(lat))
            why = f"local UTM zone for geographic {src.crs}"
        report.crs_source = why
        log.info("city CRS %s (%s); coordinates of %s read as %s", target, why, label,
                 src.axis_order)
    else:
        log.info("coordinates of %s (%s) read as %s", label, src.crs, src.axis_order)
        if src.crs != target and "crs_area" not in accept:
            _check_target_area(label, feature, sample, src, target)
    return src, target


def _check_target_area(label: str, feature, sample: np.ndarray, src: SourceCRS,
                       target: str) -> None:
    """The file's first building (*sample*, as written) must lie in the area of use of the
    output CRS *target* it is put in (widened by AREA_MARGIN_DEG)."""
    from ...errors import accept_hint
    from .crs import describe_area, in_area_of_use

    xy = src.read(np.column_stack([sample, np.zeros(len(sample))]))[:, :2]
    xy = xy[inside(xy, src.bounds)]
    if not len(xy):
        return                       # outside its own CRS's area: skipped and counted later
    lonlat = transform_xyz(np.column_stack([xy, np.zeros(len(xy))]), src.crs, "EPSG:4326")
    lon, lat = np.median(lonlat[:, 0]), np.median(lonlat[:, 1])
    if not np.isfinite([lon, lat]).all() or in_area_of_use([lon], [lat], target).all():
        return
    raise InputError(f"{label}: its city objects ({src.crs}, the first, {feature.feature_id}, at "
                     f"{lat:.2f}, {lon:.2f}) lie outside the area of use of {describe_area(target)}, "
                     "the CRS given by --crs or inputs.citygml_crs: leave it out to keep the "
                     f"file's CRS, or give one for the city's place {accept_hint('crs_area')}")


def _add_feature(feature, acc: _Accumulator, src: SourceCRS | None, target: str, cfg: CityCfg,
                 albedo: dict, counts: _Counts) -> None:
    counts.thematic.update(feature.thematic)
    for stype, reason in feature.skips:
        counts.skip(reason, stype)
    surfaces = feature.surfaces
    if not surfaces:
        return
    sizes = [len(r) for s in surfaces for r in s.rings]
    raw = np.concatenate([r for s in surfaces for r in s.rings])
    finite = np.isfinite(raw).all(axis=1)
    xyz = src.read(raw)
    ok = finite & inside(xyz, src.bounds)
    if src.crs != target:
        with np.errstate(all="ignore"):
            xyz = transform_xyz(np.where(ok[:, None], xyz, 0.0), src.crs, target)
        ok &= np.isfinite(xyz).all(axis=1)
    bounds = np.cumsum([0] + sizes)
    k = 0
    prepared = []
    for s in surfaces:
        rings = []
        reason = None
        for _ in s.rings:
            a, b = bounds[k], bounds[k + 1]
            k += 1
            if reason is None and not finite[a:b].all():
                reason = "non_finite_coordinates"
            elif reason is None and not ok[a:b].all():
                reason = "outside_crs_area"
            rings.append(xyz[a:b])
        prepared.append((s, rings, reason))
    counters = Counter()
    for s, rings, reason in prepared:
        stype = s.surface_type
        if reason is not None:
            counts.skip(reason, stype)
            if stype is not None:
                counters[stype] += 1
            continue
        if s.reversed:
            rings = [r[::-1] for r in rings]
        try:
            prep = prepare_polygon(rings, cfg.planarity_tolerance_m, cfg.min_area_m2)
            if feature.kind == "building" and prep.area > MAX_SURFACE_AREA_M2:
                raise Skip("absurd_area", f"{prep.area:.3g} m2")
        except Skip as skip:
            counts.skip(skip.reason, stype)
            if stype is not None:
                counters[stype] += 1
            continue
        counts.repaired.update(set(prep.repairs))
        if stype is None:
            stype = str(classify_normal(prep.normal[2]))
        sid = s.surface_id
        if sid is None:
            sid = f"{feature.feature_id}_{stype}_{counters[stype]}"
        counters[stype] += 1
        counts.written[stype] += 1
        counts.area[stype] += prep.area
        acc.add(prep, sid, feature.feature_id, stype, s.citygml_class, albedo[stype])


def _check_not_empty(report: IngestReport, counts: _Counts, ignored: Counter,
                     final_dir: Path, n_trees: int = 0) -> None:
    """Refuse an ingest that would replace the city with nothing."""
    files = ", ".join(report.files)
    kept = f"{final_dir} left as it was"
    if report.buildings + report.terrain_features + report.vegetation_features == 0:
        other = ", ".join(f"{v} {k}" for k, v in ignored.most_common(5))
        found = f" (found only: {other})" if other else ""
        raise InputError(f"{files}: no CityGML building, terrain or vegetation object{found}; {kept}")
    if not counts.written and not n_trees:
        why = ", ".join(f"{k} {v}" for k, v in counts.skipped.most_common()) or "no geometry"
        raise InputError(f"{files}: {report.buildings} buildings but no usable polygon "
                         f"(skipped: {why}); {kept}")


def _paths(p) -> list[Path]:
    if p is None:
        return []
    if isinstance(p, (str, os.PathLike)):
        return [Path(p)]
    return [Path(x) for x in p]


def _write_trees(city_dir: Path, collector, cfg: CityCfg, crs: str | None, mesh_tiles: set) -> dict:
    """The trees' crowns: ``trees.parquet`` (every tree, GeoParquet points) and per tile the
    trees whose crowns come within ``cfg.buffer_m`` of it (``trees/<T>.npz``); returns the
    trees' report (:class:`vipvflow.inputs.city.trees.TreeReport`)."""
    import geopandas as gpd

    from ...models.tree_table import LEAF_TYPES, TREE_SOURCES
    from .terrain import TerrainModel

    city = CityDir(city_dir)
    terrain = None
    if city.terrain.exists():
        with np.load(city.terrain, allow_pickle=False) as z:
            terrain = TerrainModel(z["tin_vertices"], z["tin_triangles"], z["ground_points"], str(z["crs"]))
    lat = 0.0
    rows = collector.rows
    if rows["x"] and crs:
        x, y = float(np.nanmedian(rows["x"])), float(np.nanmedian(rows["y"]))
        lat = float(transform_xyz(np.array([[x, y, 0.0]]), crs, "EPSG:4326")[0, 1])
    table = collector.finish(terrain, lat)
    report = asdict(collector.report)
    if not len(table):
        return report
    leaf = np.array(list(LEAF_TYPES) + ["unknown"])[table.leaf_type]
    gdf = gpd.GeoDataFrame({
        "tree_id": table.tree_id.astype(object), "source": np.array(TREE_SOURCES)[table.source].astype(object),
        "height_m": table.height.astype(np.float64), "crown_diameter_m": table.crown_diameter.astype(np.float64),
        "crown_base_m": table.crown_base.astype(np.float64), "leaf_type": leaf.astype(object),
        "leaf_off_months": [_months_text(m) for m in table.leaf_off]},
        geometry=gpd.points_from_xy(table.x, table.y, table.z), crs=crs)
    with atomic_path(city.tree_points) as tmp:
        gdf.to_parquet(tmp, index=False)
    # the tiles each crown can shade: those whose extent widened by the buffer it meets
    s, b = float(cfg.tile_size_m), float(cfg.buffer_m)
    r = 0.5 * table.crown_diameter.astype(np.float64)
    lx = np.floor((table.x - r - b) / s).astype(np.int64)
    hx = np.floor((table.x + r + b) / s).astype(np.int64)
    ly = np.floor((table.y - r - b) / s).astype(np.int64)
    hy = np.floor((table.y + r + b) / s).astype(np.int64)
    nx, ny = hx - lx + 1, hy - ly + 1
    rep = nx * ny
    tree = np.repeat(np.arange(len(table)), rep)
    k = np.arange(int(rep.sum())) - np.repeat(np.cumsum(rep) - rep, rep)
    px, py = lx[tree] + k // ny[tree], ly[tree] + k % ny[tree]
    keys, inverse = np.unique(np.stack([px, py], 1), axis=0, return_inverse=True)
    inverse = inverse.ravel()
    order = np.argsort(inverse, kind="stable")
    bounds = np.r_[0, np.cumsum(np.bincount(inverse, minlength=len(keys)))]
    city.trees.mkdir(parents=True, exist_ok=True)
    n_files = 0
    for g, (ix, iy) in enumerate(keys):
        table.take(np.sort(tree[order[bounds[g]:bounds[g + 1]]])).save(city.trees_file(tile_name(ix, iy, s)))
        n_files += 1
    report["tiles"] = n_files
    report["tiles_without_mesh"] = int(sum(tile_name(ix, iy, s) not in mesh_tiles for ix, iy in keys))
    report["latitude"] = round(lat, 4)
    return report


def _months_text(mask: int) -> str:
    """A 12-bit month mask as ``1,2,11,12``; empty for the default (-1)."""
    return "" if mask < 0 else ",".join(str(m + 1) for m in range(12) if (int(mask) >> m) & 1)


def remove_stale_ingests(data_dir: Path) -> list[Path]:
    """Remove what killed city ingests left in *data_dir*; return the paths removed.

    ``.city-ingest-<pid>`` and ``.city-old-<pid>`` as :func:`vipvflow.store.remove_stale`
    says (the previous city put back when a kill left none), and ``city/.ingest-spool-<pid>``
    (spools of older versions) when their process is gone.
    """
    data_dir = Path(data_dir)
    final = DataDir(data_dir).city.root
    had_city = final.exists()
    removed = remove_stale(final)
    if not had_city and final.exists():
        log.warning("restored %s from an interrupted ingest", final)
    for p in final.glob(".ingest-spool-*"):
        pid = p.name.rsplit("-", 1)[-1]
        if p.is_dir() and pid.isdigit() and not pid_alive(int(pid)):
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    for p in removed:
        log.info("removed %s left by a killed ingest", p)
    return removed


def _write_terrain(city_dir: Path, acc: _Accumulator, crs: str | None) -> int:
    V, T, off = [], [], 0
    for p in acc.terrain_files:
        with np.load(p) as z:
            V.append(z["V"])
            T.append(z["T"] + off)
            off += len(z["V"])
    vertices = np.concatenate(V) if V else np.zeros((0, 3))
    triangles = np.concatenate(T).astype(np.int32) if T else np.zeros((0, 3), np.int32)
    ground = np.concatenate(acc.ground_points) if acc.ground_points else np.zeros((0, 3))
    write_npz(CityDir(city_dir).terrain, tin_vertices=vertices, tin_triangles=triangles,
              ground_points=ground, crs=np.str_(crs or ""))
    return int(len(triangles))


def load_tile_mesh(data_dir, tile: str) -> TileMesh:
    """The mesh of *tile* (own + buffer surfaces) written by :func:`ingest_city`."""
    path = DataDir(data_dir).city.mesh(tile)
    if not path.exists():
        raise InputError(f"{path}: no mesh for tile {tile} (run `vipvflow ingest city` first)")
    return TileMesh.load(path)
