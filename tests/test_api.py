"""The Python API: the public names, typed tables, and docs/api.md's worked example run as
written."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

ROOT = Path(__file__).resolve().parents[1]


def test_public_names_and_their_docstrings():
    import vipvflow

    for name in ("load_config", "simulate", "open_run", "Run", "TripModel", "PVChoice"):
        obj = getattr(vipvflow, name)
        assert obj.__doc__ and len(obj.__doc__) > 40, name
    for fn in (vipvflow.simulate, vipvflow.open_run, vipvflow.Run.table):
        assert re.search(r"Parameters\n\s*-{10}\n", fn.__doc__) and re.search(r"Returns\n\s*-{7}\n", fn.__doc__)
    with pytest.raises(AttributeError):
        vipvflow.no_such_thing  # noqa: B018


def test_open_run_gives_typed_tables(small_run):
    import geopandas as gpd

    import vipvflow
    from vipvflow.simulation.dictionary import OUTPUTS

    run = vipvflow.open_run(small_run)
    assert run.year == 2024 and run.summary["coverage"] > 0 and run.data_dir.is_dir()
    assert set(run.files) == set(OUTPUTS) and all(p.is_file() for p in run.files.values())
    bd = run.block_day
    assert str(bd["window_start_utc"].dtype) == "datetime64[us, UTC]"
    assert pd.api.types.is_datetime64_dtype(bd["service_date"]) and bd["service_date"].dt.month.eq(6).all()
    assert (bd["month"] == pd.Timestamp("2024-06-01")).all()
    assert isinstance(run.segments, gpd.GeoDataFrame) and run.segments.crs.to_epsg() == 2169
    cols = run.columns("trip_energy")
    assert list(cols["column"]) == list(OUTPUTS["trip_energy"].columns)
    assert cols.set_index("column").loc["service_date", "unit"] == "date"
    with pytest.raises(KeyError):
        run.table("nope")


def test_docs_api_page_runs_as_written(demo_small, tmp_path):
    """The code blocks of docs/api.md, one after the other, as a notebook would run them
    (``python -c``: a main module without a file, as in Jupyter), in an empty directory; the small demo's inputs of this session are put
    where the page's run looks for them (the same generator, seed, size and year: its
    generation is then skipped, nothing else changes)."""
    import shutil

    from vipvflow.simulation.prepare import mark_demo

    pytest.importorskip("duckdb")
    text = (ROOT / "docs" / "api.md").read_text()
    code = "\n".join(re.findall(r"```python\n(.*?)```", text, flags=re.S))
    assert "vipvflow.simulate(" in code and "duckdb" in code and ".plot(" in code
    inputs = tmp_path / "api-example" / "data" / "demo" / "input"
    shutil.copytree(demo_small, inputs)
    mark_demo(inputs, 2024, 42, "small")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), os.environ.get("PYTHONPATH", "")])}
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                         env=env, timeout=900)
    assert res.returncode == 0, res.stdout[-3000:] + res.stderr[-3000:]
    out = res.stdout
    assert re.search(r"\d+ kWh/kWp a year the batteries take, coverage \d+\.\d\d %", out), out
    assert (tmp_path / "api-example" / "yield_map.png").stat().st_size > 10_000
    assert re.search(r"1 +Centre +\d+", out) and re.search(r"1 +Westfeld +\d+", out), out
    assert "1 to Centre, paper:" in out or "1 to Westfeld, paper:" in out, out
    losses = re.findall(r", (paper|pvlib): .* shading loss (\d+\.\d) %", out)
    assert len(losses) == 2 and losses[0][1] == losses[1][1], losses    # one definition, both models
    assert not list(tmp_path.glob("*.png"))                             # nothing outside api-example/
