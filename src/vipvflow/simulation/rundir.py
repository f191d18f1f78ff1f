"""A run folder and what it needs later, found from any working directory.

A run's ``manifest.json`` records where its data dir was, both absolute and relative to the
run folder (``paths.data_dir``). :func:`open_run` is the one place that reads it back for the
commands working on a finished run (``app``, ``export``, ``mirror``, ``track``): the
run-relative path first (a run folder copied to another machine together with its data dir,
at the same place relative to it), then the absolute one (a run folder moved alone). A
manifest written before these paths were recorded holds only the scenario's ``data_dir``,
relative to the directory the run was made in: that directory is found again from the run
folder's own path (``<there>/<out_dir>/<scenario>/<year>``).

A DSN is never stored with its password: :func:`mask_dsn` masks it for manifests, logs and
the database's ``runs`` table.
"""
from __future__ import annotations

import copy
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError

MANIFEST = "manifest.json"
#: files of the data dir every reader of a run needs (its time zone)
NEEDS = ("gtfs/feed.json",)


@dataclass(frozen=True)
class RunFolder:
    """A finished run folder: its absolute path, its manifest, its data dir (absolute).

    ``manifest["config"]["data_dir"]`` is the resolved data dir too, for readers of the
    manifest."""

    path: Path
    manifest: dict
    data_dir: Path


def data_dir_record(data_dir: Path | str, run_dir: Path | str) -> dict:
    """What a manifest records of the data dir: ``absolute`` and ``run_relative`` paths."""
    absolute = Path(data_dir).resolve()
    return {"absolute": str(absolute),
            "run_relative": os.path.relpath(absolute, Path(run_dir).resolve())}


def _candidates(run_dir: Path, manifest: dict) -> list[Path]:
    """Places the run's data dir may be, most likely first."""
    record = (manifest.get("paths") or {}).get("data_dir") or {}
    out = [run_dir / record["run_relative"]] if record.get("run_relative") else []
    out += [Path(record["absolute"])] if record.get("absolute") else []
    if not out:
        out = _candidates_before_paths(run_dir, manifest.get("config") or {})
    seen, unique = set(), []
    for c in out:
        key = os.path.normpath(c)
        if key not in seen:
            seen.add(key)
            unique.append(Path(key))
    return unique


def _candidates_before_paths(run_dir: Path, config: dict) -> list[Path]:
    """A manifest without ``paths``: its ``data_dir`` was relative to the directory the run
    was made in, which is above ``<out_dir>/<scenario>/<year>`` when out_dir was relative."""
    recorded = Path(config.get("data_dir") or "")
    if recorded.is_absolute():
        return [recorded]
    if str(recorded) in ("", "."):
        return []
    out = []
    out_dir = Path(config.get("out_dir") or "out")
    depth = len(out_dir.parts) + 2
    if not out_dir.is_absolute() and len(run_dir.parts) > depth:
        out.append(run_dir.parents[depth - 1] / recorded)
    return out + [Path.cwd() / recorded]


def open_run(run_dir: Path | str, needs: tuple[str, ...] = NEEDS) -> RunFolder:
    """The finished run in *run_dir* with its data dir, wherever the command runs from.

    Parameters
    ----------
    run_dir : a run folder (``out/<scenario>/<year>``), relative to the working directory
        or absolute
    needs : files (relative to the data dir) the caller reads; the data dir is the first
        candidate holding the first of them, and all must be there

    Raises
    ------
    InputError
        One line naming what is missing: the folder, its manifest, or the data dir (with the
        places looked at and where a copy is expected).
    """
    run_dir = Path(os.path.abspath(Path(run_dir).expanduser()))
    if not run_dir.is_dir():
        raise InputError(f"run directory not found: {run_dir}")
    path = run_dir / MANIFEST
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError:
        raise InputError(f"{run_dir}: not a finished run (no {MANIFEST}); "
                         "run 'vipvflow simulate' first") from None
    except (OSError, ValueError) as exc:
        raise InputError(f"{path}: unreadable ({' '.join(str(exc).split())})") from None
    if not isinstance(manifest, dict):
        raise InputError(f"{path}: not a run manifest (a JSON object)")
    candidates = _candidates(run_dir, manifest)
    data_dir = None
    if needs:
        data_dir = next((c for c in candidates if (c / needs[0]).is_file()), None)
        if data_dir is None:
            record = (manifest.get("paths") or {}).get("data_dir") or {}
            where = (f"; copy it to {record['run_relative']} relative to the run folder"
                     if record.get("run_relative") else "")
            looked = ", ".join(str(c) for c in candidates) or "no data dir recorded"
            raise InputError(f"{run_dir}: the run's data dir is missing (no {needs[0]} in "
                             f"{looked}){where}")
        missing = [n for n in needs[1:] if not (data_dir / n).exists()]
        if missing:
            raise InputError(f"{data_dir}: the run's data dir lacks {', '.join(missing)}")
    elif candidates:
        data_dir = next((c for c in candidates if c.is_dir()), candidates[0])
    manifest = copy.deepcopy(manifest)
    if data_dir is not None:
        manifest.setdefault("config", {})["data_dir"] = str(data_dir)
    return RunFolder(run_dir, manifest, data_dir)


# ---------------------------------------------------------------- secrets

_URI_PASSWORD = re.compile(r"(?P<head>\b[a-z][a-z0-9+.-]*://[^:/?#@\s]*:)(?P<pw>[^@/?#\s]*)(?=@)", re.I)
_KV_PASSWORD = re.compile(r"(?P<head>\bpassword\s*=\s*)(?P<pw>'(?:[^'\\]|\\.)*'|[^\s]+)", re.I)
_QUERY_PASSWORD = re.compile(r"(?P<head>[?&]password=)(?P<pw>[^&#\s]*)", re.I)


def mask_dsn(dsn: str | None) -> str | None:
    """*dsn* with its password replaced by ``***`` (URI, ``?password=`` and ``key=value``
    forms): ``postgresql://u:***@h/db``."""
    if not dsn:
        return dsn
    patterns = (_URI_PASSWORD, _QUERY_PASSWORD) if "://" in dsn else (_KV_PASSWORD,)
    for pattern in patterns:
        dsn = pattern.sub(lambda m: m.group("head") + "***", dsn)
    return dsn


_LOOSE_USERINFO = re.compile(r"(?P<head>[^\s:/@\"']+:)(?P<pw>[^\s@/\"']*)(?=@)")
_LOOSE_KV = re.compile(r"(?P<head>\bpassword\s*=\s*)(?P<pw>'(?:[^'\\]|\\.)*'|[^\s\"&]+)", re.I)


def mask_text(text: str) -> str:
    """*text* (an error message that may quote a DSN, even a malformed one) with anything
    that looks like a password masked: ``user:***@``, ``password=***``."""
    for pattern in (_LOOSE_USERINFO, _LOOSE_KV):
        text = pattern.sub(lambda m: m.group("head") + "***", text)
    return text


def masked_config(config: dict) -> dict:
    """A copy of a configuration dump (``Config.model_dump``) with ``db.dsn`` masked."""
    config = copy.deepcopy(config)
    db = config.get("db")
    if isinstance(db, dict) and db.get("dsn"):
        db["dsn"] = mask_dsn(db["dsn"])
    return config
