"""``vipvflow ingest city|gtfs|cams``: turn raw inputs into the stage files under a data dir.

The three subcommands live in ``ingest_city``, ``ingest_gtfs`` and ``ingest_cams``; each
defines ``register(subparsers)``.
"""
from __future__ import annotations

from . import register_all

PARTS = ["ingest_city", "ingest_gtfs", "ingest_cams"]


def register(sub):
    p = sub.add_parser("ingest", help="ingest CityGML, GTFS or CAMS files into a data dir")
    inner = p.add_subparsers(dest="what", metavar="WHAT")
    register_all(inner, PARTS)
    p.set_defaults(func=lambda args: p.print_help())
