"""vipvflow: VIPV yield of electric bus fleets in 3D cities."""
__version__ = "0.1.0"
