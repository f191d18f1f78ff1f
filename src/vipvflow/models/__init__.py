"""The physics of a bus roof in a street, as functions of arrays.

- :mod:`.sun_sky`: sun positions and the radiation of every minute;
- :mod:`.view_factors`: the per-segment geometry (roof plane, sky view, reflectors);
- :mod:`.shading`: rays cast against a tile's mesh (Embree), :mod:`.mesh` the mesh;
- :mod:`.irradiance`: direct, diffuse and reflected light of each pass;
- :mod:`.horizon`: horizon profiles; :mod:`.pv`: PV energy;
- :mod:`.vehicle`, :mod:`.driving_cycle`: what a bus draws; :mod:`.economics`.

What these modules compute depends on their source and on the arithmetic of a few
libraries. :func:`code_digest` names both, for the caches that a data dir keeps of such values
(the tiles' geometry, the sun vectors with the Perez coefficients, the sky tables).
"""
from __future__ import annotations

import hashlib
from functools import lru_cache
from importlib import metadata
from pathlib import Path

#: the libraries whose arithmetic the cached values depend on (their versions are read from
#: the installed packages' metadata: none of them is imported)
DIGEST_LIBRARIES = ("numpy", "numba", "embreex", "trimesh", "pandas", "pyarrow", "pvlib")


@lru_cache(maxsize=1)
def code_digest() -> str:
    """SHA-256 of the source of this package (every module, by its relative path) and of
    the versions of :data:`DIGEST_LIBRARIES`."""
    root = Path(__file__).parent
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    for name in DIGEST_LIBRARIES:
        try:
            h.update(f"{name}={metadata.version(name)}\0".encode())
        except metadata.PackageNotFoundError:
            h.update(f"{name}=\0".encode())
    return h.hexdigest()
