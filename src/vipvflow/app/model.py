"""What the web app shows, as a library: one trip recomputed for any settings, and the run's
monthly yields rescaled to another PV system.

:class:`TripModel` loads a finished run (``out/<scenario>/<year>/``) once: the segments,
their stored geometry factors (``parts/geometry``) and horizon profiles
(``parts/horizon``), the radiation table of the run's data directory, the timetable and the
run's route-month outputs.  :meth:`TripModel.trip` then recomputes one trip without ray
casting:

* departure: the first scheduled trip of the route and direction leaving at or after the
  requested time on the chosen date (the last one of the day when none leaves later; a
  trip of another service day, placed on the date, when the route does not run that day);
* per segment, at the middle of the time the bus spends on it (as the simulation does):
  sun and CAMS radiation from :class:`vipvflow.models.sun_sky.RadiationTable`, and the run's
  components summed by the simulation's own :func:`vipvflow.models.irradiance.roof_components`:
  direct ``DNI max(cos AOI, 0)`` when the sun's elevation exceeds the segment's horizon
  profile interpolated at the sun's azimuth (:mod:`vipvflow.models.horizon`), the simulation's own
  occlusion ray deciding where the profile cannot (within 1 deg of it, or at a building's
  edge between two azimuth bins); diffuse with the
  run's model (``DHI x SVF`` or the paper's isotropic ``DHI (1 + cos tilt) / 2``); reflected
  from the stored reflectors (:func:`vipvflow.models.view_factors.pack_geometry`: the facade groups and
  the street, their exchange folded in), each lit in the fraction of its stored sample points
  that see the sun: one occlusion query per trip against the tile meshes of the run's data
  directory (about 1e5 rays, milliseconds), the expectation of the simulation's one point
  per pass, whose per-pass standard deviation is given as ``reflected_sd``; the unshaded
  reference ``DNI max(cos AOI, 0) + DHI (1 + cos tilt) / 2``;
* PV: the simulation's dispatcher :func:`vipvflow.models.pv.energy` (paper mode ``kWp x POA / 1000
  x PR x dt / 3600`` or pvlib mode, PVWatts at a SAPM cell temperature cooled by the bus's
  speed);
* consumption: the pattern's 2 s driving cycle (:func:`vipvflow.models.driving_cycle.pattern_cycle`)
  through :func:`vipvflow.models.vehicle.simulate_cycle` with the chosen auxiliary base load
  (HVAC at the month's mean temperature on top), and the state of charge over the trip
  with and without PV.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
import pandas as pd

from ..config import Config, PVSystem
from ..models.loss import shading_loss
from ..store import DataDir, RunDir

#: PV technologies offered: PVWatts temperature coefficient of power (1/K, typical datasheet
#: values), module efficiency at STC (for sizing by area) and the pvlib SAPM mounting of the
#: cell-temperature model (``pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS['sapm']``).
TECHNOLOGIES = {
    "c-Si": {"gamma_pdc_per_k": -0.0037, "efficiency": 0.21,
             "temperature_model": "sapm_open_rack_glass_polymer"},
    "multi-Si": {"gamma_pdc_per_k": -0.0040, "efficiency": 0.18,
                 "temperature_model": "sapm_open_rack_glass_polymer"},
    "CdTe": {"gamma_pdc_per_k": -0.0028, "efficiency": 0.18,
             "temperature_model": "sapm_open_rack_glass_glass"},
    "CIGS": {"gamma_pdc_per_k": -0.0034, "efficiency": 0.16,
             "temperature_model": "sapm_open_rack_glass_glass"},
    "a-Si": {"gamma_pdc_per_k": -0.0020, "efficiency": 0.09,
             "temperature_model": "sapm_open_rack_glass_glass"},
}


#: s: a segment the bus stands in this much longer than it takes to drive it is a stop (its
#: dwell), shown apart on the map
STOP_DWELL_S = 5.0


#: degrees: within this of the horizon profile, or where it jumps by more between two
#: azimuth bins, the app asks the occlusion ray instead of the profile
HORIZON_BAND_DEG = 1.0


@dataclass(frozen=True)
class PVChoice:
    """The PV system the user explores.

    ``kwp`` (kW at STC) or, when ``area_m2`` is given, ``area_m2 x efficiency`` of the
    technology; ``performance_ratio`` is used in paper mode, ``losses_percent`` (DC system
    losses) and ``inverter_efficiency`` in pvlib mode.
    """

    technology: str = "c-Si"
    mode: str = "paper"
    kwp: float = 3.5
    area_m2: float | None = None
    performance_ratio: float = 0.75
    losses_percent: float = 14.0
    inverter_efficiency: float = 0.96

    @property
    def peak_kw(self) -> float:
        if self.area_m2 is not None:
            return float(self.area_m2) * TECHNOLOGIES[self.technology]["efficiency"]
        return float(self.kwp)

    def system(self) -> PVSystem:
        tech = TECHNOLOGIES[self.technology]
        return PVSystem(name=f"app {self.technology}", technology=self.technology,
                        kwp=self.peak_kw, roof_area_m2=30.0, area_share=0.8,
                        performance_ratio=self.performance_ratio,
                        gamma_pdc_per_k=tech["gamma_pdc_per_k"],
                        inverter_efficiency=self.inverter_efficiency,
                        system_losses_percent=self.losses_percent,
                        temperature_model=tech["temperature_model"])

    def linear_factor(self) -> float:
        """kW per kW/m2 of POA, for rescaling stored energies (paper: kWp x PR; pvlib:
        kWp x (1 - losses) x inverter efficiency, temperature effects not rescaled)."""
        if self.mode == "paper":
            from ..models.pv import paper_kw_per_wm2

            return 1000.0 * paper_kw_per_wm2(self.peak_kw, self.performance_ratio)
        return self.peak_kw * (1 - self.losses_percent / 100.0) * self.inverter_efficiency


@dataclass
class TripResult:
    """One recomputed trip.

    ``segments``: one row per segment pass (``segment_id, t_utc, time`` (local),
    ``dt_s, speed_mps``, W/m2 ``direct, diffuse, reflected, total, unshaded``,
    ``sun_visible``, ``elevation`` (deg), ``dwell_s`` (s standing beyond driving the segment
    at the trip's running speed), ``stop`` (dwell of :data:`STOP_DWELL_S` or more),
    ``power_kw``, ``energy_kwh``, ``x, y, x_end, y_end``);
    ``cycle``: the 2 s driving cycle (``time`` local, ``t_s``, ``speed_kmh``, ``soc``,
    ``soc_pv``, ``pv_kwh_cum``, ``battery_kwh_cum``); ``numbers``: ``pv_kwh``,
    ``pv_kwh_unshaded``, ``consumption_kwh``, ``share``, Wh/m2 of light on the roof
    ``h_direct, h_diffuse, h_reflected, h_total, h_unshaded``, ``shading_loss`` (on that
    light, :func:`vipvflow.models.loss.shading_loss`; NaN when the sun is down),
    ``sun_up``, ``stops``, ``stop_s``, ``stop_pv_kwh``, ``soc_end``, ``soc_end_pv``,
    ``distance_km``, ``duration_min``, ``compute_s``.
    """

    trip_id: str
    route_id: str
    direction_id: int
    date: pd.Timestamp
    departure: pd.Timestamp
    requested: str
    note: str
    segments: pd.DataFrame
    cycle: pd.DataFrame
    numbers: dict = field(default_factory=dict)


def _minutes(value) -> float:
    """Minutes after local midnight from ``'HH:MM'``, a number of minutes, or a time."""
    if isinstance(value, str):
        hh, mm = value.split(":")[:2]
        return int(hh) * 60 + float(mm)
    if hasattr(value, "hour"):
        return value.hour * 60 + value.minute + getattr(value, "second", 0) / 60
    return float(value)


#: files of the run's data dir the app reads
APP_NEEDS = ("gtfs/feed.json", "gtfs/segments.parquet", "gtfs/trips.parquet",
             "gtfs/patterns.parquet", "radiation/radiation.parquet")


class TripModel:
    """A finished run, loaded once, recomputing trips for the web app (a few occlusion rays
    per trip against the run's city meshes, no view-factor rays).

    Parameters
    ----------
    run_dir : path of ``out/<scenario>/<year>/`` (with ``manifest.json``)
    """

    def __init__(self, run_dir):
        from ..models.horizon import horizon_columns, load_horizons
        from ..models.view_factors import pack_geometry, read_geometry
        from ..models.sun_sky import RadiationTable
        from ..inputs.gtfs import service_dates

        from ..simulation.rundir import open_run

        run = open_run(run_dir, APP_NEEDS)
        self.run_dir, self.data_dir = run.path, run.data_dir
        manifest = run.manifest
        self.manifest = manifest
        self.year = int(manifest["year"])
        self.cfg = Config.model_validate(manifest["config"])
        gdir = DataDir(self.data_dir).gtfs
        self.timezone = json.loads(gdir.feed_json.read_text())["timezone"]
        self.vehicle = self.cfg.vehicle_params()
        self.run_pv = self.cfg.pv_system()
        self.run_pv_choice = PVChoice(
            technology=self.run_pv.technology if self.run_pv.technology in TECHNOLOGIES else "c-Si",
            mode=self.cfg.pv.mode, kwp=self.run_pv.kwp,
            performance_ratio=self.run_pv.performance_ratio,
            losses_percent=self.run_pv.system_losses_percent,
            inverter_efficiency=self.run_pv.inverter_efficiency)

        # segments with geometry factors and horizons, one row per segment id
        geo = pd.concat([read_geometry(f) for f in RunDir(self.run_dir).part_files("geometry")],
                        ignore_index=True)
        hor = load_horizons(self.run_dir)
        if len(hor) == 0:
            raise FileNotFoundError(f"{RunDir(self.run_dir).part_dir('horizon')}: no horizon profiles; "
                                    "re-run the simulation with this version of vipvflow")
        seg = pd.read_parquet(gdir.segments,
                              columns=["segment_id", "shape_id", "x", "y", "x_end", "y_end",
                                       "length_m", "tile"])
        geo = geo.merge(hor, on="segment_id", how="inner", validate="one_to_one")
        geo = geo.merge(seg, on="segment_id", how="left", validate="one_to_one")
        geo = geo.sort_values("segment_id").reset_index(drop=True)
        self.geometry = geo
        ids = geo["segment_id"].to_numpy(np.int64)
        self._row = np.full(int(ids.max()) + 1, -1, np.int64)
        self._row[ids] = np.arange(len(ids))
        self._packed = pack_geometry(geo, self.cfg.irradiance, self.cfg.city.albedo.ground)
        self._horizon = geo[horizon_columns(sum(c.startswith("h") and c[1:].isdigit()
                                                for c in hor.columns))].to_numpy(np.float32)
        self._loc = geo["rad_location"].to_numpy(np.int64) if "rad_location" in geo else None
        self._tile = geo["tile"].astype(str).to_numpy()
        self.radiation = RadiationTable.load(self.data_dir, self.year)
        summary = RunDir(self.run_dir).output("summary.json")
        self.summary = json.loads(summary.read_text()) if summary.exists() else {}

        # timetable
        self.trips = pd.read_parquet(gdir.trips)
        self.trips["route_id"] = self.trips["route_id"].astype(str)
        self.trips["service_id"] = self.trips["service_id"].astype(str)
        self.trips["direction_id"] = self.trips["direction_id"].fillna(0).astype(int)
        pat = pd.read_parquet(gdir.patterns)
        pat = pat.sort_values(["pattern_id", "t_offset_s"], kind="stable")
        self._patterns = {int(k): g for k, g in pat.groupby("pattern_id", sort=True)}
        self.service_dates = service_dates(self.data_dir, self.year)
        self.route_month = (pd.read_parquet(self.run_dir / "route_month.parquet")
                            if (self.run_dir / "route_month.parquet").exists() else pd.DataFrame())
        if len(self.route_month):
            self.route_month["route_id"] = self.route_month["route_id"].astype(str)
        # each trip's SoC at departure in the run's battery balance (its block-day under the
        # charging plan): a trip view starts from it
        te = RunDir(self.run_dir).output("trip_energy.parquet")
        self._soc_at_departure = {}
        if te.exists():
            import pyarrow.parquet as pq

            if "soc_at_departure" in pq.read_schema(te).names:
                t = pd.read_parquet(te, columns=["trip_id", "service_date", "soc_at_departure"])
                days = pd.to_datetime(t["service_date"]).dt.normalize()
                self._soc_at_departure = dict(zip(zip(t["trip_id"].astype(str), days),
                                                  t["soc_at_departure"].astype(float)))
        # the routes the run simulated: its run.routes, with trips in its outputs (a route
        # that shares a shape with a simulated one is not one), on shapes with geometry
        have = set(geo["shape_id"].dropna())
        keep = self.trips["shape_id"].isin(have)
        if self.cfg.run.routes is not None:
            keep &= self.trips["route_id"].isin({str(r) for r in self.cfg.run.routes})
        if len(self.route_month):
            keep &= self.trips["route_id"].isin(set(self.route_month["route_id"]))
        self.trips = self.trips[keep].reset_index(drop=True)

    # ------------------------------------------------------------------ choices
    def routes(self) -> pd.DataFrame:
        """Route-directions of the run: ``route_id, route_short_name, direction_id, trips`` and
        ``route_long_name``, ``trip_headsign`` (the direction's most frequent; empty when the
        feed has none)."""
        t = self.trips.reindex(columns=[*self.trips.columns.drop(["route_long_name", "trip_headsign"],
                                                                 errors="ignore"),
                                        "route_long_name", "trip_headsign"])

        def most(v):
            v = v.dropna()
            return v.mode().iloc[0] if len(v) else ""

        return (t.groupby(["route_id", "route_short_name", "direction_id"], sort=True)
                .agg(trips=("trip_id", "size"), route_long_name=("route_long_name", most),
                     trip_headsign=("trip_headsign", most))
                .reset_index())

    def departures(self, route_id, direction_id, date) -> pd.DataFrame:
        """Scheduled trips of a route-direction on a service date (``trip_id, start_s``),
        by departure time; empty when the route does not run that day."""
        date = pd.Timestamp(date).normalize()
        sids = set(self.service_dates.loc[self.service_dates["date"] == date, "service_id"].astype(str))
        t = self.trips[(self.trips["route_id"] == str(route_id))
                       & (self.trips["direction_id"] == int(direction_id))
                       & self.trips["service_id"].isin(sids)]
        return t.sort_values("start_s", kind="stable")

    def pick_trip(self, route_id, direction_id, date, depart) -> tuple[pd.Series, str]:
        """The trip leaving at or after *depart* (``'HH:MM'`` or minutes) on *date*; the
        note says which rule chose it."""
        want_s = _minutes(depart) * 60.0
        deps = self.departures(route_id, direction_id, date)
        note = "next scheduled departure at or after the chosen time"
        if deps.empty:
            deps = self.trips[(self.trips["route_id"] == str(route_id))
                              & (self.trips["direction_id"] == int(direction_id))]
            deps = deps.sort_values("start_s", kind="stable").drop_duplicates("start_s")
            note = "the route does not run that day: a trip of another service day, placed on it"
            if deps.empty:
                raise KeyError(f"no trips for route {route_id!r} direction {direction_id}")
        later = deps[deps["start_s"] >= want_s - 1e-6]
        if later.empty:
            return deps.iloc[-1], "no later departure that day: the day's last trip"
        return later.iloc[0], note

    # ------------------------------------------------------------------ compute
    @lru_cache(maxsize=64)
    def _cycle(self, pattern_id: int) -> pd.DataFrame:
        from ..models.driving_cycle import pattern_cycle

        return pattern_cycle(self.data_dir, pattern_id, self.cfg.trajectory.cycle)

    def _origin_utc(self, date) -> float:
        from ..inputs.gtfs import service_day_origin_utc

        return float(service_day_origin_utc([pd.Timestamp(date)], self.timezone)[0])

    def _scene(self, tile: str):
        from ..models.shading import get_scene

        return get_scene(self.data_dir, tile, cache_size=64)

    def reflector_lit(self, rows, sun, facing, classes=None) -> np.ndarray:
        """Sunlit fraction (0..1) of each stored reflector's sample points, (n, J).

        Parameters
        ----------
        rows : (n,) int, rows of the stored geometry
        sun : (n, 3) float32, unit vectors towards the sun
        facing : (n, J) bool, reflectors facing the sun (the others stay 0)
        classes : (n,) int, optional, each pass's class of months (the tree crowns'
            transmittance of a ray the buildings let through; 0)

        One occlusion ray per sample point, from the same origins as the simulation's
        (``reflector_sampling: all``): the mean of its one-point-per-pass estimate.
        """
        geo = self._packed
        J = geo["wn"].shape[2]
        gp = geo["group_p"]
        P = gp.shape[1]
        lit = np.zeros(facing.shape, np.float32)
        pi, gi = np.nonzero(facing)
        if not len(pi):
            return lit
        cls = np.zeros(len(rows), np.int64) if classes is None else np.asarray(classes, np.int64)
        pair = rows[pi] * J + gi
        tiles = self._tile[rows[pi]]
        L = self.cfg.irradiance.ray_length_m
        for tile in np.unique(tiles):
            sel = np.flatnonzero(tiles == tile)
            o = gp[pair[sel]].reshape(-1, 3)
            d = np.repeat(sun[pi[sel]], P, axis=0)
            scene = self._scene(tile)
            T = (~scene.occluded(o, d, L)).astype(np.float32)
            crowns = scene.crowns(self.cfg.irradiance)
            if crowns is not None:
                free = np.flatnonzero(T > 0)
                T[free] = crowns.transmittance(o[free] - scene.origin, d[free], L,
                                               np.repeat(cls[pi[sel]], P)[free])
            # each point's factor through the crowns: the reflector as the roof sees it
            f = geo["group_f"][pair[sel], :, cls[pi[sel]]]
            lit[pi[sel], gi[sel]] = (T.reshape(-1, P) * f).sum(1) / np.float32(P)
        return lit

    def sun_visible(self, rows, sun, elevation_deg, azimuth_deg, in_front) -> np.ndarray:
        """Whether the sun reaches the roof point, (n,) bool: from the stored horizon profile
        (:func:`vipvflow.models.horizon.sun_visible`), and where the profile cannot tell (the sun
        within ``HORIZON_BAND_DEG`` of it, or in an azimuth bin where it jumps by more than
        that: a building's edge) from the simulation's own occlusion ray, so the app's direct
        light is the run's.

        Parameters
        ----------
        rows : (n,) int, rows of the stored geometry
        sun : (n, 3) float32, unit vectors towards the sun
        elevation_deg, azimuth_deg : (n,) sun position (deg)
        in_front : (n,) bool, passes with the sun up and in front of the roof (the others
            get no direct light whatever the answer)
        """
        from ..models.horizon import horizon_at

        prof = self._horizon[rows]
        h = horizon_at(prof, azimuth_deg)
        visible = (elevation_deg > 0) & (elevation_deg > h)
        k = prof.shape[1]
        j = np.floor((np.asarray(azimuth_deg) % 360.0) * k / 360.0).astype(np.int64) % k
        r = np.arange(len(rows))
        jump = np.abs(prof[r, j] - prof[r, (j + 1) % k]) > HORIZON_BAND_DEG
        unsure = np.flatnonzero(in_front & ((np.abs(elevation_deg - h) < HORIZON_BAND_DEG) | jump))
        tiles = self._tile[rows[unsure]]
        for tile in np.unique(tiles):
            sel = unsure[tiles == tile]
            visible[sel] = ~self._scene(tile).occluded(self._packed["p"][rows[sel]], sun[sel],
                                                       self.cfg.irradiance.ray_length_m)
        self.rays_for_direct = len(unsure)
        return visible

    def sun_transmittance(self, rows, sun, visible, classes) -> np.ndarray:
        """The tree crowns' transmittance of the sun ray of passes the buildings let it
        through (*visible*), in each pass's class of months (float32; 0 where not visible):
        :meth:`vipvflow.models.trees.Crowns.transmittance` from the simulation's ray origin."""
        out = visible.astype(np.float32)
        idx = np.flatnonzero(visible)
        tiles = self._tile[rows[idx]]
        for tile in np.unique(tiles):
            sel = idx[tiles == tile]
            scene = self._scene(tile)
            crowns = scene.crowns(self.cfg.irradiance)
            if crowns is not None:
                out[sel] = crowns.transmittance(self._packed["p"][rows[sel]] - scene.origin, sun[sel],
                                                self.cfg.irradiance.ray_length_m, classes[sel])
        return out

    def irradiance(self, segment_ids, t_utc) -> dict:
        """Roof irradiance components (W/m2) of segments at times, from stored factors.

        Parameters
        ----------
        segment_ids : (n,) int
        t_utc : (n,) float, Unix s

        Returns
        -------
        dict of (n,) arrays: ``direct, diffuse, reflected, total, unshaded`` (W/m2),
        ``reflected_sd`` (W/m2: standard deviation of the simulation's one-sample-point
        estimate of the reflected beam for that pass), ``sun_visible`` (bool),
        ``elevation, azimuth`` (deg), ``ghi, dni, dhi`` (W/m2).
        """
        from ..models.irradiance import ROULETTE_WEIGHT, pass_classes, roof_components, sky_terms
        from ..models.sky import COS_85
        from ..models.trees import month_of
        from ..models.view_factors import isotropic_sky_view

        f32 = np.float32
        rows = self._row[np.asarray(segment_ids, np.int64)]
        if (rows < 0).any():
            raise KeyError("segments without stored geometry")
        t_utc = np.asarray(t_utc, np.float64)
        loc = None if self._loc is None else self._loc[rows]
        rad = self.radiation.lookup(t_utc, location=loc, angles=True)
        geo = self._packed
        cls = pass_classes(geo, rows, month_of(t_utc))
        dni, dhi, ghi = (np.nan_to_num(np.asarray(rad[c], f32)) for c in ("dni", "dhi", "ghi"))
        sun = np.nan_to_num(np.stack([rad["sun_x"], rad["sun_y"], rad["sun_z"]], 1).astype(f32))
        elev = 90.0 - np.nan_to_num(rad["zenith"], nan=180.0).astype(np.float64)
        up = sun[:, 2] > 0
        nrm = geo["n"][rows]
        cos_aoi = np.where(up, np.maximum(np.einsum("ij,ij->i", nrm, sun), 0), 0).astype(f32)
        visible = self.sun_visible(rows, sun, elev, np.nan_to_num(rad["azimuth"]), up & (cos_aoi > 0))
        vis_t = self.sun_transmittance(rows, sun, visible & up & (cos_aoi > 0), cls)
        iso = isotropic_sky_view(nrm[:, 2])
        sky = geo["svf"][rows, cls] if self.cfg.irradiance.diffuse_model != "isotropic" else iso
        cfg = self.cfg.irradiance
        J = geo["wn"].shape[2] if (cfg.reflection and cfg.max_reflector_groups) else 0
        beam = np.zeros((len(rows), J), f32)
        if J:
            beam[up] = np.einsum("igj,ij->ig", geo["wn"][rows[up], cls[up]], sun[up])
            beam = np.maximum(beam, 0)
            r_sky, r_ghi = geo["refl_sky"][rows, cls], geo["refl_ghi"][rows, cls]
        else:
            r_sky = r_ghi = np.zeros(len(rows), f32)
        lit = self.reflector_lit(rows, sun, beam > 0, cls)
        terms = None
        if cfg.diffuse_model == "perez_svf":
            terms = {**sky_terms(geo, rows, sun[:, 2], bool(J), cls),
                     "f1": np.nan_to_num(np.asarray(rad["f1"], f32)),
                     "f2": np.nan_to_num(np.asarray(rad["f2"], f32))}
            if geo["sky_x"].shape[1]:            # the sky the roof point sees, as the run
                terms["share"], terms["share_open"] = self.radiation.sky_share(
                    t_utc, geo["sky_x"][rows], nrm, loc)
                if geo["tsky"].shape[2]:         # less what the crowns take from it
                    terms["share"] = terms["share"] - self.radiation.sky_tree_share(
                        t_utc, geo["tsky"][rows, cls], nrm, loc)
        direct, diffuse, reflected, unshaded = roof_components(
            dni, dhi, ghi, cos_aoi, vis_t, sky, beam, lit, r_sky, r_ghi, iso, terms)
        # the run's estimate of a reflector's beam, per pass: one sample point (0 or 1),
        # faint reflectors traced only now and then at a larger weight (irradiance._roulette):
        # variance b max(b, ROULETTE_WEIGHT) L - b^2 L^2 each
        var = beam * np.maximum(beam, ROULETTE_WEIGHT) * lit - (beam * lit) ** 2
        beam_in = dni                    # the reflectors' beam: the sun's, and the circumsolar sky's
        if terms is not None:
            beam_in = dni + dhi * terms["f1"] / np.maximum(terms["cos_zenith"], f32(COS_85))
        sd = beam_in * np.sqrt(np.maximum(var, 0).sum(1)) if J else np.zeros(len(rows), f32)
        return {"direct": direct, "diffuse": diffuse, "reflected": reflected,
                "total": direct + diffuse + reflected, "unshaded": unshaded, "reflected_sd": sd,
                "sun_visible": visible, "elevation": elev, "azimuth": rad["azimuth"],
                "ghi": ghi, "dni": dni, "dhi": dhi}

    def pv_energy(self, poa, dt_s, speed_mps, month: int, pv: PVChoice) -> np.ndarray:
        """PV energy (kWh) of each pass at POA irradiance *poa* (W/m2) for *dt_s* (s), with
        the simulation's dispatcher :func:`vipvflow.models.pv.energy`."""
        from ..models import pv as pvmod

        return pvmod.energy(poa, dt_s, pv.system(), pv.mode,
                            temp_air_c=self.cfg.monthly_temperature_c()[month - 1],
                            vehicle_speed_mps=speed_mps, wind_mps=self.cfg.climate.wind_speed_mps)

    def _vehicle_run(self, pid: int, month: int, origin: float, off, dt, energy, aux_kw, soc_start,
                     soc_min):
        """The vehicle along the trip's driving cycle, with and without the PV *energy* (kWh per
        segment pass): (parameters, SoC at departure, consumption, the per-second cycle with SoC
        and cumulative kWh)."""
        from ..models.vehicle import simulate_cycle

        tz = self.timezone
        params = self.vehicle
        upd = {}
        if aux_kw is not None:
            upd["aux_base_kw"] = float(aux_kw)
        if soc_min is not None:
            upd["soc_min"] = float(soc_min)
        if soc_start is not None:
            upd["soc_max"] = max(float(soc_start), params.soc_min if soc_min is None else float(soc_min) + 1e-6)
        if upd:
            params = params.model_copy(update=upd)
        soc0 = params.soc_max if soc_start is None else float(soc_start)
        cycle = self._cycle(pid)
        cons = simulate_cycle(cycle, params, self.cfg.monthly_temperature_c()[month - 1],
                              detail=True)
        iv = cons["intervals"]
        t_s = cycle["t_s"].to_numpy(np.float64)
        e_batt = np.r_[0.0, np.cumsum(iv["p_battery"] * iv["dt_s"]) / 3.6e6]      # kWh
        seg_end = np.r_[0.0, off + dt]
        e_pv = np.interp(t_s - t_s[0], seg_end, np.r_[0.0, np.cumsum(energy)])
        cap = params.battery_kwh
        soc = soc0 - e_batt / cap
        # with PV: charging stops at soc_max (one-sided reflection of the running sum)
        free = soc0 + (e_pv - e_batt) / cap
        soc_pv = free - np.maximum(np.maximum.accumulate(free - params.soc_max), 0.0)
        cyc = pd.DataFrame({
            "t_s": t_s,
            "time": pd.to_datetime(origin + t_s - t_s[0], unit="s", utc=True).tz_convert(tz).tz_localize(None),
            "speed_kmh": cycle["speed_mps"].to_numpy(np.float64) * 3.6,
            "soc": soc, "soc_pv": soc_pv, "pv_kwh_cum": e_pv, "battery_kwh_cum": e_batt})
        return params, soc0, cons, cyc

    def trip(self, route_id, direction_id, date, depart="08:00", pv: PVChoice | None = None,
             aux_kw: float | None = None, soc_start: float | None = None,
             soc_min: float | None = None) -> TripResult:
        """Recompute one trip (see the module doc for the rules and the model).

        Parameters
        ----------
        route_id, direction_id : the route-direction
        date : service date (str ``YYYY-MM-DD``, date or Timestamp; local day)
        depart : ``'HH:MM'`` or minutes after local midnight (requested departure)
        pv : PVChoice (default: the run's PV system)
        aux_kw : auxiliary base load (kW), HVAC at the month's temperature on top
            (default: the vehicle's)
        soc_start, soc_min : SoC at the trip's start and the lower limit (0..1; defaults:
            the SoC at that departure in the run's battery balance (``trip_energy``'s
            ``soc_at_departure``; the vehicle's ``soc_max`` for a trip the run does not have
            that day) and the vehicle's ``soc_min``)
        """
        from ..models.vehicle import soc_trace

        t0 = time.perf_counter()
        pv = pv or self.run_pv_choice
        date = pd.Timestamp(date).normalize()
        row, note = self.pick_trip(route_id, direction_id, date, depart)
        pid = int(row["pattern_id"])
        pat = self._patterns[pid]
        origin = self._origin_utc(date) + float(row["start_s"])
        off = pat["t_offset_s"].to_numpy(np.float64)
        dt = pat["dt_s"].to_numpy(np.float64)
        speed = pat["speed_mps"].to_numpy(np.float64)
        sid = pat["segment_id"].to_numpy(np.int64)
        t_mid = origin + off + 0.5 * dt
        irr = self.irradiance(sid, t_mid)
        month = int(date.month)
        energy = self.pv_energy(irr["total"], dt, speed, month, pv)
        energy_uns = self.pv_energy(irr["unshaded"], dt, speed, month, pv)
        parts = {c: self.pv_energy(irr[c], dt, speed, month, pv)
                 for c in ("direct", "diffuse", "reflected", "reflected_sd")}
        g = self.geometry.iloc[self._row[sid]]
        tz = self.timezone
        # the time the bus stands in a segment beyond driving it at the trip's running speed
        # (the median of its segments'): a stop's dwell, shown apart on the map
        length = g["length_m"].to_numpy(np.float64)
        running = float(np.median(speed[speed > 0])) if (speed > 0).any() else 1.0
        dwell = np.maximum(dt - length / running, 0.0)
        segs = pd.DataFrame({
            "segment_id": sid, "t_utc": origin + off,
            "time": pd.to_datetime(origin + off, unit="s", utc=True).tz_convert(tz).tz_localize(None),
            "dt_s": dt, "speed_mps": speed,
            **{k: np.asarray(irr[k], np.float64) for k in ("direct", "diffuse", "reflected", "total",
                                                           "unshaded")},
            "sun_visible": irr["sun_visible"], "elevation": np.asarray(irr["elevation"], np.float64),
            "dwell_s": dwell, "stop": dwell >= STOP_DWELL_S,
            "power_kw": np.divide(energy * 3600.0, dt, out=np.zeros_like(dt), where=dt > 0),
            "energy_kwh": energy,
            "x": g["x"].to_numpy(), "y": g["y"].to_numpy(),
            "x_end": g["x_end"].to_numpy(), "y_end": g["y_end"].to_numpy()})

        soc_from = "as chosen"
        if soc_start is None:
            soc_start = self._soc_at_departure.get((str(row["trip_id"]), date))
            soc_from = ("the run's battery balance of its block-day" if soc_start is not None
                        else "the vehicle's soc_max (the run has no such trip that day)")
        params, soc0, cons, cyc = self._vehicle_run(pid, month, origin, off, dt, energy,
                                                    aux_kw, soc_start, soc_min)
        pv_kwh = float(energy.sum())
        use = float(cons["battery_kwh"])
        end = soc_trace(pd.DataFrame({"battery_kwh": [use]}), [pv_kwh], params, soc_start=soc0)
        uns = float(energy_uns.sum())
        # the light on the roof over the trip (Wh/m2): the shading loss is defined on it, as
        # in the run, whatever the PV model (a non-linear one would weigh the components
        # differently)
        light = {c: float((np.asarray(irr[c], np.float64) * dt).sum() / 3600.0)
                 for c in ("direct", "diffuse", "reflected", "total", "unshaded")}
        stop = segs["stop"].to_numpy()
        numbers = {
            "pv_kwh": pv_kwh, "pv_kwh_unshaded": uns, "consumption_kwh": use,
            "share": pv_kwh / use if use > 0 else float("nan"),
            "pv_kwh_direct": float(parts["direct"].sum()),
            "pv_kwh_diffuse": float(parts["diffuse"].sum()),
            "pv_kwh_reflected": float(parts["reflected"].sum()),
            # the run's reflected kWh of this trip varies by this much (its one sample point
            # per reflector and pass), independent passes
            "pv_kwh_reflected_se": float(np.sqrt((parts["reflected_sd"] ** 2).sum())),
            **{f"h_{c}": v for c, v in light.items()},
            "shading_loss": float(shading_loss(light["direct"], light["diffuse"], light["unshaded"])),
            "sun_up": bool((irr["elevation"] > 0).any() and light["unshaded"] > 0),
            "stops": int(stop.sum()), "stop_s": float(dwell[stop].sum()),
            "stop_pv_kwh": float(energy[stop].sum()),
            "soc_start": float(soc0), "soc_start_from": soc_from,
            "soc_end": float(end["soc_end"].iloc[0]), "soc_end_pv": float(end["soc_end_pv"].iloc[0]),
            "soc_min": params.soc_min, "kwp": pv.peak_kw,
            "diffuse_model": self.cfg.irradiance.diffuse_model,
            "distance_km": float(cons["distance_km"]), "duration_min": float(cons["duration_s"]) / 60.0,
        }
        departure = pd.Timestamp(origin, unit="s", tz="UTC").tz_convert(tz).tz_localize(None)
        numbers["compute_s"] = time.perf_counter() - t0
        return TripResult(trip_id=str(row["trip_id"]), route_id=str(route_id),
                          direction_id=int(direction_id), date=date, departure=departure,
                          requested=f"{int(_minutes(depart)) // 60:02d}:{int(_minutes(depart)) % 60:02d}",
                          note=note, segments=segs, cycle=cyc, numbers=numbers)

    # ------------------------------------------------------------------ fleet / months
    def monthly(self, route_id=None, direction_id=None, pv: PVChoice | None = None) -> pd.DataFrame:
        """The run's PV energy per month rescaled to *pv* (linear in kWp and PR or losses).

        Parameters
        ----------
        route_id, direction_id : a route-direction, or ``None`` for the fleet

        Returns
        -------
        DataFrame: ``month``, ``trips``, kWh ``allsky, clearsky, allsky_unshaded,
        clearsky_unshaded, consumption``, ``shading_loss`` (all-sky, 1 - (direct + diffuse)
        / unshaded), ``share`` (all-sky PV / consumption).
        """
        rm = self.route_month
        cols = ["month", "trips", "allsky", "clearsky", "allsky_unshaded", "clearsky_unshaded",
                "consumption", "shading_loss", "share"]
        if rm.empty:
            return pd.DataFrame(columns=cols)
        if route_id is not None:
            rm = rm[rm["route_id"] == str(route_id)]
            if direction_id is not None:
                rm = rm[rm["direction_id"].fillna(0).astype(int) == int(direction_id)]
        f = (pv or self.run_pv_choice).linear_factor() / self.run_pv_choice.linear_factor()
        agg = rm.groupby("month", sort=True)[["trips", "pv_kwh", "pv_kwh_clear", "pv_kwh_unshaded",
                                              "pv_kwh_clear_unshaded", "pv_kwh_direct",
                                              "pv_kwh_diffuse", "consumption_kwh"]].sum()
        # the file's months are dates (first day); the app shows them as YYYY-MM
        out = pd.DataFrame({"month": agg.index.astype(str).str.slice(0, 7), "trips": agg["trips"].to_numpy(),
                            "allsky": agg["pv_kwh"].to_numpy() * f,
                            "clearsky": agg["pv_kwh_clear"].to_numpy() * f,
                            "allsky_unshaded": agg["pv_kwh_unshaded"].to_numpy() * f,
                            "clearsky_unshaded": agg["pv_kwh_clear_unshaded"].to_numpy() * f,
                            "consumption": agg["consumption_kwh"].to_numpy()})
        out["shading_loss"] = shading_loss(agg["pv_kwh_direct"].to_numpy(),
                                           agg["pv_kwh_diffuse"].to_numpy(),
                                           agg["pv_kwh_unshaded"].to_numpy())
        out["share"] = out["allsky"] / out["consumption"].where(out["consumption"] > 0)
        return out

