"""vipvflow: VIPV yield of electric bus fleets in 3D cities.

The Python API (docs/api.md)::

    import vipvflow

    cfg = vipvflow.load_config("demo")            # a shipped scenario, or your YAML
    run = vipvflow.simulate(cfg, year=2024)       # the fleet-year -> vipvflow.Run
    run = vipvflow.open_run("out/demo/2024")      # a finished run: typed tables, summary
    model = vipvflow.TripModel(run.path)          # one trip for any PV, date and departure

The names load on first use, so ``import vipvflow`` stays light (the command line imports it).
"""
import os

__version__ = "0.1.0"

# Arrow tables that crossed processes (the workers' trip sums) may hold buffers off 8-byte
# alignment after unpickling: Acero (group_by, dataset scans) printed a warning to stderr for
# each; it copies such buffers instead, unless the user chose otherwise.  Arrow reads this
# once, at a process's first Acero plan, so it is set when vipvflow is imported.
os.environ.setdefault("ACERO_ALIGNMENT_HANDLING", "reallocate")


#: the public API: name -> module that defines it (imported on first use)
_API = {"load_config": ".config", "simulate": ".api", "open_run": ".api", "Run": ".api",
        "TripModel": ".app.model", "PVChoice": ".app.model"}
__all__ = ["__version__", *_API]


def __getattr__(name: str):
    if name in _API:
        import importlib

        value = getattr(importlib.import_module(_API[name], __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'vipvflow' has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_API))
