"""CAMS solar radiation: read, check, put on a minute grid, look up per pass.

Input files are CAMS Radiation Service (all-sky, with clear-sky columns) or CAMS McClear
(clear-sky only) CSV files in the soda-pro format, read with
:func:`pvlib.iotools.read_cams`.  CAMS gives the irradiation integrated over each
observation period (Wh/m2); pvlib divides by the period length so every value here is the
**mean irradiance over the period in W/m2**, stamped at the **centre of the period** (UTC).

``ingest_cams`` puts each location's series on a regular one-minute grid (grid times are
minute centres, ``hh:mm:30``; 15 min and hourly series are interpolated linearly between
period centres) and writes ``radiation/radiation.parquet`` plus
``radiation/ingest_report.json``.  :class:`RadiationTable` loads one year of it, computes the
sun position once on the grid (pvlib, apparent zenith) and interpolates everything to pass
times by index arithmetic.

Quality flags (bit mask, column ``flag``): a gap (missing period or ``nan``), a negative
value, GHI above 1.1 x the top-of-atmosphere horizontal irradiance, GHI above the clear-sky
GHI by more than the margin, DNI above the extraterrestrial normal irradiance.  A flagged
value is dropped and filled by linear interpolation between its good neighbours.

References
----------
CAMS solar radiation time-series, Copernicus Atmosphere Monitoring Service,
https://ads.atmosphere.copernicus.eu/datasets/cams-solar-radiation-timeseries
"""
from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pandas as pd

from ..errors import InputError, accept_hint
from ..store import DataDir, RadiationDir, staging_dir, swap_dir, write_json

#: irradiance columns kept (W/m2): all-sky and clear-sky global horizontal, direct normal,
#: diffuse horizontal
COLUMNS = ("ghi", "dni", "dhi", "ghi_clear", "dni_clear", "dhi_clear")


FLAG_GAP = 1            # missing period or nan in the file


FLAG_NEGATIVE = 2       # negative irradiance


FLAG_GHI_TOA = 4        # GHI > 1.1 x top-of-atmosphere horizontal irradiance


FLAG_GHI_CLEAR = 8      # GHI > clear-sky GHI x factor + offset


FLAG_DNI_EXTRA = 16     # DNI > extraterrestrial normal irradiance


FLAG_NO_ALLSKY = 32     # McClear only: all-sky columns are the clear-sky values


#: GHI is flagged when above ``factor x ghi_clear + offset_wm2`` (cloud enhancement can
#: exceed clear sky by tens of per cent for minutes)
CLEAR_SKY_MARGIN = (1.5, 50.0)


_REQUIRED = ("Clear sky GHI", "Clear sky DHI", "Clear sky BNI")


_ALLSKY = ("GHI", "DHI", "BNI")


_STEPS_S = {"1min": 60, "15min": 900, "1h": 3600}


_GRID_S = 60


# --------------------------------------------------------------------------- reading
#: byte order marks and the encodings they name (UTF-32 before UTF-16: FF FE starts both)
_BOMS = ((b"\xff\xfe\x00\x00", "utf-32"), (b"\x00\x00\xfe\xff", "utf-32"),
         (b"\xef\xbb\xbf", "utf-8-sig"), (b"\xff\xfe", "utf-16"), (b"\xfe\xff", "utf-16"))
#: bytes Windows-1252 leaves undefined: a file holding one is read as latin-1
_NOT_CP1252 = (b"\x81", b"\x8d", b"\x8f", b"\x90", b"\x9d")


def file_encoding(path: Path) -> str:
    """The encoding to read a CAMS CSV in: ``utf-8``, or as its byte order mark says
    (``utf-8-sig``, ``utf-16``, ``utf-32``), else ``cp1252`` (or ``latin-1`` where a byte is
    undefined in cp1252) for a file that is not UTF-8. Streamed: memory stays at one block."""
    import codecs

    try:
        fh = open(path, "rb")
    except OSError as exc:
        raise InputError(f"{path}: cannot open CAMS file: {exc.strerror}") from None
    with fh:
        head = fh.read(4)
        bom = next((enc for b, enc in _BOMS if head.startswith(b)), None)
        if bom is not None:
            return bom
        fh.seek(0)
        utf8, ok, cp1252 = codecs.getincrementaldecoder("utf-8")(), True, True
        while block := fh.read(1 << 20):
            if ok:
                try:
                    utf8.decode(block)
                except UnicodeDecodeError:
                    ok = False
            cp1252 = cp1252 and not any(b in block for b in _NOT_CP1252)
        return "utf-8" if ok else ("cp1252" if cp1252 else "latin-1")


def _scan_header(path: Path, encoding: str = "utf-8") -> dict:
    """Check the '#' header of a CAMS CSV; return the line numbers and values found."""
    import pvlib  # here and below imported where used: a worker's radiation lookups never need it
    try:
        fh = open(path, encoding=encoding, errors="replace")
    except OSError as exc:
        raise InputError(f"{path}: cannot open CAMS file: {exc.strerror}") from None
    info: dict = {"lines": {}, "encoding": encoding}
    with fh:
        first_data = None
        for no, line in enumerate(fh, start=1):
            line = line.rstrip("\r\n")
            if not line.startswith("#"):
                if line.strip():
                    first_data = (no, line)
                    break
                continue
            body = line.lstrip("# ")
            if body.startswith("Observation period"):
                info["columns"] = body.split(";")
                info["lines"]["columns"] = no
            elif ": " in body:
                key, value = body.split(": ", 1)
                info[key.strip()] = value.strip()
                info["lines"][key.strip()] = no
    if "columns" not in info:
        raise InputError(f"{path}: not a CAMS radiation/McClear CSV: no header line "
                         "'# Observation period;...' naming the columns")
    cols_line = info["lines"]["columns"]
    missing = [c for c in _REQUIRED if c not in info["columns"]]
    if missing:
        raise InputError(f"{path}: line {cols_line}: column header lacks {', '.join(missing)}")
    period = info.get("Summarization (integration) period")
    if period is None:
        raise InputError(f"{path}: header line '# Summarization (integration) period: ...' missing")
    if period not in pvlib.iotools.sodapro.SUMMATION_PERIOD_TO_TIME_STEP:
        raise InputError(f"{path}: line {info['lines']['Summarization (integration) period']}: "
                         f"unknown summarization period {period!r}")
    ref = info.get("Time reference", "")
    if not (ref.startswith("Universal time") or ref.startswith("True solar time")):
        where = f"line {info['lines']['Time reference']}" if "Time reference" in info else "header"
        raise InputError(f"{path}: {where}: time reference must be 'Universal time (UT)' or "
                         f"'True solar time (TST)', got {ref!r}")
    for key, limit in (("Latitude", 90.0), ("Longitude", 180.0)):
        full = next((k for k in info if isinstance(k, str) and k.startswith(key + " ")), None)
        try:
            info[key.lower()] = float(info[full])
        except (TypeError, ValueError):
            where = f"line {info['lines'][full]}" if full else "header"
            raise InputError(f"{path}: {where}: {key} missing or not a number") from None
        if not -limit <= info[key.lower()] <= limit:
            raise InputError(f"{path}: line {info['lines'][full]}: {key} {info[full]} is not a "
                             f"{key.lower()} (-{limit:g} to {limit:g} degrees)")
    alt = next((k for k in info if isinstance(k, str) and k.startswith("Altitude")), None)
    try:
        info["altitude"] = float(info[alt]) if alt else 0.0
        info["altitude_declared"] = alt is not None
    except (TypeError, ValueError):
        raise InputError(f"{path}: line {info['lines'][alt]}: Altitude {info[alt]!r} is not a "
                         "number") from None
    if first_data is None:
        raise InputError(f"{path}: no data rows after the header")
    no, line = first_data
    if line.count(";") + 1 != len(info["columns"]):
        raise InputError(f"{path}: line {no}: {line.count(';') + 1} fields but the header "
                         f"(line {cols_line}) names {len(info['columns'])} columns")
    last = _last_line(path, encoding)
    if not last.startswith("#") and last.count(";") + 1 != len(info["columns"]):
        raise InputError(f"{path}: last line: {last.count(';') + 1} fields but the header "
                         f"(line {cols_line}) names {len(info['columns'])} columns (file "
                         "truncated?)")
    if not re.match(r"^\d{4}-\d\d-\d\dT[\d:.]+/\d{4}-\d\d-\d\dT[\d:.]+$", line.split(";")[0]):
        raise InputError(f"{path}: line {no}: observation period {line.split(';')[0]!r} is "
                         "not 'start/end' in ISO 8601")
    info["first_data_line"] = no
    info["time_reference"] = "TST" if ref.startswith("True solar") else "UT"
    info["time_step"] = pvlib.iotools.sodapro.SUMMATION_PERIOD_TO_TIME_STEP[period]
    return info


def _last_line(path: Path, encoding: str = "utf-8", tail: int = 1 << 16) -> str:
    """The last non-empty line of a text file, read from its end only."""
    width = {"utf-16": 2, "utf-32": 4}.get(encoding, 1)
    with open(path, "rb") as fh:
        bom = fh.read(4)
        fh.seek(0, os.SEEK_END)
        size = fh.tell()
        start = max(0, size - tail)
        start -= start % width                   # whole code units of UTF-16 / UTF-32
        fh.seek(start)
        data = fh.read()
    if width > 1:
        # the tail has no byte order mark: the file's first bytes say the byte order
        big = bom.startswith(b"\xfe\xff") or bom.startswith(b"\x00\x00\xfe\xff")
        codec = f"{encoding}-{'be' if big else 'le'}"
        if start == 0:
            data = data[width if width == 2 else 4:]
    else:
        codec = encoding
    text = data.decode(codec, errors="replace").lstrip("\ufeff")
    lines = text.rstrip("\r\n").splitlines()
    return lines[-1] if lines else ""


def tst_to_utc(t_tst: pd.DatetimeIndex, longitude: float) -> pd.DatetimeIndex:
    """Convert true solar time to UTC.

    TST = UTC + longitude x 4 min/deg + equation of time (Spencer 1971, pvlib).

    Parameters
    ----------
    t_tst : DatetimeIndex, naive or UTC-labelled, true solar time
    longitude : float, degrees east
    """
    import pvlib

    naive = t_tst.tz_localize(None) if t_tst.tz is not None else t_tst
    # equation of time changes by < 30 s per day: evaluating it at the TST date is exact enough
    eot_min = pvlib.solarposition.equation_of_time_spencer71(naive.day_of_year.to_numpy())
    shift = pd.to_timedelta(longitude * 4.0 + np.asarray(eot_min), unit="min")
    return (naive - shift).tz_localize("UTC")


def read_cams_file(path, clear_sky_margin=CLEAR_SKY_MARGIN,
                   accept=()) -> tuple[pd.DataFrame, dict]:
    """Read one CAMS Radiation or McClear CSV into mean irradiances with quality flags.

    Parameters
    ----------
    path : str or Path
        CAMS CSV (1 min, 15 min, 1 h, daily or monthly; UT or true solar time).
    clear_sky_margin : (float, float)
        GHI is flagged above ``factor x ghi_clear + offset`` (W/m2).
    accept : iterable of str
        Plausibility findings accepted (``checks.accept``): with ``radiation_components``,
        GHI below DHI or above the clear-sky margin for more than
        :data:`MAX_IMPLAUSIBLE_MINUTES` is read (the values above the margin flagged and
        interpolated) instead of refused.

    Returns
    -------
    frame : DataFrame
        One row per observation period: ``t_start``, ``t_end``, ``t_centre``
        (datetime64[ns, UTC]), ``ghi, dni, dhi, ghi_clear, dni_clear, dhi_clear`` (mean W/m2
        over the period; all-sky NaN in a McClear file), ``toa`` (W/m2, horizontal),
        ``flag`` (uint8 bit mask, see module doc).  Rows for missing periods are inserted
        with NaN values and :data:`FLAG_GAP`.
    meta : dict
        ``file, latitude, longitude, altitude, time_step, time_reference, has_all_sky`` and the
        counts ``rows, gaps, negative, ghi_above_toa, ghi_above_clear, dni_above_extra``.

    Raises
    ------
    InputError
        Naming the file and the header line or column that is wrong.
    """
    import pvlib

    path = Path(path)
    encoding = file_encoding(path)
    info = _scan_header(path, encoding)
    try:
        with open(path, encoding=encoding, newline="") as fh:
            data, _ = pvlib.iotools.read_cams(fh, integrated=False, label="left",
                                              map_variables=True)
    except Exception as exc:  # pandas parse errors: name the file, the line and the column
        raise InputError(f"{path}: {_bad_row(path, info) or 'cannot parse CAMS data rows: ' + _one_line(exc)}") from None
    period = data["Observation period"].astype(str).str.split("/")
    try:
        start = pd.DatetimeIndex(pd.to_datetime(period.str[0], format="ISO8601"))
        end = pd.DatetimeIndex(pd.to_datetime(period.str[1], format="ISO8601"))
    except (ValueError, TypeError) as exc:
        raise InputError(f"{path}: {_bad_row(path, info) or 'column Observation period: not ISO 8601 start/end (' + _one_line(exc) + ')'}") from None
    # checked on the file's own clock: true solar time shifts each day by the equation of time
    step = _STEPS_S.get(info["time_step"])
    coverage = _check_periods(path, info, start, end, step)
    if info["time_reference"] == "TST":
        start, end = tst_to_utc(start, info["longitude"]), tst_to_utc(end, info["longitude"])
    else:
        start = start.tz_localize("UTC") if start.tz is None else start.tz_convert("UTC")
        end = end.tz_localize("UTC") if end.tz is None else end.tz_convert("UTC")
    has_all = all(c in info["columns"] for c in _ALLSKY)
    out = pd.DataFrame({"t_start": start, "t_end": end})
    out["t_centre"] = out["t_start"] + (out["t_end"] - out["t_start"]) / 2
    for col in COLUMNS:
        if col in data.columns:
            vals = pd.to_numeric(data[col], errors="coerce").to_numpy(np.float64)
        else:
            vals = np.full(len(data), np.nan)
        out[col] = vals
    out["toa"] = (pd.to_numeric(data["ghi_extra"], errors="coerce").to_numpy(np.float64)
                  if "ghi_extra" in data.columns else np.nan)
    bad_values = [c for c in COLUMNS if c in data.columns
                  and pd.to_numeric(data[c], errors="coerce").isna().all()]
    if bad_values and len(data) > 0:
        raise InputError(f"{path}: column(s) {', '.join(bad_values)} hold no numbers")

    if step is not None and len(out) > 1:
        out = _insert_gap_rows(out, step)
    flag = np.zeros(len(out), np.uint8)
    core = list(COLUMNS) if has_all else ["ghi_clear", "dni_clear", "dhi_clear"]
    vals = out[core].to_numpy()
    flag[np.isnan(vals).any(axis=1)] |= FLAG_GAP
    neg = (vals < 0).any(axis=1)
    flag[neg] |= FLAG_NEGATIVE
    dni_extra = pvlib.irradiance.get_extra_radiation(pd.DatetimeIndex(out["t_centre"])).to_numpy()
    toa = out["toa"].to_numpy()
    above_toa = np.zeros(len(out), bool)
    for col in ("ghi", "ghi_clear"):
        if col in core:
            above_toa |= out[col].to_numpy() > 1.1 * toa + 1.0
    flag[above_toa] |= FLAG_GHI_TOA
    above_clear = np.zeros(len(out), bool)
    if has_all:
        fac, off = clear_sky_margin
        above_clear = out["ghi"].to_numpy() > fac * out["ghi_clear"].to_numpy() + off
        flag[above_clear] |= FLAG_GHI_CLEAR
    above_extra = np.zeros(len(out), bool)
    for col in ("dni", "dni_clear"):
        if col in core:
            above_extra |= out[col].to_numpy() > dni_extra + 1.0
    flag[above_extra] |= FLAG_DNI_EXTRA
    _check_plausible(path, info, out, core, dni_extra, neg)
    if has_all and "radiation_components" not in accept:
        _check_components(path, out, above_clear, (step or 60) / 60.0, clear_sky_margin)
    if not has_all:
        flag |= FLAG_NO_ALLSKY
    out["flag"] = flag
    meta = {"file": str(path), "latitude": info["latitude"], "longitude": info["longitude"],
            "altitude": info["altitude"], "altitude_declared": info["altitude_declared"],
            "time_step": info["time_step"],
            "time_reference": info["time_reference"], "has_all_sky": has_all,
            "encoding": encoding,
            "rows": int(len(data)), "gaps": int(((flag & FLAG_GAP) > 0).sum()),
            "negative": int(neg.sum()), "ghi_above_toa": int(above_toa.sum()),
            "ghi_above_clear": int(np.asarray(above_clear).sum()),
            "dni_above_extra": int(above_extra.sum()),
            "start": str(out["t_start"].iloc[0]) if len(out) else None,
            "end": str(out["t_end"].iloc[-1]) if len(out) else None, **coverage}
    return out, meta


def _one_line(exc: Exception) -> str:
    """An exception's message on one line (pandas' parse errors run over several)."""
    return " ".join(str(exc).split())[:300]


def _bad_row(path: Path, info: dict) -> str | None:
    """Where the data rows of a CAMS file stop being readable: ``line N: observation period
    '...' is not an ISO 8601 date`` or ``line N: GHI 'abc' is not a number``; None when
    every row reads."""
    try:
        rows = pd.read_csv(path, sep=";", comment="#", header=None, names=info["columns"],
                           dtype=str, keep_default_na=False, encoding=info["encoding"])
    except (ValueError, OSError, UnicodeDecodeError):
        return None
    first = info["columns"][0]
    periods = rows[first].str.strip().str.split("/")
    for part, what in ((0, "start"), (1, "end")):
        text = periods.str[part]
        parsed = pd.to_datetime(text, format="ISO8601", errors="coerce")
        bad = (parsed.isna() | text.isna()).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            return (f"line {_line_of(info, i)}: observation period {rows[first].iloc[i]!r}: its "
                    f"{what} is not an ISO 8601 date and time")
    for col in info["columns"][1:]:
        text = rows[col].str.strip()
        empty = text.isin(["", "nan", "NaN"])
        bad = (~empty & pd.to_numeric(text.where(~empty), errors="coerce").isna()).to_numpy()
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            return f"line {_line_of(info, i)}: {col} {rows[col].iloc[i]!r} is not a number"
    return None


def _line_of(info: dict, row: int) -> int:
    """File line of data row *row* (0-based; blank lines inside the data not counted)."""
    return int(info["first_data_line"]) + int(row)


def _check_periods(path: Path, info: dict, start, end, step) -> dict:
    """Rows against the header: each row's period length, the spacing of rows, their order,
    and the first/last row against the declared ``Date begin``/``Date end``.

    A period or spacing that contradicts the declared summarization period, or rows out of
    order, raise :class:`InputError` (values would be divided by the wrong duration); rows
    ending before the declared end are reported (``rows_end_before_declared_s``)."""
    if len(start) == 0:
        return {}
    name = info["Summarization (integration) period"]
    if step is not None:
        length = (end - start).total_seconds().to_numpy()
        bad = np.flatnonzero(np.abs(length - step) > 1.0)
        if len(bad):
            i = int(bad[0])
            raise InputError(f"{path}: line {_line_of(info, i)}: observation period lasts "
                             f"{length[i] / 60:g} min but the header declares '{name}' "
                             f"({step / 60:g} min); {len(bad)} rows disagree")
    naive = start.tz_convert(None) if start.tz is not None else start
    t0 = naive.to_numpy().astype("datetime64[s]").astype(np.int64)
    if len(t0) > 1:
        d = np.diff(t0)
        back = np.flatnonzero(d <= 0)
        if len(back):
            i = int(back[0]) + 1
            raise InputError(f"{path}: line {_line_of(info, i)}: observation period starts "
                             f"{'before' if d[i - 1] < 0 else 'at'} the previous row's start "
                             "(rows must be in time order without repeats)")
        if step is not None:
            off = np.flatnonzero(d % step != 0)
            if len(off):
                i = int(off[0]) + 1
                raise InputError(f"{path}: line {_line_of(info, i)}: row starts "
                                 f"{d[i - 1] / 60:g} min after the previous one, not a "
                                 f"multiple of the declared {step / 60:g} min period")
    out = {}
    for key, which, value in (("Date begin (ISO 8601)", "declared_begin", start[0]),
                              ("Date end (ISO 8601)", "declared_end", end[-1])):
        if key not in info:
            continue
        try:
            declared = pd.Timestamp(info[key])
        except ValueError:
            raise InputError(f"{path}: line {info['lines'][key]}: {key[:-13]} "
                             f"{info[key]!r} is not an ISO 8601 date") from None
        declared = declared.tz_localize("UTC") if declared.tz is None else declared.tz_convert("UTC")
        value = value.tz_localize("UTC") if value.tz is None else value.tz_convert("UTC")
        out[which] = str(declared)
        if info["time_reference"] == "UT":
            if which == "declared_end":
                out["rows_end_before_declared_s"] = max(0.0, (declared - value).total_seconds())
            else:
                out["rows_begin_after_declared_s"] = max(0.0, (value - declared).total_seconds())
    return out


#: share of daylight rows above the physical limit or negative beyond which a file is
#: refused rather than repaired (isolated bad values are flagged and interpolated)
MAX_BAD_SHARE = 0.01


def _check_plausible(path: Path, info: dict, out: pd.DataFrame, core, dni_extra, neg) -> None:
    """Refuse values that cannot be mean irradiances over the declared period: above the
    extraterrestrial normal irradiance (e.g. 15-minute sums under a 1-minute header) or
    negative, in more than :data:`MAX_BAD_SHARE` of the daylight rows."""
    limit = 1.1 * dni_extra + 1.0
    cols = [c for c in ("ghi", "ghi_clear", "dni", "dni_clear", "toa") if c in core or c == "toa"]
    vals = out[cols].to_numpy()
    above = (vals > limit[:, None]).any(axis=1)
    light = (np.nan_to_num(vals) > 0).any(axis=1)
    allowed = max(10, MAX_BAD_SHARE * max(int(light.sum()), 1))
    name = info["Summarization (integration) period"]
    if above.sum() > allowed:
        i = int(np.flatnonzero(above)[0])
        worst = float(np.nanmax(vals[i]))
        raise InputError(f"{path}: {int(above.sum())} rows exceed the extraterrestrial "
                         f"irradiance (from {out['t_start'].iloc[i]:%Y-%m-%d %H:%M} UTC: "
                         f"{worst:.0f} W/m2 > {limit[i]:.0f}): values do not fit the declared "
                         f"period '{name}' (sums over a longer period?)")
    if neg.sum() > allowed:
        i = int(np.flatnonzero(neg)[0])
        raise InputError(f"{path}: {int(neg.sum())} rows hold negative irradiance (first "
                         f"{out['t_start'].iloc[i]:%Y-%m-%d %H:%M} UTC): not a CAMS "
                         "radiation series")


#: minutes of a file (in total) with GHI below DHI, or above the clear-sky GHI by more than
#: the margin, beyond which the file is refused (``radiation_components``): CAMS derives
#: DHI and GHI together (DHI <= GHI) and the all-sky GHI from the clear-sky one, so a real
#: series holds none; a few minutes are flagged and interpolated
MAX_IMPLAUSIBLE_MINUTES = 15
#: DHI counts as above GHI when it exceeds ``factor x GHI + offset_wm2`` (rounding of the
#: Wh/m2 sums over a minute)
DHI_ABOVE_GHI = (1.05, 10.0)


def _check_components(path: Path, out: pd.DataFrame, above_clear, step_min: float,
                      clear_sky_margin) -> None:
    """Refuse a file whose GHI lies below its DHI, or above its clear-sky GHI by more than
    *clear_sky_margin*, for more than :data:`MAX_IMPLAUSIBLE_MINUTES` (swapped columns, or a
    column in another unit), naming the first instant and the values there."""
    ghi, dhi, clear = (out[c].to_numpy() for c in ("ghi", "dhi", "ghi_clear"))
    fac, off = DHI_ABOVE_GHI
    with np.errstate(invalid="ignore"):
        below = dhi > fac * ghi + off
    hint = accept_hint("radiation_components")
    for bad, what in ((below, "GHI below DHI"),
                      (np.asarray(above_clear, bool),
                       f"GHI above {clear_sky_margin[0]:g} x the clear-sky GHI + "
                       f"{clear_sky_margin[1]:g} W/m2")):
        minutes = float(bad.sum()) * step_min
        if minutes <= MAX_IMPLAUSIBLE_MINUTES:
            continue
        i = int(np.flatnonzero(bad)[0])
        at = f"{out['t_start'].iloc[i]:%Y-%m-%d %H:%M} UTC"
        if what.startswith("GHI below"):
            found = (f"GHI {ghi[i]:.0f} W/m2, DHI {dhi[i]:.0f} W/m2: the diffuse part of the light "
                     "cannot exceed the whole; are the GHI and DHI columns swapped?")
        else:
            found = (f"GHI {ghi[i]:.0f} W/m2, clear-sky GHI {clear[i]:.0f} W/m2: are the all-sky "
                     "and clear-sky columns swapped, or GHI in other units?")
        raise InputError(f"{path}: {what} for {minutes:,.0f} minutes (first at {at}: {found}) "
                         f"{hint}")


def _insert_gap_rows(frame: pd.DataFrame, step_s: int) -> pd.DataFrame:
    """Insert NaN rows for periods missing from a regular series."""
    t0 = frame["t_start"].to_numpy("datetime64[s]").astype(np.int64)
    k = np.rint((t0 - t0[0]) / step_s).astype(np.int64)
    n = int(k.max()) + 1
    if n == len(frame) and (np.diff(k) == 1).all():
        return frame.reset_index(drop=True)
    full = pd.DataFrame({"t_start": pd.to_datetime(t0[0] + np.arange(n) * step_s, unit="s", utc=True)})
    full["t_end"] = full["t_start"] + pd.Timedelta(seconds=step_s)
    full["t_centre"] = full["t_start"] + pd.Timedelta(seconds=step_s / 2)
    for col in frame.columns:
        if col in ("t_start", "t_end", "t_centre"):
            continue
        arr = np.full(n, np.nan)
        arr[k] = frame[col].to_numpy(np.float64)
        full[col] = arr
    return full


# --------------------------------------------------------------------------- ingest
def _to_minute_grid(frames: list[pd.DataFrame]) -> pd.DataFrame:
    """Merge one location's frames onto the minute-centre grid (linear interpolation)."""
    frame = pd.concat(frames, ignore_index=True).sort_values("t_centre", kind="stable")
    tc = frame["t_centre"].to_numpy("datetime64[ms]").astype(np.int64) / 1000.0
    t_lo = np.floor(frame["t_start"].min().timestamp() / _GRID_S) * _GRID_S
    t_hi = np.ceil(frame["t_end"].max().timestamp() / _GRID_S) * _GRID_S
    grid = np.arange(t_lo, t_hi, _GRID_S) + _GRID_S / 2
    out = {"t_utc": grid.astype(np.int64)}
    flag_in = frame["flag"].to_numpy(np.uint8)
    has_all = ((flag_in & FLAG_NO_ALLSKY) == 0).any()
    flag = np.zeros(len(grid), np.uint8)
    # per grid minute, the flags of the period that contains it
    ts = frame["t_start"].to_numpy("datetime64[ms]").astype(np.int64) / 1000.0
    te = frame["t_end"].to_numpy("datetime64[ms]").astype(np.int64) / 1000.0
    order = np.argsort(ts, kind="stable")
    j = np.searchsorted(ts[order], grid, side="right") - 1
    inside = (j >= 0) & (grid < te[order][np.clip(j, 0, None)])
    flag[inside] = flag_in[order][j[inside]] & ~np.uint8(FLAG_NO_ALLSKY)
    flag[~inside] |= FLAG_GAP
    for col in COLUMNS:
        v = frame[col].to_numpy(np.float64)
        src = col
        if not has_all and not col.endswith("_clear"):
            v = frame[col + "_clear"].to_numpy(np.float64)
            src = col + "_clear"
        bad_bits = FLAG_GAP | FLAG_NEGATIVE | FLAG_GHI_TOA | FLAG_DNI_EXTRA
        good = np.isfinite(v) & (v >= 0) & ((flag_in & bad_bits) == 0)
        if src in ("ghi",):
            good &= (flag_in & FLAG_GHI_CLEAR) == 0
        if not good.any():
            raise InputError(f"radiation column {src}: no usable value (all missing, negative "
                             "or above the physical limit)")
        out[col] = np.interp(grid, tc[good], v[good]).astype(np.float32)
    if not has_all:
        flag |= FLAG_NO_ALLSKY
    out["flag"] = flag
    return pd.DataFrame(out)


def gap_runs(t_utc, flag) -> list[dict]:
    """Runs of consecutive grid minutes without data (:data:`FLAG_GAP`), interpolated on the
    grid: ``start_utc, end_utc`` (Unix s, minute edges) and ``minutes``."""
    gap = (np.asarray(flag) & FLAG_GAP) > 0
    if not gap.any():
        return []
    edges = np.diff(np.r_[0, gap.astype(np.int8), 0])
    first, stop = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    t = np.asarray(t_utc, np.int64)
    return [{"start_utc": int(t[a]) - _GRID_S // 2, "end_utc": int(t[b - 1]) + _GRID_S // 2,
             "minutes": int(b - a)} for a, b in zip(first, stop)]


def ingest_cams(paths, data_dir, clear_sky_margin=CLEAR_SKY_MARGIN, accept=()) -> dict:
    """Read CAMS files and write ``radiation/radiation.parquet`` + ``ingest_report.json``.

    Files of the same location (lat/lon to 4 decimals) are merged: a Radiation Service file
    gives all-sky and clear-sky, a McClear file clear-sky only (all-sky is then set to the
    clear-sky values and flagged :data:`FLAG_NO_ALLSKY`).  Daily and monthly files are read
    by :func:`read_cams_file` but cannot drive a per-minute simulation and are refused here.

    Parameters
    ----------
    paths : list of str or Path
    data_dir : str or Path
    accept : iterable of str
        Plausibility findings accepted (see :func:`read_cams_file`).

    Returns
    -------
    dict
        The report (also written as JSON): per file the counts of flagged values, per
        location the grid span and number of minutes.

    Output columns: ``t_utc`` int64 (Unix s, minute centre), ``ghi, dni, dhi, ghi_clear,
    dni_clear, dhi_clear`` float32 W/m2, ``flag`` uint8, ``lat, lon, altitude`` float64.
    """
    paths = [Path(p) for p in ([paths] if isinstance(paths, (str, Path)) else paths)]
    if not paths:
        raise InputError("ingest cams: no CAMS files given")
    by_loc: dict = {}
    files = []
    for p in paths:
        frame, meta = read_cams_file(p, clear_sky_margin, accept=accept)
        if meta["time_step"] not in _STEPS_S:
            raise InputError(f"{p}: time step {meta['time_step']} (daily/monthly means) cannot "
                             "drive a per-pass simulation; give 1 min, 15 min or 1 h data")
        key = (round(meta["latitude"], 4), round(meta["longitude"], 4))
        by_loc.setdefault(key, {"frames": [], "alt": meta["altitude"],
                                "alt_declared": meta["altitude_declared"]})["frames"].append(frame)
        files.append(meta)
    parts, locations = [], []
    for (lat, lon), item in by_loc.items():
        grid = _to_minute_grid(item["frames"])
        grid["lat"], grid["lon"], grid["altitude"] = lat, lon, item["alt"]
        parts.append(grid)
        locations.append({"lat": lat, "lon": lon, "altitude": item["alt"],
                          "altitude_declared": item["alt_declared"], "minutes": len(grid),
                          "start_utc": int(grid["t_utc"].iloc[0]) - _GRID_S // 2,
                          "end_utc": int(grid["t_utc"].iloc[-1]) + _GRID_S // 2,
                          "flagged_minutes": int((grid["flag"] & ~np.uint8(FLAG_NO_ALLSKY) > 0).sum()),
                          "gaps": gap_runs(grid["t_utc"].to_numpy(), grid["flag"].to_numpy()),
                          "all_sky_from_clear_sky": bool((grid["flag"] & FLAG_NO_ALLSKY).any())})
    table = pd.concat(parts, ignore_index=True)
    # a new radiation/ folder, swapped in as a whole (table, report; the sun caches rebuild)
    final = DataDir(data_dir).radiation.root
    out_dir = RadiationDir(staging_dir(final))
    table.to_parquet(out_dir.table, index=False)
    report = {"files": files, "locations": locations, "grid_step_s": _GRID_S,
              "time_stamp": "centre of each minute (Unix s)", "units": "W/m2 mean over the minute",
              "flags": {"gap": FLAG_GAP, "negative": FLAG_NEGATIVE, "ghi_above_toa": FLAG_GHI_TOA,
                        "ghi_above_clear": FLAG_GHI_CLEAR, "dni_above_extra": FLAG_DNI_EXTRA,
                        "all_sky_from_clear_sky": FLAG_NO_ALLSKY}}
    write_json(report, out_dir.report)
    swap_dir(out_dir.root, final)
    return report
