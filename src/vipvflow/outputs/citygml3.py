"""CityGML 3.0 encoding facts the exports share: namespaces, the official schema locations,
the ``srsName`` of a run's CRS, and validation against a local copy of the official XSDs.

The official schemas live at ``http://schemas.opengis.net/citygml/<module>/3.0/<file>.xsd``
(the core module at ``.../citygml/3.0/core.xsd``).  A bundle of them with relative imports
(CityGML 3.0, GML 3.2.1, xAL 3.0, ISO 19139, XLink) validates offline:
:func:`validate` maps each official URL named in a document's ``xsi:schemaLocation`` to the
file of the same name under the bundle's ``citygml/3.0/`` folder.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

CORE = "http://www.opengis.net/citygml/3.0"
DYN = "http://www.opengis.net/citygml/dynamizer/3.0"
GEN = "http://www.opengis.net/citygml/generics/3.0"
TRAN = "http://www.opengis.net/citygml/transportation/3.0"
GML = "http://www.opengis.net/gml/3.2"
XLINK = "http://www.w3.org/1999/xlink"
XSI = "http://www.w3.org/2001/XMLSchema-instance"
NSMAP = {"core": CORE, "dyn": DYN, "gen": GEN, "tran": TRAN, "gml": GML, "xlink": XLINK, "xsi": XSI}

#: namespace -> official schema URL of the CityGML 3.0 modules the exports use
SCHEMA_LOCATIONS = {
    CORE: "http://schemas.opengis.net/citygml/3.0/core.xsd",
    DYN: "http://schemas.opengis.net/citygml/dynamizer/3.0/dynamizer.xsd",
    GEN: "http://schemas.opengis.net/citygml/generics/3.0/generics.xsd",
    TRAN: "http://schemas.opengis.net/citygml/transportation/3.0/transportation.xsd",
}
_OFFICIAL = re.compile(r"^https?://schemas\.opengis\.net/citygml/(?:[a-z]+/)?3\.0/(?P<file>[A-Za-z]+\.xsd)$")


def schema_location(namespaces=SCHEMA_LOCATIONS) -> str:
    """The ``xsi:schemaLocation`` value: namespace / URL pairs."""
    return " ".join(f"{ns} {url}" for ns, url in namespaces.items())


def q(prefixed: str) -> str:
    """``"core:CityModel"`` -> ``"{http://www.opengis.net/citygml/3.0}CityModel"``."""
    prefix, name = prefixed.split(":")
    return f"{{{NSMAP[prefix]}}}{name}"


# ----------------------------------------------------------------------------- CRS
_EPSG = re.compile(r"EPSG(?::[\d.]*)?:+(\d+)$|/def/crs/EPSG/[^/]*/(\d+)$|^(\d+)$", re.IGNORECASE)


def _epsg(part: str) -> int | None:
    m = _EPSG.search(part.strip())
    return int(next(g for g in m.groups() if g)) if m else None


def vertical_epsg(srs_name: str | None) -> int | None:
    """The vertical EPSG code of a compound ``srsName`` (``urn:ogc:def:crs,crs:EPSG::2169,
    crs:EPSG::5774`` -> 5774; OGC compound URLs alike), else None."""
    if not srs_name:
        return None
    low = srs_name.lower()
    if low.startswith(("urn:ogc:def:crs,", "urn:x-ogc:def:crs,")):
        parts = [p for p in srs_name.split(",")[1:] if p]
        return _epsg(parts[1]) if len(parts) >= 2 else None
    if "/def/crs-compound" in low:
        codes = re.findall(r"/def/crs/EPSG/[^/&]*/(\d+)", srs_name, re.IGNORECASE)
        return int(codes[1]) if len(codes) >= 2 else None
    return None


def srs_name(horizontal_epsg: int | None, vertical: int | None = None) -> str | None:
    """EPSG URN of the run's CRS: ``urn:ogc:def:crs:EPSG::2169``, or the compound
    ``urn:ogc:def:crs,crs:EPSG::2169,crs:EPSG::5774`` when the heights have a vertical CRS."""
    if horizontal_epsg is None:
        return None
    if vertical is None:
        return f"urn:ogc:def:crs:EPSG::{horizontal_epsg}"
    return f"urn:ogc:def:crs,crs:EPSG::{horizontal_epsg},crs:EPSG::{vertical}"


def first_srs_name(path: Path, max_elements: int = 200_000) -> str | None:
    """The first ``srsName`` attribute in an XML file (streamed; None when there is none in
    the first *max_elements* elements or the file cannot be read)."""
    try:
        for i, (_, el) in enumerate(etree.iterparse(str(path), events=("start",), huge_tree=True)):
            name = el.get("srsName")
            if name:
                return name
            if i >= max_elements:
                return None
    except (OSError, etree.XMLSyntaxError):
        return None
    return None


# ----------------------------------------------------------------------------- validation
@dataclass
class Validation:
    """Result of :func:`validate`: ``ok`` and the schema's error lines (``file:line: message``)."""

    ok: bool
    errors: list[str]
    schema_locations: dict[str, str]     # namespace -> official URL named by the document


def local_schema(url: str, xsd_root: Path) -> Path | None:
    """The local copy of an official CityGML 3.0 schema URL under *xsd_root* (None: not one)."""
    m = _OFFICIAL.match(url)
    if not m:
        return None
    path = Path(xsd_root) / "citygml" / "3.0" / m["file"]
    return path if path.exists() else None


def validate(path: str | Path, xsd_root: str | Path, max_errors: int = 50) -> Validation:
    """Validate a CityGML 3.0 file against the official schemas found offline in *xsd_root*.

    *xsd_root* holds ``citygml3-all.xsd`` (imports every CityGML 3.0 module) and the schema
    tree beside it.  Besides the XSD validation, every ``xsi:schemaLocation`` pair of the root
    must name an official URL whose local file exists and whose ``targetNamespace`` is the
    paired namespace (the document then validates in tools that fetch the schemas online).
    """
    xsd_root = Path(xsd_root)
    schema = etree.XMLSchema(etree.parse(str(xsd_root / "citygml3-all.xsd")))
    errors: list[str] = []
    try:
        doc = etree.parse(str(path), etree.XMLParser(huge_tree=True))
    except etree.XMLSyntaxError as exc:
        return Validation(False, [f"{path}: not well-formed: {exc}"], {})
    pairs = (doc.getroot().get(f"{{{XSI}}}schemaLocation") or "").split()
    locations = dict(zip(pairs[::2], pairs[1::2]))
    if len(pairs) % 2 or not locations:
        errors.append(f"{path}: xsi:schemaLocation missing or not namespace/URL pairs")
    for ns, url in locations.items():
        local = local_schema(url, xsd_root)
        if local is None:
            errors.append(f"{path}: schemaLocation {url} is not an official CityGML 3.0 schema URL")
            continue
        target = etree.parse(str(local)).getroot().get("targetNamespace")
        if target != ns:
            errors.append(f"{path}: schemaLocation pairs {ns} with {url} (targetNamespace {target})")
    if not schema.validate(doc):
        for e in list(schema.error_log)[:max_errors]:
            errors.append(f"{e.filename}:{e.line}: {e.message}")
    return Validation(not errors, errors, locations)
