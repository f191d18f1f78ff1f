"""The air temperature of the city: the shipped climatology, chosen by the city's place."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from vipvflow.config import load_config
from vipvflow.inputs.climate import monthly_air_temperature

#: Luxembourg-Findel 1991-2020 monthly normals (MeteoLux), deg C
FINDEL = [0.8, 1.6, 5.0, 8.9, 12.8, 16.1, 18.1, 17.6, 13.9, 9.6, 4.9, 1.7]


def test_climatology_at_luxembourg_is_near_findels_normals():
    """The reanalysis at Findel (49.63 N, 6.22 E) against the station's own normals of the
    same 30 years: within 1 K every month (a flat, inland place)."""
    got = monthly_air_temperature(49.63, 6.22)
    assert np.abs(np.subtract(got, FINDEL)).max() < 1.0, got


def test_climatology_follows_the_place():
    """Each city its own: the southern hemisphere's summer in January, the tropics warm all
    year, a longitude given either way round the same place."""
    sydney = monthly_air_temperature(-33.87, 151.21)
    berlin = monthly_air_temperature(52.52, 13.40)
    assert sydney[0] > sydney[6] + 5 and berlin[6] > berlin[0] + 15
    assert min(monthly_air_temperature(1.35, 103.82)) > 24          # Singapore
    assert monthly_air_temperature(40.4, -3.7) == monthly_air_temperature(40.4, 356.3)
    with pytest.raises(ValueError):
        monthly_air_temperature(float("nan"), 0.0)


def test_run_takes_the_radiation_place_unless_the_scenario_names_its_own(tmp_path):
    """No table in the scenario: the climatology at the radiation file's place (not another
    city's); a table in the scenario wins; the paper's mode keeps the paper's."""
    from vipvflow.errors import ConfigError
    from vipvflow.store import DataDir

    cfg = load_config(None, {"data_dir": str(tmp_path / "d")})
    with pytest.raises(ConfigError, match="monthly_mean_temperature_c"):
        cfg.monthly_temperature_c()
    path = DataDir(tmp_path / "d").radiation.table
    path.parent.mkdir(parents=True)
    pd.DataFrame({"t_utc": [0], "lat": [52.52], "lon": [13.40], "ghi": [0.0]}).to_parquet(path)
    assert cfg.monthly_temperature_c() == monthly_air_temperature(52.52, 13.40)
    assert "NCEP" in cfg.temperature_source() and "52.520 N" in cfg.temperature_source()
    own = load_config(None, {"data_dir": str(tmp_path / "d"),
                             "climate": {"monthly_mean_temperature_c": list(range(12))}})
    assert own.monthly_temperature_c() == list(range(12))
    assert load_config("paper").monthly_temperature_c() == FINDEL
