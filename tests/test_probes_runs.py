"""Issue 37: runs a careless user starts, as the user would, on real LocalClusters.

Numbers refer to the issue's list: a CAMS file replaced after a finished run (1) or in the
middle of one (the resume test), two runs on one folder at once (7), run folders that are
not run folders (9), the Dask servers' addresses (10, the dashboard test), then the
tracebacks, the hang and the unclear messages the issue lists, each now one line.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import yaml

from db_run import checksums
from test_feed_probes import one_line_error, vipvflow
from test_probes_inputs import _cams_day
from vipvflow.config import load_config
from vipvflow.errors import ConfigError, InputError
from vipvflow.simulation import run_simulation

ROOT = Path(__file__).resolve().parents[1]
QUIET = {"say": lambda *a: None}


def _scaled_cams(src: Path, dest: Path, factor: float) -> Path:
    """*src* with its all-sky irradiation (GHI, BHI, DHI, BNI) times *factor*: another
    plausible radiation file (DHI still below GHI, GHI below the clear sky)."""
    with open(src) as fin, open(dest, "w") as fout:
        for line in fin:
            if not line.startswith("#"):
                v = line.rstrip("\n").split(";")
                v[6:10] = [f"{float(x) * factor:.4f}" for x in v[6:10]]
                line = ";".join(v) + "\n"
            fout.write(line)
    return dest


def _numbers(summary: dict, prefix: str = "") -> dict:
    """The numbers of a summary, nested keys flattened (``irradiation_kwh_m2.total``)."""
    out = {}
    for k, v in summary.items():
        if isinstance(v, dict):
            out.update(_numbers(v, f"{prefix}{k}."))
        elif isinstance(v, (int, float)) and not isinstance(v, bool) and v is not None:
            out[prefix + k] = v
    return out


# ------------------------------------------------------------ 1 and the resume test
def test_replaced_cams_is_refused_or_recomputed_whole(small_config, small_run, tmp_path):
    """A run stopped after 3 of its 8 partitions; the CAMS file is replaced by one with 80 %
    of the all-sky light; the rerun is refused naming both input digests and the file, its
    partitions untouched. With --force the folder is recomputed whole and equals a clean run
    on the new file (the old code resumed: 14 old and 6 new partitions in the issue's run).
    Then the file is put back after the finished run: refused again (the old code said
    "0 to compute" and kept the yield of the other file)."""
    conf = yaml.safe_load(Path(small_config).read_text())
    cams = tmp_path / "cams.csv"
    original = Path(conf["inputs"]["cams"][0])
    shutil.copyfile(original, cams)
    conf.update(data_dir=str(tmp_path / "data"), out_dir=str(tmp_path / "out"),
                demo={"enabled": False}, inputs={**conf["inputs"], "cams": [str(cams)]})
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(conf))
    cfg = load_config(path, overrides={"dask": {"n_workers": 2}})

    run_dir = run_simulation(cfg, 2024, max_partitions=3, **QUIET)
    assert not (run_dir / "manifest.json").exists()
    parts = checksums(run_dir / "parts")
    old = json.loads((run_dir / "parts" / "inputs.json").read_text())["digest"]

    _scaled_cams(original, cams, 0.8)
    with pytest.raises(InputError) as err:
        run_simulation(cfg, 2024, **QUIET)
    msg = str(err.value)
    assert "holds a run of other input files" in msg and "inputs.cams (cams.csv) changed" in msg
    assert f"inputs digest {old}" in msg and "--force" in msg
    new = msg.split("these inputs' digest is ")[1][:16]
    assert new != old
    assert checksums(run_dir / "parts") == parts            # nothing of the partial run touched

    t_force = time.time_ns()
    run_simulation(cfg, 2024, force=True, **QUIET)
    manifest = json.loads((run_dir / "manifest.json").read_text())
    assert manifest["inputs_digest"] == new
    assert manifest["partitions_computed"] + manifest["standing_partitions_computed"] == 8
    assert all(p.stat().st_mtime_ns >= t_force for p in (run_dir / "parts").rglob("*.parquet"))
    forced = json.loads((run_dir / "summary.json").read_text())

    clean_cfg = load_config(path, overrides={"dask": {"n_workers": 2},
                                             "out_dir": str(tmp_path / "clean")})
    clean = json.loads((run_simulation(clean_cfg, 2024, **QUIET) / "summary.json").read_text())
    assert _numbers(forced) == pytest.approx(_numbers(clean), rel=1e-9)
    # the new file's light, not the old one's (the session's run of the same scenario)
    before = json.loads((small_run / "summary.json").read_text())["kwh_per_kwp_driving"]
    assert forced["kwh_per_kwp_driving"] == pytest.approx(0.8 * before, rel=0.05)

    shutil.copyfile(original, cams)                     # item 1: replaced after a finished run
    with pytest.raises(InputError, match=f"inputs digest {new}; these inputs' digest is {old}"):
        run_simulation(cfg, 2024, **QUIET)


# ------------------------------------------------------------ 7, 10: two runs, the servers
def _listeners(pid: int) -> list:
    import psutil

    procs = [psutil.Process(pid)]
    procs += procs[0].children(recursive=True)
    pids = {p.pid for p in procs}
    return [c.laddr for c in psutil.net_connections("tcp")
            if c.status == psutil.CONN_LISTEN and c.pid in pids]


def test_second_run_on_a_folder_is_refused_and_servers_listen_on_localhost(small_config, tmp_path):
    """Issue items 7 and 10. While a run computes its map: (10) every socket its scheduler,
    nannies, workers and dashboard listen on is bound to 127.0.0.1, and the console printed
    a dashboard address that is one of them (Dask's dashboard listened on 0.0.0.0 while the
    console said 127.0.0.1); (7) a run of another configuration with --force on the same
    folder is refused in one line naming the first run's process (the old code let it
    replace the folder under the first, whose parts then landed in the other's folder), and a
    run with another CAMS file on the same data dir is refused too. The first run then
    finishes as if alone."""
    conf = yaml.safe_load(Path(small_config).read_text())
    conf.update(data_dir=str(tmp_path / "data"), out_dir=str(tmp_path / "out"),
                demo={"enabled": False}, run={"months": list(range(3, 11))})
    first = tmp_path / "first.yaml"
    first.write_text(yaml.safe_dump(conf))
    other = tmp_path / "other.yaml"
    other.write_text(yaml.safe_dump({**conf, "pv": {"system": "cdte_3kwp"}}))
    cams = _cams_day(Path(conf["inputs"]["cams"][0]).parent, tmp_path / "day.csv")
    third = tmp_path / "third.yaml"
    third.write_text(yaml.safe_dump({**conf, "out_dir": str(tmp_path / "out3"),
                                     "inputs": {**conf["inputs"], "cams": [str(cams)]}}))

    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), PYTHONUNBUFFERED="1")
    proc = subprocess.Popen([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", first,
                             "--year", "2024", "--workers", "2", "--quiet"], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)
    lines: list[str] = []

    def read():
        for line in proc.stdout:
            lines.append(line)
    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        deadline = time.time() + 600
        while not any("partitions," in ln for ln in lines) and proc.poll() is None:
            assert time.time() < deadline, "".join(lines)
            time.sleep(0.1)
        assert proc.poll() is None, "".join(lines) + proc.stderr.read()
        listening = _listeners(proc.pid)
        dashboard = next(ln for ln in lines if ln.startswith("dask dashboard: "))
        assert len(listening) >= 4, listening          # scheduler, dashboard, nanny, worker
        assert {a.ip for a in listening} == {"127.0.0.1"}, listening
        port = int(dashboard.split(":")[-1].split("/")[0])
        assert dashboard.startswith("dask dashboard: http://127.0.0.1:")
        assert port in {a.port for a in listening}, (dashboard, listening)

        # (each refusal names the first run's process id: it held its locks then)
        second = vipvflow("simulate", "--config", other, "--year", "2024", "--force", "--quiet",
                          "--workers", "1")
        one_line_error(second, str(tmp_path / "out" / "small" / "2024"),
                       f"another vipvflow process (pid {proc.pid}) is using this folder")
        data = vipvflow("simulate", "--config", third, "--year", "2024", "--quiet", "--workers", "1")
        one_line_error(data, str(tmp_path / "data"), f"another vipvflow run (pid {proc.pid}) is "
                       "reading this data dir", "would replace its radiation/, gtfs/")
    finally:
        if proc.poll() is None:
            proc.wait(timeout=900)
        reader.join(timeout=60)
    err = proc.stderr.read()
    assert proc.returncode == 0, err
    assert "stopped before all partitions" not in "".join(lines)
    manifest = json.loads((tmp_path / "out" / "small" / "2024" / "manifest.json").read_text())
    assert manifest["config_digest"] == load_config(first).digest()
    assert not (tmp_path / "out3").exists()


def test_folder_lock_exclusive_and_shared(tmp_path):
    from vipvflow.store import FolderLock, lock_for_writing

    a, b = FolderLock(tmp_path / ".lock", tmp_path), FolderLock(tmp_path / ".lock", tmp_path)
    assert a.take()
    assert not b.take() and not b.take(shared=True)
    with pytest.raises(InputError, match="another vipvflow process is using this folder"):
        lock_for_writing(b, "ingest")                   # our own pid is not named
    assert a.take(shared=True) and b.take(shared=True)  # readers together
    assert not a.take()                                 # no writer while another reads
    b.release()
    assert a.take()
    a.release()


# ------------------------------------------------------------ 9: run folders
def test_scenario_name_is_a_name(tmp_path):
    """Issue item 9: ``scenario: ../victim`` wrote into (and --force later deleted) a folder
    beside out_dir."""
    conf = tmp_path / "c.yaml"
    conf.write_text(yaml.safe_dump({"scenario": "../victim", "out_dir": str(tmp_path / "out")}))
    one_line_error(vipvflow("simulate", "--config", conf, "--year", "2024"), str(conf),
                   "key 'scenario'", "'../victim' is not a scenario name")
    for bad in ("..", "a/b", "/abs", ""):
        with pytest.raises(ConfigError, match="not a scenario name"):
            load_config(overrides={"scenario": bad})


def test_run_folder_that_is_not_one(small_config, tmp_path):
    """A run folder holding the user's files and no run marker is refused, with or without
    --force, and nothing in it touched."""
    conf = yaml.safe_load(Path(small_config).read_text())
    conf.update(out_dir=str(tmp_path / "out"), demo={"enabled": False})
    path = tmp_path / "c.yaml"
    path.write_text(yaml.safe_dump(conf))
    victim = tmp_path / "out" / "small" / "2024"
    victim.mkdir(parents=True)
    (victim / "thesis.tex").write_text("mine")
    res = vipvflow("simulate", "--config", path, "--year", "2024", "--force", "--quiet")
    one_line_error(res, str(victim), "not a run folder (it holds thesis.tex", "choose another "
                   "scenario or out_dir")
    assert sorted(p.name for p in victim.iterdir()) == ["thesis.tex"]


def test_force_replaces_only_a_folder_of_run_files(tmp_path):
    """``--force`` on a run folder of another configuration that also holds a file no run
    wrote is refused, naming it (it deleted the folder whole); a run folder of run files
    only is replaced; a partial run made before input digests existed is refused."""
    from vipvflow.simulation.manifest import InputDigests, check_run_dir, claim_run_dir

    inputs = InputDigests({"inputs.cams": {"c.csv": "ab" * 32}})
    run = tmp_path / "out" / "s" / "2024"
    (run / "parts").mkdir(parents=True)
    (run / "parts" / "config_digest.txt").write_text("0" * 16)
    (run / "summary.json").write_text("{}")
    (run / "notes.txt").write_text("mine")
    with pytest.raises(InputError, match=r"holds files no run wrote \(notes.txt\): --force "
                                         "replaces only a run's own files"):
        check_run_dir(run, "1" * 16, inputs, force=True)
    with pytest.raises(InputError, match="of another configuration .* and whose input files are "
                                         "unknown"):
        check_run_dir(run, "1" * 16, inputs)
    assert (run / "notes.txt").read_text() == "mine"
    (run / "notes.txt").unlink()
    claim_run_dir(run, "1" * 16, force=True, inputs=inputs, **QUIET)
    assert sorted(p.name for p in run.rglob("*")) == ["config_digest.txt", "inputs.json", "parts"]
    assert not check_run_dir(run, "1" * 16, inputs)     # its own run: resumed
    with pytest.raises(InputError, match="of other input files"):
        check_run_dir(run, "1" * 16, InputDigests({"inputs.cams": {"c.csv": "cd" * 32}}))


# ------------------------------------------------------------ tracebacks and the hang
@pytest.fixture(scope="module")
def relative_config(tmp_path_factory, small_config) -> Path:
    """The small scenario with relative data_dir and out_dir (as --out moves them)."""
    conf = yaml.safe_load(Path(small_config).read_text())
    conf.update(data_dir="data", out_dir="out")
    root = tmp_path_factory.mktemp("relative")
    path = root / "rel.yaml"
    path.write_text(yaml.safe_dump(conf))
    return path


def test_outputs_named_as_existing_files(relative_config, demo_small, tmp_path):
    """``--out`` / ``--data-dir`` / ``--dir`` naming an existing file: one line each (seven
    commands gave FileExistsError tracebacks); ``export --out`` naming a folder (an
    IsADirectoryError)."""
    afile = tmp_path / "afile"
    afile.write_text("")
    commands = [
        ["simulate", "--config", relative_config, "--year", "2024", "--out", afile],
        ["demo-data", "--out", afile, "--year", "2024", "--size", "small"],
        ["ingest", "city", demo_small / "demo_city.gml", "--data-dir", afile],
        ["ingest", "gtfs", demo_small / "demo_gtfs.zip", "--data-dir", afile],
        ["ingest", "cams", demo_small / "cams_radiation_demo.csv", "--data-dir", afile],
        ["vecto", "job", "--out", afile],
        ["db", "start", "--dir", afile],
        ["ingest", "cams", demo_small / "cams_radiation_demo.csv", "--data-dir", afile / "sub"],
    ]
    for cmd in commands:
        one_line_error(vipvflow(*cmd), str(afile), "must be a folder, and this is a file")
    assert afile.read_text() == ""


def test_export_out_naming_a_folder(small_run, tmp_path):
    one_line_error(vipvflow("export", "dynamizer", small_run, "--out", tmp_path),
                   f"{tmp_path}: --out names a folder; give the file to write, e.g. "
                   f"{tmp_path / 'twin.gml'}")


def test_app_port_out_of_range_or_busy(small_run):
    one_line_error(vipvflow("app", small_run, "--port", "99999"),
                   "argument --port: '99999' is not a port number (1..65535): try 5006")
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        one_line_error(vipvflow("app", small_run, "--port", port),
                       f"port {port} on 127.0.0.1 is in use (another app?): try --port")


def test_raw_websocket_request_is_one_log_line(small_run):
    """A WebSocket request without Bokeh's subprotocol was logged as an "Uncaught exception"
    with a traceback; now one warning line."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    # Ctrl-C handled by default, as from a terminal (a suite started in the background of a
    # shell without job control ignores SIGINT, and its children would inherit that)
    proc = subprocess.Popen([sys.executable, "-m", "vipvflow.cli", "app", small_run, "--port",
                             str(port)], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        deadline = time.time() + 300
        while True:
            assert proc.poll() is None and time.time() < deadline, proc.stderr.read()
            try:
                conn = socket.create_connection(("127.0.0.1", port), timeout=5)
                break
            except OSError:
                time.sleep(0.2)
        with conn:
            conn.sendall(f"GET /ws HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nUpgrade: websocket\r\n"
                         "Connection: Upgrade\r\nSec-WebSocket-Version: 13\r\n"
                         "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n\r\n".encode())
            conn.recv(4096)
        time.sleep(1.0)
    finally:
        os.killpg(proc.pid, signal.SIGINT)
        _, err = proc.communicate(timeout=60)
    assert "Traceback" not in err, err
    assert "refused GET /ws (127.0.0.1): Subprotocol header is not 'bokeh'" in err, err


def test_track_empty_or_outside_the_radiation(small_run, demo_small, tmp_path):
    """Issue item 6 (a track outside the radiation data ended with exit 0 and every
    irradiance 0) and the traceback of an empty track CSV."""
    import pandas as pd

    day = _cams_day(demo_small, tmp_path / "day.csv")
    data = Path(json.loads((small_run / "manifest.json").read_text())["paths"]["data_dir"]["absolute"])
    seg = pd.read_parquet(data / "gtfs" / "segments.parquet").head(3)
    track = tmp_path / "track.csv"
    pd.DataFrame({"time": ["2024-06-12T11:00:00Z", "2024-06-12T11:01:00Z", "2024-07-01T11:00:00Z"],
                  "x": seg["x"], "y": seg["y"]}).to_csv(track, index=False)
    res = vipvflow("track", track, "--city", small_run, "--cams", day, "--out", tmp_path / "o.csv")
    one_line_error(res, str(track), "1 of 3 points (from 2024-07-01 11:00 to 2024-07-01 11:00 UTC) "
                   "lie outside the radiation data of", "(2024-06-12 00:00 to 2024-06-13 00:00 UTC)")
    assert not (tmp_path / "o.csv").exists()
    empty = tmp_path / "empty.csv"
    empty.write_text("")
    one_line_error(vipvflow("track", empty, "--city", small_run, "--cams", day, "--out",
                            tmp_path / "o.csv"), f"{empty}: empty")
    one_line_error(vipvflow("track", track, "--city", small_run, "--cams", day, "--out",
                            tmp_path / "o.csv", "--crs", "NOTACRS"), "--crs NOTACRS: not a CRS")


@pytest.mark.parametrize("address,words", [
    ("tcp://127.0.0.1:1", "no Dask scheduler answers there ([Errno 111] Connection refused)"),
    ("tcp://127.0.0.1:abc", "not a scheduler address"),
    ("foo://bar", "not a scheduler address (unknown scheme 'foo'"),
])
def test_scheduler_address_that_does_not_answer(address, words, relative_config, tmp_path):
    one_line_error(vipvflow("simulate", "--config", relative_config, "--year", "2024", "--out",
                            tmp_path, "--scheduler", address, "--quiet"),
                   f"--scheduler {address}", words)


def test_negative_workers_refused_not_hung(relative_config, tmp_path):
    """``--workers -3`` printed "with 0 workers" and waited for ever."""
    res = vipvflow("simulate", "--config", relative_config, "--year", "2024", "--out", tmp_path,
                   "--workers", "-3", timeout=120)
    one_line_error(res, "--workers -3: a LocalCluster needs at least one worker")
    assert not (tmp_path / "out").exists() and not (tmp_path / "data").exists()


# ------------------------------------------------------------ unclear messages
@pytest.mark.parametrize("conf,words", [
    ({"pv": {"overrides": {"kwp": -1}}}, "key 'pv.overrides.kwp': Input should be greater than 0"),
    ({"pv": {"overrides": {"kwp": float("inf")}}}, "key 'pv.overrides.kwp': Input should be a finite number"),
    ({"vehicle": {"overrides": {"curb_mass_kg": "heavy"}}}, "key 'vehicle.overrides.curb_mass_kg'"),
    ({"vehicle": {"overrides": {"wings": 2}}}, "key 'vehicle.overrides.wings': unknown key"),
    ({"climate": {"wind_speed_mps": float("nan")}}, "key 'climate.wind_speed_mps': Input should be a finite number"),
])
def test_config_errors_name_the_users_file_and_key(conf, words, tmp_path):
    """Invalid pv.overrides / vehicle.overrides were blamed on the shipped catalogue file;
    ``kwp: .inf`` was accepted and failed only after the map."""
    path = tmp_path / "mine.yaml"
    path.write_text(yaml.safe_dump(conf))
    err = one_line_error(vipvflow("config", "--config", path), f"{path}: {words}")
    assert "pv_systems.yaml" not in err and "vehicles.yaml" not in err


def test_db_help_says_how_it_authenticates():
    res = subprocess.run([sys.executable, "-m", "vipvflow.cli", "db", "--help"],
                         capture_output=True, text=True)
    text = " ".join(res.stdout.split())
    assert res.returncode == 0 and "trust authentication" not in text
    assert "127.0.0.1 only and asks for the password of role postgres (scram-sha-256)" in text
