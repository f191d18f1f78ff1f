"""Exports of a finished run to other formats (CityGML 3.0 Dynamizers, see ``docs/dynamizer.md``)."""
from .citygml3 import validate
from .dynamizer import load_run, read_dynamizers, reflector_contributions, route_totals, write_dynamizers

__all__ = ["load_run", "read_dynamizers", "reflector_contributions", "route_totals", "validate",
           "write_dynamizers"]
