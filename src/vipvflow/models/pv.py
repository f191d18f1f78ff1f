"""PV energy from plane-of-array irradiance: the paper's performance-ratio model and pvlib.

Paper mode (section 3.3): ``E = P_peak x G_poa / 1000 W/m2 x PR x dt``.
pvlib mode: PVWatts DC power (``pvlib.pvsystem.pvwatts_dc``) at a cell temperature from
the SAPM (``pvlib.temperature.sapm_cell``) or Faiman (``pvlib.temperature.faiman``) model,
in which the wind speed is the bus's own speed plus the ambient wind, then the system
losses and the PVWatts inverter (``pvlib.inverter.pvwatts``).
"""
from __future__ import annotations

import numpy as np

from .params import PVSystem


def paper_kw_per_wm2(kwp, performance_ratio=0.75):
    """Output of the paper's model per unit of plane-of-array irradiance:
    ``kWp x PR / 1000 W/m2`` (kW per W/m2, or kWh per Wh/m2 of irradiation).

    References
    ----------
    Paper section 3.3; IEC 61724-1 (performance ratio).
    """
    return kwp * performance_ratio / 1000.0


def energy_paper(poa_wm2, dt_s, kwp, performance_ratio=0.75):
    """Energy with a constant performance ratio, ``kWp x POA / 1000 x PR x dt``.

    Parameters
    ----------
    poa_wm2 : array, plane-of-array irradiance (W/m2)
    dt_s : array, time at that irradiance (s)
    kwp : float, peak power (kW at 1000 W/m2)
    performance_ratio : float (dimensionless)

    Returns
    -------
    array, kWh

    References
    ----------
    The paper's PV model (section 3.3); IEC 61724-1 for the performance ratio.
    """
    return (paper_kw_per_wm2(kwp, performance_ratio) * np.asarray(poa_wm2, np.float64)
            * np.asarray(dt_s, np.float64) / 3600.0)


def cell_temperature(poa_wm2, temp_air_c, wind_mps, model: str = "sapm_open_rack_glass_polymer"):
    """Cell temperature of the roof modules.

    Parameters
    ----------
    poa_wm2 : array, plane-of-array irradiance (W/m2)
    temp_air_c : array, air temperature (degC)
    wind_mps : array, wind speed over the modules (m/s; the bus's speed adds to it)
    model : ``sapm_<mounting>`` (a key of pvlib's SAPM parameter table) or ``faiman``

    Returns
    -------
    array, cell temperature (degC)

    References
    ----------
    pvlib ``temperature.sapm_cell`` (King et al., SAND2004-3535) and ``temperature.faiman``
    (Faiman, Prog. Photovolt. 16, 2008).
    """
    import pvlib  # here and below imported where used: paper mode never needs it

    if model == "faiman":
        return pvlib.temperature.faiman(poa_wm2, temp_air_c, wind_mps)
    if model.startswith("sapm_"):
        p = pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"].get(model[5:])
        if p is not None:
            return pvlib.temperature.sapm_cell(poa_wm2, temp_air_c, wind_mps, **p)
    known = ["faiman"] + [f"sapm_{k}" for k in pvlib.temperature.TEMPERATURE_MODEL_PARAMETERS["sapm"]]
    raise ValueError(f"unknown temperature model {model!r} (known: {', '.join(known)})")


def power_pvlib(poa_wm2, system: PVSystem, temp_air_c=15.0, vehicle_speed_mps=0.0,
                wind_mps=0.0):
    """AC power (W) and cell temperature (degC) with pvlib's PVWatts chain.

    Parameters
    ----------
    poa_wm2 : array, plane-of-array irradiance (W/m2)
    system : PVSystem (``kwp``, ``gamma_pdc_per_k``, ``system_losses_percent``,
        ``inverter_efficiency``, ``temperature_model``)
    temp_air_c : array or float, ambient temperature (degC)
    vehicle_speed_mps : array or float, the bus's speed (m/s): relative air flow over the roof
    wind_mps : array or float, ambient wind speed (m/s)

    Returns
    -------
    p_ac_w, temp_cell_c : arrays

    References
    ----------
    pvlib ``pvsystem.pvwatts_dc`` and ``inverter.pvwatts`` (Dobos, NREL/TP-6A20-62641, 2014);
    ``temperature.sapm_cell`` (King et al., SAND2004-3535).
    """
    import pvlib

    poa = np.asarray(poa_wm2, np.float64)
    wind = np.abs(np.asarray(vehicle_speed_mps, np.float64)) + np.abs(np.asarray(wind_mps, np.float64))
    tcell = np.asarray(cell_temperature(poa, temp_air_c, wind, system.temperature_model), np.float64)
    pdc0 = system.kwp * 1000.0
    pdc = pvlib.pvsystem.pvwatts_dc(poa, tcell, pdc0, system.gamma_pdc_per_k)
    pdc = np.asarray(pdc, np.float64) * (1.0 - system.system_losses_percent / 100.0)
    pac = pvlib.inverter.pvwatts(pdc, pdc0, eta_inv_nom=system.inverter_efficiency)
    return np.clip(np.asarray(pac, np.float64), 0.0, None), tcell


def energy_pvlib(poa_wm2, dt_s, system: PVSystem, temp_air_c=15.0, vehicle_speed_mps=0.0,
                 wind_mps=0.0):
    """Energy of the pvlib PV model.

    Parameters
    ----------
    poa_wm2 : array, plane-of-array irradiance (W/m2)
    dt_s : array, time at that irradiance (s)
    system : PVSystem
    temp_air_c, vehicle_speed_mps, wind_mps : air temperature (degC), bus speed and wind (m/s)

    Returns
    -------
    array, kWh: :func:`power_pvlib`'s AC power (W) held over each ``dt_s``

    References
    ----------
    pvlib ``pvsystem.pvwatts_dc`` and ``inverter.pvwatts`` (Dobos, NREL/TP-6A20-62641, 2014).
    """
    pac, _ = power_pvlib(poa_wm2, system, temp_air_c, vehicle_speed_mps, wind_mps)
    return pac * np.asarray(dt_s, np.float64) / 3.6e6


def energy(poa_wm2, dt_s, system: PVSystem, mode: str = "paper", temp_air_c=15.0,
           vehicle_speed_mps=0.0, wind_mps=0.0):
    """PV energy (kWh) in the configured mode: the one dispatcher of the simulation and the
    web app.

    Parameters
    ----------
    poa_wm2 : array, plane-of-array irradiance (W/m2)
    dt_s : array, time at that irradiance (s)
    system : PVSystem
    mode : ``'paper'`` (``kWp x POA / 1000 x PR x dt``, :func:`energy_paper`) or
        ``'pvlib'`` (PVWatts at a cell temperature cooled by the bus's speed plus the
        ambient wind, :func:`energy_pvlib`)
    temp_air_c : array or float, ambient temperature (degC; pvlib mode)
    vehicle_speed_mps, wind_mps : array or float, the bus's speed and the ambient wind
        (m/s; pvlib mode)

    Returns
    -------
    array, kWh

    References
    ----------
    Paper section 3.3; pvlib ``pvsystem.pvwatts_dc``, ``temperature.sapm_cell``,
    ``inverter.pvwatts``.
    """
    if mode == "paper":
        return energy_paper(poa_wm2, dt_s, system.kwp, system.performance_ratio)
    if mode == "pvlib":
        return energy_pvlib(poa_wm2, dt_s, system, temp_air_c=temp_air_c,
                            vehicle_speed_mps=vehicle_speed_mps, wind_mps=wind_mps)
    raise ValueError(f"unknown PV mode {mode!r}")
