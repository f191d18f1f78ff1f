"""Energy balance of PV on bus roofs: coverage, avoided charging cycles, simple payback.

- coverage = PV energy / energy the bus draws (share of the demand the roof supplies);
- avoided charging cycles = PV energy / (battery capacity x (SoC high - SoC low)): one cycle is
  one charge of the SoC window the operator uses (default 20-80 %);
- simple payback (years) = system cost / yearly saving = (EUR/Wp x Wp) / (PV kWh/yr x EUR/kWh),
  no discounting, degradation or maintenance.

The functions take numbers or numpy arrays; :func:`energy_balance` works on the per-trip table
of the reduce step (``pv_kwh``, ``consumption_kwh`` and a vehicle/block column) and gives one
row per vehicle plus the fleet.  :func:`balance_from_inputs` checks a published result by hand
from a specific yield and a fleet's demand (``vipvflow economics``).
"""
from __future__ import annotations

import numpy as np
import pandas as pd


def coverage(pv_kwh, demand_kwh):
    """Share of the demand supplied by PV.

    Parameters
    ----------
    pv_kwh : array, PV energy over a period (kWh)
    demand_kwh : array, energy the bus draws from its battery over the same period (kWh)

    Returns
    -------
    array, ``pv_kwh / demand_kwh`` (dimensionless; NaN where the demand is 0)

    References
    ----------
    The paper's share of demand covered (section 4).
    """
    pv = np.asarray(pv_kwh, dtype=float)
    demand = np.asarray(demand_kwh, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(demand > 0, pv / np.where(demand > 0, demand, 1.0), np.nan)


def cycle_energy_kwh(battery_kwh, soc_window=(0.2, 0.8)):
    """Energy of one charging cycle.

    Parameters
    ----------
    battery_kwh : array, usable-capacity reference of the battery (kWh)
    soc_window : (low, high), state-of-charge window a depot charge restores (0..1)

    Returns
    -------
    array, ``battery_kwh x (high - low)`` (kWh)

    References
    ----------
    The paper's charging cycle (section 4): one cycle restores the SoC window.
    """
    lo, hi = _window(soc_window)
    return np.asarray(battery_kwh, dtype=float) * (hi - lo)


def avoided_cycles(pv_kwh, battery_kwh, soc_window=(0.2, 0.8)):
    """Charging cycles the PV energy replaces.

    Parameters
    ----------
    pv_kwh : array, PV energy the battery takes over a period (kWh)
    battery_kwh : array, battery capacity (kWh)
    soc_window : (low, high), state-of-charge window of one cycle (0..1)

    Returns
    -------
    array, cycles over the period of ``pv_kwh`` (``pv_kwh / cycle_energy_kwh``)

    References
    ----------
    The paper's avoided charging cycles (section 4).
    """
    return np.asarray(pv_kwh, dtype=float) / cycle_energy_kwh(battery_kwh, soc_window)


def system_cost_eur(kwp, cost_eur_per_wp):
    """Installed cost of a PV system.

    Parameters
    ----------
    kwp : array, peak power (kWp)
    cost_eur_per_wp : float, installed cost per peak watt (EUR/Wp)

    Returns
    -------
    array, EUR
    """
    return np.asarray(kwp, dtype=float) * 1e3 * cost_eur_per_wp


def simple_payback_years(kwp, annual_pv_kwh, cost_eur_per_wp, tariff_eur_per_kwh):
    """Simple (undiscounted) payback time of the PV system.

    Parameters
    ----------
    kwp : array, peak power (kWp)
    annual_pv_kwh : array, PV energy used per year (kWh/year)
    cost_eur_per_wp : float, installed cost (EUR/Wp)
    tariff_eur_per_kwh : float, price of the grid energy the PV replaces (EUR/kWh)

    Returns
    -------
    array, years: ``cost / (annual_pv_kwh x tariff)``; inf where nothing is saved

    References
    ----------
    The paper's payback (section 4), without discounting or degradation.
    """
    saving = np.asarray(annual_pv_kwh, dtype=float) * tariff_eur_per_kwh
    cost = system_cost_eur(kwp, cost_eur_per_wp)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(saving > 0, cost / np.where(saving > 0, saving, 1.0), np.inf)


def _window(soc_window) -> tuple[float, float]:
    lo, hi = (float(x) for x in soc_window)
    if not 0 <= lo < hi <= 1:
        raise ValueError(f"soc_window must be low < high within 0..1, got {soc_window}")
    return lo, hi


def energy_balance(trips: pd.DataFrame, kwp: float, battery_kwh: float,
                   soc_window=(0.2, 0.8), cost_eur_per_wp: float = 1.5,
                   tariff_eur_per_kwh: float = 0.21, by: str | None = None,
                   period_years: float = 1.0) -> pd.DataFrame:
    """Energy balance per vehicle and for the fleet from per-trip energies.

    Parameters
    ----------
    trips : DataFrame
        One row per trip (pass): ``pv_kwh`` (PV energy harvested, kWh), ``consumption_kwh``
        (energy drawn from the battery, kWh) and the vehicle column ``by``.
    kwp : float
        PV peak power per vehicle (kWp).
    battery_kwh : float
        Battery capacity per vehicle (kWh).
    soc_window : (float, float)
        SoC window of one charging cycle (0..1).
    cost_eur_per_wp, tariff_eur_per_kwh : float
        PV system cost (EUR/Wp) and the price of the charging energy it replaces (EUR/kWh).
    by : str, optional
        Vehicle column; default ``vehicle_id``, else ``block_id``, else ``block``.  Each
        distinct value is one bus carrying one PV system.
    period_years : float
        Length of the period the trips cover (years); energies are scaled by 1/period to
        give the yearly values payback needs.

    Returns
    -------
    DataFrame, one row per vehicle and a last row ``"fleet"``
        ``pv_kwh``, ``consumption_kwh`` (over the period), ``coverage``, ``avoided_cycles``
        (over the period), ``avoided_cycles_per_year``, ``cost_eur``, ``saving_eur_per_year``,
        ``payback_years``, ``n_vehicles``.

    References
    ----------
    The paper's fleet energy balance (section 4): coverage, avoided charging cycles and payback.
    """
    if by is None:
        by = next((c for c in ("vehicle_id", "block_id", "block") if c in trips), None)
        if by is None:
            raise ValueError("trips need a vehicle column (vehicle_id, block_id or block)")
    for col in ("pv_kwh", "consumption_kwh", by):
        if col not in trips:
            raise ValueError(f"trips lack the column {col!r}")
    per = trips.groupby(by, sort=True)[["pv_kwh", "consumption_kwh"]].sum()
    per["n_vehicles"] = 1
    fleet = per.sum().to_frame("fleet").T
    out = pd.concat([per, fleet])
    n = out["n_vehicles"].to_numpy(float)
    out["coverage"] = coverage(out["pv_kwh"], out["consumption_kwh"])
    out["avoided_cycles"] = avoided_cycles(out["pv_kwh"], battery_kwh, soc_window)
    out["avoided_cycles_per_year"] = out["avoided_cycles"] / period_years
    out["cost_eur"] = system_cost_eur(kwp * n, cost_eur_per_wp)
    annual_pv = out["pv_kwh"] / period_years
    out["saving_eur_per_year"] = annual_pv * tariff_eur_per_kwh
    out["payback_years"] = simple_payback_years(kwp * n, annual_pv, cost_eur_per_wp,
                                                tariff_eur_per_kwh)
    out["n_vehicles"] = out["n_vehicles"].astype(int)
    out.index.name = by
    return out


def balance_from_inputs(yield_kwh_per_kwp: float, kwp: float, fleet_demand_mwh: float,
                        buses: int, battery_kwh: float, soc_window=(0.2, 0.8),
                        cost_eur_per_wp: float = 1.5, tariff_eur_per_kwh: float = 0.21,
                        performance_ratio: float | None = None) -> dict:
    """Fleet-year balance from a specific yield, as a reader checks a published result.

    Parameters
    ----------
    yield_kwh_per_kwp : float
        Annual PV energy per kWp (kWh/kWp/yr); multiplied by ``performance_ratio`` when given
        (a yield of the irradiance on the roof before system losses: kWh/m2 at 1 kW/m2).
    kwp : float
        PV peak power per bus (kWp).
    fleet_demand_mwh : float
        Energy the fleet draws in a year (MWh).
    buses : int
        Buses carrying PV.
    battery_kwh : float
        Battery capacity per bus (kWh).

    Returns
    -------
    dict
        ``pv_kwh_per_bus``, ``pv_mwh_fleet``, ``coverage``, ``cycle_kwh``,
        ``avoided_cycles_per_bus``, ``avoided_cycles_fleet``, ``cost_eur_per_bus``,
        ``saving_eur_per_bus``, ``payback_years`` (per bus = fleet, same ratio).
    """
    pr = 1.0 if performance_ratio is None else float(performance_ratio)
    pv_bus = yield_kwh_per_kwp * pr * kwp
    pv_fleet = pv_bus * buses
    cycle = float(cycle_energy_kwh(battery_kwh, soc_window))
    return {
        "pv_kwh_per_bus": pv_bus,
        "pv_mwh_fleet": pv_fleet / 1e3,
        "coverage": float(coverage(pv_fleet, fleet_demand_mwh * 1e3)),
        "cycle_kwh": cycle,
        "avoided_cycles_per_bus": pv_bus / cycle,
        "avoided_cycles_fleet": pv_fleet / cycle,
        "cost_eur_per_bus": float(system_cost_eur(kwp, cost_eur_per_wp)),
        "saving_eur_per_bus": pv_bus * tariff_eur_per_kwh,
        "payback_years": float(simple_payback_years(kwp, pv_bus, cost_eur_per_wp,
                                                    tariff_eur_per_kwh)),
    }
