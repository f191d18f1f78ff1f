"""Trajectories: GTFS trips as passes over 10 m hyper-segments of their shapes.

- :func:`ingest_gtfs` reads a feed (gtfs-kit) and writes ``gtfs/segments.parquet``,
  ``trips.parquet``, ``patterns.parquet``, ``pattern_stops.parquet``, the calendars and
  ``feed.json`` under a data directory.
- :func:`service_dates`, :func:`iter_passes`, :func:`passes_for_trip` turn them into the
  passes of a (tile, month) partition or of one trip, in UTC; :class:`PassChunks` gives a
  partition's passes a few service days at a time.
"""
from .feed import Feed, read_feed, time_to_seconds
from .ingest import ingest_gtfs
from .schedule import (PassChunks, iter_passes, passes_for_trip, reach_time, service_dates,
                       service_day_origin_utc)

__all__ = ["ingest_gtfs", "read_feed", "Feed", "time_to_seconds", "service_dates",
           "service_day_origin_utc", "iter_passes", "PassChunks", "passes_for_trip", "reach_time"]
