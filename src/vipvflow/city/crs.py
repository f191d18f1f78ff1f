"""Coordinate reference systems named in CityGML ``srsName`` attributes.

CityGML files name their CRS in many spellings: plain EPSG codes, OGC URNs (with and
without a version, compound horizontal + height), OGC http URIs and the German AdV
URNs (``urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH``).  :func:`parse_srs_name` maps each
to the horizontal ``EPSG:<code>``; heights are kept as written (the vertical datums in
use differ by centimetres, far below the accuracy of an LoD2 model).
"""
from __future__ import annotations

import re
from functools import lru_cache

import numpy as np

from ..errors import InputError

#: horizontal part of the German AdV CRS names
ADV_CRS = {
    "ETRS89_UTM32": 25832,
    "ETRS89_UTM33": 25833,
    "DE_DHDN_3GK2": 31466,
    "DE_DHDN_3GK3": 31467,
    "DE_DHDN_3GK4": 31468,
    "DE_DHDN_3GK5": 31469,
}

_EPSG_TAIL = re.compile(r"EPSG(?::[\d.]*)?:+(\d+)$", re.IGNORECASE)
_URL = re.compile(r"/def/crs/EPSG/[^/]*/(\d+)$", re.IGNORECASE)
_GML_SRS = re.compile(r"epsg\.xml#(\d+)$", re.IGNORECASE)


def parse_srs_name(srs_name: str) -> str:
    """The horizontal CRS of a CityGML ``srsName`` as ``"EPSG:<code>"``.

    Parameters
    ----------
    srs_name : str
        e.g. ``EPSG:2169``, ``urn:ogc:def:crs:EPSG::25832``, ``urn:ogc:def:crs:EPSG:6.12:3068``,
        ``urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774`` (compound: horizontal part),
        ``http://www.opengis.net/def/crs/EPSG/0/25832``,
        ``urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH``.

    Raises
    ------
    InputError
        When the name is not one of the understood forms.
    """
    name = srs_name.strip()
    low = name.lower()
    if low.startswith("urn:ogc:def:crs,") or low.startswith("urn:x-ogc:def:crs,"):
        # compound: urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774 -> first component
        parts = [p for p in name.split(",")[1:] if p]
        if parts:
            return parse_srs_name("urn:ogc:def:" + parts[0])
    if low.startswith("urn:adv:crs:"):
        horizontal = name[len("urn:adv:crs:"):].split("*")[0]
        code = ADV_CRS.get(horizontal) or ADV_CRS.get(horizontal.upper())
        if code is None:
            raise InputError(f"srsName '{srs_name}': unknown AdV CRS '{horizontal}' "
                             f"(known: {', '.join(sorted(ADV_CRS))}); pass --crs EPSG:xxxx")
        return f"EPSG:{code}"
    for pattern in (_URL, _GML_SRS, _EPSG_TAIL):
        m = pattern.search(name)
        if m:
            return f"EPSG:{int(m.group(1))}"
    if re.fullmatch(r"\d+", name):
        return f"EPSG:{int(name)}"
    raise InputError(f"srsName '{srs_name}' is not an EPSG, OGC URN/URL or AdV CRS name; "
                     f"pass --crs EPSG:xxxx")


def normalise_crs(crs: str) -> str:
    """A user's CRS option (``EPSG:2169``, ``2169``, any srsName form) as ``EPSG:<code>``."""
    return parse_srs_name(str(crs))


@lru_cache(maxsize=32)
def _transformer(src: str, dst: str):
    from pyproj import Transformer

    return Transformer.from_crs(src, dst, always_xy=True)


def transform_xyz(xyz: np.ndarray, src: str, dst: str) -> np.ndarray:
    """Points (n, 3) in m from horizontal CRS *src* to *dst* (z unchanged)."""
    if src == dst or len(xyz) == 0:
        return xyz
    x, y = _transformer(src, dst).transform(xyz[:, 0], xyz[:, 1])
    out = np.array(xyz, dtype=np.float64, copy=True)
    out[:, 0], out[:, 1] = x, y
    return out


def is_projected(crs: str) -> bool:
    """True when *crs* is a projected CRS (metres), as tiling needs."""
    from pyproj import CRS

    return CRS.from_user_input(crs).is_projected
