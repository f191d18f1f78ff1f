"""``vipvflow export dynamizer|gltf``: a run's results as CityGML 3.0 Dynamizers, or as a
3D model (glTF binary) of its buildings and segments."""
from __future__ import annotations

import argparse
import sys


def _list(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()]


def register(sub):
    p = sub.add_parser("export", help="export a finished run to other formats",
                       description="Export the outputs of a run directory. See docs/dynamizer.md.")
    kinds = p.add_subparsers(dest="kind", metavar="KIND", required=True)
    d = kinds.add_parser(
        "dynamizer", help="CityGML 3.0 file with Dynamizer time series of the results",
        description="Write the routes (tran:Road / tran:TrafficSpace with their 3D LineStrings, per "
        "10 m segment or per route and direction), the network's hourly pattern and the reflecting "
        "building surfaces as CityGML 3.0 city objects whose generic attributes are driven by "
        "Dynamizers holding the run's monthly irradiation (Wh/m2) and energy (kWh). The file "
        "validates against the official CityGML 3.0 schemas and is written as a stream.")
    d.add_argument("run_dir", metavar="RUN_DIR", help="run directory, e.g. out/demo/2024")
    d.add_argument("--out", "-o", required=True, metavar="TWIN.gml", help="CityGML file to write")
    d.add_argument("--encoding", choices=["inline", "tabulated"], default="inline",
                   help="inline dyn:GenericTimeseries (default) or dyn:TabulatedFileTimeseries "
                   "in a CSV beside the GML")
    d.add_argument("--aggregate", choices=["segment", "route"], default=None,
                   help="a TrafficSpace per 10 m segment, or per route and direction (values summed); "
                   "default: segment up to 20,000 segments, route above")
    d.add_argument("--routes", type=_list, default=None, metavar="R1,R2",
                   help="export only these routes (route_short_name)")
    d.add_argument("--months", type=_list, default=None, metavar="M1,M2",
                   help="export only these months of the run (6 or 2024-06)")
    d.add_argument("--reflectors", action=argparse.BooleanOptionalAction, default=None,
                   help="write the building surfaces that reflect onto the routes with their share "
                   "of the reflected energy (default: with --aggregate segment only)")
    d.add_argument("--embed", metavar="INPUT_V3.gml", default=None,
                   help="a CityGML 3.0 file: write a streamed copy of it with the results added")
    d.add_argument("--segments", type=int, default=None, metavar="N",
                   help="export only the first N selected segments")
    d.set_defaults(func=run)
    g = kinds.add_parser(
        "gltf", help="3D model (glTF 2.0 binary) of the run's buildings and yield-coloured segments",
        description="Write the buildings of the run's tiles (one mesh per building) and its route "
        "segments (quads at the bus roof's height, coloured by annual PV yield) as a glTF 2.0 "
        "binary file any 3D viewer opens; coordinates are the model's CRS shifted to a local "
        "origin, stated in the file's extras. A run writes its own city.glb; see docs/outputs.md.")
    g.add_argument("run_dir", metavar="RUN_DIR", help="run directory, e.g. out/demo/2024")
    g.add_argument("--out", "-o", required=True, metavar="CITY.glb", help="file to write")
    g.set_defaults(func=run_gltf)


def run_gltf(args):
    from ..outputs.gltf import write_gltf
    from ..simulation.rundir import open_run

    run = open_run(args.run_dir, needs=("city/tiles.json",))
    res = write_gltf(run.path, args.out, data_dir=run.data_dir)
    print(f"wrote {res['path']} ({res['path'].stat().st_size:,} bytes): {res['buildings']:,} "
          f"buildings of {len(res['tiles'])} tiles, {res['segments']:,} segments; "
          f"{res['crs']} minus origin {', '.join(f'{v:.0f}' for v in res['origin'])}")
    return 0


def run(args):
    from ..outputs import write_dynamizers
    from ..simulation.rundir import open_run
    from ..store import file_path

    open_run(args.run_dir)      # the run and its data dir, or one line saying what is missing
    file_path(args.out, "--out", "twin.gml")
    res = write_dynamizers(args.run_dir, args.out, encoding=args.encoding, embed=args.embed,
                           max_segments=args.segments, aggregate=args.aggregate, routes=args.routes,
                           months=args.months, reflectors=args.reflectors)
    for f in res["files"]:
        print(f"wrote {f} ({f.stat().st_size:,} bytes)")
    if args.aggregate is None and res["aggregate"] == "route":
        print(f"{res['segments']:,} segments: aggregated per route and direction "
              "(--aggregate segment for one TrafficSpace per segment)", file=sys.stderr)
    return 0
