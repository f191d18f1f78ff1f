"""Reduce the partitions of a run into its outputs.

Per trip (trip x service date): PV kWh joined with the vehicle model's consumption;
per segment-month (with geometry, for maps); per route-direction-month; per vehicle block
and day; and the fleet-year summary with coverage, avoided charging cycles and payback.
"""
from __future__ import annotations

import logging
import re
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.dataset as ds
import pyarrow.parquet as pq

from ..config import Config
from ..errors import InputError
from ..irradiance import shading_loss
from .storage import write_json, write_parquet

log = logging.getLogger(__name__)


def _part_table(run_dir: Path, kind: str, pattern: str = "tile=*/month=*.parquet") -> pa.Table | None:
    """Every partition file of *kind* (``parts/<kind>/<pattern>``), in path order, as one Arrow
    table (``None``: no files).

    One pyarrow dataset over the files, read by Arrow's own threads (a run has hundreds to
    thousands of small files: one pandas read each cost most of the reduce); files whose
    schemas differ (an empty partition's columns, say) are read one by one and their
    schemas promoted instead."""
    files = sorted((run_dir / "parts" / kind).glob(pattern))
    if not files:
        return None
    try:
        return ds.dataset([str(f) for f in files], format="parquet").to_table()
    except (pa.ArrowInvalid, pa.ArrowTypeError, pa.ArrowNotImplementedError):
        pass
    with ThreadPoolExecutor(max_workers=4) as pool:
        tables = list(pool.map(pq.read_table, files))
    filled = [t for t in tables if t.num_rows] or tables[:1]
    return pa.concat_tables(filled, promote_options="permissive")


def _read_parts(run_dir: Path, kind: str) -> pd.DataFrame:
    """Every partition file of *kind*, in path order, as one DataFrame."""
    table = _part_table(run_dir, kind)
    return pd.DataFrame() if table is None else table.to_pandas()


def _trip_totals(run_dir: Path) -> pd.DataFrame:
    """The trip partitions summed per trip and service date (a trip crosses many tiles),
    sorted by both; the PV columns (``pv_kwh*``) and ``seconds``.

    Summed by Arrow on one thread (a fixed order of addition, so a run gives the same
    figures every time) before anything becomes a pandas object."""
    table = _part_table(run_dir, "trip")
    if table is None or not table.num_rows:
        raise InputError(f"{run_dir / 'parts' / 'trip'}: no trip partitions with passes: "
                         "the run's routes never pass its tiles in its months")
    cols = [c for c in table.column_names if c.startswith("pv_kwh")] + ["seconds"]
    keys = ["trip_id", "service_date"]
    summed = table.group_by(keys, use_threads=False).aggregate([(c, "sum") for c in cols])
    summed = summed.select(keys + [f"{c}_sum" for c in cols]).rename_columns(keys + cols)
    summed = summed.sort_by([(k, "ascending") for k in keys])
    return summed.to_pandas()


def trip_consumption(cfg: Config, data_dir: Path, year: int, pattern_ids, vecto_dir: Path | None = None,
                     say=print) -> pd.DataFrame:
    """Battery energy per trip pattern and month (kWh) from the vehicle model run over each
    pattern's 2 s driving cycle at the month's mean ambient temperature.

    With *vecto_dir* each pattern's cycle is also written as a VECTO driving cycle
    (``pattern_<id>.vdri``) with a VECTO job of the vehicle, so a VECTO user can run them;
    with ``vehicle.vmod_dir`` the VECTO modal results ``pattern_<id>.vmod`` found there
    replace the built-in consumption of those patterns (for every month).
    """
    from .. import vecto
    from ..trajectory import pattern_cycle
    from ..vehicle import simulate_cycle

    params = cfg.vehicle_params()
    temps = cfg.climate.monthly_mean_temperature_c
    vmod = {}
    if cfg.vehicle.vmod_dir is not None:
        files = {int(p.stem.split("_", 1)[1]): p for p in Path(cfg.vehicle.vmod_dir).glob("pattern_*.vmod")}
        if files:
            vmod = vecto.vmod_trip_energies(files)["consumption_kwh"].to_dict()
            bad = [str(files[k]) for k, v in vmod.items() if not np.isfinite(v)]
            if bad:
                raise InputError(f"{bad[0]}: no battery power columns (P_REESS_*): not the modal "
                                 "result of a battery-electric VECTO run")
            say(f"consumption of {len(vmod)} pattern(s) from VECTO results in {cfg.vehicle.vmod_dir}")
    rows, cycles = [], []
    if vecto_dir is not None:
        vecto_dir.mkdir(parents=True, exist_ok=True)
    for pattern_id in sorted(set(pattern_ids)):
        cycle = pattern_cycle(data_dir, pattern_id, cfg.trajectory.cycle)
        if vecto_dir is not None:
            cycles.append(vecto.write_vdri(cycle, vecto_dir / f"pattern_{pattern_id}.vdri"))
        for m in cfg.run.months:
            e = simulate_cycle(cycle, params, ambient_c=temps[m - 1])
            rows.append({"pattern_id": pattern_id, "month": f"{year}-{m:02d}",
                         "consumption_kwh": vmod.get(int(pattern_id), e["battery_kwh"]),
                         "consumption_source": "vecto" if int(pattern_id) in vmod else "built-in",
                         "traction_kwh": e["traction_kwh"], "recuperated_kwh": e["recuperated_kwh"],
                         "aux_kwh": e["aux_kwh"]})
    if vecto_dir is not None and cycles:
        vecto.write_vecto_job(vecto_dir, params, cycles=[Path(c).name for c in cycles])
    return pd.DataFrame(rows)


def reduce_run(cfg: Config, year: int, run_dir: Path, say=print) -> dict:
    """Write trip_energy, segments, segment_month, route_month, block_day, monthly, hourly
    outputs, ``summary.json`` and ``report.html``; return the summary."""
    from .. import economics
    from .report import write_report

    data_dir = Path(cfg.data_dir)
    trips_meta = pd.read_parquet(data_dir / "gtfs" / "trips.parquet")

    # --- per trip and service date
    trip = _trip_totals(run_dir)
    kwh_cols = [c for c in trip.columns if c.startswith("pv_kwh")] + ["seconds"]
    trip = trip.merge(trips_meta[["trip_id", "route_id", "route_short_name", "direction_id",
                                  "shape_id", "service_id", "block_id", "pattern_id", "start_s"]],
                      on="trip_id", how="left", validate="many_to_one")
    trip["month"] = pd.to_datetime(trip["service_date"]).dt.strftime("%Y-%m")
    cons = trip_consumption(cfg, data_dir, year, trip["pattern_id"].unique(),
                            vecto_dir=run_dir / "vecto", say=say)
    trip = trip.merge(cons, on=["pattern_id", "month"], how="left", validate="many_to_one")
    trip["coverage"] = trip["pv_kwh"] / trip["consumption_kwh"]
    write_parquet(trip, run_dir / "trip_energy.parquet")

    # --- segments with their geometry factors
    segments = gpd.read_parquet(data_dir / "gtfs" / "segments.parquet")
    segments = segments[segments["shape_id"].isin(trip["shape_id"].unique())]
    geo = _part_table(run_dir, "geometry", "tile=*.parquet")
    if geo is not None:
        geo = geo.to_pandas()
        # the factors, not the reflectors' sample points (the app reads those from parts/)
        keep = [c for c in geo.columns if c == "segment_id" or (
            geo[c].dtype.kind in "fiub" and not re.search(r"_p\d+_[xyz]$", c))]
        segments = segments.merge(geo[keep], on="segment_id", how="left")
    write_parquet(segments, run_dir / "segments.parquet")

    # --- segment-month (GeoParquet for maps)
    sm = _read_parts(run_dir, "segment_month")
    # shading loss: sky and sun light the buildings take away (1 - (direct + diffuse) / unshaded);
    # the reflected light they add is reported apart as reflection gain
    sm["shading_loss"] = shading_loss(sm["h_direct"], sm["h_diffuse"], sm["h_total_unshaded"])
    sm["shading_loss_clear"] = shading_loss(sm["h_direct_clear"], sm["h_diffuse_clear"],
                                            sm["h_total_clear_unshaded"])
    sm["reflection_gain"] = sm["h_reflected"] / sm["h_total_unshaded"].where(sm["h_total_unshaded"] > 0)
    shape_route = (trips_meta.drop_duplicates("shape_id")[["shape_id", "route_short_name", "direction_id"]])
    smg = segments[["segment_id", "shape_id", "geometry"]].merge(sm, on="segment_id", how="inner")
    smg = gpd.GeoDataFrame(smg.merge(shape_route, on="shape_id", how="left"),
                           geometry="geometry", crs=segments.crs)
    write_parquet(smg, run_dir / "segment_month.parquet")

    # --- route-direction-month
    agg = {c: "sum" for c in kwh_cols + ["consumption_kwh"]}
    rm = (trip.groupby(["route_id", "route_short_name", "direction_id", "month"], sort=True)
          .agg(trips=("trip_id", "size"), **{c: (c, "sum") for c in agg}).reset_index())
    rm["coverage"] = rm["pv_kwh"] / rm["consumption_kwh"]
    rm["shading_loss"] = shading_loss(rm["pv_kwh_direct"], rm["pv_kwh_diffuse"], rm["pv_kwh_unshaded"])
    write_parquet(rm, run_dir / "route_month.parquet")

    # --- vehicle block per day
    bd = (trip.groupby(["block_id", "service_date"], sort=True)
          .agg(trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"),
               pv_kwh_clear=("pv_kwh_clear", "sum"), consumption_kwh=("consumption_kwh", "sum"),
               first_departure_s=("start_s", "min")).reset_index())
    write_parquet(bd, run_dir / "block_day.parquet")

    # --- daily pattern by hour and month
    hourly = _read_parts(run_dir, "hourly")
    h_cols = [c for c in hourly.columns if c.startswith("h_")]
    hp = hourly.groupby(["month", "hour"], sort=True)[h_cols + ["seconds"]].sum().reset_index()
    for c in h_cols:  # mean irradiance while buses are on the road at that hour (W/m2)
        hp["g_" + c[2:]] = hp[c] * 3600.0 / hp["seconds"].where(hp["seconds"] > 0)
    write_parquet(hp, run_dir / "hourly_pattern.parquet")

    # --- fleet-year
    pv = cfg.pv_system()
    vehicle = cfg.vehicle_params()
    n_buses = int(trip.groupby("service_date")["block_id"].nunique().max())
    # a run over some months states annual figures scaled by 12 / months (flagged in the summary)
    annualise = 12.0 / len(cfg.run.months)
    pv_year = float(trip["pv_kwh"].sum()) * annualise
    demand_year = float(trip["consumption_kwh"].sum()) * annualise
    window = cfg.economics.soc_window
    eco = {
        "fleet_demand_mwh": demand_year / 1000.0,
        "coverage": float(economics.coverage(pv_year, demand_year)),
        "avoided_charging_cycles_fleet": float(economics.avoided_cycles(pv_year, vehicle.battery_kwh, window)),
        "avoided_charging_cycles_per_bus": float(
            economics.avoided_cycles(pv_year / n_buses, vehicle.battery_kwh, window)),
        "system_cost_eur_per_bus": float(economics.system_cost_eur(pv.kwp, cfg.economics.cost_eur_per_wp)),
        "payback_years": float(economics.simple_payback_years(
            pv.kwp, pv_year / n_buses, cfg.economics.cost_eur_per_wp, cfg.economics.tariff_eur_per_kwh)),
    }
    tot = sm[[c for c in sm.columns if c.startswith("h_")]].sum()
    monthly = (trip.groupby("month", sort=True)
               .agg(trips=("trip_id", "size"), pv_kwh=("pv_kwh", "sum"), pv_kwh_clear=("pv_kwh_clear", "sum"),
                    pv_kwh_unshaded=("pv_kwh_unshaded", "sum"),
                    pv_kwh_clear_unshaded=("pv_kwh_clear_unshaded", "sum"),
                    pv_kwh_direct=("pv_kwh_direct", "sum"), pv_kwh_diffuse=("pv_kwh_diffuse", "sum"),
                    pv_kwh_reflected=("pv_kwh_reflected", "sum"),
                    consumption_kwh=("consumption_kwh", "sum")).reset_index())
    monthly["shading_loss"] = shading_loss(monthly["pv_kwh_direct"], monthly["pv_kwh_diffuse"],
                                           monthly["pv_kwh_unshaded"])
    monthly["avoided_charging_cycles"] = economics.avoided_cycles(
        monthly["pv_kwh"].to_numpy(), vehicle.battery_kwh, window)
    monthly["kwh_per_kwp_allsky"] = monthly["pv_kwh"] / (pv.kwp * n_buses)
    monthly["kwh_per_kwp_clearsky"] = monthly["pv_kwh_clear"] / (pv.kwp * n_buses)
    write_parquet(monthly, run_dir / "monthly.parquet")

    summary = {
        "scenario": cfg.scenario, "year": year, "months": cfg.run.months, "pv_mode": cfg.pv.mode,
        "diffuse_model": cfg.irradiance.diffuse_model,
        "routes": int(trip["route_id"].nunique()), "trips": int(len(trip)), "buses": n_buses,
        "segments": int(len(segments)), "passes": int(sm["n_passes"].sum()),
        "kwp_per_bus": pv.kwp,
        "pv_kwh_allsky": float(trip["pv_kwh"].sum()),
        "pv_kwh_clearsky": float(trip["pv_kwh_clear"].sum()),
        "pv_kwh_allsky_unshaded": float(trip["pv_kwh_unshaded"].sum()),
        "annualised_from_months": annualise != 1.0,
        "kwh_per_kwp_allsky": float(trip["pv_kwh"].sum() * annualise / (pv.kwp * n_buses)),
        "kwh_per_kwp_clearsky": float(trip["pv_kwh_clear"].sum() * annualise / (pv.kwp * n_buses)),
        "irradiation_kwh_m2": {k[2:]: float(v) / 1000.0 for k, v in tot.items()},
        "shading_loss_allsky": float(shading_loss(tot["h_direct"], tot["h_diffuse"], tot["h_total_unshaded"])),
        "shading_loss_clearsky": float(shading_loss(tot["h_direct_clear"], tot["h_diffuse_clear"],
                                                    tot["h_total_clear_unshaded"])),
        "reflection_gain_allsky": float(tot["h_reflected"] / tot["h_total_unshaded"]),
        "net_building_effect_allsky": float(tot["h_total"] / tot["h_total_unshaded"] - 1),
        "unshaded_to_ghi_allsky": float(tot["h_total_unshaded"] / tot["h_ghi"]),
        "unshaded_to_ghi_clearsky": float(tot["h_total_clear_unshaded"] / tot["h_ghi_clear"]),
        "reflected_share": float(tot["h_reflected"] / tot["h_total"]),
        **eco,
    }
    write_json(summary, run_dir / "summary.json")
    write_report(run_dir, summary, monthly, smg, hp, rm)
    return summary
