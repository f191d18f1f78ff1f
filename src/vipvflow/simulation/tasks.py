"""The task graph of a run submitted to the cluster, with its progress view."""
from __future__ import annotations

import time
from collections import Counter

from ..progress import MapProgress
from .partition import RunContext, geometry_task, tile_task
from .standing import run_standing


#: a run's map has at least this many tasks per task slot of the cluster (worker threads)
#: where its tiles allow: fewer tiles split their months over several tasks
TASKS_PER_SLOT = 4


def tile_tasks(todo: list[tuple[str, str]], slots: int) -> list[tuple[str, list[str]]]:
    """The map's tasks as (tile, months) in the order of *todo*: each tile's months in one
    task, or, when the tiles are fewer than :data:`TASKS_PER_SLOT` x *slots* (a large
    cluster on a small city), in runs of consecutive months split evenly over as many tasks
    per tile as make up the difference."""
    months: dict[str, list[str]] = {}
    for tile, month in todo:
        months.setdefault(tile, []).append(month)
    pieces = -(-TASKS_PER_SLOT * max(1, slots) // max(1, len(months)))
    out = []
    for tile, ms in months.items():
        k = min(pieces, len(ms))
        size = -(-len(ms) // k)
        out += [(tile, ms[i:i + size]) for i in range(0, len(ms), size)]
    return out


def task_keys(tasks: list[tuple[str, list[str]]]) -> list[str]:
    """The Dask key of each (tile, months) task of :func:`tile_tasks`: ``irradiance-<TILE>``,
    or ``irradiance-<TILE>-<first month>`` for a tile split over several tasks."""
    split = _split_tiles(tasks)
    return [f"irradiance-{t}-{ms[0]}" if t in split else f"irradiance-{t}" for t, ms in tasks]


def _split_tiles(tasks: list[tuple[str, list[str]]]) -> set[str]:
    return {t for t, n in Counter(t for t, _ in tasks).items() if n > 1}


def submit_tiles(client, ctx: RunContext, todo: list[tuple[str, str]]) -> list:
    """Submit the partitions *todo* ((tile, month) pairs) to the cluster; their futures.  One
    ``irradiance-<TILE>`` task per tile computes its months (:func:`tile_task`), in the order
    of *todo* (the run's: largest tiles first); on a cluster with many task slots for the
    tiles, a tile's months are split over several ``irradiance-<TILE>-<first month>`` tasks
    after one ``geometry-<TILE>`` task (:func:`tile_tasks`).  *ctx*: the run's context, or
    its future (scattered once to the workers)."""
    slots = sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values())
    tasks = tile_tasks(todo, slots)
    geometry = {t: client.submit(geometry_task, ctx, t, key=f"geometry-{t}")
                for t in sorted(_split_tiles(tasks))}
    # a split tile's geometry seconds counted once, by its first task
    first = {}
    for i, (tile, _) in enumerate(tasks):
        first.setdefault(tile, i)
    return [client.submit(tile_task, ctx, tile, ms, geometry.get(tile), first[tile] == i, key=key)
            for i, ((tile, ms), key) in enumerate(zip(tasks, task_keys(tasks)))]


def submit_standing(client, ctx: RunContext, standing: list[str]) -> list:
    """Submit the standing points of the tiles *standing* (:func:`run_standing`); their
    futures.  A few large tasks, submitted once the timeline is written (after the tiles'
    tasks): they go ahead of the tiles' tasks still waiting for a slot.  *ctx*: as
    :func:`submit_tiles`'s."""
    return [client.submit(run_standing, ctx, tile, key=f"standing-{tile}", priority=1)
            for tile in standing]


def collect_map(client, futures: list, n_partitions: int, every_s: float = 1.0) -> list[dict]:
    """The partitions' summaries (:func:`run_partition`) of the map's *futures*
    (:func:`submit_tiles`, :func:`submit_standing`), in the order they were done; the
    progress view counts *n_partitions*."""
    view = MapProgress(n_partitions)
    results = []
    for out in finished_results(client, futures, every_s):
        for res in out if isinstance(out, list) else [out]:
            results.append(res)
            view.add(res)
    view.close()
    return results


def finished_results(client, futures: list, every_s: float = 1.0):
    """The results of *futures* (of *client*) as they finish, fetched together about every
    *every_s* seconds (one fetch per partition kept the scheduler's event loop, in this
    process, busy ~15 % of a core, taken from the workers when they fill the machine); each
    future is released once fetched.

    The futures are awaited on *client*'s own event loop: Dask's ``as_completed`` otherwise
    takes the loop of the process's default client, which is another one when the caller
    has a client of its own (a notebook's) and the run's client was started here; a result
    lost with its worker before it was fetched then failed the run with "bound to a
    different event loop" instead of being waited for while Dask computes it again."""
    from distributed import as_completed

    done, last = [], time.perf_counter()
    for n_done, fut in enumerate(as_completed(futures, loop=client.loop), start=1):
        done.append(fut)
        if time.perf_counter() - last >= every_s or n_done == len(futures):
            yield from client.gather(done)
            for f in done:
                f.release()
            done, last = [], time.perf_counter()
