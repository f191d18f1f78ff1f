"""`vipvflow track`: a GPS track through an open street and a deep canyon."""
from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from vipvflow.cli import main
from vipvflow.models.shading import box_mesh
from vipvflow.simulation.track import fit_stats, headings

X0, Y0 = 77_000.0, 75_000.0


def test_fit_stats_and_headings():
    s = fit_stats([1.0, 2.0, 3.0], [2.0, 3.0, 4.0])
    assert s["rmse"] == pytest.approx(1.0) and s["mbe"] == pytest.approx(1.0)
    assert s["r2"] == pytest.approx(1 - 3 / 2)
    h = headings([0, 10, 10, 10, 0], [0, 0, 10, 10, 10])
    np.testing.assert_allclose(h, [90, 0, 0, 270, 270])      # stationary point keeps heading


def test_track_command(tmp_path, test_data, capsys):
    data = tmp_path / "city_data"
    # an east-west canyon 10 m wide, walls 40 m high, from x0+100 to x0+300
    mesh = box_mesh([[X0 + 100, Y0 + 255, 0, X0 + 300, Y0 + 265, 40],
                     [X0 + 100, Y0 + 235, 0, X0 + 300, Y0 + 245, 40]])
    mesh.save(data / "city" / "meshes" / "E0770N0750.npz")
    (data / "city" / "tiles.json").write_text(json.dumps(
        {"crs": "EPSG:2169", "tile_size_m": 500, "buffer_m": 300,
         "tiles": {"E0770N0750": {"bounds": [X0, Y0, X0 + 500, Y0 + 500]}}}))
    n = 24
    x = X0 + np.linspace(20, 480, n)
    t = pd.date_range("2020-06-01 12:05:30", periods=n, freq="2min", tz="UTC")
    track = pd.DataFrame({"time": t.strftime("%Y-%m-%dT%H:%M:%SZ"), "x": x, "y": Y0 + 250, "z": 3.2})
    track["measured_wm2"] = 700.0
    src = tmp_path / "track.csv"
    track.to_csv(src, index=False)
    cams = test_data / "cams" / "cams_mcclear_1min_verbose_60rows_pvlib-527fa1c.csv"
    out = tmp_path / "out.csv"
    rc = main(["track", str(src), "--city", str(data), "--cams", str(cams), "--out", str(out)])
    assert rc == 0
    printed = capsys.readouterr().out
    assert "RMSE" in printed and "R2" in printed
    res = pd.read_csv(out)
    assert len(res) == n and np.allclose(res["heading_deg"], 90.0)
    inside = (x > X0 + 120) & (x < X0 + 280)
    open_ = (x < X0 + 90) | (x > X0 + 310)
    # midday sun at 57 deg elevation from the south-south-west: the canyon's south wall hides it
    assert not res["sun_visible"][inside].any() and (res["direct"][inside] == 0).all()
    assert res["sun_visible"][open_].all()
    # a horizontal roof in the open gets DNI cos z + DHI = GHI of the CAMS file (McClear)
    raw = pd.read_csv(cams, sep=";", comment="#", header=None)
    minute = ((t - pd.Timestamp("2020-06-01 12:00", tz="UTC")).total_seconds() // 60).astype(int)
    ghi = raw[2].to_numpy()[minute] * 60
    np.testing.assert_allclose(res["total_unshaded"][open_], ghi[open_], rtol=0.01)
    # direct + diffuse there: GHI less the sky the canyon's 40 m end walls hide (sky view
    # factor diffuse, the default): at most a few percent near the canyon's mouth, none far off
    dd = (res["direct"] + res["diffuse"]).to_numpy()
    assert (dd[open_] <= ghi[open_] * 1.001).all() and (dd[open_] >= 0.97 * ghi[open_]).all()
    far = (x < X0 + 40) | (x > X0 + 360)
    np.testing.assert_allclose(dd[far], ghi[far], rtol=0.01)
    assert (res["total"][inside] < 0.5 * res["total_unshaded"][inside]).all()
