"""The battery's balance under a charging plan: a block-day by hand, the demo's balance in
range, one coverage figure everywhere, every output as its data dictionary says."""
from __future__ import annotations

import json
import re

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from vipvflow.models.charging import Charger, Vehicle, block_day_soc, window_overlap_s

T8 = 8 * 3600.0                       # 08:00 (s)
CAR = Vehicle(battery_kwh=300.0, soc_min=0.1, soc_max=0.9)
DEPOT = Charger(power_kw=100.0, efficiency=0.9, target_soc=0.9)
TERMINAL = Charger(power_kw=300.0, efficiency=0.95, target_soc=0.9)


def _day(trip1_use=100.0, trip1_pv=4.0, trip2_use=120.0, trip2_pv=5.0, pv=True, hours_s=8 * 3600.0):
    """One block: trip 1 08:00-09:00, a 20 min layover at a charger, trip 2 09:20-10:20, then
    the depot with 8 h of charging (PV of the trips, the layover and parked: 4, 1, 10 kWh)."""
    k = 1.0 if pv else 0.0
    row = lambda a, b: np.array([[a, b]])  # noqa: E731
    return block_day_soc(
        CAR, row(k * trip1_pv, k * trip2_pv), row(trip1_use, trip2_use),
        row(T8, T8 + 4800.0), row(T8 + 3600.0, T8 + 8400.0),
        lay_pv=row(k * 1.0, 0.0), lay_use=row(3.0, 0.0),
        lay_t0=row(T8 + 3600.0, 0.0), lay_t1=row(T8 + 4800.0, 0.0),
        lay_charge=np.array([[True, False]]), parked_pv=np.array([k * 10.0]),
        depot_hours_s=np.array([hours_s]), depot=DEPOT, opportunity=TERMINAL, connect_s=60.0,
        trace=True)


def test_block_day_by_hand():
    """270 kWh at departure (0.9 x 300); trip 1: -100 + 4 -> 174; layover: -3 + 1 -> 172, then
    19 min x 300 kW x 0.95 = 90.25 kWh (room 98) -> 262.25, 95 kWh from the grid; trip 2:
    -120 + 5 -> 147.25; the depot: 122.75 kWh to put back, the roof's 10 first, 112.75 / 0.9 =
    125.28 kWh from the grid.  Without PV: 170, 167, 257.25, 137.25; the depot 132.75 / 0.9 =
    147.5.  PV avoids (95 + 147.5) - (95 + 125.28) = 22.22 kWh of grid energy."""
    d, n = _day(), _day(pv=False)
    np.testing.assert_allclose(d["soc_after_trip"][0] * 300, [174.0, 147.25], atol=0.1)
    np.testing.assert_allclose(d["soc_after_layover"][0, 0] * 300, 262.25, atol=0.1)
    np.testing.assert_allclose(d["soc_end"] * 300, [147.25], atol=0.1)
    np.testing.assert_allclose(d["opportunity_grid_kwh"], [95.0], atol=0.1)
    np.testing.assert_allclose(d["depot_grid_kwh"], [112.75 / 0.9], atol=0.1)
    np.testing.assert_allclose(d["parked_used_kwh"], [10.0], atol=0.1)
    np.testing.assert_allclose(n["soc_end"] * 300, [137.25], atol=0.1)
    np.testing.assert_allclose(n["depot_grid_kwh"], [147.5], atol=0.1)
    avoided = (n["depot_grid_kwh"] + n["opportunity_grid_kwh"]) - (d["depot_grid_kwh"] + d["opportunity_grid_kwh"])
    np.testing.assert_allclose(avoided, [22.2222], atol=0.1)
    assert d["feasible"].all() and (d["curtailed_in_service_kwh"] == 0).all()
    assert d["soc_lowest"][0] * 300 == pytest.approx(147.25, abs=0.1)


def test_curtailment_at_the_top():
    """Trip 1 uses 10 kWh and harvests 40: the battery at its 0.9 ceiling takes none of the
    30 kWh surplus: curtailed."""
    d = _day(trip1_use=10.0, trip1_pv=40.0)
    np.testing.assert_allclose(d["curtailed_in_service_kwh"], [30.0], atol=0.1)
    np.testing.assert_allclose(d["soc_after_trip"][0, 0] * 300, 270.0, atol=0.1)


def test_infeasible_block_flagged_at_the_minute_it_fails():
    """Trip 2 uses 250 kWh: from 262.25 kWh with 5 of PV it ends at 17.25 kWh (0.0575), below
    soc_min (30 kWh), crossing it 232.25 / 245 of the way through the trip: 10:16:52.65."""
    d = _day(trip2_use=250.0)
    assert not d["feasible"][0] and d["fail_step"][0] == 1
    assert d["fail_utc"][0] == pytest.approx(T8 + 4800.0 + 3600.0 * 232.25 / 245.0, abs=1.0)
    assert d["fail_soc"][0] == pytest.approx(17.25 / 300, abs=0.1 / 300)
    # never below zero: a trip using more than the battery holds ends empty
    e = _day(trip2_use=400.0)
    assert e["soc_end"][0] == 0.0 and e["soc_lowest"][0] == 0.0 and not e["feasible"][0]
    # a depot whose hours cannot put the day back is a shortfall: 112.75 kWh in 1 h of 90 kWh
    f = _day(hours_s=3600.0)
    np.testing.assert_allclose(f["depot_short_kwh"], [112.75 - 90.0], atol=0.1)
    assert not f["feasible"][0]


def test_depot_hours_overlap():
    """Parked 18:00-06:00 local (as seconds of a day 0), chargers 21-5 h: 8 h; 00-24: all 12 h."""
    a, b = np.array([18 * 3600.0]), np.array([30 * 3600.0])
    assert window_overlap_s(a, b, 21, 5)[0] == pytest.approx(8 * 3600.0)
    assert window_overlap_s(a, b, 0, 0)[0] == pytest.approx(12 * 3600.0)
    assert window_overlap_s(a, b, 8, 16)[0] == pytest.approx(0.0)


# ---- a run's balance ----------------------------------------------------------------------------

def test_small_demo_balance_in_range(small_run):
    """No block-day below zero; the infeasible ones (if any) counted and named; grid energy
    avoided adds up; the app's trips start from the run's SoC at departure."""
    s = json.loads((small_run / "summary.json").read_text())
    bd = pd.read_parquet(small_run / "block_day.parquet")
    assert (bd["soc_lowest_pv"] >= 0).all() and (bd["soc_end_pv"] >= 0).all()
    assert s["block_days"] == len(bd)
    assert s["block_days_infeasible"] == int((~bd["feasible"]).sum())
    assert len(s["infeasible_block_days_first"]) == min(5, s["block_days_infeasible"])
    assert bd.loc[~bd["feasible"], "infeasible_at_utc"].notna().sum() <= s["block_days_infeasible"]
    assert s["grid_kwh_avoided"] == pytest.approx(s["grid_kwh_avoided_depot"] + s["grid_kwh_avoided_opportunity"])
    assert s["grid_kwh_avoided"] == pytest.approx(bd["grid_kwh_avoided"].sum())
    assert s["pv_kwh_usable"] == pytest.approx(bd["pv_kwh_usable"].sum())
    # the headline counts what the batteries take; harvested and curtailed stand beside it
    assert s["kwh_per_kwp_usable"] <= s["kwh_per_kwp_harvested"]
    assert "kwh_per_kwp_allsky" not in s and "pv_kwh_allsky" not in s and "fleet_demand_mwh" not in s
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    assert trips["soc_at_departure"].between(0, 1).all()


def test_the_pv_the_batteries_take_is_the_grid_energy_it_saves(small_run, small_config):
    """Each block-day's usable PV (driving, layovers and parked, less what a full battery
    curtails) is the grid energy it saves at the depot's and the terminals' chargers, at
    their efficiencies, wherever the depot restores the battery: every kWh the block-day
    counts reaches its battery (a layover's PV lost on the way would count it unused).
    Not on a block-day whose battery runs empty without PV (it holds no negative energy: the
    energy it lacks is charged nowhere) or that the depot's hours cannot restore; the small
    demo's Saturday blocks run empty."""
    from vipvflow.config import load_config

    plan = load_config(small_config).charging
    bd = pd.read_parquet(small_run / "block_day.parquet")
    restored = ((bd["depot_short_kwh"] == 0) & (bd["soc_lowest_nopv"] > 0)).to_numpy()
    saved = ((bd["grid_kwh_depot_without_pv"] - bd["grid_kwh_depot"]) * plan.depot.efficiency
             + (bd["grid_kwh_opportunity_without_pv"] - bd["grid_kwh_opportunity"]) * plan.opportunity.efficiency)
    assert restored.sum() >= 0.4 * len(bd)
    assert (bd.loc[restored, "pv_kwh_layover"] > 1.0).all()
    np.testing.assert_allclose(saved[restored], bd.loc[restored, "pv_kwh_usable"], rtol=1e-9, atol=1e-9)


def test_one_coverage_figure_everywhere(small_run):
    """summary.json, the console line, the report's table, the routes figure and the app's
    fleet line give the same coverage to the printed digit."""
    from vipvflow.app.layout import numbers_html
    from vipvflow.app.model import TripModel
    from vipvflow.outputs.report import fig_routes
    from vipvflow.simulation.run import _summary_line

    s = json.loads((small_run / "summary.json").read_text())
    want = f"{100 * s['coverage']:.2f}"
    console = re.search(r"PV covers ([0-9.]+) % of the", _summary_line(s)).group(1)
    report = (small_run / "report.html").read_text()
    table = re.search(r"share of it the PV the batteries take covers</td><td class='num'>([0-9.]+)</td>",
                      report).group(1)
    rm = pd.read_parquet(small_run / "route_month.parquet")
    bd = pd.read_parquet(small_run / "block_day.parquet")
    fig = fig_routes(rm, float(bd["pv_kwh_usable"].sum() / bd["demand_kwh"].sum()))
    figure = re.search(r"covers ([0-9.]+) %", fig._suptitle.get_text()).group(1)
    model = TripModel(small_run)
    r = model.routes().iloc[0]
    res = model.trip(r["route_id"], r["direction_id"], "2024-06-12", depart="12:00")
    fleet = {"run": model.summary, "allsky": 1.0, "clearsky": 1.0, "shading_loss": 0.1, "share": 0.01,
             "consumption": 100.0}
    app = re.search(r'class="fleet-coverage">([0-9.]+)<', numbers_html(res, fleet)).group(1)
    assert console == table == figure == app == want
    # the trip view starts from the run's SoC at that departure
    trips = pd.read_parquet(small_run / "trip_energy.parquet")
    row = trips[(trips["trip_id"] == res.trip_id)
                & (pd.to_datetime(trips["service_date"]) == pd.Timestamp("2024-06-12"))]
    assert res.numbers["soc_start"] == pytest.approx(float(row["soc_at_departure"].iloc[0]))


def _dictionary_matches(run):
    from vipvflow.simulation.dictionary import OUTPUTS, SUMMARY

    for name, spec in OUTPUTS.items():
        cols = set(pq.read_schema(run / f"{name}.parquet").names)
        assert cols == set(spec.columns), (name, sorted(cols ^ set(spec.columns)))
    s = json.loads((run / "summary.json").read_text())
    assert set(s) == set(SUMMARY), sorted(set(s) ^ set(SUMMARY))


def test_outputs_are_what_the_dictionary_lists(small_run, small_config, tmp_path):
    """Every output file of a whole-day run and of a driving-only run holds exactly the
    columns its data dictionary lists, and summary.json exactly its keys."""
    from vipvflow.config import load_config
    from vipvflow.simulation import run_simulation

    _dictionary_matches(small_run)
    cfg = load_config(small_config, overrides={"out_dir": str(tmp_path), "fleet": {"harvest": "driving"},
                                               "dask": {"n_workers": 1}})
    _dictionary_matches(run_simulation(cfg, 2024, say=lambda *a: None))


def test_ranking_orders_blocks_and_routes(small_run):
    r = pd.read_parquet(small_run / "ranking.parquet")
    assert set(r["kind"]) == {"block", "route"}
    for _, g in r.groupby("kind"):
        g = g.sort_values("rank")
        assert (np.diff(g["kwh_avoided_per_kwp_year"].to_numpy()) <= 1e-9).all()
    ok = r[np.isfinite(r["payback_years"])]
    cost = 1.5 * 1000 * 3.5
    np.testing.assert_allclose(ok["payback_years"], cost / (ok["grid_kwh_avoided_per_year"] * 0.21), rtol=1e-9)


def test_the_battery_in_chunks_is_the_battery_at_once(small_run, small_config, monkeypatch):
    """The block-days' battery run a few block-days at a time (as a network's year is, to
    bound its memory) gives every block-day, every trip's SoC at departure and the traced
    days exactly as all of them at once, and as the run wrote them."""
    from vipvflow.config import load_config
    from vipvflow.simulation import reduce

    cfg = load_config(small_config, overrides={"dask": {"n_workers": 2}})
    written = pd.read_parquet(small_run / "trip_energy.parquet")
    trip = written.drop(columns=["block_id", "soc_at_departure"])
    trip["service_date"] = pd.to_datetime(trip["service_date"]).astype("datetime64[ns]")  # a date in the file
    placed = reduce._placed_trips(small_run, trip[["trip_id", "service_date"]])

    def table(rows: int):
        monkeypatch.setattr(reduce, "BATTERY_ROWS", rows)
        return reduce.block_day_table(cfg, small_run, trip.copy(), cfg.vehicle_params(), placed)

    bd, idle, trips, traces, _ = table(1 << 20)
    assert len(bd) > 7
    pd.testing.assert_series_equal(trips["soc_at_departure"], written["soc_at_departure"])
    ran = pd.read_parquet(small_run / "block_day.parquet")
    for c in ("soc_start", "soc_lowest_pv", "soc_lowest_nopv", "grid_kwh_avoided", "pv_kwh_curtailed"):
        pd.testing.assert_series_equal(bd[c], ran[c], check_exact=True)
    for rows in (3, 7):
        bd_c, _, trips_c, traces_c, _ = table(rows)
        pd.testing.assert_frame_equal(bd_c, bd, check_exact=True)
        pd.testing.assert_series_equal(trips_c["soc_at_departure"], trips["soc_at_departure"], check_exact=True)
        pd.testing.assert_frame_equal(traces_c, traces, check_exact=True)
    assert set(traces["which"]) == {"worst", "typical"}


def test_block_day_rows_are_those_of_the_string_and_date_keys():
    """Each row's block-day by integer codes (:class:`BlockDayRows`) is its row found by the
    (block, date) pair, as strings or as categories; a block or a date of none of the
    block-days, or a missing block, is -1; the sums spread per block-day are the groupby's."""
    from vipvflow.simulation.reduce import BlockDayRows

    rng = np.random.default_rng(7)
    blocks = np.array(["b10", "b2", "a", "z 9", "b1"])
    days = pd.date_range("2024-02-27", periods=5, freq="D")
    bd = (pd.DataFrame([(b, d) for b in blocks for d in days if rng.random() < 0.7],
                       columns=["block_id", "service_date"])
          .sort_values(["block_id", "service_date"]).reset_index(drop=True))
    n = 400
    frame = pd.DataFrame({
        "block_id": rng.choice(np.r_[blocks, ["nope"]], n).astype(object),
        "service_date": pd.DatetimeIndex(rng.choice(np.r_[days, pd.DatetimeIndex(["2024-03-09"])], n)),
        "v": rng.random(n)})
    frame.loc[3, "block_id"] = None
    expect = (pd.Series(np.arange(len(bd)), index=pd.MultiIndex.from_frame(bd))
              .reindex(pd.MultiIndex.from_frame(frame[["block_id", "service_date"]]))
              .to_numpy(dtype=float, na_value=np.nan))
    expect = np.where(np.isfinite(expect), expect, -1).astype(np.int64)
    rows = BlockDayRows(bd)
    assert (expect >= 0).sum() > n // 3 and (expect < 0).sum() > n // 10
    np.testing.assert_array_equal(rows.of(frame), expect)
    as_cat = frame.astype({"block_id": pd.CategoricalDtype(["zz", *blocks[::-1], "nope"])})
    np.testing.assert_array_equal(rows.of(as_cat), expect)
    as_read = pa.Table.from_pandas(frame).to_pandas()          # Arrow-backed strings, as read
    assert isinstance(as_read["block_id"].array, pd.arrays.ArrowStringArray)
    np.testing.assert_array_equal(rows.of(as_read), expect)
    sums = rows.spread(frame["v"].groupby(rows.of(frame)).sum(), 0.0)
    by_key = (frame.groupby(["block_id", "service_date"])["v"].sum()
              .reindex(pd.MultiIndex.from_frame(bd), fill_value=0.0).to_numpy())
    np.testing.assert_array_equal(sums, by_key)
    with pytest.raises(ValueError, match="sorted"):
        BlockDayRows(bd.iloc[::-1])


def test_standing_rows_read_a_file_at_a_time_are_those_of_the_whole_table(tmp_path):
    """The standing partitions read a file at a time (:func:`_standing_rows`) give the rows
    picked from all files read whole: the buses in service row by row (block-day, kind,
    trip before, PV), the idle buses' rows with their place among all rows; an empty file
    and rows of no block-day, of a missing block or kind, are taken as they come."""
    from vipvflow.inputs.gtfs.schedule import IDLE_BLOCK
    from vipvflow.simulation.reduce import BlockDayRows, _part_table, _standing_rows
    from vipvflow.store import RunDir, write_parquet

    rng = np.random.default_rng(11)
    days = pd.date_range("2024-05-01", periods=4, freq="D")
    bd = pd.DataFrame([(b, d) for b in ("b1", "b2", "c") for d in days[:3]],
                      columns=["block_id", "service_date"])
    whole = []
    for tile, n in (("E1", 50), ("E2", 0), ("E3", 80), ("E4", 30)):
        frame = pd.DataFrame({
            "block_id": rng.choice(["b1", "b2", "c", "x", IDLE_BLOCK], n).astype(object),
            "service_date": pd.DatetimeIndex(rng.choice(days, n)),
            "kind": rng.choice(["layover", "parked"], n).astype(object),
            "after_trip": rng.integers(-1, 6, n), "point_id": rng.integers(0, 9, n),
            "buses": np.ones(n, np.int64), "seconds": rng.random(n) * 600,
            "pv_kwh": rng.random(n), "pv_kwh_clear": rng.random(n), "h_total": rng.random(n)})
        if n:
            frame.loc[2, "block_id"] = None
            frame.loc[4, "kind"] = None
        write_parquet(frame, RunDir(tmp_path).part("standing", tile, "all"))
        whole.append(frame)
    rows = BlockDayRows(bd)
    busy, idle = _standing_rows(tmp_path, rows)

    st = _part_table(tmp_path, "standing").to_pandas()
    off = (st["block_id"] == IDLE_BLOCK).to_numpy(bool)
    on = st.loc[~off]
    assert 10 < len(idle) == off.sum() and len(busy["at"]) == len(on) > 100
    np.testing.assert_array_equal(busy["at"], rows.of(on))
    assert (busy["at"] < 0).sum() > 10 and (busy["at"] >= 0).sum() > 50
    for kind in ("layover", "parked"):
        np.testing.assert_array_equal(busy[kind], (on["kind"] == kind).to_numpy(bool))
    for c in ("after_trip", "pv_kwh", "pv_kwh_clear"):
        np.testing.assert_array_equal(busy[c], on[c].to_numpy())
    names = ["block_id", "service_date", "kind", "after_trip", "buses", "seconds", "pv_kwh", "pv_kwh_clear"]
    pd.testing.assert_frame_equal(idle, st.loc[off, names], check_exact=True)
