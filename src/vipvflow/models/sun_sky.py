"""The sun and the sky of every minute of a year.

Sun positions (pvlib) and the radiation lookup table
(:class:`RadiationTable`) of the ingested ``radiation/`` folder, interpolated
to pass times.
"""
from __future__ import annotations

import json
import logging
import os
import weakref
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from ..inputs.cams import _GRID_S, COLUMNS, ingest_cams
from ..store import DataDir, RadiationDir, npz_member, write_npz
from . import code_digest
from .sky import (SKY_AZIMUTH_BINS, SKY_PACK, SKY_STEP_S, open_terms, pack_sky, perez_table,
                  sky_table, unpack_sky)

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- sun
def sun_vectors(t_utc, lat, lon, altitude, step_s: float = 300.0) -> np.ndarray:
    """Unit vectors towards the sun (east, north, up) on a time grid, (3, K, N) float32.

    pvlib's solar position (SPA, apparent zenith) every *step_s* seconds, its unit vector
    interpolated linearly to the grid *t_utc* (Unix s) and normalised.

    Parameters
    ----------
    t_utc : (N,) float, Unix s;  lat, lon : (K,) degrees;  altitude : (K,) m

    References
    ----------
    pvlib ``solarposition.get_solarposition`` (NREL SPA: Reda and Andreas, Solar Energy 76,
    2004).
    """
    import pvlib

    t = np.asarray(t_utc, np.float64)
    lat, lon = np.atleast_1d(lat), np.atleast_1d(lon)
    alt = np.broadcast_to(np.asarray(altitude, np.float64), lat.shape)
    sun = np.empty((3, len(lat), len(t)), np.float32)
    coarse = np.arange(t[0] - step_s, t[-1] + 2 * step_s, step_s)
    times = pd.to_datetime(np.round(coarse * 1e3).astype(np.int64), unit="ms", utc=True)
    for i in range(len(lat)):
        sp = pvlib.solarposition.get_solarposition(times, lat[i], lon[i], altitude=alt[i])
        z, a = np.radians(sp["apparent_zenith"].to_numpy()), np.radians(sp["azimuth"].to_numpy())
        for j, comp in enumerate((np.sin(z) * np.sin(a), np.sin(z) * np.cos(a), np.cos(z))):
            sun[j, i] = np.interp(t, coarse, comp)
    return sun / np.sqrt((sun ** 2).sum(axis=0))


#: the Perez sky's coefficients a radiation table holds per time step, all-sky and clear-sky
#: (:func:`vipvflow.models.sky.perez_table`)
PEREZ_COLUMNS = ("f1", "f2", "f1_clear", "f2_clear")


def _perez(t_utc, values: dict, sun_z) -> dict:
    """The Perez coefficients (:data:`PEREZ_COLUMNS`) of *values*' DHI and DNI (all-sky and
    clear-sky, (K, N)) on the grid *t_utc* with the sun's up component *sun_z*."""
    out = {}
    for sfx in ("", "_clear"):
        out["f1" + sfx], out["f2" + sfx] = perez_table(t_utc, values["dhi" + sfx], values["dni" + sfx], sun_z)
    return out


def _sky_tables(grid_t0: float, n_steps: int, table: "RadiationTable", k: int) -> dict:
    """The Perez (1993) visible-sky tables of location *k* every :data:`SKY_STEP_S` from
    *grid_t0*: ``rows`` (n_steps,) int32 (-1 where the sun is more than 3 deg below the
    horizon), ``all`` and ``clear`` (rows, 36, 9) float32 (:func:`vipvflow.models.sky.sky_table`)."""
    import pvlib

    t = grid_t0 + SKY_STEP_S * np.arange(n_steps)
    v = table.lookup(t, location=k, angles=False)
    sun = np.stack([v["sun_x"], v["sun_y"], v["sun_z"]], 1).astype(np.float64)
    day = np.nan_to_num(v["sun_z"], nan=-1.0) > -0.05
    rows = np.full(n_steps, -1, np.int32)
    rows[day] = np.arange(int(day.sum()), dtype=np.int32)
    times = pd.DatetimeIndex(pd.to_datetime(np.round(t[day] * 1e3).astype(np.int64), unit="ms", utc=True))
    e0 = np.asarray(pvlib.irradiance.get_extra_radiation(times.day_of_year.to_numpy()), np.float64)
    out = {"rows": rows}
    for sfx, name in (("", "all"), ("_clear", "clear")):
        out[name], out[name + "_h"] = sky_table(v["dhi" + sfx][day], v["dni" + sfx][day], e0, sun[day])
        out[name + "_open"] = open_terms(out[name + "_h"])
    return out


#: what the sky tables' file holds: the four tables packed (:func:`vipvflow.models.sky.pack_sky`)
#: and stored by table row (``packed_rows``: the packed array's transpose, so that the rows of
#: a few days are one contiguous read, :meth:`RadiationTable.sky_window`)
_SKY_KEYS = ("rows", "packed_rows", "all_open", "clear_open")
_SKY_TABLES = ("all", "all_h", "clear", "clear_h")
_SKY_OPEN = ("all_open", "clear_open")
#: :meth:`RadiationTable.sky_window` also reads the rows up to this long after the end of
#: the month (UTC) of its passes' last (a month's next chunks of passes come in order: one
#: read serves them all; a service day's last trips end after midnight)
SKY_READ_AHEAD_S = 86400


def _identity(st: os.stat_result) -> tuple:
    """A file's identity for a reader that opens it again: device, inode, size, time."""
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


# --------------------------------------------------------------------------- lookup
#: the tables this process maps from their caches (:meth:`RadiationTable.load`)
_MAPPED: list = []

#: the filesystems a table is mapped from: on these a cache written again while a process
#: maps it (another run's code on the same data dir) is a new file, and the mapping keeps
#: the old one's pages.  Elsewhere (NFS, SMB, Ceph, FUSE, ... : a worker of a cluster
#: reading a shared data dir) a page read again after :func:`release_mapped_pages` could come
#: from a file another host has removed, and the process would die of ``SIGBUS``: the table
#: is read into memory there.
MAPPED_FILESYSTEMS = frozenset({"ext2", "ext3", "ext4", "xfs", "btrfs", "zfs", "f2fs", "jfs",
                                "bcachefs", "nilfs2", "reiserfs", "tmpfs", "ramfs", "overlay",
                                "squashfs", "erofs"})


def filesystem_of(path, mountinfo: str | Path = "/proc/self/mountinfo") -> str | None:
    """The type of the filesystem holding *path* (``ext4``, ``nfs4``, ...), from the mount
    with the longest mount point that contains it (the last of equal ones: it hides the
    others); ``None`` where the mount table cannot be read (not Linux)."""
    try:
        lines = Path(mountinfo).read_text().splitlines()
    except OSError:
        return None
    where = os.path.realpath(path)
    best, kind = -1, None
    for line in lines:
        fields = line.split()
        if " - " not in line or len(fields) < 5:
            continue
        point = fields[4].replace("\\040", " ").replace("\\011", "\t").replace("\\134", "\\")
        inside = point == "/" or where == point or where.startswith(point.rstrip("/") + "/")
        if inside and len(point) >= best:
            best, kind = len(point), line.split(" - ", 1)[1].split()[0]
    return kind


def _map_member(path: Path, name: str) -> tuple | None:
    """The array *name* of the uncompressed ``.npz`` *path* mapped from the file, private
    and copy-on-write (writeable, like an array read into memory; nothing is ever written
    back): ``(array, mmap)``; ``None`` when it cannot be mapped (compressed, misaligned for
    its type, no ``mmap``) or is not to be (on a filesystem not in
    :data:`MAPPED_FILESYSTEMS`), for the caller to read it."""
    import mmap

    if filesystem_of(path) not in MAPPED_FILESYSTEMS:
        return None
    with open(path, "rb") as fh:
        where = npz_member(fh, name)
        if where is None:
            return None
        offset, dtype, shape, order = where
        if offset % dtype.alignment:
            return None
        try:
            m = mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_COPY)
        except (OSError, ValueError):
            return None
    return np.ndarray(shape, dtype, buffer=m, offset=offset, order=order), m


def release_mapped_pages() -> None:
    """Let the operating system take back the pages of the radiation tables this process
    maps (:meth:`RadiationTable.load`): they are read again from the file (the page cache)
    where next needed.  A tile task's end calls it
    (:func:`vipvflow.simulation.partition.hand_back_memory`): a worker's RSS then holds the
    month it is computing, not every month it has computed (~27 MB a location for a
    year, in each worker)."""
    import mmap

    if not hasattr(mmap, "MADV_DONTNEED"):
        return
    alive = []
    for ref in _MAPPED:
        table = ref()
        if table is not None and table.__dict__.get("_map") is not None:
            table.__dict__["_map"].madvise(mmap.MADV_DONTNEED)
            alive.append(ref)
    _MAPPED[:] = alive


@dataclass
class RadiationTable:
    """Radiation and sun position on a regular time grid, for K locations.

    Attributes
    ----------
    t0 : float, Unix s of grid point 0
    step_s : float, grid step (s)
    data : dict name -> (K, N) float32; ``ghi ... dhi_clear`` (W/m2), the sun unit vector
        ``sun_x, sun_y, sun_z`` (east, north, up; from pvlib apparent zenith and azimuth) and
        the Perez coefficients ``f1, f2, f1_clear, f2_clear`` (dimensionless)
    lat, lon : (K,) float64, degrees

    References
    ----------
    CAMS solar radiation time series (Copernicus Atmosphere Monitoring Service; Qu et al.,
    Meteorol. Z. 26, 2017): GHI, DHI, BNI and their clear-sky values per minute.
    """

    t0: float
    step_s: float
    data: dict
    lat: np.ndarray
    lon: np.ndarray

    def _packed(self):
        """All series as one (K, N, C) float32 array: one gather per pass instead of C.
        The float32 series of :attr:`data` are then views into it (the table holds each
        value once: ~26 MB for a year and one location)."""
        cache = self.__dict__.get("_pack")
        if cache is None or cache[0] != tuple(self.data) or any(
                cache[2][c] is not self.data[c] for c in self.data):
            names = tuple(self.data)
            packed = np.ascontiguousarray(np.stack([self.data[c] for c in names], axis=-1),
                                          dtype=np.float32)
            for j, c in enumerate(names):
                if self.data[c].dtype == np.float32 and self.data[c].shape == packed.shape[:2]:
                    self.data[c] = packed[..., j]
            cache = (names, packed, dict(self.data))
            self.__dict__["_pack"] = cache
        return cache[0], cache[1]

    def _light(self) -> np.ndarray:
        """(K, N) bool: grid intervals [i, i + 1] in which any radiation value is non-zero or
        missing (NaN) at either end; outside them every interpolated value is exactly 0."""
        cache = self.__dict__.get("_light_cache")
        arrays = tuple(self.data[c] for c in COLUMNS)
        if cache is None or any(a is not b for a, b in zip(cache[0], arrays)):
            lit = np.zeros(self.data["ghi"].shape, bool)
            for a in arrays:
                lit |= (a != 0) | np.isnan(a)
            lit[:, :-1] |= lit[:, 1:]
            cache = (arrays, lit)
            self.__dict__["_light_cache"] = cache
        return cache[1]

    def has_light(self, t_utc, location=None) -> np.ndarray:
        """Whether radiation may be non-zero at each time (bool array).

        ``False`` means every value :meth:`lookup` would return at that time is exactly 0
        (night, in CAMS), so callers may skip the pass; times outside the grid are ``True``
        (their lookup is NaN, handled by the caller).

        Parameters
        ----------
        t_utc : array of float, Unix seconds
        location : None, int or int array, as in :meth:`lookup`
        """
        t = np.asarray(t_utc, dtype=np.float64)
        f = (t - self.t0) / self.step_s
        inside = (f >= 0) & (f <= self.n - 1)
        i = np.clip(np.nan_to_num(f), 0, self.n - 1).astype(np.int64)
        lit = self._light()
        loc = 0 if location is None else np.asarray(location, np.int64)
        return lit[loc, i] | ~inside

    @property
    def n(self) -> int:
        return self.data["ghi"].shape[1]

    @property
    def t_end(self) -> float:
        return self.t0 + (self.n - 1) * self.step_s

    @classmethod
    def from_grid(cls, t_utc, values: dict, lat, lon, altitude=0.0, sun_step_s: float = 300.0,
                  sun: np.ndarray | None = None, perez: dict | None = None):
        """Build from arrays on a regular grid; computes the sun position once.

        Parameters
        ----------
        t_utc : (N,) Unix seconds, regular
        values : dict of (N,) or (K, N) arrays, W/m2, keys :data:`COLUMNS`
        lat, lon, altitude : float or (K,), degrees, m
        sun_step_s : float
            pvlib's solar position is evaluated every ``sun_step_s`` and the unit vector
            interpolated (chord error below 1e-4 degrees for 5 min).
        sun : (3, K, N) float32, optional
            The unit sun vectors of an earlier call on the same grid (see :meth:`load`).
        perez : dict of (K, N) float32, optional
            The Perez coefficients (:data:`PEREZ_COLUMNS`) of an earlier call on the same
            grid and values (see :meth:`load`).
        """
        t = np.asarray(t_utc, dtype=np.float64)
        lat = np.atleast_1d(np.asarray(lat, np.float64))
        lon = np.atleast_1d(np.asarray(lon, np.float64))
        alt = np.broadcast_to(np.asarray(altitude, np.float64), lat.shape)
        step = float(t[1] - t[0]) if len(t) > 1 else 60.0
        if len(t) > 2 and np.abs(np.diff(t) - step).max() > 1e-6:
            raise ValueError("time grid is not regular")
        data = {c: np.atleast_2d(np.asarray(values[c], np.float32)) for c in COLUMNS}
        k = len(lat)
        for c in COLUMNS:
            if data[c].shape[0] != k:
                data[c] = np.broadcast_to(data[c], (k, len(t))).copy()
        if sun is None:
            sun = sun_vectors(t, lat, lon, alt, sun_step_s)
        for j, name in enumerate(("sun_x", "sun_y", "sun_z")):
            data[name] = sun[j]
        # the Perez sky's circumsolar and horizon coefficients of every time step, all-sky
        # and clear-sky (models.sky): looked up per pass like the radiation
        data.update(perez if perez is not None else _perez(t, data, data["sun_z"]))
        return cls(t0=float(t[0]), step_s=step, data=data, lat=lat, lon=lon)

    @classmethod
    def load(cls, data_dir, year: int, pad_days: float = 1.0) -> "RadiationTable":
        """Load ``radiation/radiation.parquet`` for *year* (UTC, padded by *pad_days*).

        The first load of a year puts the table on its minute grid with its sun vectors and
        Perez coefficients beside the file (``table_<year>.npz``, uncompressed: the series
        interleaved as :meth:`_packed` holds them); each later load (a run's workers) maps
        them from there: no Parquet read (~0.1 GB of a process's memory for a moment), no
        SPA and no pvlib, and the process holds the pages of the minutes it reads until
        :func:`release_mapped_pages` lets them go (a tile task reads one month's, ~2 MB of
        the year's ~27 MB a location; on a filesystem not in :data:`MAPPED_FILESYSTEMS`,
        NFS, SMB, FUSE, ..., it reads them into memory instead).  The cache names the
        radiation file's size and time, *year*, *pad_days*, and the code and libraries that
        computed it
        (:func:`vipvflow.models.code_digest`), and is written again when any differ or a
        member is missing (and not written where the folder is read-only).

        Raises
        ------
        InputError
            When the file is missing or does not cover any of the year.
        """
        path = DataDir(data_dir).radiation.table
        if not path.is_file():
            raise InputError(f"{path}: not found; run 'vipvflow ingest cams' first")
        st = path.stat()
        key = json.dumps(["table-2", code_digest(), st.st_size, st.st_mtime_ns, year, pad_days])
        cache = RadiationDir(path.parent).table_cache(year)
        out = None
        try:
            with np.load(cache) as z:
                if str(z["key"]) == key:
                    names = tuple(str(c) for c in z["names"])
                    mapped = _map_member(cache, "packed")
                    packed = z["packed"] if mapped is None else mapped[0]
                    if packed.shape[:2] != (len(z["lat"]), int(z["n"])) or len(names) != packed.shape[2]:
                        raise ValueError("packed table of another shape")
                    data = {c: packed[..., j] for j, c in enumerate(names)}
                    out = cls(t0=float(z["t0"]), step_s=float(_GRID_S), data=data,
                              lat=np.array(z["lat"], np.float64), lon=np.array(z["lon"], np.float64))
                    out.__dict__["_pack"] = (names, packed, dict(data))
                    covered = float(z["covered"])
                    if mapped is not None:
                        out.__dict__["_map"] = mapped[1]
                        _MAPPED.append(weakref.ref(out))
        except (OSError, KeyError, ValueError):
            out = None
        if out is None:
            grid, locs, values, covered = cls._grid_of(path, year, pad_days)
            sun = sun_vectors(grid, locs[:, 0], locs[:, 1], locs[:, 2])
            perez = _perez(grid, values, sun[2])
            out = cls.from_grid(grid, values, locs[:, 0], locs[:, 1], locs[:, 2], sun=sun, perez=perez)
            names, packed = out._packed()
            try:
                # the interleaved series first: their place in the file is then a multiple
                # of 4 bytes, which the mapping needs (np.savez writes in this order)
                write_npz(cache, packed=packed, names=np.array(names), key=np.array(key),
                          t0=np.float64(out.t0), n=np.int64(out.n), lat=locs[:, 0],
                          lon=locs[:, 1], alt=locs[:, 2], covered=np.float64(covered))
            except OSError:
                pass
        if covered < 1.0:
            log.warning("%s: %.1f %% of %d's minute grid has no radiation (NaN)", path,
                        100 * (1 - covered), year)
        out.__dict__["_source"] = str(path)            # where the sky tables are cached
        return out

    def __getstate__(self) -> dict:
        """Pickled without the file mapping (its arrays are pickled as values)."""
        state = dict(self.__dict__)
        state.pop("_map", None)
        return state

    @staticmethod
    def _grid_of(path: Path, year: int, pad_days: float) -> tuple:
        """The radiation file's rows of *year* (padded by *pad_days*) on their minute grid:
        ``(grid, locs, values, covered)``: the grid (N,) Unix s, the locations (K, 3) lat,
        lon, altitude, the :data:`COLUMNS` (K, N) float32 (NaN where a minute has no row)
        and the share of the grid the GHI covers."""
        lo = pd.Timestamp(f"{year}-01-01", tz="UTC").timestamp() - pad_days * 86400
        hi = pd.Timestamp(f"{year + 1}-01-01", tz="UTC").timestamp() + pad_days * 86400
        table = pd.read_parquet(path, filters=[("t_utc", ">=", int(lo)), ("t_utc", "<", int(hi))])
        if table.empty:
            raise InputError(f"{path}: holds no radiation for {year} (re-ingest CAMS data "
                             f"covering {year})")
        locs = table[["lat", "lon"]].drop_duplicates().to_numpy()
        t_all = table["t_utc"].to_numpy()
        grid = np.arange(t_all.min(), t_all.max() + 1, _GRID_S, dtype=np.float64)
        values = {c: np.full((len(locs), len(grid)), np.nan, np.float32) for c in COLUMNS}
        alts = []
        for i, (la, lo_) in enumerate(locs):
            part = table[(table["lat"] == la) & (table["lon"] == lo_)]
            idx = ((part["t_utc"].to_numpy() - grid[0]) // _GRID_S).astype(np.int64)
            for c in COLUMNS:
                values[c][i, idx] = part[c].to_numpy(np.float32)
            alts.append(float(part["altitude"].iloc[0]) if "altitude" in part else 0.0)
        locs = np.column_stack([locs.astype(np.float64), np.array(alts, np.float64)])
        return grid, locs, values, float(np.isfinite(values["ghi"]).mean())

    @classmethod
    def from_cams(cls, paths, accept=()) -> "RadiationTable":
        """Read CAMS files straight into a table (no data dir), for single runs and tracks
        (*accept*: the plausibility findings accepted, see :func:`ingest_cams`)."""
        import tempfile

        with tempfile.TemporaryDirectory() as tmp:
            ingest_cams(paths, tmp, accept=accept)
            table = pd.read_parquet(DataDir(tmp).radiation.table)
        locs = table[["lat", "lon", "altitude"]].drop_duplicates().to_numpy()
        grid = np.arange(table["t_utc"].min(), table["t_utc"].max() + 1, _GRID_S, dtype=np.float64)
        values = {c: np.full((len(locs), len(grid)), np.nan, np.float32) for c in COLUMNS}
        for i, (la, lo_, _) in enumerate(locs):
            part = table[(table["lat"] == la) & (table["lon"] == lo_)]
            idx = ((part["t_utc"].to_numpy() - grid[0]) // _GRID_S).astype(np.int64)
            for c in COLUMNS:
                values[c][i, idx] = part[c].to_numpy(np.float32)
        return cls.from_grid(grid, values, locs[:, 0], locs[:, 1], locs[:, 2])

    def sky(self) -> dict:
        """The Perez (1993) sky's visible-share tables of every location, every
        :data:`vipvflow.models.sky.SKY_STEP_S` from the grid's start (``diffuse_model:
        perez_svf``): ``t0``, ``step``, ``rows`` (K, n_steps) int32 (-1 at night) into
        ``all``, ``all_h``, ``clear`` and ``clear_h`` (rows, 36, 10) float32 (the ``_h``
        tables the tilt term, :func:`vipvflow.models.sky.sky_table`) and ``all_open``,
        ``clear_open`` (rows, 2) (:func:`vipvflow.models.sky.open_terms`).  Computed once per
        table (a few seconds for a year) and kept beside the radiation file where it came
        from one (:meth:`load`)."""
        cache = self.__dict__.get("_sky")
        if cache is not None:
            return cache
        n_steps = int(np.floor((self.t_end - self.t0) / SKY_STEP_S)) + 2
        key, file = self._sky_key()
        if key is not None:
            try:
                with np.load(file) as z:
                    if str(z["key"]) == key:
                        cache = {k: z[k] for k in _SKY_KEYS}
                        cache["packed"] = np.ascontiguousarray(cache.pop("packed_rows").T)
            except (OSError, KeyError, ValueError):
                cache = None
        if cache is None:
            parts = [_sky_tables(self.t0, n_steps, self, k) for k in range(len(self.lat))]
            offset = np.cumsum([0] + [len(p["all"]) for p in parts])
            cache = {"rows": np.stack([np.where(p["rows"] >= 0, p["rows"] + offset[i], -1)
                                       for i, p in enumerate(parts)]).astype(np.int32),
                     **{k: np.concatenate([p[k] for p in parts]) for k in _SKY_OPEN},
                     "packed": pack_sky({k: np.concatenate([p[k] for p in parts]) for k in _SKY_TABLES})}
            if key is not None:
                try:
                    write_npz(file, key=np.array(key), packed_rows=np.ascontiguousarray(cache["packed"].T),
                              **{k: cache[k] for k in _SKY_KEYS if k != "packed_rows"})
                except OSError:
                    pass
        # the four tables are kept once, interleaved for the compiled kernel, and read as views
        packed = cache["packed"]
        shape = (packed.shape[1], SKY_AZIMUTH_BINS, packed.shape[0] // SKY_PACK // SKY_AZIMUTH_BINS)
        cache = {**cache, **unpack_sky(packed, shape), "t0": float(self.t0), "step": float(SKY_STEP_S)}
        self.__dict__["_sky"] = cache
        return cache

    def _sky_key(self) -> tuple:
        """The key of :meth:`sky`'s tables (the radiation file's size and time, the grid,
        the locations, :func:`vipvflow.models.code_digest`) and the file beside the
        radiation file that keeps them; ``(None, None)`` for a table that did not come
        from a file."""
        path = self.__dict__.get("_source")
        if path is None:
            return None, None
        st = Path(path).stat()
        key = json.dumps(["sky-6", code_digest(), st.st_size, st.st_mtime_ns, self.t0, self.n,
                          SKY_STEP_S, np.round(self.lat, 8).tolist(),
                          np.round(self.lon, 8).tolist()])
        return key, RadiationDir(Path(path).parent).sky_cache(int(self.t0), self.n)

    def sky_index(self) -> dict:
        """:meth:`sky`'s tables without their values: ``t0``, ``step``, ``rows``,
        ``all_open``, ``clear_open``, and ``n_rows`` and where the values (``packed``) are:
        in memory (``packed``) or in the file that keeps them (``file``: its path, identity
        and the array's place in it), read a window at a time by :meth:`sky_window`.  A
        year's values are ~100 MB; a process that reads the file keeps none of them."""
        index = self.__dict__.get("_sky_index")
        if index is not None:
            return index
        key, file = self._sky_key()
        if key is not None and "_sky" not in self.__dict__:
            try:
                with open(file, "rb") as fh:
                    ident = _identity(os.fstat(fh.fileno()))
                    with np.load(fh) as z:
                        if str(z["key"]) == key:
                            index = {k: z[k] for k in ("rows", *_SKY_OPEN)}
                    member = npz_member(fh, "packed_rows") if index is not None else None
                if member is None or len(member[2]) != 2 or member[3] != "C":
                    index = None
                else:
                    index.update(file=(str(file), ident, member), n_rows=int(member[2][0]))
            except (OSError, KeyError, ValueError):
                index = None
        if index is None:           # computed here (and kept beside the radiation file)
            index = self._sky_in_memory()
        index.update(t0=float(self.t0), step=float(SKY_STEP_S))
        self.__dict__["_sky_index"] = index
        return index

    def _sky_in_memory(self) -> dict:
        """:meth:`sky_index`'s entries for :meth:`sky`'s tables held in memory."""
        full = self.sky()
        return {**{k: full[k] for k in ("rows", *_SKY_OPEN, "packed")},
                "n_rows": int(full["packed"].shape[1])}

    def sky_window(self, t_utc) -> dict:
        """:meth:`sky`'s tables for passes at the times *t_utc* (Unix s) only, as the
        compiled kernel reads them: ``t0``, ``step``, ``rows`` (K, n_steps) int32 into
        ``packed`` (cells x 4, m) float32 and ``all_open``, ``clear_open`` (m, 2), which hold
        the m table rows of the steps from the first time's to the end of the last time's
        month and :data:`SKY_READ_AHEAD_S` (their values those of :meth:`sky`; -1 at night
        and at the steps outside).  The last window is kept and serves a later call whose
        steps it holds.  *t_utc* may be just the first and last time (NaN is none)."""
        index = self.sky_index()
        rows = index["rows"]
        t = np.asarray(t_utc, np.float64)
        t = t[~np.isnan(t)]
        used = np.zeros(0, np.int64)
        if len(t) and rows.shape[1]:
            # the steps of the first and last time, as the kernel finds them (sky_steps)
            f = (np.array([t.min(), t.max()]) - index["t0"]) / index["step"]
            j0, j1 = np.clip(np.floor(f + 0.5), 0, rows.shape[1] - 1).astype(np.int64)
            near = rows[:, j0:j1 + 1]
            used = np.unique(near[near >= 0]).astype(np.int64)
            last = self.__dict__.get("_sky_last")
            if last is not None and last[0] is index and (last[1][used] >= 0).all():
                return last[2]              # the window read for an earlier call holds them
            # and the rows up to the end of the last time's month (UTC) and a day: the next
            # chunks of a month's passes come in order
            last_s = int(index["t0"] + j1 * index["step"])
            month_end = (np.datetime64(last_s, "s").astype("datetime64[M]") + 1).astype(
                "datetime64[s]").astype(np.int64) + SKY_READ_AHEAD_S
            j2 = int(np.clip(np.floor((month_end - index["t0"]) / index["step"] + 0.5), j1, rows.shape[1] - 1))
            ahead = rows[:, j1 + 1:j2 + 1]
            used = np.union1d(used, ahead[ahead >= 0]).astype(np.int64)
        packed = self._sky_values(index, used)
        if packed is None:
            # the file changed under the run: the tables read again (or made), kept in memory
            self.__dict__.pop("_sky", None)
            index = {"t0": index["t0"], "step": index["step"], **self._sky_in_memory()}
            self.__dict__["_sky_index"] = index
            rows = index["rows"]
            packed = self._sky_values(index, used)
        new = np.full(index["n_rows"] + 1, -1, np.int32)           # [-1] stays -1
        new[used] = np.arange(len(used), dtype=np.int32)
        window = {"t0": index["t0"], "step": index["step"], "rows": new[rows], "packed": packed,
                  **{k: np.ascontiguousarray(index[k][used]) for k in _SKY_OPEN}}
        self.__dict__["_sky_last"] = (index, new, window)
        return window

    @staticmethod
    def _sky_values(index: dict, used: np.ndarray) -> np.ndarray | None:
        """The columns *used* (sorted) of the sky tables' values, a C-ordered copy; ``None``
        when the file that keeps them is no longer the one :meth:`sky_index` checked."""
        if "packed" in index:
            lo, hi = (int(used[0]), int(used[-1]) + 1) if len(used) else (0, 0)
            pick = slice(lo, hi) if hi - lo == len(used) else used
            return np.array(index["packed"][:, pick], np.float32, order="C")
        path, ident, (offset, dtype, shape, _) = index["file"]
        width = int(shape[1])
        out = np.empty((width, len(used)), np.float32)
        # each run of consecutive rows (one per location) is one read of the file
        cut = np.flatnonzero(np.diff(used) != 1) + 1
        with open(path, "rb") as fh:
            if _identity(os.fstat(fh.fileno())) != ident:
                return None
            for run, at in zip(np.split(used, cut), np.concatenate([[0], cut])):
                if not len(run):
                    continue
                fh.seek(offset + int(run[0]) * width * dtype.itemsize)
                block = np.fromfile(fh, dtype=dtype, count=len(run) * width)
                if len(block) != len(run) * width:
                    return None
                block = block.reshape(len(run), width)
                for i in range(0, len(run), 128):       # in slabs that stay in the cache
                    out[:, at + i:at + min(i + 128, len(run))] = block[i:i + 128].T
        return out

    def sky_share(self, t_utc, levels, normal, location=None, clear: bool = False):
        """The share of DHI a roof point receives from the Perez (1993) sky it sees, and
        the same in the open: two float32 (n,) arrays, at times *t_utc* (Unix s), for
        horizons *levels* (n, 36) (:func:`vipvflow.models.sky.sky_levels`) and roof unit
        *normal* (n, 3), from the table row of :meth:`sky` nearest in time (the sun moves
        at most 1.9 deg from it); all-sky or *clear*-sky.  At night both are 0."""
        sky = self.sky()
        rows = sky["rows"]
        j = self.sky_steps(t_utc)
        loc = np.zeros(len(j), np.int64) if location is None else np.broadcast_to(np.asarray(location, np.int64), j.shape)
        r = rows[loc, j]
        name = "clear" if clear else "all"
        from .sky import open_share, sky_share as share

        out, open_ = np.zeros(len(j), np.float32), np.zeros(len(j), np.float32)
        ok = r >= 0
        if ok.any():
            nrm = np.asarray(normal, np.float32)[ok]
            out[ok] = share(sky[name][r[ok]], sky[name + "_h"][r[ok]], np.asarray(levels, np.float32)[ok], nrm)
            open_[ok] = open_share(sky[name + "_open"][r[ok]], nrm)
        return out, open_

    def sky_tree_share(self, t_utc, loss, normal, location=None, clear: bool = False):
        """The share of DHI the tree crowns take from roof points at times *t_utc* (Unix s),
        from their loss per sky cell *loss* (n, 324) (:func:`vipvflow.models.trees.sky_cell_loss`,
        the pass's class of months) and roof unit *normal* (n, 3), with the table row of
        :meth:`sky` nearest in time (:func:`vipvflow.models.sky.tree_share`); float32 (n,),
        0 at night."""
        from .sky import tree_share

        sky = self.sky()
        j = self.sky_steps(t_utc)
        loc = np.zeros(len(j), np.int64) if location is None else np.broadcast_to(np.asarray(location, np.int64), j.shape)
        r = sky["rows"][loc, j]
        name = "clear" if clear else "all"
        out = np.zeros(len(j), np.float32)
        ok = r >= 0
        if ok.any():
            out[ok] = tree_share(sky[name][r[ok]], sky[name + "_h"][r[ok]],
                                 np.asarray(loss, np.float32)[ok], np.asarray(normal, np.float32)[ok])
        return out

    def sky_steps(self, t_utc) -> np.ndarray:
        """The sky tables' step nearest each time (int64, within the tables)."""
        sky = self.sky_index()
        f = (np.asarray(t_utc, np.float64) - sky["t0"]) / sky["step"]
        return np.clip(np.floor(f + 0.5), 0, sky["rows"].shape[1] - 1).astype(np.int64)

    def nearest_location(self, lat, lon) -> np.ndarray:
        """Index of the nearest table location for each point (degrees; great-circle)."""
        lat = np.radians(np.atleast_1d(np.asarray(lat, np.float64)))[:, None]
        lon = np.radians(np.atleast_1d(np.asarray(lon, np.float64)))[:, None]
        la, lo = np.radians(self.lat)[None], np.radians(self.lon)[None]
        h = (np.sin((la - lat) / 2) ** 2
             + np.cos(lat) * np.cos(la) * np.sin((lo - lon) / 2) ** 2)
        return np.argmin(h, axis=1).astype(np.int32)

    def lookup(self, t_utc, location=None, angles: bool = True) -> dict:
        """Interpolate radiation and sun position to times (linear, by index arithmetic).

        Parameters
        ----------
        t_utc : array of float, Unix seconds
        location : None, int or int array (index into ``lat``/``lon``; see
            :meth:`nearest_location`); ``None`` means location 0
        angles : bool, also return ``zenith`` and ``azimuth`` (degrees)

        Returns
        -------
        dict of float32 arrays
            ``ghi, dni, dhi, ghi_clear, dni_clear, dhi_clear`` (W/m2), ``sun_x, sun_y, sun_z``
            (unit vector east/north/up), ``f1, f2, f1_clear, f2_clear`` (the Perez sky's
            circumsolar and horizon coefficients, :mod:`vipvflow.models.sky`), ``zenith`` (apparent, deg), ``azimuth`` (deg from
            north, clockwise).  NaN outside the grid.
        """
        t = np.asarray(t_utc, dtype=np.float64)
        f = (t - self.t0) / self.step_s
        outside = ~((f >= 0) & (f <= self.n - 1))
        f = np.clip(np.nan_to_num(f), 0, self.n - 1)
        i = np.minimum(f.astype(np.int64), self.n - 2) if self.n > 1 else np.zeros(f.shape, np.int64)
        w = (f - i).astype(np.float32)[:, None]
        names, packed = self._packed()
        if location is None or np.ndim(location) == 0:
            rows = packed[0 if location is None else int(location)]
            a, b = rows[i], rows[i + 1] if self.n > 1 else rows[i]
        else:
            loc = np.asarray(location, np.int64)
            a = packed[loc, i]
            b = packed[loc, i + 1] if self.n > 1 else a
        v = a + w * (b - a)
        if outside.any():
            v[outside] = np.nan
        vt = np.ascontiguousarray(v.T)          # contiguous columns for the callers' arithmetic
        out = {name: vt[j] for j, name in enumerate(names)}
        if angles:
            sz = np.clip(out["sun_z"], -1, 1)
            out["zenith"] = np.degrees(np.arccos(sz)).astype(np.float32)
            out["azimuth"] = (np.degrees(np.arctan2(out["sun_x"], out["sun_y"])) % 360).astype(np.float32)
        return out
