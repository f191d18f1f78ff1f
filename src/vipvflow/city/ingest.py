"""City ingest: CityGML files -> tiled semantic surfaces (GeoParquet) and tile meshes.

Two passes with bounded memory:

1. Stream every file (:class:`~vipvflow.city.citygml.CityGMLReader`), clean and
   triangulate each polygon (:mod:`~vipvflow.city.geometry`), and keep the results in
   compact numpy chunks.  A full chunk is routed to spool files, one per tile it touches:
   the tile of each surface's area centroid ("own") and every tile whose buffer-expanded
   bounds its bounding box overlaps ("buffer").
2. For each tile, read its spool files and write ``city/surfaces/tile=<T>/part-0.parquet``
   (own surfaces) and ``city/meshes/<T>.npz`` (own + buffer surfaces), both atomically.

Peak memory is set by the chunk size and the largest tile, not by the size of the city.
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

from ..config import CityCfg
from ..errors import InputError
from ..mesh import SURFACE_CODE, SURFACE_TYPES, TileMesh
from ..progress import Progress, citygml_bytes, file_position
from ..tiles import tile_bounds, tile_index, tile_name
from .citygml import CityGMLReader, open_sources
from .crs import is_projected, normalise_crs, parse_srs_name, transform_xyz
from .geometry import Skip, classify_normal, prepare_polygon

log = logging.getLogger(__name__)

CHUNK_SURFACES = 20_000


@dataclass
class IngestReport:
    """What a city ingest read, wrote and skipped."""

    files: list = field(default_factory=list)
    crs: str | None = None
    file_crs: dict = field(default_factory=dict)
    buildings: int = 0
    building_parts: int = 0
    terrain_features: int = 0
    vegetation_features: int = 0
    surfaces: dict = field(default_factory=dict)          # polygons written, per type
    thematic_surfaces: dict = field(default_factory=dict)  # thematic elements read, per type
    area_m2: dict = field(default_factory=dict)            # per type
    skipped: dict = field(default_factory=dict)            # polygons, per reason
    skipped_by_type: dict = field(default_factory=dict)    # polygons, per thematic type
    repaired: dict = field(default_factory=dict)           # polygons, per repair
    problems: dict = field(default_factory=dict)           # unreadable parts, per reason
    ignored_features: dict = field(default_factory=dict)   # city objects not read, per class
    tiles: int = 0
    triangles: int = 0
    terrain_triangles: int = 0
    elapsed_s: float = 0.0
    report_path: str = ""

    @property
    def n_surfaces(self) -> int:
        return int(sum(self.surfaces.values()))

    @property
    def n_skipped(self) -> int:
        return int(sum(self.skipped.values()))

    def summary(self) -> str:
        """One line: files, CRS, buildings, surfaces per type, skips, tiles, speed."""
        types = ", ".join(f"{k} {v}" for k, v in sorted(self.surfaces.items()))
        skips = ", ".join(f"{k} {v}" for k, v in sorted(self.skipped.items())) or "none"
        rate = self.n_surfaces / self.elapsed_s if self.elapsed_s > 0 else float("nan")
        return (f"{len(self.files)} file(s) in {self.crs}: {self.buildings} buildings, "
                f"{self.n_surfaces} surfaces ({types}), skipped {self.n_skipped} ({skips}), "
                f"{self.tiles} tiles, {self.triangles} mesh triangles, "
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
        tmp = path.with_name(path.name + ".tmp.npz")
        np.savez(tmp, own=own, **{k: getattr(self, k) for k in self.FIELDS})
        tmp.replace(path)

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


def _write_tile(name: str, spool: Path, city_dir: Path, cfg: CityCfg, crs: str) -> dict:
    """Write one tile's GeoParquet (own surfaces) and mesh (own + buffer); return its tiles.json entry."""
    import geopandas as gpd
    import shapely

    files = sorted((spool / name).glob("*.npz"))
    chunk, own = _Chunk.load_many(files)
    order = np.argsort(~own, kind="stable")      # own surfaces first
    chunk = chunk.take(order)
    n_own = int(own.sum())
    # -- surfaces (own) -> GeoParquet
    own_part = chunk.take(np.arange(n_own))
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
    out = city_dir / "surfaces" / f"tile={name}" / "part-0.parquet"
    out.parent.mkdir(parents=True, exist_ok=True)
    tmp = out.with_name(out.name + ".tmp")
    gdf.to_parquet(tmp, index=False)
    tmp.replace(out)
    del gdf, polys, rings
    # -- mesh (own + buffer)
    vo = _offsets(chunk.vsz)
    tri_owner = np.repeat(np.arange(chunk.n, dtype=np.int32), chunk.tsz)
    triangles = (chunk.T + vo[:-1][tri_owner][:, None]).astype(np.int32)
    bounds = np.array(tile_bounds(name, cfg.tile_size_m))
    mesh = TileMesh(vertices=chunk.V, triangles=triangles, surface_index=tri_owner,
                    surface_ids=chunk.sid, albedo=chunk.albedo[tri_owner],
                    normals=chunk.normal[tri_owner].astype(np.float32),
                    surface_type=chunk.code[tri_owner], bounds=bounds,
                    buffer_m=float(cfg.buffer_m), name=name)
    mesh.save(city_dir / "meshes" / f"{name}.npz")
    return {"bounds": bounds.tolist(), "n_surfaces": n_own,
            "n_buffer_surfaces": int(chunk.n - n_own), "n_triangles": int(len(triangles))}


def ingest_city(paths, data_dir, city_cfg: CityCfg | None = None, crs: str | None = None,
                chunk_surfaces: int = CHUNK_SURFACES) -> IngestReport:
    """Read CityGML files into tiled surfaces, tile meshes and a terrain model.

    Parameters
    ----------
    paths : path or list of paths
        CityGML files (``.gml``, ``.xml``, ``.gml.gz``, or ``.zip`` holding GML files).
    data_dir : path
        Scenario data dir; outputs go to ``<data_dir>/city/`` (docs/contracts.md).
    city_cfg : CityCfg, optional
        Tile size (m), buffer (m), albedo per type, planarity tolerance (m), min area (m2).
    crs : str, optional
        Output CRS (``EPSG:xxxx``) and the CRS assumed for files without ``srsName``.
        Default: the first file's CRS.
    chunk_surfaces : int
        Surfaces held in memory before they are spooled to disk.

    Returns
    -------
    IngestReport
        Also written to ``city/ingest_report.json``.

    Raises
    ------
    InputError
        Missing or broken file (with line number), unknown or missing CRS.
    """
    t0 = time.perf_counter()
    cfg = city_cfg or CityCfg()
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    paths = [Path(p) for p in paths]
    city_dir = Path(data_dir) / "city"
    city_dir.mkdir(parents=True, exist_ok=True)
    target = normalise_crs(crs) if crs else None
    if target and not is_projected(target):
        raise InputError(f"--crs {crs}: tiles need a projected CRS in metres, not {target}")
    albedo = cfg.albedo.model_dump()
    report = IngestReport()
    skipped, repaired, problems, ignored = Counter(), Counter(), Counter(), Counter()
    written, thematic, area = Counter(), Counter(), Counter()
    spool = city_dir / f".ingest-spool-{os.getpid()}"
    if spool.exists():
        shutil.rmtree(spool)
    spool.mkdir()
    acc = _Accumulator(spool, cfg, chunk_surfaces)
    bar = Progress("CityGML ingest", citygml_bytes(paths), unit="B")
    read_before = 0
    try:
        for path in paths:
            with open_sources(path) as sources:
                for label, opener in sources:
                    report.files.append(label)
                    with opener() as fh:
                        reader = CityGMLReader(fh, label)
                        src = None
                        for n_feature, feature in enumerate(reader):
                            if n_feature % 64 == 0:
                                bar.advance_to(read_before + file_position(fh))
                            if src is None:
                                src, target = _resolve_crs(reader, label, target, crs)
                                report.file_crs[label] = src
                            _add_feature(feature, acc, src, target, cfg, albedo, written,
                                         thematic, area, skipped, repaired)
                            problems.update(feature.problems)
                            if feature.kind == "building":
                                report.buildings += 1
                                report.building_parts += feature.n_parts
                            elif feature.kind == "terrain":
                                report.terrain_features += 1
                            else:
                                report.vegetation_features += 1
                        ignored.update(reader.ignored)
                        if src is None:
                            report.file_crs[label] = None
                        read_before += file_position(fh)
                        bar.advance_to(read_before, "tiles and meshes next")
                    log.info("read %s", label)
        acc.flush()
        report.crs = target
        tiles = {}
        for name in sorted(acc.own_tiles):
            tiles[name] = _write_tile(name, spool, city_dir, cfg, target)
        _remove_stale(city_dir, set(tiles))
        terrain_tris = _write_terrain(city_dir, acc, target)
    finally:
        bar.close()
        shutil.rmtree(spool, ignore_errors=True)
    _atomic_json(city_dir / "tiles.json", {
        "crs": target, "tile_size_m": cfg.tile_size_m, "buffer_m": cfg.buffer_m, "tiles": tiles})
    report.surfaces = dict(written)
    report.thematic_surfaces = dict(thematic)
    report.area_m2 = {k: round(v, 3) for k, v in area.items()}
    report.skipped = {k: v for k, v in skipped.items() if not isinstance(k, tuple)}
    report.skipped_by_type = {k[1]: v for k, v in skipped.items() if isinstance(k, tuple)}
    report.repaired = dict(repaired)
    report.problems, report.ignored_features = dict(problems), dict(ignored)
    report.tiles = len(tiles)
    report.triangles = int(sum(t["n_triangles"] for t in tiles.values()))
    report.terrain_triangles = terrain_tris
    report.elapsed_s = round(time.perf_counter() - t0, 3)
    report.report_path = str(city_dir / "ingest_report.json")
    _atomic_json(city_dir / "ingest_report.json", json.loads(report.to_json()))
    return report


def _resolve_crs(reader: CityGMLReader, label: str, target: str | None, option: str | None):
    """(CRS of this file, output CRS) once the reader has met its first feature."""
    if reader.srs_name:
        src = parse_srs_name(reader.srs_name)
    elif target:
        src = target
    else:
        raise InputError(f"{label}: the file names no CRS (no srsName); pass --crs EPSG:xxxx")
    if target is None:
        if not is_projected(src):
            raise InputError(f"{label}: CRS {src} is not projected (metres); pass --crs EPSG:xxxx")
        target = src
    return src, target


def _add_feature(feature, acc: _Accumulator, src: str, target: str, cfg: CityCfg, albedo: dict,
                 written: Counter, thematic: Counter, area: Counter, skipped: Counter,
                 repaired: Counter) -> None:
    thematic.update(feature.thematic)
    surfaces = feature.surfaces
    if not surfaces:
        return
    if src != target:
        sizes = [len(r) for s in surfaces for r in s.rings]
        xyz = transform_xyz(np.concatenate([r for s in surfaces for r in s.rings]), src, target)
        parts = iter(np.split(xyz, np.cumsum(sizes)[:-1]))
        for s in surfaces:
            s.rings = [next(parts) for _ in s.rings]
    counters = Counter()
    for s in surfaces:
        rings = [r[::-1] for r in s.rings] if s.reversed else s.rings
        stype = s.surface_type
        try:
            prep = prepare_polygon(rings, cfg.planarity_tolerance_m, cfg.min_area_m2)
        except Skip as skip:
            skipped[skip.reason] += 1
            if stype is not None:
                counters[stype] += 1
                skipped[("type", stype)] += 1
            continue
        repaired.update(set(prep.repairs))
        if stype is None:
            stype = str(classify_normal(prep.normal[2]))
        sid = s.surface_id
        if sid is None:
            sid = f"{feature.feature_id}_{stype}_{counters[stype]}"
        counters[stype] += 1
        written[stype] += 1
        area[stype] += prep.area
        acc.add(prep, sid, feature.feature_id, stype, s.citygml_class, albedo[stype])


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
    out = city_dir / "terrain.npz"
    tmp = out.with_name(out.name + ".tmp.npz")
    np.savez(tmp, tin_vertices=vertices, tin_triangles=triangles, ground_points=ground,
             crs=np.str_(crs or ""))
    tmp.replace(out)
    return int(len(triangles))


def _remove_stale(city_dir: Path, keep: set) -> None:
    """Delete tiles of an earlier ingest that this one did not write."""
    for d in (city_dir / "surfaces").glob("tile=*"):
        if d.name[len("tile="):] not in keep:
            shutil.rmtree(d, ignore_errors=True)
    for f in (city_dir / "meshes").glob("*.npz"):
        if f.stem not in keep:
            f.unlink()


def _atomic_json(path: Path, data) -> None:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(json.dumps(data, indent=2, sort_keys=True, default=str))
    tmp.replace(path)


def load_tile_mesh(data_dir, tile: str) -> TileMesh:
    """The mesh of *tile* (own + buffer surfaces) written by :func:`ingest_city`."""
    path = Path(data_dir) / "city" / "meshes" / f"{tile}.npz"
    if not path.exists():
        raise InputError(f"{path}: no mesh for tile {tile} (run `vipvflow ingest city` first)")
    return TileMesh.load(path)
