"""The simulation: the fleet-year as a Dask task graph over (tile, month) partitions.

``run_simulation(cfg, year, scheduler=None, n_workers=None)`` prepares the inputs
(demo generation, ingest with caching), builds and runs the graph
(an ``irradiance-<TILE>`` task per tile: its geometry, then its months), reduces the partitions
into per-trip, per-segment-month, per-route-month, per-block and fleet-year results and
writes them with a manifest and an HTML report into ``<out_dir>/<scenario>/<year>/``.
"""
from .run import run_simulation  # noqa: F401
