"""Small file helpers shared by the stages."""
from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path


def sha256(path: str | Path) -> str:
    """SHA-256 hex digest of a file, read in 1 MiB blocks."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def remove_stale(final: str | Path) -> list[Path]:
    """Clean up beside folder *final* after killed ingests; return the paths removed.

    ``.<name>-ingest-<pid>`` (an unfinished new version) goes when its process is gone;
    ``.<name>-old-<pid>`` (the previous version, when the kill came between the two renames of
    :func:`swap_dir`) is put back if *final* is missing, else removed.
    """
    final = Path(final)
    removed = []
    for p in sorted(final.parent.glob(f".{final.name}-old-*")):
        if _stale(p):
            if not final.exists():
                p.rename(final)
                continue
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    for p in sorted(final.parent.glob(f".{final.name}-ingest-*")):
        if p.is_dir() and _stale(p):
            shutil.rmtree(p, ignore_errors=True)
            removed.append(p)
    return removed


def staging_dir(final: str | Path) -> Path:
    """An empty folder beside *final* (``.<name>-ingest-<pid>``) to write a new version of
    *final* into before :func:`swap_dir`; what killed ingests left there is cleaned up first
    (:func:`remove_stale`)."""
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    remove_stale(final)
    stage = final.with_name(f".{final.name}-ingest-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    return stage


def swap_dir(new: Path, final: Path) -> None:
    """Replace folder *final* by *new* as a whole (two renames; a reader sees the old or the
    new version, never a mix of files; :func:`remove_stale` repairs a kill between them)."""
    old = final.with_name(f".{final.name}-old-{os.getpid()}")
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    new.rename(final)
    shutil.rmtree(old, ignore_errors=True)


def _stale(path: Path) -> bool:
    """A ``...-<pid>`` folder whose process is gone."""
    pid = path.name.rsplit("-", 1)[-1]
    return pid.isdigit() and not pid_alive(int(pid))


def pid_alive(pid: int) -> bool:
    """Whether a process of this id runs (it may be another user's)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
