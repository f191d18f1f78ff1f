"""Energy a battery-electric bus draws from its battery along a driving cycle.

A longitudinal model in the manner of VECTO (the EU's Vehicle Energy Consumption calculation
Tool, Regulation (EU) 2017/2400): the wheel force is

    F = m (1 + f_rot) a + m g (c_rr cos(alpha) + sin(alpha)) + 1/2 rho CdA v^2

with the vehicle mass ``m`` (curb + passengers at a load factor), rotating-mass factor
``f_rot``, rolling resistance coefficient ``c_rr``, road angle ``alpha = atan(dz/ds)``, air
density ``rho`` and drag area ``CdA``.  Positive wheel power goes through the e-axle (motor,
inverter and gear; an efficiency map over motor torque and speed, or a constant), negative
wheel power is recuperated up to a power limit and above a minimum speed, the rest goes to the
friction brakes.  Auxiliaries draw a base load plus heating/cooling as a function of the ambient
temperature; the battery's charge and discharge efficiencies give its internal losses.

The cycle is evaluated per interval between consecutive samples with the speed taken as linear
in time inside an interval, so kinetic, rolling and aerodynamic work are exact for a piecewise
linear speed trace (the trapezoid profiles the driving-cycle generator produces).

:func:`simulate_cycle` gives kWh per trip, :func:`soc_trace` the state of charge through a
vehicle block with and without PV, :func:`infer_blocks` the blocks of a timetable.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd
from pydantic import BaseModel, ConfigDict, Field, model_validator

G = 9.81  # m/s2, standard gravity as in VECTO

CYCLE_COLUMNS = ("t_s", "dist_m", "speed_mps", "stop", "gradient")


class EfficiencyMap(BaseModel):
    """E-axle efficiency (motor + inverter + gear, dimensionless) on a torque x speed grid.

    ``torque_nm`` and ``speed_rpm`` are per motor at the motor shaft, ascending;
    ``efficiency[i][j]`` belongs to ``torque_nm[i]`` and ``speed_rpm[j]``.  The same map serves
    motoring and generating (|torque|).  Outside the grid the nearest edge value holds.
    """

    model_config = ConfigDict(extra="forbid")

    torque_nm: list[float] = Field(min_length=2)
    speed_rpm: list[float] = Field(min_length=2)
    efficiency: list[list[float]]

    @model_validator(mode="after")
    def _shape(self):
        if np.any(np.diff(self.torque_nm) <= 0) or np.any(np.diff(self.speed_rpm) <= 0):
            raise ValueError("torque_nm and speed_rpm must be strictly ascending")
        eff = np.asarray(self.efficiency, dtype=float)
        if eff.shape != (len(self.torque_nm), len(self.speed_rpm)):
            raise ValueError(f"efficiency must be {len(self.torque_nm)} rows (torque) x "
                             f"{len(self.speed_rpm)} columns (speed), got {eff.shape}")
        if np.any(eff <= 0) or np.any(eff > 1):
            raise ValueError("efficiency values must be in (0, 1]")
        return self

    def __call__(self, torque_nm, speed_rpm) -> np.ndarray:
        """Bilinear interpolation at |torque| (N m) and speed (rpm); arrays broadcast."""
        return _bilinear(np.asarray(self.torque_nm), np.asarray(self.speed_rpm),
                         np.asarray(self.efficiency, dtype=float),
                         np.abs(np.asarray(torque_nm, dtype=float)),
                         np.abs(np.asarray(speed_rpm, dtype=float)))


class HvacCurve(BaseModel):
    """Electric power of heating / cooling (kW) against ambient temperature (deg C), interpolated."""

    model_config = ConfigDict(extra="forbid")

    ambient_c: list[float] = Field(min_length=1)
    power_kw: list[float] = Field(min_length=1)

    @model_validator(mode="after")
    def _shape(self):
        if len(self.ambient_c) != len(self.power_kw):
            raise ValueError("ambient_c and power_kw must have the same length")
        if np.any(np.diff(self.ambient_c) <= 0):
            raise ValueError("ambient_c must be strictly ascending")
        if min(self.power_kw) < 0:
            raise ValueError("power_kw must be >= 0")
        return self

    def __call__(self, ambient_c) -> np.ndarray:
        return np.interp(ambient_c, self.ambient_c, self.power_kw)


class VehicleParams(BaseModel):
    """A battery-electric bus (catalog entry of ``conf/vehicles.yaml``); SI units unless named."""

    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)

    name: str = ""
    description: str = ""
    length_m: float = Field(12.0, gt=0)
    # masses
    curb_mass_kg: float = Field(gt=0)
    max_mass_kg: float | None = Field(None, gt=0)
    passenger_capacity: int = Field(0, ge=0)
    passenger_mass_kg: float = Field(68.0, ge=0)
    load_factor: float = Field(0.0, ge=0, le=1)
    rotating_mass_factor: float = Field(0.0, ge=0)
    # driving resistances
    crr: float = Field(ge=0)
    cda_m2: float = Field(ge=0)
    air_density_kg_m3: float = Field(1.188, gt=0)
    # drivetrain
    wheel_radius_m: float = Field(0.465, gt=0)
    gear_ratio: float = Field(1.0, gt=0)
    n_motors: int = Field(1, ge=1)
    motor_power_kw: float = Field(gt=0)
    motor_torque_nm: float = Field(gt=0)
    eaxle_efficiency: float = Field(0.85, gt=0, le=1)
    eaxle_map: EfficiencyMap | None = None
    regen_power_limit_kw: float | None = Field(None, ge=0)
    regen_min_speed_kmh: float = Field(0.0, ge=0)
    # auxiliaries
    aux_base_kw: float = Field(0.0, ge=0)
    hvac: HvacCurve | None = None
    # battery
    battery_kwh: float = Field(gt=0)
    charge_efficiency: float = Field(1.0, gt=0, le=1)
    discharge_efficiency: float = Field(1.0, gt=0, le=1)
    soc_min: float = Field(0.0, ge=0, le=1)
    soc_max: float = Field(1.0, ge=0, le=1)

    @model_validator(mode="after")
    def _checks(self):
        if not self.soc_min < self.soc_max:
            raise ValueError("soc_min must be below soc_max")
        if self.max_mass_kg is not None and self.mass_kg > self.max_mass_kg:
            raise ValueError(f"mass {self.mass_kg:.0f} kg at load_factor {self.load_factor} "
                             f"exceeds max_mass_kg {self.max_mass_kg:.0f}")
        return self

    @property
    def mass_kg(self) -> float:
        """Vehicle test mass (kg): curb mass plus passengers at the load factor."""
        return (self.curb_mass_kg
                + self.passenger_capacity * self.load_factor * self.passenger_mass_kg)

    @property
    def usable_kwh(self) -> float:
        """Energy of the usable SoC window (kWh)."""
        return self.battery_kwh * (self.soc_max - self.soc_min)

    def aux_kw(self, ambient_c: float | np.ndarray = 15.0) -> np.ndarray:
        """Electric auxiliary power (kW): base load + HVAC at the ambient temperature (deg C)."""
        hvac = self.hvac(ambient_c) if self.hvac is not None else 0.0
        return self.aux_base_kw + np.asarray(hvac, dtype=float)

    def eaxle_eta(self, torque_nm, speed_rpm) -> np.ndarray:
        """E-axle efficiency at motor torque (N m, per motor) and speed (rpm)."""
        if self.eaxle_map is None:
            return np.full(np.broadcast(np.asarray(torque_nm), np.asarray(speed_rpm)).shape,
                           self.eaxle_efficiency)
        return self.eaxle_map(torque_nm, speed_rpm)


def _bilinear(xg, yg, z, x, y):
    x = np.clip(x, xg[0], xg[-1])
    y = np.clip(y, yg[0], yg[-1])
    i = np.clip(np.searchsorted(xg, x, side="right") - 1, 0, len(xg) - 2)
    j = np.clip(np.searchsorted(yg, y, side="right") - 1, 0, len(yg) - 2)
    tx = (x - xg[i]) / (xg[i + 1] - xg[i])
    ty = (y - yg[j]) / (yg[j + 1] - yg[j])
    return ((1 - tx) * (1 - ty) * z[i, j] + tx * (1 - ty) * z[i + 1, j]
            + (1 - tx) * ty * z[i, j + 1] + tx * ty * z[i + 1, j + 1])


def wheel_power(cycle: pd.DataFrame, params: VehicleParams) -> dict[str, np.ndarray]:
    """Mean power at the wheels per interval of a driving cycle.

    Parameters
    ----------
    cycle : DataFrame
        ``t_s`` (s), ``speed_mps`` (m/s), ``gradient`` (dz/ds, dimensionless); samples in time
        order.  The speed is taken as linear in time between samples.
    params : VehicleParams

    Returns
    -------
    dict of ndarray, one value per interval (n - 1)
        ``dt_s`` (s), ``v_mean`` (m/s), ``ds_m`` (m, v_mean * dt), ``p_inertia``, ``p_roll``,
        ``p_grade``, ``p_air``, ``p_wheel`` (W, interval means).

    Notes
    -----
    Inertia: m (1+f_rot) a v_mean is the exact mean of m (1+f_rot) a v for constant a, so its
    integral is the kinetic-energy change.  Air: the mean of v^3 over a linear ramp is
    (v0 + v1)(v0^2 + v1^2) / 4.  Gradient: the mean of the two samples' dz/ds.

    References
    ----------
    VECTO's longitudinal dynamics (European Commission JRC, VECTO user manual: rolling
    resistance, air drag, gradient and inertia at the wheel).
    """
    t = np.asarray(cycle["t_s"], dtype=float)
    v = np.asarray(cycle["speed_mps"], dtype=float)
    grad = np.asarray(cycle["gradient"], dtype=float) if "gradient" in cycle else np.zeros_like(v)
    dt = np.diff(t)
    if np.any(dt <= 0):
        raise ValueError("cycle t_s must be strictly increasing")
    v0, v1 = v[:-1], v[1:]
    v_mean = 0.5 * (v0 + v1)
    a = (v1 - v0) / dt
    g = 0.5 * (grad[:-1] + grad[1:])
    alpha = np.arctan(g)
    m = params.mass_kg
    p_inertia = m * (1.0 + params.rotating_mass_factor) * a * v_mean
    p_roll = m * G * params.crr * np.cos(alpha) * v_mean
    p_grade = m * G * np.sin(alpha) * v_mean
    p_air = 0.5 * params.air_density_kg_m3 * params.cda_m2 * (v0 + v1) * (v0**2 + v1**2) / 4.0
    return {"dt_s": dt, "v_mean": v_mean, "ds_m": v_mean * dt, "p_inertia": p_inertia,
            "p_roll": p_roll, "p_grade": p_grade, "p_air": p_air,
            "p_wheel": p_inertia + p_roll + p_grade + p_air}


def simulate_cycle(cycle: pd.DataFrame, params: VehicleParams, ambient_c: float = 15.0,
                   detail: bool = False) -> dict:
    """Battery energy of one trip along a driving cycle (built-in VECTO-style model).

    Parameters
    ----------
    cycle : DataFrame
        Columns ``t_s`` (s), ``dist_m`` (m), ``speed_mps`` (m/s), ``stop`` (bool),
        ``gradient`` (dz/ds); usually 2 s steps from the driving-cycle generator.
    params : VehicleParams
    ambient_c : float
        Ambient temperature (deg C) for the HVAC load.
    detail : bool
        Also return the per-interval arrays (W) under ``"intervals"``.

    Returns
    -------
    dict
        ``traction_kwh``: electric energy into the e-axle while driving (DC side);
        ``recuperated_kwh``: electric energy back from the e-axle while braking;
        ``aux_kwh``: auxiliaries; ``battery_loss_kwh``: internal battery losses;
        ``battery_kwh``: energy taken from the battery (traction - recuperated + aux + losses);
        ``wheel_kwh``: positive work at the wheels; ``brake_kwh``: negative wheel work
        (positive number) of which ``friction_brake_kwh`` went to the friction brakes;
        ``distance_km``, ``duration_s``, ``peak_power_kw`` (wheel) and ``overload_s`` (time
        the wheel power exceeded the motors' rated power).

    References
    ----------
    VECTO longitudinal dynamics: Fontaras G. et al. (2016), "The development of a simulation
    tool for monitoring heavy-duty vehicle CO2 emissions and fuel consumption in Europe",
    Energy Procedia 86; Regulation (EU) 2017/2400, Annex III.
    """
    missing = [c for c in ("t_s", "speed_mps") if c not in cycle]
    if missing:
        raise ValueError(f"driving cycle lacks columns {missing}; expected {CYCLE_COLUMNS}")
    w = wheel_power(cycle, params)
    dt, v_mean, p = w["dt_s"], w["v_mean"], w["p_wheel"]

    moving = v_mean > 1e-6
    force = np.where(moving, p / np.where(moving, v_mean, 1.0), 0.0)  # N at the wheels
    torque = force * params.wheel_radius_m / (params.gear_ratio * params.n_motors)
    speed_rpm = v_mean / params.wheel_radius_m * params.gear_ratio * 60.0 / (2.0 * np.pi)
    eta = params.eaxle_eta(torque, speed_rpm)

    drive = np.maximum(p, 0.0)
    brake = np.maximum(-p, 0.0)
    regen_ok = v_mean * 3.6 >= params.regen_min_speed_kmh
    limit = np.inf if params.regen_power_limit_kw is None else params.regen_power_limit_kw * 1e3
    regen_wheel = np.where(regen_ok, np.minimum(brake, limit), 0.0)
    p_traction = drive / eta
    p_recup = regen_wheel * eta
    p_aux = np.full_like(dt, float(params.aux_kw(ambient_c)) * 1e3)
    p_dc = p_traction - p_recup + p_aux  # at the battery terminals
    p_int = np.where(p_dc >= 0, p_dc / params.discharge_efficiency,
                     p_dc * params.charge_efficiency)

    def kwh(x):
        return float(np.sum(x * dt) / 3.6e6)

    dist = np.asarray(cycle["dist_m"], dtype=float) if "dist_m" in cycle else None
    distance_m = float(dist[-1] - dist[0]) if dist is not None else float(np.sum(w["ds_m"]))
    out = {
        "traction_kwh": kwh(p_traction),
        "recuperated_kwh": kwh(p_recup),
        "aux_kwh": kwh(p_aux),
        "battery_loss_kwh": kwh(p_int - p_dc),
        "battery_kwh": kwh(p_int),
        "wheel_kwh": kwh(drive),
        "brake_kwh": kwh(brake),
        "friction_brake_kwh": kwh(brake - regen_wheel),
        "distance_km": distance_m / 1e3,
        "duration_s": float(np.sum(dt)),
        "peak_power_kw": float(drive.max() / 1e3) if len(drive) else 0.0,
        "overload_s": float(np.sum(dt[drive > params.n_motors * params.motor_power_kw * 1e3])),
    }
    if detail:
        out["intervals"] = {**w, "eta": eta, "p_traction": p_traction, "p_recup": p_recup,
                            "p_aux": p_aux, "p_battery": p_int}
    return out


def soc_trace(trips_energy: pd.DataFrame, pv_kwh: Sequence[float] | np.ndarray | None,
              params: VehicleParams, soc_start: float | None = None,
              layover_charge_kw: float = 0.0) -> pd.DataFrame:
    """State of charge through one vehicle block, without and with PV.

    Parameters
    ----------
    trips_energy : DataFrame
        The block's trips in service order: ``battery_kwh`` (energy from the battery, kWh,
        as :func:`simulate_cycle` gives; ``consumption_kwh`` is accepted too) and, when
        layover charging is used, ``start_s`` and ``end_s`` (s after midnight).
    pv_kwh : array-like or None
        PV energy harvested during each trip (kWh); ``None`` for none.
    params : VehicleParams
        Battery capacity ``battery_kwh`` and usable window ``soc_min`` .. ``soc_max``.
    soc_start : float, optional
        SoC at the block's start (0..1); default ``soc_max`` (left the depot charged).
    layover_charge_kw : float
        Opportunity charging power at the termini between trips (kW, battery side).

    Returns
    -------
    DataFrame, one row per trip
        ``soc_start``, ``soc_end`` (without PV), ``soc_start_pv``, ``soc_end_pv``,
        ``pv_curtailed_kwh`` (PV that found the battery at ``soc_max``), ``below_min`` and
        ``below_min_pv`` (bool: the trip ended under ``soc_min``, the block does not fit the
        usable window).

    Notes
    -----
    PV feeds the DC bus and offsets the trip's consumption first (no battery round trip), so a
    trip changes the SoC by ``(pv - consumption) / capacity``; charging (PV surplus, layover)
    stops at ``soc_max``.  The SoC is not clipped at ``soc_min``: a value below it shows how
    far the block overruns the window.  Trips of a block are sequential, so this is a short
    loop over the block's trips.

    References
    ----------
    The paper's block-day energy balance (section 4): PV charges the battery up to the SoC
    ceiling, the rest is curtailed.
    """
    col = "battery_kwh" if "battery_kwh" in trips_energy else "consumption_kwh"
    use = np.asarray(trips_energy[col], dtype=float)
    n = len(use)
    pv = np.zeros(n) if pv_kwh is None else np.asarray(pv_kwh, dtype=float)
    if pv.shape != (n,):
        raise ValueError(f"pv_kwh has {pv.size} values for {n} trips")
    cap = params.battery_kwh
    gap_h = np.zeros(n)
    if layover_charge_kw > 0:
        start = np.asarray(trips_energy["start_s"], dtype=float)
        end = np.asarray(trips_energy["end_s"], dtype=float)
        gap_h[1:] = np.maximum(start[1:] - end[:-1], 0.0) / 3600.0
    soc0 = params.soc_max if soc_start is None else float(soc_start)

    rows = {k: np.zeros(n) for k in ("soc_start", "soc_end", "soc_start_pv", "soc_end_pv",
                                     "pv_curtailed_kwh")}
    s, s_pv = soc0, soc0
    for i in range(n):
        charge = layover_charge_kw * gap_h[i] / cap
        s = min(s + charge, max(s, params.soc_max))
        s_pv = min(s_pv + charge, max(s_pv, params.soc_max))
        rows["soc_start"][i], rows["soc_start_pv"][i] = s, s_pv
        s = s - use[i] / cap
        target = s_pv + (pv[i] - use[i]) / cap
        if target > params.soc_max and pv[i] > use[i]:
            kept = max(params.soc_max, s_pv)
            rows["pv_curtailed_kwh"][i] = (target - kept) * cap
            target = kept
        s_pv = target
        rows["soc_end"][i], rows["soc_end_pv"][i] = s, s_pv
    out = pd.DataFrame(rows, index=trips_energy.index)
    out["below_min"] = out["soc_end"] < params.soc_min - 1e-12
    out["below_min_pv"] = out["soc_end_pv"] < params.soc_min - 1e-12
    return out


def infer_blocks(trips: pd.DataFrame, min_layover_s: float = 0.0) -> pd.Series:
    """Vehicle block of every trip: the GTFS ``block_id`` where given, else inferred.

    Parameters
    ----------
    trips : DataFrame
        ``trip_id``, ``route_id``, ``start_s``, ``end_s`` (s after midnight) and optionally
        ``block_id``, ``service_id``, ``direction_id``, ``first_stop_id``, ``last_stop_id``.
    min_layover_s : float
        Shortest time (s) between arriving at a terminus and leaving it again.

    Returns
    -------
    Series of str, index of ``trips``
        Block id per trip.  Trips without a ``block_id`` are chained per route (and service)
        in time order: a trip continues a block whose last trip ended at the stop this trip
        starts from (``last_stop_id == first_stop_id``; without stop ids, a trip of the other
        direction) at least ``min_layover_s`` earlier; the block waiting longest is taken
        (first in, first out), else a new block starts.  Inferred ids read
        ``<route_id>:<service_id>:<n>``.
    """
    out = pd.Series(pd.NA, index=trips.index, dtype="object")
    if "block_id" in trips:
        given = trips["block_id"].astype("string").str.strip()
        has = given.notna() & (given != "")
        out[has] = given[has].astype(str)
    else:
        has = pd.Series(False, index=trips.index)
    todo = trips[~has]
    if todo.empty:
        return out.astype(str)
    keys = ["route_id"] + (["service_id"] if "service_id" in todo else [])
    by_stop = "first_stop_id" in todo and "last_stop_id" in todo
    by_dir = not by_stop and "direction_id" in todo
    for key, group in todo.groupby(keys, sort=True, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        prefix = ":".join(str(k) for k in key)
        group = group.sort_values("start_s", kind="stable")
        if by_stop:
            origins, dests = group["first_stop_id"].tolist(), group["last_stop_id"].tolist()
        elif by_dir:
            d = group["direction_id"].astype(int).tolist()
            origins, dests = [1 - x for x in d], d
        else:
            origins = dests = [None] * len(group)
        open_blocks: list[list] = []  # [free_at_s, terminus, block_no]
        n_blocks = 0
        for idx, start, end, origin, dest in zip(group.index, group["start_s"], group["end_s"],
                                                 origins, dests):
            ready = [k for k, (free_at, terminus, _) in enumerate(open_blocks)
                     if free_at + min_layover_s <= start and terminus == origin]
            chosen = min(ready, key=lambda k: open_blocks[k][0]) if ready else None
            if chosen is None:
                n_blocks += 1
                block = n_blocks
            else:
                block = open_blocks.pop(chosen)[2]
            open_blocks.append([end, dest, block])
            out[idx] = f"{prefix}:{block}"
    return out.astype(str)

