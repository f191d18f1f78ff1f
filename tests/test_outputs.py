"""Outputs a GIS user reads: the data dictionary in every file and in docs/outputs.md, months
as dates, segments.parquet's public columns and yearly figures, the summary's per-bus and
site figures, and the report (its table, inputs, CRS and maps over the building footprints)."""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import geopandas as gpd
import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import shapely

from vipvflow.simulation.dictionary import OUTPUTS, describe, render_markdown
from vipvflow.store import write_parquet

ROOT = Path(__file__).resolve().parents[1]


def test_docs_page_is_the_dictionary():
    """docs/outputs.md is rendered from the dictionary module (regenerate it with
    ``python -m vipvflow.simulation.dictionary > docs/outputs.md``)."""
    assert (ROOT / "docs" / "outputs.md").read_text(encoding="utf-8") == render_markdown()


def test_every_column_of_a_run_is_documented_in_its_file(small_run):
    for name in OUTPUTS:
        path = small_run / f"{name}.parquet"
        schema = pq.read_schema(path)
        kv = json.loads(schema.metadata[b"vipvflow:columns"])
        for field in schema:
            entry = describe(name, field.name)
            assert entry is not None, f"{name}.parquet: column {field.name!r} has no dictionary entry"
            assert field.metadata[b"unit"].decode() == entry.unit
            assert field.metadata[b"description"].decode() == entry.meaning
            assert kv[field.name] == {"unit": entry.unit, "description": entry.meaning}
        if "month" in schema.names:
            assert schema.field("month").type == pa.date32(), name


def test_months_are_the_first_day_of_the_simulated_month(small_run):
    """The small run simulates June 2024: every month column holds 2024-06-01."""
    import datetime

    for name in ("segment_month", "route_month", "monthly", "hourly_pattern", "trip_energy"):
        months = set(pd.read_parquet(small_run / f"{name}.parquet", columns=["month"])["month"])
        assert months == {datetime.date(2024, 6, 1)}, name
    smg = gpd.read_parquet(small_run / "segment_month.parquet")
    assert smg.crs.to_epsg() == 2169 and isinstance(smg["month"].iloc[0], datetime.date)


def test_instants_are_utc_timestamps_and_dates_are_date32(small_run):
    """The schema of every output file: a column the dictionary calls an instant is a
    timestamp with time zone UTC, one it calls a date a ``date32``, and no other column
    holds a time (no float Unix seconds, no naive or nanosecond timestamp for a day); the
    instants are where they should be (a block-day's window holds its first departure)."""
    from vipvflow.simulation.dictionary import DATE, INSTANT

    seen = {DATE: set(), INSTANT: set()}
    for name in OUTPUTS:
        schema = pq.read_schema(small_run / f"{name}.parquet")
        for field in schema:
            unit = describe(name, field.name).unit
            if unit == INSTANT:
                assert field.type == pa.timestamp("us", tz="UTC"), (name, field.name, field.type)
            elif unit == DATE:
                assert field.type == pa.date32(), (name, field.name, field.type)
            else:
                assert not pa.types.is_temporal(field.type), (name, field.name, field.type)
                assert not field.name.endswith("_utc") and "date" not in field.name, (name, field.name)
            if unit in seen:
                seen[unit].add(field.name)
    assert {"window_start_utc", "window_end_utc", "first_departure_utc", "last_arrival_utc",
            "infeasible_at_utc"} <= seen[INSTANT]
    assert seen[DATE] == {"service_date", "month"}
    bd = pd.read_parquet(small_run / "block_day.parquet")
    assert str(bd["window_start_utc"].dtype) == "datetime64[us, UTC]"
    assert (bd["window_start_utc"] <= bd["first_departure_utc"]).all()
    assert (bd["first_departure_utc"] < bd["last_arrival_utc"]).all()
    assert (bd["last_arrival_utc"] <= bd["window_end_utc"]).all()
    # the window is the block-day's seconds; it starts on its service date (local calendar,
    # Luxembourg: UTC+2 in June, so at 22:00 UTC the day before at the latest)
    seconds = (bd["window_end_utc"] - bd["window_start_utc"]).dt.total_seconds()
    np.testing.assert_allclose(seconds, bd["window_s"])
    local = bd["window_start_utc"].dt.tz_convert("Europe/Luxembourg")
    assert (local.dt.date >= bd["service_date"]).all()
    # a block-day the plan serves never fails; one whose SoC falls below soc_min says when
    crossed = bd[~bd["feasible"] & (bd["depot_short_kwh"] == 0)]
    assert crossed["infeasible_at_utc"].notna().all()
    assert bd.loc[bd["feasible"], "infeasible_at_utc"].isna().all()


def test_writer_keeps_undocumented_columns_and_geometry(tmp_path):
    """A column nobody documented is written without metadata, not refused; a GeoDataFrame
    keeps its CRS and reads back with dates."""
    import datetime

    df = pd.DataFrame({"month": ["2024-01", "2024-12"], "pv_kwh": [1.0, 2.0], "new_thing": [3, 4]})
    write_parquet(df, tmp_path / "monthly.parquet")
    schema = pq.read_schema(tmp_path / "monthly.parquet")
    assert schema.field("new_thing").metadata is None
    assert schema.field("pv_kwh").metadata[b"unit"] == b"kWh"
    back = pd.read_parquet(tmp_path / "monthly.parquet")
    assert list(back["month"]) == [datetime.date(2024, 1, 1), datetime.date(2024, 12, 1)]
    assert back["new_thing"].tolist() == [3, 4]

    g = gpd.GeoDataFrame({"segment_id": [0], "month": ["2024-03"], "mystery": [1.5]},
                         geometry=[shapely.LineString([(0, 0, 1), (10, 0, 1)])], crs="EPSG:2169")
    write_parquet(g, tmp_path / "segment_month.parquet")
    back = gpd.read_parquet(tmp_path / "segment_month.parquet")
    assert back.crs.to_epsg() == 2169 and back.geometry.iloc[0].length == 10.0
    assert back["month"].iloc[0] == datetime.date(2024, 3, 1)
    # a file that is not a run output is written as it is
    write_parquet(df, tmp_path / "other.parquet")
    assert pq.read_schema(tmp_path / "other.parquet").field("month").type == pa.string()


def test_segments_hold_public_factors_and_their_year(small_run):
    seg = gpd.read_parquet(small_run / "segments.parquet")
    summary = json.loads((small_run / "summary.json").read_text())
    assert not [c for c in seg.columns if c.startswith("r0_") or c in ("px", "py", "pz", "nx")]
    assert len(seg.columns) == len(OUTPUTS["segments"].columns)
    assert seg["svf"].between(0, 1).all() and seg["shading_loss"].between(-1e-6, 1).all()
    # mean irradiance on a segment is h (Wh/m2) over its hours
    row = seg.iloc[len(seg) // 2]
    assert row["g_total_in_service"] == pytest.approx(row["h_total"] / (row["seconds"] / 3600.0))
    # the fleet's specific yield is the segments' yearly yield weighted by the time spent on them
    # (the summary sums the trips' kWh, stored per partition in float32: 1e-7 relative)
    assert np.average(seg["kwh_per_kwp_year"], weights=seg["seconds"]) == pytest.approx(
        summary["kwh_per_kwp_driving"], rel=1e-7)
    assert summary["segments"] == len(seg)


def test_summary_per_bus_figures(small_run):
    s = json.loads((small_run / "summary.json").read_text())
    months = len(s["months"])
    # the old key is the fleet's sum over the simulated months; per bus it is scaled to a year
    assert s["roof_irradiation_kwh_m2_per_bus"] * s["buses"] * months / 12 == pytest.approx(
        s["irradiation_kwh_m2"]["total"], rel=1e-12)
    assert s["roof_irradiation_kwh_m2_per_bus"] < s["roof_irradiation_unshaded_kwh_m2_per_bus"] * (
        1 + s["reflection_gain_allsky"])
    # the demo's CAMS file covers 2024: a site year between Luxembourg's usual bounds
    assert 900 < s["site_ghi_kwh_m2_year"] < 1300


def _radiation(data_dir: Path, t_utc: np.ndarray, ghi: float) -> None:
    out = data_dir / "radiation"
    out.mkdir(parents=True)
    pd.DataFrame({"t_utc": t_utc.astype(np.int64), "ghi": np.float32(ghi), "dni": np.float32(0),
                  "dhi": np.float32(ghi), "lat": 49.6, "lon": 6.1}).to_parquet(out / "radiation.parquet")


def test_site_ghi_is_the_year_of_minutes(tmp_path):
    """A constant 100 W/m2 through leap year 2024 (8,784 h) is 878.4 kWh/m2; a year with 2 % of
    its minutes missing is not stated."""
    from vipvflow.simulation.annual import site_ghi_kwh_m2

    lo = pd.Timestamp("2024-01-01", tz="UTC").timestamp()
    minutes = lo + 30 + 60 * np.arange(366 * 1440)
    _radiation(tmp_path / "full", minutes, 100.0)
    assert site_ghi_kwh_m2(tmp_path / "full", 2024) == pytest.approx(878.4, rel=1e-9)
    _radiation(tmp_path / "gappy", minutes[: int(0.98 * len(minutes))], 100.0)
    assert site_ghi_kwh_m2(tmp_path / "gappy", 2024) is None
    # kept for the file as it was: a file written again is read again
    shutil.rmtree(tmp_path / "full")
    _radiation(tmp_path / "full", minutes, 50.0)
    assert site_ghi_kwh_m2(tmp_path / "full", 2024) == pytest.approx(439.2, rel=1e-9)


def test_footprints_are_the_city_ground_surfaces(small_config):
    """One footprint per building of the small demo city (its ground surfaces), in metres of
    EPSG:2169 around the routes."""
    from vipvflow.config import load_config
    from vipvflow.inputs.city.footprints import building_footprints
    from vipvflow.simulation.prepare import ensure_ingested

    cfg = load_config(small_config)
    ensure_ingested(cfg, say=lambda *a: None)
    report = json.loads((Path(cfg.data_dir) / "city" / "ingest_report.json").read_text())
    rings = building_footprints(cfg.data_dir)
    assert len(rings) == report["surfaces"]["ground"] == report["buildings"] > 0
    assert all(r.shape[1] == 2 and np.allclose(r[0], r[-1]) for r in rings)
    areas = [shapely.Polygon(r).area for r in rings]
    assert 20 < np.median(areas) < 2000   # m2: buildings, not tiles or degrees


def test_report_reads(small_run):
    html = (small_run / "report.html").read_text(encoding="utf-8")
    assert "How to read this" in html and "EPSG:2169" in html
    assert "demo_gtfs.zip" in html and "cams_radiation_demo.csv" in html
    assert "e+0" not in html.split("<img")[0]          # no scientific notation in the tables
    s = json.loads((small_run / "summary.json").read_text())
    assert f"{100 * s['shading_loss_allsky']:.1f}</td><td>%" in html
    for name in ("map_yield", "map_shading", "monthly_yield", "hourly_pattern", "routes", "avoided_cycles"):
        assert (small_run / "figures" / f"{name}.png").stat().st_size > 10_000, name


def test_report_carries_its_own_data_dictionary(small_run):
    """report.html explains every column of every output file and every summary key itself
    (a pip install has no docs/): no link to docs/outputs.md, the links go to its section."""
    import html as h

    from vipvflow.simulation.dictionary import SUMMARY

    text = (small_run / "report.html").read_text(encoding="utf-8")
    assert "docs/outputs.md" not in text
    assert 'id="data-dictionary"' in text and text.count("href='#data-dictionary'") >= 1
    dictionary = text.split('id="data-dictionary"', 1)[1]
    for name, spec in OUTPUTS.items():
        assert f"<code>{name}.parquet</code>" in dictionary, name
        for c in spec.columns:
            e = describe(name, c)
            assert f"<tr><td><code>{c}</code></td><td>{h.escape(e.unit)}</td><td>{h.escape(e.meaning)}</td></tr>" \
                in dictionary, (name, c)
    assert all(f"<code>{k}</code>" in dictionary for k in SUMMARY)
    assert "timestamp (UTC)" in dictionary and "date32" in dictionary


def test_monthly_chart_stacks_driving_in_service_and_whole_day(small_run):
    """The monthly chart's bars: driving, then terminals on top (in service), then parked
    time (whole day), each month's stack summing to the monthly table's whole-day yield, in
    the proportions of the summary's three yields (kWh/kWp)."""
    from vipvflow.outputs.report import fig_monthly

    monthly = pd.read_parquet(small_run / "monthly.parquet")
    s = json.loads((small_run / "summary.json").read_text())
    kwp = s["kwp_per_bus"] * s["buses"]
    ax = fig_monthly(monthly, s).axes[0]
    heights = np.array([p.get_height() for p in ax.patches]).reshape(3, len(monthly))
    np.testing.assert_allclose(heights.sum(0), monthly["pv_kwh_whole_day"] / kwp, rtol=1e-9)
    np.testing.assert_allclose(heights[0], monthly["pv_kwh_driving"] / kwp, rtol=1e-9)
    # the summary's yields are per year (scaled from the months simulated): same proportions
    year = heights.sum(1)
    np.testing.assert_allclose(np.array([year[0], year[:2].sum(), year.sum()]) / year.sum(),
                               np.array([s["kwh_per_kwp_driving"], s["kwh_per_kwp_in_service"],
                                         s["kwh_per_kwp_whole_day"]]) / s["kwh_per_kwp_whole_day"],
                               rtol=1e-6)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("in service" in t for t in labels) and any("whole day" in t for t in labels)
    assert "kWh per installed kWp" in ax.get_ylabel()


def test_close_up_is_on_the_canyons(small_run):
    """The map's close-up window holds the segment whose roof sees the least sky."""
    from vipvflow.outputs.report import CLOSE_UP_M, close_up_window

    seg = gpd.read_parquet(small_run / "segments.parquet")
    xmin, ymin, xmax, ymax = close_up_window(seg)
    assert xmax - xmin == pytest.approx(CLOSE_UP_M)
    darkest = seg.loc[seg["svf"].idxmin(), "geometry"].interpolate(0.5, normalized=True)
    assert xmin <= darkest.x <= xmax and ymin <= darkest.y <= ymax


def test_app_map_draws_the_same_footprints(small_run):
    """The web app's map background is the report's building footprints (city model, offline)."""
    from bokeh.document import Document
    from bokeh.models import GlyphRenderer, Patches

    from vipvflow.app.layout import build_document
    from vipvflow.app.model import TripModel
    from vipvflow.inputs.city.footprints import building_footprints

    model = TripModel(small_run)
    doc = Document()
    build_document(model, doc)
    patches = [r for r in doc.select({"type": GlyphRenderer}) if isinstance(r.glyph, Patches)]
    assert len(patches) == 1
    xs = patches[0].data_source.data["xs"]
    g = model.geometry
    bounds = (min(g["x"].min(), g["x_end"].min()) - 200, min(g["y"].min(), g["y_end"].min()) - 200,
              max(g["x"].max(), g["x_end"].max()) + 200, max(g["y"].max(), g["y_end"].max()) + 200)
    rings = building_footprints(model.data_dir, tiles=sorted(g["tile"].unique()), bounds=bounds)
    assert len(xs) == len(rings) > 0
    assert [list(r[:, 0]) for r in rings] == [list(x) for x in xs]


def test_the_report_module_leaves_matplotlib_to_where_figures_are_drawn():
    """The command's process loads the report module for the reduce; a run's workers draw
    the figures, so matplotlib is loaded there (and by the first figure drawn here) only.
    Nor does the reduce load the ray tracing's modules (Embree, trimesh, numba: ~110 MB of
    the command's process through the whole run)."""
    code = ("import sys\n"
            "import vipvflow.simulation.reduce, vipvflow.simulation.run, vipvflow.outputs.report as r\n"
            "assert 'matplotlib' not in sys.modules, 'matplotlib loaded by an import'\n"
            "loaded = {'numba', 'embreex', 'trimesh', 'vipvflow.models.irradiance'} & set(sys.modules)\n"
            "assert not loaded, loaded\n"
            "assert r._loaded() and 'matplotlib.pyplot' in sys.modules\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_a_run_that_ingests_nothing_loads_no_ray_tracing_in_its_own_process(small_config):
    """A run's own process checks its ingested folders (the city's fingerprint names the
    mesh format) and goes on to the map: with nothing to ingest it loads neither trimesh nor
    Embree (~55 MB of the command's process through the whole run)."""
    from vipvflow.config import load_config
    from vipvflow.simulation.prepare import ensure_ingested

    ensure_ingested(load_config(small_config), say=lambda *a: None)
    code = ("import sys\n"
            "from vipvflow.config import load_config\n"
            "from vipvflow.simulation.prepare import ensure_ingested\n"
            "said = []\n"
            f"ensure_ingested(load_config({str(small_config)!r}), say=said.append)\n"
            "assert not said, said\n"
            "loaded = {'trimesh', 'embreex', 'scipy', 'numba'} & set(sys.modules)\n"
            "assert not loaded, loaded\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_map_lines_and_the_close_ups_shapes():
    from shapely.geometry import LineString

    from vipvflow.outputs.report import _near, _segment_lines

    geoms = [LineString([(0, 0), (10, 0)]), LineString(), LineString([(5, 5, 1), (6, 7, 1), (9, 9, 2)]),
             LineString([(100, 100), (110, 100)]), LineString()]
    lines = _segment_lines(gpd.GeoDataFrame(geometry=geoms))
    assert [a.tolist() for a in lines] == [np.asarray(g.coords).reshape(-1, 2 + g.has_z)[:, :2].tolist()
                                           for g in geoms]
    # inside the view, crossing its edge, within the margin, beyond it
    shapes = [np.array([[1.0, 1.0], [2.0, 2.0]]), np.array([[-5.0, 3.0], [5.0, 3.0]]),
              np.array([[11.5, 0.0], [12.0, 1.0]]), np.array([[13.0, 0.0], [14.0, 1.0]])]
    assert _near(shapes, (0.0, 0.0, 10.0, 10.0), 2.0).tolist() == [True, True, True, False]
    assert _near([], (0.0, 0.0, 10.0, 10.0), 2.0).tolist() == []
    # shapes without points (an empty line) are never drawn in the close-up
    empty = np.zeros((0, 2))
    assert _near([empty, shapes[0], empty], (0.0, 0.0, 10.0, 10.0), 2.0).tolist() == [False, True, False]
    assert _near([empty], (0.0, 0.0, 10.0, 10.0), 2.0).tolist() == [False]
