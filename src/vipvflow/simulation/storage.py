"""Atomic writes and partition paths of a run directory."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pandas as pd


def write_parquet(df: pd.DataFrame, path: Path) -> Path:
    """Write *df* (DataFrame or GeoDataFrame) to *path* atomically (temporary name, rename)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    df.to_parquet(tmp, index=False)
    os.replace(tmp, path)
    return path


def write_json(obj, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(obj, indent=2, default=str))
    os.replace(tmp, path)
    return path


def partition_path(run_dir: Path, kind: str, tile: str, month: str) -> Path:
    """``parts/<kind>/tile=<TILE>/month=<YYYY-MM>.parquet``: findable with ls."""
    return run_dir / "parts" / kind / f"tile={tile}" / f"month={month}.parquet"


def geometry_path(run_dir: Path, tile: str) -> Path:
    return run_dir / "parts" / "geometry" / f"tile={tile}.parquet"
