"""The tiles' geometry kept in the data dir for the next run that needs the same.

A tile's geometry (:func:`vipvflow.simulation.partition.tile_geometry`: sky view factors,
reflectors, the Perez sky's cells, the horizon profiles) depends on the tile's segments, its
mesh and trees, the ``irradiance`` settings, the street options and the code that computes
it, and on nothing a run changes more often: not the year, the weather, the months, the
routes' timetables, the bus or the PV system.  It was a fifth to a quarter of a run's worker
time (benchmarks/README), paid again by every run of the same city.

Each tile's files are kept under ``<data_dir>/cache/geometry/<key>/`` (``geometry.parquet``
and ``horizon.parquet``, the run's own ``parts/`` files linked or copied), where *key* is
the SHA-256 of all of the above: the segments' rows as the physics takes them, the mesh
and tree files' bytes, the settings, and the source of :mod:`vipvflow.models` with the
versions of the libraries whose arithmetic it uses.  A change to any of them is another
key: an entry is never used for other inputs, only found again for the same.  The files
are written under temporary names and renamed, the geometry last: an entry without its
geometry file is not one.  The folder may be deleted at any time (the next run computes
the geometry again).
"""
from __future__ import annotations

import hashlib
import json
import os
import shutil
from pathlib import Path

import pandas as pd

from ..models import code_digest
from ..store import GEOMETRY_CACHE_FILES, DataDir, atomic_path


def _file_digest(path: Path) -> bytes:
    if not path.is_file():
        return b"absent"
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.digest()


def tile_key(data_dir, tile: str, segments: pd.DataFrame, settings: dict, modelled: bool) -> str:
    """The key of *tile*'s geometry: its *segments* (the rows the physics takes, with their
    columns' names and types), its mesh and trees files in *data_dir*, whether the city
    model covers it (*modelled*), the *settings* (``irradiance`` and the street options)
    and :func:`code_digest`."""
    city = DataDir(data_dir).city
    h = hashlib.sha256()
    h.update(code_digest().encode())
    h.update(json.dumps({"tile": tile, "settings": settings, "modelled": bool(modelled)},
                        sort_keys=True, default=str).encode())
    h.update(json.dumps([[str(c), str(t)] for c, t in segments.dtypes.items()]).encode())
    h.update(pd.util.hash_pandas_object(segments, index=True).to_numpy().tobytes())
    h.update(_file_digest(city.mesh(tile)))
    h.update(_file_digest(city.trees_file(tile)))
    return h.hexdigest()[:40]


def entry(data_dir, key: str) -> Path:
    """The folder of the entry *key* in *data_dir*."""
    return DataDir(data_dir).geometry_cache(key)


def fetch(data_dir, key: str, geometry_path: Path, horizon_path: Path) -> bool:
    """Place the entry *key*'s files at *geometry_path* and *horizon_path* (a run's parts;
    the horizon first, the geometry last, each renamed into place); False when there is no
    such entry (or it went while being read)."""
    geometry, horizon = (entry(data_dir, key) / name for name in GEOMETRY_CACHE_FILES)
    if not (geometry.is_file() and horizon.is_file()):
        return False
    try:
        _place(horizon, Path(horizon_path))
        _place(geometry, Path(geometry_path))
    except FileNotFoundError:               # the entry deleted meanwhile
        Path(horizon_path).unlink(missing_ok=True)
        return False
    return True


def keep(data_dir, key: str, geometry_path: Path, horizon_path: Path) -> None:
    """Keep a run's geometry and horizon files of a tile as the entry *key* (the horizon
    first, the geometry last).  A cache that cannot be written (a read-only data dir, a
    full disk) is skipped: the run has its files."""
    dest = entry(data_dir, key)
    geometry, horizon = (dest / name for name in GEOMETRY_CACHE_FILES)
    try:
        _place(Path(horizon_path), horizon)
        _place(Path(geometry_path), geometry)
    except OSError:
        shutil.rmtree(dest, ignore_errors=True)


def _place(src: Path, dest: Path) -> None:
    """*src* at *dest*: a hard link where both lie on one file system (the files are never
    written again in place: every writer renames a new file over the old), else a copy;
    under a temporary name, renamed, its time of change set to now (the file is placed by
    this run: a run folder's files are never older than the run).  A failed copy names
    *dest* (a full or read-only disk is the destination's); a missing *src* raises
    FileNotFoundError."""
    with atomic_path(dest) as tmp:
        try:
            os.link(src, tmp)
        except FileNotFoundError:
            raise
        except OSError:
            try:
                shutil.copyfile(src, tmp)
            except FileNotFoundError:
                raise
            except OSError as exc:
                raise OSError(exc.errno, exc.strerror, str(dest)) from None
        os.utime(tmp)
