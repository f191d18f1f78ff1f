"""``vipvflow ingest cams FILE... --data-dir DIR``: CAMS CSV -> radiation/radiation.parquet."""
from __future__ import annotations

from pathlib import Path

from ..config import load_config
from ..errors import InputError
from . import accepted, add_accept, add_config, ingest_lock


def register(sub):
    p = sub.add_parser(
        "cams", help="read CAMS radiation / McClear CSV files onto a one-minute grid",
        description="Read CAMS Radiation Service or McClear CSV files (1 min, 15 min or 1 h; "
                    "UT or true solar time; several locations) and write "
                    "<data-dir>/radiation/radiation.parquet (mean W/m2 per minute, stamped at "
                    "the minute's centre) and radiation/ingest_report.json (flagged values).")
    p.add_argument("files", nargs="*", type=Path, help="CAMS CSV files (default: inputs.cams)")
    p.add_argument("--data-dir", type=Path, default=None,
                   help="scenario data dir (default: data_dir of the config)")
    add_config(p)
    add_accept(p)
    p.set_defaults(func=run)


def run(args):
    from ..inputs.cams import ingest_cams

    cfg = load_config(args.config)
    files = list(args.files) or list(cfg.inputs.cams)
    if not files:
        raise InputError("no CAMS file given (pass FILE... or set inputs.cams in --config)")
    with ingest_lock(args.data_dir or cfg.data_dir):
        report = ingest_cams(files, args.data_dir or cfg.data_dir, accept=accepted(cfg, args))
    for f in report["files"]:
        print(f"{f['file']}: {f['rows']} rows, step {f['time_step']}, {f['time_reference']}; "
              f"gaps {f['gaps']}, negative {f['negative']}, GHI>1.1 TOA {f['ghi_above_toa']}, "
              f"GHI>clear {f['ghi_above_clear']}, DNI>extraterrestrial {f['dni_above_extra']}")
    for line in findings(report):
        print(line)
    return 0


def findings(report: dict) -> list[str]:
    """Per location: span, flagged minutes and gaps, and rows missing against the header
    (also shown by ``simulate``)."""
    import pandas as pd

    def day(t):
        return pd.Timestamp(t, unit="s", tz="UTC").strftime("%Y-%m-%d %H:%M")

    lines = []
    for f in report["files"]:
        if f.get("encoding", "utf-8") not in ("utf-8", "utf-8-sig"):
            lines.append(f"{f['file']}: encoded in {f['encoding']}, not UTF-8: read as {f['encoding']}")
        short = f.get("rows_end_before_declared_s", 0)
        if short:
            lines.append(f"{f['file']}: rows end {f['end']}, {short / 86400:.1f} days before the "
                         f"declared end {f['declared_end']} (file truncated?)")
    for loc in report["locations"]:
        gaps = loc.get("gaps", [])
        lines.append(f"location {loc['lat']:.4f}, {loc['lon']:.4f}: {day(loc['start_utc'])} to "
                     f"{day(loc['end_utc'])} UTC, {loc['minutes']} minutes, "
                     f"{loc['flagged_minutes']} flagged and interpolated, {len(gaps)} gaps")
        longest = sorted(gaps, key=lambda g: -g["minutes"])[:3]
        for g in longest:
            lines.append(f"  gap {day(g['start_utc'])} to {day(g['end_utc'])} UTC "
                         f"({g['minutes']} min)")
    return lines
