"""What a run writes for people and other tools.

- :mod:`.report`: ``report.html`` with its figures;
- :mod:`.vecto`: VECTO driving cycles, modal results and job files;
- :mod:`.dynamizer`, :mod:`.citygml3`: CityGML 3.0 Dynamizers of the results
  (``vipvflow export dynamizer``, see ``docs/dynamizer.md``).
"""
from .citygml3 import validate
from .dynamizer import load_run, read_dynamizers, reflector_contributions, route_totals, write_dynamizers

__all__ = ["load_run", "read_dynamizers", "reflector_contributions", "route_totals", "validate",
           "write_dynamizers"]
