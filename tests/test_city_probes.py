"""Hostile CityGML input: every probe ends in one clear line or a counted repair, never a traceback.

Where the error is fatal the data dir's previous city stays exactly as it was (checked file by
file with SHA-256).  The bad files are built here from a small valid city.
"""
from __future__ import annotations

import gzip
import hashlib
import io
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from vipvflow.cli import main
from vipvflow.inputs.city import ingest_city
from vipvflow.inputs.city.ingest import remove_stale_ingests
from vipvflow.inputs.city.synthetic import HEADER, building_xml, house_polygons, write_synthetic_city

SRS = "EPSG:2169"
X0, Y0 = 77000.0, 75000.0


def city_text(polys_by_id: dict, header: str | None = None) -> str:
    head = header or HEADER.format(srs=SRS, x0=X0, y0=Y0, x1=X0 + 100, y1=Y0 + 100)
    return head + "".join(building_xml(b, p) for b, p in polys_by_id.items()) + "</core:CityModel>\n"


def houses(n: int = 3) -> dict:
    return {f"H{i}": house_polygons(X0 + 30 * i, Y0, 300.0, 12, 10, 6, 3) for i in range(n)}


def snapshot(data_dir: Path) -> dict:
    """Relative path -> SHA-256 of every file under *data_dir* (hidden ones included)."""
    return {str(p.relative_to(data_dir)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(data_dir.rglob("*")) if p.is_file()}


@pytest.fixture
def data_dir(tmp_path) -> Path:
    """A data dir holding a good city (3 houses) from an earlier ingest."""
    good = tmp_path / "good.gml"
    good.write_text(city_text(houses()))
    d = tmp_path / "data"
    report = ingest_city(good, d)
    assert report.surfaces == {"roof": 6, "wall": 12, "ground": 3}
    return d


def run_cli(capsys, path: Path, data_dir: Path, *extra) -> tuple[int, str, str]:
    rc = main(["ingest", "city", str(path), "--data-dir", str(data_dir), *extra])
    out, err = capsys.readouterr()
    return rc, out, err


# -- fatal probes: one line, data dir untouched --------------------------------------------------
def _gz_corrupt(tmp: Path) -> Path:
    p = tmp / "city.gml.gz"
    p.write_bytes(b"\x1f\x8b\x08\x00" + os.urandom(2000))
    return p


def _gz_truncated(tmp: Path) -> Path:
    data = gzip.compress(city_text(houses(30)).encode())
    p = tmp / "city.gml.gz"
    p.write_bytes(data[: len(data) // 2])
    return p


def _gz_not_gzip(tmp: Path) -> Path:
    p = tmp / "city.gml.gz"
    p.write_text(city_text(houses()))
    return p


def _zip_truncated(tmp: Path) -> Path:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("city.gml", city_text(houses(30)))
    p = tmp / "city.zip"
    p.write_bytes(buf.getvalue()[: len(buf.getvalue()) // 2])
    return p


def _zip_bad_crc(tmp: Path) -> Path:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_STORED) as zf:
        zf.writestr("city.gml", city_text(houses(3)))
    data = bytearray(buf.getvalue())
    i = data.find(b"RoofSurface")
    data[i:i + 4] = b"Xoof"                       # a stored member whose bytes no longer match its CRC
    p = tmp / "city.zip"
    p.write_bytes(bytes(data))
    return p


def _version_9(tmp: Path) -> Path:
    p = tmp / "v9.gml"
    p.write_text(city_text(houses()).replace("citygml/2.0", "citygml/9.0")
                 .replace("citygml/building/2.0", "citygml/building/9.0"))
    return p


def _not_citygml(tmp: Path) -> Path:
    p = tmp / "other.xml"
    p.write_text('<?xml version="1.0"?><gpx xmlns="http://www.topografix.com/GPX/1/1">'
                 '<trk><trkseg><trkpt lat="49.6" lon="6.1"/></trkseg></trk></gpx>\n')
    return p


def _all_outside(tmp: Path) -> Path:
    """Every building 9000 km north of Luxembourg: outside EPSG:2169's area of use."""
    p = tmp / "far.gml"
    far = {f"F{i}": house_polygons(X0, Y0 + 9e6 + 30 * i, 300.0, 12, 10, 6, 3) for i in range(2)}
    p.write_text(city_text(far))
    return p


def _broken_xml(tmp: Path) -> Path:
    p = tmp / "broken.gml"
    p.write_text(city_text(houses())[:-40])
    return p


def _directory(tmp: Path) -> Path:
    p = tmp / "tiles.gml"
    p.mkdir()
    return p


def _empty(tmp: Path) -> Path:
    p = tmp / "empty.gml"
    p.write_bytes(b"")
    return p


FATAL = {
    "directory": (_directory, "is a directory"),
    "empty_file": (_empty, "empty file"),
    "gz_corrupt": (_gz_corrupt, "corrupt or truncated"),
    "gz_truncated": (_gz_truncated, "corrupt or truncated"),
    "gz_not_gzip": (_gz_not_gzip, "corrupt or truncated"),
    "zip_truncated": (_zip_truncated, "corrupt or truncated zip"),
    "zip_bad_crc": (_zip_bad_crc, "corrupt or truncated"),
    "citygml_9_0": (_version_9, "CityGML version 9.0"),
    "not_citygml": (_not_citygml, "no CityGML building"),
    "all_outside_crs_area": (_all_outside, "outside_crs_area 14"),
    "broken_xml": (_broken_xml, "not well-formed"),
}


@pytest.mark.parametrize("probe", sorted(FATAL))
def test_fatal_probe_one_line_data_dir_kept(probe, data_dir, tmp_path, capsys):
    make, words = FATAL[probe]
    before = snapshot(data_dir)
    bad = make(tmp_path)
    rc, out, err = run_cli(capsys, bad, data_dir)
    assert rc != 0
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err, err
    assert words in lines[0] and bad.name in lines[0]
    assert snapshot(data_dir) == before
    assert sorted(p.name for p in data_dir.iterdir()) == ["city"]      # no staging folder left


def test_fatal_probe_through_the_real_command(data_dir, tmp_path):
    """The installed entry point, in its own process: exit code 2, one line on stderr."""
    bad = _gz_truncated(tmp_path)
    before = snapshot(data_dir)
    res = subprocess.run([sys.executable, "-m", "vipvflow.cli", "ingest", "city", str(bad),
                          "--data-dir", str(data_dir)], capture_output=True, text=True, timeout=120)
    assert res.returncode == 2
    assert len(res.stderr.strip().splitlines()) == 1 and "Traceback" not in res.stderr
    assert "corrupt or truncated" in res.stderr and snapshot(data_dir) == before


# -- counted repairs: the bad polygon skipped, named in the summary line --------------------------
def _poisoned(value, ring=("wall", 2), vertex=3, text=None) -> dict:
    """3 good houses and one whose east gable (a closed 6-point ring) has one bad coordinate."""
    polys = houses()
    bad = house_polygons(X0, Y0 + 40, 300.0, 12, 10, 6, 3)
    bad[ring[0]][ring[1]] = bad[ring[0]][ring[1]].copy()
    bad[ring[0]][ring[1]][vertex, 0] = value
    polys["BAD"] = bad
    return polys


def _giant() -> dict:
    """3 good houses and a 3 km x 3 km one: its ground (9 km2) and roofs (4.5 km2 each) are absurd."""
    polys = houses()
    polys["BAD"] = house_polygons(X0, Y0 + 40, 300.0, 3000, 3000, 6, 3)
    return polys


REPAIRED = {
    # probe: (polygons, text replacement, reason counted, polygons skipped)
    "nan_vertex": (lambda: _poisoned(np.nan), None, "non_finite_coordinates", 1),
    "inf_vertex": (lambda: _poisoned(np.inf), None, "non_finite_coordinates", 1),
    "vertex_at_1e30": (lambda: _poisoned(1e30), None, "outside_crs_area", 1),
    "unreadable_number": (lambda: _poisoned(123456.789), ("123456.789", "12x3456"),
                          "unreadable_coordinates", 1),
    "absurd_area": (_giant, None, "absurd_area", 3),
}


@pytest.mark.parametrize("probe", sorted(REPAIRED))
def test_repaired_probe_counted_in_summary(probe, tmp_path, capsys):
    make, swap, reason, n = REPAIRED[probe]
    text = city_text(make())
    if swap:
        text = text.replace(*swap)
    path = tmp_path / f"{probe}.gml"
    path.write_text(text)
    rc, out, err = run_cli(capsys, path, tmp_path / "data")
    # stderr holds at most the ingest's progress line (a log's plain line), never an error
    assert rc == 0 and all(line.startswith("CityGML ingest:") for line in err.splitlines()), err
    summary = out.splitlines()[0]
    assert f"skipped {n} ({reason} {n})" in summary
    assert "duplicate_points" not in out
    report = ingest_city(path, tmp_path / "again")
    assert report.skipped == {reason: n}
    # the other polygons of the poisoned house and all 3 good houses are kept
    assert report.n_surfaces == 4 * 7 - n
    assert report.repaired == {}
    tiles = [p.name for p in (tmp_path / "again" / "city" / "surfaces").iterdir()]
    assert all(len(t) == len("tile=E0770N0750") for t in tiles), tiles   # no tile at 1e30


# -- interruption ------------------------------------------------------------------------------
KILL_SCRIPT = """
import sys
from vipvflow.inputs.city import ingest_city
from vipvflow.config import CityCfg
ingest_city(sys.argv[1], sys.argv[2], CityCfg(tile_size_m=100, buffer_m=20), chunk_surfaces=200)
"""


def test_killed_ingest_keeps_city_and_is_cleaned_up(data_dir, tmp_path):
    """SIGKILL during an ingest: city/ unchanged; the next ingest removes the leftovers."""
    big = tmp_path / "big.gml"
    write_synthetic_city(big, 3000, origin=(X0, Y0))
    before = snapshot(data_dir)
    proc = subprocess.Popen([sys.executable, "-c", KILL_SCRIPT, str(big), str(data_dir)])
    staging = data_dir / f".city-ingest-{proc.pid}"
    deadline = time.monotonic() + 60
    while not (staging / ".spool").exists() or not any((staging / ".spool").iterdir()):
        assert proc.poll() is None, "ingest ended before it could be killed"
        assert time.monotonic() < deadline
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    assert staging.is_dir()                                   # what the kill left behind
    after = snapshot(data_dir)
    assert {k: v for k, v in after.items() if not k.startswith(".city-ingest-")} == before
    # a spool of the older layout, left by a killed ingest of an earlier version
    old_spool = data_dir / "city" / f".ingest-spool-{proc.pid}"
    (old_spool / "E0770N0750").mkdir(parents=True)
    (old_spool / "E0770N0750" / "000000.npz").write_bytes(b"x" * 1000)
    removed = remove_stale_ingests(data_dir)
    assert set(removed) == {staging, old_spool}
    assert snapshot(data_dir) == before
    report = ingest_city(tmp_path / "good.gml", data_dir)
    assert report.buildings == 3 and sorted(p.name for p in data_dir.iterdir()) == ["city"]


def test_a_running_ingests_folder_is_left_alone(data_dir):
    """Only folders of processes that are gone are removed (here: this test's parent process)."""
    mine = data_dir / f".city-ingest-{os.getppid()}"
    mine.mkdir()
    assert remove_stale_ingests(data_dir) == [] and mine.is_dir()


def test_kill_between_the_swaps_renames_puts_the_old_city_back(data_dir, tmp_path):
    """A kill after `city/` was moved aside but before the new one took its place: the next
    ingest's clean-up restores the previous city (no data dir is ever left without one)."""
    before = snapshot(data_dir)
    gone = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"],
                          capture_output=True, text=True, check=True)
    pid = int(gone.stdout)                                   # a process that has ended
    (data_dir / "city").rename(data_dir / f".city-old-{pid}")
    (data_dir / f".city-ingest-{pid}").mkdir()               # its unfinished new city
    remove_stale_ingests(data_dir)
    assert sorted(p.name for p in data_dir.iterdir()) == ["city"]
    assert snapshot(data_dir) == before


def test_geographic_crs_option_refused_before_anything_is_written(data_dir, tmp_path, capsys):
    good = tmp_path / "good.gml"
    before = snapshot(data_dir)
    rc, _, err = run_cli(capsys, good, data_dir, "--crs", "EPSG:4326")
    assert rc == 2 and "projected CRS" in err and len(err.strip().splitlines()) == 1
    assert snapshot(data_dir) == before and sorted(p.name for p in data_dir.iterdir()) == ["city"]
