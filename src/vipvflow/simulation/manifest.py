"""A run directory's configuration stamp and its manifest (inputs, versions, timings)."""
from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

from ..errors import InputError
from ..store import RunDir, aside_folders, set_aside, write_json, write_text
from .rundir import data_dir_record, masked_config


def digest_in(run_dir: Path) -> str | None:
    """The configuration digest of the run (finished or partial) in *run_dir*, if any."""
    run = RunDir(run_dir)
    if run.config_stamp.is_file():
        return run.config_stamp.read_text().strip()
    try:
        return json.loads(run.manifest.read_text()).get("config_digest")
    except (OSError, ValueError, AttributeError):
        return None


def claim_run_dir(run_dir: Path, digest: str, force: bool = False, say=print) -> None:
    """Make *run_dir* the folder of a run of configuration *digest*.

    A folder holding a run (finished or partial) of another configuration is refused with
    both digests named; with *force* it is replaced as a whole: renamed aside in one step,
    then deleted, so that an interruption leaves either the old run or the new one, never
    parts of both. Folders left aside by an interrupted replacement are removed.
    """
    for stale in aside_folders(run_dir):
        shutil.rmtree(stale, ignore_errors=True)
    other = digest_in(run_dir)
    if other is not None and other != digest:
        if not force:
            raise InputError(
                f"{run_dir}: holds a run of another configuration (digest {other}; this "
                f"configuration's digest is {digest}): pass --force to replace it, or set "
                "another scenario or out_dir")
        aside = set_aside(run_dir, other)
        say(f"replacing the run of configuration {other} in {run_dir}")
        shutil.rmtree(aside, ignore_errors=True)
    stamp = RunDir(run_dir).config_stamp
    if not stamp.is_file():
        write_text(digest, stamp)


def write_manifest(cfg, year, run_dir, checksums, timings, results, builds) -> None:
    from importlib import metadata

    versions = {}
    for name in ["vipvflow", "numpy", "pandas", "dask", "distributed", "geopandas", "pyarrow",
                 "embreex", "trimesh", "pvlib", "gtfs-kit", "lxml"]:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    stage = {}
    for res in results:
        for k, v in res.get("timings", {}).items():
            stage[k] = stage.get(k, 0.0) + v
    manifest = {
        "scenario": cfg.scenario, "year": year, "config_digest": cfg.digest(),
        "config": masked_config(cfg.model_dump(mode="json")),
        "paths": {"data_dir": data_dir_record(cfg.data_dir, run_dir)},
        "inputs_sha256": checksums, "versions": versions,
        "timings_s": {k: round(v, 3) for k, v in timings.items()},
        "partition_timings_s": {k: round(v, 3) for k, v in stage.items()},
        "partitions_computed": sum(1 for r in results if "intervals" not in r),
        # layovers and parked time (the standing tasks; their worker time is standing_s above)
        "standing_partitions_computed": sum(1 for r in results if "intervals" in r),
        "standing_intervals": int(sum(r.get("intervals", 0) for r in results)),
        "passes_computed": int(sum(r["passes"] for r in results)),
        "bvh_builds_per_worker": builds,
        "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    write_json(manifest, RunDir(run_dir).manifest)
