"""Helpers shared by the pipeline benchmarks.

- :class:`PeakRSS`: peak resident memory of this process and all its descendants (the Dask
  nanny and worker processes of a LocalCluster), sampled by a thread with psutil;
- :func:`prepare_demo`: the demo scenario generated and ingested once into
  ``benchmarks/work/demo-<size>/`` (gitignored), timed the first time and cached after;
- :func:`demo_config` / :func:`run_pipeline`: a configuration for a part of the demo and one
  timed :func:`vipvflow.simulation.run.run_simulation` of it from a fresh output folder;
- :func:`demo_run`: a finished demo run to read (the repository's, or a fresh one).
"""
from __future__ import annotations

import json
import os
import resource
import shutil
import threading
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
WORK = HERE / "work"
YEAR = 2024


class PeakRSS:
    """Peak RSS (MB) of a process tree, sampled every *interval_s* while the block runs.

    ``with PeakRSS() as mem: ...`` then ``mem.peak_mb`` (sum over the tree at the sampled
    moment of its largest total) and ``mem.peak_self_mb`` (this process alone).  Sampling
    misses peaks shorter than the interval; the OS high-water mark of this process is also
    taken into account for ``peak_self_mb``.  A sample costs ~2.5 ms of CPU (psutil walks
    ``/proc`` for the children), taken from the run it measures when the workers fill the
    cores: 0.25 s keeps that to 1 % of a core.

    With *pss* also ``mem.peak_pss_mb``: the same peak of the proportional set sizes
    (``/proc/<pid>/smaps_rollup``: each shared page split among the processes mapping it).
    The sum of RSS counts the pages a forked Dask worker shares with the forkserver it came
    from (the imported libraries) once per process; the sum of PSS counts them once, so it
    is the memory the run takes from the machine.  A PSS sample costs a few ms more.
    """

    def __init__(self, pid: int | None = None, interval_s: float = 0.25, pss: bool = False):
        self.pid = pid or os.getpid()
        self.interval_s = interval_s
        self.pss = pss
        self.peak_mb = 0.0
        self.peak_pss_mb = 0.0
        self.peak_self_mb = 0.0
        self.by_pid: dict[int, float] = {}       # each process's own peak RSS (MB)
        self.peak_at_s = 0.0                      # when the total peaked (s after the start)
        self.at_peak_mb: list[int] = []           # each process's RSS then (MB, largest first)
        self.samples = 0
        self.series: list[tuple] = []             # each sample: s, total MB, each process's bytes
        self.pids: list[list[int]] = []           # each sample's processes, in the order of its bytes
        self.procs: dict[int, str] = {}            # each child's parent pid and command line
        self._t0 = time.perf_counter()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._poll, daemon=True, name="peak-rss")

    def _sample(self, root) -> None:
        import psutil

        total = 0
        try:
            own = root.memory_info().rss
        except psutil.Error:
            return
        total = own
        children = root.children(recursive=True)
        self.by_pid[root.pid] = max(self.by_pid.get(root.pid, 0.0), own / 2**20)
        now, pids = [own], [root.pid]
        for child in children:
            try:
                rss = child.memory_info().rss
            except psutil.Error:
                continue
            total += rss
            now.append(rss)
            pids.append(child.pid)
            if child.pid not in self.procs:
                try:
                    self.procs[child.pid] = f"{child.ppid()} " + " ".join(child.cmdline())[-100:]
                except psutil.Error:
                    pass
            self.by_pid[child.pid] = max(self.by_pid.get(child.pid, 0.0), rss / 2**20)
        self.series.append((time.perf_counter() - self._t0, total / 2**20, now))
        self.pids.append(pids)
        if total / 2**20 > self.peak_mb:
            self.peak_mb = total / 2**20
            self.peak_at_s = time.perf_counter() - self._t0
            self.at_peak_mb = sorted((round(v / 2**20) for v in now), reverse=True)
        if self.pss:
            pss = 0
            for p in [root, *children]:
                try:
                    pss += p.memory_full_info().pss
                except psutil.Error:
                    pass
            self.peak_pss_mb = max(self.peak_pss_mb, pss / 2**20)
        self.peak_self_mb = max(self.peak_self_mb, own / 2**20)
        self.samples += 1

    def _poll(self) -> None:
        import psutil

        root = psutil.Process(self.pid)
        while not self._stop.is_set():
            self._sample(root)
            self._stop.wait(self.interval_s)

    def __enter__(self) -> "PeakRSS":
        self._t0 = time.perf_counter()
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()
        if self.pid == os.getpid():
            self.peak_self_mb = max(self.peak_self_mb,
                                    resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024)
        out = os.environ.get("VIPVFLOW_BENCH_RSS_SERIES")
        if out:         # every sample: s after the start, each process's pid and MB
            rows = [[round(s, 2), {p: round(b / 2**20) for p, b in zip(pids, now)}]
                    for (s, _, now), pids in zip(self.series, self.pids)]
            with open(out, "a") as f:       # one line per sampler (a benchmark may run several)
                f.write(json.dumps({"root": self.pid, "processes": self.procs, "samples": rows}) + "\n")


def _quiet(*_args, **_kw) -> None:
    pass


def demo_paths(size: str) -> dict:
    root = WORK / f"demo-{size}"
    return {"root": root, "input": root / "input", "data": root / "data"}


def demo_config(size: str = "full", *, data_dir: Path | None = None, out_dir: Path | None = None,
                routes=None, months=None, n_workers: int | None = None, inputs: dict | None = None,
                scenario: str | None = None):
    """The demo scenario of *size* with its inputs and data under ``benchmarks/work``."""
    from vipvflow.config import load_config

    p = demo_paths(size)
    over = {
        "scenario": scenario or f"bench-{size}",
        "data_dir": str(data_dir or p["data"]),
        "out_dir": str(out_dir or WORK / "runs"),
        "demo": {"enabled": inputs is None, "seed": 42, "size": size},
        "inputs": inputs or {"citygml": [str(p["input"] / "demo_city.gml")],
                             "gtfs": str(p["input"] / "demo_gtfs.zip"),
                             "cams": [str(p["input"] / "cams_radiation_demo.csv")]},
        "run": {"months": list(months or range(1, 13)), "routes": routes},
    }
    if n_workers:
        over["dask"] = {"n_workers": n_workers}
    return load_config(None, over)


def prepare_demo(size: str = "full", year: int = YEAR) -> dict:
    """Generate and ingest the demo of *size* once; return the times of the first preparation
    (``generate_s``, ``ingest_s``) and whether this call found it already done."""
    from vipvflow.simulation.prepare import ensure_demo, ensure_ingested

    p = demo_paths(size)
    stamp = p["root"] / "prepared.json"
    cfg = demo_config(size)
    t0 = time.perf_counter()
    ensure_demo(cfg, year, say=_quiet)
    t1 = time.perf_counter()
    ensure_ingested(cfg, say=_quiet)
    t2 = time.perf_counter()
    cached = stamp.exists() and (t2 - t0) < 5.0
    if not cached:
        stamp.write_text(json.dumps({"generate_s": round(t1 - t0, 2), "ingest_s": round(t2 - t1, 2),
                                     "size": size, "year": year}))
    info = json.loads(stamp.read_text())
    info["cached"] = cached
    return info


def _finished(run_dir: Path) -> bool:
    return all((run_dir / f).exists() for f in ("manifest.json", "segment_month.parquet", "segments.parquet"))


def demo_run(tiny: bool, env: str, name: str) -> tuple[Path, str]:
    """A finished demo run for a benchmark that reads one, and where it came from: ``$<env>``;
    the repository's ``out/demo/2024`` when a demo run is there (``vipvflow simulate
    --config demo --year 2024``); else a fresh run of the full demo for the year made here
    (~3 min; the caller deletes it when the source starts with "fresh"). *tiny*: a fresh run
    of the small demo, June."""
    given = os.environ.get(env)
    if given and not tiny:
        return Path(given), env
    local = HERE.parent / "out" / "demo" / "2024"
    if not tiny and _finished(local):
        return local, "out/demo/2024"
    size = "small" if tiny else "full"
    prepare_demo(size)
    # a fresh output folder (deleted after use): never a run of an older configuration
    cfg = demo_config(size, months=[6] if tiny else None, scenario=f"bench-{name}-{size}",
                      out_dir=fresh_dir(f"{name}-{size}"))
    return run_pipeline(cfg)["run_dir"], f"fresh {size} demo run"


def fresh_dir(name: str) -> Path:
    """An empty folder ``benchmarks/work/runs/<name>-<pid>-<ns>`` (nothing to resume)."""
    path = WORK / "runs" / f"{name}-{os.getpid()}-{time.time_ns()}"
    path.mkdir(parents=True)
    return path


def remove(path: Path) -> None:
    """Delete a benchmark's output folder unless ``VIPVFLOW_BENCH_KEEP`` is set."""
    if not os.environ.get("VIPVFLOW_BENCH_KEEP"):
        shutil.rmtree(path, ignore_errors=True)


def run_pipeline(cfg, year: int = YEAR, n_workers: int | None = None, rss_interval_s: float = 0.25,
                 scheduler: str | None = None, pss: bool = False,
                 geometry_cache: bool = False) -> dict:
    """One :func:`run_simulation` of *cfg* (on the cluster at *scheduler*, if given): wall
    time, peak RSS of the process tree, manifest, and the CPU time of this process (the
    command's: scheduler, client, prepare, the reduce's joins; all its threads) and of the
    child processes that ended during the run (a LocalCluster's workers and nannies).

    The data dir's geometry cache (:mod:`vipvflow.simulation.geometry_cache`) is emptied
    first, so every run computes its tiles' geometry as a first run does; with
    *geometry_cache* an earlier run's entries are used."""
    from vipvflow.simulation.run import run_simulation
    from vipvflow.store import DataDir

    if not geometry_cache:
        shutil.rmtree(DataDir(cfg.data_dir).geometry_cache(), ignore_errors=True)

    log: list[str] = []
    said: list[float] = []                  # when each line of *log* was said (s after the start)
    with PeakRSS(interval_s=rss_interval_s, pss=pss) as mem:
        cpu0, children0 = time.process_time(), _children_cpu()
        t0 = time.perf_counter()

        def say(*a):
            said.append(time.perf_counter() - t0)
            log.append(" ".join(map(str, a)))

        run_dir = run_simulation(cfg, year, scheduler=scheduler, n_workers=n_workers, say=say)
        wall = time.perf_counter() - t0
        cpu, children = time.process_time() - cpu0, _children_cpu() - children0
    manifest = json.loads((run_dir / "manifest.json").read_text())
    before = [line for t, line in zip(said, log) if t <= mem.peak_at_s]
    return {"wall_s": wall, "peak_rss_mb": mem.peak_mb, "peak_rss_main_mb": mem.peak_self_mb,
            "peak_pss_mb": mem.peak_pss_mb if pss else None,
            "peak_rss_by_process_mb": sorted((round(v) for v in mem.by_pid.values()), reverse=True),
            # the moment of the peak: when, each process's RSS then, and the run's last line before
            "peak_at_s": round(mem.peak_at_s, 1), "rss_at_peak_by_process_mb": mem.at_peak_mb,
            "peak_after_line": before[-1][:120] if before else None,
            "peak_rss_by_step_mb": peaks_by_step(mem.series, t0 - mem._t0, manifest.get("timings_s", {})),
            "cpu_s_command": cpu, "cpu_s_workers": children,
            "run_dir": run_dir, "manifest": manifest, "log": log}


def peaks_by_step(series: list, run_start: float, timings: dict) -> dict:
    """The process tree's peak RSS (MB, and each process's then) in each step of a run:
    before the map (the cluster's start, the timeline), the map, and each step of the
    reduce, from *series* (the sampler's ``(s, MB, bytes of each process)``), the run's start
    on the sampler's clock and the run's own *timings* (``map_s``, ``reduce_<step>_s``,
    ``restart_s``, ``close_wait_s``, ``total_s``).  The steps are placed back from the run's
    end: the reduce's steps run one after another, the workers' restart (a LocalCluster's)
    just before them, the map before that."""
    if "total_s" not in timings or "map_s" not in timings:
        return {}
    steps = [(k[len("reduce_"):-2], v) for k, v in timings.items()
             if k.startswith("reduce_") and k.endswith("_s") and k != "reduce_s"]
    end = run_start + timings["total_s"] - timings.get("close_wait_s", 0.0)
    start = end - sum(v for _, v in steps)
    map_end = start - timings.get("restart_s", 0.0)
    bounds = [("before_map", run_start, map_end - timings["map_s"]), ("map", map_end - timings["map_s"], map_end)]
    if "restart_s" in timings:
        bounds.append(("restart", map_end, start))
    for name, seconds in steps:
        bounds.append((f"reduce_{name}", start, start + seconds))
        start += seconds
    out = {}
    for name, lo, hi in bounds:
        top = max((s for s in series if lo <= s[0] < hi), key=lambda s: s[1], default=None)
        # the peak, and each process's RSS then (largest first); None: no sample in the step
        out[name] = None if top is None else {
            "mb": round(top[1]), "by_process_mb": sorted((round(v / 2**20) for v in top[2]), reverse=True)}
    return out


def _children_cpu() -> float:
    """User and system CPU seconds of this process's ended (and waited for) children, and of
    its live children with their own ended children: a LocalCluster's workers are forked
    by a forkserver (:mod:`vipvflow.simulation.worker_preload`) that outlives the run and
    waits for them itself."""
    import psutil

    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    total = r.ru_utime + r.ru_stime
    for child in psutil.Process().children():
        try:
            t = child.cpu_times()
        except psutil.Error:
            continue
        total += t.user + t.system + t.children_user + t.children_system
    return total


def stage_split(manifest: dict) -> dict:
    """Worker time per stage (s, summed over partitions) and each stage's share of the sum.

    Stages: each tile's geometry (sky view factor, reflector and horizon-band rays, the
    crowns' sky cells: ``geometry_s``, once per tile, in its first partition's timings; read
    back where the run folder has it; with its packing for the fused kernel where the tile
    is one task), pass generation, radiation lookup, ray-batch setup,
    Embree rays, irradiance components (direct, diffuse, reflected), packing,
    per-trip/segment/hour aggregation, and writing the partition files; ``load_and_other``
    is the rest of the irradiance call (the worker's first load of the radiation table and
    of the tile's BVH).
    """
    t = manifest.get("partition_timings_s", {})
    stages = {
        "geometry": t.get("geometry_s", 0.0),
        "passes": t.get("passes_s", 0.0),
        "lookup": t.get("irradiance_lookup_s", 0.0),
        "ray_setup": t.get("irradiance_ray_setup_s", 0.0),
        "rays": t.get("irradiance_rays_s", 0.0),
        "components": t.get("irradiance_components_s", 0.0),
        "sun_masks": t.get("irradiance_sun_masks_s", 0.0),
        "pack": t.get("irradiance_pack_s", 0.0),
        "aggregate": t.get("reduce_s", 0.0),
        "write": t.get("write_s", 0.0),
    }
    untracked = t.get("irradiance_s", 0.0) - sum(stages[k] for k in ("lookup", "ray_setup", "rays",
                                                                     "components", "sun_masks", "pack"))
    # the rest of irradiance_s: the worker's first load of the radiation table (sun positions)
    # and of the tile's BVH, both cached afterwards, and the segment index of evaluate_passes
    stages["load_and_other"] = max(untracked, 0.0)
    total = sum(stages.values())
    out = {f"{k}_s": round(v, 2) for k, v in stages.items()}
    out.update({f"{k}_share": round(v / total, 3) if total else 0.0 for k, v in stages.items()})
    out["partition_work_s"] = round(total, 2)
    return out
