"""Set-up of the worker processes of a run's LocalCluster (a Dask worker preload).

The workers share the terminal's process group with the ``vipvflow`` command: Ctrl-C reaches
them too. They ignore it (the command closes the cluster), instead of each printing a
``KeyboardInterrupt`` traceback. A task's failure reaches the command, which prints it as one
line (a :class:`vipvflow.errors.VipvError`) or with its traceback (a bug): the worker's own
"Compute Failed ... Traceback" log of the same failure is left out unless the command runs
with ``-v`` (Dask setting ``vipvflow.worker-failure-log``), and so is a heartbeat's
traceback when the command closes the cluster of a run that stopped.

Each worker loads the fused per-pass kernel (:func:`vipvflow.models.passkernel.warm`: compiled once
and cached on disk, loaded here) before its first task, so no task pays for the compilation.
What is loaded then (modules, compiled kernels: ~280,000 objects) lives as long as the worker
and is moved out of the cyclic garbage collector's reach (``gc.freeze``): its full passes walked
all of it, ~0.12 s each, three times in a worker's line-year, and several times more when the
worker process exits (0.4-0.7 s that the run's shutdown waited for); at the worker's close
everything is frozen again for that reason.
"""
from __future__ import annotations

import gc
import logging
import signal


#: worker log lines the command speaks for itself: a task's failure (reported by the command
#: as one line), and a heartbeat cut by the cluster's shutdown when a run stops (an error,
#: Ctrl-C; the command has said why: a scheduler really lost is reported by the command too)
_SAID_BY_THE_COMMAND = ("Compute Failed", "Failed to communicate with scheduler during heartbeat")


def _not_said_by_the_command(record: logging.LogRecord) -> bool:
    return not (isinstance(record.msg, str) and record.msg.startswith(_SAID_BY_THE_COMMAND))


def dask_setup(worker) -> None:
    import dask

    import multiprocessing

    # only a worker process of its own (started by a nanny): a worker inside the command's or a
    # test's process must leave that process's Ctrl-C alone (its children would inherit it)
    if multiprocessing.parent_process() is not None:
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        except ValueError:      # not the process's main thread
            pass
    if not dask.config.get("vipvflow.worker-failure-log", False):
        logging.getLogger("distributed.worker").addFilter(_not_said_by_the_command)
    from ..models import passkernel

    passkernel.warm()
    gc.freeze()


def dask_teardown(worker) -> None:
    # the process exits next: its collections at exit then skip the heap that is dropped anyway
    gc.freeze()
