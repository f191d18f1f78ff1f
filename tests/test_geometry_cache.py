"""The tiles' geometry kept in the data dir (vipvflow.simulation.geometry_cache): a later run
of the same segments, city and settings takes it from there and computes the same numbers;
anything else that changes the geometry is another key."""
from __future__ import annotations

import shutil

import pandas as pd
import pytest

from vipvflow.config import IrradianceCfg
from vipvflow.simulation import geometry_cache
from vipvflow.simulation import partition as part


def _ctx(cfg, data_dir, run_dir, **irradiance):
    settings = IrradianceCfg(**{**cfg.irradiance.model_dump(), **irradiance}).model_dump()
    return part.RunContext(data_dir=str(data_dir), run_dir=str(run_dir), year=2024,
                           irradiance=settings, pv_system=cfg.pv_system().model_dump(),
                           pv_mode="paper", monthly_temperature_c=(15.0,) * 12,
                           wind_speed_mps=2.0, timezone="Europe/Luxembourg")


@pytest.fixture()
def data_copy(small_run, small_config, tmp_path):
    """A copy of the small demo's ingested data dir (its cache this test's own), its config,
    and the tile with the most segments."""
    from vipvflow.config import load_config

    cfg = load_config(small_config)
    data = tmp_path / "data"
    shutil.copytree(cfg.data_dir, data, ignore=shutil.ignore_patterns("cache"))
    seg = part._segments(str(data))
    tile = seg["tile"].value_counts().index[0]
    yield cfg, data, tile
    part._segments.cache_clear()


def test_a_later_run_takes_the_tiles_geometry_from_the_cache(data_copy, tmp_path):
    cfg, data, tile = data_copy
    first = part.tile_geometry(_ctx(cfg, data, tmp_path / "a"), tile)
    assert first.attrs["from_cache"] is False
    entries = list(part.DataDir(data).geometry_cache().iterdir())
    assert len(entries) == 1 and {p.name for p in entries[0].iterdir()} == {"geometry.parquet",
                                                                             "horizon.parquet"}
    later = part.tile_geometry(_ctx(cfg, data, tmp_path / "b"), tile)
    assert later.attrs["from_cache"] is True
    # the numbers the first run computed, as it computed them (its table in memory)
    pd.testing.assert_frame_equal(later, first, check_exact=True)
    for kind in ("geometry", "horizon"):
        a = part.RunDir(tmp_path / "a").tile_part(kind, tile).read_bytes()
        assert part.RunDir(tmp_path / "b").tile_part(kind, tile).read_bytes() == a
    # other settings: another entry, computed
    other = part.tile_geometry(_ctx(cfg, data, tmp_path / "c", svf_rays=64), tile)
    assert other.attrs["from_cache"] is False
    assert len(list(part.DataDir(data).geometry_cache().iterdir())) == 2
    # the tile task counts the tiles taken from the cache
    done = part.tile_task(_ctx(cfg, data, tmp_path / "d"), tile, ["2024-06"])
    assert done[0]["counts"] == {**done[0]["counts"], "geometry_tiles": 1,
                                 "geometry_tiles_from_cache": 1}


def test_an_entry_without_its_geometry_file_is_none(data_copy, tmp_path):
    cfg, data, tile = data_copy
    part.tile_geometry(_ctx(cfg, data, tmp_path / "a"), tile)
    (entry,) = part.DataDir(data).geometry_cache().iterdir()
    (entry / "geometry.parquet").unlink()
    again = part.tile_geometry(_ctx(cfg, data, tmp_path / "b"), tile)
    assert again.attrs["from_cache"] is False
    assert (entry / "geometry.parquet").is_file()


def test_the_key_changes_with_each_thing_the_geometry_depends_on(data_copy, monkeypatch):
    cfg, data, tile = data_copy
    seg = part._segments(str(data))
    seg = seg[seg["tile"] == tile]
    settings = {"irradiance": cfg.irradiance.model_dump(), "street": {"road_albedo": 0.1}}

    def key(s=seg, st=settings, modelled=True):
        return geometry_cache.tile_key(str(data), tile, s, st, modelled)

    base = key()
    assert key() == base                                         # the same inputs: found again
    moved = seg.copy()
    moved.iloc[0, moved.columns.get_loc("z")] += 0.01            # one segment 1 cm higher
    assert key(s=moved) != base
    assert key(s=seg.iloc[1:]) != base                           # a segment fewer
    assert key(st={**settings, "street": {"road_albedo": 0.2}}) != base
    assert key(modelled=False) != base
    mesh = part.DataDir(data).city.mesh(tile)
    assert mesh.is_file()
    raw = bytearray(mesh.read_bytes())
    raw[-1] ^= 1                                                 # the mesh file one bit apart
    mesh.write_bytes(bytes(raw))
    assert key() != base
    changed = key()
    monkeypatch.setattr(geometry_cache, "code_digest", lambda: "another version of the physics")
    assert key() != changed


def test_the_code_digest_covers_the_physics_modules():
    from vipvflow import models

    digest = geometry_cache.code_digest()
    assert len(digest) == 64 and digest == geometry_cache.code_digest()
    sources = sorted(p.name for p in geometry_cache.Path(models.__file__).parent.rglob("*.py"))
    assert {"view_factors.py", "shading.py", "trees.py", "horizon.py", "sky.py"} <= set(sources)


def test_entries_are_copies_where_the_run_folder_is_on_another_file_system(data_copy, tmp_path,
                                                                          monkeypatch):
    import errno
    import os

    cfg, data, tile = data_copy

    def no_link(src, dst):
        raise OSError(errno.EXDEV, "Invalid cross-device link", str(src))

    monkeypatch.setattr(geometry_cache.os, "link", no_link)
    part.tile_geometry(_ctx(cfg, data, tmp_path / "a"), tile)
    (entry,) = part.DataDir(data).geometry_cache().iterdir()
    made = part.RunDir(tmp_path / "a").tile_part("geometry", tile)
    assert (entry / "geometry.parquet").read_bytes() == made.read_bytes()
    assert os.stat(entry / "geometry.parquet").st_ino != os.stat(made).st_ino
    later = part.tile_geometry(_ctx(cfg, data, tmp_path / "b"), tile)
    assert later.attrs["from_cache"] is True
    assert not [p for p in entry.iterdir() if p.name.startswith(".")]     # no temporaries left
