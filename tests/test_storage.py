"""Atomic Parquet writes keep every column's values and type, fast path or not."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from vipvflow.store import _plain_table, write_parquet


@pytest.mark.parametrize("frame, fast", [
    (pd.DataFrame({"segment_id": np.arange(4, dtype=np.int64), "h": np.float32([0, 1.5, 2, 3]),
                   "seen": [True, False, True, True], "tile": "E0770N0750",
                   "service_date": pd.to_datetime(["2024-06-01"] * 4),
                   "trip_id": ["a", "b", None, "d"]}), True),
    (pd.DataFrame({"wkb": pd.Series([b"\x01\x02", b"", b"\xff", b"x"], dtype=object)}), False),
    (pd.DataFrame({"route": pd.Categorical(["1", "2", "1", "2"])}), False),
])
def test_round_trip(tmp_path, frame, fast):
    assert (_plain_table(frame) is not None) == fast
    path = write_parquet(frame, tmp_path / "x.parquet")
    pd.testing.assert_frame_equal(pd.read_parquet(path), frame)
    assert [p.name for p in tmp_path.iterdir()] == ["x.parquet"]        # no temporary left
