"""``vipvflow track --city DIR --cams FILE TRACK.csv --out OUT.csv``: irradiance along a GPS track."""
from __future__ import annotations

import json
from pathlib import Path

from ..config import load_config
from ..errors import InputError
from ..store import DataDir, file_path
from . import accepted, add_accept, add_config


def register(sub):
    p = sub.add_parser(
        "track", help="model the roof irradiance along a recorded GPS track",
        description="Evaluate direct, diffuse and reflected irradiance at every point of a "
                    "track CSV (time, lat/lon or x/y, optional z, heading_deg, measured_wm2) "
                    "in an ingested city; with measured_wm2, print RMSE, MBE and R2.")
    p.add_argument("track", type=Path, help="track CSV")
    p.add_argument("--city", type=Path, required=True,
                   help="data dir holding city/ (tiles, meshes), or a run folder (its data dir)")
    p.add_argument("--cams", type=Path, nargs="+", required=True, help="CAMS CSV file(s) covering the track")
    p.add_argument("--crs", default=None, help="CRS of x/y columns (default: the city's)")
    p.add_argument("--out", type=Path, required=True, help="output CSV")
    add_config(p)
    add_accept(p)
    p.set_defaults(func=run)


def run(args):
    from ..models.sun_sky import RadiationTable
    from ..simulation.track import check_track_times, fit_stats, model_track, read_track

    cfg = load_config(args.config)
    if (args.city / "manifest.json").is_file():      # a run folder: the city of its data dir
        from ..simulation.rundir import open_run

        args.city = open_run(args.city, needs=("city/tiles.json",)).data_dir
    tiles_json = DataDir(args.city).city.tiles_json
    if not tiles_json.is_file():
        raise InputError(f"{tiles_json}: not found; run 'vipvflow ingest city' first")
    city_crs = json.loads(tiles_json.read_text())["crs"]
    file_path(args.out, "--out", "track_irradiance.csv")
    track = read_track(args.track, city_crs, args.crs)
    table = RadiationTable.from_cams(args.cams, accept=accepted(cfg, args))
    check_track_times(track, table, args.track, args.cams)
    out = model_track(track, args.city, table, cfg.irradiance, cfg.trajectory.roof_height_m,
                      ground_albedo=cfg.city.albedo.ground, road_albedo=cfg.city.albedo.road)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    out.to_csv(args.out, index=False)
    print(f"{len(out)} points -> {args.out}")
    if "measured_wm2" in out:
        s = fit_stats(out["measured_wm2"], out["total"])
        print(f"measured vs modelled total (n={s['n']}): RMSE {s['rmse']:.1f} W/m2, "
              f"MBE {s['mbe']:+.1f} W/m2, R2 {s['r2']:.3f}")
    return 0
