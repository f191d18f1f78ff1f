"""The tile mesh as a trimesh.Trimesh: built, merged, checked, saved and loaded; an older
format refused; Embree (the runs' ray backend) against trimesh's own numpy ray backend."""
from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from trimesh.ray.ray_triangle import RayMeshIntersector

from vipvflow.config import CityCfg
from vipvflow.errors import InputError
from vipvflow.inputs.city import ingest_city, load_tile_mesh
from vipvflow.inputs.city.synthetic import write_synthetic_city
from vipvflow.models.mesh import FACE_ATTRIBUTES, MESH_FORMAT, SURFACE_CODE, TileMesh
from vipvflow.models.shading import Scene, box_mesh
from vipvflow.store import write_npz

X0, Y0 = 77_000.0, 75_000.0


def _street() -> TileMesh:
    walls = box_mesh([[X0 - 30, Y0 - 50, 0, X0 - 10, Y0 + 50, 20], [X0 + 10, Y0 - 50, 0, X0 + 30, Y0 + 50, 14]],
                     name="E0770N0750")
    road = TileMesh.from_triangles([[[X0 - 10, Y0 - 50, 0], [X0 + 10, Y0 - 50, 0], [X0 + 10, Y0 + 50, 0]],
                                    [[X0 - 10, Y0 - 50, 0], [X0 + 10, Y0 + 50, 0], [X0 - 10, Y0 + 50, 0]]],
                                   albedo=0.12, surface_type="ground")
    return TileMesh.merge([walls, road], bounds=[X0 - 250, Y0 - 250, X0 + 250, Y0 + 250], buffer_m=60)


def test_a_tile_mesh_is_a_trimesh_with_its_face_attributes(tmp_path):
    mesh = _street()
    tm = mesh.trimesh
    assert isinstance(tm, trimesh.Trimesh) and mesh.n_triangles == len(tm.faces) == 22
    assert set(tm.face_attributes) == set(FACE_ATTRIBUTES)
    # merged: the road's surfaces numbered after the walls', its attributes on its faces
    assert list(mesh.surface_index[-2:]) == [20, 21] and list(mesh.surface_ids[-2:]) == ["t0", "t1"]
    assert (mesh.surface_type[-2:] == SURFACE_CODE["ground"]).all()
    assert np.allclose(mesh.albedo[-2:], 0.12) and np.allclose(mesh.albedo[:20][mesh.surface_type[:20] == 0], 0.15)
    assert mesh.name == "E0770N0750" and mesh.buffer_m == 60 and mesh.bounds[0] == X0 - 250
    # trimesh's own normals of the triangles agree with the stored surface normals
    assert np.allclose(tm.face_normals, mesh.normals, atol=1e-6)
    assert mesh.check() == {"triangles": 22, "degenerate_triangles": 0}
    mesh.save(tmp_path / "m.npz")
    back = TileMesh.load(tmp_path / "m.npz")
    assert np.array_equal(back.vertices, mesh.vertices) and back.vertices.dtype == np.float64
    assert np.array_equal(back.triangles, mesh.triangles)
    for key in FACE_ATTRIBUTES:
        got, want = back.trimesh.face_attributes[key], tm.face_attributes[key]
        assert got.dtype == want.dtype and np.array_equal(got, want), key
    assert list(back.surface_ids) == list(mesh.surface_ids) and back.name == mesh.name
    assert np.array_equal(back.bounds, mesh.bounds) and back.buffer_m == 60


def test_a_mesh_that_does_not_fit_is_caught_by_the_check():
    mesh = _street()
    mesh.surface_index[0] = 99
    with pytest.raises(ValueError, match="names no surface"):
        mesh.check()
    sliver = TileMesh.from_triangles([[[0, 0, 0], [1, 0, 0], [2, 0, 1e-12]]])
    assert sliver.check()["degenerate_triangles"] == 1
    with pytest.raises(TypeError, match="unknown face attribute"):
        TileMesh(np.zeros((3, 3)), [[0, 1, 2]], ["s"], surface_index=[0], surface_type=[0],
                 albedo=[0.2], normals=[[0, 0, 1]], colour=[1])


def test_a_mesh_of_an_older_format_is_refused_in_one_line(tmp_path):
    """A data dir ingested before the meshes were Trimeshes: its file is refused, naming
    itself and what to do (simulate ingests again by itself: the format is in the stamp)."""
    old = tmp_path / "city" / "meshes" / "E0770N0750.npz"
    write_npz(old, vertices=np.zeros((3, 3)), triangles=np.array([[0, 1, 2]], np.int32),
              surface_index=np.zeros(1, np.int32), surface_ids=np.array(["s"]),
              albedo=np.zeros(1, np.float32), normals=np.zeros((1, 3), np.float32),
              surface_type=np.zeros(1, np.int8), bounds=np.zeros(4), buffer_m=np.float64(0),
              name=np.str_("E0770N0750"))
    with pytest.raises(InputError) as err:
        load_tile_mesh(tmp_path, "E0770N0750")
    msg = str(err.value)
    assert msg.startswith(f"{old}: a tile mesh of format 1, this vipvflow reads format {MESH_FORMAT}")
    assert "ingest the city again" in msg and "\n" not in msg


def test_simulate_ingests_a_city_of_an_older_mesh_format_again(tmp_path, monkeypatch):
    """The city's ingest stamp holds the mesh format: a stamp without it (an older vipvflow's)
    does not match, so ``ensure_ingested`` ingests the city again."""
    import vipvflow.inputs.city as city
    from vipvflow.config import load_config
    from vipvflow.simulation import prepare

    calls = []

    class Stop(Exception):
        pass

    def ingest(*args, **kwargs):
        calls.append(args)
        raise Stop

    gml = tmp_path / "city.gml"
    write_synthetic_city(gml, 4, spacing_m=25.0, origin=(X0, Y0))
    cfg = load_config(None, {"data_dir": str(tmp_path / "data"),
                             "inputs": {"citygml": [str(gml)], "gtfs": str(gml), "cams": [str(gml)]}})
    city_fp = prepare._fingerprints(cfg, prepare.input_digests(cfg))["city"]
    current = dict(city_fp["config"])
    for key in ("mesh_format", "format", "trees_format"):   # a stamp from before the formats
        del city_fp["config"][key]
    stamp = tmp_path / "data" / "city" / ".inputs.json"
    stamp.parent.mkdir(parents=True)
    stamp.write_text(json.dumps(city_fp))
    monkeypatch.setattr(city, "ingest_city", ingest)
    with pytest.raises(Stop):
        prepare.ensure_ingested(cfg, say=lambda *_: None)
    assert len(calls) == 1
    # the stamp of this version (mesh format, the city's own ingest format, the trees'): kept
    from vipvflow.models.trees import TREES_FORMAT

    assert current["mesh_format"] == MESH_FORMAT and current["trees_format"] == TREES_FORMAT
    city_fp["config"] = current
    stamp.write_text(json.dumps(city_fp))
    calls.clear()
    with pytest.raises(Exception) as err:                   # goes on to the GTFS ingest
        prepare.ensure_ingested(cfg, say=lambda *_: None)
    assert not calls and not isinstance(err.value, Stop)


@pytest.fixture(scope="module")
def city_tile(tmp_path_factory):
    """A tile of an ingested synthetic city (houses with gabled roofs, terrain-free), with
    its buffer: 25 m spacing, 200 m tiles."""
    d = tmp_path_factory.mktemp("mesh")
    write_synthetic_city(d / "city.gml", 64, spacing_m=25.0, origin=(X0, Y0))
    ingest_city(d / "city.gml", d / "data", CityCfg(tile_size_m=200, buffer_m=40))
    tiles = json.loads((d / "data" / "city" / "tiles.json").read_text())["tiles"]
    name = max(tiles, key=lambda t: tiles[t]["n_triangles"])
    return load_tile_mesh(d / "data", name)


def test_embree_and_trimesh_ray_backends_find_the_same_hits(city_tile):
    """The runs' Embree scene (float32, relative to the tile's centre) and trimesh's numpy
    ray-triangle backend (float64, on the same Trimesh) on 4,000 rays aimed at points inside
    the mesh's triangles from random places around it: the same first triangle and distance,
    and the same occlusion within a distance. Where the triangles differ the ray met an edge
    two triangles share: both backends then hit the same point."""
    mesh = city_tile
    rng = np.random.default_rng(7)
    n = 4000
    tri = mesh.vertices[mesh.triangles]
    pick = rng.integers(0, mesh.n_triangles, n)
    a, b = rng.uniform(0.05, 0.9, n), rng.uniform(0.05, 0.9, n)
    flip = a + b > 0.95
    a[flip], b[flip] = 0.95 - a[flip] * 0.9, 0.95 - b[flip] * 0.9
    target = tri[pick, 0] + a[:, None] * (tri[pick, 1] - tri[pick, 0]) + b[:, None] * (tri[pick, 2] - tri[pick, 0])
    lo, hi = mesh.vertices.min(0), mesh.vertices.max(0)
    origin = rng.uniform(lo - [20, 20, 0], hi + [20, 20, 30], (n, 3))
    origin[:, 2] = np.maximum(origin[:, 2], lo[2] + 0.5)
    d = target - origin
    d /= np.linalg.norm(d, axis=1, keepdims=True)

    embree_tri, embree_t = Scene(mesh).first_hit(origin, d)
    numpy_rays = RayMeshIntersector(mesh.trimesh)
    loc, ray_idx, tri_idx = numpy_rays.intersects_location(origin, d, multiple_hits=False)
    numpy_tri = np.full(n, -1)
    numpy_t = np.full(n, np.inf)
    numpy_tri[ray_idx] = tri_idx
    numpy_t[ray_idx] = np.linalg.norm(loc - origin[ray_idx], axis=1)

    hit_e, hit_n = embree_tri >= 0, numpy_tri >= 0
    assert hit_e.mean() > 0.95 and (hit_e == hit_n).all()
    assert np.abs(embree_t[hit_e] - numpy_t[hit_e]).max() < 2e-3           # m, float32 near 10^5 m
    differ = hit_e & (embree_tri != numpy_tri)
    assert differ.sum() <= 0.005 * n, f"{differ.sum()} rays hit other triangles"
    shared = [len(set(mesh.triangles[i]) & set(mesh.triangles[j])) >= 2
              for i, j in zip(embree_tri[differ], numpy_tri[differ])]
    assert all(shared)

    # occlusion within a distance: halfway to the first hit, and just beyond it
    tfar = np.where(hit_e, embree_t, 50.0)
    for scale, want in ((0.5, False), (1.01, True)):
        got = Scene(mesh).occluded(origin, d, tfar * scale)
        if want:
            assert (got[hit_e]).all()
        assert np.array_equal(got, numpy_rays.intersects_any(origin, d) & (numpy_t <= tfar * scale))
