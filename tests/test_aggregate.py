"""Per-partition sums (per trip, segment and local hour) against per-pass arithmetic."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from vipvflow.config import IrradianceCfg, PVSystem, load_config
from vipvflow.models import pv
from vipvflow.simulation.partition import COMPONENTS, RunContext, aggregate_partition


def _partition(seed=3):
    """Two trips on two dates over 5 segments, 2 s per segment, one trip at night."""
    rng = np.random.default_rng(seed)
    rows = []
    # (trip, date, start UTC): June in Luxembourg is UTC+2; the 23:50 UTC trip is dark
    for trip, date, start in (("T1", "2024-06-03", "2024-06-03 09:59:59"),
                              ("T2", "2024-06-03", "2024-06-03 23:50:00"),
                              ("T1", "2024-06-04", "2024-06-04 10:30:00")):
        t0 = pd.Timestamp(start, tz="UTC").timestamp()
        for k, seg in enumerate([11, 12, 13, 14, 15]):
            rows.append((seg, trip, pd.Timestamp(date), t0 + 2.0 * k, 2.0, 5.0))
    passes = pd.DataFrame(rows, columns=["segment_id", "trip_id", "service_date", "t_utc",
                                         "dt_s", "speed_mps"])
    passes["trip_id"] = pd.Categorical(passes["trip_id"])
    passes["dt_s"] = passes["dt_s"].astype(np.float32)
    passes["speed_mps"] = passes["speed_mps"].astype(np.float32)
    irr = pd.DataFrame({c: rng.uniform(50, 900, len(passes)).astype(np.float32) for c in COMPONENTS})
    irr.loc[passes["trip_id"] == "T2", :] = 0.0                 # night: no light at all
    return passes, irr


def _ctx(mode: str) -> RunContext:
    cfg = load_config(None)
    return RunContext(data_dir="", run_dir="", year=2024, irradiance=IrradianceCfg().model_dump(),
                      pv_system=cfg.pv_system().model_dump(), pv_mode=mode,
                      monthly_temperature_c=(0.0,) * 5 + (16.1,) + (0.0,) * 6,   # June: 16.1 deg C
                      wind_speed_mps=3.0, timezone="Europe/Luxembourg")


@pytest.mark.parametrize("mode", ["paper", "pvlib"])
def test_sums_equal_per_pass_arithmetic(mode):
    passes, irr = _partition()
    ctx = _ctx(mode)
    system = PVSystem(**ctx.pv_system)
    trip, segm, hourly = aggregate_partition(passes, irr, 6, ctx)
    dt = passes["dt_s"].to_numpy(np.float64)
    if mode == "paper":
        e = pv.energy_paper(irr["total"].to_numpy(np.float64), dt, system.kwp, system.performance_ratio)
    else:   # PVWatts with the module cooled by the bus's speed plus the ambient wind
        e = pv.energy_pvlib(irr["total"].to_numpy(np.float64), dt, system, temp_air_c=16.1,
                            vehicle_speed_mps=5.0, wind_mps=3.0)
    key = passes["trip_id"].astype(str) + "/" + passes["service_date"].dt.strftime("%F")
    want = pd.Series(e).groupby(key.to_numpy()).sum()
    got = trip.set_index(trip["trip_id"] + "/" + trip["service_date"].dt.strftime("%F"))["pv_kwh"]
    assert list(trip["trip_id"]) == ["T1", "T1", "T2"]          # sorted by trip, then date
    np.testing.assert_allclose(got.loc[want.index], want.to_numpy(), rtol=1e-6)
    assert got["T2/2024-06-03"] == 0 and trip["seconds"].tolist() == [10.0, 10.0, 10.0]
    # per segment: 3 passes each, the irradiation in Wh/m2
    assert segm["segment_id"].tolist() == [11, 12, 13, 14, 15]
    assert (segm["n_passes"] == 3).all() and np.allclose(segm["seconds"], 6.0)
    h = irr["direct"].to_numpy(np.float64) * dt / 3600.0
    np.testing.assert_allclose(segm["h_direct"], pd.Series(h).groupby(passes["segment_id"]).sum(), rtol=1e-9)
    # per local hour: 11:59:59 and 12:00:01 CEST fall in different hours, the dark trip at 01:50
    assert hourly["hour"].tolist() == [1, 11, 12]
    np.testing.assert_allclose(hourly["seconds"], [10.0, 2.0, 18.0])
    assert hourly.loc[hourly["hour"] == 1, "h_total"].item() == 0
    np.testing.assert_allclose(hourly["h_ghi"].sum(), (irr["ghi"].to_numpy(np.float64) * dt / 3600).sum())
