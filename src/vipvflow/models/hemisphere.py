"""Compiled loop of :func:`vipvflow.models.view_factors.cosine_directions`: the stratified
cosine-weighted hemisphere directions about each normal, written straight into the output.

The numpy form made a dozen (normals x rays) temporaries per call; the tile geometry calls it
for every segment's sky rays, roof hemisphere rays and reflector groups' rays (~16 % of a
tile's geometry time on the demo, three times faster compiled).  The arithmetic is the
numpy form's, in the same order (the tangent frame ``n x ref``, ``n x t1``, then the
spiral), so the directions are equal to it (``tests/test_irradiance.py`` keeps the numpy
form and compares them).  Kept apart from :mod:`vipvflow.models.view_factors` so that importing
that module (the command's process does) does not load numba; compiled once and cached on
disk like :mod:`vipvflow.models.passkernel`.
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def directions(normals, uniforms, n_rays, golden):
    """(m, n_rays, 3) float64 unit vectors about the unit *normals* (m, 3) from the
    *uniforms* (m, n_rays + 1): ray ``k``'s radial jitter ``uniforms[:, k]``, the spiral's
    rotation ``uniforms[:, n_rays]``; *golden* the spiral's angle step (in turns)."""
    m = normals.shape[0]
    out = np.empty((m, n_rays, 3))
    for i in range(m):
        nx, ny, nz = normals[i, 0], normals[i, 1], normals[i, 2]
        # the tangent frame: t1 = n x ref (normalised), t2 = n x t1
        if abs(nx) < 0.9:
            rx, ry, rz = 1.0, 0.0, 0.0
        else:
            rx, ry, rz = 0.0, 1.0, 0.0
        ax, ay, az = ny * rz - nz * ry, nz * rx - nx * rz, nx * ry - ny * rx
        norm = np.sqrt(ax * ax + ay * ay + az * az)
        ax, ay, az = ax / norm, ay / norm, az / norm
        bx, by, bz = ny * az - nz * ay, nz * ax - nx * az, nx * ay - ny * ax
        rotation = uniforms[i, n_rays]
        for k in range(n_rays):
            u = (k + uniforms[i, k]) / n_rays
            phi = 2 * np.pi * ((k * golden + rotation) % 1.0)
            r = np.sqrt(u)
            lx, ly = r * np.cos(phi), r * np.sin(phi)
            lz = np.sqrt(min(max(1 - u, 0.0), 1.0))
            out[i, k, 0] = lx * ax + ly * bx + lz * nx
            out[i, k, 1] = lx * ay + ly * by + lz * ny
            out[i, k, 2] = lx * az + ly * bz + lz * nz
    return out
