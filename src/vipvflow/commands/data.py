"""``vipvflow data fetch``: download the real datasets listed in ``data_manifest.yaml``."""
from __future__ import annotations

import os
import urllib.request
from pathlib import Path

import yaml

from ..errors import InputError
from ..files import sha256


def register(sub):
    p = sub.add_parser("data", help="fetch the real datasets of data_manifest.yaml (needs a network)")
    inner = p.add_subparsers(dest="action", metavar="ACTION")
    f = inner.add_parser("fetch", help="download what has a direct URL, explain the rest")
    f.add_argument("--manifest", default="data_manifest.yaml")
    f.add_argument("--year", type=int, default=2024, help="year of CAMS series to request")
    f.add_argument("names", nargs="*", help="datasets to fetch (default: all)")
    f.set_defaults(func=fetch)
    p.set_defaults(func=lambda args: p.print_help())


def fetch(args) -> int:
    try:
        manifest = yaml.safe_load(Path(args.manifest).read_text())
    except FileNotFoundError:
        raise InputError(f"{args.manifest}: manifest not found") from None
    datasets = manifest.get("datasets", {})
    names = args.names or list(datasets)
    failed = 0
    for name in names:
        if name not in datasets:
            raise InputError(f"{args.manifest}: no dataset named {name!r} (known: {', '.join(datasets)})")
        entry = datasets[name]
        target = Path(entry.get("target", f"data/raw/{name}"))
        url = entry.get("download")
        if entry.get("kind") == "generated":
            print(f"{name}: generated locally: {entry['command']}")
        elif url == "pvlib.iotools.get_cams":
            email = os.environ.get("CAMS_EMAIL")
            if not email:
                print(f"{name}: set CAMS_EMAIL to your registered CAMS e-mail to fetch it ({entry['page']})")
                continue
            import pandas as pd
            import pvlib

            try:
                data, meta = pvlib.iotools.get_cams(
                    entry["latitude"], entry["longitude"], pd.Timestamp(f"{args.year}-01-01"),
                    pd.Timestamp(f"{args.year}-12-31"), email, identifier="cams_radiation",
                    altitude=entry.get("altitude"), time_step="1min", time_ref="UT",
                    map_variables=False)
            except Exception as exc:  # network or service error: one line
                print(f"{name}: download failed: {exc}")
                failed += 1
                continue
            print(f"{name}: {len(data)} rows fetched; save with the CAMS service's CSV output to {target}")
        elif url:
            target.parent.mkdir(parents=True, exist_ok=True)
            try:
                tmp = target.with_name(target.name + ".part")
                urllib.request.urlretrieve(url, tmp)
                tmp.replace(target)
            except OSError as exc:
                print(f"{name}: download failed from {url}: {exc}")
                failed += 1
                continue
            want = entry.get("sha256")
            if want and sha256(target) != want:
                print(f"{name}: checksum mismatch for {target}")
                failed += 1
                continue
            print(f"{name}: {target} ({target.stat().st_size:,} B)")
        else:
            print(f"{name}: download by hand from {entry.get('page')} into {target} "
                  f"({entry.get('licence')})")
    return 1 if failed else 0
