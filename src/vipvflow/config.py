"""Scenario configuration: one schema, validated on load.

``default.yaml`` holds every default; a scenario YAML (``demo.yaml``, ``luxembourg.yaml`` or
a user's file) overrides any part of it.  Catalog entries (vehicles in ``vehicles.yaml``, PV
systems in ``pv_systems.yaml``) are chosen by name.  The shipped files live in the repository's
top-level ``conf/``, installed as the package data of ``vipvflow.conf`` (pyproject.toml maps that
package to ``conf/``), so an installed vipvflow has them; ``$VIPVFLOW_CONF_DIR`` replaces that
folder.  A wrong key or value raises :class:`ConfigError`
naming the file, the key and the reason.
"""
from __future__ import annotations

import copy
import hashlib
import json
import os
import re
from importlib.util import find_spec
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import (BaseModel, ConfigDict, Field, ValidationError, field_validator,
                      model_validator)

from .errors import ConfigError
from .models.params import CycleCfg, IrradianceCfg, PVSystem
from .store import TILE_SIZE_M


def _conf_dir() -> Path:
    """The folder of the shipped YAML files: ``$VIPVFLOW_CONF_DIR``; else the package
    ``vipvflow.conf`` (a wheel's copy, or the repository's ``conf/`` in an editable install);
    else, in a source tree on ``sys.path`` without an install, ``conf/`` beside ``src/``."""
    if os.environ.get("VIPVFLOW_CONF_DIR"):
        return Path(os.environ["VIPVFLOW_CONF_DIR"])
    spec = find_spec("vipvflow.conf")
    if spec is not None and spec.submodule_search_locations:
        for folder in spec.submodule_search_locations:
            if (Path(folder) / "default.yaml").is_file():
                return Path(folder)
    return Path(__file__).resolve().parents[2] / "conf"


CONF_DIR = _conf_dir()
_NOT_SCENARIOS = {"default", "vehicles", "pv_systems"}


def shipped_scenarios() -> list[str]:
    """Names of the scenario files shipped with vipvflow (``demo``, ``luxembourg``)."""
    return sorted(p.stem for p in CONF_DIR.glob("*.yaml") if p.stem not in _NOT_SCENARIOS)


def scenario_path(name: str | Path) -> Path:
    """The scenario file *name* stands for: an existing file as given; else a shipped scenario
    by name (``demo``, ``demo.yaml``, or ``conf/demo.yaml`` from outside the repository); else
    *name* unchanged (reading it then reports the missing file)."""
    path = Path(name)
    if path.is_file():
        return path
    if path.parent in (Path("."), Path("conf")):
        shipped = CONF_DIR / f"{path.stem}.yaml"
        if path.suffix in ("", ".yaml") and path.stem not in _NOT_SCENARIOS and shipped.is_file():
            return shipped
    return path


class _Model(BaseModel):
    # no inf or nan: "kwp: .inf" passed validation and failed only after the map
    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)


class DemoSpec(_Model):
    """The embedded demo scenario, generated when its files are missing."""

    enabled: bool = False
    seed: int = 42
    size: Literal["full", "small"] = "full"


class Inputs(_Model):
    citygml: list[Path] = Field(default_factory=list)
    citygml_crs: str | None = None
    gtfs: Path | None = None
    # IANA zone of the timetable for a feed without agency.txt (the feed's own wins)
    gtfs_timezone: str | None = None
    cams: list[Path] = Field(default_factory=list)
    # tree tables (CSV or GeoParquet points: height, crown_diameter, optional crown_base,
    # leaf_type or genus, leaf_off_months), their trees beside the CityGML vegetation
    trees: list[Path] = Field(default_factory=list)
    # CRS of a CSV tree table's x/y columns (default: the city's; lon/lat columns are WGS84)
    trees_crs: str | None = None


class Albedo(_Model):
    """Broadband albedo per surface type (dimensionless, 0..1)."""

    roof: float = Field(0.15, ge=0, le=1)
    wall: float = Field(0.30, ge=0, le=1)
    ground: float = Field(0.20, ge=0, le=1)
    road: float = Field(0.10, ge=0, le=1)
    closure: float = Field(0.0, ge=0, le=1)
    terrain: float = Field(0.20, ge=0, le=1)
    other: float = Field(0.20, ge=0, le=1)

    @model_validator(mode="before")
    @classmethod
    def _no_vegetation(cls, data):
        if isinstance(data, dict) and "vegetation" in data:
            raise ValueError("vegetation is gone: trees are crowns that let through a share of "
                             "the light (irradiance.trees), not reflecting surfaces")
        return data


class CityTreesCfg(_Model):
    """How the ingest makes crowns of trees whose data says less than a crown needs."""

    # the crown base (lowest leaves) of a tree whose data gives none, as a share of its
    # height (a crown of two thirds of the tree, as urban trees' live crown ratios go)
    crown_base_fraction: float = Field(0.35, ge=0, lt=1)


class CityCfg(_Model):
    # bounds keep a run's tile and mesh count sane (a 1 mm tile would ask for GiBs of index)
    tile_size_m: float = Field(TILE_SIZE_M, ge=50, le=100_000)
    buffer_m: float = Field(300.0, ge=0, le=5_000)
    albedo: Albedo = Field(default_factory=Albedo)
    planarity_tolerance_m: float = Field(0.10, gt=0)
    min_area_m2: float = Field(0.01, ge=0)
    trees: CityTreesCfg = Field(default_factory=CityTreesCfg)




class TrajectoryCfg(_Model):
    segment_length_m: float = Field(10.0, ge=0.5, le=1_000)
    roof_height_m: float = Field(3.2, ge=0, le=10)
    # the ground's height above sea level (m) where the city model has neither relief nor a
    # building within 100 m; null: the radiation file's declared altitude
    ground_elevation_m: float | None = Field(None, ge=-500, le=9_000)
    timing: Literal["stop_times", "driving_cycle"] = "stop_times"
    cycle: CycleCfg = Field(default_factory=CycleCfg)

    @model_validator(mode="before")
    @classmethod
    def _renamed(cls, data):
        if isinstance(data, dict) and "default_elevation_m" in data:
            raise ValueError("default_elevation_m is gone (a constant put roads outside the "
                             "city model at 300 m); the ground comes from the city model, else "
                             "the radiation file's altitude, else ground_elevation_m")
        return data






class PVCfg(_Model):
    system: str = "csi_3p5kwp"
    mode: Literal["paper", "pvlib"] = "paper"
    overrides: dict[str, Any] = Field(default_factory=dict)


class VehicleCfg(_Model):
    model: str = "ecitaro_12m"
    overrides: dict[str, Any] = Field(default_factory=dict)
    # folder of VECTO modal results named pattern_<id>.vmod (from running VECTO on the
    # run's vecto/ cycles): they replace the built-in consumption of those patterns
    vmod_dir: Path | None = None


class EconomicsCfg(_Model):
    cost_eur_per_wp: float = Field(1.5, ge=0)
    tariff_eur_per_kwh: float = Field(0.21, ge=0)
    soc_window: tuple[float, float] = (0.2, 0.8)

    @model_validator(mode="after")
    def _window(self):
        lo, hi = self.soc_window
        if not 0 <= lo < hi <= 1:
            raise ValueError("soc_window must be [low, high] with 0 <= low < high <= 1")
        return self


class ClimateCfg(_Model):
    """Ambient conditions for the vehicle's HVAC and the PV cell temperature."""

    # monthly mean air temperature of the city (deg C), Jan..Dec; null: the shipped
    # climatology at the radiation file's location (vipvflow.inputs.climate)
    monthly_mean_temperature_c: list[float] | None = Field(None, min_length=12, max_length=12)
    wind_speed_mps: float = Field(3.0, ge=0)


class DaskCfg(_Model):
    scheduler: str | None = None
    n_workers: int | None = Field(None, gt=0)
    threads_per_worker: int | None = Field(None, gt=0)
    memory_limit: str = "auto"
    bvh_cache_size: int = Field(8, gt=0)
    # Embree threads per task (a tile's months); null: cores / workers on a LocalCluster, 1 on a
    # remote cluster (one task per worker thread already fills the cores)
    ray_threads: int | None = Field(None, gt=0)
    # Dask's statistical profiler (the dashboard's Profile tab) on the LocalCluster's workers:
    # it samples every worker's stack 100 times a second, which cost a worker ~7 % of its CPU
    worker_profile: bool = False
    # the LocalCluster's dashboard: this port when free, else (or null) any free one
    dashboard_port: int | None = Field(8787, ge=0, le=65535)
    # the address the LocalCluster's scheduler, workers and dashboard listen on: this
    # machine only by default; 0.0.0.0 (every interface) to reach them from elsewhere
    host: str = "127.0.0.1"


class RunCfg(_Model):
    """What part of the year and network to simulate (all months and routes by default)."""

    months: list[int] = Field(default_factory=lambda: list(range(1, 13)), min_length=1)
    routes: list[str] | None = None
    # GTFS route_type values to simulate: "bus" (3 bus, 11 trolleybus, extended 700..716 bus
    # services and 800 trolleybus), "all", or a list (0 tram, 1 subway, 2 rail, 109 suburban
    # railway, ...: a building model knows no tunnels or viaducts, said at ingest)
    route_types: Literal["bus", "all"] | list[int] = "bus"

    @field_validator("route_types", mode="before")
    @classmethod
    def _route_types(cls, v):
        if v is None:
            return "all"
        if isinstance(v, list) and not v:
            raise ValueError("an empty list keeps no route; use bus, all or a list of GTFS route types")
        bad = [t for t in v if not isinstance(t, int) or isinstance(t, bool)
               or not (0 <= t <= 12 or 100 <= t <= 1799)] if isinstance(v, list) else []
        if bad:
            raise ValueError(f"not GTFS route types (0..12 or extended 100..1799): {bad}")
        return v

    @model_validator(mode="after")
    def _months(self):
        bad = [m for m in self.months if not 1 <= m <= 12]
        if bad:
            raise ValueError(f"months must be 1..12, got {bad}")
        self.__dict__["months"] = sorted(set(self.months))
        return self


class RadiationCfg(_Model):
    """How much missing radiation a run accepts."""

    # a gap in the radiation data longer than this, while buses run, stops the run before the
    # cluster starts; shorter gaps are interpolated and counted (min)
    max_gap_minutes: float = Field(60.0, gt=0)


class DepotCfg(_Model):
    """Where the buses stand outside their blocks (WGS84 degrees)."""

    lat: float = Field(ge=-90, le=90)
    lon: float = Field(ge=-180, le=180)


class FleetCfg(_Model):
    """What the roofs harvest besides driving: layovers at terminals and parking at a depot."""

    # driving: the minutes on trips only (the paper's accounting); in_service: driving plus
    # the layovers between the trips of a block; whole_day: also parked outside the blocks
    harvest: Literal["driving", "in_service", "whole_day"] = "whole_day"
    # the depot (lat/lon); null: the first stop of each block's first trip
    depot: DepotCfg | None = None
    # open: a field without shade; covered: under a roof (no light); city: the depot's
    # position in the city model (buildings shade and reflect as on the road)
    depot_shading: Literal["open", "covered", "city"] = "city"


class DepotChargingCfg(_Model):
    """The depot's chargers: they restore each morning's SoC while the bus is parked."""

    power_kw: float = Field(100.0, gt=0, le=2_000)        # drawn from the grid per bus
    efficiency: float = Field(0.95, gt=0, le=1)           # battery energy / grid energy
    # local hours [from, to) the chargers run (to < from: past midnight); null: whenever parked
    hours: tuple[float, float] | None = None
    target_soc: float | None = Field(None, ge=0, le=1)    # null: the vehicle's soc_max

    @field_validator("hours")
    @classmethod
    def _hours(cls, v):
        if v is not None and not all(0 <= h <= 24 for h in v):
            raise ValueError("hours are local clock hours 0..24, e.g. [21, 5]")
        return v


class OpportunityChargingCfg(_Model):
    """Chargers at terminals (pantographs): a charge during a layover long enough for it."""

    # stop_ids of the terminals with a charger, "all" (every terminal a block lays over
    # at), or null (no opportunity charging)
    terminals: list[str] | Literal["all"] | None = None
    min_layover_min: float = Field(10.0, ge=0)            # a shorter layover is not used
    connect_min: float = Field(1.0, ge=0)                 # of each layover, docking and undocking
    power_kw: float = Field(300.0, gt=0, le=2_000)
    efficiency: float = Field(0.95, gt=0, le=1)
    target_soc: float | None = Field(None, ge=0, le=1)    # null: the vehicle's soc_max

    @field_validator("terminals", mode="before")
    @classmethod
    def _terminals(cls, v):
        if isinstance(v, list):
            return [str(t) for t in v]
        return v


class ChargingCfg(_Model):
    """The charging plan the battery's balance runs under (docs/whole_day.md)."""

    depot: DepotChargingCfg = Field(default_factory=DepotChargingCfg)
    opportunity: OpportunityChargingCfg = Field(default_factory=OpportunityChargingCfg)


class DbCfg(_Model):
    dsn: str | None = None


#: how far (km) a radiation location may lie from the city model (without one: from the
#: routes) before a run is refused (``radiation_far``): CAMS series are point values of a
#: 3-5 km satellite pixel; 50 km keeps a city's own weather, not another region's
RADIATION_MAX_KM = 50.0

#: the plausibility findings a run or an ingest refuses, each in one line naming it, unless
#: it is listed in ``checks.accept`` (or given with ``--accept``): docs/checks.md
PLAUSIBILITY_FINDINGS = {
    "radiation_far": f"a radiation location more than {RADIATION_MAX_KM:g} km from the city "
                     "model (without one: from the routes)",
    "radiation_components": "GHI below DHI, or above the clear-sky GHI by more than the margin, "
                            "for more than a few minutes (columns swapped or in other units)",
    "crs_area": "the city model or the feed's stops outside the area of use of the CRS they "
                "are put in",
}


class ChecksCfg(_Model):
    """Plausibility checks of the inputs before a run (docs/checks.md)."""

    # findings accepted for the rare real case: each refusal names its finding
    accept: list[Literal["radiation_far", "radiation_components", "crs_area"]] = Field(
        default_factory=list)


class Config(_Model):
    scenario: str = "default"
    data_dir: Path = Path("data/default")
    out_dir: Path = Path("out")
    demo: DemoSpec = Field(default_factory=DemoSpec)
    inputs: Inputs = Field(default_factory=Inputs)
    city: CityCfg = Field(default_factory=CityCfg)
    trajectory: TrajectoryCfg = Field(default_factory=TrajectoryCfg)
    irradiance: IrradianceCfg = Field(default_factory=IrradianceCfg)
    pv: PVCfg = Field(default_factory=PVCfg)
    vehicle: VehicleCfg = Field(default_factory=VehicleCfg)
    economics: EconomicsCfg = Field(default_factory=EconomicsCfg)
    climate: ClimateCfg = Field(default_factory=ClimateCfg)
    run: RunCfg = Field(default_factory=RunCfg)
    radiation: RadiationCfg = Field(default_factory=RadiationCfg)
    fleet: FleetCfg = Field(default_factory=FleetCfg)
    charging: ChargingCfg = Field(default_factory=ChargingCfg)
    checks: ChecksCfg = Field(default_factory=ChecksCfg)
    dask: DaskCfg = Field(default_factory=DaskCfg)
    db: DbCfg = Field(default_factory=DbCfg)

    # where the values came from, for error messages and the run manifest
    _source: str = "<defaults>"

    @field_validator("scenario")
    @classmethod
    def _scenario_name(cls, v: str) -> str:
        # the run folder is <out_dir>/<scenario>/<year>: a name, never a path out of out_dir
        if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*", v or "") or v in (".", ".."):
            raise ValueError(f"{v!r} is not a scenario name (letters, digits, '.', '_', '-'; no "
                             "'/' or '..'): it names the run folder <out_dir>/<scenario>/<year>")
        return v

    def pv_system(self) -> PVSystem:
        """The PV system chosen by ``pv.system``, with ``pv.overrides`` applied."""
        catalog = _read_yaml(CONF_DIR / "pv_systems.yaml")
        return _catalog_entry(catalog, self.pv.system, self.pv.overrides, PVSystem,
                              CONF_DIR / "pv_systems.yaml", "pv", self._source)

    def vehicle_params(self):
        """The vehicle chosen by ``vehicle.model`` (a :class:`vipvflow.models.vehicle.VehicleParams`)."""
        from .models.vehicle import VehicleParams

        catalog = _read_yaml(CONF_DIR / "vehicles.yaml")
        return _catalog_entry(catalog, self.vehicle.model, self.vehicle.overrides,
                              VehicleParams, CONF_DIR / "vehicles.yaml", "vehicle", self._source)

    def monthly_temperature_c(self) -> list[float]:
        """The run's monthly mean air temperature (deg C, Jan..Dec): the scenario's
        ``climate.monthly_mean_temperature_c``, or the shipped climatology at the place of
        the ingested radiation (:func:`vipvflow.inputs.climate.monthly_air_temperature`);
        :meth:`temperature_source` says which."""
        return list(self._temperature()[0])

    def temperature_source(self) -> str:
        """Where :meth:`monthly_temperature_c` comes from (for summary.json and the manifest)."""
        return self._temperature()[1]

    def _temperature(self) -> tuple[tuple, str]:
        given = self.climate.monthly_mean_temperature_c
        if given is not None:
            return tuple(given), f"{Path(self._source).name}: climate.monthly_mean_temperature_c"
        key = str(Path(self.data_dir).resolve())
        hit = _TEMPERATURES.get(key)
        if hit is None:
            from .inputs.climate import SOURCE, monthly_air_temperature
            from .store import DataDir

            path = DataDir(self.data_dir).radiation.table
            try:
                import pyarrow.parquet as pq

                first = pq.ParquetFile(path).read_row_group(0, columns=["lat", "lon"])
                lat, lon = float(first["lat"][0].as_py()), float(first["lon"][0].as_py())
            except (OSError, KeyError, IndexError) as exc:
                raise ConfigError(f"{self._source}: climate.monthly_mean_temperature_c is not set "
                                  f"and the city's place is unknown ({path}: {exc}); ingest the "
                                  "radiation first or give the 12 monthly values") from None
            hit = (tuple(monthly_air_temperature(lat, lon)),
                   f"{SOURCE} ({lat:.3f} N, {lon:.3f} E)")
            _TEMPERATURES[key] = hit
        return hit

    def digest(self) -> str:
        """A stable hash of what decides a run's results (for run manifests and resuming):
        the validated configuration without where it runs (``dask``), where it writes
        (``out_dir``), where it mirrors (``db``) and which plausibility findings it accepts
        (``checks``: they change no number)."""
        text = json.dumps(self.model_dump(mode="json", exclude={"dask", "db", "out_dir", "checks"}),
                          sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


#: the climatology's monthly temperatures per data dir (the radiation's place)
_TEMPERATURES: dict[str, tuple[tuple, str]] = {}

#: PyYAML's safe loader, libyaml's when PyYAML has it (the same documents, ~10x faster: the
#: catalogs are read each time a run asks for its vehicle or PV system)
_SAFE_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def _read_yaml(path: Path) -> dict:
    try:
        with open(path, encoding="utf-8") as fh:
            data = yaml.load(fh, Loader=_SAFE_LOADER)
    except FileNotFoundError:
        raise ConfigError(f"{path}: file not found") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" line {mark.line + 1}" if mark else ""
        raise ConfigError(f"{path}:{where}: not valid YAML: {getattr(exc, 'problem', exc)}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"{path}: top level must be a mapping of keys, got {type(data).__name__}")
    return data


def _merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict) and key != "overrides":
            out[key] = _merge(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


def _has_path(data: dict, loc: tuple) -> bool:
    node: Any = data
    for part in loc:
        if isinstance(node, dict) and part in node:
            node = node[part]
        elif isinstance(node, list) and isinstance(part, int) and part < len(node):
            node = node[part]
        else:
            return False
    return True


def _format_errors(exc: ValidationError, files: list[tuple[Path, dict]], prefix: str = "") -> str:
    lines = []
    for err in exc.errors():
        loc = tuple(err["loc"])
        key = prefix + ".".join(str(p) for p in loc)
        origin = next((str(f) for f, d in reversed(files) if _has_path(d, loc)), None)
        if origin is None:
            origin = str(files[-1][0])
        msg = err["msg"]
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
        lines.append(f"{origin}: key '{key}': {msg}")
    return "; ".join(lines)             # one line, however many keys are wrong


def _catalog_entry(catalog: dict, name: str, overrides: dict, model, path: Path, section: str,
                   source: str):
    """Catalog entry *name* of *path* with *overrides* (``<section>.overrides`` of the
    scenario file *source*) applied, validated; an error names the scenario file and its
    key (``pv.overrides.kwp``) when the value came from there, else the catalog's."""
    choice = "model" if section == "vehicle" else "system"
    if name not in catalog:
        known = ", ".join(sorted(catalog)) or "none"
        raise ConfigError(f"{source}: key '{section}.{choice}': '{name}' is not in the catalog "
                          f"{path} (known: {known})")
    data = _merge(catalog[name], overrides or {})
    data.setdefault("name", name)
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        files = [(path, catalog[name]), (Path(source), overrides or {})]
        lines = []
        for err in exc.errors():
            loc = tuple(err["loc"])
            mine = _has_path(overrides or {}, loc)
            key = f"{section}.overrides." if mine else f"{name}."
            msg = "unknown key" if err["type"] == "extra_forbidden" else err["msg"]
            lines.append(f"{files[1][0] if mine else path}: key '{key}{'.'.join(map(str, loc))}': {msg}")
        raise ConfigError("; ".join(lines)) from None


def load_config(path: str | Path | None = None, overrides: dict | None = None) -> Config:
    """Load the shipped ``default.yaml``, apply the scenario at *path* and *overrides*, validate.

    Parameters
    ----------
    path : str or Path, optional
        Scenario YAML, or a shipped scenario's name (:func:`scenario_path`). ``None`` gives
        the defaults alone.
    overrides : dict, optional
        Nested mapping applied last (command-line options).

    Raises
    ------
    ConfigError
        With ``file: key 'a.b': reason`` for every invalid key or value.
    """
    default_path = CONF_DIR / "default.yaml"
    files = [(default_path, _read_yaml(default_path))]
    if path is not None:
        path = scenario_path(path)
        if not path.is_file():
            raise ConfigError(f"{path}: file not found (shipped scenarios by name: "
                              f"{', '.join(shipped_scenarios())})")
        files.append((path, _read_yaml(path)))
    if overrides:
        files.append((Path("<command line>"), overrides))
    merged: dict = {}
    for _, data in files:
        merged = _merge(merged, data)
    try:
        cfg = Config.model_validate(merged)
    except ValidationError as exc:
        raise ConfigError(_format_errors(exc, files)) from None
    cfg._source = str(path) if path else str(default_path)
    # validate catalog choices now, so a bad name fails at load time
    cfg.pv_system()
    try:
        cfg.vehicle_params()
    except ImportError:
        pass
    return cfg
