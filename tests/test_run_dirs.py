"""Run folders that travel, and a run folder of another configuration (issues 18, 19).

The run folder under test is the session's real small-demo simulation (``small_run``): it is
copied, with or without its data dir, and read from ``/`` by the app's model, the Dynamizer
export (library and CLI) and :func:`open_run`.  A changed configuration on an existing run
folder runs for real on a LocalCluster, its replacement killed (SIGKILL) during the map.
"""
from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from db_run import checksums
from vipvflow.config import load_config
from vipvflow.errors import InputError
from vipvflow.simulation import run_simulation
from vipvflow.simulation.rundir import open_run

ROOT = Path(__file__).resolve().parents[1]


def _cli(*args, cwd="/") -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-m", "vipvflow.cli", *map(str, args)], cwd=cwd,
                          env=env, capture_output=True, text=True, timeout=600)


def _copy_run(small_run: Path, dest: Path, with_data: bool = True) -> Path:
    """*dest*/out/<scenario>/<year> (and *dest*/data): the layout the small run was made in."""
    manifest = json.loads((small_run / "manifest.json").read_text())
    data = Path(manifest["paths"]["data_dir"]["absolute"])
    run = dest / "out" / small_run.parent.name / small_run.name
    shutil.copytree(small_run, run)
    if with_data:
        shutil.copytree(data, dest / "data")
    return run


@pytest.fixture(scope="module")
def copied_run(small_run, tmp_path_factory) -> Path:
    """The small run and its data dir copied elsewhere (as to another machine)."""
    return _copy_run(small_run, tmp_path_factory.mktemp("elsewhere"))


def test_manifest_records_the_data_dir_absolute_and_run_relative(small_run):
    manifest = json.loads((small_run / "manifest.json").read_text())
    record = manifest["paths"]["data_dir"]
    data = Path(manifest["config"]["data_dir"]).resolve()
    assert Path(record["absolute"]) == data
    assert (small_run / record["run_relative"]).resolve() == data
    assert not Path(record["run_relative"]).is_absolute()


def test_app_model_from_root_on_a_copied_run(copied_run, monkeypatch):
    from vipvflow.app.model import TripModel

    monkeypatch.chdir("/")
    model = TripModel(copied_run.relative_to("/"))      # a path relative to /
    data = copied_run.parents[2] / "data"
    assert model.data_dir == data                        # the copy's data dir, not the original's
    feed = json.loads((data / "gtfs" / "feed.json").read_text())
    assert model.timezone == feed["timezone"] == "Europe/Luxembourg"
    assert model.year == 2024 and len(model.trips) > 0


def test_dynamizer_export_of_a_copied_run_from_root_equals_the_original(small_run, copied_run,
                                                                          tmp_path, monkeypatch):
    from vipvflow.outputs import write_dynamizers

    monkeypatch.chdir("/")
    original = write_dynamizers(small_run, tmp_path / "original.gml")
    copy = write_dynamizers(copied_run, tmp_path / "copy.gml")
    counts = ["segments", "surfaces", "network", "dynamizers"]
    assert [copy[k] for k in counts] == [original[k] for k in counts]
    assert copy["surfaces"] > 0          # reflecting surfaces found in the copy's city meshes


def test_export_cli_from_root_on_a_copied_run(copied_run, tmp_path):
    proc = _cli("export", "dynamizer", copied_run, "-o", tmp_path / "twin.gml", "--segments", "20")
    assert proc.returncode == 0, proc.stderr
    assert "no city mesh" not in proc.stderr and "Traceback" not in proc.stderr
    assert (tmp_path / "twin.gml").stat().st_size > 0


def test_run_folder_moved_alone_uses_the_absolute_path(small_run, tmp_path, monkeypatch):
    run = _copy_run(small_run, tmp_path, with_data=False)
    monkeypatch.chdir("/")
    manifest = json.loads((small_run / "manifest.json").read_text())
    assert open_run(run).data_dir == Path(manifest["paths"]["data_dir"]["absolute"])


def test_missing_data_dir_is_one_line_naming_where_it_belongs(small_run, tmp_path):
    run = _copy_run(small_run, tmp_path, with_data=False)
    manifest = json.loads((run / "manifest.json").read_text())
    manifest["paths"]["data_dir"]["absolute"] = "/nonexistent/machine/data"   # another machine
    manifest["config"]["data_dir"] = "/nonexistent/machine/data"
    (run / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(InputError, match=r"data dir is missing .*copy it to \.\./\.\./\.\./data"):
        open_run(run)
    for args in (["export", "dynamizer", run, "-o", tmp_path / "x.gml"], ["app", run]):
        proc = _cli(*args)
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "gtfs/feed.json" in lines[0], proc.stderr
    assert not (tmp_path / "x.gml").exists()


def test_manifest_without_paths_finds_the_data_dir_beside_out_dir(small_run, tmp_path, monkeypatch):
    """A manifest of an earlier version: a relative data_dir, relative to where the run was made."""
    run = _copy_run(small_run, tmp_path)
    manifest = json.loads((run / "manifest.json").read_text())
    del manifest["paths"]
    manifest["config"].update(data_dir="data", out_dir="out")
    (run / "manifest.json").write_text(json.dumps(manifest))
    monkeypatch.chdir("/")
    assert open_run(run).data_dir == tmp_path / "data"


# ---------------------------------------------------------------- a changed configuration

def _files(run_dir: Path) -> dict[str, int]:
    return {str(p.relative_to(run_dir)): p.stat().st_mtime_ns for p in run_dir.rglob("*") if p.is_file()}


PARTS = "parts/segment_month/tile=*/month=*.parquet"


def _killed_mid_map(cmd: list, run_dir: Path, digest: str, n: int) -> int:
    """Run *cmd* in its own process group, SIGKILL the group once *n* partitions of the run
    of configuration *digest* are written in *run_dir*; returns the partitions then written."""
    stamp = run_dir / "parts" / "config_digest.txt"

    def written():
        try:
            ours = stamp.read_text() == digest
        except OSError:
            ours = False
        return len(list(run_dir.glob(PARTS))) if ours else 0

    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.Popen([sys.executable, "-m", "vipvflow.cli", *map(str, cmd)], env=env,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)
    deadline = time.time() + 300
    while time.time() < deadline and proc.poll() is None:
        if written() >= n:
            os.killpg(proc.pid, signal.SIGKILL)
            break
        time.sleep(0.02)
    proc.wait(timeout=60)
    return len(list(run_dir.glob(PARTS)))


def test_changed_configuration_is_refused_or_replaced_whole(small_config, tmp_path):
    quiet = {"say": lambda *a: None}
    out = {"out_dir": str(tmp_path / "out"), "dask": {"n_workers": 1}}
    first = load_config(small_config, overrides=out)
    run_dir = run_simulation(first, 2024, **quiet)
    before = checksums(run_dir)
    changed = load_config(small_config, overrides={**out, "run": {"months": [5, 6, 7, 8]}})
    assert changed.digest() != first.digest()

    # refused, both digests named, nothing touched
    with pytest.raises(InputError) as err:
        run_simulation(changed, 2024, **quiet)
    assert first.digest() in str(err.value) and changed.digest() in str(err.value)
    assert "--force" in str(err.value)
    assert checksums(run_dir) == before

    # --force, killed during the map: only the new run's files are there
    conf = yaml.safe_load(Path(small_config).read_text())
    conf.update(out_dir=str(tmp_path / "out"), run={"months": [5, 6, 7, 8]})
    conf_file = tmp_path / "changed.yaml"
    conf_file.write_text(yaml.safe_dump(conf))
    assert load_config(conf_file).digest() == changed.digest()
    t_force = time.time_ns()
    done = _killed_mid_map(["simulate", "--config", conf_file, "--year", 2024, "--workers", 1,
                            "--force"], run_dir, changed.digest(), 2)
    files = _files(run_dir)
    assert 2 <= done < 24, f"not killed mid-map ({done} of 24 partitions)"
    assert "manifest.json" not in files and "summary.json" not in files
    assert min(files.values()) >= t_force, "a file of the replaced run is left"
    assert (run_dir / "parts" / "config_digest.txt").read_text() == changed.digest()
    with pytest.raises(InputError, match="not a finished run"):
        open_run(run_dir)                          # a mirror or the app refuse it

    # the same changed configuration resumes without --force, from its own partitions only
    run_simulation(changed, 2024, **quiet)
    manifest = json.loads((run_dir / "manifest.json").read_text())
    assert manifest["config_digest"] == changed.digest()
    assert manifest["partitions_computed"] == 24 - done


def test_track_on_a_copied_run_from_root(copied_run, small_config, tmp_path):
    """``vipvflow track --city RUN_DIR``: the city of the run's data dir (the copy's)."""
    import pandas as pd

    data = copied_run.parents[2] / "data"
    road = pd.read_parquet(data / "gtfs" / "segments.parquet").head(5)
    # and points across the first tile, some beyond the terrain model (no ground height)
    x0, y0, x1, y1 = next(iter(json.loads((data / "city" / "tiles.json").read_text())["tiles"].values()))["bounds"]
    x = list(road["x"]) + [x0 + (x1 - x0) * f for f in (0.3, 0.4, 0.5)]
    y = list(road["y"]) + [(y0 + y1) / 2] * 3
    n = len(x)
    t = pd.date_range("2024-06-15 11:00", periods=n, freq="1min", tz="UTC")
    track = pd.DataFrame({"time": t.strftime("%Y-%m-%dT%H:%M:%SZ"), "x": x, "y": y})
    track.to_csv(tmp_path / "track.csv", index=False)
    cams = yaml.safe_load(Path(small_config).read_text())["inputs"]["cams"][0]
    rel = lambda p: Path(p).relative_to("/")                       # noqa: E731 - paths from /
    proc = _cli("track", rel(tmp_path / "track.csv"), "--city", rel(copied_run), "--cams", cams,
                "--out", rel(tmp_path / "out.csv"))
    assert proc.returncode == 0, proc.stderr
    res = pd.read_csv(tmp_path / "out.csv")
    assert len(res) == n and (res["total_unshaded"] > 0).all()       # never NaN
