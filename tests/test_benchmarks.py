"""Smoke test of the benchmarks: every one runs on a tiny input and writes its JSON.

Nothing is asserted about time (tests never assert wall-clock figures); only that each
benchmark completes, writes ``<name>.tiny.json`` with figures and targets, and that the
figures that are facts rather than speeds hold (equal results, agreeing engines).
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NAMES = sorted(p.stem[len("bench_"):] for p in (ROOT / "benchmarks").glob("bench_*.py"))


def _postgres_available() -> bool:
    from vipvflow.db.server import find_bindir, postgis_available

    bindir = find_bindir()
    return bindir is not None and postgis_available(bindir)


@pytest.fixture(scope="module")
def tiny_results(tmp_path_factory):
    results = tmp_path_factory.mktemp("bench-results")
    names = [n for n in NAMES if n not in ("postgis", "mirror") or _postgres_available()]
    proc = subprocess.run([sys.executable, "-m", "benchmarks", *names, "--tiny", "--results", str(results)],
                          cwd=ROOT, capture_output=True, text=True, timeout=1800,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 0, proc.stderr[-3000:]
    return results, names, proc.stdout


def test_every_benchmark_writes_its_json(tiny_results):
    results, names, stdout = tiny_results
    for name in names:
        doc = json.loads((results / f"{name}.tiny.json").read_text())
        assert doc["name"] == name and doc["tiny"] is True
        assert doc["figures"], name
        assert set(doc["targets"]) <= set(doc["figures"]), name
    assert "benchmark" in stdout.splitlines()[0]


def test_facts_in_the_tiny_results(tiny_results):
    results, names, _ = tiny_results
    scaling = json.loads((results / "scaling.tiny.json").read_text())["figures"]
    assert scaling["results_equal"] is True
    # the CPU accounting sees the workers (child processes) and the command's own process
    assert scaling["cpu_s_workers_2_workers"] > 0 and scaling["cpu_s_command_2_workers"] > 0
    # the machine's ceiling is probed before the pair of runs and after, by both probes
    assert len(scaling["machine_speedup_2_processes_probes"]) == 2
    assert len(scaling["machine_speedup_2_processes_numpy_probes"]) == 2
    assert scaling["machine_speedup_2_processes"] > 0
    if "mirror" in names:  # the same rows in both servers; Citus's shards on both workers
        mirror = json.loads((results / "mirror.tiny.json").read_text())
        assert mirror["figures"]["rows"] == sum(mirror["rows_per_table"].values()) > 0
        for table, per_worker in (mirror["citus_placement"] or {}).items():
            assert set(per_worker) == {"worker1", "worker2"}, table
    # the network's peak RSS is stated with its moment and each process's share then
    net = json.loads((results / "network.tiny.json").read_text())["figures"]
    assert 0 < net["peak_at_s"] <= net["wall_s"] + 1
    assert len(net["rss_at_peak_by_process_mb"]) >= 2          # the command and its workers
    assert abs(sum(net["rss_at_peak_by_process_mb"]) - net["peak_rss_gb"] * 1024) <= len(
        net["rss_at_peak_by_process_mb"]) + 2
    assert net["peak_after_line"]
    line = json.loads((results / "line_year.tiny.json").read_text())["figures"]
    assert line["passes"] > 0 and line["partitions"] > 0
    # so is the line-year's (its highest run's)
    assert abs(sum(line["rss_at_peak_by_process_mb"]) - line["peak_rss_gb"] * 1024) <= len(
        line["rss_at_peak_by_process_mb"]) + 2
    assert line["peak_after_line"] and line["peak_at_s"] > 0
    # the sun masks spare rays and change no result (the all-rays leg of the same round)
    assert line["masks_equal_all_rays"] is True
    assert line["sun_rays_masked"] > 0 and line["sun_rays_cast"] > 0
    # the trees' cost is measured on a demo that has trees, in the three legs of a round
    sky = json.loads((results / "sky.tiny.json").read_text())["figures"]
    assert sky["trees_in_city_model"] > 0
    assert len(sky["perez_ratio_rounds"]) == len(sky["trees_ratio_rounds"]) == len(sky["both_ratio_rounds"]) == 1
    if "postgis" in names:
        pg = json.loads((results / "postgis.tiny.json").read_text())["figures"]
        # every disagreement between PostGIS and Embree must be a graze (1 mm changes it)
        assert pg["agreement_apart_from_grazes"] == 1.0


def test_the_ceiling_is_the_best_one_process_over_the_best_two():
    """The machine's ceiling takes the statistic of the runs' speed-up: the best time of one
    process over the best of two, whichever probes they came from."""
    sys.path.insert(0, str(ROOT))
    from benchmarks.bench_scaling import ceiling

    probes = [{"kernel": {"s_1_process": 10.0, "s_2_processes": 6.0}},
              {"kernel": {"s_1_process": 9.0, "s_2_processes": 6.5}},
              {"kernel": {"s_1_process": 12.0, "s_2_processes": 5.5}}]
    assert ceiling(probes, "kernel") == round(2 * 9.0 / 5.5, 3)
