"""``vipvflow ingest gtfs FEED --data-dir DIR``: a GTFS feed to hyper-segments and patterns."""
from __future__ import annotations

from pathlib import Path

from ..store import DataDir
from . import add_config


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
    p.set_defaults(func=run)


def run(args) -> int:
    from ..config import load_config
    from ..inputs.gtfs import ingest_gtfs

    cfg = load_config(args.config)
    report = ingest_gtfs(Path(args.feed), Path(args.data_dir), cfg.trajectory, crs=args.crs,
                         dist_units=args.dist_units,
                         timezone=args.timezone or cfg.inputs.gtfs_timezone,
                         route_types=cfg.run.route_types)
    c = report["counts"]
    print(f"GTFS {args.feed} -> {DataDir(args.data_dir).gtfs.root}  ({report['seconds']} s)")
    print(f"  CRS {report['crs']} ({report['crs_source']}), timezone {report['timezone']}, "
          f"timing {report['timing']}")
    print(f"  shapes {c['shapes']}  segments {c['segments']}  tiles {c['tiles']}  "
          f"trips {c['trips']}  patterns {c['patterns']}  routes {c['routes']}  "
          f"({report['total_shape_length_km']} km of shapes)")
    for line in findings(report):
        print("  " + line)
    return 0


def findings(report: dict) -> list[str]:
    """The ingest's problems as printed lines (also shown by ``simulate``)."""
    if not report["problems"]:
        return ["problems: none"]
    return [f"problems ({len(report['problems'])}):"] + [f"  - {p}" for p in report["problems"]]
