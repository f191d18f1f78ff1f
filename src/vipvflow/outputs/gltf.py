"""A run as a 3D model any viewer opens: ``city.glb`` (glTF 2.0 binary, written by trimesh).

What it holds:

- the **buildings** of the run's tiles (the tiles its segments lie in): one mesh per building
  (node ``building <building_id>``), its surfaces (roofs, walls, ground and closure surfaces)
  as in the tile meshes the run cast its rays against, each surface in the tile of its
  centroid, so a building is written once;
- the **route segments** as one mesh (node ``segments``): each 10 m segment a quad of two
  triangles at the bus roof's height, 2.5 m wide on the right of the direction of travel
  (both directions of a street side by side), coloured by its annual PV yield
  (``kwh_per_kwp_year`` of ``segments.parquet``, viridis from the lowest to the highest;
  grey where it has none); face ``2k`` and ``2k+1`` are segment ``segment_ids[k]`` of the
  mesh's extras.

Coordinates are the model's CRS shifted to a local origin (vertex = CRS coordinate - origin,
metres, x east, y north, z up); the node ``city`` above both turns them into glTF's y-up frame.
The scene's extras state the CRS, the origin, the counts and the colour scale.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from ..models.mesh import SURFACE_CODE, TileMesh
from ..store import DataDir, RunDir, write_bytes

#: surface types of the buildings (the meshes also hold terrain and vegetation)
BUILDING_TYPES = ("roof", "wall", "ground", "closure", "other")
#: width (m) of a segment's quad: about a bus roof
SEGMENT_WIDTH_M = 2.5
#: glTF is y-up: (x east, y north, z up) -> (x, z, -y)
Z_UP_TO_Y_UP = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])
_BUILDING_RGBA = np.array([205, 200, 190, 255], np.uint8)
_NO_VALUE_RGBA = np.array([128, 128, 128, 255], np.uint8)


def _buildings(data_dir: Path, tiles: list[str]) -> tuple[np.ndarray, np.ndarray]:
    """The building triangles of *tiles* (own surfaces only): corners (F, 3, 3) in the CRS and
    each triangle's building id."""
    import pyarrow.parquet as pq

    city = DataDir(data_dir).city
    if not city.tiles_json.is_file():     # a scenario without a city model
        return np.zeros((0, 3, 3)), np.zeros(0, dtype=object)
    entries = json.loads(city.tiles_json.read_text())["tiles"]
    codes = np.array([SURFACE_CODE[t] for t in BUILDING_TYPES])
    corners, owners = [], []
    for tile in tiles:
        if tile not in entries or not entries[tile]["n_surfaces"]:
            continue                      # a segment's tile without buildings of its own
        mesh = TileMesh.load(city.mesh(tile))
        n_own = int(entries[tile]["n_surfaces"])
        bid = pq.read_table(city.surface_part(tile), columns=["building_id"]).column(0).to_numpy(
            zero_copy_only=False)
        keep = (mesh.surface_index < n_own) & np.isin(mesh.surface_type, codes)
        corners.append(mesh.vertices[mesh.triangles[keep]])
        owners.append(np.asarray(bid, dtype=object)[mesh.surface_index[keep]])
    if not corners:
        return np.zeros((0, 3, 3)), np.zeros(0, dtype=object)
    return np.concatenate(corners), np.concatenate(owners)


def _segment_quads(seg: pd.DataFrame, origin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (4 per segment, local) and faces (2 per segment) of the segments' quads."""
    p0 = seg[["x", "y", "z"]].to_numpy(float) - origin
    p1 = seg[["x_end", "y_end", "z_end"]].to_numpy(float) - origin
    d = p1[:, :2] - p0[:, :2]
    length = np.linalg.norm(d, axis=1)
    d = d / np.where(length > 0, length, 1.0)[:, None]
    right = np.column_stack([d[:, 1], -d[:, 0], np.zeros(len(d))])   # right of travel
    near, far = right * 0.25, right * (0.25 + SEGMENT_WIDTH_M)
    v = np.stack([p0 + near, p1 + near, p1 + far, p0 + far], axis=1).reshape(-1, 3)
    base = 4 * np.arange(len(seg))[:, None]
    faces = np.concatenate([base + [0, 2, 1], base + [0, 3, 2]], axis=1).reshape(-1, 3)   # facing up
    return v, faces


def _colours(values: np.ndarray) -> tuple[np.ndarray, dict]:
    """RGBA per value (viridis from the lowest to the highest finite value) and the scale."""
    from matplotlib import colormaps

    ok = np.isfinite(values)
    lo, hi = (float(values[ok].min()), float(values[ok].max())) if ok.any() else (0.0, 1.0)
    scaled = (values - lo) / (hi - lo) if hi > lo else np.full(len(values), 0.5)
    rgba = (colormaps["viridis"](np.where(ok, scaled, 0.0)) * 255).round().astype(np.uint8)
    rgba[~ok] = _NO_VALUE_RGBA
    return rgba, {"min": lo, "max": hi, "colormap": "viridis", "no_value_rgba": _NO_VALUE_RGBA.tolist()}


def city_scene(run_dir, data_dir, column: str = "kwh_per_kwp_year"):
    """The trimesh.Scene of :mod:`this module <vipvflow.outputs.gltf>` for a finished run."""
    import geopandas as gpd
    import trimesh

    run_dir = Path(run_dir)
    cols = ["segment_id", "tile", "x", "y", "z", "x_end", "y_end", "z_end", column]
    seg = gpd.read_parquet(RunDir(run_dir).output("segments.parquet"), columns=cols + ["geometry"])
    crs = seg.crs.to_string() if seg.crs is not None else None
    seg = pd.DataFrame(seg.drop(columns="geometry")).sort_values("segment_id", kind="stable")
    tiles = sorted(seg["tile"].unique())
    corners, owners = _buildings(Path(data_dir), tiles)

    points = np.concatenate([corners.reshape(-1, 3), seg[["x", "y", "z"]].to_numpy(float),
                             seg[["x_end", "y_end", "z_end"]].to_numpy(float)])
    origin = np.floor(points.min(axis=0) / [100.0, 100.0, 1.0]) * [100.0, 100.0, 1.0]

    scene = trimesh.Scene(base_frame="world")
    scene.graph.update(frame_from="world", frame_to="city", matrix=Z_UP_TO_Y_UP)
    order = np.argsort(owners, kind="stable")
    ids, starts = np.unique(owners[order], return_index=True)
    bounds = np.append(starts, len(order))
    for k, bid in enumerate(ids):
        tri = corners[order[bounds[k]:bounds[k + 1]]] - origin
        mesh = trimesh.Trimesh(vertices=tri.reshape(-1, 3), faces=np.arange(3 * len(tri)).reshape(-1, 3),
                               process=False, metadata={"building_id": str(bid)})
        # one colour per vertex, as glTF stores it: given per face, trimesh's export turned
        # each mesh's face colours into vertex colours (sparse sums), half of the export's
        # time; the file is the same to the byte
        mesh.visual.vertex_colors = np.broadcast_to(_BUILDING_RGBA, (3 * len(tri), 4))
        scene.add_geometry(mesh, geom_name=f"building {bid}", node_name=f"building {bid}",
                           parent_node_name="city")
    values = seg[column].to_numpy(float)
    rgba, scale = _colours(values)
    v, f = _segment_quads(seg, origin)
    segments = trimesh.Trimesh(vertices=v, faces=f, vertex_colors=np.repeat(rgba, 4, axis=0),
                               process=False,
                               metadata={"segment_ids": seg["segment_id"].astype(int).tolist(),
                                         "faces_per_segment": 2})
    scene.add_geometry(segments, geom_name="segments", node_name="segments", parent_node_name="city")
    scene.metadata.update({
        "vipvflow": "buildings of the run's tiles and its route segments coloured by annual PV yield",
        "crs": crs, "origin": origin.tolist(),
        "coordinates": "vertex = model CRS coordinate - origin (m; x east, y north, z up); "
                       "the node 'city' turns them into glTF's y-up frame",
        "buildings": int(len(ids)), "segments": int(len(seg)), "tiles": tiles,
        "colour": {"column": column, "unit": "kWh/kWp" if column == "kwh_per_kwp_year" else "",
                   **scale},
    })
    return scene


def write_gltf(run_dir, out, data_dir=None, column: str = "kwh_per_kwp_year") -> dict:
    """Write the run's ``city.glb`` to *out* (atomically); return the scene's extras (counts,
    CRS, origin, colour scale) and the path.  *data_dir*: the run's (found from its manifest
    when not given)."""
    if data_dir is None:
        from ..simulation.rundir import open_run

        data_dir = open_run(run_dir, needs=("city/tiles.json",)).data_dir
    scene = city_scene(run_dir, data_dir, column)
    path = write_bytes(scene.export(file_type="glb"), out)
    return {**scene.metadata, "path": path}
