"""Failures a user causes end a run in one line, never a traceback (issue 19).

Each probe runs ``vipvflow simulate`` as a user would (a subprocess, from ``/``, on a real
LocalCluster) over the small demo: an output folder on a read-only or a full file system
(a tmpfs mounted by the test when it runs as root, else a folder without write permission
and a file-size limit), Ctrl-C sent to the command's process group during the map, and
radiation data that do not cover the simulated year (an InputError raised inside the tasks).
"""
from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]


def _mount_tmpfs(where: Path, options: str) -> bool:
    """Mount a tmpfs at *where* (root only); False when it cannot be done here."""
    if os.geteuid() != 0:
        return False
    where.mkdir(parents=True, exist_ok=True)
    proc = subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", str(where)],
                          capture_output=True)
    return proc.returncode == 0


@pytest.fixture
def mounts():
    done = []
    yield done
    for m in done:
        subprocess.run(["umount", str(m)], capture_output=True)


def _config(small_config: Path, dest: Path, **changes) -> Path:
    conf = yaml.safe_load(Path(small_config).read_text())
    conf.update(changes)
    path = dest / "probe.yaml"
    path.write_text(yaml.safe_dump(conf))
    return path


def _simulate(config: Path, year: int = 2024, on_output=None, preexec_fn=None):
    """Run the command from /; *on_output(proc, text_so_far)* may signal it."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), PYTHONUNBUFFERED="1")
    cmd = [sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(config), "--year",
           str(year), "--workers", "1"]
    proc = subprocess.Popen(cmd, cwd="/", env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, preexec_fn=preexec_fn)
    if on_output is None:
        out, err = proc.communicate(timeout=600)
        return proc.returncode, out, err
    chunks = []

    def read():                        # progress bars end in \r, not \n: raw reads
        while True:
            data = os.read(proc.stderr.fileno(), 65536)
            if not data:
                return
            chunks.append(data)
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    deadline = time.time() + 600
    while proc.poll() is None and time.time() < deadline:
        on_output(proc, b"".join(chunks).decode(errors="replace"))
        time.sleep(0.05)
    proc.wait(timeout=120)
    reader.join(timeout=60)
    return proc.returncode, proc.stdout.read(), b"".join(chunks).decode(errors="replace")


def probe_read_only(small_config, tmp_path, mounts):
    out = tmp_path / "ro"
    if _mount_tmpfs(out, "ro,size=1m"):
        mounts.append(out)
        reason = "Read-only file system"
    elif os.geteuid() != 0:
        out.mkdir()
        out.chmod(0o555)
        reason = "Permission denied"
    else:
        pytest.skip("running as root where a tmpfs cannot be mounted: no read-only folder to try")
    rc, _, err = _simulate(_config(small_config, tmp_path, out_dir=str(out / "out")))
    return rc, err, [reason, str(out)]


def probe_full_disk(small_config, tmp_path, mounts):
    out = tmp_path / "full"
    limit = None
    if _mount_tmpfs(out, "size=300k"):
        mounts.append(out)
        reason = "No space left on device"
    else:                      # a file-size limit: the same failure of a write, EFBIG
        out.mkdir()
        reason, limit = "File too large", 100_000

    def small_files():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    rc, _, err = _simulate(_config(small_config, tmp_path, out_dir=str(out / "out")),
                           preexec_fn=small_files if limit else None)
    return rc, err, [reason, str(out)]


def probe_ctrl_c(small_config, tmp_path, mounts):
    config = _config(small_config, tmp_path, out_dir=str(tmp_path / "out"),
                     run={"months": list(range(1, 13))})
    sent = {}

    parts = tmp_path / "out"

    def interrupt(proc, err):
        # Ctrl-C in a terminal (the whole group) once the map has written a partition
        if not sent and any(parts.glob("*/2024/parts/segment_month/tile=*/month=*.parquet")):
            os.killpg(proc.pid, signal.SIGINT)
            sent["at"] = len(list(parts.glob("*/2024/parts/segment_month/tile=*/month=*.parquet")))
    # as from a terminal: Ctrl-C handled by default (an ignored SIGINT would be inherited)
    rc, _, err = _simulate(config, on_output=interrupt,
                           preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    assert sent, err
    return rc, err, ["vipvflow: interrupted"]


def probe_radiation_of_another_year(small_config, tmp_path, mounts):
    """A feed of 2025 with a CAMS file of 2023: the tasks find no radiation for 2025."""
    from vipvflow.demo import generate_demo

    for year in (2023, 2025):
        generate_demo(tmp_path / f"demo{year}", year=year, seed=42, size="small")
    conf = yaml.safe_load(Path(small_config).read_text())
    inputs = dict(conf["inputs"], gtfs=str(tmp_path / "demo2025" / "demo_gtfs.zip"),
                  cams=[str(tmp_path / "demo2023" / "cams_radiation_demo.csv")])
    config = _config(small_config, tmp_path, out_dir=str(tmp_path / "out"), inputs=inputs,
                     data_dir=str(tmp_path / "data"), demo={"enabled": False})
    rc, _, err = _simulate(config, year=2025)
    return rc, err, ["2025"]


PROBES = {"read-only output folder": (probe_read_only, 2),
          "full output disk": (probe_full_disk, 2),
          "ctrl-c to the process group": (probe_ctrl_c, 130),
          "radiation of another year (inside the tasks)": (probe_radiation_of_another_year, 2)}


@pytest.mark.parametrize("name", list(PROBES))
def test_failure_is_one_line(name, small_config, tmp_path, mounts):
    probe, expected_rc = PROBES[name]
    rc, err, words = probe(small_config, tmp_path, mounts)
    assert rc == expected_rc, err
    for noise in ("Traceback", "Compute Failed", "KeyboardInterrupt", "distributed."):
        assert noise not in err, f"{noise!r} in:\n{err}"
    last = err.rstrip().splitlines()[-1]
    if expected_rc == 2:
        assert last.startswith("vipvflow simulate: error: "), err
        assert [ln for ln in err.splitlines() if "error" in ln] == [last], err
    for word in words:
        assert word in last, err


def test_worker_lines_the_command_speaks_for_are_left_out():
    """The worker log lines the command reports itself (a task's failure, a heartbeat cut by
    the shutdown of a stopped run's cluster) are filtered; others pass."""
    import logging

    from vipvflow.simulation.worker_setup import _not_said_by_the_command

    def record(msg):
        return logging.LogRecord("distributed.worker", logging.ERROR, __file__, 1, msg, (), None)

    assert not _not_said_by_the_command(record("Compute Failed\nKey: irradiance-E1N2-2024-06"))
    assert not _not_said_by_the_command(record("Failed to communicate with scheduler during heartbeat."))
    assert _not_said_by_the_command(record("Unexpected exception during heartbeat. Closing worker."))
    assert _not_said_by_the_command(record("Worker stream died during communication"))
