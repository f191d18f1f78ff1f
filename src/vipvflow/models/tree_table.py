"""The trees of a tile as a table (:class:`TreeTable`, ``city/trees/<TILE>.npz``), their
sources, leaf types and leaf-off months: what the city ingest writes and the runs read,
without the ray tracing of :mod:`vipvflow.models.trees` (so the ingest does not load numba).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .params import TreeCfg

#: version of ``city/trees/<TILE>.npz``
TREES_FORMAT = 1
#: where a tree comes from (``TreeTable.source``)
TREE_SOURCES = ("citygml", "plant_cover", "table")
#: leaf types (``TreeTable.leaf_type``; -1 unknown)
LEAF_TYPES = ("deciduous", "evergreen")
#: months deciduous trees are leafless by default, north and south of the equator
LEAF_OFF_NORTH = (11, 12, 1, 2, 3, 4)
LEAF_OFF_SOUTH = (5, 6, 7, 8, 9, 10)


def month_mask(months) -> int:
    """The 12-bit mask of *months* (1..12): bit ``m - 1`` set for month ``m``."""
    return int(sum(1 << (int(m) - 1) for m in set(months)))


def default_leaf_off(cfg: TreeCfg, latitude: float) -> tuple:
    """The leaf-off months of trees without their own: ``cfg.leaf_off_months``, else
    November to April north of the equator and May to October south of it."""
    if cfg.leaf_off_months is not None:
        return tuple(cfg.leaf_off_months)
    return LEAF_OFF_NORTH if latitude >= 0 else LEAF_OFF_SOUTH


@dataclass
class TreeTable:
    """The trees of one tile (its own and those of its buffer), as the city ingest writes
    them (``city/trees/<TILE>.npz``).

    Attributes (one row per tree)
    -----------------------------
    x, y, z : float64, m, the trunk's base on the ground (the city's projected CRS)
    height : float32, m, top of the crown above the ground
    crown_diameter : float32, m
    crown_base : float32, m above the ground, the crown's lowest leaves
    leaf_type : int8, index into :data:`LEAF_TYPES`, -1 unknown
    leaf_off : int16, the tree's own leaf-off months as a 12-bit mask (:func:`month_mask`),
        -1 for the default (:func:`default_leaf_off`)
    source : int8, index into :data:`TREE_SOURCES`
    tree_id : str
    latitude : float, the city's latitude (degrees; the default leaf-off calendar's hemisphere)
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    height: np.ndarray
    crown_diameter: np.ndarray
    crown_base: np.ndarray
    leaf_type: np.ndarray
    leaf_off: np.ndarray
    source: np.ndarray
    tree_id: np.ndarray
    latitude: float = 0.0

    _DTYPES = {"x": np.float64, "y": np.float64, "z": np.float64, "height": np.float32,
               "crown_diameter": np.float32, "crown_base": np.float32, "leaf_type": np.int8,
               "leaf_off": np.int16, "source": np.int8, "tree_id": str}

    def __post_init__(self):
        for name, dtype in self._DTYPES.items():
            setattr(self, name, np.asarray(getattr(self, name), dtype=dtype).reshape(-1))
        n = len(self.x)
        bad = [k for k in self._DTYPES if len(getattr(self, k)) != n]
        if bad:
            raise ValueError(f"TreeTable: columns of another length than x: {bad}")

    def __len__(self) -> int:
        return len(self.x)

    @classmethod
    def empty(cls, latitude: float = 0.0) -> "TreeTable":
        return cls(**{k: np.zeros(0, d if d is not str else "U1") for k, d in cls._DTYPES.items()},
                   latitude=latitude)

    def take(self, idx) -> "TreeTable":
        return TreeTable(**{k: getattr(self, k)[idx] for k in self._DTYPES}, latitude=self.latitude)

    @classmethod
    def concat(cls, tables, latitude: float | None = None) -> "TreeTable":
        tables = [t for t in tables if t is not None]
        if not tables:
            return cls.empty(latitude or 0.0)
        lat = tables[0].latitude if latitude is None else latitude
        return cls(**{k: np.concatenate([getattr(t, k) for t in tables]) for k in cls._DTYPES},
                   latitude=lat)

    def crown_extent(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Each crown's centre (n, 3), horizontal and vertical semi-axes (m)."""
        a = 0.5 * self.crown_diameter.astype(np.float64)
        c = 0.5 * (self.height.astype(np.float64) - self.crown_base)
        centre = np.column_stack([self.x, self.y, self.z + self.crown_base + c])
        return centre, a, c

    def save(self, path) -> None:
        from ..store import write_npz

        write_npz(path, format=np.int64(TREES_FORMAT), latitude=np.float64(self.latitude),
                  **{k: getattr(self, k) for k in self._DTYPES})

    @classmethod
    def load(cls, path) -> "TreeTable":
        """A tile's trees (:meth:`save`); a file of another format raises
        :class:`~vipvflow.errors.InputError` saying to ingest the city again."""
        from ..errors import InputError

        with np.load(path, allow_pickle=False) as z:
            fmt = int(z["format"]) if "format" in z.files else 0
            if fmt != TREES_FORMAT:
                raise InputError(f"{path}: trees of format {fmt}, this vipvflow reads format "
                                 f"{TREES_FORMAT}: ingest the city again")
            return cls(**{k: z[k] for k in cls._DTYPES}, latitude=float(z["latitude"]))
