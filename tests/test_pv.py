"""PV energy: paper mode by hand, pvlib mode cooled by the bus's own speed."""
from __future__ import annotations

import numpy as np
import pytest

from vipvflow.config import PVSystem
from vipvflow.models.pv import energy, energy_paper, power_pvlib

SYSTEM = PVSystem(name="t", kwp=3.5, roof_area_m2=30.0, area_share=0.6, performance_ratio=0.75)


def test_paper_mode_by_hand():
    # 3.5 kWp x 800/1000 x 0.75 x 1 h = 2.1 kWh; a 36 s segment gets 1/100 of it
    assert energy_paper(800.0, 3600.0, 3.5, 0.75) == pytest.approx(2.1)
    np.testing.assert_allclose(energy_paper([800.0, 0.0], [36.0, 36.0], 3.5, 0.75), [0.021, 0.0])
    assert energy(800.0, 3600.0, SYSTEM, "paper") == pytest.approx(2.1)


def test_pvlib_mode_faster_bus_runs_cooler():
    poa = np.array([900.0, 900.0])
    speed = np.array([0.0, 15.0])
    pac, tcell = power_pvlib(poa, SYSTEM, temp_air_c=25.0, vehicle_speed_mps=speed, wind_mps=1.0)
    # SAPM open rack glass/polymer: T = E exp(a + b ws) + Ta + E/1000 dT, a=-3.56, b=-0.075, dT=3
    ws = speed + 1.0
    expected = 900 * np.exp(-3.56 - 0.075 * ws) + 25 + 0.9 * 3
    np.testing.assert_allclose(tcell, expected, rtol=1e-9)
    assert tcell[1] < tcell[0] and pac[1] > pac[0]
    # PVWatts DC at the cell temperature, then 14 % losses; AC below DC
    pdc = 3500 * 0.9 * (1 - 0.0037 * (tcell - 25)) * 0.86
    assert (pac < pdc).all() and (pac > 0.9 * pdc).all()
    e = energy(poa, [3600.0, 3600.0], SYSTEM, "pvlib", temp_air_c=25.0,
               vehicle_speed_mps=speed, wind_mps=1.0)
    np.testing.assert_allclose(e, pac / 1000.0)
    faiman = SYSTEM.model_copy(update={"temperature_model": "faiman"})
    _, tf = power_pvlib(poa, faiman, 25.0, speed)
    assert tf[1] < tf[0]
    with pytest.raises(ValueError, match="unknown temperature model"):
        power_pvlib(poa, SYSTEM.model_copy(update={"temperature_model": "nope"}))
