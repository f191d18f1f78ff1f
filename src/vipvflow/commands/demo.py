"""``vipvflow demo-data``: write the embedded demo scenario's input files."""
from __future__ import annotations

from pathlib import Path

from ..progress import set_quiet


def register(sub):
    p = sub.add_parser(
        "demo-data", help="generate the demo town: CityGML, GTFS, CAMS radiation and layout",
        description="Write demo_city.gml (CityGML 2.0 LoD2), demo_gtfs.zip, "
                    "cams_radiation_demo.csv (1 min, whole year) and demo_layout.json. "
                    "The same seed, year and size give byte-identical files.")
    p.add_argument("--out", default="data/demo/input", type=Path,
                   help="output directory (default: data/demo/input)")
    p.add_argument("--year", required=True, type=int, help="year of the timetable and radiation")
    p.add_argument("--seed", default=42, type=int, help="random seed (default: 42)")
    p.add_argument("--size", default="full", choices=["full", "small"],
                   help="full: 18 km line + 6.5 km line, ~3,600 buildings; small: a 3 km line")
    p.add_argument("--quiet", "-q", action="store_true",
                   help="no progress bars or progress lines")
    p.set_defaults(func=run)


def run(args):
    set_quiet(args.quiet)
    from ..demo import generate_demo
    from ..simulation.prepare import check_year, mark_demo
    from ..store import folder_path

    check_year(args.year)
    folder_path(args.out, "--out")
    res = generate_demo(args.out, year=args.year, seed=args.seed, size=args.size)
    mark_demo(args.out, args.year, args.seed, args.size)
    c = res["counts"]
    for kind, path in res["paths"].items():
        size = path.stat().st_size
        human = f"{size / 1e6:.1f} MB" if size >= 1e6 else f"{size / 1e3:.0f} kB"
        print(f"{kind:8s} {path}  ({human}, {res['seconds'][kind]:.1f} s)")
    print(f"city:    {c['buildings']} buildings, {c['roof_surfaces']} roof / {c['wall_surfaces']} wall / "
          f"{c['ground_surfaces']} ground surfaces, {c['terrain_triangles']} terrain triangles")
    print(f"gtfs:    {c['trips']} trips in the timetable, {c['stops']} stops, {c['blocks']} blocks")
    for line, per_dir in c["trips_per_year"].items():
        print(f"         line {line}: {c['line_length_m'][line] / 1000:.2f} km, trips in {args.year}: "
              + ", ".join(f"direction {d} {n}" for d, n in per_dir.items()))
    s = res["annual_kwh_m2"]
    print(f"cams:    {c['cams_rows']} rows, annual GHI {s['GHI']:.0f} kWh/m2 "
          f"(clear sky {s['Clear sky GHI']:.0f})")
    return 0
