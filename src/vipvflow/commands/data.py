"""``vipvflow data fetch``: download the real datasets listed in ``data_manifest.yaml``."""
from __future__ import annotations

import os
import re
import urllib.error
import urllib.parse
import urllib.request
from pathlib import Path

import yaml

from ..errors import InputError
from ..store import sha256

#: the CAMS radiation service (SoDa WPS); ``$VIPVFLOW_CAMS_URL`` replaces it (a mirror, tests)
CAMS_SERVICE = "https://api.soda-solar.com/service/wps"
CAMS_DOWNLOADS = ("cams", "pvlib.iotools.get_cams")


def register(sub):
    p = sub.add_parser("data", help="fetch the real datasets of data_manifest.yaml (needs a network)")
    inner = p.add_subparsers(dest="action", metavar="ACTION")
    f = inner.add_parser("fetch", help="download what has a direct URL, explain the rest")
    f.add_argument("--manifest", default="data_manifest.yaml",
                   help="the list of datasets (URL, licence, checksum; default: data_manifest.yaml "
                        "of the repository)")
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
        elif url in CAMS_DOWNLOADS:
            email = os.environ.get("CAMS_EMAIL")
            if not email:
                print(f"{name}: set CAMS_EMAIL to your registered CAMS e-mail to fetch it ({entry['page']})")
                continue
            try:
                rows = fetch_cams(entry, args.year, email, target)
            except InputError as exc:
                print(f"{name}: {exc}")
                failed += 1
                continue
            print(f"{name}: {target} ({rows:,} rows, {target.stat().st_size:,} B)")
        elif url:
            target.parent.mkdir(parents=True, exist_ok=True)
            tmp = target.with_name(target.name + ".part")
            try:
                urllib.request.urlretrieve(url, tmp)
            except OSError as exc:
                print(f"{name}: download failed from {url}: {exc}")
                tmp.unlink(missing_ok=True)
                failed += 1
                continue
            want = entry.get("sha256")
            if want and sha256(tmp) != want:
                print(f"{name}: checksum mismatch for {target}")
                tmp.unlink()
                failed += 1
                continue
            tmp.replace(target)
            print(f"{name}: {target} ({target.stat().st_size:,} B)")
        else:
            print(f"{name}: download by hand from {entry.get('page')} into {target} "
                  f"({entry.get('licence')})")
    return 1 if failed else 0


def cams_request_url(entry: dict, year: int, email: str, service: str | None = None) -> str:
    """The CAMS radiation service's request of a year of 1-minute all-sky and clear-sky
    irradiation (UT, verbose: with the clear-sky columns) at the entry's coordinates; the
    service answers with its CSV format (``application/csv``) or an XML exception."""
    service = service or os.environ.get("VIPVFLOW_CAMS_URL") or CAMS_SERVICE
    inputs = {"latitude": entry["latitude"], "longitude": entry["longitude"],
              "altitude": entry.get("altitude", -999) if entry.get("altitude") is not None else -999,
              "date_begin": f"{year}-01-01", "date_end": f"{year}-12-31", "time_ref": "UT",
              "summarization": "PT01M", "username": email.replace("@", "%2540"), "verbose": "true"}
    params = {"Service": "WPS", "Request": "Execute", "Identifier": "get_cams_radiation",
              "version": "1.0.0", "RawDataOutput": "irradiation"}
    data_inputs = ";".join(f"{k}={v}" for k, v in inputs.items())
    return f"{service}?DataInputs={data_inputs}&{urllib.parse.urlencode(params)}"


def fetch_cams(entry: dict, year: int, email: str, target: Path, timeout: float = 300) -> int:
    """Download a CAMS year into *target* as the service's CSV (what ``ingest cams`` reads);
    returns its number of data lines. One-line :class:`InputError` on a service or network error or an
    answer that is not a CAMS CSV, and then *target* is left as it was."""
    from ..inputs.cams import read_cams_file

    url = cams_request_url(entry, year, email)
    host = urllib.parse.urlsplit(url).netloc
    try:
        with urllib.request.urlopen(url, timeout=timeout) as res:
            kind = res.headers.get("Content-Type", "")
            body = res.read()
    except (urllib.error.URLError, OSError) as exc:
        raise InputError(f"download failed from {host}: {getattr(exc, 'reason', exc)}") from None
    if "xml" in kind or body.lstrip().startswith(b"<"):
        text = body.decode("utf-8", "replace")
        found = re.search(r"ExceptionText>(.*?)</", text, flags=re.S)
        reason = " ".join((found.group(1) if found else text[:200]).split())
        raise InputError(f"the CAMS service refused the request: {reason}")
    target.parent.mkdir(parents=True, exist_ok=True)
    part = target.with_name(target.name + ".part")
    part.write_bytes(body)
    try:
        read_cams_file(part)
    except InputError as exc:
        part.unlink()
        raise InputError(f"the CAMS service's answer is not a CAMS CSV ({exc})") from None
    part.replace(target)
    return sum(1 for line in body.decode("utf-8", "replace").splitlines()
               if line.strip() and not line.startswith("#"))
