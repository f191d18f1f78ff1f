"""The interactive web app: a finished run explored per trip and per fleet.

- :mod:`vipvflow.app.model`: :class:`TripModel`, the computation the app displays (one trip
  recomputed with the run's physics from stored geometry factors, horizon profiles and
  radiation, occlusion rays only for the reflectors' sunlit share);
- :mod:`vipvflow.app.layout`: the Bokeh document (controls, views, callbacks);
- :mod:`vipvflow.app.server`: a Bokeh server started programmatically, BokehJS served by
  itself (no CDN, no map tiles).
"""
from .model import TECHNOLOGIES, PVChoice, TripModel, TripResult

__all__ = ["TripModel", "TripResult", "PVChoice", "TECHNOLOGIES"]
