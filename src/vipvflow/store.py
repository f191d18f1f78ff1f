"""Where every stage's files live, what a run's partitions hold, and how files are written.

Two folders hold everything the pipeline writes (docs/store.md draws them):

- the **data dir** (``data_dir`` of the scenario): the ingested inputs, one folder per source,
  each written whole by its ingest (:func:`staging_dir`, then :func:`swap_dir`):
  ``city/`` (:class:`CityDir`), ``gtfs/`` (:class:`GtfsDir`), ``radiation/``
  (:class:`RadiationDir`); :class:`DataDir` names them;
- the **run dir** (``out/<scenario>/<year>/``, :class:`RunDir`): the partitions the workers
  write under ``parts/`` (kinds in :data:`PARTS`), then the outputs the reduce writes beside
  them and the run's ``manifest.json``.

Stages ask these classes for paths instead of spelling folder names, and write through one
family of atomic writers (:func:`atomic_path`, :func:`write_parquet`, :func:`write_json`,
:func:`write_text`, :func:`write_bytes`, :func:`write_npz`): each writes a temporary name
beside the file and renames it, so a reader sees the old file or the new one, never half of
one.

The columns of the run's *output* files, with units, are in
:mod:`vipvflow.simulation.dictionary`; :data:`PARTS` says what one row of each partition kind
is and which columns identify it.
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator

from .errors import InputError

#: tile edge (m) of a data dir without a city: the GTFS ingest's grid when no
#: ``city/tiles.json`` gives one; the default of the configuration's ``city.tile_size_m``
TILE_SIZE_M = 500.0


# --------------------------------------------------------------------------- folder entries
class _Entry:
    """A file or folder of a store folder: as a class attribute ``segments =
    _Entry("segments.parquet")``, ``folder.segments`` is ``folder.root / "segments.parquet"``
    (*within*: under that attribute's path instead of ``root``; *kind*: a store class built
    on the path, e.g. ``DataDir.city`` is a :class:`CityDir`)."""

    def __init__(self, name: str, doc: str = "", *, within: str | None = None, kind=None):
        self.name, self.within, self.kind = name, within, kind
        self.__doc__ = doc or f"``{name}``"

    def __get__(self, folder, owner=None):
        if folder is None:
            return self
        base = getattr(folder, self.within) if self.within else folder.root
        path = base / self.name
        return self.kind(path) if self.kind else path


# --------------------------------------------------------------------------- data dir
@dataclass(frozen=True)
class _Ingested:
    """A folder one ingest writes as a whole (``city/``, ``gtfs/``, ``radiation/``).

    *root* is the folder itself (``<data_dir>/<name>`` or the ingest's staging folder)."""
    root: Path

    report = _Entry("ingest_report.json", "What the ingest found (counts, problems, gaps).")
    stamp = _Entry(".inputs.json", "Digest of the inputs this folder was ingested from (``prepare``).")


@dataclass(frozen=True)
class CityDir(_Ingested):
    """``city/``: tiled surfaces, tile meshes and terrain of the CityGML ingest."""

    tiles_json = _Entry("tiles.json", "CRS, tile size, buffer and the tiles with their extents.")
    terrain = _Entry("terrain.npz")
    meshes = _Entry("meshes")
    surfaces = _Entry("surfaces", "GeoParquet of every tile's own surfaces: "
                                  "``surfaces/tile=<T>/part-0.parquet``.")
    coverage = _Entry("coverage.parquet", "GeoParquet, one row: the area the city model covers "
                                          "(its footprints closed and widened).")
    trees = _Entry("trees", "The tree crowns each tile's rays meet (its own trees and its "
                            "buffer's): ``trees/<T>.npz`` (:class:`vipvflow.models.trees.TreeTable`).")
    tree_points = _Entry("trees.parquet", "GeoParquet, every tree the ingest kept: trunk point, "
                                          "height, crown diameter and base, leaf type, source.")

    def mesh(self, tile: str) -> Path:
        """Triangle mesh of *tile*, its own surfaces and the buffer around it."""
        return self.meshes / f"{tile}.npz"

    def surface_part(self, tile: str) -> Path:
        return self.surfaces / f"tile={tile}" / "part-0.parquet"

    def trees_file(self, tile: str) -> Path:
        """The trees whose crowns *tile*'s rays can meet (own and buffer)."""
        return self.trees / f"{tile}.npz"


#: the tables of ``gtfs/``, each ``<name>.parquet``
GTFS_TABLES = ("segments", "trips", "patterns", "pattern_stops", "calendar", "calendar_dates")


@dataclass(frozen=True)
class GtfsDir(_Ingested):
    """``gtfs/``: the timetable cut into segments, by the GTFS ingest (its report is
    :attr:`feed_json`)."""

    feed_json = _Entry("feed.json", 'Time zone, CRS, tile size, counts and problems of the '
                                    'ingested feed.')
    segments = _Entry("segments.parquet")
    trips = _Entry("trips.parquet")
    patterns = _Entry("patterns.parquet")

    def table(self, name: str) -> Path:
        """``<name>.parquet``, one of :data:`GTFS_TABLES`."""
        if name not in GTFS_TABLES:
            raise ValueError(f"no GTFS table {name!r} in the store")
        return self.root / f"{name}.parquet"


@dataclass(frozen=True)
class RadiationDir(_Ingested):
    """``radiation/``: the CAMS series of the CAMS ingest (and its sun-position caches)."""

    table = _Entry("radiation.parquet")

    def table_cache(self, year: int) -> Path:
        """The table of *year* on its minute grid, with its sun vectors and Perez
        coefficients, kept for the workers of a run
        (:meth:`vipvflow.models.sun_sky.RadiationTable.load`)."""
        return self.root / f"table_{year}.npz"

    def sky_cache(self, first_s: int, n: int) -> Path:
        """The Perez sky's visible-share tables of the table's grid from *first_s* (Unix s),
        *n* steps (:meth:`vipvflow.models.sun_sky.RadiationTable.sky`)."""
        return self.root / f"sky_{first_s}_{n}.npz"


#: the files of an entry of the geometry cache (:meth:`DataDir.geometry_cache`): a tile's
#: ``parts/geometry`` and ``parts/horizon`` files
GEOMETRY_CACHE_FILES = ("geometry.parquet", "horizon.parquet")


@dataclass(frozen=True)
class DataDir:
    """The ingested inputs of a scenario: ``city/``, ``gtfs/``, ``radiation/``."""
    root: Path

    def __post_init__(self):
        object.__setattr__(self, "root", Path(self.root))

    city = _Entry("city", kind=CityDir)
    gtfs = _Entry("gtfs", kind=GtfsDir)
    radiation = _Entry("radiation", kind=RadiationDir)

    def geometry_cache(self, key: str | None = None) -> Path:
        """The runs' cache of the tiles' geometry (``cache/geometry/``), or the folder of its
        entry *key* (:data:`GEOMETRY_CACHE_FILES`; :mod:`vipvflow.simulation.geometry_cache`)."""
        root = self.root / "cache" / "geometry"
        return root / key if key is not None else root

    def tile_size_m(self) -> float:
        """The tile edge (m) of this data dir's grid: ``tile_size_m`` of ``gtfs/feed.json``
        (the grid the segments were cut on), else of ``city/tiles.json``.

        Raises :class:`InputError` naming the file when neither exists or neither says."""
        for path in (self.gtfs.feed_json, self.city.tiles_json):
            if path.is_file():
                try:
                    size = json.loads(path.read_text()).get("tile_size_m")
                except (ValueError, AttributeError) as exc:
                    raise InputError(f"{path}: not a JSON object: {exc}") from None
                if size is not None:
                    return float(size)
        raise InputError(f"{self.gtfs.feed_json}: not found, and no tile_size_m in "
                         f"{self.city.tiles_json}; run 'vipvflow ingest gtfs' first")


# --------------------------------------------------------------------------- run dir
@dataclass(frozen=True)
class PartKind:
    """A kind of file the workers write under ``parts/``."""
    per: str
    """``"tile/month"`` (one file per tile and month), ``"tile"`` or ``"run"`` (named files)"""
    rows: str
    """what one row holds"""
    key: dict
    """columns that identify a row within its file, with their Arrow types (the tile and the
    month are named by the path, not stored; the other columns: the measures of
    :mod:`vipvflow.simulation.partition`, named as in the data dictionary)"""


#: every kind of file under a run's ``parts/``; a partition (tile, month) is complete when its
#: :data:`PARTITION_KINDS` files exist (``segment_month`` is written last)
PARTS = {
    "trip": PartKind("tile/month", "one trip on one service date: PV kWh by sky and component",
                     {"trip_id": "string", "service_date": "timestamp[ns]"}),
    "segment_month": PartKind("tile/month", "one segment: passes, irradiation sums, kWh (and "
                              "in the file's metadata, HOURLY_METADATA, the sums per local hour)",
                              {"segment_id": "int64"}),
    "standing": PartKind("tile/month", "one layover or parked interval of a block at a stop "
                         "(month=all: the whole year)",
                         {"block_id": "string", "service_date": "timestamp[ns]",
                          "kind": "string", "after_trip": "int64"}),
    "geometry": PartKind("tile", "one segment: its roof's view of the sky and the reflectors",
                         {"segment_id": "int64"}),
    "horizon": PartKind("tile", "one segment: the horizon profile the web app reads",
                        {"segment_id": "int64"}),
    "timeline": PartKind("run", "the fleet's day: block_days, intervals, trip_runs, points", {}),
    "hourly": PartKind("tile/month", "one local hour of the day: irradiation sums and pass time "
                       "(runs before 2026-11-26 only, read by the reduce; now HOURLY_METADATA)",
                       {"hour": "int8"}),
}
PARTITION_KINDS = ("trip", "segment_month")
#: the key of a segment partition's Parquet metadata holding the partition's sums per local
#: hour of the day (``hour``, irradiation ``h_*``, ``seconds``) as JSON of the table's
#: columns: 24 rows did not earn a file of their own (a third of the files a run wrote and
#: the reduce read)
HOURLY_METADATA = b"vipvflow.hourly"
#: the tables of ``parts/timeline/``, each ``<name>.parquet``
TIMELINE_TABLES = ("block_days", "intervals", "trip_runs", "points")
#: the ``month`` of a standing partition: one per tile holds all the run's months (a tile
#: has only a few standing points; per month, loading the tile's scene cost more than them)
ALL_MONTHS = "all"


@dataclass(frozen=True)
class RunDir:
    """A run's folder ``out/<scenario>/<year>/``."""
    root: Path

    def __post_init__(self):
        object.__setattr__(self, "root", Path(self.root))

    parts = _Entry("parts")
    manifest = _Entry("manifest.json")
    config_stamp = _Entry("config_digest.txt", 'Digest of the configuration the partitions under '
                          '``parts/`` were computed with.', within="parts")
    inputs_stamp = _Entry("inputs.json", "Content digests (SHA-256) of the input files the "
                          "partitions under ``parts/`` were computed from.", within="parts")

    @property
    def timeline(self) -> Path:
        return self.part_dir("timeline")

    def part_dir(self, kind: str) -> Path:
        """``parts/<kind>/``."""
        if kind not in PARTS:
            raise ValueError(f"no partition kind {kind!r}")
        return self.parts / kind

    def part(self, kind: str, tile: str, month: str) -> Path:
        """``parts/<kind>/tile=<TILE>/month=<YYYY-MM>.parquet``: findable with ls."""
        if PARTS[kind].per != "tile/month":
            raise ValueError(f"parts/{kind} is not stored per tile and month")
        return self.part_dir(kind) / f"tile={tile}" / f"month={month}.parquet"

    def tile_part(self, kind: str, tile: str) -> Path:
        """``parts/<kind>/tile=<TILE>.parquet`` (``geometry``, ``horizon``)."""
        if PARTS[kind].per != "tile":
            raise ValueError(f"parts/{kind} is not stored per tile")
        return self.part_dir(kind) / f"tile={tile}.parquet"

    def timeline_table(self, name: str) -> Path:
        """``parts/timeline/<name>.parquet``, one of :data:`TIMELINE_TABLES`."""
        if name not in TIMELINE_TABLES:
            raise ValueError(f"no timeline table {name!r} in the store")
        return self.timeline / f"{name}.parquet"

    def part_files(self, kind: str, pattern: str | None = None) -> list[Path]:
        """Every file of *kind* (matching *pattern* under ``parts/<kind>/``), in path order."""
        if pattern is None:
            pattern = {"tile/month": "tile=*/month=*.parquet", "tile": "tile=*.parquet",
                       "run": "*.parquet"}[PARTS[kind].per]
        return sorted(self.part_dir(kind).glob(pattern))

    figures = _Entry("figures", "The report's PNG figures.")
    geoparquet = _Entry("geoparquet", "The segment results as partitioned GeoParquet datasets "
                        "(``geoparquet/<name>/part.<i>.parquet``, spatial partitions).")

    def dataset(self, name: str) -> Path:
        """``geoparquet/<name>/``: ``segments`` or ``segment_month`` as a dataset of
        spatial partitions (:mod:`vipvflow.outputs.datasets`)."""
        return self.geoparquet / name

    vecto = _Entry("vecto", "VECTO driving cycles and job files of the run's patterns.")
    report = _Entry("report.html")

    def output(self, name: str) -> Path:
        """An output of the reduce beside ``parts/``: ``summary.json``, ``trip_energy.parquet``..."""
        return self.root / name

    @staticmethod
    def written_by_run(name: str) -> bool:
        """Whether an entry *name* of a run folder's top level is one a run writes: ``parts/``,
        ``figures/``, ``vecto/``, ``geoparquet/``, ``manifest.json``, ``summary.json``,
        ``report.html``, ``city.glb``, the
        outputs of the data dictionary (``<name>.parquet``) and the atomic writers'
        temporary files (``.<name>.<pid>.tmp``). ``simulate --force`` replaces only a folder
        holding nothing else."""
        from .simulation.dictionary import OUTPUTS

        if name in ("parts", "figures", "vecto", "geoparquet", "manifest.json", "summary.json",
                    "report.html", "city.glb"):
            return True
        if name.endswith(".parquet") and name[:-len(".parquet")] in OUTPUTS:
            return True
        return name.startswith(".") and ".tmp" in name


# --------------------------------------------------------------------------- atomic writes
@contextmanager
def atomic_path(path: str | Path, suffix: str = "") -> Iterator[Path]:
    """The temporary name to write *path* under, renamed to *path* when the block ends.

    The temporary file ``.<name>.<pid>.tmp<suffix>`` sits beside *path* (same file system,
    hidden from ``ls`` and from the progress view); *suffix* is for writers that insist on an
    extension (``np.savez`` adds ``.npz``). On failure it is removed and an OSError names
    *path* (a full disk's ``ENOSPC`` from a write names no file)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp{suffix}")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.errno and not exc.filename:
            raise OSError(exc.errno, os.strerror(exc.errno), str(path)) from exc
        raise


#: a table with more columns than this is written without column statistics or
#: dictionaries (:func:`write_parquet`)
WIDE_COLUMNS = 64


def write_parquet(df, path: str | Path, pandas_dtypes: bool = False, compact: bool = False,
                  float32: tuple[str, ...] = ()) -> Path:
    """Write *df* (DataFrame, GeoDataFrame or pyarrow Table) to *path* atomically.

    With *pandas_dtypes* pandas writes it, with its metadata: nullable integers and pandas'
    string flavours read back as they were (the GTFS tables).  Otherwise plain tables
    (numbers, bools, dates, strings) go straight to pyarrow: pandas' own conversion costs
    more than the write for the run's wide, small tables.  A file named as one of the run's
    outputs (``trip_energy.parquet``, ... :data:`dictionary.OUTPUTS`) is written as the data
    dictionary describes it: ``month`` as a date, every documented column with its unit and
    meaning in the field metadata.  *compact* (partition files): zstd, dictionaries for the
    non-float columns only, floats byte-stream split.  Float columns whose names start with
    one of *float32* are stored as float32 (rounded to nearest, as numpy does)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .simulation.dictionary import OUTPUTS, annotate

    path = Path(path)
    output = path.stem if path.suffix == ".parquet" and path.stem in OUTPUTS else None
    with atomic_path(path) as tmp:
        if isinstance(df, pa.Table):
            table = df
        else:
            table = None if pandas_dtypes else _plain_table(df)
        if table is not None and float32:
            table = _as_float32(table, float32)
        if table is None and output is not None and not pandas_dtypes:
            table = _arrow_table(df)
        if table is None:
            df.to_parquet(tmp, index=False)
        elif compact:
            pq.write_table(table, tmp, **_compact_options(table))
        elif table.num_columns > WIDE_COLUMNS and output is None:
            # per-column statistics and dictionaries of a wide table (the geometry
            # partitions) cost more to write than its values, and made the file larger
            pq.write_table(table, tmp, write_statistics=False, use_dictionary=False)
        else:
            pq.write_table(annotate(table, output) if output else table, tmp)
    return path


class PartSchemaError(ValueError):
    """A part given to :func:`write_parquet_parts` converts to another schema than the first
    (its values decide a column's type: a nullable integer column with a gap, say)."""


#: pyarrow's row group (rows): the row groups :func:`write_parquet_parts` gives a file, as
#: a whole written at once has them
ROW_GROUP_ROWS = 1 << 20


def write_parquet_parts(parts, path: str | Path, metadata: dict | None = None,
                        row_group_rows: int = ROW_GROUP_ROWS) -> Path:
    """Write the frames *parts* (consecutive slices of one DataFrame or GeoDataFrame, in
    order, of any length) to *path* atomically as one file, as :func:`write_parquet` writes
    their concatenation: each part converted the same way, and the converted parts written
    as row groups of *row_group_rows* rows (the whole's), so what is held is one part and
    the Arrow columns of one row group.  *metadata* replaces the entries of the file's
    key-value metadata that describe the whole rather than a part (a GeoParquet's ``geo``:
    the bounding box and geometry types of all rows).  A part whose schema differs from the
    first's is an error."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from .simulation.dictionary import OUTPUTS, annotate

    path = Path(path)
    output = path.stem if path.suffix == ".parquet" and path.stem in OUTPUTS else None
    with atomic_path(path) as tmp:
        writer, pending, n, first = None, [], 0, None

        def write(table):
            nonlocal writer
            if writer is None:
                writer = pq.ParquetWriter(tmp, table.schema)
            writer.write_table(table, row_group_size=row_group_rows)

        try:
            for part in parts:
                table = _plain_table(part)
                table = _arrow_table(part) if table is None else table
                if metadata:
                    table = table.replace_schema_metadata({**(table.schema.metadata or {}), **metadata})
                table = annotate(table, output) if output else table
                first = table.schema if first is None else first
                if not table.schema.equals(first, check_metadata=True):
                    raise PartSchemaError(f"{path}: a part's schema differs from the first's")
                pending.append(table)
                n += table.num_rows
                while n >= row_group_rows:      # a whole row group: written, its columns let go
                    whole = pa.concat_tables(pending)
                    write(whole.slice(0, row_group_rows))
                    rest = whole.slice(row_group_rows)
                    del whole
                    pending, n = ([rest] if rest.num_rows else []), rest.num_rows
            if pending and (n or writer is None):
                write(pa.concat_tables(pending))
        finally:
            if writer is not None:
                writer.close()
        if writer is None:
            raise ValueError(f"{path}: no parts to write")
    return path


def _as_float32(table, prefixes: tuple[str, ...]):
    """*table* with its float columns named ``<prefix>...`` cast to float32."""
    import pyarrow as pa

    for i, field in enumerate(table.schema):
        if field.name.startswith(prefixes) and pa.types.is_floating(field.type):
            table = table.set_column(i, pa.field(field.name, pa.float32()),
                                     table.column(i).cast(pa.float32(), safe=False))
    return table


def _compact_options(table) -> dict:
    """Parquet settings of the partition files: floats (most of their bytes) byte-stream
    split before zstd (level 1), dictionaries for the rest only (ids, dates), no column
    statistics."""
    import pyarrow as pa

    floats = [f.name for f in table.schema if pa.types.is_floating(f.type)]
    # zstd level 1 and no column statistics (nothing filters on them): a third less time
    # per partition than level 3 with statistics, and files a few % smaller
    return {"compression": "zstd", "compression_level": 1, "write_statistics": False,
            "use_byte_stream_split": floats,
            "use_dictionary": [f.name for f in table.schema if f.name not in floats]}


def write_json(obj, path: str | Path, sort_keys: bool = False) -> Path:
    """Write *obj* as indented JSON (values JSON does not know as ``str``)."""
    return write_text(json.dumps(obj, indent=2, sort_keys=sort_keys, default=str), path)


def write_text(text: str, path: str | Path) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")
    return path


def write_bytes(data: bytes, path: str | Path) -> Path:
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return path


def write_npz(path: str | Path, **arrays) -> Path:
    """``np.savez`` of *arrays* to *path* atomically."""
    import numpy as np

    path = Path(path)
    with atomic_path(path, suffix=".npz") as tmp:
        np.savez(tmp, **arrays)
    return path


def npz_member(file, name: str) -> tuple | None:
    """Where the array *name* of an uncompressed ``.npz`` (:func:`write_npz`) lies in it, for
    a reader that seeks to it (``np.fromfile``, ``np.memmap``): ``(offset, dtype, shape,
    order)``; ``None`` when the member is compressed
    or not a plain array.  *file*: the ``.npz`` opened in binary mode (read, then left where
    it was); :class:`KeyError` when it has no such member."""
    import struct
    import zipfile

    import numpy as np

    at = file.tell()
    try:
        with zipfile.ZipFile(file) as zf:
            info = zf.getinfo(name + ".npy")
        if info.compress_type != zipfile.ZIP_STORED:
            return None
        # the member's local header (30 bytes, then its name and extra field), then the array
        file.seek(info.header_offset)
        head = file.read(30)
        if len(head) < 30 or head[:4] != b"PK\x03\x04":
            return None
        n_name, n_extra = struct.unpack("<HH", head[26:30])
        file.seek(info.header_offset + 30 + n_name + n_extra)
        read = {(1, 0): np.lib.format.read_array_header_1_0,
                (2, 0): np.lib.format.read_array_header_2_0}.get(np.lib.format.read_magic(file))
        if read is None:
            return None
        shape, fortran, dtype = read(file)
        if dtype.hasobject:
            return None
        return file.tell(), dtype, shape, "F" if fortran else "C"
    finally:
        file.seek(at)


def _plain_table(df):
    """*df* as a pyarrow Table built column by column from numpy, when every column is a
    number (pandas' nullable ones with their gaps as nulls), bool, datetime64 or string
    (the partition and geometry tables); ``None`` otherwise (GeoDataFrames, categoricals,
    ...), for pandas to convert."""
    import numpy as np
    import pandas as pd
    import pyarrow as pa

    if hasattr(df, "geometry") or not df.columns.is_unique:
        return None
    arrays = _numpy_columns(df) if len(df.columns) > WIDE_COLUMNS else {}
    for i, name in enumerate(df.columns):
        if i in arrays:
            continue
        col = df[name]
        kind = col.dtype.kind
        if isinstance(col.dtype, np.dtype) and kind in "biufM":
            arrays[i] = pa.array(col.to_numpy())
        elif kind in "biuf" and hasattr(col.array, "__arrow_array__"):
            # pandas' nullable numbers and bools: their gaps as nulls (as NaN from numpy)
            arrays[i] = pa.array(col.array)
        elif pd.api.types.is_string_dtype(col.dtype) and not isinstance(col.dtype, pd.CategoricalDtype):
            try:        # object columns may hold anything: only real strings take this path
                arr = (pa.array(col.array) if hasattr(col.array, "__arrow_array__")
                       else pa.array(col.to_numpy(dtype=object), from_pandas=True))
            except (pa.ArrowInvalid, pa.ArrowTypeError):
                return None
            if not (pa.types.is_string(arr.type) or pa.types.is_large_string(arr.type)
                    or (pa.types.is_null(arr.type) and col.dtype != object)):
                return None
            arrays[i] = arr.cast(pa.string())
        else:
            return None
    arrays = [arrays[i] for i in range(len(df.columns))]
    return pa.Table.from_arrays(arrays, names=[str(c) for c in df.columns])


def _numpy_columns(df) -> dict:
    """The plain numpy columns of a wide *df* (numbers, bools, naive datetimes) as Arrow
    arrays by column position, taken out one 2-D block per dtype: the geometry partitions
    have about a thousand columns, and one pandas lookup per column cost more than writing
    them (for a narrow table the block costs more than the lookups)."""
    import numpy as np
    import pyarrow as pa

    by_dtype: dict = {}
    for i, dtype in enumerate(df.dtypes):
        if isinstance(dtype, np.dtype) and dtype.kind in "biufM":
            by_dtype.setdefault(dtype, []).append(i)
    arrays = {}
    for positions in by_dtype.values():
        block = np.ascontiguousarray(df.iloc[:, positions].to_numpy().T)
        arrays.update({i: pa.array(block[j]) for j, i in enumerate(positions)})
    return arrays


def _arrow_table(df):
    """*df* as pyarrow converts it for ``to_parquet`` (GeoDataFrames with their GeoParquet
    metadata)."""
    import pyarrow as pa

    if hasattr(df, "geometry"):
        # geopandas' own conversion of to_parquet (WKB geometry, "geo" schema metadata)
        from geopandas.io.arrow import _geopandas_to_arrow

        return _geopandas_to_arrow(df, index=False)
    return pa.Table.from_pandas(df, preserve_index=False)


# --------------------------------------------------------------------------- whole folders
def staging_dir(final: str | Path) -> Path:
    """An empty folder beside *final* (``.<name>-ingest-<pid>``) to write a new version of
    *final* into before :func:`swap_dir`; what killed ingests left there is cleaned up first
    (:func:`remove_stale`)."""
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(final)
    stage = final.with_name(f".{final.name}-ingest-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    return stage


def swap_dir(new: Path, final: Path) -> None:
    """Replace folder *final* by *new* as a whole (two renames; a reader sees the old or the
    new version, never a mix of files; :func:`remove_stale` repairs a kill between them)."""
    old = final.with_name(f".{final.name}-old-{os.getpid()}")
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    new.rename(final)
    shutil.rmtree(old, ignore_errors=True)


def set_aside(folder: Path, tag: str) -> Path:
    """Rename *folder* to ``.<name>.replaced-<tag>-<pid>`` beside it in one step (for the
    caller to delete); the aside folders of earlier, interrupted calls are :func:`aside_folders`."""
    aside = folder.parent / f".{folder.name}.replaced-{tag}-{os.getpid()}"
    os.replace(folder, aside)
    return aside


def aside_folders(folder: Path) -> list[Path]:
    """The folders :func:`set_aside` left beside *folder*."""
    return sorted(folder.parent.glob(f".{folder.name}.replaced-*"))


def remove_stale(final: str | Path) -> list[Path]:
    """Clean up beside folder *final* after killed ingests; return the paths removed.

    ``.<name>-ingest-<pid>`` (an unfinished new version) goes when its process is gone;
    ``.<name>-old-<pid>`` (the previous version, when the kill came between the two renames of
    :func:`swap_dir`) is put back if *final* is missing, else removed.
    """
    final = Path(final)
    removed = []
    for p in sorted(final.parent.glob(f".{final.name}-old-*")):
        if _stale(p):
            if not final.exists():
                p.rename(final)
                continue
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    for p in sorted(final.parent.glob(f".{final.name}-ingest-*")):
        if p.is_dir() and _stale(p):
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    return removed


def _stale(path: Path) -> bool:
    """A ``...-<pid>`` folder whose process is gone."""
    pid = path.name.rsplit("-", 1)[-1]
    return pid.isdigit() and not pid_alive(int(pid))


def pid_alive(pid: int) -> bool:
    """Whether a process of this id runs (it may be another user's)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


class FolderLock:
    """An advisory lock (``flock``) on the file *path*, guarding *folder* against a second
    vipvflow process: exclusive for whoever writes, shared for readers that need it to stay
    as it is. Taken without waiting (:meth:`take` says whether it was); released by
    :meth:`release`, or by the operating system when the process ends, however it ends. The
    exclusive holder writes its process id into the file, for the refusal of another."""

    def __init__(self, path: str | Path, folder: str | Path):
        self.path, self.folder = Path(path), Path(folder)
        self._fh = None

    def take(self, shared: bool = False) -> bool:
        """Take the lock (shared or exclusive; an exclusive one held is converted); False
        when another process holds it in a way that excludes this."""
        try:
            import fcntl
        except ImportError:             # not POSIX: no locking
            return True
        if self._fh is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fh = open(self.path, "a+", encoding="utf-8")
        try:
            fcntl.flock(self._fh, (fcntl.LOCK_SH if shared else fcntl.LOCK_EX) | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        if not shared:
            self._fh.seek(0)
            self._fh.truncate()
            self._fh.write(f"{os.getpid()}\n")
            self._fh.flush()
        return True

    def holder(self) -> str:
        """`` (pid N)`` of the process that last took the lock exclusively, when it runs."""
        try:
            pid = int(self.path.read_text().split()[0])
        except (OSError, ValueError, IndexError):
            return ""
        return f" (pid {pid})" if pid != os.getpid() and pid_alive(pid) else ""

    def release(self) -> None:
        if self._fh is not None:
            self._fh.close()            # closing the file releases the lock
            self._fh = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()


def run_dir_lock(run_dir: str | Path) -> FolderLock:
    """The lock of a run folder: ``.<year>.lock`` beside it (it outlives the folder's
    replacement by ``--force``)."""
    run_dir = Path(run_dir)
    return FolderLock(run_dir.parent / f".{run_dir.name}.lock", run_dir)


def data_dir_lock(data_dir: str | Path) -> FolderLock:
    """The lock of a data dir: ``.<name>.lock`` beside it (the data dir holds only what the
    ingests write), or ``.lock`` in it where its parent folder is not writable; ingests hold
    it exclusively, runs shared while they read the data dir."""
    data_dir = Path(data_dir)
    parent = data_dir.absolute().parent
    beside = parent / f".{data_dir.absolute().name}.lock"
    if beside.exists() or (parent.is_dir() and os.access(parent, os.W_OK)) or not parent.exists():
        return FolderLock(beside, data_dir)
    return FolderLock(data_dir / ".lock", data_dir)


def lock_for_writing(lock: FolderLock, doing: str) -> FolderLock:
    """*lock* taken exclusively, or :class:`InputError` in one line naming the folder and
    the process holding it."""
    if not lock.take():
        raise InputError(f"{lock.folder}: another vipvflow process{lock.holder()} is using this "
                         f"folder; wait for it to finish, then {doing} again")
    return lock


def file_path(path: str | Path, what: str, example: str) -> Path:
    """*path* as a file to write: :class:`InputError` naming it when it is a folder (the
    file *example* in it is suggested), or a folder above it exists as a file."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{path}: {what} names a folder; give the file to write, e.g. "
                         f"{path / example}")
    folder_path(path.parent, f"the folder of {what}")
    return path


def folder_path(path: str | Path, what: str) -> Path:
    """*path* as a folder to write into: :class:`InputError` naming it when it, or a folder
    above it, exists as something else than a folder (a file named as ``--out``)."""
    path = Path(path)
    for p in (path, *path.parents):
        if p.exists() or p.is_symlink():
            if not p.is_dir():
                where = "" if p == path else f" (in {path})"
                raise InputError(f"{p}: {what} must be a folder, and this is a file{where}")
            break
    return path


def sha256(path: str | Path) -> str:
    """SHA-256 hex digest of a file, read in 1 MiB blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()
