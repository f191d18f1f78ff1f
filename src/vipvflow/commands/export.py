"""``vipvflow export dynamizer``: a run's results as CityGML 3.0 Dynamizers."""
from __future__ import annotations


def register(sub):
    p = sub.add_parser("export", help="export a finished run to other formats",
                       description="Export the outputs of a run directory. See docs/dynamizer.md.")
    kinds = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    d = kinds.add_parser(
        "dynamizer", help="CityGML 3.0 file with Dynamizer time series of the results",
        description="Write the route segments (tran:Road / tran:TrafficSpace with their 3D "
        "LineStrings), the network's hourly pattern and the reflecting building surfaces as "
        "CityGML 3.0 city objects whose generic attributes are driven by Dynamizers holding the "
        "run's monthly irradiation (Wh/m2) and energy (kWh).")
    d.add_argument("run_dir", metavar="RUN_DIR", help="run directory, e.g. out/demo/2024")
    d.add_argument("--out", "-o", required=True, metavar="TWIN.gml", help="CityGML file to write")
    d.add_argument("--encoding", choices=["inline", "tabulated"], default="inline",
                   help="inline dyn:GenericTimeseries (default) or dyn:TabulatedFileTimeseries "
                   "in a CSV beside the GML")
    d.add_argument("--embed", metavar="INPUT_V3.gml", default=None,
                   help="a CityGML 3.0 file: write a streamed copy of it with the results added")
    d.add_argument("--segments", type=int, default=None, metavar="N",
                   help="export only the first N segments")
    d.set_defaults(func=run)


def run(args):
    from ..export import write_dynamizers
    from ..simulation.rundir import open_run

    open_run(args.run_dir)      # the run and its data dir, or one line saying what is missing
    res = write_dynamizers(args.run_dir, args.out, encoding=args.encoding, embed=args.embed,
                           max_segments=args.segments)
    for f in res["files"]:
        print(f"wrote {f} ({f.stat().st_size:,} bytes)")
    return 0
