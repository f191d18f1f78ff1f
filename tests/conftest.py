"""Shared fixtures: the public sample data in ../shared/data and the generated demo scenario."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("VIPVFLOW_SHARED_DATA", ROOT.parent / "shared" / "data"))
TEST_DATA = ROOT / "tests" / "data"
ARTIFACTS = ROOT / "tests" / "artifacts"
CHROMIUM = Path("/usr/bin/chromium")
# CI (.ci/run) installs the system packages first and sets this: there a missing one is a failure
REQUIRE_SYSTEM_DEPS = os.environ.get("VIPVFLOW_REQUIRE_SYSTEM_DEPS") == "1"


def missing_system_package(problem: str, packages: str) -> None:
    """Skip (fail under VIPVFLOW_REQUIRE_SYSTEM_DEPS=1) with one line saying what to install."""
    line = f"{problem}: install it with `make system-deps` (Debian: apt-get install {packages})"
    if REQUIRE_SYSTEM_DEPS:
        pytest.fail(line)
    pytest.skip(line)


@pytest.fixture(scope="session")
def chromium() -> Path:
    """The headless browser of the web-app tests; skipped with what to install when absent."""
    if not CHROMIUM.exists():
        missing_system_package(f"Chromium not found at {CHROMIUM}", "chromium")
    return CHROMIUM


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """``../shared/data`` (public samples); skipped with a reason in a user's clone without it."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"public sample data not found at {SHARED_DATA} (only in CI and developer machines)")
    return SHARED_DATA


@pytest.fixture(scope="session")
def test_data() -> Path:
    return TEST_DATA


@pytest.fixture(scope="session")
def artifacts() -> Path:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    return ARTIFACTS


@pytest.fixture(scope="session")
def demo_small(tmp_path_factory) -> Path:
    """The small demo scenario (same generator, fewer buildings and a short line) for 2024."""
    from vipvflow.demo import generate_demo

    out = tmp_path_factory.mktemp("demo_small")
    generate_demo(out, year=2024, seed=42, size="small")
    return out


def write_small_config(root: Path, inputs: Path, months=(6,), name: str = "small") -> Path:
    """A scenario YAML over the small demo inputs in *inputs*, data and outputs under *root*."""
    import yaml

    conf = {
        "scenario": name, "data_dir": str(root / "data"), "out_dir": str(root / "out"),
        "demo": {"enabled": True, "seed": 42, "size": "small"},
        "inputs": {"citygml": [str(inputs / "demo_city.gml")], "gtfs": str(inputs / "demo_gtfs.zip"),
                   "cams": [str(inputs / "cams_radiation_demo.csv")]},
        "run": {"months": list(months)},
    }
    path = root / f"{name}.yaml"
    path.write_text(yaml.safe_dump(conf))
    return path


@pytest.fixture(scope="session")
def small_config(tmp_path_factory, demo_small) -> Path:
    """Scenario YAML of the small demo for June 2024 (ingested once per session)."""
    root = tmp_path_factory.mktemp("small_scenario")
    return write_small_config(root, demo_small)


@pytest.fixture(scope="session")
def small_run(small_config) -> Path:
    """A finished simulation of the small demo (June 2024) on a real 2-worker LocalCluster."""
    from vipvflow.config import load_config
    from vipvflow.simulation import run_simulation

    cfg = load_config(small_config, overrides={"dask": {"n_workers": 2}})
    return run_simulation(cfg, 2024, say=lambda *a: None)
