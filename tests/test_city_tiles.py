"""Tiles: file contract, shading equivalence with the whole city, bounded memory, CLI."""
from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import geopandas as gpd
import numpy as np
import pyarrow.parquet as pq
import pytest
import trimesh
from embreex import rtcore_scene
from embreex.mesh_construction import TriangleMesh

from vipvflow.cli import main
from vipvflow.config import CityCfg
from vipvflow.errors import InputError
from vipvflow.inputs.city import SURFACE_TYPES, ingest_city, load_tile_mesh
from vipvflow.models.mesh import FACE_ATTRIBUTES
from vipvflow.inputs.city.synthetic import write_synthetic_city
from vipvflow.inputs.tiles import tile_bounds, tile_names


@pytest.fixture(scope="module")
def small_city(tmp_path_factory):
    """400 houses over ~500 m x 500 m, cut in 200 m tiles with a 60 m buffer."""
    d = tmp_path_factory.mktemp("tiles")
    info = write_synthetic_city(d / "city.gml", 400, spacing_m=25.0, origin=(77000.0, 75000.0))
    cfg = CityCfg(tile_size_m=200, buffer_m=60)
    report = ingest_city(d / "city.gml", d / "tiled", cfg)
    whole = ingest_city(d / "city.gml", d / "whole", CityCfg(tile_size_m=100_000, buffer_m=0))
    return d, info, cfg, report, whole


def test_contract_files(small_city):
    d, info, cfg, report, _ = small_city
    city = d / "tiled" / "city"
    tiles = json.loads((city / "tiles.json").read_text())
    assert tiles["crs"] == "EPSG:2169" and tiles["tile_size_m"] == 200 and tiles["buffer_m"] == 60
    assert report.tiles == len(tiles["tiles"]) >= 9
    assert report.surfaces == info["surfaces"]
    for t, a in info["area_m2"].items():   # analytic areas (coordinates written to 1 mm)
        assert report.area_m2[t] == pytest.approx(a, rel=1e-4)
    n_total = 0
    for name, entry in tiles["tiles"].items():
        assert tuple(entry["bounds"]) == tile_bounds(name, 200)
        path = city / "surfaces" / f"tile={name}" / "part-0.parquet"
        if not entry["n_surfaces"]:
            # a tile within the buffer of another's surfaces: a mesh of those, no surfaces file
            assert not path.exists() and entry["n_buffer_surfaces"] > 0
            assert load_tile_mesh(d / "tiled", name).n_triangles == entry["n_triangles"] > 0
            continue
        meta = json.loads(pq.read_schema(path).metadata[b"geo"])
        assert meta["columns"]["geometry"]["geometry_types"] == ["Polygon Z"]
        gdf = gpd.read_parquet(path)
        assert gdf.crs.to_epsg() == 2169
        assert {"surface_id", "building_id", "surface_type", "area_m2", "nx", "ny", "nz", "albedo",
                "tile"} <= set(gdf.columns)
        assert (gdf.tile == name).all() and len(gdf) == entry["n_surfaces"]
        # a surface belongs to the tile of its centroid
        c = gdf.geometry.centroid
        assert (tile_names(c.x.to_numpy(), c.y.to_numpy(), 200) == name).all()
        mesh = load_tile_mesh(d / "tiled", name)
        assert isinstance(mesh.trimesh, trimesh.Trimesh)
        assert mesh.vertices.dtype == np.float64 and mesh.triangles.dtype.kind == "i"
        assert set(mesh.trimesh.face_attributes) == set(FACE_ATTRIBUTES)
        assert entry["n_degenerate_triangles"] == mesh.check()["degenerate_triangles"]
        assert mesh.surface_index.dtype == np.int32 and mesh.albedo.dtype == np.float32
        assert mesh.normals.dtype == np.float32 and mesh.surface_type.dtype == np.int8
        assert mesh.n_triangles == entry["n_triangles"] and mesh.buffer_m == 60
        # own surfaces first, in parquet row order; buffer surfaces after
        assert list(mesh.surface_ids[:len(gdf)]) == list(gdf.surface_id)
        assert len(mesh.surface_ids) == entry["n_surfaces"] + entry["n_buffer_surfaces"]
        own_tri = mesh.surface_index < len(gdf)
        types = np.asarray(SURFACE_TYPES)[mesh.surface_type[own_tri]]
        assert (types == gdf.surface_type.to_numpy()[mesh.surface_index[own_tri]]).all()
        n_total += len(gdf)
    assert n_total == sum(info["surfaces"].values())
    assert json.loads((city / "ingest_report.json").read_text())["surfaces"] == report.surfaces
    with pytest.raises(InputError, match="no mesh"):
        load_tile_mesh(d / "tiled", "E9999N9999")


def _scene(mesh, offset):
    scene = rtcore_scene.EmbreeScene()
    TriangleMesh(scene, (mesh.vertices[mesh.triangles] - offset).astype(np.float32))
    return scene


def test_tile_shading_equals_whole_city(small_city):
    d, _, cfg, _, whole_report = small_city
    tiles = json.loads((d / "tiled" / "city" / "tiles.json").read_text())["tiles"]
    assert whole_report.tiles == 1
    whole = load_tile_mesh(d / "whole", json.loads(
        (d / "whole" / "city" / "tiles.json").read_text())["tiles"].popitem()[0])
    offset = np.array([77000.0, 75000.0, 300.0])
    whole_scene = _scene(whole, offset)
    rng = np.random.default_rng(11)
    n, hits, buffer_hits = 20_000, 0, 0
    for name in tiles:
        mesh = load_tile_mesh(d / "tiled", name)
        assert mesh.n_triangles < whole.n_triangles
        x0, y0, x1, y1 = mesh.bounds
        org = np.column_stack([rng.uniform(x0, x1, n), rng.uniform(y0, y1, n), rng.uniform(298, 330, n)])
        v = rng.normal(size=(n, 3))
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        tfar = rng.uniform(1, cfg.buffer_m * 0.99, n).astype(np.float32)
        o32, v32 = (org - offset).astype(np.float32), v.astype(np.float32)
        scene = _scene(mesh, offset)
        a = scene.run(o32, v32, dists=tfar.copy(), query="OCCLUDED") >= 0
        prim = scene.run(o32, v32, dists=tfar.copy())          # first hit: triangle id
        n_own = tiles[name]["n_surfaces"]
        buffer_hits += int((mesh.surface_index[prim[prim >= 0]] >= n_own).sum())
        b = whole_scene.run(o32, v32, dists=tfar.copy(), query="OCCLUDED") >= 0
        assert (a == b).all(), f"{name}: {np.sum(a != b)} of {n} rays differ"
        hits += a.sum()
    assert 0.1 < hits / (n * len(tiles)) < 0.95          # the test sees both outcomes
    assert buffer_hits > 0.01 * hits                     # and rays that need the buffer


PROBE = textwrap.dedent("""
    import gc, json, resource, sys, threading
    import psutil
    import geopandas, numpy, pyproj, shapely, trimesh  # the baseline every ingest pays
    from vipvflow.inputs.city import ingest_city
    from vipvflow.config import CityCfg
    proc = psutil.Process()
    gc.collect()
    base = proc.memory_info().rss
    peak = [base]
    done = threading.Event()
    def sample():
        while not done.is_set():
            peak[0] = max(peak[0], proc.memory_info().rss)
            done.wait(0.002)
    t = threading.Thread(target=sample)
    t.start()
    r = ingest_city(sys.argv[1], sys.argv[2], CityCfg(tile_size_m=200, buffer_m=50),
                    chunk_surfaces=int(sys.argv[3]))
    done.set()
    t.join()
    print(json.dumps({"base": base, "peak": peak[0], "surfaces": r.n_surfaces,
                      "ru_maxrss_kb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss}))
""")


#: what a Dask LocalCluster's nannies put into the environment of the process that started
#: them (the test session's, after any run): glibc's trim threshold there lowered the probe's
#: peak and made the memory test fail whenever a run came before it
DASK_ENVIRON = ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
                "OPENBLAS_NUM_THREADS")


def _peak(path, out, chunk):
    env = {k: v for k, v in os.environ.items() if k not in DASK_ENVIRON}
    res = subprocess.run([sys.executable, "-c", PROBE, str(path), str(out), str(chunk)],
                         capture_output=True, text=True, check=True, env=env)
    return json.loads(res.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_peak_memory_does_not_grow_with_city_size(tmp_path):
    n = 1500
    write_synthetic_city(tmp_path / "n.gml", n)
    write_synthetic_city(tmp_path / "2n.gml", 2 * n)
    a = _peak(tmp_path / "n.gml", tmp_path / "a", 2000)
    b = _peak(tmp_path / "2n.gml", tmp_path / "b", 2000)
    assert b["surfaces"] == 2 * a["surfaces"] == 14 * n
    grow_a, grow_b = a["peak"] - a["base"], b["peak"] - b["base"]
    assert b["peak"] / a["peak"] < 1.3
    assert grow_b / grow_a < 1.3, (grow_a, grow_b)
    # the probe is sensitive: holding every surface in memory (one chunk) does grow
    c = _peak(tmp_path / "2n.gml", tmp_path / "c", 10**9)
    assert c["peak"] - c["base"] > 1.3 * grow_b


def test_cli_ingest_city(tmp_path, capsys, test_data):
    src = test_data / "citygml" / "fzk_haus_lod2_v2.gml"
    rc = main(["ingest", "city", str(src), "--data-dir", str(tmp_path)])
    out = capsys.readouterr().out.splitlines()
    assert rc == 0
    assert "1 buildings" in out[0] and "roof 2" in out[0] and "EPSG:25832" in out[0]
    assert out[1] == f"report: {tmp_path / 'city' / 'ingest_report.json'}"
    assert (tmp_path / "city" / "ingest_report.json").exists()
    broken = tmp_path / "broken.gml"
    broken.write_text("<CityModel>\n<a>\n</CityModel>\n")
    assert main(["ingest", "city", str(broken), "--data-dir", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "broken.gml: line 3" in err
