"""City model: CityGML LoD2 -> tiled semantic surfaces, tile meshes and terrain.

Public API
----------
ingest_city(paths, data_dir, city_cfg, crs=None) -> IngestReport
load_tile_mesh(data_dir, tile) -> vipvflow.models.mesh.TileMesh
TerrainModel.load(data_dir).elevation(x, y)
SURFACE_TYPES : surface type names, index = code in ``TileMesh.surface_type``
"""
from ...models.mesh import SURFACE_CODE, SURFACE_TYPES, TileMesh
from .citygml import CityGMLReader
from .crs import parse_srs_name
from .geometry import prepare_polygon
from .ingest import IngestReport, ingest_city, load_tile_mesh
from .terrain import TerrainModel

__all__ = ["ingest_city", "IngestReport", "load_tile_mesh", "TerrainModel", "TileMesh",
           "SURFACE_TYPES", "SURFACE_CODE", "CityGMLReader", "parse_srs_name", "prepare_polygon"]
