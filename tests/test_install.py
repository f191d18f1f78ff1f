"""A plain (non-editable) install: the wheel built from the sources, installed in a fresh
venv, works from a directory that is not the repository, with the configuration it ships."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pandas as pd
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[1]
SHIPPED = ["default.yaml", "demo.yaml", "luxembourg.yaml", "pv_systems.yaml", "vehicles.yaml"]


def _run(cmd, cwd, env, timeout=600) -> subprocess.CompletedProcess:
    res = subprocess.run([str(c) for c in cmd], cwd=cwd, env=env, capture_output=True, text=True,
                         timeout=timeout)
    assert res.returncode == 0, f"{cmd} exited {res.returncode}:\n{res.stdout}\n{res.stderr}"
    return res


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> dict:
    """The wheel of a copy of the sources (the build writes nothing into the repository),
    installed in a new venv that borrows this environment's packages through a plain path
    entry (no network, no editable vipvflow: that one's .pth file is not read)."""
    tmp = tmp_path_factory.mktemp("install")
    src = tmp / "src_copy"
    for folder in ("src", "conf"):
        shutil.copytree(ROOT / folder, src / folder,
                        ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    for name in ["pyproject.toml", "README.md", "LICENSE"]:
        shutil.copy(ROOT / name, src / name)
    env = {k: v for k, v in os.environ.items() if not k.startswith("PYTHON")}
    wheels = tmp / "wheels"
    _run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--wheel-dir", wheels, src],
         cwd=tmp, env=env)
    wheel = next(wheels.glob("vipvflow-*.whl"))

    venv = tmp / "venv"
    _run([sys.executable, "-m", "venv", "--without-pip", venv], cwd=tmp, env=env)
    py = venv / "bin" / "python"
    site = Path(_run([py, "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                     cwd=tmp, env=env).stdout.strip())
    ours = {sysconfig.get_path("purelib"), sysconfig.get_path("platlib")}
    (site / "borrowed_packages.pth").write_text("\n".join(sorted(ours)) + "\n")
    # --no-index: every dependency must already be satisfied by the borrowed packages
    _run([py, "-m", "pip", "install", "-q", "--no-index", wheel], cwd=tmp, env=env)
    return {"wheel": wheel, "venv": venv, "py": py, "bin": venv / "bin" / "vipvflow",
            "env": env, "tmp": tmp}


def test_wheel_carries_configuration_and_licence(installed):
    names = zipfile.ZipFile(installed["wheel"]).namelist()
    for name in SHIPPED:
        assert f"vipvflow/conf/{name}" in names
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names), names
    meta = next(n for n in names if n.endswith(".dist-info/METADATA"))
    text = zipfile.ZipFile(installed["wheel"]).read(meta).decode()
    assert "License-Expression: MIT" in text
    assert "Provides-Extra: db" in text and "Provides-Extra: app" in text


def test_the_wheel_names_every_package_and_conf_has_one_copy():
    """pyproject.toml lists the packages by hand (conf/ is mapped in as ``vipvflow.conf``):
    every package under src/ is in the list, and the shipped YAML files exist once, in conf/."""
    import tomllib

    setup = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    found = {".".join(p.parent.relative_to(ROOT / "src").parts)
             for p in (ROOT / "src").rglob("__init__.py")}
    assert set(setup["packages"]) == found | {"vipvflow.conf"}
    assert setup["package-dir"]["vipvflow.conf"] == "conf"
    assert sorted(p.name for p in (ROOT / "conf").glob("*.yaml")) == sorted(SHIPPED + ["paper.yaml"])
    assert not list((ROOT / "src").rglob("*.yaml"))


def test_installed_config_from_another_directory(installed, tmp_path):
    where = _run([installed["py"], "-c", "import vipvflow; print(vipvflow.__file__)"],
                 cwd=tmp_path, env=installed["env"]).stdout.strip()
    assert Path(where).is_relative_to(installed["venv"])            # the wheel's copy, not src/
    defaults = _run([installed["bin"], "config"], cwd=tmp_path, env=installed["env"]).stdout
    assert yaml.safe_load(defaults)["scenario"] == "default"
    demo = _run([installed["bin"], "config", "--config", "demo"], cwd=tmp_path,
                env=installed["env"]).stdout
    cfg = yaml.safe_load(demo)
    assert cfg["scenario"] == "demo" and cfg["demo"]["enabled"] is True
    bad = subprocess.run([installed["bin"], "config", "--config", "nowhere"], cwd=tmp_path,
                         env=installed["env"], capture_output=True, text=True)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert bad.stderr.strip().splitlines() == [
        "vipvflow config: error: nowhere: file not found (shipped scenarios by name: demo, luxembourg, paper)"]


def test_installed_small_simulation_writes_under_out(installed, tmp_path):
    """The small demo for June, generated and simulated by the installed command in another
    directory; inputs, data and results land under --out."""
    scenario = {"scenario": "small", "data_dir": "data/small", "out_dir": "out",
                "demo": {"enabled": True, "seed": 42, "size": "small"},
                "inputs": {"citygml": ["data/small/input/demo_city.gml"],
                           "gtfs": "data/small/input/demo_gtfs.zip",
                           "cams": ["data/small/input/cams_radiation_demo.csv"]},
                "run": {"months": [6]}}
    (tmp_path / "small.yaml").write_text(yaml.safe_dump(scenario))
    work = tmp_path / "work"
    _run([installed["bin"], "simulate", "--config", "small.yaml", "--year", "2024",
          "--workers", "1", "--out", work], cwd=tmp_path, env=installed["env"], timeout=900)
    assert (work / "data" / "small" / "input" / "demo_city.gml").is_file()
    run = work / "out" / "small" / "2024"
    manifest = json.loads((run / "manifest.json").read_text())
    assert manifest["versions"]["vipvflow"] == "0.1.0"
    trips = pd.read_parquet(run / "trip_energy.parquet")
    june = pd.to_datetime(trips["service_date"])
    assert len(trips) > 0 and (june.dt.month == 6).all()
    assert trips["pv_kwh"].sum() > 0
    assert not (tmp_path / "out").exists() and not (tmp_path / "data").exists()
