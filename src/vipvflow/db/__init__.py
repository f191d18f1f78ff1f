"""The PostGIS / Citus mirror of a run's results, and a local server to mirror into.

``mirror_run(dsn, run_dir)`` copies the outputs of ``out/<scenario>/<year>/`` into tables of
schema ``vipvflow`` keyed by run id (see ``docs/database.md``); :mod:`vipvflow.db.server`
starts and stops a local PostgreSQL + PostGIS server or Citus cluster (``make db``), and
:mod:`vipvflow.db.citus` finds Citus or builds it from source (``make citus``).
"""
from .mirror import DatabaseError, MirrorError, describe_dsn, mirror_run, run_id_of
from .schema import SCHEMA, citus_statements, ddl

__all__ = ["mirror_run", "DatabaseError", "MirrorError", "describe_dsn", "run_id_of", "SCHEMA",
           "citus_statements", "ddl"]
