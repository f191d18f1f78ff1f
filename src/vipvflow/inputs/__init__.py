"""The inputs of a run, read and ingested into a data dir.

- :mod:`.city`: CityGML LoD2 -> tiled surfaces, tile meshes and terrain;
- :mod:`.gtfs`: a GTFS feed -> trips as passes over 10 m segments;
- :mod:`.cams`: CAMS radiation files -> a one-minute radiation table;
- :mod:`.tiles`: the square tiles everything is cut into.
"""
