"""The mirror's tables, in schema ``vipvflow``, and the SQL that creates and distributes them.

Every table is keyed by ``run_id`` (``<scenario>/<year>/<config_digest>``), so runs of several
scenarios, years and cities live side by side. Each table mirrors one file of the run
directory; its *core* columns (below) are created up front and are what the documented queries
use. Any further column a file carries (a new geometry factor, an economics figure) is added on
load with the type its Parquet column has, so the mirror never drops data silently.

With the Citus extension the segment-level tables are distributed by ``tile`` (colocated:
a segment and its months live on the same worker, as the simulation's partitions do), the
trips and the bus-days by ``block_id`` (colocated: a bus's trips and its days on the same
worker; a trip crosses many tiles, and there are many more blocks than routes); the small
tables (runs, progress, fleet and route months, the hourly pattern, the summary) are
reference tables (a copy on every node, cheap to join). Without Citus the same tables are
plain PostGIS tables.
"""
from __future__ import annotations

from dataclasses import dataclass, field

SCHEMA = "vipvflow"

#: arrow type for a PostgreSQL column type (the loader casts file columns to it)
ARROW_OF_SQL = {
    "text": "string", "bigint": "int64", "integer": "int32", "smallint": "int16",
    "double precision": "float64", "real": "float32", "boolean": "bool_", "date": "date32",
    "timestamptz": "timestamp_utc", "jsonb": "string",
}

_PV = ["pv_kwh", "pv_kwh_clear", "pv_kwh_unshaded", "pv_kwh_clear_unshaded",
       "pv_kwh_direct", "pv_kwh_diffuse", "pv_kwh_reflected"]
_H = ["h_direct", "h_diffuse", "h_reflected", "h_total", "h_total_unshaded",
      "h_direct_clear", "h_diffuse_clear", "h_reflected_clear", "h_total_clear",
      "h_total_clear_unshaded", "h_ghi", "h_ghi_clear", "h_direct_no_trees", "h_diffuse_no_trees"]
_F = "double precision"


def _cols(names, sql_type):
    return [(n, sql_type) for n in names]


@dataclass(frozen=True)
class Table:
    """One mirrored table.

    name : table name in schema ``vipvflow``
    source : file of the run directory it mirrors (None: built from the JSON files)
    key : primary key after ``run_id`` (must hold *distribute_by* under Citus)
    columns : core columns after ``run_id``, as (name, SQL type)
    partition_by : column whose values are the load partitions (one transaction each);
        None loads the table as one partition ``all``
    distribute_by : Citus distribution column; None makes a reference table
    colocate_with : Citus table to colocate with
    drop : file columns not mirrored (``segment_month``'s copy of the segment geometry)
    """

    name: str
    source: str | None
    key: tuple[str, ...]
    columns: list[tuple[str, str]]
    partition_by: str | None = None
    distribute_by: str | None = None
    colocate_with: str | None = None
    drop: tuple[str, ...] = ()
    geometry: bool = False
    extra_indexes: tuple[tuple[str, ...], ...] = field(default=())

    @property
    def qualified(self) -> str:
        return f"{SCHEMA}.{self.name}"

    def sql_type(self, column: str) -> str | None:
        return dict(self.columns).get(column)


RUNS = Table(
    "runs", None, (), [
        ("scenario", "text"), ("year", "integer"), ("config_digest", "text"),
        ("crs_epsg", "integer"), ("status", "text"), ("mirrored_at", "timestamptz"),
        ("row_counts", "jsonb"), ("manifest", "jsonb"), ("config", "jsonb"), ("summary", "jsonb"),
    ])

PROGRESS = Table(
    "mirror_progress", None, ("table_name", "part"), [
        ("table_name", "text"), ("part", "text"), ("rows", "bigint"),
        ("source_sha256", "text"), ("finished_at", "timestamptz"),
    ])

SEGMENTS = Table(
    "segments", "segments.parquet", ("tile", "segment_id"), [
        ("tile", "text"), ("segment_id", "bigint"), ("shape_id", "text"), ("seg_index", "integer"),
        *_cols(["x", "y", "z", "x_end", "y_end", "z_end", "ground_z", "heading_deg", "gradient",
                "length_m", "cum_dist_m"], _F),
        ("geom", "geometry(LineStringZ)"),
    ], partition_by="tile", distribute_by="tile", geometry=True,
    extra_indexes=(("run_id", "shape_id", "seg_index"),))

SEGMENT_MONTH = Table(
    "segment_month", "segment_month.parquet", ("tile", "segment_id", "month"), [
        ("tile", "text"), ("segment_id", "bigint"), ("month", "date"), ("shape_id", "text"),
        ("route_short_name", "text"), ("direction_id", "integer"), ("n_passes", "bigint"),
        *_cols(_PV, _F), *_cols(_H, _F), ("seconds", _F),
        ("shading_loss", _F), ("shading_loss_clear", _F),
    ], partition_by="month", distribute_by="tile", colocate_with="segments",
    drop=("geometry",), extra_indexes=(("run_id", "month"), ("run_id", "route_short_name", "month")))

TRIP_ENERGY = Table(
    "trip_energy", "trip_energy.parquet", ("block_id", "trip_id", "service_date"), [
        ("route_id", "text"), ("trip_id", "text"), ("service_date", "date"), ("month", "date"),
        ("route_short_name", "text"), ("direction_id", "integer"), ("shape_id", "text"),
        ("service_id", "text"), ("block_id", "text"), ("pattern_id", "bigint"), ("start_s", _F),
        ("seconds", _F), *_cols(_PV, _F),
        *_cols(["consumption_kwh", "traction_kwh", "recuperated_kwh", "aux_kwh", "coverage"], _F),
    ], partition_by="month", distribute_by="block_id",
    extra_indexes=(("run_id", "month"), ("run_id", "route_id", "month"),
                   ("run_id", "block_id", "service_date")))

ROUTE_MONTH = Table(
    "route_month", "route_month.parquet", ("route_id", "direction_id", "month"), [
        ("route_id", "text"), ("direction_id", "integer"), ("month", "date"),
        ("route_short_name", "text"), ("trips", "bigint"), ("seconds", _F), *_cols(_PV, _F),
        ("consumption_kwh", _F), ("coverage", _F), ("shading_loss", _F),
    ], partition_by="month")

BLOCK_DAY = Table(
    "block_day", "block_day.parquet", ("block_id", "service_date"), [
        ("block_id", "text"), ("service_date", "date"), ("trips", "bigint"), ("pv_kwh", _F),
        ("pv_kwh_clear", _F), ("consumption_kwh", _F), ("first_departure_s", _F),
        # instants: UTC timestamps in the file (vipvflow.simulation.dictionary.INSTANT)
        *_cols(["window_start_utc", "window_end_utc", "first_departure_utc", "last_arrival_utc",
                "infeasible_at_utc"], "timestamptz"),
    ], distribute_by="block_id", colocate_with="trip_energy")

FLEET_MONTH = Table(
    "fleet_month", "monthly.parquet", ("month",), [
        ("month", "date"), ("trips", "bigint"),
        *_cols(["pv_kwh", "pv_kwh_clear", "pv_kwh_unshaded", "pv_kwh_clear_unshaded",
                "consumption_kwh", "avoided_charging_cycles", "kwh_per_kwp_driving",
                "kwh_per_kwp_driving_clearsky"], _F),
    ])

HOURLY_PATTERN = Table(
    "hourly_pattern", "hourly_pattern.parquet", ("month", "hour"), [
        ("month", "date"), ("hour", "smallint"), *_cols(_H, _F), ("seconds", _F),
        *_cols(["g_" + h[2:] for h in _H], _F),
    ])

FLEET_SUMMARY = Table(
    "fleet_summary", "summary.json", (), [
        ("scenario", "text"), ("year", "integer"), ("pv_mode", "text"), ("diffuse_model", "text"),
        ("routes", "bigint"), ("trips", "bigint"), ("buses", "bigint"), ("segments", "bigint"),
        ("passes", "bigint"), ("kwp_per_bus", _F),
        *_cols(["pv_kwh_driving", "pv_kwh_driving_clearsky", "pv_kwh_driving_unshaded",
                "pv_kwh_usable", "pv_kwh_curtailed", "kwh_per_kwp_usable", "kwh_per_kwp_driving",
                "kwh_per_kwp_driving_clearsky", "shading_loss_allsky",
                "shading_loss_clearsky", "unshaded_to_ghi_allsky", "unshaded_to_ghi_clearsky",
                "reflected_share", "coverage", "coverage_driving", "fleet_demand_in_service_mwh",
                "fleet_demand_driving_mwh", "grid_kwh_avoided", "avoided_charging_cycles_per_bus",
                "payback_years"], _F),
        ("block_days_infeasible", "bigint"),
    ])

#: tables filled from the run's files, in load order
DATA_TABLES = [SEGMENTS, SEGMENT_MONTH, TRIP_ENERGY, ROUTE_MONTH, BLOCK_DAY, FLEET_MONTH,
               HOURLY_PATTERN, FLEET_SUMMARY]
ALL_TABLES = [RUNS, PROGRESS] + DATA_TABLES


def _ident(name: str) -> str:
    return '"' + name.replace('"', '""') + '"'


def create_table_sql(t: Table) -> str:
    cols = ["run_id text NOT NULL"]
    for name, sql_type in t.columns:
        if name in ("run_id",):
            continue
        null = " NOT NULL" if name in t.key else ""
        cols.append(f"{_ident(name)} {sql_type}{null}")
    pk = ", ".join(_ident(c) for c in ("run_id",) + t.key)
    cols.append(f"PRIMARY KEY ({pk})")
    body = ",\n    ".join(cols)
    return f"CREATE TABLE IF NOT EXISTS {t.qualified} (\n    {body}\n)"


def schema_statements() -> list[str]:
    """DDL of the mirror's tables and indexes (idempotent)."""
    out = ["CREATE EXTENSION IF NOT EXISTS postgis", f"CREATE SCHEMA IF NOT EXISTS {SCHEMA}"]
    out += [create_table_sql(t) for t in ALL_TABLES]
    out.append(f"CREATE INDEX IF NOT EXISTS segments_geom_gist ON {SEGMENTS.qualified} "
               "USING gist (geom)")
    for t in ALL_TABLES:
        for i, cols in enumerate(t.extra_indexes):
            out.append(f"CREATE INDEX IF NOT EXISTS {t.name}_idx{i} ON {t.qualified} "
                       f"({', '.join(cols)})")
    return out


def view_statements() -> list[str]:
    """Views for web clients and maps (created after the tables are distributed)."""
    out = []
    out.append(f"""CREATE OR REPLACE VIEW {SCHEMA}.segments_4326 AS
SELECT s.run_id, s.tile, s.segment_id, s.shape_id, s.seg_index, s.length_m,
       ST_Transform(s.geom, 4326)::geometry(LineStringZ, 4326) AS geom
FROM {SEGMENTS.qualified} s""")
    out.append(f"""CREATE OR REPLACE VIEW {SCHEMA}.segment_month_geo AS
SELECT s.geom, m.*
FROM {SEGMENT_MONTH.qualified} m
JOIN {SEGMENTS.qualified} s USING (run_id, tile, segment_id)""")
    return out


def citus_statements(distributed: set[str] = frozenset()) -> list[str]:
    """Statements that make the mirror a Citus layout (run on the coordinator after
    :func:`schema_statements`); tables already in ``pg_dist_partition`` (*distributed*, as
    ``vipvflow.<name>``) are left alone, so the list is empty on a second run."""
    out = []
    for t in ALL_TABLES:
        if t.qualified in distributed:
            continue
        if t.distribute_by is None:
            out.append(f"SELECT create_reference_table('{t.qualified}')")
        else:
            assert t.distribute_by in t.key, f"{t.name}: distribution column not in the key"
            # a group's first table starts its own colocation group: Citus would otherwise
            # put every table distributed by a text column in one group (tile and route
            # shards side by side, as if their keys were related)
            colo = f"'{SCHEMA}.{t.colocate_with}'" if t.colocate_with else "'none'"
            out.append(f"SELECT create_distributed_table('{t.qualified}', "
                       f"'{t.distribute_by}', colocate_with => {colo})")
    return out


def ddl(citus: bool) -> list[str]:
    """Every statement that sets the mirror up, in order, for a server with or without Citus
    (a Citus server also needs ``CREATE EXTENSION citus`` before these)."""
    return schema_statements() + (citus_statements() if citus else []) + view_statements()

