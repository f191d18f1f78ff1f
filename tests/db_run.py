"""A small run directory with the files and columns ``simulation.reduce`` writes.

Used by ``tests/test_db.py`` until a real simulated run is at hand (set
``VIPVFLOW_TEST_RUN_DIR`` to a real ``out/<scenario>/<year>`` to test the mirror on it).
The values are synthetic but consistent: route, block and fleet tables are sums of the trip
table, as in the reduce step.
"""
from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import shapely

PV = ["pv_kwh", "pv_kwh_clear", "pv_kwh_unshaded", "pv_kwh_clear_unshaded",
      "pv_kwh_direct", "pv_kwh_diffuse", "pv_kwh_reflected"]
H = ["h_direct", "h_diffuse", "h_reflected", "h_total", "h_total_unshaded", "h_direct_clear",
     "h_diffuse_clear", "h_reflected_clear", "h_total_clear", "h_total_clear_unshaded", "h_ghi",
     "h_ghi_clear"]
CRS = "EPSG:2169"


def write_run(run_dir: Path, scenario: str = "dbtest", year: int = 2024, seed: int = 7) -> Path:
    """Write a run of 2 routes (one shape each way), ~60 segments, 12 months, ~200 trips."""
    rng = np.random.default_rng(seed)
    run_dir.mkdir(parents=True, exist_ok=True)
    months = [f"{year}-{m:02d}" for m in range(1, 13)]

    # --- segments: 10 m pieces of two streets in Luxembourg City (LUREF metres)
    seg_rows, lines = [], []
    shapes = {"S1": ((77050.0, 75020.0), 0.0), "S2": ((77400.0, 75480.0), 90.0)}
    sid = 0
    for shape_id, ((x0, y0), heading) in shapes.items():
        n = 30
        dx, dy = np.sin(np.radians(heading)) * 10.0, np.cos(np.radians(heading)) * 10.0
        for k in range(n):
            xa, ya, xb, yb = x0 + k * dx, y0 + k * dy, x0 + (k + 1) * dx, y0 + (k + 1) * dy
            za, zb = 300.0 + 0.02 * k * 10 + 3.2, 300.0 + 0.02 * (k + 1) * 10 + 3.2
            seg_rows.append({
                "segment_id": sid, "shape_id": shape_id, "seg_index": k,
                "x": xa, "y": ya, "z": za, "x_end": xb, "y_end": yb, "z_end": zb,
                "ground_z": za - 3.2, "heading_deg": heading, "gradient": 0.02,
                "length_m": 10.0, "cum_dist_m": 10.0 * k,
                "tile": f"E{int(xa // 500 * 5):04d}N{int(ya // 500 * 5):04d}"})
            mid = ((xa + xb) / 2 + rng.normal(0, 0.5), (ya + yb) / 2 + rng.normal(0, 0.5), (za + zb) / 2)
            lines.append(shapely.LineString([(xa, ya, za), mid, (xb, yb, zb)]))
            sid += 1
    seg = pd.DataFrame(seg_rows).astype({"seg_index": "int32", "segment_id": "int64"})
    # geometry factors merged from parts/geometry (any numeric columns)
    seg["sky_view_factor"] = rng.uniform(0.3, 1.0, len(seg))
    seg["n_reflectors"] = rng.integers(0, 40, len(seg)).astype("int32")
    segments = gpd.GeoDataFrame(seg, geometry=lines, crs=CRS)
    segments.to_parquet(run_dir / "segments.parquet", index=False)

    # --- trips: per route and direction, a few trips on a few service dates a month
    routes = {("R1", 0): ("1", "S1"), ("R1", 1): ("1", "S2"), ("R16", 0): ("16", "S2")}
    trip_rows = []
    for (route_id, direction), (short, shape_id) in routes.items():
        for m in range(1, 13):
            for day in (3, 17):
                for t in range(2):
                    trip_id = f"{route_id}-{direction}-{t}"
                    pv = rng.uniform(0.05, 2.0, 3)
                    row = {"trip_id": trip_id,
                           "service_date": pd.Timestamp(year, m, day),
                           "pv_kwh": pv[0], "pv_kwh_clear": pv[0] * 1.4,
                           "pv_kwh_unshaded": pv[0] * 1.1, "pv_kwh_clear_unshaded": pv[0] * 1.6,
                           "pv_kwh_direct": pv[0] * 0.6, "pv_kwh_diffuse": pv[0] * 0.35,
                           "pv_kwh_reflected": pv[0] * 0.05, "seconds": float(rng.integers(600, 1800)),
                           "route_id": route_id, "route_short_name": short,
                           "direction_id": direction, "shape_id": shape_id,
                           "service_id": "WD", "block_id": f"B{t + 1}",
                           "pattern_id": f"P{route_id}{direction}", "start_s": 21600.0 + 3600 * t,
                           "month": f"{year}-{m:02d}"}
                    row["consumption_kwh"] = rng.uniform(15, 40)
                    row["traction_kwh"] = row["consumption_kwh"] * 0.7
                    row["recuperated_kwh"] = row["consumption_kwh"] * 0.2
                    row["aux_kwh"] = row["consumption_kwh"] * 0.5
                    trip_rows.append(row)
    trip = pd.DataFrame(trip_rows).sort_values(["trip_id", "service_date"]).reset_index(drop=True)
    trip["coverage"] = trip["pv_kwh"] / trip["consumption_kwh"]
    trip.to_parquet(run_dir / "trip_energy.parquet", index=False)

    # --- segment-month (GeoParquet)
    sm_rows = []
    for _, s in seg.iterrows():
        for month in months:
            n = int(rng.integers(20, 200))
            h = rng.uniform(50, 5000, len(H))
            sm_rows.append({"segment_id": s.segment_id, "n_passes": n,
                            **{c: float(rng.uniform(0, 0.3)) for c in PV},
                            **dict(zip(H, h)), "seconds": float(n * 1.3), "month": month,
                            "tile": s.tile})
    sm = pd.DataFrame(sm_rows)
    sm.loc[3, "h_total_unshaded"] = 0.0  # a segment never in the sun: shading loss undefined
    sm["shading_loss"] = 1.0 - sm["h_total"] / sm["h_total_unshaded"].where(sm["h_total_unshaded"] > 0)
    sm["shading_loss_clear"] = 1.0 - sm["h_total_clear"] / sm["h_total_clear_unshaded"].where(
        sm["h_total_clear_unshaded"] > 0)
    shape_route = trip.drop_duplicates("shape_id")[["shape_id", "route_short_name", "direction_id"]]
    smg = segments[["segment_id", "shape_id", "geometry"]].merge(sm, on="segment_id", how="inner")
    smg = gpd.GeoDataFrame(smg.merge(shape_route, on="shape_id", how="left"),
                           geometry="geometry", crs=CRS)
    smg.to_parquet(run_dir / "segment_month.parquet", index=False)

    # --- route-month, block-day, fleet-month, hourly pattern
    kwh_cols = PV + ["seconds"]
    rm = (trip.groupby(["route_id", "route_short_name", "direction_id", "month"], sort=True)
          .agg(trips=("trip_id", "size"),
               **{c: (c, "sum") for c in kwh_cols + ["consumption_kwh"]}).reset_index())
    rm["coverage"] = rm["pv_kwh"] / rm["consumption_kwh"]
    rm["shading_loss"] = 1 - rm["pv_kwh"] / rm["pv_kwh_unshaded"]
    rm.to_parquet(run_dir / "route_month.parquet", index=False)
    bd = (trip.groupby(["block_id", "service_date"], sort=True)
          .agg(trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"),
               pv_kwh_clear=("pv_kwh_clear", "sum"), consumption_kwh=("consumption_kwh", "sum"),
               first_departure_s=("start_s", "min")).reset_index())
    bd.to_parquet(run_dir / "block_day.parquet", index=False)
    n_buses, kwp, usable = 2, 3.0, 300.0
    monthly = (trip.groupby("month", sort=True)
               .agg(trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"),
                    pv_kwh_clear=("pv_kwh_clear", "sum"), pv_kwh_unshaded=("pv_kwh_unshaded", "sum"),
                    pv_kwh_clear_unshaded=("pv_kwh_clear_unshaded", "sum"),
                    consumption_kwh=("consumption_kwh", "sum")).reset_index())
    monthly["avoided_charging_cycles"] = monthly["pv_kwh"] / usable
    monthly["kwh_per_kwp_allsky"] = monthly["pv_kwh"] / (kwp * n_buses)
    monthly["kwh_per_kwp_clearsky"] = monthly["pv_kwh_clear"] / (kwp * n_buses)
    monthly.to_parquet(run_dir / "monthly.parquet", index=False)
    hp = pd.DataFrame([{"month": m, "hour": np.int8(h)} for m in months for h in range(5, 23)])
    hp["hour"] = hp["hour"].astype("int8")
    for c in H:
        hp[c] = rng.uniform(0, 300, len(hp))
    hp["seconds"] = rng.uniform(0, 5000, len(hp))
    for c in H:
        hp["g_" + c[2:]] = hp[c] * 3600.0 / hp["seconds"].where(hp["seconds"] > 0)
    hp.to_parquet(run_dir / "hourly_pattern.parquet", index=False)

    tot = smg[H].sum()
    summary = {
        "scenario": scenario, "year": year, "pv_mode": "paper", "diffuse_model": "isotropic",
        "routes": int(trip["route_id"].nunique()), "trips": int(len(trip)), "buses": n_buses,
        "segments": int(len(segments)), "passes": int(smg["n_passes"].sum()), "kwp_per_bus": kwp,
        "pv_kwh_allsky": float(trip["pv_kwh"].sum()), "pv_kwh_clearsky": float(trip["pv_kwh_clear"].sum()),
        "pv_kwh_allsky_unshaded": float(trip["pv_kwh_unshaded"].sum()),
        "kwh_per_kwp_allsky": float(trip["pv_kwh"].sum() / (kwp * n_buses)),
        "kwh_per_kwp_clearsky": float(trip["pv_kwh_clear"].sum() / (kwp * n_buses)),
        "irradiation_kwh_m2": {k[2:]: float(v) / 1000.0 for k, v in tot.items()},
        "shading_loss_allsky": float(1 - tot["h_total"] / tot["h_total_unshaded"]),
        "coverage": float(trip["pv_kwh"].sum() / trip["consumption_kwh"].sum()),
        "fleet_demand_mwh": float(trip["consumption_kwh"].sum() / 1000.0),
        "payback_years": 11.5, "avoided_charging_cycles_per_bus": 3.25,
    }
    (run_dir / "summary.json").write_text(json.dumps(summary, indent=2))
    digest = hashlib.sha256(f"{scenario}{seed}".encode()).hexdigest()[:16]
    manifest = {"scenario": scenario, "year": year, "config_digest": digest,
                "config": {"scenario": scenario, "pv": {"mode": "paper"}},
                "inputs_sha256": {}, "versions": {"vipvflow": "0.1.0"},
                "created_utc": "2024-12-31T00:00:00Z"}
    (run_dir / "manifest.json").write_text(json.dumps(manifest, indent=2))
    return run_dir


def clone_run(src: Path, dest: Path, scenario: str) -> Path:
    """A copy of a run directory under another scenario name (so another run id)."""
    shutil.copytree(src, dest, ignore=shutil.ignore_patterns("parts", "figures", "*.html"))
    for name in ("manifest.json", "summary.json"):
        d = json.loads((dest / name).read_text())
        d["scenario"] = scenario
        (dest / name).write_text(json.dumps(d, indent=2))
    return dest


def checksums(run_dir: Path) -> dict:
    """(size, mtime, SHA-256) of every file below *run_dir*."""
    out = {}
    for p in sorted(run_dir.rglob("*")):
        if p.is_file():
            st = p.stat()
            out[str(p.relative_to(run_dir))] = (st.st_size, st.st_mtime_ns,
                                                hashlib.sha256(p.read_bytes()).hexdigest())
    return out
