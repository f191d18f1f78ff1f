"""VECTO interop: .vdri round trips and real mission cycles, .vmod energies, job files."""
from __future__ import annotations

import csv
import json

import numpy as np
import pandas as pd
import pytest

from test_vehicle import trapezoid_cycle
from vipvflow import cli
from vipvflow.outputs import vecto
from vipvflow.config import load_config
from vipvflow.errors import InputError

VMOD_NAME = "24t Coach_Cycle_Accelerate_0_85_level.vmod"
# lengths of the declaration mission cycles (shared/data/PROVENANCE.md, section 4)
MISSION_LENGTHS_M = {"HeavyUrban": 30483, "Urban": 39551, "Suburban": 23504}


def test_vdri_written_and_read_back_unchanged(tmp_path):
    rows = pd.DataFrame({"s_m": [0.0, 1.0, 2.5, 100.125, 250.0],
                         "v_kmh": [0.0, 34.4, 33.6, 0.1, 0.0],
                         "grad_pct": [0.6, -0.7, 0.0, 1e-3, -2.25],
                         "stop_s": [45.4, 0.0, 0.0, 0.0, 2.0],
                         "Aux_Alt": [1.77, 1.77, 1.8, 1.8, 1.8],
                         "Padd": [5.82, 5.82, 5.82, 5.82, 5.82]})
    path = vecto.write_vdri(rows, tmp_path / "trip.vdri")
    text = path.read_bytes()
    assert text.startswith(b"<s>,<v>,<grad>,<stop>,<Aux_Alt>,<Padd>\r\n0,0,0.6,45.4,1.77,5.82\r\n")
    pd.testing.assert_frame_equal(vecto.read_vdri(path), rows)
    # the same file with a UTF-8 BOM, spaces and a comment reads the same
    bom = tmp_path / "with bom.vdri"
    bom.write_bytes(b"\xef\xbb\xbf# written by hand\r\n"
                    + text.replace(b",", b", ").replace(b"<v>", b"<v> "))
    pd.testing.assert_frame_equal(vecto.read_vdri(bom), rows)


def test_written_cycle_keeps_distance_and_stops(tmp_path):
    legs = 12
    cycle = trapezoid_cycle(legs, 400.0, 9.0, 1.0, 1.3, 20.0)
    cycle["gradient"] = 0.02
    standing = np.diff(np.concatenate([[0], (cycle["speed_mps"] == 0).astype(int)])) == 1
    assert standing.sum() == legs + 1                    # the start, each stop, the end
    path = vecto.write_vdri(cycle, tmp_path / "trip.vdri")
    info = vecto.vdri_summary(vecto.read_vdri(path))
    assert info["distance_m"] == pytest.approx(legs * 400.0)
    assert info["stops"] == legs + 1
    assert info["stop_time_s"] == pytest.approx(20.0 * (legs + 1), abs=2 * (legs + 1) * 2.0)
    rows = vecto.read_vdri(path)
    assert (rows["grad_pct"] == 2.0).all()
    assert rows["v_kmh"].max() == pytest.approx(9.0 * 3.6)


def test_heavy_urban_copy_reads_and_expands(test_data):
    rows = vecto.read_vdri(test_data / "vecto" / "HeavyUrban.vdri")
    assert list(rows.columns) == ["s_m", "v_kmh", "grad_pct", "stop_s"]
    info = vecto.vdri_summary(rows)
    assert info["distance_m"] == MISSION_LENGTHS_M["HeavyUrban"]
    assert rows.iloc[0].tolist() == [0.0, 0.0, 0.6, 45.4]          # first line of the file
    cycle = vecto.vdri_to_cycle(rows)
    assert cycle["dist_m"].iloc[-1] == pytest.approx(MISSION_LENGTHS_M["HeavyUrban"])
    assert np.all(np.diff(cycle["dist_m"]) >= -1e-9) and np.all(np.diff(cycle["t_s"]) > 0)
    assert cycle["speed_mps"].max() <= rows["v_kmh"].max() / 3.6 + 1e-9
    # the standing time of the expanded cycle is the file's stop time (finely sampled: each
    # stop may lose up to two samples)
    fine = vecto.vdri_to_cycle(rows, dt_s=0.1)
    v = fine["speed_mps"].to_numpy()
    standing = np.sum(np.diff(fine["t_s"])[(v[:-1] == 0) & (v[1:] == 0)])
    assert standing == pytest.approx(info["stop_time_s"], abs=2 * 0.1 * info["stops"])


def test_expanded_cycle_follows_driver_limits():
    """0 -> 36 km/h at 1 m/s2, cruise, brake at 1.25 m/s2 to a halt at 1000 m: analytic time."""
    rows = pd.DataFrame({"s_m": [0.0, 1.0, 1000.0], "v_kmh": [0.0, 36.0, 0.0],
                         "grad_pct": [0.0, 0.0, 0.0], "stop_s": [10.0, 0.0, 5.0]})
    cycle = vecto.vdri_to_cycle(rows, dt_s=2.0, max_accel_mps2=1.0, max_decel_mps2=1.25,
                                grid_m=0.5)
    expected = 10 + 10 + (1000 - 50 - 40) / 10 + 8 + 5
    assert cycle["t_s"].iloc[-1] == pytest.approx(expected, abs=0.2)
    assert cycle["speed_mps"].max() == pytest.approx(10.0)
    assert cycle["stop"].iloc[0] and cycle["stop"].iloc[-1]
    assert cycle.loc[cycle["t_s"] == 16.0, "speed_mps"].iloc[0] == pytest.approx(6.0, abs=0.05)


@pytest.mark.shared
def test_declaration_cycles_have_their_lengths(shared_data):
    folder = shared_data / "vecto" / "declaration_mission_cycles"
    for name, length in MISSION_LENGTHS_M.items():
        rows = vecto.read_vdri(folder / f"{name}.vdri")
        assert vecto.vdri_summary(rows)["distance_m"] == length
        assert vecto.vdri_to_cycle(rows)["dist_m"].iloc[-1] == pytest.approx(length)
    citybus = vecto.read_vdri(shared_data / "vecto" / "citybus_AT_demo_vehicle"
                              / "zykl_Citybus_1_Heavy_Urban.vdri")
    assert list(citybus.columns) == ["s_m", "v_kmh", "grad_pct", "stop_s", "Aux_Alt", "Padd"]
    assert citybus.iloc[0].tolist() == [0.0, 0.0, 0.6, 45.4, 1.77, 5.82]


def _hand_vmod(path):
    """The .vmod read with the csv module: BOM off, columns by header name."""
    with open(path, encoding="utf-8-sig", newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    col = {name: [float(r[head.index(name)]) for r in rows[1:]]
           for name in ("time [s]", "dist [m]", "Pwheel [kW]", "Pbrake [kW]")}
    return {k: np.array(v) for k, v in col.items()}


def _check_vmod(path):
    hand = _hand_vmod(path)
    t = hand["time [s]"]
    assert np.allclose(np.diff(t), 1.0)                # 1 s steps at interval midpoints
    e = vecto.vmod_energy(path)
    assert e["distance_km"] * 1e3 == pytest.approx(hand["dist [m]"][-1])
    assert e["duration_s"] == pytest.approx(len(t) * 1.0)
    assert e["wheel_kwh"] == pytest.approx(np.sum(np.maximum(hand["Pwheel [kW]"], 0)) / 3600)
    assert e["brake_kwh"] == pytest.approx(np.sum(np.abs(hand["Pbrake [kW]"])) / 3600)
    assert np.isnan(e["battery_kwh"])                  # a diesel coach has no battery
    # 85 km/h steady state: Pwheel = (Proll + Pair) at that speed, 53.7 kW in the file
    df = vecto.read_vmod(path)
    steady = df[df["v_act [km/h]"] > 84.99]
    assert (steady["Pwheel [kW]"] - steady["Proll [kW]"] - steady["Pair [kW]"]).abs().max() < 1e-3
    assert df.attrs["units"]["Pwheel [kW]"] == "kW"
    return e


def test_vmod_copy_energies(test_data):
    _check_vmod(test_data / "vecto" / VMOD_NAME)


@pytest.mark.shared
def test_vmod_original_energies(shared_data):
    _check_vmod(shared_data / "vecto" / "coach_24t_vmod_example" / VMOD_NAME)


def test_vmod_battery_columns_of_newer_vecto(tmp_path):
    """A battery-electric .vmod (VECTO 0.7+ column names, dt column) integrates per interval."""
    path = tmp_path / "bev.vmod"
    path.write_text("time [s],dt [s],dist [m],P_wheel_in [kW],P_brake_loss [kW],P_aux_el [kW],"
                    "P_REESS_T [kW],P_REESS_int [kW],P_REESS_loss [kW]\n"
                    "0.25,0.5,0,0,0,5,10,10.5,0.5\n"
                    "1,1,2,100,0,5,120,126,6\n"
                    "2.5,2,20,-50,-10,5,-30,-28.5,1.5\n", encoding="utf-8-sig")
    e = vecto.vmod_energy(path)
    assert e["duration_s"] == 3.5
    assert e["wheel_kwh"] == pytest.approx(100 / 3600)
    assert e["brake_kwh"] == pytest.approx(20 / 3600)
    assert e["aux_kwh"] == pytest.approx(5 * 3.5 / 3600)
    assert e["battery_kwh"] == pytest.approx((10.5 * 0.5 + 126 - 28.5 * 2) / 3600)
    assert e["battery_loss_kwh"] == pytest.approx((0.25 + 6 + 3) / 3600)
    table = vecto.vmod_trip_energies({"trip_1": path})
    assert table.loc["trip_1", "consumption_kwh"] == pytest.approx(e["battery_kwh"])


def test_bad_files_raise_input_errors(tmp_path):
    timed = tmp_path / "timed.vdri"
    timed.write_text("<t>,<v>,<grad>\n0,0,0\n", encoding="utf-8")
    with pytest.raises(InputError, match="time-based"):
        vecto.read_vdri(timed)
    broken = tmp_path / "broken.vdri"
    broken.write_text("<s>,<v>,<grad>,<stop>\n0,0,0,5\n10,fast,0,0\n", encoding="utf-8")
    with pytest.raises(InputError, match="line 3"):
        vecto.read_vdri(broken)


def test_vecto_job_files(tmp_path):
    params = load_config().vehicle_params()
    paths = vecto.write_vecto_job(tmp_path, params, cycles=["trip 1.vdri"], ambient_c=15.0)
    veh = json.loads(paths["vveh"].read_text())["Body"]
    assert veh["CurbWeight"] == params.curb_mass_kg
    assert veh["Loading"] == pytest.approx(88 * 0.3 * 68)
    assert veh["CdxA"] == params.cda_m2 and veh["rdyn"] == pytest.approx(465.0)
    assert veh["ElectricMotors"][0]["Count"] == 2 and veh["ElectricMotors"][0]["Ratio"] == 22.6
    assert {a["RRCISO"] for a in veh["AxleConfig"]["Axles"]} == {0.007}
    job = json.loads(paths["vecto"].read_text())["Body"]
    assert job["Cycles"] == ["trip 1.vdri"]
    assert job["Padd_electric"] == pytest.approx((7.0 + 5.0) * 1e3)
    bat = json.loads(paths["vbat"].read_text())["Body"]
    assert bat["Capacity"] * 650 / 1e3 == pytest.approx(330, rel=1e-3)
    # the electric power map: P_el = T omega / eta while driving
    emap = pd.read_csv(paths["vemo"], skipinitialspace=True)
    emap.columns = [c.strip() for c in emap.columns]
    row = emap[(emap["n [rpm]"] == 5000) & (emap["T [Nm]"] > 0)].iloc[0]
    p_mech = row["T [Nm]"] * 5000 * 2 * np.pi / 60 / 1e3
    assert row["P_el [kW]"] == pytest.approx(p_mech / params.eaxle_eta(row["T [Nm]"], 5000), rel=1e-4)


def test_cli_cycle_and_vmod(test_data, capsys):
    assert cli.main(["vecto", "cycle", str(test_data / "vecto" / "HeavyUrban.vdri")]) == 0
    out = capsys.readouterr().out
    assert "distance: 30483.0 m" in out and "stops: 155" in out
    kwh = float(out.split("battery_kwh:")[1].split()[0])
    assert 1.0 < kwh / 30.483 < 3.0                                 # kWh/km of a 12 m e-bus
    assert cli.main(["vecto", "vmod", str(test_data / "vecto" / VMOD_NAME)]) == 0
    out = capsys.readouterr().out
    hand = _hand_vmod(test_data / "vecto" / VMOD_NAME)
    assert f"distance_km: {hand['dist [m]'][-1] / 1e3:.4f}" in out
    assert f"wheel_kwh: {np.sum(np.maximum(hand['Pwheel [kW]'], 0)) / 3600:.4f}" in out
