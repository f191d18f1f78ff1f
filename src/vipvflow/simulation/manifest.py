"""A run directory's identity (configuration and input digests), its claim and its manifest.

A run folder holds the partitions of one configuration computed from one set of input
files: ``parts/config_digest.txt`` and ``parts/inputs.json`` (the SHA-256 of every input
file's content) are written when a run claims the folder, before any partition.  A run whose
configuration or inputs differ from the folder's is refused naming both digests, or with
``--force`` replaces the folder as a whole; a resume therefore never mixes partitions of two
configurations or of two versions of an input (docs/run_folders.md).
"""
from __future__ import annotations

import hashlib
import json
import shutil
import time
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError
from ..store import RunDir, aside_folders, set_aside, write_json, write_text
from .rundir import data_dir_record, masked_config


@dataclass(frozen=True)
class InputDigests:
    """The content digests (SHA-256, hex) of a run's input files, by configuration key
    (``inputs.citygml``, ``inputs.gtfs``, ``inputs.cams``) and path."""

    files: dict

    @property
    def by_path(self) -> dict:
        """``{path: sha256}`` of every input (the manifest's ``inputs_sha256``)."""
        return {path: sha for role in self.files.values() for path, sha in role.items()}

    @property
    def digest(self) -> str:
        """The inputs' digest: of their contents only, whatever their names or order."""
        return _digest_of(self.by_path.values())

    def record(self) -> dict:
        return {"digest": self.digest, "files": self.files}

    def changed(self, record: dict) -> list[str]:
        """What differs from a recorded set (:meth:`record`, or a manifest's ``{path:
        sha256}``): ``inputs.cams (cams.csv)`` per input whose content changed."""
        files = record.get("files")
        if isinstance(files, dict):
            out = []
            for role, now in self.files.items():
                was = files.get(role) or {}
                if sorted(was.values()) != sorted(now.values()):
                    names = [Path(p).name for p, sha in now.items() if sha not in was.values()]
                    out.append(f"{role} ({', '.join(names)})" if names else role)
            return out
        shas = set(record.values())
        return [Path(p).name for p, sha in self.by_path.items() if sha not in shas]


def _digest_of(shas) -> str:
    return hashlib.sha256("\n".join(sorted(shas)).encode()).hexdigest()[:16]


def digest_in(run_dir: Path) -> str | None:
    """The configuration digest of the run (finished or partial) in *run_dir*, if any."""
    run = RunDir(run_dir)
    if run.config_stamp.is_file():
        return run.config_stamp.read_text().strip()
    try:
        return json.loads(run.manifest.read_text()).get("config_digest")
    except (OSError, ValueError, AttributeError):
        return None


def inputs_in(run_dir: Path) -> dict | None:
    """What *run_dir* records of its inputs: ``parts/inputs.json`` (``digest``, ``files``),
    else for a run finished before those stamps its manifest's ``inputs_sha256`` as
    ``{"digest", "files_by_path"}``; None when the folder records none."""
    run = RunDir(run_dir)
    try:
        record = json.loads(run.inputs_stamp.read_text())
        if isinstance(record, dict) and "digest" in record:
            return record
    except (OSError, ValueError):
        pass
    try:
        by_path = json.loads(run.manifest.read_text()).get("inputs_sha256")
    except (OSError, ValueError, AttributeError):
        return None
    if isinstance(by_path, dict) and by_path:
        return {"digest": _digest_of(by_path.values()), "files_by_path": by_path}
    return None


def _is_run_folder(run_dir: Path) -> bool:
    run = RunDir(run_dir)
    return run.config_stamp.is_file() or run.manifest.is_file()


def check_run_dir(run_dir: Path, digest: str, inputs: InputDigests | None = None,
                  force: bool = False) -> bool:
    """Whether *run_dir* may take a run of configuration *digest* and *inputs*; True when it
    holds another run, which *force* replaces. Writes nothing.

    Raises
    ------
    InputError
        In one line: *run_dir* is a file, or a folder that is neither empty nor a run folder
        (no ``parts/config_digest.txt`` or ``manifest.json``); it holds a run of another
        configuration or of other input files (both digests named) and *force* is not given;
        or *force* would delete files that no run wrote.
    """
    run_dir = Path(run_dir)
    if not run_dir.exists():
        return False
    if not run_dir.is_dir():
        raise InputError(f"{run_dir}: the run folder is a file; choose another scenario or out_dir")
    entries = sorted(e.name for e in run_dir.iterdir())
    if not entries:
        return False
    if not _is_run_folder(run_dir):
        raise InputError(f"{run_dir}: not a run folder (it holds {_names(entries)}, but no "
                         "parts/config_digest.txt or manifest.json): a run writes only into an "
                         "empty folder or its own; choose another scenario or out_dir")
    reasons = []
    other = digest_in(run_dir)
    if other is not None and other != digest:
        reasons.append(f"of another configuration (digest {other}; this configuration's digest "
                       f"is {digest})")
    if inputs is not None:
        record = inputs_in(run_dir)
        if record is None:
            reasons.append(f"whose input files are unknown (made before their digests were "
                           f"recorded; these inputs' digest is {inputs.digest})")
        elif record["digest"] != inputs.digest:
            changed = inputs.changed(record.get("files_by_path") or record)
            reasons.append(f"of other input files (inputs digest {record['digest']}; these "
                           f"inputs' digest is {inputs.digest}"
                           + (f": {', '.join(changed)} changed" if changed else "") + ")")
    if not reasons:
        return False
    if not force:
        raise InputError(f"{run_dir}: holds a run {' and '.join(reasons)}: pass --force to "
                         "replace it, or set another scenario or out_dir")
    foreign = [e for e in entries if not RunDir.written_by_run(e)]
    if foreign:
        raise InputError(f"{run_dir}: holds files no run wrote ({_names(foreign)}): --force "
                         "replaces only a run's own files; move them out of the folder first")
    return True


def _names(entries: list[str], n: int = 4) -> str:
    return ", ".join(entries[:n]) + (f" and {len(entries) - n} more" if len(entries) > n else "")


def claim_run_dir(run_dir: Path, digest: str, force: bool = False, say=print,
                  inputs: InputDigests | None = None) -> None:
    """Make *run_dir* the folder of a run of configuration *digest* and *inputs*.

    A folder holding a run (finished or partial) of another configuration or other inputs
    is refused with both digests named (:func:`check_run_dir`); with *force* it is replaced
    as a whole: renamed aside in one step, then deleted, so that an interruption leaves
    either the old run or the new one, never parts of both. Folders left aside by an
    interrupted replacement are removed.
    """
    for stale in aside_folders(run_dir):
        shutil.rmtree(stale, ignore_errors=True)
    if check_run_dir(run_dir, digest, inputs, force):
        other = digest_in(run_dir) or "unknown"
        aside = set_aside(run_dir, other)
        say(f"replacing the run of configuration {other} in {run_dir}")
        shutil.rmtree(aside, ignore_errors=True)
    run = RunDir(run_dir)
    if not run.config_stamp.is_file():
        write_text(digest, run.config_stamp)
    if inputs is not None and not run.inputs_stamp.is_file():
        write_json(inputs.record(), run.inputs_stamp)


def write_manifest(cfg, year, run_dir, inputs: InputDigests, timings, results, builds) -> None:
    from importlib import metadata

    versions = {}
    for name in ["vipvflow", "numpy", "pandas", "dask", "distributed", "geopandas", "pyarrow",
                 "embreex", "trimesh", "pvlib", "gtfs-kit", "lxml"]:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    stage, counts = {}, {}
    for res in results:
        for k, v in res.get("timings", {}).items():
            stage[k] = stage.get(k, 0.0) + v
        for k, v in res.get("counts", {}).items():
            counts[k] = counts.get(k, 0) + int(v)
    manifest = {
        "scenario": cfg.scenario, "year": year, "config_digest": cfg.digest(),
        "config": masked_config(cfg.model_dump(mode="json")),
        "paths": {"data_dir": data_dir_record(cfg.data_dir, run_dir)},
        "inputs_sha256": inputs.by_path, "inputs_digest": inputs.digest, "versions": versions,
        "timings_s": {k: round(v, 3) for k, v in timings.items()},
        "partition_timings_s": {k: round(v, 3) for k, v in stage.items()},
        "partitions_computed": sum(1 for r in results if "intervals" not in r),
        # layovers and parked time (the standing tasks; their worker time is standing_s above)
        "standing_partitions_computed": sum(1 for r in results if "intervals" in r),
        "standing_intervals": int(sum(r.get("intervals", 0) for r in results)),
        "passes_computed": int(sum(r["passes"] for r in results)),
        # sun rays in front of the roof in the driving partitions: cast with Embree, or told
        # clear by the sun masks among the buildings (irradiance.sun_masks); the tiles whose
        # geometry this run made or read back (its seconds: geometry_s above)
        "partition_counts": counts,
        "bvh_builds_per_worker": builds,
        "created_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
    }
    write_json(manifest, RunDir(run_dir).manifest)
