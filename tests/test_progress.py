"""Progress displays: plain lines when the output is not a terminal (a log reads line by
line), tqdm bars on a terminal, nothing with --quiet; the CityGML ingest counts bytes."""
from __future__ import annotations

import gzip
import io
import os
import re
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from vipvflow import progress
from vipvflow.progress import MapProgress, Progress, citygml_bytes, file_position

ROOT = Path(__file__).resolve().parents[1]


class _Tty(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.fixture(autouse=True)
def _loud():
    progress.set_quiet(False)
    yield
    progress.set_quiet(False)


def test_plain_lines_with_eta_and_no_carriage_return():
    out = io.StringIO()
    with Progress("work", 4, unit="steps", stream=out, every_s=0) as bar:
        for _ in range(4):
            bar.update(1, "busy")
    lines = out.getvalue().splitlines()
    assert "\r" not in out.getvalue()
    assert len(lines) == 4                        # one per update, the last not repeated by close
    assert re.fullmatch(r"work: 1 of 4 steps \(25 %\), 0:00 elapsed, ETA 0:00; busy", lines[0])
    assert lines[-1].startswith("work: 4 of 4 steps (100 %)") and "ETA" not in lines[-1]


def test_plain_lines_are_periodic():
    out = io.StringIO()
    with Progress("work", 1000, stream=out, every_s=3600) as bar:
        for _ in range(1000):
            bar.update(1)
    lines = out.getvalue().splitlines()
    assert len(lines) == 1 and lines[0].startswith("work: 1,000 of 1,000 it (100 %)")


def test_terminal_gets_a_tqdm_bar_and_quiet_gets_nothing():
    tty = _Tty()
    with MapProgress(3, stream=tty) as bar:
        for kwh in (1.0, 2.0, 3.5):
            bar.add({"passes": 1000, "kwh_by_route": {"L1": kwh, "L2": 1.0}})
    text = tty.getvalue()
    assert "\r" in text and "3/3" in text and "route kWh L1: 6" in text
    progress.set_quiet(True)
    silent = io.StringIO()
    with Progress("work", 2, stream=silent, every_s=0) as bar:
        bar.update(2)
    assert silent.getvalue() == ""


def _pty_stream(columns: int):
    """The writing end of a real pseudo-terminal whose window is *columns* wide, and a
    function reading what reached its other end."""
    import fcntl
    import pty
    import struct
    import termios

    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, columns, 0, 0))
    stream = os.fdopen(slave, "w", buffering=1)

    def read() -> str:
        stream.flush()
        chunks = []
        os.set_blocking(master, False)
        while True:
            try:
                chunk = os.read(master, 65536)
            except (BlockingIOError, OSError):
                break
            if not chunk:
                break
            chunks.append(chunk)
        return b"".join(chunks).decode("utf-8", "replace")

    return stream, read, master


@pytest.mark.parametrize("columns", [0, 80])
def test_a_terminal_without_width_gets_plain_lines(columns, monkeypatch):
    """A terminal reporting 0 columns (a CI runner's, ``docker exec`` without a size) gets
    the plain lines a log gets, never a bar drawn as blank lines; one of 80 a bar."""
    monkeypatch.delenv("COLUMNS", raising=False)
    stream, read, master = _pty_stream(columns)
    try:
        assert stream.isatty() and progress.terminal_columns(stream) == columns
        with MapProgress(3, stream=stream, every_s=0) as bar:
            for kwh in (1.0, 2.0, 3.5):
                bar.add({"passes": 1000, "kwh_by_route": {"S5": kwh}})
        text = read()
    finally:
        stream.close()
        os.close(master)
    lines = [l for l in text.replace("\r\n", "\n").split("\n")]
    if columns == 0:
        assert "\r" not in text.replace("\r\n", "\n"), repr(text)
        assert not any(l.strip() == "" for l in lines[:-1]), repr(text)
        assert lines[-2].startswith("map: 3 of 3 partitions (100 %)") and "route kWh S5: 6" in lines[-2]
    else:
        assert "3/3" in text and "\r" in text.replace("\r\n", "\n")


def test_citygml_bytes_and_positions(tmp_path, test_data):
    gml = next(p for p in sorted(test_data.rglob("*.gml")) if p.stat().st_size > 10_000)
    assert citygml_bytes([gml]) == gml.stat().st_size
    gz = tmp_path / "city.gml.gz"
    with open(gml, "rb") as src, gzip.open(gz, "wb") as dst:
        shutil.copyfileobj(src, dst)
    assert citygml_bytes([gz]) == gz.stat().st_size
    with gzip.open(gz, "rb") as fh:
        while fh.read(1 << 16):
            pass
        assert file_position(fh) == gz.stat().st_size


def test_ingest_reports_bytes_read(demo_small, tmp_path, capsys):
    from vipvflow.inputs.city import ingest_city

    gml = demo_small / "demo_city.gml"
    ingest_city([gml], tmp_path / "data")
    err = capsys.readouterr().err
    size = gml.stat().st_size / 1e6
    assert f"CityGML ingest: {size:.1f} MB of {size:.1f} MB (100 %)" in err


def test_dashboard_on_8787_when_free_else_any_port():
    """The dashboard's address: on 127.0.0.1 (dask.host) only, the configured port when it is
    free there, else any."""
    from vipvflow.simulation.cluster import dashboard_address

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        taken = s.getsockname()[1]
        assert dashboard_address(taken) == "127.0.0.1:0"
    assert dashboard_address(None) == "127.0.0.1:0"
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    assert dashboard_address(free) == f"127.0.0.1:{free}"
    assert dashboard_address(free, "0.0.0.0") == f"0.0.0.0:{free}"


def test_simulate_into_a_log_reads_line_by_line(small_config, tmp_path):
    """``vipvflow simulate > log``: the map and reduce progress as plain lines."""
    conf = yaml.safe_load(small_config.read_text())
    conf["out_dir"] = str(tmp_path / "out")
    path = tmp_path / "small.yaml"
    path.write_text(yaml.safe_dump(conf))
    log = tmp_path / "log"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    with socket.socket() as s:           # a free port for the dashboard (--dashboard-port)
        s.bind(("", 0))
        port = s.getsockname()[1]
    with open(log, "w") as fh:
        res = subprocess.run([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(path),
                              "--year", "2024", "--workers", "1", "--dashboard-port", str(port)],
                             stdout=fh, stderr=subprocess.STDOUT, env=env, cwd=tmp_path, timeout=600)
    text = log.read_text()
    assert res.returncode == 0, text
    assert "\r" not in text
    lines = text.splitlines()
    n = int(re.search(r"= (\d+) partitions", text).group(1))
    assert any(l.startswith(f"map: {n} of {n} partitions (100 %)") and "M passes/s" in l for l in lines)
    assert any(re.match(r"reduce: \d+ files, .*last ", l) for l in lines)
    assert re.search(rf"^dask dashboard: http://\S+:{port}/status$", text, flags=re.M)
    quiet = subprocess.run([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(path),
                            "--year", "2024", "--workers", "1", "--quiet"], capture_output=True,
                           text=True, env=env, cwd=tmp_path, timeout=600)
    assert quiet.returncode == 0
    assert not re.search(r"^(map|reduce|CityGML ingest|demo generation): ", quiet.stdout + quiet.stderr,
                         flags=re.M)
