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


def staging_dir(final: str | Path) -> Path:
    """An empty folder beside *final* (``.<name>-ingest-<pid>``) to write a new version of
    *final* into before :func:`swap_dir`; what killed processes left there is removed."""
    final = Path(final)
    final.parent.mkdir(parents=True, exist_ok=True)
    for old in final.parent.glob(f".{final.name}-ingest-*"):
        pid = old.name.rsplit("-", 1)[-1]
        if pid.isdigit() and not pid_alive(int(pid)):
            shutil.rmtree(old, ignore_errors=True)
    stage = final.with_name(f".{final.name}-ingest-{os.getpid()}")
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    return stage


def swap_dir(new: Path, final: Path) -> None:
    """Replace folder *final* by *new* as a whole (two renames; a reader sees the old or the
    new version, never a mix of files)."""
    old = final.with_name(f".{final.name}-old-{os.getpid()}")
    shutil.rmtree(old, ignore_errors=True)
    if final.exists():
        final.rename(old)
    new.rename(final)
    shutil.rmtree(old, ignore_errors=True)


def pid_alive(pid: int) -> bool:
    """Whether a process of this id runs (it may be another user's)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
