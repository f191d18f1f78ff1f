"""Inputs of a run: generate the demo when asked, ingest each input once (cached by fingerprint)."""
from __future__ import annotations

import json
import logging
from pathlib import Path

from ..config import Config
from ..errors import InputError
from ..files import sha256

log = logging.getLogger(__name__)


def _fingerprint(paths: list[Path], extra: dict) -> dict:
    return {"files": [{"path": str(p), "size": p.stat().st_size, "mtime_ns": p.stat().st_mtime_ns}
                      for p in paths], "config": extra}


def _cached(stamp: Path, fp: dict) -> bool:
    try:
        return json.loads(stamp.read_text()) == fp
    except (OSError, ValueError):
        return False


def _stamp(stamp: Path, fp: dict) -> None:
    stamp.parent.mkdir(parents=True, exist_ok=True)
    stamp.write_text(json.dumps(fp, indent=1))


def ensure_demo(cfg: Config, year: int, say=print) -> None:
    """Generate the demo inputs when the scenario is the demo and they are missing or are
    for another year."""
    if not cfg.demo.enabled:
        return
    from ..demo import generate_demo

    inputs = [*cfg.inputs.citygml, cfg.inputs.gtfs, *cfg.inputs.cams]
    folder = Path(cfg.inputs.gtfs).parent
    marker = folder / "demo_generated.json"
    want = {"year": year, "seed": cfg.demo.seed, "size": cfg.demo.size}
    if all(Path(p).exists() for p in inputs) and _cached(marker, want):
        return
    say(f"generating the demo scenario ({cfg.demo.size}, seed {cfg.demo.seed}) for {year} in {folder}")
    generate_demo(folder, year=year, seed=cfg.demo.seed, size=cfg.demo.size)
    _stamp(marker, want)


def ensure_ingested(cfg: Config, say=print) -> dict:
    """Ingest city, GTFS and CAMS inputs into ``cfg.data_dir`` unless already done for the same
    files and settings. Returns the inputs' checksums for the run manifest."""
    from ..city import ingest_city
    from ..radiation import ingest_cams
    from ..trajectory import ingest_gtfs

    data_dir = Path(cfg.data_dir)
    city_files = [Path(p) for p in cfg.inputs.citygml]
    cams_files = [Path(p) for p in cfg.inputs.cams]
    gtfs = Path(cfg.inputs.gtfs) if cfg.inputs.gtfs else None
    missing = [str(p) for p in [*city_files, *cams_files, *([gtfs] if gtfs else [])] if not p.exists()]
    if missing:
        raise InputError("input file(s) not found: " + ", ".join(missing)
                         + " (see data_manifest.yaml and `make data`)")
    if gtfs is None or not cams_files:
        raise InputError(f"{cfg._source}: inputs.gtfs and inputs.cams are required")

    city_fp = _fingerprint(city_files, {"city": cfg.city.model_dump(mode="json"),
                                        "crs": cfg.inputs.citygml_crs})
    stamp = data_dir / "city" / ".inputs.json"
    if city_files and not _cached(stamp, city_fp):
        say(f"ingesting {len(city_files)} CityGML file(s)")
        report = ingest_city(city_files, data_dir, cfg.city, crs=cfg.inputs.citygml_crs)
        say("  " + report.summary())
        _stamp(stamp, city_fp)
    gtfs_fp = _fingerprint([gtfs], {"trajectory": cfg.trajectory.model_dump(mode="json"), "city": city_fp,
                                    "timezone": cfg.inputs.gtfs_timezone,
                                    "route_types": cfg.run.route_types})
    stamp = data_dir / "gtfs" / ".inputs.json"
    if not _cached(stamp, gtfs_fp):
        from ..commands.ingest_gtfs import findings

        say(f"ingesting GTFS feed {gtfs}")
        report = ingest_gtfs(gtfs, data_dir, cfg.trajectory, crs=cfg.inputs.citygml_crs,
                             timezone=cfg.inputs.gtfs_timezone, route_types=cfg.run.route_types)
        c = report["counts"]
        say(f"  shapes {c['shapes']} ({c['shapes_built_from_stops']} built from stops), segments "
            f"{c['segments']}, tiles {c['tiles']}, trips {c['trips']}, patterns {c['patterns']}, "
            f"routes {c['routes']}; timezone {report['timezone']}, CRS {report['crs']}")
        for line in findings(report):
            say("  " + line)
        _stamp(stamp, gtfs_fp)
    cams_fp = _fingerprint(cams_files, {})
    stamp = data_dir / "radiation" / ".inputs.json"
    if not _cached(stamp, cams_fp):
        say(f"ingesting {len(cams_files)} CAMS file(s)")
        report = ingest_cams(cams_files, data_dir)
        say("  " + _summary(report))
        _stamp(stamp, cams_fp)
    return {str(p): sha256(p) for p in [*city_files, gtfs, *cams_files]}


def _summary(report) -> str:
    if hasattr(report, "summary"):
        return report.summary()
    if isinstance(report, dict):
        keys = [k for k, v in report.items() if isinstance(v, (int, float, str))][:8]
        return ", ".join(f"{k}={report[k]}" for k in keys)
    return str(report)
