"""Energy balance: coverage, avoided charging cycles and payback against hand computations."""
from __future__ import annotations

import re

import numpy as np
import pandas as pd
import pytest

from vipvflow import cli
from vipvflow.models import economics


def _number(text: str, label: str) -> float:
    m = re.search(rf"^{re.escape(label)}:\s*([-+0-9.eE]+)", text, re.MULTILINE)
    assert m, f"no '{label}:' line in\n{text}"
    return float(m.group(1))


def test_cli_direct_inputs_match_hand_computation(capsys):
    # a roof yield of 1200 kWh/kWp before system losses, PR 0.75 -> 900 kWh/kWp
    argv = ["economics", "--yield-kwh-per-kwp", "1200", "--performance-ratio", "0.75",
            "--kwp", "3.5", "--fleet-demand-mwh", "1500", "--buses", "25",
            "--battery-kwh", "330", "--soc-window", "0.2", "0.8",
            "--cost-eur-per-wp", "1.5", "--tariff-eur-per-kwh", "0.21"]
    assert cli.main(argv) == 0
    out = capsys.readouterr().out
    pv_bus = 1200 * 0.75 * 3.5                        # 3150 kWh per bus and year
    assert _number(out, "PV per bus") == pytest.approx(pv_bus)
    assert _number(out, "coverage") == pytest.approx(100 * pv_bus * 25 / 1.5e6, abs=1e-3)  # 5.25 %
    assert _number(out, "avoided charging cycles") == pytest.approx(pv_bus / (330 * 0.6), abs=0.01)
    assert "397.7 fleet" in out                       # 25 x 3150 / 198
    assert _number(out, "payback") == pytest.approx(3.5e3 * 1.5 / (pv_bus * 0.21), abs=0.01)


def test_cli_defaults_from_configuration(capsys):
    # kWp (3.5), battery (330 kWh), window (0.2-0.8), cost (1.5) and tariff (0.21) from conf/
    assert cli.main(["economics", "--yield-kwh-per-kwp", "1000", "--fleet-demand-mwh", "100"]) == 0
    out = capsys.readouterr().out
    assert _number(out, "coverage") == pytest.approx(100 * 3500 / 1e5, abs=1e-3)
    assert _number(out, "payback") == pytest.approx(5250 / (3500 * 0.21), abs=0.01)


def test_cli_trip_table(tmp_path, capsys):
    trips = pd.DataFrame({"block_id": ["b1", "b1", "b2"], "pv_kwh": [1.0, 2.0, 1.5],
                          "consumption_kwh": [20.0, 25.0, 24.0]})
    path = tmp_path / "trips.csv"
    trips.to_csv(path, index=False)
    assert cli.main(["economics", "--trips", str(path), "--kwp", "2", "--battery-kwh", "100",
                     "--period-years", "0.01"]) == 0
    out = capsys.readouterr().out
    assert _number(out, "coverage") == pytest.approx(100 * 4.5 / 69.0, abs=1e-3)
    assert _number(out, "avoided charging cycles") == pytest.approx(4.5 / 60 / 0.01, abs=0.01)
    assert _number(out, "payback") == pytest.approx(2 * 2e3 * 1.5 / (450 * 0.21), abs=0.01)


def test_cli_without_inputs_is_a_clear_error(capsys):
    assert cli.main(["economics"]) == 2
    assert "--yield-kwh-per-kwp" in capsys.readouterr().err


def test_energy_balance_per_vehicle_and_fleet():
    trips = pd.DataFrame({"vehicle_id": ["A", "A", "B"], "pv_kwh": [2.0, 4.0, 3.0],
                          "consumption_kwh": [50.0, 70.0, 60.0]})
    table = economics.energy_balance(trips, kwp=3.0, battery_kwh=300.0, soc_window=(0.1, 0.9),
                                     cost_eur_per_wp=1.0, tariff_eur_per_kwh=0.25,
                                     period_years=0.5)
    a, fleet = table.loc["A"], table.loc["fleet"]
    assert a["coverage"] == pytest.approx(6 / 120)
    assert a["avoided_cycles"] == pytest.approx(6 / 240)
    assert a["avoided_cycles_per_year"] == pytest.approx(12 / 240)
    assert a["payback_years"] == pytest.approx(3000 / (12 * 0.25))
    assert fleet["n_vehicles"] == 2 and fleet["cost_eur"] == 6000
    assert fleet["coverage"] == pytest.approx(9 / 180)
    assert fleet["payback_years"] == pytest.approx(6000 / (18 * 0.25))


def test_edge_cases():
    assert economics.simple_payback_years(3.5, 0.0, 1.5, 0.21) == np.inf
    assert np.isnan(economics.coverage(1.0, 0.0))
    assert economics.cycle_energy_kwh(330, (0.2, 0.8)) == pytest.approx(198)
    with pytest.raises(ValueError):
        economics.avoided_cycles(10, 330, (0.8, 0.2))
