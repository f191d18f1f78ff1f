"""Embree ray queries against a plain-numpy reference and analytic distances."""
from __future__ import annotations

import numpy as np
import pytest

from vipvflow.models import shading
from vipvflow.models.shading import Scene, box_mesh, get_scene, occluded_reference

X0, Y0 = 77_000.0, 75_000.0       # LUREF-like coordinates: precision must survive float32


def _city(n=40, seed=1):
    rng = np.random.default_rng(seed)
    c = rng.uniform(0, 200, (n, 2))
    w = rng.uniform(5, 20, (n, 2))
    h = rng.uniform(5, 30, n)
    return box_mesh(np.column_stack([X0 + c[:, 0] - w[:, 0] / 2, Y0 + c[:, 1] - w[:, 1] / 2,
                                     np.zeros(n), X0 + c[:, 0] + w[:, 0] / 2,
                                     Y0 + c[:, 1] + w[:, 1] / 2, h]))


def _rays(n, seed=2):
    rng = np.random.default_rng(seed)
    o = np.column_stack([X0 + rng.uniform(-20, 220, n), Y0 + rng.uniform(-20, 220, n),
                         rng.uniform(0.5, 10, n)])
    d = rng.normal(size=(n, 3))
    d[:, 2] = np.abs(d[:, 2]) * 0.5
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return o, d


def test_occluded_matches_numpy_reference():
    mesh = _city()
    scene = Scene(mesh)
    o, d = _rays(3000)
    tfar = np.random.default_rng(3).uniform(5, 150, len(o))
    fast = scene.occluded(o, d, tfar)
    ref = occluded_reference(mesh, o, d, tfar)
    assert 0.2 < ref.mean() < 0.8
    assert (fast == ref).mean() >= 0.999          # edge-grazing rays may differ in float32


def test_first_hit_distance_and_triangle():
    # a wall in the plane x = X0 + 10, facing -x
    mesh = box_mesh([[X0 + 10, Y0 - 50, 0, X0 + 12, Y0 + 50, 20]])
    scene = Scene(mesh)
    ang = np.radians([0, 30, -45, 60])
    o = np.tile([X0, Y0, 5.0], (4, 1))
    d = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(4)])
    tri, t = scene.first_hit(o, d, 100.0)
    assert np.allclose(t, 10 / np.cos(ang), atol=1e-3)
    assert np.allclose(mesh.normals[tri], [-1, 0, 0])
    tri, t = scene.first_hit(o, -d, 100.0)                # away from the wall: no hit
    assert (tri == -1).all() and np.isinf(t).all()
    assert not scene.occluded(o[:1], d[:1], 9.99)[0] and scene.occluded(o[:1], d[:1], 10.01)[0]


def test_float32_precision_far_from_origin():
    x = 1_000_000.0
    scene = Scene(box_mesh([[x, x, 0, x + 10, x + 10, 12.0]]))
    o = np.array([[x - 20, x + 5, 12.005], [x - 20, x + 5, 11.995]])
    d = np.tile([1.0, 0, 0], (2, 1))
    assert scene.occluded(o, d, 100.0).tolist() == [False, True]


def test_threaded_batches_equal_single_thread():
    mesh = _city()
    o, d = _rays(4 * shading._MIN_SPLIT + 17)
    a = Scene(mesh, n_threads=1).occluded(o, d, 100.0)
    b = Scene(mesh, n_threads=4).occluded(o, d, 100.0)
    assert (a == b).all()
    ta, da = Scene(mesh, n_threads=1).first_hit(o, d, 100.0)
    tb, db = Scene(mesh, n_threads=4).first_hit(o, d, 100.0)
    assert (ta == tb).all() and np.array_equal(da, db)


def test_empty_mesh_never_occludes():
    empty = box_mesh(np.zeros((0, 6)))
    scene = Scene(empty)
    o, d = _rays(10)
    assert not scene.occluded(o, d, 100.0).any()
    assert (scene.first_hit(o, d, 100.0)[0] == -1).all()


def test_get_scene_builds_once_per_tile(tmp_path):
    for name in ("E0770N0750", "E0775N0750"):
        _city().save(tmp_path / "city" / "meshes" / f"{name}.npz")
    shading.clear_scene_cache()
    key = (str(tmp_path.resolve()), "E0770N0750")
    before = shading.BVH_BUILDS[key]
    s1 = get_scene(tmp_path, "E0770N0750", cache_size=1)
    s2 = get_scene(tmp_path, "E0770N0750", cache_size=1)
    assert s1 is s2 and shading.BVH_BUILDS[key] == before + 1
    get_scene(tmp_path, "E0775N0750", cache_size=1)       # evicts the first
    get_scene(tmp_path, "E0770N0750", cache_size=1)
    assert shading.BVH_BUILDS[key] == before + 2
    # a tile without a mesh (a line leaving the city model) is an open field
    assert len(get_scene(tmp_path, "E0000N0000").mesh.triangles) == 0


def test_benchmark_tiny_writes_figures():
    import sys

    from conftest import ROOT

    sys.path.insert(0, str(ROOT))
    from benchmarks.bench_shading import run

    res = run(tiny=True)
    fig = res["figures"]
    for key in ("raw_embreex_rays_per_s", "kernel_rays_per_s", "kernel_vs_raw", "passes_per_s",
                "passes_per_s_per_core"):
        assert fig[key] > 0
    assert fig["kernel_equals_raw"] is True
    assert 0 < fig["sun_visible_share"] < 1 and 0 <= fig["shading_loss_share"] < 1
