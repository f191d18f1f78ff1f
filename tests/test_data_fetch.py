"""``vipvflow data fetch`` writes what it fetches: a CAMS year from a local stand-in of the
CAMS service (HTTP on 127.0.0.1, no network) and a direct download from a file:// URL."""
from __future__ import annotations

import hashlib
import threading
import urllib.parse
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import pytest
import yaml

from vipvflow.cli import main

CSV = "cams_radiation_1min_verbose.csv"
XML_ERROR = (b'<?xml version="1.0" encoding="utf-8"?><ows:ExceptionReport><ows:Exception>'
             b'<ows:ExceptionText>Unknown user: please register</ows:ExceptionText>'
             b'</ows:Exception></ows:ExceptionReport>')


@pytest.fixture
def cams_service(test_data):
    """A local HTTP server answering like the CAMS service: the sample CSV, or an XML
    exception for the user ``refused@example.org``; it records the requests."""
    body = (test_data / "cams" / CSV).read_bytes()
    seen: list[str] = []

    class Handler(BaseHTTPRequestHandler):
        def do_GET(self):  # noqa: N802 (http.server's name)
            seen.append(self.path)
            refused = "refused%2540example.org" in self.path
            payload, kind = (XML_ERROR, "application/xml") if refused else (body, "application/csv")
            self.send_response(200)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(payload)))
            self.end_headers()
            self.wfile.write(payload)

        def log_message(self, *args):
            pass

    server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield {"url": f"http://127.0.0.1:{server.server_address[1]}/service/wps", "seen": seen,
               "body": body}
    finally:
        server.shutdown()
        server.server_close()


def _manifest(tmp_path, datasets: dict) -> Path:
    path = tmp_path / "manifest.yaml"
    path.write_text(yaml.safe_dump({"datasets": datasets}, sort_keys=False))
    return path


def test_cams_fetch_writes_the_service_csv(cams_service, tmp_path, monkeypatch, capsys):
    target = tmp_path / "raw" / "cams.csv"
    manifest = _manifest(tmp_path, {"cams_here": {
        "kind": "cams", "download": "cams", "latitude": 49.611, "longitude": 6.13, "altitude": 300,
        "page": "https://example.org", "target": str(target)}})
    monkeypatch.setenv("VIPVFLOW_CAMS_URL", cams_service["url"])
    monkeypatch.setenv("CAMS_EMAIL", "someone@example.org")
    assert main(["data", "fetch", "--manifest", str(manifest), "--year", "2023"]) == 0
    assert target.read_bytes() == cams_service["body"]
    assert not list(target.parent.glob("*.part"))
    data_lines = [l for l in cams_service["body"].decode().splitlines() if l.strip() and not l.startswith("#")]
    assert capsys.readouterr().out.strip() == (
        f"cams_here: {target} ({len(data_lines):,} rows, {target.stat().st_size:,} B)")
    # the request: a year of 1-minute verbose all-sky radiation in UT at the entry's place
    (path,) = cams_service["seen"]
    query = urllib.parse.unquote(path.split("?", 1)[1])
    inputs = dict(kv.split("=", 1) for kv in query.split("&")[0].removeprefix("DataInputs=").split(";"))
    assert inputs == {"latitude": "49.611", "longitude": "6.13", "altitude": "300",
                      "date_begin": "2023-01-01", "date_end": "2023-12-31", "time_ref": "UT",
                      "summarization": "PT01M", "username": "someone%40example.org", "verbose": "true"}
    assert "Identifier=get_cams_radiation" in path and "RawDataOutput=irradiation" in path
    # and what it wrote is what the ingest reads
    from vipvflow.inputs.cams import read_cams_file

    frame, meta = read_cams_file(target)
    assert len(frame) > 0


def test_cams_service_refusal_is_one_line_and_writes_nothing(cams_service, tmp_path, monkeypatch, capsys):
    target = tmp_path / "cams.csv"
    manifest = _manifest(tmp_path, {"cams_here": {
        "kind": "cams", "download": "cams", "latitude": 49.6, "longitude": 6.1,
        "page": "https://example.org", "target": str(target)}})
    monkeypatch.setenv("VIPVFLOW_CAMS_URL", cams_service["url"])
    monkeypatch.setenv("CAMS_EMAIL", "refused@example.org")
    assert main(["data", "fetch", "--manifest", str(manifest)]) == 1
    assert capsys.readouterr().out.splitlines() == [
        "cams_here: the CAMS service refused the request: Unknown user: please register"]
    assert not target.exists() and not list(tmp_path.glob("*.part"))


def test_direct_download_checks_its_checksum(test_data, tmp_path, capsys):
    src = test_data / "cams" / CSV
    good = hashlib.sha256(src.read_bytes()).hexdigest()
    manifest = _manifest(tmp_path, {
        "good": {"download": src.as_uri(), "sha256": good, "target": str(tmp_path / "a.csv")},
        "bad": {"download": src.as_uri(), "sha256": "0" * 64, "target": str(tmp_path / "b.csv")}})
    assert main(["data", "fetch", "--manifest", str(manifest)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert (tmp_path / "a.csv").read_bytes() == src.read_bytes()
    assert out[0] == f"good: {tmp_path / 'a.csv'} ({src.stat().st_size:,} B)"
    assert out[1] == f"bad: checksum mismatch for {tmp_path / 'b.csv'}"
    assert not (tmp_path / "b.csv").exists() and not list(tmp_path.glob("*.part"))
