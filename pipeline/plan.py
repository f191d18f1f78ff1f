"""Print the Dask task graph of a scenario-year before (or between) runs.

    .venv/bin/python pipeline/plan.py --config conf/demo.yaml --year 2024

Shows the ``irradiance-<TILE>`` tasks the simulation will submit (one per tile: its
geometry, then its (tile, month) partitions), how many partitions are already written (a
re-run resumes from them, and submits tasks for the missing months only), so a user can size
a cluster. The inputs must have been ingested once
(``vipvflow ingest ...`` or a first ``make simulate``). The graph itself is built by
:mod:`vipvflow.simulation.run`; this script only prints :func:`vipvflow.simulation.run.plan`.
"""
from __future__ import annotations

import argparse
import sys

from vipvflow.config import load_config
from vipvflow.errors import VipvError
from vipvflow.simulation.run import plan


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--config", default="conf/demo.yaml")
    ap.add_argument("--year", type=int, required=True)
    ap.add_argument("--tasks", action="store_true", help="list every task key")
    args = ap.parse_args(argv)
    try:
        table = plan(load_config(args.config), args.year)
    except (VipvError, FileNotFoundError) as exc:
        print(f"plan: {exc}", file=sys.stderr)
        return 2
    tiles = table["tile"].nunique()
    todo = table[~table["done"]]
    print(f"{tiles} tiles x {table['month'].nunique()} months = {len(table)} partitions "
          f"({int(table['done'].sum())} already written, {len(todo)} to compute "
          f"by {todo['key'].nunique()} irradiance tasks)")
    if args.tasks:
        for row in table.itertuples():
            print(f"{row.key:<30} {row.month}  {'done' if row.done else 'to do'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
