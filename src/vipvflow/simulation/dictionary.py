"""The data dictionary of a run's outputs: every column of every output file, its unit and meaning.

The same entries go three ways: into each output Parquet file as field metadata (``unit``,
``description``; :func:`annotate`, applied by :func:`vipvflow.store.write_parquet`
to files named as an output), into ``docs/outputs.md`` (:func:`render_markdown`, kept in sync
by a test) and into the report.

A column is looked up first in its file's own entries (:data:`OUTPUTS`), then in the
vocabulary shared by every file (:data:`COLUMNS`); the file says what one row holds, so
``pv_kwh`` is "PV energy" of a trip in ``trip_energy`` and of a month in ``monthly``.
Columns nobody documented are written without metadata (never an error); the tests require
an entry for every column a run writes.

Times are typed by what they are, whatever the table held in memory: a column whose unit is
:data:`DATE` (``service_date``, ``month``: a day of the feed's local calendar; a month as its
first day) is written as a Parquet ``date32``; a column whose unit is :data:`INSTANT` (the
``*_utc`` columns: a moment) as a timestamp in microseconds with time zone UTC (from Unix
seconds or a timestamp).
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Column:
    unit: str
    meaning: str


#: the unit of a calendar day (``date32`` in the files)
DATE = "date"
#: the unit of a moment (a timestamp with time zone UTC in the files, microseconds)
INSTANT = "timestamp (UTC)"


#: the light a roof receives, by component and sky (``h_<c>`` sums, ``g_<c>`` means, ``pv_kwh_<c>``)
_LIGHT = {
    "direct": "beam (direct) light on the roof, after the shadow of the buildings and the tree crowns",
    "diffuse": "sky diffuse light on the roof, from the part of the sky the buildings leave open, "
               "through the tree crowns",
    "direct_no_trees": "beam (direct) light on the roof with the buildings alone (no tree crowns; "
                       "the reference of the trees' shading loss)",
    "diffuse_no_trees": "sky diffuse light on the roof with the buildings alone (no tree crowns)",
    "reflected": "light reflected onto the roof by the buildings and the ground",
    "total": "all light on the roof: direct + diffuse + reflected, with the buildings",
    "total_unshaded": "all light on the roof without any building (the reference of the shading loss)",
    "ghi": "global horizontal irradiance of the sky (CAMS) at the times of the passes, for comparison",
}


def _light(component: str) -> str:
    clear = component.endswith("_clear") or "_clear_" in component
    base = component.replace("_clear", "")
    sky = "clear-sky (CAMS McClear)" if clear else "all-sky (CAMS)"
    return f"{_LIGHT[base]}; {sky}"


_PV = {
    "pv_kwh": "PV energy, all-sky, with the buildings (shading and reflections): the run's result",
    "pv_kwh_clear": "PV energy, clear-sky (cloudless reference), with the buildings",
    "pv_kwh_unshaded": "PV energy, all-sky, without buildings (shading loss reference)",
    "pv_kwh_clear_unshaded": "PV energy, clear-sky, without buildings",
    "pv_kwh_direct": "part of pv_kwh from direct (beam) light",
    "pv_kwh_diffuse": "part of pv_kwh from sky diffuse light",
    "pv_kwh_reflected": "part of pv_kwh from light the buildings and the ground reflect",
    # the whole-day model (energy outside the timetabled trips and what the battery refused)
    "pv_kwh_driving": "PV energy while driving timetabled trips (whole-day model)",
    "pv_kwh_layover": "PV energy while standing at terminals between trips (whole-day model)",
    "pv_kwh_parked": "PV energy while parked out of service, e.g. at the depot (whole-day model)",
    "pv_kwh_curtailed": "PV energy the battery could not take (at its SoC ceiling), lost",
    "pv_kwh_whole_day": "PV energy over the whole day: driving + layover + parked (0 where fleet.harvest does not count them)",
    "pv_kwh_usable": "PV energy the battery takes: pv_kwh_whole_day - pv_kwh_curtailed",
    "pv_kwh_clear_layover": "clear-sky PV energy while standing at terminals between trips",
    "pv_kwh_clear_parked": "clear-sky PV energy while parked out of service",
}

_COMPONENTS = ["direct", "diffuse", "reflected", "total", "total_unshaded",
               "direct_clear", "diffuse_clear", "reflected_clear", "total_clear",
               "total_clear_unshaded", "ghi", "ghi_clear", "direct_no_trees", "diffuse_no_trees"]

#: columns shared by the output files (a file's own entry overrides)
COLUMNS: dict[str, Column] = {
    # keys and labels
    "segment_id": Column("", "segment number (gtfs/segments.parquet), 0..N-1"),
    "shape_id": Column("", "GTFS shape_id: the path the buses drive"),
    "seg_index": Column("", "position of the segment along its shape, from 0"),
    "tile": Column("", "city tile holding the segment's start, named by its south-west corner in "
                       "hundreds of metres of the city CRS (E0770N0750: x 77,000 m, y 75,000 m)"),
    "trip_id": Column("", "GTFS trip_id"),
    "service_date": Column(DATE, "GTFS service date (local calendar of the feed)"),
    "month": Column(DATE, "month, as its first day (local calendar of the feed)"),
    "hour": Column("h", "local clock hour, 0..23 (hour starting then)"),
    "route_id": Column("", "GTFS route_id"),
    "route_short_name": Column("", "GTFS route_short_name (the line's public name; its long name, "
                                   "else its route_id, when the feed gives none); on a segment: "
                                   "every route that drives it, sorted, joined by ', '"),
    "route_long_name": Column("", "GTFS route_long_name (empty when the feed gives none)"),
    "trip_headsign": Column("", "GTFS trip_headsign: where the trip goes (per route and "
                                "direction: the most frequent)"),
    "direction_id": Column("", "GTFS direction_id (0 or 1)"),
    "service_id": Column("", "GTFS service_id (the trip's calendar)"),
    "block_id": Column("", "GTFS block_id: one vehicle's sequence of trips in a day"),
    "pattern_id": Column("", "stop pattern of the trip (same stops and times: same driving cycle)"),
    "trips": Column("count", "trips (trip x service date) in the row"),
    "n_passes": Column("count", "segment passes: one bus crossing the segment once"),
    "seconds": Column("s", "time buses spent on the road in the row (sum over passes, stops included)"),
    "start_s": Column("s", "departure of the trip, seconds after local midnight of the service date "
                           "(may exceed 86,400 after midnight)"),
    "first_departure_s": Column("s", "first departure of the block that day, seconds after local midnight"),
    "geometry": Column("m (CRS in the GeoParquet metadata)",
                       "the segment's line (LineString Z at roof height) in the city's projected CRS"),
    # consumption and economics
    "consumption_kwh": Column("kWh", "battery energy the bus used (vehicle model or VECTO), at the "
                                     "month's mean temperature"),
    "consumption_source": Column("", "'built-in' (vipvflow's vehicle model) or 'vecto' (VECTO modal results)"),
    "traction_kwh": Column("kWh", "energy at the wheels for driving (vehicle model)"),
    "recuperated_kwh": Column("kWh", "braking energy recovered into the battery (vehicle model)"),
    "aux_kwh": Column("kWh", "auxiliaries: base load and heating/cooling at the month's temperature"),
    "coverage": Column("fraction", "pv_kwh / consumption_kwh: share of the battery energy the roof supplied"),
    "shading_loss": Column("fraction", "1 - (direct + diffuse) / total_unshaded, all-sky: light the "
                                       "buildings take away (reflections not counted; see reflection_gain)"),
    "shading_loss_clear": Column("fraction", "shading_loss under clear sky"),
    "reflection_gain": Column("fraction", "reflected / total_unshaded, all-sky: light the buildings add"),
    "avoided_charging_cycles": Column("cycles", "battery energy the chargers need not put in (the "
                                                "battery's balance) / (battery capacity x the economics "
                                                "SoC window), fleet"),
    "layover_aux_kwh": Column("kWh", "auxiliaries and HVAC drawn from the battery during the layovers "
                                     "(month's mean temperature, discharge efficiency)"),

    "soc_start": Column("fraction", "battery state of charge at the block-day's first departure: the "
                                    "depot charge's target (charging.depot.target_soc)"),
    "soc_end_pv": Column("fraction", "state of charge at the block-day's last arrival, with PV, under the "
                                     "charging plan (never below 0)"),
    "soc_lowest_pv": Column("fraction", "lowest state of charge of the block-day with PV (never below 0)"),
    "soc_lowest_nopv": Column("fraction", "the same without PV"),
    "feasible": Column("", "true when the charging plan serves the block-day with PV: the SoC stays at "
                           "or above the vehicle's soc_min and the depot restores the morning's SoC"),
    "feasible_without_pv": Column("", "the same without PV"),
    "infeasible_at_utc": Column(INSTANT, "when the SoC (with PV) crosses soc_min, linear in time within the "
                                       "trip or layover; null when it never does"),
    "infeasible_soc": Column("fraction", "SoC (with PV) at the end of the trip or layover where it falls "
                                         "below soc_min"),
    "depot_short_kwh": Column("kWh", "battery energy the depot's charging hours cannot restore before "
                                     "the next morning (with PV)"),
    "grid_kwh_depot": Column("kWh", "grid energy of the depot charge with PV (at the charger: battery "
                                    "energy / charging.depot.efficiency)"),
    "grid_kwh_depot_without_pv": Column("kWh", "the same without PV"),
    "grid_kwh_opportunity": Column("kWh", "grid energy of the charges at terminals during layovers, with PV"),
    "grid_kwh_opportunity_without_pv": Column("kWh", "the same without PV"),
    "grid_kwh_avoided": Column("kWh", "grid energy PV saves: (depot + terminals) without PV - with PV"),
    "soc_at_departure": Column("fraction", "the trip's battery state of charge at departure in its "
                                           "block-day's balance with PV (the web app starts from it)"),
    "window_start_utc": Column(INSTANT, "start of the block-day's time window (its GTFS service day)"),
    "window_end_utc": Column(INSTANT, "end of the block-day's time window (stretched to the last "
                                         "arrival past the service day)"),
    "window_s": Column("s", "length of the block-day's window: seconds_driving + seconds_layover + seconds_parked"),
    "first_departure_utc": Column(INSTANT, "first departure of the block-day"),
    "last_arrival_utc": Column(INSTANT, "last arrival of the block-day"),
    "overlap_s": Column("s", "time two trips of the block overlap in the timetable (counted once, as driving)"),
    "seconds_driving": Column("s", "time on trips (first departure to last arrival of each trip)"),
    "seconds_layover": Column("s", "time standing at terminals between the block's trips"),
    "seconds_parked": Column("s", "time parked at the depot before the first and after the last trip"),
    "kwh_per_kwp_driving": Column("kWh/kWp", "all-sky PV energy while driving per installed kWp of the fleet"),
    "kwh_per_kwp_driving_clearsky": Column("kWh/kWp", "clear-sky PV energy while driving per installed kWp"),
    "kwh_per_kwp_usable": Column("kWh/kWp", "PV energy the batteries take per installed kWp of the fleet"),
    "demand_kwh": Column("kWh", "battery energy the block-days need in service: trips' consumption_kwh + "
                                "layover_aux_kwh"),
    "block_days": Column("count", "block-days (vehicle block x service date)"),
    "block_days_infeasible": Column("count", "block-days the charging plan cannot serve (with PV)"),
    "grid_kwh_avoided_depot": Column("kWh", "grid energy PV saves at the depot"),
    "grid_kwh_avoided_opportunity": Column("kWh", "grid energy PV saves at the terminals"),
    # segment geometry (gtfs/segments.parquet)
    "x": Column("m", "segment start, easting in the city CRS"),
    "y": Column("m", "segment start, northing in the city CRS"),
    "z": Column("m", "roof height at the segment start (ground + roof height), in the CRS's height system"),
    "x_end": Column("m", "segment end, easting"),
    "y_end": Column("m", "segment end, northing"),
    "z_end": Column("m", "roof height at the segment end"),
    "ground_z": Column("m", "ground (terrain) height at the segment start"),
    "ground_source": Column("", "where ground_z comes from: 'relief' (the city model's TIN), "
                                "'buildings' (its buildings' ground surfaces within 100 m, blended "
                                "with the fallback), 'radiation_header' (the CAMS file's altitude) or "
                                "'configured' (trajectory.ground_elevation_m): the last two are roads "
                                "more than 100 m from any building of the model"),
    "in_city_model": Column("", "true when the segment's midpoint lies in the area the city model "
                                "covers (its buildings' footprints closed by 60 m and widened by 20 m); "
                                "outside it the road is computed under the open sky"),
    "in_building": Column("", "true when the segment's midpoint lies inside a building footprint "
                              "(a straight line between stops of a feed without shapes): its light is "
                              "taken at light_dx_m, light_dy_m from the midpoint, outside the block, "
                              "and it is left out of the summary's shading statistics"),
    "light_dx_m": Column("m", "easting offset of the point the segment's light is taken from "
                              "(0 unless in_building)"),
    "light_dy_m": Column("m", "northing offset of that point (0 unless in_building)"),
    "heading_deg": Column("deg", "driving direction, clockwise from grid north"),
    "gradient": Column("m/m", "road gradient dz/ds of the ground (positive uphill)"),
    "length_m": Column("m", "segment length along the shape"),
    "cum_dist_m": Column("m", "distance of the segment start from the shape's start"),
    # public geometry factors (parts/geometry holds the internal reflector geometry)
    "tilt_deg": Column("deg", "roof tilt (follows the road gradient)"),
    "azimuth_deg": Column("deg", "direction the tilted roof faces, clockwise from north"),
    "svf": Column("fraction", "sky view factor of the roof: cosine-weighted share of the sky it sees "
                              "(1 on open flat ground)"),
    "refl_vf": Column("fraction", "albedo-weighted view factor of the building and ground surfaces the roof sees"),
    # per segment over the run's months
    "g_total_in_service": Column("W/m2", "mean all-sky irradiance on the roof while buses are on the "
                                         "segment (h_total / seconds)"),
    "g_total_unshaded_in_service": Column("W/m2", "the same without buildings"),
    "kwh_per_kwp_year": Column("kWh/kWp per year",
                               "specific yield of a bus that spent its whole service year in this "
                               "segment's light: pv_kwh per kWp and hour on the segment x the fleet's "
                               "service hours per bus and year (the fleet's kWh/kWp is their "
                               "time-weighted mean)"),
    "irradiation_kwh_m2_year": Column("kWh/m2 per year",
                                      "the same for the all-sky light on the roof: mean irradiance on "
                                      "the segment x service hours per bus and year"),
    **{k: Column("kWh", v) for k, v in _PV.items()},
    **{f"h_{c}": Column("Wh/m2", f"irradiation summed over the row's passes (every bus, every pass): "
                                 f"{_light(c)}") for c in _COMPONENTS},
    **{f"g_{c}": Column("W/m2", f"mean irradiance while buses are on the road: {_light(c)}")
       for c in _COMPONENTS},
}


@dataclass(frozen=True)
class Output:
    title: str
    rows: str
    columns: tuple[str, ...]
    own: dict


def _out(title: str, rows: str, columns: str, **own: Column) -> Output:
    return Output(title, rows, tuple(columns.split()), own)


_PVS = "pv_kwh pv_kwh_clear pv_kwh_unshaded pv_kwh_clear_unshaded pv_kwh_direct pv_kwh_diffuse pv_kwh_reflected"
_HS = " ".join(f"h_{c}" for c in _COMPONENTS)
_GS = " ".join(f"g_{c}" for c in _COMPONENTS)
_WHOLE_DAY = "pv_kwh_driving pv_kwh_layover pv_kwh_parked pv_kwh_curtailed"

#: the run's output files (``<name>.parquet`` in ``out/<scenario>/<year>/``), in reading order
OUTPUTS: dict[str, Output] = {
    "trip_energy": _out(
        "PV and consumption per trip", "one row per trip and service date",
        f"trip_id service_date month route_id route_short_name route_long_name trip_headsign "
        f"direction_id shape_id service_id "
        f"block_id pattern_id start_s seconds {_PVS} consumption_kwh consumption_source "
        f"traction_kwh recuperated_kwh aux_kwh coverage soc_at_departure",
        coverage=Column("fraction", "pv_kwh / consumption_kwh: the trip's driving PV over its own "
                                    "consumption")),
    "segments": _out(
        "The network's segments, their geometry factors and their year (GeoParquet)",
        "one row per segment of the simulated routes (about 10 m of road); totals over the run's months",
        f"segment_id shape_id route_short_name direction_id seg_index tile geometry x y z x_end y_end "
        f"z_end ground_z ground_source heading_deg gradient length_m cum_dist_m in_city_model "
        f"in_building light_dx_m light_dy_m tilt_deg azimuth_deg svf refl_vf "
        f"n_passes seconds pv_kwh pv_kwh_unshaded h_total h_total_unshaded g_total_in_service "
        f"g_total_unshaded_in_service shading_loss reflection_gain kwh_per_kwp_year "
        f"irradiation_kwh_m2_year"),
    "segment_month": _out(
        "Segments per month (GeoParquet, for maps)", "one row per segment and month",
        f"segment_id month tile shape_id route_short_name direction_id geometry n_passes seconds "
        f"{_PVS} {_HS} shading_loss shading_loss_clear reflection_gain"),
    "route_month": _out(
        "Routes per direction and month", "one row per route, direction and month",
        f"route_id route_short_name route_long_name direction_id trip_headsign month trips seconds "
        f"{_PVS} {_WHOLE_DAY} pv_kwh_usable consumption_kwh coverage shading_loss",
        coverage=Column("fraction", "pv_kwh / consumption_kwh: the driving PV over the trips' "
                                    "consumption (coverage_driving of the route)"),
        pv_kwh_layover=Column("kWh", "PV at layovers of the block-days serving the route, shared by "
                                     "the trips' time in each block-day"),
        pv_kwh_parked=Column("kWh", "PV parked at the depot on those block-days, shared the same way"),
        pv_kwh_curtailed=Column("kWh", "PV curtailed on those block-days, shared the same way"),
        pv_kwh_usable=Column("kWh", "PV the batteries take on those block-days, shared the same way")),
    "block_day": _out(
        "Vehicles per day", "one row per vehicle block and service date",
        f"block_id service_date month trips window_start_utc window_end_utc first_departure_utc "
        f"last_arrival_utc overlap_s pv_kwh pv_kwh_clear consumption_kwh first_departure_s "
        f"pv_kwh_driving seconds_driving pv_kwh_layover pv_kwh_clear_layover seconds_layover "
        f"pv_kwh_parked pv_kwh_clear_parked seconds_parked pv_kwh_whole_day window_s layover_aux_kwh "
        f"demand_kwh soc_start soc_lowest_pv soc_end_pv soc_lowest_nopv feasible feasible_without_pv "
        f"infeasible_at_utc infeasible_soc depot_short_kwh pv_kwh_curtailed grid_kwh_depot "
        f"grid_kwh_depot_without_pv grid_kwh_opportunity grid_kwh_opportunity_without_pv "
        f"grid_kwh_avoided pv_kwh_usable"),
    "monthly": _out(
        "The fleet per month", "one row per month, the whole fleet",
        f"month trips {_PVS} consumption_kwh shading_loss {_WHOLE_DAY} pv_kwh_usable layover_aux_kwh "
        f"demand_kwh grid_kwh_avoided grid_kwh_avoided_depot grid_kwh_avoided_opportunity block_days "
        f"block_days_infeasible pv_kwh_whole_day avoided_charging_cycles coverage kwh_per_kwp_usable "
        f"kwh_per_kwp_driving kwh_per_kwp_driving_clearsky",
        coverage=Column("fraction", "pv_kwh_usable / demand_kwh: the month's share of the demand in "
                                    "service the PV the batteries take covers")),
    "ranking": _out(
        "Which buses to equip: blocks and routes by grid energy avoided per kWp",
        "one row per vehicle block and per route",
        "kind id name block_days grid_kwh_avoided_per_year pv_kwh_usable_per_year "
        "kwh_avoided_per_kwp_year payback_years rank",
        kind=Column("", "'block' (a bus's daily duty) or 'route'"),
        id=Column("", "block_id or route_id"),
        name=Column("", "the block's id or the route's route_short_name"),
        block_days=Column("count", "block-days of the block in the run; for a route, bus-days it takes "
                                   "(the trips' share of their block-days' time)"),
        grid_kwh_avoided_per_year=Column("kWh per year", "grid energy one bus's PV avoids in a year on "
                                                         "this block (its block-days scaled to a year) or "
                                                         "route (per bus it keeps busy)"),
        pv_kwh_usable_per_year=Column("kWh per year", "PV the battery takes, the same way"),
        kwh_avoided_per_kwp_year=Column("kWh/kWp per year", "grid_kwh_avoided_per_year per installed kWp"),
        payback_years=Column("years", "simple payback of one bus's PV system from the grid energy it "
                                      "avoids (inf: it avoids none)"),
        rank=Column("", "1: the most grid energy avoided per kWp, within its kind")),
    "hourly_pattern": _out(
        "Daily pattern by hour and month", "one row per month and local clock hour, the whole fleet",
        f"month hour seconds {_HS} {_GS}",
        seconds=Column("s", "time buses spent on the road in that hour of that month (all buses)")),
}

#: ``summary.json``: key -> unit and meaning (keys holding a dict have one entry for the dict)
SUMMARY: dict[str, Column] = {
    "scenario": Column("", "scenario name (configuration)"),
    "year": Column("", "simulated year"),
    "months": Column("", "simulated months (1-12)"),
    "pv_mode": Column("", "PV model: 'paper' (kWp x POA x PR) or 'pvlib' (PVWatts with cell temperature)"),
    "diffuse_model": Column("", "sky diffuse model on the tilted, obstructed roof"),
    "air_temperature_c": Column("degC", "monthly mean air temperature, January to December (HVAC, PV cell)"),
    "air_temperature_source": Column("", "where the air temperature comes from: the scenario's table, or the climatology at the city's place"),
    "routes": Column("count", "routes simulated"),
    "trips": Column("count", "trips simulated (trip x service date)"),
    "buses": Column("count", "fleet size: most vehicle blocks on one service date"),
    "segments": Column("count", "segments of the simulated routes"),
    "passes": Column("count", "segment passes evaluated"),
    "kwp_per_bus": Column("kWp", "installed PV per bus"),
    "pv_kwh_driving_clearsky": Column("kWh", "fleet PV energy while driving over the simulated months, "
                                             "clear-sky, with buildings"),
    "pv_kwh_driving_unshaded": Column("kWh", "the same all-sky, without buildings"),
    "annualised_from_months": Column("", "true when the yearly figures are scaled by 12 / months"),
    "kwh_per_kwp_usable": Column("kWh/kWp per year", "specific yield the batteries take (the headline: "
                                                     "harvested PV minus what a full battery curtails)"),
    "kwh_per_kwp_harvested": Column("kWh/kWp per year", "specific yield harvested in the time "
                                                        "fleet.harvest counts"),
    "kwh_per_kwp_driving_clearsky": Column("kWh/kWp per year", "specific yield while driving, clear-sky"),
    "irradiation_kwh_m2": Column("kWh/m2", "per component: light on the roofs summed over every pass of "
                                           "every bus in the simulated months - a fleet total, not a site "
                                           "figure (see roof_irradiation_kwh_m2_per_bus, site_ghi_kwh_m2_year)"),
    "roof_irradiation_kwh_m2_per_bus": Column("kWh/m2 per year", "all-sky light on one bus's roof in a year "
                                                                 "of service, with buildings"),
    "roof_irradiation_unshaded_kwh_m2_per_bus": Column("kWh/m2 per year", "the same without buildings"),
    "ghi_in_service_kwh_m2_per_bus": Column("kWh/m2 per year", "global horizontal irradiation while one bus "
                                                               "is in service (its share of the site's year)"),
    "site_ghi_kwh_m2_year": Column("kWh/m2 per year", "global horizontal irradiation of the site over the "
                                                      "calendar year (CAMS radiation file; mean of its "
                                                      "locations); null when the file covers less than 99 %"),
    "service_hours_per_bus_year": Column("h per year", "time a bus spends on its trips in a year"),
    "shading_loss_allsky": Column("fraction", "1 - (direct + diffuse) / unshaded light on the roofs, all-sky "
                                              "(segments inside building footprints left out)"),
    "shading_loss_clearsky": Column("fraction", "the same, clear-sky"),
    "shading_loss_allsky_without_trees": Column("fraction", "shading_loss_allsky with the buildings "
                                                            "alone (no tree crowns), all-sky"),
    "tree_shading_loss_allsky": Column("fraction", "what the tree crowns add to the shading loss: "
                                                   "shading_loss_allsky - "
                                                   "shading_loss_allsky_without_trees"),
    "trees_in_city_model": Column("count", "trees (crowns) the city ingest kept from the CityGML "
                                           "vegetation and the tree tables (0 when "
                                           "irradiance.trees.enabled is false; null when the "
                                           "ingest's report cannot be read)"),
    "reflection_gain_allsky": Column("fraction", "reflected / unshaded light, all-sky"),
    "net_building_effect_allsky": Column("fraction", "light with buildings / without - 1 (shading and "
                                                     "reflections together), all-sky"),
    "unshaded_to_ghi_allsky": Column("ratio", "unshaded roof light / GHI at the same times, all-sky"),
    "unshaded_to_ghi_clearsky": Column("ratio", "the same, clear-sky"),
    "reflected_share": Column("fraction", "reflected / total light on the roofs, all-sky"),
    "fleet_demand_in_service_mwh": Column("MWh per year", "battery energy the fleet uses in service in "
                                                          "a year: trips and layover auxiliaries"),
    "fleet_demand_driving_mwh": Column("MWh per year", "battery energy of the trips alone"),
    "coverage": Column("fraction", "PV the batteries take / fleet_demand_in_service (the headline)"),
    "coverage_driving": Column("fraction", "PV while driving / the trips' consumption (the paper's "
                                           "accounting)"),
    "block_days": Column("count", "block-days (a bus's day of service) in the run"),
    "block_days_infeasible": Column("count", "block-days the charging plan cannot serve with PV (the SoC "
                                             "would fall below soc_min, or the depot cannot restore it)"),
    "block_days_infeasible_without_pv": Column("count", "the same without PV"),
    "infeasible_block_days_first": Column("", "the first infeasible block-days: block, date and the time "
                                              "the SoC crosses soc_min"),
    "soc_lowest_pv": Column("fraction", "lowest state of charge of any block-day, with PV"),
    "grid_kwh_without_pv": Column("kWh", "grid energy of the depot and terminal chargers without PV, "
                                         "over the simulated months"),
    "grid_kwh_avoided": Column("kWh", "grid energy PV saves at the chargers over the simulated months "
                                      "(the battery's balance with PV against without)"),
    "grid_kwh_avoided_depot": Column("kWh", "of which at the depot"),
    "grid_kwh_avoided_opportunity": Column("kWh", "of which at the terminals"),
    "avoided_charging_cycles_fleet": Column("cycles per year", "battery energy the chargers need not put "
                                                               "in (the balance) / (battery capacity x the "
                                                               "economics SoC window), fleet"),
    "avoided_charging_cycles_per_bus": Column("cycles per year", "the same per bus"),
    "avoided_charging_cycles_per_bus_paper": Column("cycles per year", "the paper's formula: PV the "
                                                                       "battery takes / (capacity x SoC "
                                                                       "window), per bus"),
    "system_cost_eur_per_bus": Column("EUR", "PV system cost per bus"),
    "payback_years": Column("years", "simple payback of one bus's PV system from the grid energy it "
                                     "avoids at the configured tariff"),
    "payback_years_paper": Column("years", "the paper's: from the PV the battery takes x the tariff"),
    # the whole day (docs/whole_day.md)
    "harvest": Column("", "fleet.harvest: which time counts (driving | in_service | whole_day)"),
    "depot_shading": Column("", "fleet.depot_shading: open | covered | city"),
    "pv_kwh_driving": Column("kWh", "fleet PV energy on trips over the simulated months, all-sky"),
    "pv_kwh_layover": Column("kWh", "fleet PV energy at terminals between trips (null: fleet.harvest "
                                    "does not count it)"),
    "pv_kwh_parked": Column("kWh", "fleet PV energy parked at the depot, idle buses included (null: not "
                                   "counted)"),
    "pv_kwh_in_service": Column("kWh", "driving + layover (null: not counted)"),
    "pv_kwh_whole_day": Column("kWh", "driving + layover + parked (null: not counted)"),
    "pv_kwh_harvested": Column("kWh", "PV harvested in the time fleet.harvest counts"),
    "kwh_per_kwp_driving": Column("kWh/kWp per year", "specific yield counting the trips only (the paper's "
                                                      "accounting), all-sky"),
    "kwh_per_kwp_in_service": Column("kWh/kWp per year", "specific yield of driving + layovers"),
    "kwh_per_kwp_whole_day": Column("kWh/kWp per year", "specific yield of the whole day (driving, layovers, parked)"),
    "pv_kwh_usable": Column("kWh", "PV energy the batteries take (coverage, cycles and payback use it)"),
    "pv_kwh_curtailed": Column("kWh", "PV energy beyond the SoC ceiling, lost"),
    "idle_bus_days": Column("count", "bus-days without a block (parked all day)"),
    "layover_hours": Column("h", "fleet time standing at terminals over the simulated months"),
    "parked_hours": Column("h", "fleet time parked at the depot over the simulated months"),
    "layover_aux_kwh": Column("kWh", "auxiliaries and HVAC during the layovers (in the demand)"),
    # the study area (the city model covers part of the lines)
    "route_km": Column("km", "length of the simulated routes' segments (each shape once)"),
    "route_km_in_city_model": Column("km", "of which in the area the city model covers (in_city_model)"),
    "route_km_in_city_model_share": Column("fraction", "route_km_in_city_model / route_km"),
    "driving_time_in_city_model_share": Column("fraction", "share of the buses' time on the road spent "
                                                           "in the city model"),
    "pv_kwh_driving_in_city_model_share": Column("fraction", "share of the driving PV harvested in the "
                                                             "city model"),
    "kwh_per_kwp_driving_in_city_model": Column("kWh/kWp per year", "driving yield of a bus that drove "
                                                                    "only the modelled streets (the "
                                                                    "fleet's driving yield x PV per "
                                                                    "second inside / PV per second)"),
    "kwh_per_kwp_driving_outside_city_model": Column("kWh/kWp per year", "the same outside the city model "
                                                                         "(open sky)"),
    "shading_loss_allsky_in_city_model": Column("fraction", "shading_loss_allsky of the segments in the "
                                                            "city model (null: none)"),
    "shading_loss_allsky_outside_city_model": Column("fraction", "the same outside it (no building to "
                                                                 "shade: about 0)"),
    "segments_in_buildings": Column("count", "segments whose midpoint lies inside a building footprint "
                                             "(in_building: lit as the street next to them, left out of "
                                             "the shading statistics)"),
    "route_km_in_buildings_share": Column("fraction", "their share of route_km"),
    "driving_time_in_buildings_share": Column("fraction", "their share of the buses' time on the road"),
    "ground_sources": Column("count", "segments by the source of their ground height (see "
                                      "segments.parquet ground_source)"),
    "radiation_gaps_interpolated": Column("count", "gaps in the radiation data within the run's months, "
                                                   "interpolated (each shorter than radiation.max_gap_minutes)"),
    "radiation_gap_minutes_interpolated": Column("min", "minutes of those gaps"),
}


def describe(output: str, column: str) -> Column | None:
    """The entry of *column* in the output file *output* (``None``: undocumented)."""
    spec = OUTPUTS.get(output)
    if spec is not None and column in spec.own:
        return spec.own[column]
    return COLUMNS.get(column)


def annotate(table, output: str):
    """*table* (pyarrow) as written for the output file *output*: its dates as ``date32``
    and its instants as UTC timestamps (:func:`typed_times`), each documented field with
    ``unit`` and ``description`` metadata; in the file's key-value metadata the file's title
    (``vipvflow:rows``) and the same column entries as JSON (``vipvflow:columns``, for readers
    that do not show Arrow field metadata, e.g. DuckDB's ``parquet_kv_metadata``)."""
    import json

    import pyarrow as pa

    spec = OUTPUTS[output]
    table = typed_times(table, output)
    fields, columns = [], {}
    for f in table.schema:
        entry = describe(output, f.name)
        if entry is not None:
            meta = dict(f.metadata or {})
            meta.update({b"unit": entry.unit.encode(), b"description": entry.meaning.encode()})
            f = f.with_metadata(meta)
            columns[f.name] = {"unit": entry.unit, "description": entry.meaning}
        fields.append(f)
    meta = dict(table.schema.metadata or {})
    meta[b"vipvflow:rows"] = f"{spec.title}: {spec.rows}".encode()
    meta[b"vipvflow:columns"] = json.dumps(columns).encode()
    return table.cast(pa.schema(fields, metadata=meta))


def typed_times(table, output: str):
    """*table* (pyarrow) with each column the dictionary calls a :data:`DATE` as ``date32``
    (from ``"YYYY-MM"`` or ``"YYYY-MM-DD"`` strings, timestamps or dates) and each it calls
    an :data:`INSTANT` as ``timestamp[us, tz=UTC]`` (from Unix seconds, or a timestamp: a
    naive one is taken as UTC); NaN seconds become nulls.  The pandas metadata (a
    GeoDataFrame carries some) is told the new types, so pandas reads them as typed."""
    import pyarrow as pa
    import pyarrow.compute as pc

    changed = {}
    for i, name in enumerate(table.column_names):
        entry = describe(output, name)
        if entry is None or entry.unit not in (DATE, INSTANT):
            continue
        col = table.column(i)
        t = col.type
        if entry.unit == DATE:
            if pa.types.is_date32(t):
                continue
            if pa.types.is_string(t) or pa.types.is_large_string(t):
                text = col.cast(pa.string())
                whole = pc.if_else(pc.equal(pc.utf8_length(text), 7),
                                   pc.binary_join_element_wise(text, "-01", ""), text)
                col = pc.strptime(whole, format="%Y-%m-%d", unit="s")
            elif pa.types.is_timestamp(t) and t.tz is not None:
                col = col.cast(pa.timestamp(t.unit))
            col = col.cast(pa.date32())
        else:
            if pa.types.is_timestamp(t) and t.tz == "UTC" and t.unit == "us":
                continue
            if pa.types.is_floating(t) or pa.types.is_integer(t):
                seconds = col.cast(pa.float64())
                us = pc.round(pc.multiply(seconds, 1e6))
                us = pc.if_else(pc.is_nan(us), None, us) if pa.types.is_floating(t) else us
                col = us.cast(pa.int64()).cast(pa.timestamp("us", tz="UTC"))
            elif pa.types.is_timestamp(t):          # to microseconds (truncated), in UTC
                col = pc.cast(col, pa.timestamp("us", tz=t.tz or "UTC"), safe=False)
                if t.tz not in (None, "UTC"):
                    col = col.cast(pa.timestamp("us", tz="UTC"))
            else:
                raise TypeError(f"{output}.{name}: an instant, but of type {t}")
        table = table.set_column(i, pa.field(name, col.type), col)
        changed[name] = entry.unit
    if changed:
        table = table.replace_schema_metadata(_pandas_types(table.schema.metadata, changed))
    return table


def _pandas_types(meta: dict | None, changed: dict) -> dict | None:
    """Schema metadata whose pandas entry (GeoDataFrames carry one) gives the *changed*
    columns their new types (a date, a UTC timestamp), so pandas reads them as such rather
    than as what the frame held before."""
    import json

    if not meta or b"pandas" not in meta:
        return meta
    pandas_meta = json.loads(meta[b"pandas"])
    for col in pandas_meta.get("columns", []):
        unit = changed.get(col.get("name"))
        if unit == DATE:
            col.update({"pandas_type": "date", "numpy_type": "object", "metadata": None})
        elif unit == INSTANT:
            col.update({"pandas_type": "datetimetz", "numpy_type": "datetime64[us, UTC]",
                        "metadata": {"timezone": "UTC"}})
    return {**meta, b"pandas": json.dumps(pandas_meta).encode()}


def render_markdown() -> str:
    """``docs/outputs.md``: every output file's columns, then ``summary.json``'s keys."""
    lines = [
        "# Outputs: the data dictionary",
        "",
        "<!-- generated from src/vipvflow/simulation/dictionary.py by "
        "`python -m vipvflow.simulation.dictionary > docs/outputs.md`; a test keeps it in sync -->",
        "",
        "A run writes its outputs into `out/<scenario>/<year>/`. Every Parquet file carries the "
        "unit and meaning of each column: as Arrow field metadata (`unit`, `description`; in Python "
        "`pyarrow.parquet.read_schema(path).field('pv_kwh').metadata`) and, for other readers, as "
        "JSON in the file's key-value metadata `vipvflow:columns` (DuckDB: "
        "`SELECT decode(value) FROM parquet_kv_metadata('segments.parquet') "
        "WHERE decode(key) = 'vipvflow:columns'`). "
        "Geometries are in the city's projected CRS (named in the GeoParquet metadata and in "
        "`report.html`). Times: a column of unit `date` (`service_date`, `month`) is a Parquet "
        "`date32`, a day of the feed's local calendar (`month`: the month's first day); a column "
        "of unit `timestamp (UTC)` (the `*_utc` columns) is a moment, a Parquet timestamp in "
        "microseconds with time zone UTC (pandas: `datetime64[us, UTC]`; DuckDB: `TIMESTAMP WITH "
        "TIME ZONE`). Units: `fraction` is 0..1 "
        "(x 100 for %), `Wh/m2` and `kWh/m2` are irradiation (energy per m2 of roof), `W/m2` "
        "irradiance (power).",
        "",
        "Sums over *passes* add every bus that crossed: `h_total` of a segment-month is the light "
        "every roof received on that segment that month, not the light of one place. For "
        "place-like figures use the means (`g_*`, `g_total_in_service`) or the per-year figures "
        "of `segments.parquet` (`kwh_per_kwp_year`, `irradiation_kwh_m2_year`).",
        "",
        "The internal geometry of the irradiance model (ray origins, reflector groups) is in "
        "`parts/geometry/tile=<TILE>.parquet`, the horizon profiles in `parts/horizon/`; the web "
        "app reads them, they are not documented here.",
        "",
        "## `geoparquet/segments/`, `geoparquet/segment_month/`: the same rows as datasets of "
        "spatial partitions",
        "",
        "The rows of `segments.parquet` and `segment_month.parquet` (same columns) as partitioned "
        "GeoParquet datasets (`part.<i>.parquet`, written by dask-geopandas): a partition is a "
        "group of whole tiles of the run, consecutive in the Hilbert order of the tiles (about "
        "2,000 segments), the same groups in both; each file's GeoParquet metadata holds its "
        "own bbox, so Dask opens each dataset as one GeoDataFrame with `spatial_partitions` "
        "(the columns' units as JSON in each file's `vipvflow:columns`):",
        "",
        "```python",
        "import dask_geopandas",
        "sm = dask_geopandas.read_parquet(\"out/demo/2024/geoparquet/segment_month\")  # sm.spatial_partitions",
        "```",
        "",
        "## `city.glb`: the run in 3D",
        "",
        "glTF 2.0 binary (any glTF viewer, Blender, `trimesh.load`): the buildings of the run's "
        "tiles, one mesh per building (node `building <building_id>`), and the route segments "
        "as one mesh (node `segments`; each segment a 2.5 m quad at roof height on the right of "
        "its direction of travel, faces `2k` and `2k+1` for `segment_ids[k]` of the mesh's "
        "extras) coloured by `kwh_per_kwp_year` (viridis, lowest to highest). Coordinates: the "
        "city's CRS minus a local origin (m, x east, y north, z up; the node `city` turns them "
        "into glTF's y-up); the scene's extras state `crs`, `origin`, `buildings`, `segments`, "
        "`tiles` and the colour scale. `vipvflow export gltf RUN_DIR --out FILE.glb` writes it "
        "again or elsewhere.",
        "",
    ]
    for name, spec in OUTPUTS.items():
        lines += [f"## `{name}.parquet`: {spec.title}", "", f"{spec.rows[0].upper()}{spec.rows[1:]}.", "",
                  "| column | unit | meaning |", "|---|---|---|"]
        for c in spec.columns:
            e = describe(name, c)
            lines.append(f"| `{c}` | {e.unit} | {e.meaning} |")
        lines.append("")
    lines += ["Columns of the whole-day model (`pv_kwh_driving`, `pv_kwh_layover`, `pv_kwh_parked`, "
              "`pv_kwh_curtailed`) appear only in runs that model the whole day.", "",
              "## `summary.json`", "",
              "The fleet-year. Yearly figures are scaled by 12 / months when the run covers fewer "
              "months (`annualised_from_months`).", "",
              "| key | unit | meaning |", "|---|---|---|"]
    for k, e in SUMMARY.items():
        lines.append(f"| `{k}` | {e.unit} | {e.meaning} |")
    lines.append("")
    return "\n".join(lines)


def render_html() -> str:
    """The data dictionary as HTML for the report (the report carries its own: a pip install
    has no docs/ folder): an introduction, then each output file's columns and
    ``summary.json``'s keys, each in a ``<details>`` block."""
    import html

    def row(name: str, e: Column) -> str:
        return (f"<tr><td><code>{html.escape(name)}</code></td><td>{html.escape(e.unit)}</td>"
                f"<td>{html.escape(e.meaning)}</td></tr>")

    parts = ["<p>Every Parquet file of the run carries the unit and meaning of each column (Arrow "
             "field metadata <code>unit</code>, <code>description</code>; for other readers JSON in "
             "the key-value metadata <code>vipvflow:columns</code>). Dates (<code>service_date</code>, "
             "<code>month</code>: a day of the feed's local calendar, a month as its first day) are "
             "Parquet <code>date32</code>; instants (<code>*_utc</code>) are timestamps in "
             "microseconds with time zone UTC. <code>fraction</code> is 0..1; W/m2 irradiance, "
             "Wh/m2 and kWh/m2 irradiation.</p>"]
    for name, spec in OUTPUTS.items():
        rows = "".join(row(c, describe(name, c)) for c in spec.columns)
        parts.append(f"<details><summary><code>{name}.parquet</code>: {html.escape(spec.title)} "
                     f"({html.escape(spec.rows)})</summary><table class='dictionary'>"
                     f"<tr><th>column</th><th>unit</th><th>meaning</th></tr>{rows}</table></details>")
    rows = "".join(row(k, e) for k, e in SUMMARY.items())
    parts.append("<details><summary><code>summary.json</code>: the fleet-year (yearly figures scaled "
                 "by 12 / months when the run covers fewer)</summary><table class='dictionary'>"
                 f"<tr><th>key</th><th>unit</th><th>meaning</th></tr>{rows}</table></details>")
    return "\n".join(parts)


if __name__ == "__main__":
    print(render_markdown(), end="")
