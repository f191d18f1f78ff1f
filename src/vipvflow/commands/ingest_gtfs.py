"""``vipvflow ingest gtfs FEED --data-dir DIR``: a GTFS feed to hyper-segments and patterns."""
from __future__ import annotations

from pathlib import Path

from ..store import DataDir
from . import accepted, add_accept, add_config, ingest_lock


def register(sub):
    p = sub.add_parser("gtfs", help="GTFS feed -> gtfs/segments.parquet, trips, patterns",
                       description="Read a GTFS zip or folder (gtfs-kit), cut every shape into "
                       "hyper-segments and write the trajectory stage files under "
                       "DATA_DIR/gtfs/.")
    p.add_argument("feed", help="GTFS zip file or folder")
    p.add_argument("--data-dir", required=True, help="scenario data directory")
    p.add_argument("--crs", default=None,
                   help="projected CRS when the city is not ingested, e.g. EPSG:2169 "
                        "(default: city/tiles.json, else the local UTM zone)")
    add_config(p)
    p.add_argument("--dist-units", default=None, choices=["m", "km", "mi", "ft"],
                   help="units of shape_dist_traveled (default: inferred and checked)")
    p.add_argument("--timezone", default=None,
                   help="IANA time zone of the timetable when the feed has no agency.txt "
                        "(default: inputs.gtfs_timezone of --config)")
    p.add_argument("--ground-elevation", type=float, default=None, metavar="M",
                   help="ground height (m above sea level) where the city model has no relief and "
                        "no building within 100 m (default: trajectory.ground_elevation_m of "
                        "--config, else the altitude in the header of the ingested CAMS files)")
    add_accept(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..config import load_config
    from ..inputs.gtfs import ingest_gtfs

    cfg = load_config(args.config)
    traj = cfg.trajectory
    if args.ground_elevation is not None:
        traj = traj.model_copy(update={"ground_elevation_m": args.ground_elevation})
    with ingest_lock(args.data_dir):
        report = ingest_gtfs(Path(args.feed), Path(args.data_dir), traj, crs=args.crs,
                             dist_units=args.dist_units,
                             timezone=args.timezone or cfg.inputs.gtfs_timezone,
                             route_types=cfg.run.route_types, accept=accepted(cfg, args))
    print(f"GTFS {args.feed} -> {DataDir(args.data_dir).gtfs.root}  ({report['seconds']} s)")
    print(f"  CRS {report['crs']} ({report['crs_source']}), timezone {report['timezone']}, "
          f"timing {report['timing']}")
    for line in summary_lines(report):
        print("  " + line)
    for line in findings(report):
        print("  " + line)
    return 0


def summary_lines(report: dict) -> list[str]:
    """What the ingest made: counts, route-km in the city model, where the ground comes from."""
    c = report["counts"]
    lines = [f"shapes {c['shapes']} ({c['shapes_built_from_stops']} built from stops), segments "
             f"{c['segments']}, tiles {c['tiles']}, trips {c['trips']}, patterns {c['patterns']}, "
             f"routes {c['routes']} ({report['total_shape_length_km']} km of shapes); "
             f"timezone {report['timezone']}, CRS {report['crs']}"]
    if "route_km" in report:
        km, inside = report["route_km"], report["route_km_in_city_model"]
        share = 100 * inside / km if km else 0.0
        src = ", ".join(f"{k} {v}" for k, v in report.get("ground_sources", {}).items() if v)
        lines.append(f"in the city model: {inside:.1f} of {km:.1f} route-km ({share:.0f} %); "
                     f"ground height of the segments from: {src or 'none'}")
    return lines


def findings(report: dict) -> list[str]:
    """The ingest's problems as printed lines (also shown by ``simulate``)."""
    if not report["problems"]:
        return ["problems: none"]
    return [f"problems ({len(report['problems'])}):"] + [f"  - {p}" for p in report["problems"]]
