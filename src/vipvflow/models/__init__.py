"""The physics of a bus roof in a street, as functions of arrays.

- :mod:`.sun_sky`: sun positions and the radiation of every minute;
- :mod:`.view_factors`: the per-segment geometry (roof plane, sky view, reflectors);
- :mod:`.shading`: rays cast against a tile's mesh (Embree), :mod:`.mesh` the mesh;
- :mod:`.irradiance`: direct, diffuse and reflected light of each pass;
- :mod:`.horizon`: horizon profiles; :mod:`.pv`: PV energy;
- :mod:`.vehicle`, :mod:`.driving_cycle`: what a bus draws; :mod:`.economics`.
"""
