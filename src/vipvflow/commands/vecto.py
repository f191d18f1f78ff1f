"""``vipvflow vecto cycle|vmod|job``: VECTO driving cycles, modal results and job files."""
from __future__ import annotations

from pathlib import Path

from ..config import load_config
from ..models.vehicle import simulate_cycle
from ..outputs import vecto
from . import add_config


def register(sub):
    p = sub.add_parser("vecto", help="VECTO interop: read cycles and modal results, write a job")
    inner = p.add_subparsers(dest="what", metavar="WHAT")

    c = inner.add_parser("cycle", help="summarise a .vdri cycle and run the built-in model on it")
    c.add_argument("vdri", type=Path, help="VECTO distance-based cycle (.vdri)")
    add_config(c)
    c.add_argument("--ambient-c", type=float, default=15.0, help="ambient temperature (deg C)")
    c.set_defaults(func=run_cycle)

    m = inner.add_parser("vmod", help="energies integrated from VECTO modal results (.vmod)")
    m.add_argument("vmod", type=Path, nargs="+", help=".vmod file(s)")
    m.set_defaults(func=run_vmod)

    j = inner.add_parser("job", help="write the configured vehicle as a VECTO engineering job")
    j.add_argument("--out", type=Path, required=True, help="output directory")
    add_config(j)
    j.add_argument("--cycles", type=Path, nargs="*", default=[], help=".vdri files to list")
    j.add_argument("--ambient-c", type=float, default=15.0, help="ambient for Padd_electric")
    j.set_defaults(func=run_job)
    p.set_defaults(func=lambda args: p.print_help())


def run_cycle(args):
    cfg = load_config(args.config)
    params = cfg.vehicle_params()
    cyc_cfg = cfg.trajectory.cycle
    rows = vecto.read_vdri(args.vdri)
    info = vecto.vdri_summary(rows)
    cycle = vecto.vdri_to_cycle(rows, dt_s=cyc_cfg.dt_s, max_accel_mps2=cyc_cfg.max_accel_mps2,
                                max_decel_mps2=cyc_cfg.max_decel_mps2)
    r = simulate_cycle(cycle, params, ambient_c=args.ambient_c)
    print(f"cycle: {args.vdri}")
    print(f"distance: {info['distance_m']:.1f} m")
    print(f"duration: {r['duration_s']:.0f} s (built-in driver, "
          f"{r['distance_km'] / max(r['duration_s'], 1e-9) * 3600:.1f} km/h average)")
    print(f"stops: {info['stops']} ({info['stop_time_s']:.0f} s standing)")
    print(f"vehicle: {params.name} ({params.mass_kg:.0f} kg), ambient {args.ambient_c:g} C")
    for key in ("traction_kwh", "recuperated_kwh", "aux_kwh", "battery_loss_kwh", "battery_kwh"):
        print(f"{key}: {r[key]:.3f}")
    print(f"kwh_per_km: {r['battery_kwh'] / max(r['distance_km'], 1e-9):.3f}")
    return 0


def run_vmod(args):
    for path in args.vmod:
        e = vecto.vmod_energy(path)
        print(f"file: {path}")
        print(f"distance_km: {e['distance_km']:.4f}")
        print(f"duration_s: {e['duration_s']:.1f}")
        for key in ("wheel_kwh", "brake_kwh", "aux_kwh", "battery_kwh", "battery_loss_kwh"):
            src = e["columns"].get(key.replace("_kwh", ""), "")
            print(f"{key}: {e[key]:.4f}" + (f"  ({src})" if src else ""))
    return 0


def run_job(args):
    from ..store import folder_path

    folder_path(args.out, "--out")
    cfg = load_config(args.config)
    cyc = cfg.trajectory.cycle
    paths = vecto.write_vecto_job(args.out, cfg.vehicle_params(), cycles=args.cycles,
                                  ambient_c=args.ambient_c, max_accel_mps2=cyc.max_accel_mps2,
                                  max_decel_mps2=cyc.max_decel_mps2)
    for kind, path in paths.items():
        print(f"{kind}: {path}")
    return 0
