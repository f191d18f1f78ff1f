"""The task graph of a run submitted to the cluster, with its progress view."""
from __future__ import annotations

import time

from ..progress import MapProgress
from .partition import RunContext, geometry_task, run_partition
from .standing import run_standing


def map_tasks(client, ctx: RunContext, todo: list[tuple[str, str]], standing: list[str] = (),
         every_s: float = 1.0) -> list[dict]:
    from distributed import as_completed

    geometry = {}
    futures = []
    for tile in sorted({t for t, _ in todo}):
        geometry[tile] = client.submit(geometry_task, ctx, tile, key=f"geometry-{tile}")
    for tile, month in todo:
        futures.append(client.submit(run_partition, ctx, tile, month, geometry[tile],
                                     key=f"irradiance-{tile}-{month}"))
    for tile in standing:
        futures.append(client.submit(run_standing, ctx, tile, key=f"standing-{tile}"))
    view = MapProgress(len(futures))
    results = []
    done, last = [], time.perf_counter()
    # the finished partitions' summaries are fetched together about once a second: one
    # fetch per partition kept the scheduler's event loop (in this process) busy ~15 % of a
    # core, taken from the workers when they fill the machine
    for n_done, fut in enumerate(as_completed(futures), start=1):
        done.append(fut)
        if time.perf_counter() - last >= every_s or n_done == len(futures):
            for res in client.gather(done):
                results.append(res)
                view.add(res)
            for f in done:
                f.release()
            done, last = [], time.perf_counter()
    view.close()
    return results
