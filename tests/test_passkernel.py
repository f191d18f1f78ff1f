"""The fused per-pass kernel (numba) against the numpy reference of the same physics."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from vipvflow.config import IrradianceCfg
from vipvflow.inputs.cams import COLUMNS
from vipvflow.models import passkernel
from vipvflow.models.irradiance import evaluate_passes
from vipvflow.models.shading import Scene, box_mesh
from vipvflow.models.sun_sky import RadiationTable
from vipvflow.models.view_factors import COMPONENTS, pack_geometry, read_geometry, segment_geometry

LAT, LON, ALT = 49.61, 6.13, 300.0


def _assert_same(ref: pd.DataFrame, new: pd.DataFrame):
    """Equal to float32 precision (W/m2), the sun visibility exactly."""
    assert list(ref.columns) == list(new.columns)
    for c in ref.columns:
        a, b = ref[c].to_numpy(), new[c].to_numpy()
        if a.dtype == bool:
            assert (a == b).all(), c
        else:
            np.testing.assert_allclose(b, a, rtol=2e-7, atol=1e-4, err_msg=c)


def _clear_day_table(day: str):
    """pvlib's Ineichen clear sky at Luxembourg on a minute grid around *day*, the all-sky
    DNI at 70 % of the clear sky's."""
    import pvlib

    t = pd.date_range(pd.Timestamp(day, tz="UTC") - pd.Timedelta("1D"), periods=3 * 1440,
                      freq="1min") + pd.Timedelta("30s")
    loc = pvlib.location.Location(LAT, LON, altitude=ALT)
    cs = loc.get_clearsky(t, model="ineichen")
    sp = loc.get_solarposition(t)
    cos_z = np.maximum(np.cos(np.radians(sp["apparent_zenith"].to_numpy())), 0)
    vals = {"ghi_clear": cs["ghi"], "dni_clear": cs["dni"], "dhi_clear": cs["dhi"],
            "dni": 0.7 * cs["dni"], "dhi": 1.2 * cs["dhi"], "azimuth": sp["azimuth"]}
    vals["ghi"] = vals["dni"] * cos_z + vals["dhi"]
    grid = ((t - pd.Timestamp(0, tz="UTC")) / pd.Timedelta(seconds=1)).to_numpy(float)
    return RadiationTable.from_grid(grid, {c: np.asarray(vals[c], float) for c in COLUMNS}, LAT, LON, ALT)


def _canyon_scene(H=16.0, W=18.0, L=400.0):
    """A street canyon along y (facades of two blocks) over a road in the mesh, and a
    tower at its end."""
    from vipvflow.models.mesh import SURFACE_CODE, TileMesh

    walls = box_mesh([[-W / 2 - 20, -L, 0, -W / 2, L, H], [W / 2, -L, 0, W / 2 + 20, L, H],
                      [-30, L + 10, 0, 30, L + 40, 60]], albedo_wall=0.35)
    g = 2 * L
    road = np.array([[[-g, -g, 0], [g, -g, 0], [g, g, 0]], [[-g, -g, 0], [g, g, 0], [-g, g, 0]]])
    mesh = TileMesh.from_triangles(np.concatenate([walls.vertices[walls.triangles], road]),
                                   albedo=np.r_[walls.albedo, [0.15] * 2])
    mesh.surface_type[:] = np.r_[walls.surface_type, [SURFACE_CODE["ground"]] * 2]
    return Scene(mesh)


@pytest.mark.parametrize("sampling, diffuse", [("rotate", "sky_view_factor"), ("all", "isotropic"),
                                             ("rotate", "perez_svf"), ("all", "perez_svf")])
def test_fused_equals_numpy_on_a_canyon_with_layovers(sampling, diffuse):
    """Driving passes (climbing and descending segments along the canyon) and a layover's
    minutes (a standing point, :mod:`vipvflow.simulation.standing`) over a clear June day:
    every component of the fused kernel equals the numpy reference's."""
    table = _clear_day_table("2024-06-10")
    scene = _canyon_scene()
    cfg = IrradianceCfg(reflector_sampling=sampling, diffuse_model=diffuse, reflector_points=4,
                        reflection_rays=256, svf_rays=256)
    n_seg = 12
    segs = pd.DataFrame({"segment_id": np.arange(n_seg) + 100,
                         "x": np.linspace(-6.0, 6.0, n_seg), "y": np.linspace(-300.0, 300.0, n_seg),
                         "z": np.full(n_seg, 3.2),
                         "heading_deg": np.where(np.arange(n_seg) % 2, 0.0, 180.0),
                         "gradient": np.linspace(-0.06, 0.06, n_seg)})
    # the layover: a flat roof standing in the canyon (segment id = point id)
    segs.loc[n_seg] = [7, 2.0, 350.0, 3.2, 0.0, 0.0]
    segs["segment_id"] = segs["segment_id"].astype(np.int64)
    geometry = segment_geometry(scene, segs, cfg)
    rng = np.random.default_rng(5)
    day0 = pd.Timestamp("2024-06-10", tz="UTC").timestamp()
    drive = pd.DataFrame({"segment_id": rng.choice(segs["segment_id"].to_numpy()[:n_seg], 20_000),
                          "t_utc": day0 + rng.uniform(0, 86400, 20_000),
                          "dt_s": rng.uniform(1, 8, 20_000).astype(np.float32)})
    minutes = np.arange(day0, day0 + 86400, 60.0)
    layover = pd.DataFrame({"segment_id": np.full(len(minutes), 7, np.int64), "t_utc": minutes,
                            "dt_s": np.full(len(minutes), 60.0, np.float32)})
    geo = pack_geometry(geometry, cfg, 0.2, scene)
    assert passkernel.usable(geo, scene)
    for passes in (drive, layover):
        ref = evaluate_passes(passes, None, geometry, table, scene, cfg, packed=geo, kernel="numpy")
        new = evaluate_passes(passes, None, geometry, table, scene, cfg, packed=geo)
        _assert_same(ref, new)
        lit = ref["direct_clear"] > 0
        # the case has it all: sun and shade, light reflected onto the roof, night
        assert lit.any() and (~ref["sun_visible"] & (ref["diffuse"] > 0)).any()
        assert (ref["reflected"] > 0).any() and (ref["total"] == 0).any()


def test_fused_equals_numpy_on_the_demo_passes(small_run, small_config):
    """The small demo's passes of June, tile by tile: the fused kernel's components equal
    the numpy reference's, and so do the partition sums it accumulates without per-pass
    outputs (trip, segment and hourly tables of :func:`aggregate_partition`)."""
    from vipvflow.config import load_config
    from vipvflow.inputs.gtfs import iter_passes
    from vipvflow.simulation import partition as part

    cfg = load_config(small_config)
    data_dir = str(cfg.data_dir)
    irr_cfg = IrradianceCfg(**cfg.irradiance.model_dump())
    ctx = part.RunContext(data_dir=data_dir, run_dir=str(small_run), year=2024,
                          irradiance=irr_cfg.model_dump(), pv_system=cfg.pv_system().model_dump(),
                          pv_mode="paper", monthly_temperature_c=(15.0,) * 12, wind_speed_mps=2.0,
                          timezone="Europe/Luxembourg")
    table = part._radiation(data_dir, 2024)
    tiles = sorted(p.name[5:-8] for p in (small_run / "parts" / "geometry").glob("tile=*.parquet"))
    assert tiles
    n_passes = 0
    for tile in tiles:
        passes = iter_passes(data_dir, tile, "2024-06", 2024)
        if not len(passes):
            continue
        n_passes += len(passes)
        geometry = read_geometry(small_run / "parts" / "geometry" / f"tile={tile}.parquet")
        scene = part._scene(ctx, tile)
        geo = part._packed_geometry(ctx, tile, geometry, scene)
        ref = evaluate_passes(passes, None, geometry, table, scene, irr_cfg, packed=geo, kernel="numpy")
        _assert_same(ref, evaluate_passes(passes, None, geometry, table, scene, irr_cfg, packed=geo))
        want = part.aggregate_partition(passes, ref, 6, ctx)
        groups, bins, n = part._fused_sums(ctx, tile, [passes], geometry, {})
        assert n == len(passes)
        got = part.aggregate_partition(passes, None, 6, ctx, groups=groups, bins=bins)
        for a, b in zip(want, got):
            assert list(a.columns) == list(b.columns) and len(a) == len(b)
            for c in a.columns:
                if a[c].dtype.kind == "f":
                    np.testing.assert_allclose(b[c], a[c], rtol=1e-9, atol=1e-12, err_msg=c)
                else:
                    assert (a[c].to_numpy() == b[c].to_numpy()).all(), c
    assert n_passes > 1000


def test_fused_sums_of_passes_in_chunks_are_those_of_all_at_once(small_run, small_config):
    """The small demo's June, tile by tile: the fused kernel fed a few service days at a time
    (PassChunks) gives the partition tables of all the passes at once, bit for bit."""
    from vipvflow.config import load_config
    from vipvflow.inputs.gtfs import PassChunks, iter_passes
    from vipvflow.simulation import partition as part

    cfg = load_config(small_config)
    data_dir = str(cfg.data_dir)
    ctx = part.RunContext(data_dir=data_dir, run_dir=str(small_run), year=2024,
                          irradiance=IrradianceCfg(**cfg.irradiance.model_dump()).model_dump(),
                          pv_system=cfg.pv_system().model_dump(), pv_mode="paper",
                          monthly_temperature_c=(15.0,) * 12, wind_speed_mps=2.0,
                          timezone="Europe/Luxembourg")
    tiles = sorted(p.name[5:-8] for p in (small_run / "parts" / "geometry").glob("tile=*.parquet"))
    most = 0
    for tile in tiles:
        passes = iter_passes(data_dir, tile, "2024-06", 2024)
        if not len(passes):
            continue
        geometry = read_geometry(small_run / "parts" / "geometry" / f"tile={tile}.parquet")
        budget = int(passes.groupby("service_date").size().max() * 3)
        chunks = PassChunks(data_dir, tile, "2024-06", 2024, max_passes=budget)
        most = max(most, len(chunks.bounds()))
        timings: dict = {}
        groups, bins, n = part._fused_sums(ctx, tile, chunks, geometry, timings)
        assert n == len(passes) and timings["passes_s"] > 0
        got = part.partition_tables(None, None, 6, ctx, groups=groups, bins=bins)
        groups, bins, _ = part._fused_sums(ctx, tile, [passes], geometry, {})
        want = part.partition_tables(None, None, 6, ctx, groups=groups, bins=bins)
        for a, b in zip(want, got):
            assert a.equals(b), tile
        # and the kernel's own batches of rays, a few hundred passes each
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(passkernel, "RAY_BUDGET", 4096)
            groups, bins, _ = part._fused_sums(ctx, tile, [passes], geometry, {})
        batched = part.partition_tables(None, None, 6, ctx, groups=groups, bins=bins)
        for a, b in zip(want, batched):
            assert a.equals(b), tile
    assert most >= 5


def test_a_tile_task_leaves_no_packed_geometry_no_task_can_find(small_run, small_config, tmp_path):
    """A tile task that read its own geometry table drops that table's packed geometry when
    it is done (no other task holds the table the cache keys it by); one handed the table
    (a geometry task's result, shared by the tile's tasks) leaves it for the next."""
    import shutil

    from vipvflow.config import load_config
    from vipvflow.simulation import partition as part

    cfg = load_config(small_config)
    run_dir = tmp_path / "run"
    shutil.copytree(small_run / "parts" / "geometry", run_dir / "parts" / "geometry")
    ctx = part.RunContext(data_dir=str(cfg.data_dir), run_dir=str(run_dir), year=2024,
                          irradiance=IrradianceCfg(**cfg.irradiance.model_dump()).model_dump(),
                          pv_system=cfg.pv_system().model_dump(), pv_mode="paper",
                          monthly_temperature_c=(15.0,) * 12, wind_speed_mps=2.0,
                          timezone="Europe/Luxembourg")
    tiles = sorted(p.name[5:-8] for p in (run_dir / "parts" / "geometry").glob("tile=*.parquet"))
    tile = next(t for t in tiles if part.tile_task(ctx, t, ["2024-06"])[0]["passes"])
    assert (ctx.run_dir, tile) not in part._PACKED
    shared = part.geometry_task(ctx, tile)
    done = part.tile_task(ctx, tile, ["2024-06"], shared)
    assert done[0]["passes"] and part._PACKED[(ctx.run_dir, tile)][0] is shared.frame
    part._PACKED.clear()


def test_a_tile_task_keeps_the_packed_geometry_and_writes_what_the_whole_table_gives(
        small_run, small_config, tmp_path):
    """A tile task holds, of the geometry table it read, only the segments' ids and radiation
    locations with the packed geometry (the rest of the table let go), and writes the
    partition files the whole table gives, bit for bit, even when the tile's scene was
    dropped from the cache and built again in between."""
    import shutil

    import pyarrow.parquet as pq

    from vipvflow.config import load_config
    from vipvflow.models import shading
    from vipvflow.simulation import partition as part

    cfg = load_config(small_config)
    ctxs = {}
    for name in ("held", "whole"):
        run_dir = tmp_path / name
        shutil.copytree(small_run / "parts" / "geometry", run_dir / "parts" / "geometry")
        ctxs[name] = part.RunContext(
            data_dir=str(cfg.data_dir), run_dir=str(run_dir), year=2024,
            irradiance=IrradianceCfg(**cfg.irradiance.model_dump()).model_dump(),
            pv_system=cfg.pv_system().model_dump(), pv_mode="paper",
            monthly_temperature_c=(15.0,) * 12, wind_speed_mps=2.0, timezone="Europe/Luxembourg")
    tiles = sorted(p.name[5:-8] for p in (tmp_path / "held" / "parts" / "geometry").glob("tile=*.parquet"))
    tile = max(tiles, key=lambda t: len(part.tile_geometry(ctxs["whole"], t)))
    whole = part.tile_geometry(ctxs["whole"], tile)
    held = part._held_geometry(ctxs["held"], tile, part.tile_geometry(ctxs["held"], tile))
    assert list(held.columns) == [c for c in ("segment_id", "rad_location") if c in whole.columns]
    assert part._PACKED[(ctxs["held"].run_dir, tile)][0] is held
    # the tile's BVH dropped from the scenes' cache meanwhile (other tiles' tasks): its
    # scene built again, the packing kept
    shading._cache.clear()
    assert part.run_partition(ctxs["held"], tile, "2024-06", held)["passes"]
    assert part._PACKED[(ctxs["held"].run_dir, tile)][1] is part._scene(ctxs["held"], tile)
    part._PACKED.clear()
    assert part.run_partition(ctxs["whole"], tile, "2024-06", whole)["passes"]
    part._PACKED.clear()
    files = sorted(p.relative_to(tmp_path / "whole") for p in (tmp_path / "whole" / "parts").rglob("month=*.parquet"))
    assert len(files) >= 2
    for f in files:
        assert pq.read_table(tmp_path / "held" / f).equals(pq.read_table(tmp_path / "whole" / f)), f


def test_block_columns_are_the_components():
    assert passkernel.BLOCK_COLUMNS == tuple(COMPONENTS) + ("ghi", "ghi_clear")


@pytest.mark.parametrize("spread", [1, 10**9])
def test_pass_groups_equal_the_numpy_reference(spread):
    """Runs, segment positions and local hours of passes across the spring clock change
    (2024-03-31 01:00 UTC in Luxembourg), compact and sparse segment ids."""
    from vipvflow.simulation.partition import _dense_positions, _local_hours

    rng = np.random.default_rng(1)
    n = 50_000
    t = np.sort(pd.Timestamp("2024-03-30 20:00", tz="UTC").timestamp() + rng.uniform(0, 12 * 3600, n))
    trip = np.repeat(np.arange(n // 50), 50)
    day = np.repeat(np.arange(n // 100), 100) + 19_800
    seg = rng.integers(0, 300, n) * spread + 5
    dt = rng.uniform(1, 9, n)
    g = passkernel.pass_groups(trip, day, seg, t, dt, "Europe/Luxembourg")
    hour = _local_hours(t, "Europe/Luxembourg")
    # UTC+1 until 01:00 UTC, then UTC+2: local 21:00 .. 01:59, then from 03:00 (no 02:00)
    assert (g["seg_hour"] % 24 == hour).all() and set(hour[t < 1711846800]) == {21, 22, 23, 0, 1}
    assert set(hour[t >= 1711846800]) == set(range(3, 10))
    ids, pos = _dense_positions(seg)
    assert (g["seg_ids"] == ids).all() and (g["seg_pos"] == pos).all()
    assert (g["seg_hour"] == pos * 24 + hour).all()
    assert (g["run"] == np.repeat(np.arange(n // 50), 50)).all() and len(g["starts"]) == n // 50
    np.testing.assert_allclose(g["run_s"], np.bincount(g["run"], dt), rtol=1e-12)
    np.testing.assert_allclose(g["hour_s"], np.bincount(hour, dt, 24), rtol=1e-12)
    assert (g["seg_n"] == np.bincount(pos)).all() and g["seg_s"].sum() == pytest.approx(dt.sum())

    # positions among a wider set of ids, the passes in three parts adding to the same totals
    extra = np.r_[seg.min() - 1, np.unique(seg), seg.max() + spread]
    totals = dict(seg_s=np.zeros(len(extra)), hour_s=np.zeros(24),
                  seg_n=np.zeros(len(extra), np.int64), hour_n=np.zeros(24, np.int64))
    cuts = [0, 10_000, 30_000, n]
    for a, b in zip(cuts, cuts[1:]):
        part = passkernel.pass_groups(trip[a:b], day[a:b], seg[a:b], t[a:b], dt[a:b],
                                      "Europe/Luxembourg", extra, totals)
        assert (part["seg_pos"] == pos[a:b] + 1).all() and part["seg_s"] is totals["seg_s"]
        assert (part["seg_hour"] % 24 == hour[a:b]).all()
    assert (totals["seg_n"][1:-1] == g["seg_n"]).all() and totals["seg_n"][[0, -1]].sum() == 0
    assert (totals["seg_s"][1:-1] == g["seg_s"]).all() and (totals["hour_s"] == g["hour_s"]).all()
    assert (totals["hour_n"] == g["hour_n"]).all()


def test_utc_offsets_from_the_cached_table_equal_pandas_conversion():
    """The per-process table of UTC offsets, sliced, gives what pandas' own conversion of the
    span gives: across clock changes, at the table's block edges, over a year's end, and
    for a span longer than a table."""
    from vipvflow.models.passkernel import _OFFSET_TABLE_HOURS, _offsets, utc_offsets

    block = _OFFSET_TABLE_HOURS // 2
    h_2024 = int(pd.Timestamp("2024-01-01", tz="UTC").timestamp() // 3600)
    spans = [(h_2024 + 2000, h_2024 + 2000 + 744),          # March-April: spring change
             (h_2024 + 7200, h_2024 + 7200 + 744),          # October-November: autumn change
             (h_2024 + 8700, h_2024 + 8784 + 300),          # over the year's end
             (block * 95 - 10, block * 95 + 10),            # over a block edge
             (block * 95, block * 95 + _OFFSET_TABLE_HOURS + 5)]   # longer than a table
    for tz in ("Europe/Luxembourg", "Asia/Tokyo", "America/New_York", "Australia/Lord_Howe"):
        for lo, hi in spans:
            got, want = utc_offsets(tz, lo, hi), _offsets(tz, lo, hi)
            assert got.shape == (hi - lo + 1,) and (got == want).all(), (tz, lo, hi)



def test_time_span_holds_every_pass_time():
    """The span of the passes' radiation times the sky tables are read for (_time_span):
    no pass time outside it, NaN left out; none without passes."""
    from vipvflow.models.passkernel import _time_span

    rng = np.random.default_rng(5)
    t_start = rng.uniform(1.7e9, 1.7e9 + 3e6, 5000)
    dt = rng.uniform(0.0, 400.0, 5000)
    t_start[::97], dt[::61] = np.nan, np.nan
    for mid in (True, False):
        lo, hi = _time_span(t_start, dt, mid)
        t = t_start + 0.5 * dt if mid else t_start
        t = t[~np.isnan(t)]
        assert lo <= t.min() and hi >= t.max() and hi - lo < 3e6 + 400
    assert len(_time_span(np.zeros(0), np.zeros(0), True)) == 0
