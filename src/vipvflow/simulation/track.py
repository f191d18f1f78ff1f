"""Model the roof irradiance along a recorded GPS track and compare with measurements.

A track CSV has a ``time`` column (ISO 8601, naive = UTC, or Unix seconds), positions as
``lat, lon`` (WGS84) or ``x, y`` (a projected CRS, by default the city's), optionally ``z``
(height of the PV plane, m), ``heading_deg`` and a measured irradiance ``measured_wm2``.
Each point is evaluated like a segment pass of the simulation (the same geometry, Embree
shading and reflection code) at its own instant.
"""
from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import pandas as pd

from ..config import IrradianceCfg
from ..errors import InputError
from ..store import DataDir
from ..models.irradiance import evaluate_passes
from ..models.view_factors import segment_geometry
from ..models.shading import get_scene
from ..inputs.tiles import tile_names

log = logging.getLogger(__name__)


def _parse_time(col: pd.Series, path) -> np.ndarray:
    if pd.api.types.is_numeric_dtype(col):
        return col.to_numpy(np.float64)
    try:
        t = pd.to_datetime(col, utc=True, format="ISO8601")
    except (ValueError, TypeError) as exc:
        raise InputError(f"{path}: column 'time': not ISO 8601 or Unix seconds ({exc})") from None
    return t.to_numpy("datetime64[ns]").astype(np.int64) / 1e9


def headings(x, y, min_step_m: float = 0.5) -> np.ndarray:
    """Heading (deg from north, clockwise) from consecutive points; held while stationary."""
    x, y = np.asarray(x, float), np.asarray(y, float)
    if len(x) < 2:
        return np.zeros(len(x))
    dx, dy = np.diff(x), np.diff(y)
    h = np.degrees(np.arctan2(dx, dy)) % 360.0
    moving = np.hypot(dx, dy) >= min_step_m
    if not moving.any():
        return np.zeros(len(x))
    idx = np.where(moving, np.arange(len(h)), -1)
    idx = np.maximum.accumulate(idx)
    idx[idx < 0] = np.flatnonzero(moving)[0]
    h = h[idx]
    return np.append(h, h[-1])


def read_track(path, city_crs: str, crs: str | None = None) -> pd.DataFrame:
    """Read a track CSV into ``t_utc, x, y`` (city CRS) and optional ``z, heading_deg,
    measured_wm2, lat, lon``."""
    from pyproj import Transformer

    try:
        df = pd.read_csv(path)
    except pd.errors.EmptyDataError:
        raise InputError(f"{path}: empty: a track CSV needs a header (time, lat, lon or x, y) "
                         "and one row per point") from None
    except (OSError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: cannot read track CSV: {' '.join(str(exc).split())}") from None
    if "time" not in df.columns:
        raise InputError(f"{path}: column 'time' missing (have: {', '.join(map(str, df.columns))})")
    if df.empty:
        raise InputError(f"{path}: no points (a header and no rows)")
    out = pd.DataFrame({"t_utc": _parse_time(df["time"], path)})
    bad = ~np.isfinite(out["t_utc"].to_numpy(float))
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InputError(f"{path}: line {i + 2}: time {df['time'].iloc[i]!r} is missing or not a "
                         "time")
    if crs is not None:
        from pyproj import CRS
        from pyproj.exceptions import CRSError

        try:
            CRS.from_user_input(crs)
        except CRSError:
            raise InputError(f"--crs {crs}: not a CRS PROJ knows (give one such as EPSG:2169)") from None
    to_city = None
    if {"lat", "lon"} <= set(df.columns):
        to_city = Transformer.from_crs("EPSG:4326", city_crs, always_xy=True)
        out["x"], out["y"] = to_city.transform(df["lon"].to_numpy(float), df["lat"].to_numpy(float))
        out["lat"], out["lon"] = df["lat"].to_numpy(float), df["lon"].to_numpy(float)
    elif {"x", "y"} <= set(df.columns):
        x, y = df["x"].to_numpy(float), df["y"].to_numpy(float)
        if crs and crs != city_crs:
            x, y = Transformer.from_crs(crs, city_crs, always_xy=True).transform(x, y)
        out["x"], out["y"] = x, y
        back = Transformer.from_crs(city_crs, "EPSG:4326", always_xy=True)
        out["lon"], out["lat"] = back.transform(out["x"].to_numpy(), out["y"].to_numpy())
    else:
        raise InputError(f"{path}: needs columns 'lat, lon' or 'x, y'")
    for col in ("z", "heading_deg", "measured_wm2"):
        if col in df.columns:
            out[col] = pd.to_numeric(df[col], errors="coerce").to_numpy(float)
    return out


def check_track_times(track: pd.DataFrame, table, path, cams) -> None:
    """Every point's time must lie within the radiation data (its first to its last minute):
    outside them the lookup has no value and the point would read 0 W/m2. Raises
    :class:`InputError` naming the points outside, the track's and the data's spans."""
    t = track["t_utc"].to_numpy(float)
    lo, hi = table.t0 - table.step_s / 2, table.t_end + table.step_s / 2
    out = (t < lo) | (t > hi)
    if not out.any():
        return

    def day(x):
        return pd.Timestamp(x, unit="s", tz="UTC").strftime("%Y-%m-%d %H:%M")
    files = ", ".join(str(c) for c in cams)
    raise InputError(f"{path}: {int(out.sum())} of {len(t)} points (from {day(t[out].min())} to "
                     f"{day(t[out].max())} UTC) lie outside the radiation data of {files} "
                     f"({day(lo)} to {day(hi)} UTC): give CAMS data covering the track")


def fit_stats(measured, modelled) -> dict:
    """RMSE, MBE (W/m2; modelled - measured) and R2 (coefficient of determination)."""
    m, p = np.asarray(measured, float), np.asarray(modelled, float)
    ok = np.isfinite(m) & np.isfinite(p)
    m, p = m[ok], p[ok]
    err = p - m
    ss = ((m - m.mean()) ** 2).sum()
    return {"n": int(ok.sum()), "rmse": float(np.sqrt((err ** 2).mean())), "mbe": float(err.mean()),
            "r2": float(1 - (err ** 2).sum() / ss) if ss > 0 else float("nan")}


def model_track(track: pd.DataFrame, data_dir, radiation_table, cfg: IrradianceCfg | None = None,
                roof_height_m: float = 3.2, ground_albedo: float = 0.20,
                road_albedo: float = 0.10) -> pd.DataFrame:
    """Irradiance components (W/m2) at every point of a track read by :func:`read_track`.

    Parameters
    ----------
    track : DataFrame from :func:`read_track`
    data_dir : the scenario's data dir (tiles, meshes, terrain)
    radiation_table : vipvflow.models.sun_sky.RadiationTable
    cfg : IrradianceCfg, the run's physics (diffuse model, rays); its reflector sampling
        is replaced by ``all``: each point is one instant, and every sample point of its
        reflectors is traced (the lit fraction of that instant), not one in turn (right only
        on average over many passes)
    roof_height_m : float, m, the roof above the street where the track gives no ``z``
    ground_albedo, road_albedo : float, the open ground's and the street's albedo
        (``city.albedo.ground``, ``city.albedo.road``)
    """
    cfg = (cfg or IrradianceCfg()).model_copy(update={"reflector_sampling": "all"})
    data_dir = Path(data_dir)
    tiles_json = DataDir(data_dir).city.tiles_json
    meta = json.loads(tiles_json.read_text())
    tr = track.sort_values("t_utc", kind="stable").reset_index(drop=True)
    x, y = tr["x"].to_numpy(), tr["y"].to_numpy()
    z = tr["z"].to_numpy() if "z" in tr else np.full(len(tr), np.nan)
    if np.isnan(z).any():
        ground = np.full(len(tr), np.nan)
        try:
            from ..inputs.city import TerrainModel

            ground = TerrainModel.load(data_dir).elevation(x, y)
        except Exception as exc:  # no terrain stored: the mesh's lowest point below
            log.warning("no terrain model (%s); using the lowest mesh point of the tile", exc)
        z = np.where(np.isnan(z), ground + roof_height_m, z)
    heading = tr["heading_deg"].to_numpy() if "heading_deg" in tr else np.full(len(tr), np.nan)
    heading = np.where(np.isnan(heading), headings(x, y), heading)
    dist = np.hypot(np.diff(x), np.diff(y))
    grad = np.where(dist > 1.0, np.diff(z) / np.maximum(dist, 1e-9), 0.0)
    # a point without a height yet (outside the terrain model: the tile's lowest mesh point
    # below) is taken as level, instead of making every component NaN
    grad = np.where(np.isfinite(grad), grad, 0.0)
    grad = np.clip(np.append(grad, grad[-1] if len(grad) else 0.0), -0.3, 0.3)
    tiles = tile_names(x, y, float(meta["tile_size_m"]))
    loc = radiation_table.nearest_location(tr["lat"].to_numpy(), tr["lon"].to_numpy())
    parts = []
    for tile in pd.unique(tiles):
        sel = np.flatnonzero(tiles == tile)
        if tile not in meta.get("tiles", {}):
            raise InputError(f"{tiles_json}: track leaves the city: no tile {tile} "
                             f"(point {sel[0]} at x={x[sel[0]]:.1f}, y={y[sel[0]]:.1f})")
        scene = get_scene(data_dir, tile)
        zz = z[sel]
        if np.isnan(zz).any():
            zz = np.where(np.isnan(zz), scene.mesh.vertices[:, 2].min() + roof_height_m, zz)
        segs = pd.DataFrame({"segment_id": np.arange(len(sel)), "x": x[sel], "y": y[sel], "z": zz,
                             "heading_deg": heading[sel], "gradient": grad[sel]})
        geom = segment_geometry(scene, segs, cfg, road_albedo=road_albedo,
                                roof_height_m=roof_height_m if cfg.virtual_street else None)
        geom["rad_location"] = loc[sel]
        passes = pd.DataFrame({"segment_id": np.arange(len(sel)), "t_utc": tr["t_utc"].to_numpy()[sel]})
        res = evaluate_passes(passes, segs, geom, radiation_table, scene, cfg,
                              ground_albedo=ground_albedo, time_at="start")
        res.index = sel
        res["z"], res["tilt_deg"], res["svf"] = zz, geom["tilt_deg"].to_numpy(), geom["svf"].to_numpy()
        parts.append(res)
    res = pd.concat(parts).sort_index()
    out = pd.DataFrame({"time": pd.to_datetime(tr["t_utc"] * 1e9, utc=True), "x": x, "y": y,
                        "z": res["z"].to_numpy(), "heading_deg": heading, "tilt_deg": res["tilt_deg"],
                        "svf": res["svf"]})
    for col in ("direct", "diffuse", "reflected", "total", "total_clear", "total_unshaded",
                "sun_visible"):
        out[col] = res[col].to_numpy()
    if "measured_wm2" in tr:
        out["measured_wm2"] = tr["measured_wm2"].to_numpy()
    return out
