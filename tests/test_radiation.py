"""CAMS radiation: reading real pvlib CAMS files, quality flags, minute grid, lookup."""
from __future__ import annotations

import json
import mmap
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pvlib
import pytest

from vipvflow.errors import InputError
from vipvflow.inputs.cams import FLAG_GAP, FLAG_NEGATIVE, FLAG_NO_ALLSKY, ingest_cams, read_cams_file
from vipvflow.models.sun_sky import MAPPED_FILESYSTEMS, RadiationTable, filesystem_of


@pytest.fixture(scope="module")
def cams(test_data):
    return test_data / "cams"


def _data_rows(path):
    lines = path.read_text().splitlines(keepends=True)
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    return head, body


def test_one_minute_wh_to_w(cams):
    frame, meta = read_cams_file(cams / "cams_radiation_1min_verbose.csv")
    # first row: GHI 13.5893 Wh/m2 over one minute, BNI 14.2954, DHI 1.8837, clear GHI 14.1417
    row = frame.iloc[0]
    assert row["ghi"] == pytest.approx(13.5893 * 60, rel=1e-6)
    assert row["dni"] == pytest.approx(14.2954 * 60, rel=1e-6)
    assert row["dhi"] == pytest.approx(1.8837 * 60, rel=1e-6)
    assert row["ghi_clear"] == pytest.approx(14.1417 * 60, rel=1e-6)
    assert row["t_centre"] == pd.Timestamp("2020-06-01 12:00:30", tz="UTC")
    assert meta["time_step"] == "1min" and meta["has_all_sky"]
    assert meta["latitude"] == pytest.approx(55.7906) and meta["longitude"] == pytest.approx(12.5251)
    assert meta["gaps"] == meta["negative"] == meta["dni_above_extra"] == 0


def test_monthly_files(cams):
    frame, meta = read_cams_file(cams / "cams_radiation_monthly.csv")
    jan = frame.iloc[0]
    assert jan["ghi"] == pytest.approx(15531.9336 / (31 * 24), rel=1e-6)
    assert jan["dni_clear"] == pytest.approx(105764.5547 / (31 * 24), rel=1e-6)
    feb = frame.iloc[1]                               # 2020 is a leap year: 29 days
    assert feb["ghi"] == pytest.approx(33073.7422 / (29 * 24), rel=1e-6)
    assert jan["t_centre"] == pd.Timestamp("2020-01-16 12:00", tz="UTC")
    year, meta = read_cams_file(cams / "cams_mcclear_monthly_12rows_pvlib-2092f8b.csv")
    assert len(year) == 12 and not meta["has_all_sky"]
    assert year["ghi"].isna().all() and (year["ghi_clear"] > 0).all()
    # the monthly means of a year cannot drive a minute simulation
    with pytest.raises(InputError, match="monthly|daily"):
        ingest_cams([cams / "cams_mcclear_monthly.csv"], "unused")


def test_broken_header_names_problem(cams, tmp_path):
    head, body = _data_rows(cams / "cams_radiation_1min_verbose.csv")
    bad = tmp_path / "no_columns.csv"
    bad.write_text("".join(h for h in head if not h.startswith("# Observation period")) + "".join(body))
    with pytest.raises(InputError, match=r"no_columns\.csv.*Observation period"):
        read_cams_file(bad)
    bad = tmp_path / "period.csv"
    bad.write_text("".join(h.replace("0 h 1 min 0 s", "0 h 7 min 0 s") for h in head) + "".join(body))
    with pytest.raises(InputError, match=r"period\.csv: line 27: unknown summarization period"):
        read_cams_file(bad)
    bad = tmp_path / "cols.csv"
    bad.write_text("".join(h.replace(";Clear sky BNI;", ";Clear sky XYZ;") for h in head) + "".join(body))
    with pytest.raises(InputError, match=r"cols\.csv: line \d+: column header lacks Clear sky BNI"):
        read_cams_file(bad)
    bad = tmp_path / "fields.csv"
    bad.write_text("".join(head) + body[0].replace(";", ";1;", 1))
    with pytest.raises(InputError, match=r"fields\.csv: line \d+: 36 fields"):
        read_cams_file(bad)


def test_gap_and_negative_are_flagged(cams, tmp_path):
    src = cams / "cams_mcclear_1min_verbose_60rows_pvlib-527fa1c.csv"
    head, body = _data_rows(src)
    body = list(body)
    del body[10]                                      # 12:10 missing
    fields = body[20].split(";")                      # 12:21 gets a negative clear-sky GHI
    fields[2] = "-3.0"
    body[20] = ";".join(fields)
    f = tmp_path / "gappy.csv"
    f.write_text("".join(head) + "".join(body))
    frame, meta = read_cams_file(f)
    assert meta["gaps"] == 1 and meta["negative"] == 1
    assert len(frame) == 60
    report = ingest_cams([f], tmp_path / "data")
    table = pd.read_parquet(tmp_path / "data" / "radiation" / "radiation.parquet")
    assert len(table) == 60
    t = pd.to_datetime(table["t_utc"], unit="s", utc=True)
    flags = dict(zip(t.dt.strftime("%H:%M"), table["flag"]))
    assert flags["12:10"] & FLAG_GAP and flags["12:21"] & FLAG_NEGATIVE
    assert flags["12:05"] & ~FLAG_NO_ALLSKY == 0
    # filled values lie between their neighbours and are physical
    v = table["ghi_clear"].to_numpy()
    assert (v >= 0).all()
    assert min(v[9], v[11]) - 1e-3 <= v[10] <= max(v[9], v[11]) + 1e-3
    assert report["files"][0]["negative"] == 1 and report["files"][0]["gaps"] == 1
    saved = json.loads((tmp_path / "data" / "radiation" / "ingest_report.json").read_text())
    assert saved["locations"][0]["all_sky_from_clear_sky"] is True


def test_true_solar_time_file(cams, tmp_path):
    """12:00 true solar time is the sun's transit: the UTC stamp must match pvlib's transit."""
    head, body = _data_rows(cams / "cams_mcclear_1min_verbose_60rows_pvlib-527fa1c.csv")
    f = tmp_path / "tst.csv"
    f.write_text("".join(h.replace("Universal time (UT)", "True solar time (TST)") for h in head)
                 + "".join(body))
    frame, meta = read_cams_file(f)
    assert meta["time_reference"] == "TST"
    noon_utc = frame["t_start"].iloc[0]
    day = pd.DatetimeIndex([pd.Timestamp("2020-06-01", tz="UTC")])
    transit = pvlib.solarposition.sun_rise_set_transit_spa(day, 55.7906, 12.5251)["transit"].iloc[0]
    assert abs((noon_utc - transit).total_seconds()) < 20


def test_table_lookup_and_sun_position(cams, tmp_path):
    src = cams / "cams_mcclear_1min_verbose_60rows_pvlib-527fa1c.csv"
    ingest_cams([src], tmp_path)
    table = RadiationTable.load(tmp_path, 2020)
    raw = pd.read_csv(src, sep=";", comment="#", header=None)
    t0 = pd.Timestamp("2020-06-01 12:00:30", tz="UTC").timestamp()
    t = t0 + np.array([0.0, 60.0, 90.0, 600.0])
    out = table.lookup(t)
    ghi = raw[2].to_numpy() * 60
    assert out["ghi_clear"][0] == pytest.approx(ghi[0], rel=1e-5)
    assert out["ghi_clear"][1] == pytest.approx(ghi[1], rel=1e-5)
    assert out["ghi_clear"][2] == pytest.approx((ghi[1] + ghi[2]) / 2, rel=1e-5)
    assert out["ghi"][3] == pytest.approx(ghi[10], rel=1e-5)     # McClear: all-sky = clear
    # CAMS gives the solar zenith angle at each period's middle (column 7, 'sza')
    sza = raw[6].to_numpy()
    assert np.abs(out["zenith"] - sza[[0, 1, 1, 10]] + [0, 0, (sza[1] - sza[2]) / 2, 0]).max() < 0.05
    assert np.isnan(table.lookup([t0 - 7200])["ghi"][0])
    with pytest.raises(InputError, match="2019"):
        RadiationTable.load(tmp_path, 2019)


def test_several_locations_nearest(cams, tmp_path):
    src = cams / "cams_radiation_1min_verbose.csv"
    head, body = _data_rows(src)
    other = tmp_path / "south.csv"
    other.write_text("".join(h.replace("55.7906", "49.6116").replace("12.5251", "6.1319") for h in head)
                     + "".join(body))
    ingest_cams([src, other], tmp_path / "d")
    table = RadiationTable.load(tmp_path / "d", 2020)
    assert len(table.lat) == 2
    loc = table.nearest_location([49.5, 56.0], [6.0, 12.0])
    assert table.lat[loc[0]] == pytest.approx(49.6116) and table.lat[loc[1]] == pytest.approx(55.7906)
    t = pd.Timestamp("2020-06-01 12:01:30", tz="UTC").timestamp()
    a, b = table.lookup([t, t], location=loc)["zenith"]
    assert a < b        # the same minute, the sun higher in Luxembourg than in Denmark


def test_a_loaded_table_is_read_from_its_cache_with_its_sun_and_perez_coefficients(cams, tmp_path):
    """The table of a year on its minute grid, its sun vectors and its Perez coefficients
    are computed once, kept beside the radiation file, and read back by every later load (a
    run's workers): the same values to the bit as computed, without reading the Parquet
    file or loading pvlib; a cache missing a member is written again."""
    import subprocess
    import sys

    from vipvflow.models.sun_sky import PEREZ_COLUMNS, _perez
    from vipvflow.store import DataDir

    src = cams / "cams_radiation_1min_verbose.csv"
    ingest_cams([src], tmp_path)
    first = RadiationTable.load(tmp_path, 2020)
    cache, = DataDir(tmp_path).radiation.root.glob("table_*.npz")
    assert cache == DataDir(tmp_path).radiation.table_cache(2020)
    grid = first.t0 + first.step_s * np.arange(first.n)
    computed = _perez(grid, first.data, first.data["sun_z"])
    with np.load(cache) as z:
        assert set(PEREZ_COLUMNS) <= set(z["names"].tolist())
    again = RadiationTable.load(tmp_path, 2020)
    assert (again.t0, again.step_s, again.n) == (first.t0, first.step_s, first.n)
    assert np.array_equal(again.lat, first.lat) and np.array_equal(again.lon, first.lon)
    assert set(again.data) == set(first.data)
    for c in first.data:
        assert np.array_equal(again.data[c], first.data[c], equal_nan=True), c
    for c in PEREZ_COLUMNS:
        assert np.array_equal(first.data[c], computed[c], equal_nan=True), c
    code = ("import sys\n"
            "from vipvflow.models.sun_sky import RadiationTable\n"
            f"RadiationTable.load({str(tmp_path)!r}, 2020)\n"
            "assert 'pvlib' not in sys.modules, 'pvlib loaded with the cache in place'\n"
            "assert 'pyarrow.parquet' not in sys.modules, 'the Parquet file read'\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    # a cache without its series (an older version's kept one member per series) is replaced
    with np.load(cache) as z:
        np.savez(cache, **{k: z[k] for k in z.files if k != "packed"})
    again = RadiationTable.load(tmp_path, 2020)
    assert np.array_equal(again.data["f1"], computed["f1"], equal_nan=True)
    with np.load(cache) as z:
        assert "packed" in z.files and set(PEREZ_COLUMNS) <= set(z["names"].tolist())


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/smaps")
def test_a_table_read_from_its_cache_is_mapped_and_its_pages_let_go(tmp_path):
    """A later load maps the cached series from the file instead of reading them into the
    process's memory: release_mapped_pages (a tile task's end) lets the pages read go, and
    the values read again afterwards, the lookups and a pickled copy are the same to the
    bit."""
    import pickle

    from vipvflow.models.sun_sky import release_mapped_pages
    from vipvflow.store import DataDir

    from vipvflow.demo.cams import write_cams_csv

    write_cams_csv(tmp_path / "cams.csv", 2020, 52.52, 13.40, 40.0, seed=3, months=[6])
    ingest_cams([tmp_path / "cams.csv"], tmp_path)
    first = RadiationTable.load(tmp_path, 2020)          # computes and writes the cache
    cache = DataDir(tmp_path).radiation.table_cache(2020)
    if filesystem_of(cache) not in MAPPED_FILESYSTEMS:
        pytest.skip(f"{tmp_path} is on {filesystem_of(cache)}: tables are not mapped from there")
    table = RadiationTable.load(tmp_path, 2020)
    names, packed = table._packed()
    assert table.__dict__.get("_map") is not None and packed.flags.writeable and packed.flags.aligned

    def resident_kb() -> int:
        """The resident size of this process's mappings of the cache file (kB)."""
        kb, inside = 0, False
        for line in Path("/proc/self/smaps").read_text().splitlines():
            if line[:1].isalnum() and "-" in line.split()[0] and ":" not in line.split()[0]:
                inside = line.rstrip().endswith(str(cache))
            elif inside and line.startswith("Rss:"):
                kb += int(line.split()[1])
        return kb

    touched = {c: float(np.nansum(table.data[c])) for c in names}
    assert resident_kb() * 1024 >= 0.9 * packed.nbytes
    release_mapped_pages()
    assert resident_kb() * 1024 < 0.1 * packed.nbytes
    assert {c: float(np.nansum(table.data[c])) for c in names} == touched
    for c in first.data:
        assert np.array_equal(table.data[c], first.data[c], equal_nan=True), c
    t = first.t0 + np.linspace(0, (first.n - 1) * first.step_s, 5000)
    a, b = first.lookup(t), table.lookup(t)
    assert all(np.array_equal(a[k], b[k], equal_nan=True) for k in a)
    copy = pickle.loads(pickle.dumps(table))
    assert "_map" not in copy.__dict__
    assert all(np.array_equal(copy.data[c], first.data[c], equal_nan=True) for c in first.data)


def test_the_filesystem_of_a_path_is_its_longest_mount_point(tmp_path):
    """filesystem_of reads the mount table: the mount with the longest mount point holding
    the path decides (not a mount point that is only a prefix of the path's name), the last
    of two on the same point, escaped spaces; no mount table: unknown."""
    info = tmp_path / "mountinfo"
    info.write_text(
        "27 1 254:0 / / rw,relatime - ext4 /dev/vda rw\n"
        "40 27 0:50 / /data rw,relatime shared:5 - nfs4 srv:/export rw,vers=4.2\n"
        "41 27 0:51 / /data/local rw,relatime - xfs /dev/vdb rw\n"
        "42 27 0:52 / /mnt/my\\040share rw,relatime - cifs //srv/s rw\n"
        "43 27 0:53 / /scratch rw - ext4 /dev/vdc rw\n"
        "44 27 0:54 / /scratch rw - fuse.sshfs host:/x rw\n")
    assert filesystem_of("/data/berlin/radiation/table_2019.npz", info) == "nfs4"
    assert filesystem_of("/data", info) == "nfs4"
    assert filesystem_of("/data/local/radiation/table_2019.npz", info) == "xfs"
    assert filesystem_of("/database/table_2019.npz", info) == "ext4"
    assert filesystem_of("/mnt/my share/table_2019.npz", info) == "cifs"
    assert filesystem_of("/scratch/t.npz", info) == "fuse.sshfs"
    assert filesystem_of("/data/t.npz", tmp_path / "no-such-file") is None
    for kind in ("nfs4", "cifs", "fuse.sshfs", None):
        assert kind not in MAPPED_FILESYSTEMS


def test_a_table_on_a_network_filesystem_is_read_into_memory(tmp_path, monkeypatch):
    """Where the cache is on a filesystem a table is not mapped from (NFS, SMB, FUSE: a file
    another host writes again could take a released page away), a later load reads the
    series into memory, with the same values."""
    from vipvflow.demo.cams import write_cams_csv
    from vipvflow.models import sun_sky

    write_cams_csv(tmp_path / "cams.csv", 2020, 52.52, 13.40, 40.0, seed=3, months=[6])
    ingest_cams([tmp_path / "cams.csv"], tmp_path)
    first = RadiationTable.load(tmp_path, 2020)
    monkeypatch.setattr(sun_sky, "filesystem_of", lambda path, *a: "nfs4")
    table = RadiationTable.load(tmp_path, 2020)
    assert "_map" not in table.__dict__
    assert all(ref() is not table for ref in sun_sky._MAPPED)
    names, packed = table._packed()
    base = packed
    while base is not None:                      # nothing under the series is a mapping
        assert not isinstance(base, mmap.mmap)
        base = getattr(base, "base", None)
    for c in first.data:
        assert np.array_equal(table.data[c], first.data[c], equal_nan=True), c


def test_the_radiation_caches_are_computed_again_by_another_version_of_the_code(cams, tmp_path,
                                                                               monkeypatch):
    """The sun vectors, the Perez coefficients and the sky tables kept beside the radiation
    file name the code and the libraries that computed them (code_digest): another version
    writes them again instead of reading values an older one computed."""
    from vipvflow import models
    from vipvflow.models import sun_sky
    from vipvflow.store import DataDir

    ingest_cams([cams / "cams_radiation_1min_verbose.csv"], tmp_path)
    first = RadiationTable.load(tmp_path, 2020)
    sky = first.sky()
    radiation = DataDir(tmp_path).radiation.root
    (sun_file,), (sky_file,) = radiation.glob("table_*.npz"), radiation.glob("sky_*.npz")

    def key(path):
        with np.load(path) as z:
            return str(z["key"])

    assert models.code_digest() in key(sun_file) and models.code_digest() in key(sky_file)
    # the same version reads them as they are
    before = {p: p.stat().st_mtime_ns for p in (sun_file, sky_file)}
    RadiationTable.load(tmp_path, 2020).sky()
    assert {p: p.stat().st_mtime_ns for p in (sun_file, sky_file)} == before
    # another version: both computed again, with its digest, to the same values
    for path in (sun_file, sky_file):
        with np.load(path) as z:
            members = {k: z[k] for k in z.files}
        members = {k: (v if k == "key" or v.dtype.kind != "f" else np.zeros_like(v))
                   for k, v in members.items()}
        np.savez(path, **members)                 # stale values under the old key
    monkeypatch.setattr(sun_sky, "code_digest", lambda: "another version of the physics")
    again = RadiationTable.load(tmp_path, 2020)
    again_sky = again.sky()
    assert "another version of the physics" in key(sun_file)
    assert "another version of the physics" in key(sky_file)
    for c in ("sun_x", "sun_y", "sun_z", "f1", "f2", "f1_clear", "f2_clear"):
        assert np.array_equal(again.data[c], first.data[c], equal_nan=True), c
    for k in ("rows", "all", "clear", "all_open"):
        assert np.array_equal(again_sky[k], sky[k], equal_nan=True), k


def test_npz_member_maps_an_uncompressed_array(tmp_path):
    """npz_member: where np.savez put an array, for np.memmap; None for a compressed one."""
    from vipvflow.store import npz_member, write_npz

    a = np.arange(12 * 7, dtype=np.float32).reshape(12, 7)
    write_npz(tmp_path / "a.npz", key=np.array("k"), packed=a)
    with open(tmp_path / "a.npz", "rb") as fh:
        offset, dtype, shape, order = npz_member(fh, "packed")
        assert fh.tell() == 0
        mapped = np.memmap(fh, dtype=dtype, mode="r", offset=offset, shape=shape, order=order)
        np.testing.assert_array_equal(mapped, a)
        del mapped
        with pytest.raises(KeyError):
            npz_member(fh, "other")
    np.savez_compressed(tmp_path / "c.npz", packed=a)
    with open(tmp_path / "c.npz", "rb") as fh:
        assert npz_member(fh, "packed") is None


def test_sky_window_reads_the_tables_of_its_days_only(small_config, tmp_path):
    """The compiled kernel's sky tables (RadiationTable.sky_window): for a year's table
    kept beside the radiation file, the rows of the passes' steps only, read from the file
    (no year of values in memory) up to the end of their month, each equal to the whole
    table's; still equal after the file was written again under the reader."""
    import os

    from vipvflow.config import load_config
    from vipvflow.models.sun_sky import SKY_READ_AHEAD_S

    # the small demo's year at its place and, a second location, 2 deg further north
    src = load_config(small_config).inputs.cams[0]
    head, body = _data_rows(src)
    north = tmp_path / "north.csv"
    north.write_text("".join(h.replace("Latitude (positive North, ISO 19115): 49.",
                                       "Latitude (positive North, ISO 19115): 51.") for h in head)
                     + "".join(body))
    data_dir = tmp_path / "data"
    ingest_cams([src, north], data_dir)
    RadiationTable.load(data_dir, 2024).sky_index()            # the file kept beside the radiation
    full = RadiationTable.load(data_dir, 2024).sky()
    table = RadiationTable.load(data_dir, 2024)
    index = table.sky_index()
    assert "file" in index and "packed" not in index and "_sky" not in table.__dict__
    assert full["rows"].shape[0] == 2
    rng = np.random.default_rng(3)
    for k in range(6):
        if k == 5:                      # written again (same tables): read from the new file
            cache = index["file"][0]
            os.utime(cache, ns=(os.stat(cache).st_atime_ns, os.stat(cache).st_mtime_ns + 10**9))
        start = pd.Timestamp(f"2024-{2 * k + 1:02d}-02", tz="UTC").timestamp()
        t = start + rng.uniform(0, 3 * 86400, 500)
        win = table.sky_window(t)
        # the window: both places' rows from the first pass's step to the end of its month
        # and a day
        end = pd.Timestamp(f"2024-{2 * k + 2:02d}-01", tz="UTC").timestamp() + SKY_READ_AHEAD_S
        steps = full["rows"][:, table.sky_steps([t.min()])[0]:table.sky_steps([end])[0] + 1]
        assert win["packed"].shape[1] == (steps >= 0).sum() == len(win["all_open"])
        assert win["packed"].flags.c_contiguous and win["packed"].dtype == np.float32
        later = t + 25 * 86400          # the month's later days: the same window serves them
        assert table.sky_window(later) is win
        for times, loc in ((t, 0), (later, 1)):
            j = table.sky_steps(times)
            rows, got = full["rows"][loc, j], win["rows"][loc, j]
            assert ((rows >= 0) == (got >= 0)).all() and (rows >= 0).any()
            day = rows >= 0
            np.testing.assert_array_equal(win["packed"][:, got[day]], full["packed"][:, rows[day]])
            for name in ("all_open", "clear_open"):
                np.testing.assert_array_equal(win[name][got[day]], full[name][rows[day]])
    assert table.sky_window(np.array([np.nan]))["packed"].shape[1] == 0


def test_packed_table_holds_each_value_once(cams, tmp_path):
    """Once packed for the kernel, the table's series are views into the packed array: the
    same lookups, no second copy."""
    ingest_cams([cams / "cams_radiation_1min_verbose.csv"], tmp_path)
    table = RadiationTable.load(tmp_path, 2020)
    t = pd.Timestamp("2020-06-01 12:00:30", tz="UTC").timestamp() + np.linspace(0, 3000, 41)
    before = table.lookup(t)
    names, packed = table._packed()
    for j, name in enumerate(names):
        assert np.shares_memory(table.data[name], packed)
        np.testing.assert_array_equal(table.data[name], packed[..., j])
    after = table.lookup(t)
    for k in before:
        np.testing.assert_array_equal(before[k], after[k])
    assert table._packed()[1] is packed
