"""Coordinate reference systems named in CityGML ``srsName`` attributes.

CityGML files name their CRS in many spellings: plain EPSG codes, OGC URNs (with and
without a version, compound horizontal + height), OGC http URIs and the German AdV
URNs (``urn:adv:crs:ETRS89_UTM32*DE_DHHN2016_NH``).  :func:`parse_srs_name` maps each
to an ``EPSG:<code>`` and :func:`horizontal` to its horizontal part (EPSG:6697, JGD2011 +
height, becomes EPSG:6668); heights are kept as written.

Axis order
----------
GML writes coordinates in the axis order of the CRS's definition: latitude first for the
geographic CRSs of the EPSG registry (4326, 4258, 6668, 6697 ...), northing first for the
projected CRSs EPSG defines that way (2169, 31468, 3035, 6674 ...).  Real city models of
projected CRSs are nearly all written easting first whatever EPSG says (3DCityDB exports, the
AdV tiles, this project's demo).  :class:`SourceCRS` therefore lets the data decide between
the two orders where they can -- only one order puts the file's first building inside the
CRS's area of use -- and otherwise takes the EPSG order for geographic CRSs and easting first
for projected ones.  The order used is reported per file.

Every vertex is then checked against the CRS's area of use (widened by
:data:`AREA_MARGIN_DEG`): polygons with a vertex outside, or with a non-finite value, are
skipped and counted by the ingest, never tiled.
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ...errors import InputError

log = logging.getLogger(__name__)

#: degrees by which a CRS's area of use is widened before a vertex counts as outside it
#: (UTM zones are used well beyond their 6 degrees; a misread axis or a vertex at 1e30 is not)
AREA_MARGIN_DEG = 3.0
#: how a file's axis order is chosen (see :meth:`SourceCRS.decide`)
AXIS_MODES = ("auto", "epsg", "xy")

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


@lru_cache(maxsize=64)
def _crs(code: str):
    from pyproj import CRS

    try:
        return CRS.from_user_input(code)
    except Exception as exc:  # pyproj.exceptions.CRSError
        raise InputError(f"CRS {code} is not known to PROJ ({exc}); pass --crs EPSG:xxxx") from None


def horizontal(crs: str) -> str:
    """The horizontal part of *crs* as ``EPSG:<code>``: a compound CRS's first component."""
    c = _crs(crs)
    if c.is_compound and c.sub_crs_list:
        code = c.sub_crs_list[0].to_epsg()
        if code:
            return f"EPSG:{code}"
    return crs


def is_geographic(crs: str) -> bool:
    return bool(_crs(crs).is_geographic)


def north_first(crs: str) -> bool:
    """True when the CRS's definition (EPSG order) puts latitude / northing first."""
    axes = _crs(crs).axis_info
    return bool(axes) and axes[0].direction.lower() in ("north", "south")


@lru_cache(maxsize=64)
def area_bounds(crs: str) -> tuple[float, float, float, float] | None:
    """(xmin, ymin, xmax, ymax) in *crs* (x = east or longitude) of its area of use widened by
    :data:`AREA_MARGIN_DEG`; None when PROJ knows no area of use."""
    from pyproj import Transformer

    c = _crs(crs)
    aou = c.area_of_use
    if aou is None:
        return None
    m = AREA_MARGIN_DEG
    w, s, e, n = aou.west - m, max(aou.south - m, -90.0), aou.east + m, min(aou.north + m, 90.0)
    if aou.west > aou.east:          # crosses the antimeridian: longitude not checked
        w, e = -1e300, 1e300
    if c.is_geographic:
        return (w, s, e, n)
    geog = c.geodetic_crs
    for box in ((max(w, -180.0), s, min(e, 180.0), n), aou.bounds):
        try:
            t = Transformer.from_crs(geog, c, always_xy=True)
            b = t.transform_bounds(*box, densify_pts=21)
        except Exception:  # noqa: BLE001 -- PROJ cannot project that box: try the narrower one
            continue
        if np.all(np.isfinite(b)):
            return tuple(float(v) for v in b)
    return None


def area_of_use_deg(crs) -> tuple[float, float, float, float] | None:
    """(west, south, east, north) in degrees of *crs*'s area of use widened by
    :data:`AREA_MARGIN_DEG` (west > east: across the antimeridian); None when PROJ knows none."""
    from pyproj import CRS

    aou = CRS.from_user_input(crs).area_of_use
    if aou is None:
        return None
    m = AREA_MARGIN_DEG
    return (aou.west - m, max(aou.south - m, -90.0), aou.east + m, min(aou.north + m, 90.0))


def in_area_of_use(lon, lat, crs) -> np.ndarray:
    """Per point (degrees): inside *crs*'s area of use widened by :data:`AREA_MARGIN_DEG`
    (all True when PROJ knows no area of use)."""
    lon, lat = np.asarray(lon, float), np.asarray(lat, float)
    box = area_of_use_deg(crs)
    if box is None:
        return np.isfinite(lon) & np.isfinite(lat)
    w, s, e, n = box
    lon_ok = (lon >= w) & (lon <= e) if w <= e else (lon >= w) | (lon <= e)
    return lon_ok & (lat >= s) & (lat <= n)


def describe_area(crs) -> str:
    """``EPSG:25832 (ETRS89 / UTM zone 32N; area of use 6.0..12.0 E, 47.3..55.1 N)``."""
    from pyproj import CRS

    c = CRS.from_user_input(crs)
    code = c.to_string()
    aou = c.area_of_use
    if aou is None:
        return f"{code} ({c.name})"

    def deg(v, pos, neg):
        return f"{abs(v):.1f} {pos if v >= 0 else neg}"
    return (f"{code} ({c.name}; area of use {deg(aou.west, 'E', 'W')}..{deg(aou.east, 'E', 'W')}, "
            f"{deg(aou.south, 'N', 'S')}..{deg(aou.north, 'N', 'S')})")


def inside(xy: np.ndarray, bounds) -> np.ndarray:
    """Per point (n, >=2, x = east): finite and inside *bounds* (None: finite only)."""
    ok = np.isfinite(xy[:, 0]) & np.isfinite(xy[:, 1])
    if bounds is not None:
        ok &= (xy[:, 0] >= bounds[0]) & (xy[:, 0] <= bounds[2])
        ok &= (xy[:, 1] >= bounds[1]) & (xy[:, 1] <= bounds[3])
    return ok


@dataclass
class SourceCRS:
    """How the coordinates of one file are read: horizontal CRS and axis order.

    Attributes
    ----------
    crs : str -- horizontal ``EPSG:<code>`` of the file
    swap : bool -- the file writes (north, east) / (lat, lon): columns 0 and 1 are swapped on read
    axis_order : str -- what was read, for the report (``"lat,lon (EPSG order)"`` ...)
    bounds : tuple or None -- widened area of use in (east, north) order of ``crs``
    """

    crs: str
    swap: bool
    axis_order: str
    bounds: tuple | None

    @classmethod
    def decide(cls, crs: str, sample_xy: np.ndarray, mode: str = "auto") -> "SourceCRS":
        """Axis order of a file in *crs* whose first building has vertices *sample_xy* (as written).

        *mode* ``auto``: the order that puts the sample inside the CRS's area of use wins; when
        both do (or neither), the EPSG order for geographic CRSs and easting first for projected
        ones.  ``epsg``: the EPSG order, always.  ``xy``: easting / longitude first, always.
        """
        if mode not in AXIS_MODES:
            raise InputError(f"axis order '{mode}': use one of {', '.join(AXIS_MODES)}")
        crs = horizontal(crs)
        geographic = is_geographic(crs)
        bounds = area_bounds(crs)
        epsg_north = north_first(crs)
        names = ("lat,lon", "lon,lat") if geographic else ("north,east", "east,north")
        if mode != "auto":
            swap = epsg_north if mode == "epsg" else False
            order = names[0] if swap else names[1]
            return cls(crs, swap, f"{order} (--axis-order {mode})", bounds)
        pts = sample_xy[np.isfinite(sample_xy).all(axis=1)]
        if len(pts):
            as_written = inside(pts, bounds).mean()       # read (x=east, y=north)
            swapped = inside(pts[:, ::-1], bounds).mean()   # read (north, east)
        else:
            as_written = swapped = 1.0
        if swapped > as_written:
            swap = True
        elif as_written > swapped:
            swap = False
        else:
            swap = epsg_north and geographic
        order = names[0] if swap else names[1]
        if swap == epsg_north:
            note = f"{order} (EPSG order)"
        elif as_written != swapped:
            note = f"{order} (EPSG order is {names[0] if epsg_north else names[1]}, " \
                   f"but only {order} puts the data inside the CRS's area of use)"
        else:
            note = f"{order} (as written by city-model producers; EPSG order is {names[0]})"
        return cls(crs, swap, note, bounds)

    def read(self, xyz: np.ndarray) -> np.ndarray:
        """Coordinates as written -> (east/lon, north/lat, height)."""
        return xyz[:, [1, 0, 2]] if self.swap else xyz


def local_utm(crs: str, lon: float, lat: float) -> str:
    """The UTM zone CRS at (*lon*, *lat*) on the datum of geographic *crs* (else WGS 84),
    found with PROJ's UTM query as ``geopandas.GeoSeries.estimate_utm_crs`` does."""
    from pyproj.aoi import AreaOfInterest
    from pyproj.database import query_utm_crs_info

    datum = _crs(crs).datum.name if _crs(crs).datum else None
    aoi = AreaOfInterest(lon, lat, lon, lat)
    infos = query_utm_crs_info(area_of_interest=aoi)
    candidates = []
    for info in infos:
        if "UTM zone" not in info.name or not info.name.split("/")[-1].strip().startswith("UTM zone"):
            continue                     # skip "(N-E)" / "(zE-N)" variants
        if "(" in info.name.split("UTM zone")[-1]:
            continue
        code = f"{info.auth_name}:{info.code}"
        c = _crs(code)
        if north_first(code):
            continue
        same = datum is not None and c.datum is not None and c.datum.name == datum
        candidates.append((not same, not info.name.startswith("WGS 84"), code))
    if not candidates:
        raise InputError(f"no UTM zone found at lon {lon:.4f}, lat {lat:.4f}; pass --crs EPSG:xxxx")
    best = sorted(candidates)[0]
    return best[2]
