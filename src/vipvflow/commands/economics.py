"""``vipvflow economics``: PV coverage, avoided charging cycles and simple payback.

Direct inputs let a reader check a published result by hand::

    vipvflow economics --yield-kwh-per-kwp 900 --kwp 3.5 --fleet-demand-mwh 1200 --buses 20

or ``--trips FILE`` (CSV or Parquet with ``pv_kwh``, ``consumption_kwh`` and a vehicle column)
gives the balance per vehicle and for the fleet.  Cost, tariff, SoC window, kWp and battery
default to the scenario configuration (``--config``).
"""
from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..config import load_config
from ..errors import InputError
from ..models import economics
from . import add_config


def register(sub):
    p = sub.add_parser("economics", help="PV coverage, avoided charging cycles and payback",
                       description=__doc__.split("\n\n")[0])
    add_config(p)
    p.add_argument("--yield-kwh-per-kwp", type=float, help="annual PV yield (kWh/kWp/yr)")
    p.add_argument("--performance-ratio", type=float, default=None,
                   help="multiply the yield by this PR (when the yield is given before losses)")
    p.add_argument("--kwp", type=float, help="PV peak power per bus (kWp; default: PV system)")
    p.add_argument("--fleet-demand-mwh", type=float, help="energy the fleet draws per year (MWh)")
    p.add_argument("--buses", type=int, default=1, help="buses with PV (default 1)")
    p.add_argument("--battery-kwh", type=float, help="battery capacity per bus (kWh; default: vehicle)")
    p.add_argument("--soc-window", type=float, nargs=2, metavar=("LOW", "HIGH"),
                   help="SoC window of one charging cycle (default: economics.soc_window)")
    p.add_argument("--cost-eur-per-wp", type=float, help="PV system cost (EUR/Wp)")
    p.add_argument("--tariff-eur-per-kwh", type=float, help="charging energy price (EUR/kWh)")
    p.add_argument("--trips", type=Path, help="per-trip table (CSV/Parquet) instead of a yield")
    p.add_argument("--by", default=None, help="vehicle column of --trips (default vehicle_id/block_id)")
    p.add_argument("--period-years", type=float, default=1.0, help="years the --trips cover")
    p.set_defaults(func=run)


def _defaults(args):
    cfg = load_config(args.config)
    eco = cfg.economics
    kwp = args.kwp if args.kwp is not None else cfg.pv_system().kwp
    battery = args.battery_kwh if args.battery_kwh is not None else cfg.vehicle_params().battery_kwh
    window = tuple(args.soc_window) if args.soc_window else tuple(eco.soc_window)
    cost = args.cost_eur_per_wp if args.cost_eur_per_wp is not None else eco.cost_eur_per_wp
    tariff = args.tariff_eur_per_kwh if args.tariff_eur_per_kwh is not None else eco.tariff_eur_per_kwh
    if not 0 <= window[0] < window[1] <= 1:
        raise InputError(f"--soc-window: need 0 <= LOW < HIGH <= 1, got {window[0]} {window[1]}")
    return kwp, battery, window, cost, tariff


def _read_trips(path: Path) -> pd.DataFrame:
    try:
        if path.suffix.lower() in (".parquet", ".pq"):
            return pd.read_parquet(path)
        return pd.read_csv(path)
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: cannot read the trip table: {exc}") from None


def run(args):
    kwp, battery, window, cost, tariff = _defaults(args)
    cycle = float(economics.cycle_energy_kwh(battery, window))
    if args.trips is not None:
        try:
            table = economics.energy_balance(
                _read_trips(args.trips), kwp, battery, window, cost, tariff, by=args.by,
                period_years=args.period_years)
        except ValueError as exc:
            raise InputError(f"{args.trips}: {exc}") from None
        with pd.option_context("display.width", 160, "display.max_columns", 20):
            print(table.to_string(float_format=lambda x: f"{x:.4g}"))
        fleet = table.loc["fleet"]
        print(f"coverage: {100 * fleet['coverage']:.3f} %")
        print(f"avoided charging cycles: {fleet['avoided_cycles_per_year']:.2f} per year (fleet)")
        print(f"payback: {fleet['payback_years']:.2f} years")
        return 0
    if args.yield_kwh_per_kwp is None or args.fleet_demand_mwh is None:
        raise InputError("give --yield-kwh-per-kwp and --fleet-demand-mwh, or --trips FILE")
    r = economics.balance_from_inputs(
        args.yield_kwh_per_kwp, kwp, args.fleet_demand_mwh, args.buses, battery, window,
        cost, tariff, performance_ratio=args.performance_ratio)
    pr = "" if args.performance_ratio is None else f" x PR {args.performance_ratio:g}"
    print(f"PV per bus: {r['pv_kwh_per_bus']:.1f} kWh/yr "
          f"({args.yield_kwh_per_kwp:g} kWh/kWp{pr} x {kwp:g} kWp)")
    print(f"PV fleet: {r['pv_mwh_fleet']:.3f} MWh/yr ({args.buses} buses)")
    print(f"coverage: {100 * r['coverage']:.3f} % of {args.fleet_demand_mwh:g} MWh/yr")
    print(f"avoided charging cycles: {r['avoided_cycles_per_bus']:.2f} per bus per year, "
          f"{r['avoided_cycles_fleet']:.1f} fleet "
          f"(one cycle = {battery:g} kWh x ({window[1]:g} - {window[0]:g}) = {cycle:g} kWh)")
    print(f"payback: {r['payback_years']:.2f} years "
          f"({r['cost_eur_per_bus']:.0f} EUR per bus / {r['saving_eur_per_bus']:.2f} EUR/yr "
          f"at {tariff:g} EUR/kWh, {cost:g} EUR/Wp)")
    return 0
