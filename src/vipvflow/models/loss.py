"""The shading loss: the share of the open-field light that the buildings take away.

Its own module, with numpy alone: the reduce, the report and the web app give it without
loading the ray tracing's modules (Embree, trimesh, numba: ~110 MB of a run's own process).
"""
from __future__ import annotations

import numpy as np


def shading_loss(direct, diffuse, unshaded):
    """Share of the open-field light the buildings take away: ``1 - (direct + diffuse) /
    unshaded`` (sun and sky both count; the light the buildings reflect onto the roof is
    reported apart, as a gain).  Irradiances, irradiations or energies alike (same unit in
    all three); NaN where nothing was received unshaded.  Arrays, pandas Series or floats.

    References
    ----------
    The definition in README.md and docs/physics.md: the sun and sky light the buildings
    take away; their reflections are reported apart.
    """
    shaded = direct + diffuse
    if hasattr(unshaded, "where"):
        return 1.0 - shaded / unshaded.where(unshaded > 0)
    u = np.asarray(unshaded, np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        out = np.where(u > 0, 1.0 - np.asarray(shaded, np.float64) / np.where(u > 0, u, 1.0), np.nan)
    return out[()] if out.ndim == 0 else out
