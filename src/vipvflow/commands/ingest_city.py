"""``vipvflow ingest city FILE... --data-dir DIR``: CityGML -> tiled surfaces and meshes."""
from __future__ import annotations

from pathlib import Path

from ..config import load_config
from ..errors import InputError
from ..progress import set_quiet
from . import accepted, add_accept, add_config, ingest_lock


def register(sub):
    p = sub.add_parser(
        "city", help="read CityGML LoD2 files into tiled surfaces, tile meshes and terrain",
        description="Stream-read CityGML 1.0/2.0/3.0 files (.gml, .xml, .gml.gz or .zip) and "
                    "write <data-dir>/city/: surfaces per tile (GeoParquet), tile meshes, "
                    "tiles.json, terrain.npz, the trees' crowns (CityGML vegetation and tree "
                    "tables: trees.parquet, trees/) and ingest_report.json.")
    p.add_argument("files", nargs="*", type=Path,
                   help="CityGML files (default: inputs.citygml of the config)")
    p.add_argument("--data-dir", type=Path, default=None,
                   help="scenario data dir (default: data_dir of the config)")
    p.add_argument("--crs", default=None,
                   help="output CRS (projected), also assumed for files without srsName (e.g. "
                        "EPSG:2169); default: the file's CRS, or its local UTM zone when geographic")
    p.add_argument("--axis-order", choices=["auto", "epsg", "xy"], default="auto",
                   help="coordinate order in the files: auto (default: the CRS's EPSG order for "
                        "geographic CRSs; for projected ones the order that fits the CRS's area "
                        "of use, easting first when both do), epsg (always the EPSG order), "
                        "xy (always easting/longitude first)")
    p.add_argument("--trees", type=Path, action="append", default=None, metavar="TABLE",
                   help="a tree table (CSV or GeoParquet points: height, crown_diameter, ...; "
                        "repeat for more); default: inputs.trees of the config")
    p.add_argument("--trees-crs", default=None,
                   help="CRS of a CSV tree table's x/y columns (default: inputs.trees_crs, else "
                        "the city's)")
    add_config(p)
    add_accept(p)
    p.add_argument("--quiet", "-q", action="store_true",
                   help="no progress bars or progress lines")
    p.set_defaults(func=run)


def run(args):
    set_quiet(args.quiet)
    from ..inputs.city import ingest_city

    cfg = load_config(args.config)
    files = list(args.files) or list(cfg.inputs.citygml)
    if not files:
        raise InputError("no CityGML file given (pass FILE... or set inputs.citygml in --config)")
    data_dir = args.data_dir or cfg.data_dir
    crs = args.crs or cfg.inputs.citygml_crs
    trees = list(args.trees) if args.trees else list(cfg.inputs.trees)
    with ingest_lock(data_dir):
        report = ingest_city(files, data_dir, cfg.city, crs=crs, axis_order=args.axis_order,
                             accept=accepted(cfg, args), trees=trees,
                             trees_crs=args.trees_crs or cfg.inputs.trees_crs)
    print(report.summary())
    print(f"report: {report.report_path}")
    return 0
