"""The network a run covers: its trips, shapes and tiles after ``run.routes``."""
from __future__ import annotations

import pandas as pd

from ..config import Config
from ..errors import InputError
from ..store import DataDir


def selected_network(cfg: Config) -> tuple[pd.DataFrame, tuple | None, list[str]]:
    """The trips (``trip_id, route_id, route_short_name, shape_id``), shapes (``None``: all)
    and tiles that
    the run covers, after ``run.routes``; needs the ingested GTFS in ``cfg.data_dir``.

    The tiles come largest first: by their segments' passes in the feed (each segment
    counted once per trip of its shape), then by name.  A run computes them in that order,
    so the cluster's last tasks are small ones (a tile's months are one task)."""
    gtfs = DataDir(cfg.data_dir).gtfs
    trips = pd.read_parquet(gtfs.trips, columns=["trip_id", "route_id", "route_short_name", "shape_id"])
    routes = cfg.run.routes
    shapes = None
    if routes is not None:
        unknown = sorted(set(routes) - set(trips["route_id"].astype(str)))
        if unknown:
            raise InputError(f"{cfg._source}: run.routes: route_id(s) not in the feed: {', '.join(unknown)}")
        trips = trips[trips["route_id"].astype(str).isin(routes)]
        shapes = tuple(sorted(trips["shape_id"].unique()))
    seg = pd.read_parquet(gtfs.segments, columns=["tile", "shape_id"])
    if shapes is not None:
        seg = seg[seg["shape_id"].isin(shapes)]
    passes = seg["shape_id"].map(trips.groupby("shape_id").size()).fillna(0).to_numpy()
    work = pd.Series(passes, index=seg["tile"].to_numpy()).groupby(level=0).sum()
    return trips, shapes, sorted(work.index, key=lambda tile: (-work[tile], tile))
