"""A real multi-process cluster started with Dask's own command-line tools (`dask scheduler`,
two `dask worker` processes), driven through `vipvflow simulate --scheduler tcp://...` from
another working directory: the results equal the LocalCluster run's."""
from __future__ import annotations

import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from test_simulate import assert_same_results


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _dask_cli() -> list[str]:
    exe = Path(sys.executable).with_name("dask")
    if exe.exists():
        return [str(exe)]
    if shutil.which("dask"):
        return [shutil.which("dask")]
    pytest.skip("the `dask` command-line tool is not installed beside this Python")


@pytest.fixture
def cli_cluster(tmp_path):
    """`dask scheduler` on a loopback port and two `dask worker` processes of one thread each."""
    from distributed import Client

    dask = _dask_cli()
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = tmp_path / "cluster-logs"
    logs.mkdir()
    common = dict(cwd=tmp_path, env=dict(os.environ), start_new_session=True, stdin=subprocess.DEVNULL)
    procs = [subprocess.Popen(dask + ["scheduler", "--host", "127.0.0.1", "--port", str(port),
                                      "--dashboard-address", ":0"],
                              stdout=open(logs / "scheduler.log", "w"), stderr=subprocess.STDOUT, **common)]
    try:
        for i in range(2):
            procs.append(subprocess.Popen(
                dask + ["worker", address, "--nworkers", "1", "--nthreads", "1", "--host", "127.0.0.1",
                        "--dashboard-address", ":0", "--memory-limit", "4GiB", "--name", f"cli-worker-{i}"],
                stdout=open(logs / f"worker{i}.log", "w"), stderr=subprocess.STDOUT, **common))
        with Client(address, timeout=60) as client:
            client.wait_for_workers(2, timeout=120)
            assert len(client.scheduler_info()["workers"]) == 2
        yield address
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                os.killpg(p.pid, signal.SIGTERM)
        for p in procs:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)


@pytest.mark.slow
def test_simulate_on_a_dask_cli_cluster_equals_the_local_run(small_run, small_config, cli_cluster, tmp_path):
    conf = yaml.safe_load(Path(small_config).read_text())
    conf["out_dir"] = str(tmp_path / "remote-out")
    scenario = tmp_path / "remote.yaml"
    scenario.write_text(yaml.safe_dump(conf))
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    proc = subprocess.run([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(scenario),
                           "--year", "2024", "--scheduler", cli_cluster],
                          cwd=elsewhere, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    run_dir = tmp_path / "remote-out" / conf["scenario"] / "2024"
    assert_same_results(small_run, run_dir)
    # the partitions were computed by the two CLI workers (each built the BVHs of its tiles)
    builds = json.loads((run_dir / "manifest.json").read_text())["bvh_builds_per_worker"]
    assert len(builds) == 2 and all(sum(per.values()) >= 1 for per in builds.values())
    # an outside cluster's workers are not restarted before the reduce (a LocalCluster's are)
    assert "restart_s" not in json.loads((run_dir / "manifest.json").read_text())["timings_s"]
    assert "restart_s" in json.loads((small_run / "manifest.json").read_text())["timings_s"]


@pytest.mark.slow
def test_the_network_benchmark_asks_an_outside_cluster_for_its_peak_rss(cli_cluster):
    """On an outside cluster the benchmark states each process's own peak RSS: the scheduler's
    and both workers', asked of them (the cluster need not see ``benchmarks/``)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from benchmarks.bench_network import outside_cluster_peak_rss

    rss = outside_cluster_peak_rss(cli_cluster)
    per = rss["cluster_peak_rss_mb"]
    assert set(per) - {"scheduler"} and len(per) == 3
    # a Python process with Dask loaded holds tens of MB at least
    assert all(mb > 20 for mb in per.values())
    assert abs(rss["cluster_peak_rss_gb_sum"] - sum(per.values()) / 1024) < 0.01
