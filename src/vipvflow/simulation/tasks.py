"""The task graph of a run submitted to the cluster, with its progress view."""
from __future__ import annotations

import time

from ..progress import MapProgress
from .partition import RunContext, tile_task
from .standing import run_standing


def map_tasks(client, ctx: RunContext, todo: list[tuple[str, str]], standing: list[str] = (),
         every_s: float = 1.0) -> list[dict]:
    """Compute the partitions *todo* ((tile, month) pairs) and the standing points of the
    tiles *standing* on the cluster; the partitions' summaries (:func:`run_partition`), in
    the order they were done.  One ``irradiance-<TILE>`` task per tile computes its months
    (:func:`tile_task`), in the order of *todo* (the run's: largest tiles first); the
    standing tasks (a few large ones) go first; the progress view counts partitions."""
    from distributed import as_completed

    months: dict[str, list[str]] = {}
    for tile, month in todo:
        months.setdefault(tile, []).append(month)
    futures = [client.submit(run_standing, ctx, tile, key=f"standing-{tile}") for tile in standing]
    futures += [client.submit(tile_task, ctx, tile, ms, key=f"irradiance-{tile}")
                for tile, ms in months.items()]
    view = MapProgress(len(todo) + len(standing))
    results = []
    done, last = [], time.perf_counter()
    # the finished partitions' summaries are fetched together about once a second: one
    # fetch per partition kept the scheduler's event loop (in this process) busy ~15 % of a
    # core, taken from the workers when they fill the machine
    for n_done, fut in enumerate(as_completed(futures), start=1):
        done.append(fut)
        if time.perf_counter() - last >= every_s or n_done == len(futures):
            for out in client.gather(done):
                for res in out if isinstance(out, list) else [out]:
                    results.append(res)
                    view.add(res)
            for f in done:
                f.release()
            done, last = [], time.perf_counter()
    view.close()
    return results
