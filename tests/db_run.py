"""Helpers of ``tests/test_db.py``: a run under another name, and checksums of a run's files."""
from __future__ import annotations

import hashlib
import json
import shutil
from pathlib import Path


def clone_run(src: Path, dest: Path, scenario: str) -> Path:
    """A copy of a run directory under another scenario name (so another run id)."""
    shutil.copytree(src, dest, ignore=shutil.ignore_patterns("parts", "figures", "*.html"))
    for name in ("manifest.json", "summary.json"):
        d = json.loads((dest / name).read_text())
        d["scenario"] = scenario
        (dest / name).write_text(json.dumps(d, indent=2))
    return dest


def checksums(run_dir: Path) -> dict:
    """(size, mtime, SHA-256) of every file below *run_dir*."""
    out = {}
    for p in sorted(run_dir.rglob("*")):
        if p.is_file():
            st = p.stat()
            out[str(p.relative_to(run_dir))] = (st.st_size, st.st_mtime_ns,
                                                hashlib.sha256(p.read_bytes()).hexdigest())
    return out
