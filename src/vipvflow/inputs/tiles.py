"""Square tiles in the projected CRS, named by their south-west corner.

A tile of size ``s`` metres covering ``[x0, x0+s) x [y0, y0+s)`` is named
``E{x0/100:04d}N{y0/100:04d}`` (corner in hectometres), e.g. ``E0770N0750`` for the
500 m tile whose corner is at (77000, 75000) in LUREF.
"""
from __future__ import annotations

import re

import numpy as np

_NAME = re.compile(r"^E(-?\d+)N(-?\d+)$")


def tile_index(x, y, size: float):
    """Integer tile indices (ix, iy) of points (m)."""
    return (np.floor(np.asarray(x, dtype=float) / size).astype(np.int64),
            np.floor(np.asarray(y, dtype=float) / size).astype(np.int64))


def tile_name(ix: int, iy: int, size: float) -> str:
    """Name of tile (ix, iy): its south-west corner in hectometres."""
    return f"E{int(round(ix * size / 100)):04d}N{int(round(iy * size / 100)):04d}"


def tile_names(x, y, size: float) -> np.ndarray:
    """Tile name of each point (vectorised over unique tiles)."""
    ix, iy = tile_index(x, y, size)
    pairs, inverse = np.unique(np.stack([np.atleast_1d(ix), np.atleast_1d(iy)], axis=1),
                               axis=0, return_inverse=True)
    names = np.array([tile_name(a, b, size) for a, b in pairs], dtype=object)
    return names[inverse.ravel()]


def tile_bounds(name: str, size: float) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of a tile from its name (m)."""
    m = _NAME.match(name)
    if not m:
        raise ValueError(f"not a tile name: {name!r}")
    x0, y0 = int(m.group(1)) * 100.0, int(m.group(2)) * 100.0
    return (x0, y0, x0 + size, y0 + size)
