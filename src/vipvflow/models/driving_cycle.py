"""Driving cycles: the scheduled timing between stops as a 2 s speed / stop / gradient series.

Between two consecutive stops the bus follows a trapezoidal speed profile (accelerate at
``a``, cruise at ``v``, brake at ``b``) that covers the inter-stop distance D in exactly the
scheduled running time T (departure to next arrival)::

    D = v T - v^2 / (2 a) - v^2 / (2 b)   =>   v = (T - sqrt(T^2 - 4 k D)) / (2 k),
    k = 1 / (2 a) + 1 / (2 b)

which is the slowest cruise speed that makes it (triangular when the cruise time is zero).
When no such v <= speed limit exists the schedule is infeasible: the bus drives the
minimum-time profile (at the limit, or triangular on short legs), arrives late, and the
delay is recorded in the report, never hidden. At a stop it dwells for the scheduled dwell,
or ``dwell_s`` when the timetable gives none (arrival = departure); a late bus leaves after
at most ``dwell_s``, so layovers absorb delays. The profile is analytic; it is sampled on a
``dt_s`` grid (2 s, as VECTO cycles), and road gradient comes from the segments.
"""
from __future__ import annotations


import numpy as np
import pandas as pd

from ..store import DataDir


def _limits(cfg):
    if cfg is None:
        from .params import CycleCfg
        cfg = CycleCfg()
    return (float(cfg.max_accel_mps2), float(cfg.max_decel_mps2),
            float(cfg.speed_limit_kmh) / 3.6, float(cfg.dwell_s), float(cfg.dt_s))


def cycle_phases(stop_dist_m, arrival_s, departure_s, cfg=None):
    """Analytic phases of the cycle and the per-leg report.

    Parameters
    ----------
    stop_dist_m : array (m,)
        Stop distances along the shape (m, non-decreasing).
    arrival_s, departure_s : array (m,)
        Scheduled times (s, from the trip's first departure).
    cfg : vipvflow.config.CycleCfg, optional

    Returns
    -------
    phases : DataFrame[t0, dur, x0, v0, acc, stop]
        Start time (s), duration (s), start distance (m), start speed (m/s), acceleration
        (m/s2) and whether it is a dwell.
    legs : DataFrame
        Per leg: ``from_stop, to_stop, dist_m, scheduled_s, driven_s, arrival_s,
        scheduled_arrival_s, delay_s, feasible``.
    """
    acc_max, dec_max, vmax, dwell_s, _ = _limits(cfg)
    d = np.asarray(stop_dist_m, float)
    arr = np.asarray(arrival_s, float)
    dep = np.asarray(departure_s, float)
    k = 1.0 / (2 * acc_max) + 1.0 / (2 * dec_max)
    ph: list[tuple] = []
    legs = []
    t = dep[0]
    for i in range(len(d) - 1):
        D = d[i + 1] - d[i]
        T = arr[i + 1] - t
        feasible = True
        if D <= 1e-9:
            run = max(T, 0.0)
            if run > 0:
                ph.append((t, run, d[i], 0.0, 0.0, True))
        else:
            disc = T * T - 4 * k * D
            v = (T - np.sqrt(disc)) / (2 * k) if T > 0 and disc >= 0 else np.inf
            if v > vmax:
                feasible = False
                v = vmax if D >= k * vmax * vmax else np.sqrt(D / k)
            t_acc, t_dec = v / acc_max, v / dec_max
            d_cruise = max(D - k * v * v, 0.0)
            t_cruise = d_cruise / v
            x = d[i]
            ph.append((t, t_acc, x, 0.0, acc_max, False))
            x += v * v / (2 * acc_max)
            if t_cruise > 0:
                ph.append((t + t_acc, t_cruise, x, v, 0.0, False))
                x += d_cruise
            ph.append((t + t_acc + t_cruise, t_dec, x, v, -dec_max, False))
            run = t_acc + t_cruise + t_dec
        t_arr = t + run
        legs.append((i, i + 1, D, T, run, t_arr, arr[i + 1], t_arr - arr[i + 1], feasible))
        t = t_arr
        if i + 1 < len(d) - 1:                                   # dwell at an inner stop
            sched = dep[i + 1] - arr[i + 1]
            dwell = sched if sched > 0 else dwell_s
            leave = max(arr[i + 1] + dwell, t + min(dwell, dwell_s))
            ph.append((t, leave - t, d[i + 1], 0.0, 0.0, True))
            t = leave
    phases = pd.DataFrame(ph, columns=["t0", "dur", "x0", "v0", "acc", "stop"])
    legs = pd.DataFrame(legs, columns=["from_stop", "to_stop", "dist_m", "scheduled_s",
                                       "driven_s", "arrival_s", "scheduled_arrival_s",
                                       "delay_s", "feasible"])
    # rounding noise of a feasible leg is not a delay
    legs.loc[legs["feasible"], "delay_s"] = legs.loc[legs["feasible"], "delay_s"].clip(lower=0)
    legs["delay_s"] = legs["delay_s"].where(legs["delay_s"].abs() > 1e-6, 0.0)
    return phases, legs


def _state(phases: pd.DataFrame, t: np.ndarray):
    t0 = phases["t0"].to_numpy()
    # a phase starting within a microsecond of a sample owns it (sums of durations carry
    # rounding noise, and a sample at the scheduled arrival must see the dwell)
    j = np.clip(np.searchsorted(t0, t + 1e-6, side="right") - 1, 0, len(t0) - 1)
    tau = np.clip(t - t0[j], 0.0, phases["dur"].to_numpy()[j])
    v0, a = phases["v0"].to_numpy()[j], phases["acc"].to_numpy()[j]
    x = phases["x0"].to_numpy()[j] + v0 * tau + 0.5 * a * tau * tau
    v = np.maximum(v0 + a * tau, 0.0)
    return x, v, phases["stop"].to_numpy()[j]


def _gradient_at(dist, segments):
    if segments is None or len(segments) == 0:
        return np.zeros(len(dist))
    s = segments.sort_values("cum_dist_m")
    cum = s["cum_dist_m"].to_numpy()
    j = np.clip(np.searchsorted(cum, dist, side="right") - 1, 0, len(cum) - 1)
    return s["gradient"].to_numpy(float)[j]


def driving_cycle(stop_dist_m, arrival_s, departure_s, cfg=None, segments=None) -> pd.DataFrame:
    """A trip's driving cycle sampled every ``cfg.dt_s`` seconds.

    Parameters
    ----------
    stop_dist_m, arrival_s, departure_s : array
        Stops of the trip: distance along the shape (m), scheduled arrival and departure (s
        after the first departure).
    cfg : vipvflow.config.CycleCfg, optional
        Accelerations (m/s2), speed limit (km/h), default dwell (s), time step (s).
    segments : DataFrame, optional
        The shape's segments (``cum_dist_m, gradient``) for the gradient column.

    Returns
    -------
    DataFrame[t_s, dist_m, speed_mps, stop, gradient]
        ``t_s`` from 0 (first departure) to the last arrival (rounded up to the step),
        ``dist_m`` along the shape, ``stop`` True while dwelling at a stop or at rest at
        the end. ``attrs["report"]`` holds ``feasible`` (bool), ``max_delay_s``,
        ``final_delay_s`` and ``late_legs`` (list of dicts), and ``attrs["legs"]`` every leg.

    References
    ----------
    VECTO's distance-based driving cycle (``.vdri``: target speed, stop time and gradient
    per distance; European Commission JRC, VECTO user manual), sampled here in time at
    ``dt_s`` as VECTO's modal results are.
    """
    *_, step = _limits(cfg)
    phases, legs = cycle_phases(stop_dist_m, arrival_s, departure_s, cfg)
    t_end = float(phases["t0"].iloc[-1] + phases["dur"].iloc[-1]) if len(phases) else 0.0
    t0 = float(np.asarray(departure_s, float)[0])
    n = int(np.ceil((t_end - t0) / step - 1e-9)) + 1
    t = t0 + np.arange(n) * step
    if len(phases):
        x, v, stop = _state(phases, t)
    else:
        x = np.full(n, float(np.asarray(stop_dist_m)[0]))
        v, stop = np.zeros(n), np.ones(n, bool)
    stop = stop | (t >= t_end - 1e-9)
    out = pd.DataFrame({"t_s": t - t0, "dist_m": x, "speed_mps": v, "stop": stop,
                        "gradient": _gradient_at(x, segments)})
    late = legs[~legs["feasible"]]
    out.attrs["report"] = {
        "feasible": bool(legs["feasible"].all()),
        "max_delay_s": float(legs["delay_s"].max()) if len(legs) else 0.0,
        "final_delay_s": float(legs["delay_s"].iloc[-1]) if len(legs) else 0.0,
        "late_legs": late.to_dict("records"),
    }
    out.attrs["legs"] = legs
    return out


def reach_times_from_phases(phases: pd.DataFrame, s) -> np.ndarray:
    """First time the cycle reaches distance *s* (s), exact on the analytic profile."""
    s = np.asarray(s, float)
    moving = phases[phases["dur"] > 0]
    x0, v0, a = (moving[c].to_numpy(float) for c in ("x0", "v0", "acc"))
    t0, dur = moving["t0"].to_numpy(float), moving["dur"].to_numpy(float)
    x1 = x0 + v0 * dur + 0.5 * a * dur * dur
    j = np.clip(np.searchsorted(x1, s, side="left"), 0, len(x1) - 1)
    ds = np.clip(s - x0[j], 0.0, None)
    aj, vj = a[j], v0[j]
    disc = np.maximum(vj * vj + 2 * aj * ds, 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        tau = np.where(np.abs(aj) > 1e-12, (np.sqrt(disc) - vj) / np.where(aj == 0, 1, aj),
                       ds / np.where(vj > 0, vj, np.inf))
    return t0[j] + np.clip(tau, 0.0, dur[j])


def cycle_reach_times(stop_d, arr, dep, seg_start, seg_len, cfg):
    """Per-segment timing of a pattern from its driving cycle (as
    :func:`vipvflow.inputs.gtfs.schedule.pattern_segment_times`, plus the cycle report)."""
    from ..inputs.gtfs.schedule import pattern_segment_times

    idx, _, _, cov = pattern_segment_times(stop_d, arr, dep, seg_start, seg_len)
    phases, legs = cycle_phases(stop_d, arr, dep, cfg)
    first, last = float(stop_d[0]), float(stop_d[-1])
    a = np.maximum(seg_start[idx], first)
    b = np.minimum(seg_start[idx] + seg_len[idx], last)
    if len(phases) == 0 or not (phases["dur"] > 0).any():
        t0 = np.zeros(len(idx))
        t1 = t0.copy()
    else:
        t0 = reach_times_from_phases(phases, a)
        t1 = reach_times_from_phases(phases, b)
        t0[a <= first] = 0.0
        # a stop inside a segment: the bus reaches the segment's end after dwelling there
        t1[b >= last] = phases["t0"].iloc[-1] + phases["dur"].iloc[-1]
    rep = {"max_delay_s": float(legs["delay_s"].max()) if len(legs) else 0.0}
    return idx, t0, t1 - t0, cov, rep


def pattern_cycle(data_dir, pattern_id: int, cfg=None) -> pd.DataFrame:
    """The driving cycle of one stored pattern (``gtfs/pattern_stops.parquet``)."""
    import pyarrow.parquet as pq

    gdir = DataDir(data_dir).gtfs
    ps = pq.read_table(gdir.table("pattern_stops"),
                       filters=[("pattern_id", "==", int(pattern_id))]).to_pandas()
    if ps.empty:
        raise KeyError(f"pattern {pattern_id} not in {gdir.table('pattern_stops')}")
    ps = ps.sort_values("stop_index")
    trips = pq.read_table(gdir.trips, columns=["pattern_id", "shape_id"],
                          filters=[("pattern_id", "==", int(pattern_id))]).to_pandas()
    segs = pq.read_table(gdir.segments, columns=["shape_id", "cum_dist_m", "gradient"],
                         filters=[("shape_id", "==", str(trips["shape_id"].iloc[0]))]).to_pandas()
    return driving_cycle(ps["dist_m"].to_numpy(), ps["arr_s"].to_numpy(), ps["dep_s"].to_numpy(),
                         cfg, segs)
