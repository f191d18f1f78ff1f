"""Interoperability with VECTO, the EU's vehicle energy consumption tool.

- Driving cycles: VECTO's distance-based cycle ``.vdri`` (header ``<s>,<v>,<grad>,<stop>``:
  distance m, target speed km/h, road gradient %, stop time s; optional extra columns such as
  ``<Aux_Alt>,<Padd>``).  A row's speed and gradient hold from its distance to the next row's;
  a row with ``v = 0`` is a stop of ``stop`` seconds at that distance.  :func:`read_vdri`,
  :func:`write_vdri`, :func:`cycle_to_vdri` (a trip's 2 s cycle to distance-based rows) and
  :func:`vdri_to_cycle` (VECTO's own mission cycles to a time-based cycle the built-in model
  runs).
- Vehicle: :func:`write_vecto_job` writes an engineering-mode battery-electric job (``.vecto``,
  ``.vveh``, ``.vem`` + motor curves, ``.vbat``, ``.vacc``) from a
  :class:`vipvflow.models.vehicle.VehicleParams`, as far as the formats allow (its docstring lists what
  maps and what does not).
- Results: :func:`read_vmod` reads VECTO's modal results (``.vmod``: time-resolved, units in
  brackets, UTF-8 BOM) and :func:`vmod_energy` integrates their power columns into the same
  per-trip energies :func:`vipvflow.models.vehicle.simulate_cycle` gives, so a user who runs VECTO can
  replace the built-in consumption.

VECTO files seen in the wild start with a UTF-8 BOM or not, are sometimes Windows-1252 (``m/s²``
in ``.vacc`` headers) and may hold ``#`` comments; the readers accept all of these.
"""
from __future__ import annotations

import io
import json
import re
from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError
from ..store import write_bytes, write_text

VDRI_NAMES = {"s": "s_m", "v": "v_kmh", "grad": "grad_pct", "stop": "stop_s"}
VDRI_HEADER = {v: f"<{k}>" for k, v in VDRI_NAMES.items()}


# --------------------------------------------------------------------------- CSV basics

def _read_text(path: str | Path) -> str:
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        return raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        return raw.decode("cp1252", errors="replace")


def _read_vecto_csv(path: str | Path) -> pd.DataFrame:
    """A VECTO CSV file as a DataFrame with the header's names stripped of spaces and BOM."""
    text = _read_text(path)
    lines = [ln.split("#", 1)[0].rstrip() for ln in text.splitlines()]
    lines = [ln for ln in lines if ln.strip()]
    if not lines:
        raise InputError(f"{path}: empty file")
    try:
        df = pd.read_csv(io.StringIO("\n".join(lines)), skipinitialspace=True,
                         na_values=["-"], keep_default_na=True)
    except (pd.errors.ParserError, ValueError) as exc:
        raise InputError(f"{path}: not a VECTO CSV file: {exc}") from None
    df.columns = [str(c).strip() for c in df.columns]
    return df


def _fmt(values) -> list[str]:
    """Shortest text that reads back to the same float; integers without a decimal point."""
    return [np.format_float_positional(float(x), trim="-") for x in values]


# --------------------------------------------------------------------------- .vdri

def read_vdri(path: str | Path) -> pd.DataFrame:
    """Read a VECTO distance-based driving cycle.

    Parameters
    ----------
    path : str or Path
        ``.vdri`` file, with or without a UTF-8 BOM.

    Returns
    -------
    DataFrame
        ``s_m`` (m), ``v_kmh`` (km/h), ``grad_pct`` (%), ``stop_s`` (s), in file order, plus
        any further columns under their names without brackets (``Aux_Alt``, ``Padd``, ...).

    Raises
    ------
    InputError
        Naming the file when a column is missing, a value is not a number or the distance
        decreases.
    """
    df = _read_vecto_csv(path)
    names = {}
    for col in df.columns:
        key = col.strip().strip("<>").strip()
        key = re.sub(r"\s*\[.*\]$", "", key)
        names[col] = VDRI_NAMES.get(key.lower(), key)
    df = df.rename(columns=names)
    missing = [c for c in ("s_m", "v_kmh", "stop_s") if c not in df]
    if missing:
        kind = " (a time-based cycle: only distance-based .vdri are read)" if "t" in df else ""
        raise InputError(f"{path}: missing columns {', '.join(VDRI_HEADER[c] for c in missing)}"
                         f"{kind}; header is {', '.join(map(str, names))}")
    if "grad_pct" not in df:
        df["grad_pct"] = 0.0
    for col in df.columns:
        values = pd.to_numeric(df[col], errors="coerce")
        bad = values.isna() & df[col].notna()
        if bad.any():
            row = int(np.flatnonzero(bad.to_numpy())[0])
            raise InputError(f"{path}: line {row + 2}: column {col}: not a number: {df[col].iloc[row]!r}")
        df[col] = values.astype(float)
    if (np.diff(df["s_m"].to_numpy()) < 0).any():
        row = int(np.flatnonzero(np.diff(df["s_m"].to_numpy()) < 0)[0]) + 1
        raise InputError(f"{path}: line {row + 2}: distance <s> decreases")
    first = ["s_m", "v_kmh", "grad_pct", "stop_s"]
    return df[first + [c for c in df.columns if c not in first]].reset_index(drop=True)


def write_vdri(vdri: pd.DataFrame, path: str | Path) -> Path:
    """Write rows with columns ``s_m, v_kmh, grad_pct, stop_s`` (+ extras) as a ``.vdri`` file.

    Plain UTF-8 without BOM, ``\\r\\n`` line ends as VECTO writes them; numbers in their shortest
    exact form, so :func:`read_vdri` gives the same values back.  A time-based cycle (columns
    ``t_s, dist_m, speed_mps, stop, gradient``) is converted with :func:`cycle_to_vdri` first.
    """
    if "s_m" not in vdri and "speed_mps" in vdri:
        vdri = cycle_to_vdri(vdri)
    first = ["s_m", "v_kmh", "grad_pct", "stop_s"]
    cols = first + [c for c in vdri.columns if c not in first]
    header = ",".join(VDRI_HEADER.get(c, f"<{c}>") for c in cols)
    columns = [_fmt(vdri[c].to_numpy()) for c in cols]
    lines = [header] + [",".join(row) for row in zip(*columns)]
    return write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8"), path)


def _stationary_runs(moving: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and last index of each run of consecutive stationary samples."""
    still = (~moving).astype(np.int8)
    edges = np.diff(np.concatenate([[0], still, [0]]))
    return np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1


def cycle_to_vdri(cycle: pd.DataFrame, decimals: int = 2, min_stop_s: float = 1.0,
                  v_still_mps: float = 1e-3) -> pd.DataFrame:
    """A time-based driving cycle as VECTO distance-based rows.

    Parameters
    ----------
    cycle : DataFrame
        ``t_s`` (s), ``dist_m`` (m), ``speed_mps`` (m/s), ``gradient`` (dz/ds).
    decimals : int
        Distances are rounded to this many decimals (m); rows falling on the same distance
        are merged (a stop row wins).
    min_stop_s : float
        Shortest stop time written (s): VECTO needs a positive stop time where ``v = 0``, and a
        bus that halts for less than a sample step still halts.
    v_still_mps : float
        Speeds at or below this count as standing.

    Returns
    -------
    DataFrame ``s_m, v_kmh, grad_pct, stop_s``
        One row per moving sample (its distance, speed and gradient) and one row per stop
        (each run of standing samples: ``v = 0``, ``stop`` = its duration).  Distances start
        at 0, so the last ``s_m`` is the cycle's length.
    """
    t = cycle["t_s"].to_numpy(float)
    s = np.round(cycle["dist_m"].to_numpy(float) - float(cycle["dist_m"].iloc[0]), decimals)
    v = cycle["speed_mps"].to_numpy(float)
    grad = cycle["gradient"].to_numpy(float) if "gradient" in cycle else np.zeros_like(v)
    moving = v > v_still_mps
    first, last = _stationary_runs(moving)
    mov = np.flatnonzero(moving)
    rows = pd.DataFrame({
        "s_m": np.concatenate([s[first], s[mov]]),
        "v_kmh": np.concatenate([np.zeros(len(first)), np.round(v[mov] * 3.6, 3)]),
        "grad_pct": np.round(np.concatenate([grad[first], grad[mov]]) * 100.0, 3),
        "stop_s": np.concatenate([np.maximum(t[last] - t[first], min_stop_s),
                                  np.zeros(len(mov))]),
        "_order": np.concatenate([first, mov]),
        "_is_stop": np.concatenate([np.ones(len(first), bool), np.zeros(len(mov), bool)]),
    })
    rows = rows.sort_values(["s_m", "_is_stop", "_order"], ascending=[True, False, True])
    rows = rows.drop_duplicates("s_m", keep="first").sort_values("_order")
    return rows[["s_m", "v_kmh", "grad_pct", "stop_s"]].reset_index(drop=True)


def vdri_summary(vdri: pd.DataFrame) -> dict:
    """Length (m), stops (rows with ``v = 0``) and total stop time (s) of a distance-based cycle."""
    s = vdri["s_m"].to_numpy(float)
    stops = vdri["v_kmh"].to_numpy(float) == 0
    return {"distance_m": float(s[-1] - s[0]) if len(s) else 0.0,
            "stops": int(stops.sum()),
            "stop_time_s": float(vdri["stop_s"].to_numpy(float)[stops].sum())}


def vdri_to_cycle(vdri: pd.DataFrame, dt_s: float = 2.0, max_accel_mps2: float = 1.0,
                  max_decel_mps2: float = 1.3, grid_m: float = 1.0) -> pd.DataFrame:
    """Expand a VECTO distance-based cycle into a time-based one the built-in model runs.

    The bus follows each row's target speed as closely as constant acceleration and
    deceleration limits allow (a simple driver, not VECTO's look-ahead coasting), halts at every
    ``v = 0`` row for its stop time and leaves it towards the next non-zero target speed (VECTO's
    queue rows such as ``10809,0,..,52.4`` followed by ``10860,0,..,28.2`` become creep-and-stop).
    It starts from standstill.

    Parameters
    ----------
    vdri : DataFrame
        As :func:`read_vdri` gives.
    dt_s : float
        Output step (s); the last sample falls on the cycle's end.
    max_accel_mps2, max_decel_mps2 : float
        Driver limits (m/s2), as the ``trajectory.cycle`` configuration.
    grid_m : float
        Distance step (m) on which the speed profile is computed.

    Returns
    -------
    DataFrame ``t_s, dist_m, speed_mps, stop, gradient``

    Notes
    -----
    The speed limit from the accelerations is found without a loop: with ``u = v^2``, the
    forward limit is ``u(x) = min_{x' <= x} (cap(x') + 2 a (x - x'))`` = ``2 a x +
    cummin(cap - 2 a x)``, the backward one the same with ``d`` from the end.  Within a grid
    step the acceleration is constant, so its time is ``2 dx / (v0 + v1)``.
    """
    s = vdri["s_m"].to_numpy(float)
    v = vdri["v_kmh"].to_numpy(float) / 3.6
    stop = vdri["stop_s"].to_numpy(float)
    grad = vdri["grad_pct"].to_numpy(float) / 100.0
    if len(s) < 2:
        raise InputError("driving cycle has fewer than two rows")
    a, d = max_accel_mps2, max_decel_mps2
    halt = v <= 0
    # target of the interval after a halt: the next non-zero speed
    target = pd.Series(np.where(halt, np.nan, v)).bfill().fillna(0.0).to_numpy()
    x = np.unique(np.concatenate([np.arange(s[0], s[-1], grid_m), s]))
    row = np.clip(np.searchsorted(s, x, side="right") - 1, 0, len(s) - 1)
    cap = target[row] ** 2
    halt_x = np.isin(x, s[halt])
    cap[halt_x] = 0.0
    cap[0] = 0.0
    fwd = 2 * a * x + np.minimum.accumulate(cap - 2 * a * x)
    bwd = -2 * d * x + np.minimum.accumulate((cap + 2 * d * x)[::-1])[::-1]
    u = np.maximum(np.minimum(np.minimum(cap, fwd), bwd), 0.0)
    vel = np.sqrt(u)

    dx = np.diff(x)
    vsum = vel[:-1] + vel[1:]
    # rest-to-rest inside one step: accelerate then brake, peak v^2 = 2 dx a d / (a + d)
    vpeak = np.sqrt(2 * dx * a * d / (a + d))
    step_t = np.where(vsum > 1e-9, 2 * dx / np.maximum(vsum, 1e-12), vpeak / a + vpeak / d)
    dwell = np.zeros_like(x)
    stop_at = {float(si): st for si, st in zip(s[halt], stop[halt])}
    for i in np.flatnonzero(halt_x):  # a handful of stops per km
        dwell[i] = stop_at[float(x[i])]
    arrive = np.concatenate([[0.0], np.cumsum(step_t + dwell[:-1])])
    depart = arrive + dwell
    kt = np.column_stack([arrive, depart]).ravel()
    kx = np.repeat(x, 2)
    kv = np.repeat(vel, 2)
    t_end = depart[-1]
    t = np.arange(0.0, t_end, dt_s)
    t = np.append(t[t < t_end - 1e-9], t_end)
    dist = np.interp(t, kt, kx)
    speed = np.interp(t, kt, kv)
    hi = np.flatnonzero(halt_x & (dwell > 0))
    in_stop = np.zeros(len(t), bool)
    if len(hi):
        k = np.clip(np.searchsorted(arrive[hi], t, side="right") - 1, 0, len(hi) - 1)
        in_stop = (t >= arrive[hi][k] - 1e-9) & (t <= depart[hi][k] + 1e-9)
    speed[in_stop] = 0.0
    g_row = np.clip(np.searchsorted(s, dist, side="right") - 1, 0, len(s) - 1)
    return pd.DataFrame({"t_s": t, "dist_m": dist - s[0], "speed_mps": speed,
                         "stop": in_stop, "gradient": grad[g_row]})


# --------------------------------------------------------------------------- .vmod

def read_vmod(path: str | Path) -> pd.DataFrame:
    """Read a VECTO modal results file (``.vmod``).

    Column names are kept as in the file (``"time [s]"``, ``"Pwheel [kW]"``, ...), stripped of
    the BOM and spaces; ``-`` (not applicable) becomes NaN.  ``df.attrs["units"]`` maps each
    column to the unit in its brackets.
    """
    df = _read_vecto_csv(path)
    units = {}
    for col in df.columns:
        m = re.search(r"\[(.*)\]\s*$", col)
        units[col] = m.group(1) if m else ""
    if not any(c.startswith("time") for c in df.columns):
        raise InputError(f"{path}: no 'time [s]' column: not a VECTO modal results file")
    df.attrs["units"] = units
    df.attrs["source"] = str(path)
    return df


# names of the same quantity in VECTO 2.x/3.0 (first) and later versions (second)
_VMOD_COLUMNS = {
    "time": ["time [s]"],
    "dt": ["dt [s]", "simulation_interval [s]"],
    "dist": ["dist [m]"],
    "wheel": ["Pwheel [kW]", "P_wheel_in [kW]"],
    "brake": ["Pbrake [kW]", "P_brake_loss [kW]"],
    "aux": ["Paux [kW]", "P_aux_el [kW]", "P_aux_mech [kW]"],
    "battery_terminal": ["P_REESS_T [kW]", "P_bat_T [kW]", "P_Bat_T [kW]"],
    "battery_internal": ["P_REESS_int [kW]", "P_bat_int [kW]"],
    "battery_loss": ["P_REESS_loss [kW]", "P_bat_loss [kW]", "P_Bat_loss [kW]"],
}


def _col(df: pd.DataFrame, key: str) -> str | None:
    lower = {c.lower().replace(" ", ""): c for c in df.columns}
    for name in _VMOD_COLUMNS[key]:
        hit = lower.get(name.lower().replace(" ", ""))
        if hit is not None:
            return hit
    return None


def vmod_intervals(df: pd.DataFrame) -> np.ndarray:
    """Duration (s) of each row of a ``.vmod``: the ``dt [s]`` column, else from ``time [s]``.

    VECTO writes the midpoint of each simulated interval as its time; without a ``dt`` column an
    interval reaches halfway to its neighbours (the first and last mirror their neighbour).
    """
    dt_col = _col(df, "dt")
    if dt_col is not None:
        return df[dt_col].to_numpy(float)
    t = df[_col(df, "time")].to_numpy(float)
    if len(t) < 2:
        return np.ones_like(t)
    mid = 0.5 * (t[:-1] + t[1:])
    edges = np.concatenate([[t[0] - (mid[0] - t[0])], mid, [t[-1] + (t[-1] - mid[-1])]])
    return np.diff(edges)


def vmod_energy(vmod: pd.DataFrame | str | Path) -> dict:
    """Energies of one VECTO run, integrated from its modal results.

    Parameters
    ----------
    vmod : DataFrame or path
        As :func:`read_vmod` gives.

    Returns
    -------
    dict
        ``distance_km`` (last ``dist`` value), ``duration_s`` (sum of the intervals),
        ``wheel_kwh`` (positive wheel power integrated), ``brake_kwh`` (brake power,
        positive number), ``aux_kwh``, and for battery-electric runs ``battery_kwh`` (internal
        battery power, else terminal power), ``battery_loss_kwh``; NaN where the file lacks
        the column (a conventional vehicle has no battery).  ``columns`` names the columns used.
    """
    df = read_vmod(vmod) if not isinstance(vmod, pd.DataFrame) else vmod
    dt = vmod_intervals(df)
    used = {}

    def integrate(key, part=None):
        col = _col(df, key)
        if col is None:
            return float("nan")
        used[key] = col
        p = np.nan_to_num(df[col].to_numpy(float))
        if part == "pos":
            p = np.maximum(p, 0.0)
        elif part == "abs":
            p = np.abs(p)
        return float(np.sum(p * dt) / 3600.0)

    dist_col = _col(df, "dist")
    out = {
        "distance_km": float(df[dist_col].to_numpy(float)[-1]) / 1e3 if dist_col else float("nan"),
        "duration_s": float(np.sum(dt)),
        "wheel_kwh": integrate("wheel", "pos"),
        "brake_kwh": integrate("brake", "abs"),
        "aux_kwh": integrate("aux"),
        "battery_kwh": integrate("battery_internal"),
        "battery_loss_kwh": integrate("battery_loss"),
    }
    if np.isnan(out["battery_kwh"]):
        out["battery_kwh"] = integrate("battery_terminal")
    out["columns"] = used
    return out


def vmod_trip_energies(files: dict[str, str | Path] | list[str | Path]) -> pd.DataFrame:
    """Energies of several VECTO runs, one row each, to replace the built-in consumption.

    Parameters
    ----------
    files : dict or list
        ``{trip_id or pattern_id: path}``; a list uses each file's stem as the key.

    Returns
    -------
    DataFrame indexed by key
        The :func:`vmod_energy` values, with ``consumption_kwh`` = ``battery_kwh`` (the column
        the reduce step joins with PV kWh).
    """
    if not isinstance(files, dict):
        files = {Path(f).stem: f for f in files}
    rows = {}
    for key, path in files.items():
        e = vmod_energy(path)
        e.pop("columns")
        rows[key] = e
    out = pd.DataFrame.from_dict(rows, orient="index")
    out["consumption_kwh"] = out["battery_kwh"]
    out.index.name = "key"
    return out


# --------------------------------------------------------------------------- job files

def _header() -> dict:
    return {"CreatedBy": "vipvflow", "Date": datetime.now(timezone.utc).isoformat(timespec="seconds"),
            "AppVersion": "3", "FileVersion": 10}


def _write_json(path: Path, body: dict, file_version: int) -> Path:
    header = _header()
    header["FileVersion"] = file_version
    return write_text(json.dumps({"Header": header, "Body": body}, indent=2) + "\n", path)


def _write_csv(path: Path, header: str, rows: np.ndarray) -> Path:
    lines = [header] + [",".join(_fmt(r)) for r in rows]
    return write_bytes(("\r\n".join(lines) + "\r\n").encode("utf-8"), path)


def write_vecto_job(out_dir: str | Path, params, cycles: list[str | Path] = (),
                    name: str | None = None, ambient_c: float = 15.0,
                    nominal_voltage_v: float = 650.0, initial_soc: float | None = None,
                    max_accel_mps2: float = 1.0, max_decel_mps2: float = 1.3) -> dict[str, Path]:
    """Write the vehicle as a VECTO engineering-mode battery-electric job.

    Files (``<name>`` defaults to the catalog name): ``<name>.vecto`` (job, lists the cycles),
    ``<name>.vveh`` (vehicle), ``<name>.vem`` with ``<name>.vemp`` (max drive / recuperation
    torque) and ``<name>.vemo`` (electric power map), ``<name>.vbat`` (battery) and
    ``<name>.vacc`` (driver acceleration limits).  The layout follows VECTO's generic
    battery-electric test vehicle (``GenericVehicleB4``: B4 = e-axle at the wheel side).

    What maps:

    - ``curb_mass_kg`` -> ``CurbWeight``; passengers x load factor x mass each -> ``Loading``;
      ``max_mass_kg`` -> ``MassMax`` (t); ``cda_m2`` -> ``CdxA``; ``crr`` -> ``RRCISO`` of both
      axles; ``wheel_radius_m`` -> ``rdyn`` (mm);
    - ``n_motors``, ``gear_ratio`` -> ``ElectricMotors[0].Count`` and ``Ratio``;
      ``motor_torque_nm`` and ``motor_power_kw`` -> ``.vemp`` (T = min(T_max, P/omega), the
      recuperation side further limited by ``regen_power_limit_kw`` shared by the motors);
      ``eaxle_map`` (or the constant efficiency) -> ``.vemo`` as electric power
      P_el = P_mech / eta (motoring) and P_mech x eta (generating); because the map already
      holds the gear losses, ``MechanicalEfficiency`` is written as 1;
    - ``rotating_mass_factor`` -> the motor ``Inertia``, all rotating mass lumped on the motors
      (J = f_rot m r^2 / (i^2 n)), axle inertias 0;
    - ``battery_kwh`` -> ``Capacity`` (Ah at ``nominal_voltage_v``); ``soc_min``/``soc_max`` ->
      ``SOC_min``/``SOC_max`` (%); ``initial_soc`` (default ``soc_max``) -> ``InitialSoC``;
    - ``aux_kw(ambient_c)`` -> the job's constant ``Padd_electric`` (W).

    What does not map: the HVAC curve over temperature (VECTO models bus auxiliaries its own
    way; only the value at ``ambient_c`` is written), ``regen_min_speed_kmh`` (VECTO has no
    such threshold), ``air_density_kg_m3`` (a VECTO constant, 1.188), the battery's charge /
    discharge efficiencies (VECTO uses an internal-resistance curve and an open-circuit voltage
    curve: the ``.vbat`` names ``<name>.vbatr`` and ``<name>.vbatv``, which the user supplies
    with the pack's data, as the motor's drag curve ``<name>.vemd``).  VECTO validates the job
    when it loads it; the files are a start, not a certified input.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    name = name or params.name or "vehicle"
    r, i, n = params.wheel_radius_m, params.gear_ratio, params.n_motors
    m = params.mass_kg
    paths: dict[str, Path] = {}

    # motor curves (per motor)
    t_max = params.motor_torque_nm
    p_max = params.motor_power_kw * 1e3
    n_max = 11000.0 if params.eaxle_map is None else max(params.eaxle_map.speed_rpm)
    speeds = np.unique(np.concatenate([np.linspace(0.0, n_max, 12),
                                       [round(p_max / t_max * 60 / (2 * np.pi), 1)]]))
    omega = speeds * 2 * np.pi / 60
    drive = np.minimum(t_max, p_max / np.maximum(omega, 1e-9))
    p_rec = p_max if params.regen_power_limit_kw is None else min(p_max, params.regen_power_limit_kw * 1e3 / n)
    recup = np.minimum(t_max, p_rec / np.maximum(omega, 1e-9))
    paths["vemp"] = _write_csv(out / f"{name}.vemp", "n [rpm] , T_drive [Nm] , T_recuperation [Nm]",
                               np.column_stack([speeds, np.round(drive, 2), -np.round(recup, 2)]))
    torques = np.linspace(-t_max, t_max, 13)
    nn, tt = np.meshgrid(speeds, torques, indexing="ij")
    eta = params.eaxle_eta(tt, nn)
    p_mech = tt * nn * 2 * np.pi / 60
    p_el = np.where(p_mech >= 0, p_mech / eta, p_mech * eta) / 1e3
    paths["vemo"] = _write_csv(out / f"{name}.vemo", "n [rpm] , T [Nm] , P_el [kW]",
                               np.column_stack([nn.ravel(), np.round(tt.ravel(), 2),
                                                np.round(p_el.ravel(), 4)]))
    inertia = params.rotating_mass_factor * m * r**2 / (i**2 * n)
    paths["vem"] = _write_json(out / f"{name}.vem", {
        "SavedInDeclMode": False, "Model": f"{name} e-axle motor",
        "FullLoadCurve": f"{name}.vemp", "DragCurve": f"{name}.vemd",
        "EfficiencyMap": f"{name}.vemo", "Inertia": round(inertia, 4),
        "ContinuousPower": params.motor_power_kw * 1e3,
        "ThermalOverloadBuffer": 0.6, "ThermalOverloadRecoveryFactor": 0.9}, 1)
    paths["vbat"] = _write_json(out / f"{name}.vbat", {
        "SavedInDeclMode": False, "Model": f"{name} battery",
        "InternalResistanceCurve": f"{name}.vbatr",
        "SOC_min": round(params.soc_min * 100, 3), "SOC_max": round(params.soc_max * 100, 3),
        "MaxCurrentFactor": 5,
        "Capacity": round(params.battery_kwh * 1e3 / nominal_voltage_v, 2),
        "SoCCurve": f"{name}.vbatv"}, 1)
    loading = params.passenger_capacity * params.load_factor * params.passenger_mass_kg
    axle = {"Inertia": 0.0, "Wheels": "-", "TwinTyres": False, "RRCISO": params.crr,
            "FzISO": 30436.0}
    paths["vveh"] = _write_json(out / f"{name}.vveh", {
        "SavedInDeclMode": False, "VehCat": "Citybus", "LegislativeClass": "M3",
        "CurbWeight": params.curb_mass_kg, "CurbWeightExtra": 0.0, "Loading": round(loading, 1),
        "MassMax": round((params.max_mass_kg or m) / 1e3, 3), "rdyn": round(r * 1e3, 1),
        "PowertrainConfiguration": "BatteryElectric", "CdCorrMode": "CdofVdecl", "CdCorrFile": "",
        "ElectricMotors": [{"Count": n, "Ratio": i, "MechanicalEfficiency": 1.0,
                            "Position": "B4", "MotorFile": f"{name}.vem"}],
        "Battery": {"NumPacks": 1, "BatteryFile": f"{name}.vbat"},
        "InitialSoC": round(100 * (params.soc_max if initial_soc is None else initial_soc), 3),
        "TorqueLimits": {}, "IdlingSpeed": 0.0,
        "AxleConfig": {"Type": "4x2", "Axles": [
            {**axle, "AxleWeightShare": 0.38, "Type": "VehicleNonDriven"},
            {**axle, "AxleWeightShare": 0.62, "TwinTyres": True, "Type": "VehicleDriven"}]},
        "EngineStopStart": False, "EcoRoll": "None", "PredictiveCruiseControl": "None",
        "CdxA": params.cda_m2, "VehicleHeight": 3.2}, 10)
    paths["vacc"] = _write_csv(out / f"{name}.vacc", "v [km/h],acc [m/s^2],dec [m/s^2]",
                               np.array([[0.0, max_accel_mps2, -max_decel_mps2],
                                         [120.0, max_accel_mps2, -max_decel_mps2]]))
    paths["vecto"] = _write_json(out / f"{name}.vecto", {
        "SavedInDeclMode": False, "EngineOnlyMode": False, "VehicleFile": f"{name}.vveh",
        "Padd_electric": round(float(params.aux_kw(ambient_c)) * 1e3, 1),
        "VACC": f"{name}.vacc",
        "LAC": {"Enabled": False, "PreviewDistanceFactor": 10.0, "DF_offset": 2.5,
                "DF_scaling": 1.5, "DF_targetSpeedLookup": "", "Df_velocityDropLookup": ""},
        "OverSpeedEcoRoll": {"Mode": "Off", "MinSpeed": 50.0, "OverSpeed": 5.0, "UnderSpeed": 5.0},
        "Cycles": [Path(c).name for c in cycles]}, 9)
    return paths
