"""A bus battery through its day: trips, layovers, the depot, and the chargers of a plan.

:func:`block_day_soc` integrates the state of charge of many block-days at once (vectorised
over block-days, a short loop over each day's steps in time order):

1. The bus leaves the depot at the depot charge's target SoC (``depot.target_soc``; the
   depot charged it overnight).
2. Each trip draws its consumption; its PV feeds the DC bus and offsets it first (no battery
   round trip), so the trip changes the SoC by ``(pv - use) / capacity``.  A surplus charges
   the battery up to ``soc_max``; the rest is curtailed.
3. Each layover after a trip draws the auxiliaries and HVAC, takes its PV (the same rule)
   and, at a terminal of the plan with a layover of at least ``min_layover_s``, an
   opportunity charge: ``power_kw x (layover - connect_s)`` from the grid, of which
   ``efficiency`` reaches the battery, up to ``target_soc`` (PV first: the charger tops up
   what the roof did not).
4. Back at the depot the charger restores the target SoC for the next morning.  PV parked at
   the depot that day goes first (smart charging: the charger supplies only what the roof
   did not, up to what the day used), the rest of it is curtailed.  The depot's charger
   delivers at most ``power_kw x efficiency x`` the hours the bus is parked within the
   charging hours; more than that is a shortfall.

The SoC never goes below zero: a block-day whose SoC would fall below the vehicle's
``soc_min`` is *infeasible* under the plan, with the time it crosses ``soc_min`` (linear in
time within the step) and the SoC at the end of that step; one whose depot charge falls short
is infeasible too.  Everything runs twice, with PV and without, so the grid energy PV saves
at the depot and at the terminals is a difference of two balances.

References
----------
The paper's block-day energy balance (section 4: PV charges the battery up to the SoC
ceiling, the rest is curtailed), extended with a charging plan as operators run battery
buses: overnight depot charging (plug-in, 50-150 kW) and pantograph opportunity charging at
terminals (150-450 kW) during layovers (e.g. UITP, "Charging infrastructure for e-buses",
2021; VDV 261 / ISO 15118-20 for the pantograph interface).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Charger:
    """One kind of charger of a plan.

    Attributes
    ----------
    power_kw : power drawn from the grid while charging, kW
    efficiency : battery energy / grid energy (charger, cable, battery charging), 0..1
    target_soc : SoC the charge stops at, 0..1
    """

    power_kw: float
    efficiency: float
    target_soc: float


@dataclass(frozen=True)
class Vehicle:
    """What the balance needs of a bus: ``battery_kwh`` and its usable window (0..1)."""

    battery_kwh: float
    soc_min: float
    soc_max: float


#: block_day_soc's per-day outputs (kWh, 0..1 SoC, Unix s)
OUTPUTS = ("soc_start", "soc_end", "soc_lowest", "feasible", "fail_step", "fail_utc",
           "fail_soc", "curtailed_in_service_kwh", "curtailed_parked_kwh", "parked_used_kwh",
           "opportunity_grid_kwh", "depot_grid_kwh", "depot_short_kwh")


def block_day_soc(vehicle: Vehicle, trip_pv, trip_use, trip_t0, trip_t1, lay_pv, lay_use,
                  lay_t0, lay_t1, lay_charge, parked_pv, depot_hours_s, depot: Charger,
                  opportunity: Charger | None, connect_s: float = 60.0,
                  trace: bool = False) -> dict:
    """The state of charge of block-days through their steps, under a charging plan.

    Parameters
    ----------
    vehicle : Vehicle
    trip_pv, trip_use : (n, K) kWh, PV and battery energy of each day's trips in order (0
        where a day has fewer than K trips)
    trip_t0, trip_t1 : (n, K) Unix s, each trip's departure and arrival
    lay_pv, lay_use : (n, K) kWh, PV and auxiliaries of the layover after trip k (0 for
        the last trip and unused steps)
    lay_t0, lay_t1 : (n, K) Unix s, the layover's start and end
    lay_charge : (n, K) bool, an opportunity charger is there and the layover is long enough
    parked_pv : (n,) kWh, PV while parked at the depot that day (before and after the block)
    depot_hours_s : (n,) s, time parked at the depot within the charging hours
    depot : Charger, the depot's (its ``target_soc`` is the SoC of each morning)
    opportunity : Charger or None, the terminals'
    connect_s : s of a layover lost docking and undocking
    trace : also return ``soc_after_trip`` and ``soc_after_layover`` (n, K)

    Returns
    -------
    dict of (n,) arrays, :data:`OUTPUTS`
        ``soc_start`` at the first departure, ``soc_end`` at the last arrival, ``soc_lowest``;
        ``feasible`` (bool), ``fail_step`` (trip position of the step that falls below
        ``soc_min``, -1 when none), ``fail_utc`` (when the SoC crosses ``soc_min``, NaN when
        it never does), ``fail_soc`` (SoC at the end of that step); curtailed PV in service
        and parked, parked PV used; grid energy of the opportunity charges and of the depot
        charge (kWh at the charger), ``depot_short_kwh`` (battery energy the depot's charging
        hours could not restore).
    """
    cap, lo, hi = float(vehicle.battery_kwh), float(vehicle.soc_min), float(vehicle.soc_max)
    tp, tu = np.asarray(trip_pv, float), np.asarray(trip_use, float)
    n, K = tp.shape
    s = np.full(n, float(depot.target_soc))
    start = s.copy()
    lowest = s.copy()
    curtailed = np.zeros(n)
    opp_grid = np.zeros(n)
    fail_step = np.full(n, -1, np.int64)
    fail_utc = np.full(n, np.nan)
    fail_soc = np.full(n, np.nan)
    after_trip = np.full((n, K), np.nan) if trace else None
    after_lay = np.full((n, K), np.nan) if trace else None

    def step(s, pv, use, t0, t1, k):
        """One trip or layover: PV offsets the use, a surplus charges up to soc_max."""
        nonlocal curtailed
        target = s + (pv - use) / cap
        ceiling = np.maximum(hi, s)
        over = (target > ceiling) & (pv > use)
        curtailed = curtailed + np.where(over, (target - ceiling) * cap, 0.0)
        new = np.where(over, ceiling, target)
        # the first time the SoC goes under soc_min: when, linearly in time over the step
        crosses = (fail_step < 0) & (new < lo) & (t1 > t0)
        if crosses.any():
            frac = np.clip((s - lo) / np.where(s - new > 0, s - new, 1.0), 0.0, 1.0)
            fail_utc[crosses] = (t0 + frac * (t1 - t0))[crosses]
            fail_step[crosses] = k
            fail_soc[crosses] = np.maximum(new, 0.0)[crosses]
        return np.maximum(new, 0.0)                 # a battery holds no negative energy

    for k in range(K):
        s = step(s, tp[:, k], tu[:, k], trip_t0[:, k], trip_t1[:, k], k)
        lowest = np.minimum(lowest, s)
        if trace:
            after_trip[:, k] = s
        s = step(s, np.asarray(lay_pv)[:, k], np.asarray(lay_use)[:, k], lay_t0[:, k], lay_t1[:, k], k)
        lowest = np.minimum(lowest, s)
        if opportunity is not None:
            can = np.asarray(lay_charge)[:, k] & (fail_step < 0)
            t = np.clip(np.asarray(lay_t1)[:, k] - np.asarray(lay_t0)[:, k] - connect_s, 0.0, None)
            room = np.clip(opportunity.target_soc - s, 0.0, None) * cap
            got = np.where(can, np.minimum(opportunity.power_kw * opportunity.efficiency * t / 3600.0,
                                           room), 0.0)
            s = s + got / cap
            opp_grid += got / opportunity.efficiency
        if trace:
            after_lay[:, k] = s
    end = s
    # back at the depot: the roof first, the charger the rest, up to the morning's SoC
    need = np.clip(depot.target_soc - end, 0.0, None) * cap
    parked = np.asarray(parked_pv, float)
    used = np.minimum(parked, need)
    battery_from_grid = need - used
    capacity = depot.power_kw * depot.efficiency * np.asarray(depot_hours_s, float) / 3600.0
    short = np.clip(battery_from_grid - capacity, 0.0, None)
    out = {"soc_start": start, "soc_end": end, "soc_lowest": lowest,
           "feasible": (fail_step < 0) & (short <= 1e-9), "fail_step": fail_step,
           "fail_utc": fail_utc, "fail_soc": fail_soc, "curtailed_in_service_kwh": curtailed,
           "curtailed_parked_kwh": parked - used, "parked_used_kwh": used,
           "opportunity_grid_kwh": opp_grid,
           "depot_grid_kwh": np.minimum(battery_from_grid, capacity) / depot.efficiency,
           "depot_short_kwh": short}
    if trace:
        out.update(soc_after_trip=after_trip, soc_after_layover=after_lay)
    return out


def window_overlap_s(t0_local, t1_local, start_h: float, end_h: float) -> np.ndarray:
    """Seconds of each interval ``[t0, t1)`` (local clock time as seconds since the epoch,
    arrays) within the daily window ``[start_h, end_h)`` (local hours; ``end_h < start_h``
    wraps past midnight; equal: the whole day).

    Returns
    -------
    ndarray, s
    """
    a, b = np.asarray(t0_local, float), np.asarray(t1_local, float)
    if start_h == end_h:
        return np.clip(b - a, 0.0, None)
    day = 86400.0
    first = np.floor(a / day) - 1
    total = np.zeros(len(a))
    span = int(np.max(np.ceil((b - a) / day)) if len(a) else 0) + 3
    for k in range(span):
        d = (first + k) * day
        w0 = d + start_h * 3600.0
        w1 = d + (end_h if end_h > start_h else end_h + 24.0) * 3600.0
        total += np.clip(np.minimum(b, w1) - np.maximum(a, w0), 0.0, None)
    return total
