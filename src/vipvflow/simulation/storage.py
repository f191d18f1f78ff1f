"""Atomic writes and partition paths of a run directory."""
from __future__ import annotations

import json
import os
from contextlib import contextmanager
from pathlib import Path

import pandas as pd


def _plain_table(df: pd.DataFrame):
    """*df* as a pyarrow Table built column by column from numpy, when every column is a
    number, bool, datetime64 or string (the partition and geometry tables); ``None``
    otherwise (GeoDataFrames, categoricals, ...), for pandas to convert."""
    import pyarrow as pa

    if hasattr(df, "geometry") or not df.columns.is_unique:
        return None
    arrays = []
    for name in df.columns:
        col = df[name]
        kind = col.dtype.kind
        if kind in "biuf" or (kind == "M" and getattr(col.dtype, "tz", None) is None):
            arrays.append(pa.array(col.to_numpy()))
        elif pd.api.types.is_string_dtype(col.dtype) and not isinstance(col.dtype, pd.CategoricalDtype):
            try:        # object columns may hold anything: only real strings take this path
                arr = pa.array(col.to_numpy(dtype=object), from_pandas=True)
            except (pa.ArrowInvalid, pa.ArrowTypeError):
                return None
            if not (pa.types.is_string(arr.type) or pa.types.is_large_string(arr.type)
                    or (pa.types.is_null(arr.type) and col.dtype != object)):
                return None
            arrays.append(arr.cast(pa.string()))
        else:
            return None
    return pa.Table.from_arrays(arrays, names=[str(c) for c in df.columns])


@contextmanager
def _atomic(path: Path):
    """The temporary name to write *path* under, renamed to *path* when the block ends; on
    failure the temporary file is removed and an OSError names *path* (a full disk's
    ``ENOSPC`` from a write names no file)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException as exc:
        tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.errno and not exc.filename:
            raise OSError(exc.errno, os.strerror(exc.errno), str(path)) from exc
        raise


def write_parquet(df: pd.DataFrame, path: Path, compact: bool = False) -> Path:
    """Write *df* (DataFrame or GeoDataFrame) to *path* atomically (temporary name, rename).

    Plain tables (numbers, bools, dates, strings) go straight to pyarrow: pandas' own
    conversion costs more than the write for the run's wide, small tables.  A file named as
    one of the run's outputs (``trip_energy.parquet``, ... :data:`dictionary.OUTPUTS`) is
    written as the data dictionary describes it: ``month`` as a date, every documented
    column with its unit and meaning in the field metadata.  *compact* (partition files):
    zstd, dictionaries for the non-float columns only, floats byte-stream split."""
    import pyarrow.parquet as pq

    from .dictionary import OUTPUTS, annotate

    output = path.stem if path.suffix == ".parquet" and path.stem in OUTPUTS else None
    with _atomic(path) as tmp:
        table = _plain_table(df)
        if table is None and output is not None:
            table = _arrow_table(df)
        if table is None:
            df.to_parquet(tmp, index=False)
        elif compact:
            pq.write_table(table, tmp, **_compact_options(table))
        else:
            pq.write_table(annotate(table, output) if output else table, tmp)
    return path


def _compact_options(table) -> dict:
    """Parquet settings of the partition files: floats (most of their bytes) byte-stream
    split before zstd, dictionaries for the rest only (ids, dates)."""
    import pyarrow as pa

    floats = [f.name for f in table.schema if pa.types.is_floating(f.type)]
    return {"compression": "zstd", "use_byte_stream_split": floats,
            "use_dictionary": [f.name for f in table.schema if f.name not in floats]}


def _arrow_table(df: pd.DataFrame):
    """*df* as pyarrow converts it for ``to_parquet`` (GeoDataFrames with their GeoParquet
    metadata)."""
    import pyarrow as pa

    if hasattr(df, "geometry"):
        # geopandas' own conversion of to_parquet (WKB geometry, "geo" schema metadata)
        from geopandas.io.arrow import _geopandas_to_arrow

        return _geopandas_to_arrow(df, index=False)
    return pa.Table.from_pandas(df, preserve_index=False)


def write_json(obj, path: Path) -> Path:
    with _atomic(path) as tmp:
        tmp.write_text(json.dumps(obj, indent=2, default=str))
    return path


def partition_path(run_dir: Path, kind: str, tile: str, month: str) -> Path:
    """``parts/<kind>/tile=<TILE>/month=<YYYY-MM>.parquet``: findable with ls."""
    return run_dir / "parts" / kind / f"tile={tile}" / f"month={month}.parquet"


def geometry_path(run_dir: Path, tile: str) -> Path:
    return run_dir / "parts" / "geometry" / f"tile={tile}.parquet"
