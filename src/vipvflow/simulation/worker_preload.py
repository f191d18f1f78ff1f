"""What the worker processes of a run's LocalCluster are forked with (Linux).

A LocalCluster started by a run makes its workers with multiprocessing's ``forkserver``
(:func:`vipvflow.simulation.cluster.make_client`): one server process imports this module
once, and every worker is then a fork of it, with Dask, numpy, pandas, pyarrow, trimesh, the
simulation's modules and the fused per-pass kernel (loaded from numba's on-disk cache) already
in memory.  A worker started with ``spawn`` loaded all of that itself: ~3 s of a core per
worker, paid again by every worker of every run and by the second worker on the same two
cores as the first.  The server lives as long as the process that started it, so a second
run of the same process (a notebook, the web app, the benchmarks, the tests) starts its
workers in well under a second.

matplotlib is not loaded here: only the reduce's figures need it, and the workers load it
then (:class:`vipvflow.outputs.report.Figures`, while the client joins the fleet's tables).
Loaded here it was ~24 MB of the server's heap that every worker's RSS counted through the
whole map (the forked pages are the server's until written), ~70 MB of the sum of a 2-worker
run's processes.

Importing this module never fails: what cannot be loaded here is loaded by the worker
itself (multiprocessing would otherwise leave out only an ``ImportError``)."""
from __future__ import annotations


def _preload() -> None:
    import importlib

    for name in ("distributed", "numpy", "pandas", "pyarrow.parquet", "lz4", "trimesh",
                 "vipvflow.simulation.worker_setup", "vipvflow.simulation.partition",
                 "vipvflow.simulation.standing", "vipvflow.simulation.reduce",
                 "vipvflow.models.irradiance", "vipvflow.models.shading",
                 "vipvflow.models.view_factors", "vipvflow.models.sun_sky",
                 "vipvflow.inputs.gtfs", "vipvflow.outputs.report"):
        try:
            importlib.import_module(name)
        except Exception:       # noqa: BLE001 - the worker loads it (and reports) itself
            pass
    try:
        from .partition import arrow_on_the_heap

        arrow_on_the_heap()
    except Exception:       # noqa: BLE001 - the worker's tasks set it themselves
        pass
    try:
        from ..models import passkernel

        passkernel.warm()
    except Exception:       # noqa: BLE001 - as above
        pass


_preload()
