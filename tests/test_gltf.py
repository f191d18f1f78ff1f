"""The run's 3D model (city.glb): written by the run and by ``vipvflow export gltf``, linked by
the report, loaded back by trimesh with the run's building and segment counts."""
from __future__ import annotations

import json
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import trimesh

from vipvflow.cli import main
from vipvflow.simulation.rundir import open_run


def _buildings_of_the_run(run: Path) -> set:
    """The buildings with a roof, wall, ground or closure surface in the run's tiles, counted
    from the city's surface GeoParquet (not from the meshes the export reads)."""
    folder = open_run(run).data_dir / "city"
    tiles = set(pd.read_parquet(run / "segments.parquet", columns=["tile"])["tile"])
    ids = set()
    for tile in tiles:
        path = folder / "surfaces" / f"tile={tile}" / "part-0.parquet"
        if path.exists():
            s = pd.read_parquet(path, columns=["building_id", "surface_type"])
            ids |= set(s.loc[~s["surface_type"].isin(["terrain", "vegetation"]), "building_id"])
    return ids


def test_the_run_writes_its_3d_model_and_the_report_links_it(small_run):
    run = Path(small_run)
    scene = trimesh.load(run / "city.glb")
    assert isinstance(scene, trimesh.Scene)
    segments = gpd.read_parquet(run / "segments.parquet")
    buildings = _buildings_of_the_run(run)
    nodes = [n for n in scene.graph.nodes_geometry if n.startswith("building ")]
    assert len(buildings) > 10 and {n.split(" ", 1)[1] for n in nodes} == buildings
    seg = scene.geometry["segments"]
    assert len(seg.faces) == 2 * len(segments)
    extras = scene.metadata
    assert extras["buildings"] == len(buildings) and extras["segments"] == len(segments)
    assert extras["crs"] == "EPSG:2169" and sorted(extras["tiles"]) == sorted(segments["tile"].unique())
    report = (run / "report.html").read_text()
    assert "<a href='city.glb'>city.glb</a>" in report and f"{len(segments):,} route segments" in report


def test_export_gltf_from_another_directory(small_run, tmp_path, monkeypatch, capsys):
    run = Path(small_run)
    monkeypatch.chdir(tmp_path)
    assert main(["export", "gltf", str(run), "--out", "twin.glb"]) == 0
    assert "buildings of" in capsys.readouterr().out
    scene = trimesh.load(tmp_path / "twin.glb")
    origin = np.array(scene.metadata["origin"])
    segments = gpd.read_parquet(run / "segments.parquet").sort_values("segment_id")
    seg = scene.geometry["segments"]
    assert seg.metadata["segment_ids"] == segments["segment_id"].tolist()
    # the model's CRS shifted to the origin: each quad starts 0.25 m right of its segment's start
    first = seg.vertices[0::4] + origin
    start = segments[["x", "y", "z"]].to_numpy()
    assert np.allclose(np.linalg.norm(first[:, :2] - start[:, :2], axis=1), 0.25, atol=1e-3)
    assert np.allclose(first[:, 2], start[:, 2], atol=1e-3)
    # the node above turns z-up into glTF's y-up
    matrix, _ = scene.graph["segments"]
    assert np.allclose(matrix[:3, :3], [[1, 0, 0], [0, 0, 1], [0, -1, 0]])
    # coloured by the annual yield: the lowest viridis' dark violet, the highest its yellow
    colours = seg.visual.vertex_colors[0::4, :3].astype(int)
    kwh = segments["kwh_per_kwp_year"].to_numpy()
    assert np.abs(colours[np.nanargmin(kwh)] - [68, 1, 84]).max() <= 1
    assert np.abs(colours[np.nanargmax(kwh)] - [253, 231, 37]).max() <= 1
    scale = scene.metadata["colour"]
    assert scale["min"] == np.nanmin(kwh) and scale["max"] == np.nanmax(kwh)
    # buildings in place: within the tiles of the run (own surfaces of each tile)
    tiles = json.loads((open_run(run).data_dir / "city" / "tiles.json").read_text())["tiles"]
    lo = np.min([tiles[t]["bounds"][:2] for t in scene.metadata["tiles"] if t in tiles], axis=0)
    hi = np.max([tiles[t]["bounds"][2:] for t in scene.metadata["tiles"] if t in tiles], axis=0)
    for name in [n for n in scene.geometry if n.startswith("building ")][:50]:
        xy = scene.geometry[name].vertices[:, :2] + origin[:2]
        centre = xy.mean(axis=0)
        assert (centre > lo - 50).all() and (centre < hi + 50).all()
        # each building in its one colour, every vertex of it (COLOR_0 in the file)
        assert (scene.geometry[name].visual.vertex_colors == [205, 200, 190, 255]).all()


def test_export_gltf_of_a_folder_that_is_no_run_says_so(tmp_path, capsys):
    assert main(["export", "gltf", str(tmp_path), "--out", str(tmp_path / "x.glb")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "not a finished run" in err[0]
