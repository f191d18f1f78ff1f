"""The Dask client of a run: a LocalCluster sized to the machine, or a running scheduler."""
from __future__ import annotations

import logging
import os
import time
import warnings

from ..config import Config
from ..errors import InputError

log = logging.getLogger(__name__)


#: Dask settings of a LocalCluster started by a run, whose processes share the machine's
#: cores with the simulation: event-loop ticks every 1 s instead of 20 ms, system monitors
#: every 2 s instead of 0.5 s, memory monitors every 0.5 s instead of 0.1 s (the scheduler's
#: and nannies' event loop took ~15 % of a core at the defaults during the line-year)
LOCAL_CLUSTER_DASK_CONFIG = {
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.worker.memory.monitor-interval": "500ms",
}


def make_client(cfg: Config, scheduler: str | None, n_workers: int | None):
    """A client of the given scheduler, or of a LocalCluster sized to the machine.

    The LocalCluster's workers run without Dask's statistical profiler unless
    ``dask.worker_profile`` is set: on a machine whose cores the workers fill, its 100 stack
    samples a second per worker come out of the simulation's time (the 2-worker line-year
    spent ~7 % of each worker's CPU on it).  On Linux the workers are forked from a
    preloaded server (:func:`_forkserver`)."""
    import dask
    from distributed import Client, LocalCluster

    scheduler = scheduler or cfg.dask.scheduler
    if not log.isEnabledFor(logging.INFO):
        for name in ("distributed", "distributed.scheduler", "distributed.nanny", "distributed.core",
                     "distributed.worker", "distributed.http.proxy"):
            logging.getLogger(name).setLevel(logging.WARNING)
    if scheduler:
        return _remote_client(Client, scheduler), None
    n, threads = local_cluster_size(cfg, n_workers)
    host = cfg.dask.host
    # the dashboard's port was free a moment ago (dashboard_address); a run starting at the
    # same time may take it first: Dask then serves on another port and warns, but the
    # command prints the dashboard's address itself
    warnings.filterwarnings("ignore", message=r"Port \d+ is already in use", category=UserWarning)
    settings = {**LOCAL_CLUSTER_DASK_CONFIG, "distributed.worker.profile.enabled": cfg.dask.worker_profile,
                # workers ignore Ctrl-C and leave a task's failure for this process to report
                "distributed.worker.preload": ["vipvflow.simulation.worker_setup"],
                "vipvflow.worker-failure-log": log.isEnabledFor(logging.INFO)}
    settings.update(_forkserver())
    with dask.config.set(settings):     # the nannies hand this configuration to their workers
        # the scheduler, the nannies, the workers and the dashboard listen on *host* only
        # (127.0.0.1 unless dask.host says otherwise): Dask's ":8787" was every interface
        cluster = LocalCluster(n_workers=n, threads_per_worker=threads,
                               processes=True, memory_limit=cfg.dask.memory_limit, host=host,
                               dashboard_address=dashboard_address(cfg.dask.dashboard_port, host),
                               silence_logs=logging.ERROR)
    return Client(cluster), cluster


def _refusal(address: str, what: str, exc: BaseException) -> InputError:
    reason = " ".join(str(exc).split())[:200] or type(exc).__name__
    return InputError(f"--scheduler {address} (or dask.scheduler): {what} ({reason}); start one "
                      "(dask scheduler) or leave it out for a LocalCluster on this machine")


def check_scheduler(address: str) -> None:
    """A scheduler address must be one Dask can read, and a TCP one must answer: else
    :class:`InputError` in one line, at once (before a run ingests anything; Dask itself
    retried a refused connection until its connect timeout, then raised a traceback)."""
    import socket

    import dask
    from distributed.comm.addressing import parse_address, parse_host_port
    from distributed.comm.registry import backends

    try:
        scheme, location = parse_address(address)
        if scheme not in backends:
            raise ValueError(f"unknown scheme {scheme!r}; Dask knows {', '.join(sorted(backends))}")
        if scheme == "tcp":
            host, port = parse_host_port(location)
            if not 0 < port < 65536:
                raise ValueError(f"port {port} out of range")
    except (ValueError, TypeError) as exc:
        raise _refusal(address, "not a scheduler address", exc) from None
    if scheme == "tcp":
        timeout = dask.config.get("distributed.comm.timeouts.connect")
        try:
            socket.create_connection((host.strip("[]"), port),
                                     timeout=dask.utils.parse_timedelta(timeout, "s")).close()
        except OSError as exc:
            raise _refusal(address, "no Dask scheduler answers there", exc) from None


def _remote_client(Client, address: str):
    """A client of the scheduler at *address* (:func:`check_scheduler` first), or
    :class:`InputError` in one line when it does not answer within Dask's connect timeout
    (``distributed.comm.timeouts.connect``)."""
    import dask

    check_scheduler(address)

    class _Quiet(Client):
        # a client whose connection failed is closed again when it is collected, and that
        # close times out: said as "Exception ignored in Client.__del__" with a traceback
        def __del__(self):
            try:
                super().__del__()
            except Exception:  # noqa: BLE001
                pass

    timeout = dask.config.get("distributed.comm.timeouts.connect")
    try:
        return _Quiet(address)
    except OSError as exc:                           # TimeoutError is an OSError
        raise _refusal(address, f"no Dask scheduler answered there within {timeout}", exc) from None
    except (ValueError, TypeError) as exc:
        raise _refusal(address, "not a scheduler address", exc) from None


def bound_dashboard(client, cluster) -> str:
    """The dashboard's address as it was bound: for a LocalCluster the address its HTTP
    server's socket listens on (``http://127.0.0.1:8787/status``), else the scheduler's own
    link."""
    link = client.dashboard_link
    server = getattr(getattr(cluster, "scheduler", None), "http_server", None)
    try:
        host, port = next(iter(server._sockets.values())).getsockname()[:2]
    except (AttributeError, StopIteration, OSError, TypeError, ValueError):
        return link
    return f"http://{'[' + host + ']' if ':' in host else host}:{port}/status"


#: the module the forkserver of a run's LocalCluster loads before it forks the workers
FORKSERVER_PRELOAD = "vipvflow.simulation.worker_preload"


def _forkserver() -> dict:
    """The Dask settings that make a LocalCluster's nannies fork their workers from a
    forkserver preloaded with :mod:`vipvflow.simulation.worker_preload` (on Linux; elsewhere
    none: the workers are spawned).  The server is started once per process, by the first
    worker; its preload is set here, after Dask's own (``distributed.utils.get_mp_context``,
    which would replace it), and does nothing when a server already runs.  Each worker still
    starts in the directory and with the ``sys.path`` of the process at its own start
    (multiprocessing hands them over with every fork request)."""
    import multiprocessing
    import sys

    if not sys.platform.startswith("linux") or "forkserver" not in multiprocessing.get_all_start_methods():
        return {}
    import dask
    from distributed.utils import get_mp_context

    settings = {"distributed.worker.multiprocessing-method": "forkserver"}
    with dask.config.set(settings):
        get_mp_context().set_forkserver_preload(["distributed", FORKSERVER_PRELOAD])
    return settings


def local_cluster_size(cfg: Config, n_workers: int | None = None) -> tuple[int, int]:
    """Workers and threads per worker of the LocalCluster a run starts: *n_workers*, else
    ``dask.n_workers``, else one per core; ``dask.threads_per_worker``, else 1."""
    if n_workers is not None and n_workers < 1:
        raise InputError(f"--workers {n_workers}: a LocalCluster needs at least one worker")
    return n_workers or cfg.dask.n_workers or os.cpu_count() or 1, cfg.dask.threads_per_worker or 1


def dashboard_address(port: int | None, host: str = "127.0.0.1") -> str:
    """``host:port`` when that port is free on *host*, else ``host:0`` (any free port)."""
    import socket

    if port is None:
        return f"{host}:0"
    with socket.socket() as s:
        try:
            s.bind((host, port))
        except OSError:
            return f"{host}:0"
    return f"{host}:{port}"


#: how long the workers of a run's LocalCluster may take to restart for its reduce (s)
RESTART_TIMEOUT_S = 120.0


def fresh_workers(client, say=print) -> float:
    """Restart the workers of a run's LocalCluster (forked again from its preloaded server,
    :func:`_forkserver`: ~1.5 s) and return the seconds it took; every result they hold is
    dropped.  The reduce then starts from what a new worker holds rather than from what the
    map's tasks left in each worker's heap, which the sums' reads add to (the heap's freed
    pieces are not handed back).  Only for a cluster the run started: an outside
    scheduler's workers may be another client's too.  When they do not all come back in
    :data:`RESTART_TIMEOUT_S`, a line says so and the reduce goes on with those there are
    (a LocalCluster's nannies start the others)."""
    t = time.perf_counter()
    # each nanny logs its worker's restart as a warning: asked for here, not news to the user
    nanny, quiet = logging.getLogger("distributed.nanny"), _NotRestarting()
    nanny.addFilter(quiet)
    try:
        client.restart(timeout=RESTART_TIMEOUT_S)
    except (TimeoutError, OSError) as exc:
        say(f"the workers were not all restarted ({exc or type(exc).__name__}): "
            f"the reduce goes on with those there are")
    finally:
        nanny.removeFilter(quiet)
    return time.perf_counter() - t


#: the workers a run's LocalCluster keeps for the reduce's tail, once the sums are gathered
TAIL_WORKERS = 1


def fewer_fresh_workers(client, cluster, say=print, keep: int = TAIL_WORKERS) -> float:
    """Close all but *keep* of the workers of a run's LocalCluster *cluster* (the last ones
    started), restart those left (:func:`fresh_workers`) and return the seconds it took.

    Once the sums are gathered, the workers only draw the report's figures and write
    ``city.glb`` and the GeoParquet datasets: each worker doing so loaded matplotlib and
    dask.dataframe and read the city's footprints and surfaces, so each worker
    beyond one added its ~150 MB to the line-year's peak (there, in the figures), and an
    idle one its ~300 MB beside the command's trips step (the network's).  The command's
    own process does not take them over: what it loads it keeps for its next run (a
    notebook, the benchmarks).  A worker that does not close in :data:`RESTART_TIMEOUT_S`
    is left to the cluster's shutdown."""
    t = time.perf_counter()
    if cluster is not None and len(cluster.worker_spec) > keep:
        cluster.scale(keep)
        deadline = time.monotonic() + RESTART_TIMEOUT_S
        while len(cluster.workers) > keep and time.monotonic() < deadline:
            time.sleep(0.02)
    fresh_workers(client, say)
    return time.perf_counter() - t


class _NotRestarting(logging.Filter):
    """Drops a nanny's "Restarting worker" record (:func:`fresh_workers`)."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("Restarting worker")


def close_client(client, cluster) -> None:
    client.close()
    if cluster is not None:
        cluster.close()
