"""Street and line layout of the demo town (EPSG:2169, metres).

A bus line is traced as a polyline of straight street pieces (a "turtle" walk with random
bends drawn from the seed) made of *legs*; every leg is a street stretch of one kind:

``canyon``
    dense centre: continuous perimeter-block rows of 4-6 storeys (14-20 m eaves) on both
    sides of a 12-16 m wide street (facade to facade);
``suburban``
    detached houses of 7-10 m eaves, set back from a 9 m road, with gaps between them;
``open``
    no buildings at all.

Each line is translated so that the middle of its canyon stretch lies on the town centre
(77000, 75000), so all lines cross there.  Headings are azimuths in degrees clockwise from
north.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

CRS = "EPSG:2169"
CENTRE_XY = (77000.0, 75000.0)
KINDS = ("canyon", "suburban", "open")

# nominal street geometry per kind: width of the street (facade to facade in a canyon,
# road with pavements elsewhere) in m, and the set-back of the first building row from the
# road edge in m
_WIDTH_RANGE = {"canyon": (12.0, 16.0), "suburban": (9.0, 9.0), "open": (7.0, 7.0)}
_SETBACK_RANGE = {"canyon": (0.0, 0.0), "suburban": (4.0, 8.0), "open": (0.0, 0.0)}
# eaves height range of the buildings along a stretch (m)
EAVES_RANGE = {"canyon": (14.0, 20.0), "suburban": (7.0, 10.0), "open": (0.0, 0.0)}
# standard deviation of the bend at each new street piece (degrees)
_BEND_SIGMA = {"canyon": 4.0, "suburban": 12.0, "open": 10.0}


@dataclass(frozen=True)
class LineSpec:
    """What a line is made of: legs of (kind, length in m) and its mean heading (deg)."""

    name: str
    heading_deg: float
    legs: tuple[tuple[str, float], ...]
    long_name: str = ""


LINE_SPECS = {
    "full": (
        LineSpec("1", 78.0, (("open", 2000), ("suburban", 2500), ("canyon", 2500),
                             ("suburban", 2000), ("open", 2500), ("suburban", 1500),
                             ("open", 2000), ("suburban", 1500), ("open", 1500)),
                 "Westfeld - Centre - Ostheim"),
        LineSpec("2", 350.0, (("open", 1000), ("suburban", 1800), ("canyon", 1000),
                              ("suburban", 1700), ("open", 1000)),
                 "Sudberg - Centre - Nordhaff"),
    ),
    "small": (
        LineSpec("1", 78.0, (("open", 900), ("canyon", 1200), ("suburban", 900)),
                 "Westfeld - Centre"),
    ),
}


@dataclass
class Stretch:
    """One leg of a line: a street stretch of one kind."""

    line: str
    index: int
    kind: str
    s_start_m: float
    s_end_m: float
    xy: np.ndarray            # (n, 2) centre line, EPSG:2169
    width_m: float            # street width (facade to facade in a canyon)
    setback_m: float          # first building row behind the road edge

    @property
    def length_m(self) -> float:
        return self.s_end_m - self.s_start_m

    @property
    def stretch_id(self) -> str:
        return f"L{self.line}_{self.index:02d}_{self.kind}"


@dataclass
class Line:
    """A bus line: its centre line (direction 0) and its stretches."""

    name: str
    long_name: str
    xy: np.ndarray            # (n, 2) vertices, EPSG:2169, direction 0
    stretches: list[Stretch] = field(default_factory=list)

    @property
    def route_id(self) -> str:
        return f"L{self.name}"

    @property
    def length_m(self) -> float:
        return float(cumulative_length(self.xy)[-1])


@dataclass
class Layout:
    size: str
    seed: int
    lines: list[Line]

    def stretches(self, kind: str | None = None) -> list[Stretch]:
        return [s for line in self.lines for s in line.stretches if kind in (None, s.kind)]

    def bounds(self, margin: float = 0.0) -> tuple[float, float, float, float]:
        xy = np.concatenate([line.xy for line in self.lines])
        lo, hi = xy.min(axis=0) - margin, xy.max(axis=0) + margin
        return (float(lo[0]), float(lo[1]), float(hi[0]), float(hi[1]))


def cumulative_length(xy: np.ndarray) -> np.ndarray:
    """Distance along a polyline at each vertex (m), starting at 0."""
    steps = np.hypot(*np.diff(xy, axis=0).T)
    return np.concatenate([[0.0], np.cumsum(steps)])


def point_at(xy: np.ndarray, s) -> np.ndarray:
    """Points at distances *s* (m) along a polyline (linear interpolation)."""
    cum = cumulative_length(xy)
    s = np.clip(np.asarray(s, dtype=float), 0.0, cum[-1])
    return np.stack([np.interp(s, cum, xy[:, 0]), np.interp(s, cum, xy[:, 1])], axis=-1)


def densify(xy: np.ndarray, max_step: float) -> np.ndarray:
    """The polyline with extra points so no step exceeds *max_step* m (vertices kept)."""
    out = [xy[:1]]
    for a, b in zip(xy[:-1], xy[1:]):
        n = max(1, int(np.ceil(np.hypot(*(b - a)) / max_step)))
        f = np.arange(1, n + 1)[:, None] / n
        out.append(a + f * (b - a))
    return np.concatenate(out)


def _trace(spec: LineSpec, rng: np.random.Generator):
    """Walk the legs of *spec*: vertices and the vertex index where each leg ends."""
    pts = [np.zeros(2)]
    leg_end = []
    az = spec.heading_deg
    for kind, length in spec.legs:
        remaining = float(length)
        while remaining > 1e-6:
            piece = rng.uniform(250.0, 550.0)
            if remaining - piece < 150.0:
                piece = remaining
            # mean-reverting bends keep the line going its general way
            az = spec.heading_deg + 0.5 * (az - spec.heading_deg) + rng.normal(0.0, _BEND_SIGMA[kind])
            rad = np.radians(az)
            pts.append(pts[-1] + piece * np.array([np.sin(rad), np.cos(rad)]))
            remaining -= piece
        leg_end.append(len(pts) - 1)
    return np.array(pts), leg_end


def build_layout(seed: int = 42, size: str = "full") -> Layout:
    """The lines and street stretches of the demo town.

    Parameters
    ----------
    seed : int
        Seed of the numpy Generator the bends and street widths are drawn from.
    size : {"full", "small"}
        ``full``: line 1 of 18 km (canyon, suburban and open stretches) and line 2 of
        6.5 km crossing it in the centre; ``small``: a 3 km line 1 only.

    Returns
    -------
    Layout
        Coordinates in EPSG:2169 (m).
    """
    if size not in LINE_SPECS:
        raise ValueError(f"size must be one of {sorted(LINE_SPECS)}, got {size!r}")
    rng = np.random.default_rng([seed, 1])
    lines = []
    for spec in LINE_SPECS[size]:
        xy, leg_end = _trace(spec, rng)
        cum = cumulative_length(xy)
        starts = [0] + leg_end[:-1]
        # put the middle of the canyon leg on the town centre
        k = next(i for i, (kind, _) in enumerate(spec.legs) if kind == "canyon")
        mid = point_at(xy, 0.5 * (cum[starts[k]] + cum[leg_end[k]]))
        xy = np.round(xy - mid + np.asarray(CENTRE_XY), 3)
        cum = cumulative_length(xy)
        line = Line(spec.name, spec.long_name, xy)
        for i, ((kind, _), a, b) in enumerate(zip(spec.legs, starts, leg_end)):
            width = float(np.round(rng.uniform(*_WIDTH_RANGE[kind]), 1))
            setback = float(np.round(rng.uniform(*_SETBACK_RANGE[kind]), 1))
            line.stretches.append(Stretch(spec.name, i, kind, float(cum[a]), float(cum[b]),
                                          xy[a:b + 1].copy(), width, setback))
        lines.append(line)
    return Layout(size, seed, lines)
