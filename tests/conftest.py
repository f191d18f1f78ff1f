"""Shared fixtures: the public sample data in ../shared/data and the generated demo scenario."""
from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("VIPVFLOW_SHARED_DATA", ROOT.parent / "shared" / "data"))
TEST_DATA = ROOT / "tests" / "data"
ARTIFACTS = ROOT / "tests" / "artifacts"


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
