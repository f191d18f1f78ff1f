"""Configuration: defaults equal the schema, scenarios validate, errors name file, key and reason."""
from pathlib import Path

import pytest
import yaml

from vipvflow.config import CONF_DIR, Config, load_config
from vipvflow.errors import ConfigError


def test_default_yaml_states_every_default_of_the_schema():
    from vipvflow.config import _read_yaml

    on_disk = Config.model_validate(_read_yaml(CONF_DIR / "default.yaml"))
    assert on_disk.model_dump() == Config().model_dump()


@pytest.mark.parametrize("name", ["demo.yaml", "luxembourg.yaml"])
def test_scenarios_validate(name):
    cfg = load_config(CONF_DIR / name)
    assert cfg.scenario == name.removesuffix(".yaml")
    pv = cfg.pv_system()
    assert pv.kwp == 3.5 and pv.performance_ratio == 0.75 and pv.area_share == 0.8


def test_unknown_key_names_file_and_key(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("scenario: x\ncity:\n  tile_size: 250\n")
    with pytest.raises(ConfigError) as err:
        load_config(bad)
    assert str(bad) in str(err.value) and "city.tile_size" in str(err.value)
    assert "unknown key" in str(err.value)


def test_wrong_value_names_reason(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("irradiance:\n  diffuse_model: perez\neconomics:\n  soc_window: [0.9, 0.2]\n")
    with pytest.raises(ConfigError) as err:
        load_config(bad)
    text = str(err.value)
    assert "irradiance.diffuse_model" in text and "isotropic" in text
    assert "soc_window" in text


def test_unknown_catalog_entry(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("pv:\n  system: perovskite_9000\n")
    with pytest.raises(ConfigError, match="perovskite_9000.*not in the catalog"):
        load_config(bad)


def test_overrides_apply_last(tmp_path):
    cfg = load_config(CONF_DIR / "demo.yaml", overrides={"dask": {"n_workers": 1}})
    assert cfg.dask.n_workers == 1 and cfg.city.tile_size_m == 500


def test_broken_yaml_names_line(tmp_path):
    bad = tmp_path / "broken.yaml"
    bad.write_text("scenario: x\ncity: [unclosed\n")
    with pytest.raises(ConfigError, match=r"broken.yaml: line \d+"):
        load_config(bad)


def test_cli_config_prints_merged(capsys):
    from vipvflow.cli import main

    assert main(["config", "--config", str(CONF_DIR / "demo.yaml")]) == 0
    out = yaml.safe_load(capsys.readouterr().out.split("# pv system")[0])
    assert out["scenario"] == "demo" and out["trajectory"]["segment_length_m"] == 10.0


def test_cli_bad_config_is_one_line(tmp_path, capsys):
    from vipvflow.cli import main

    bad = tmp_path / "bad.yaml"
    bad.write_text("nonsense: 1\n")
    assert main(["config", "--config", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "nonsense" in err and str(bad) in err


def test_scenarios_by_name_from_any_directory(tmp_path, monkeypatch):
    """The shipped scenarios by name, and the repository's conf/<name>.yaml paths from anywhere;
    a local file of that name wins."""
    from vipvflow.config import scenario_path, shipped_scenarios

    monkeypatch.chdir(tmp_path)
    assert shipped_scenarios() == ["demo", "luxembourg", "paper"]
    for name in ("demo", "demo.yaml", "conf/demo.yaml"):
        assert scenario_path(name) == CONF_DIR / "demo.yaml"
        assert load_config(name).scenario == "demo"
    (tmp_path / "demo.yaml").write_text("scenario: mine\n")
    assert load_config("demo.yaml").scenario == "mine"
    with pytest.raises(ConfigError, match="^elsewhere/demo.yaml: file not found"):
        load_config("elsewhere/demo.yaml")
