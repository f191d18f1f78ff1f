"""Benchmarks: each ``bench_*.py`` module defines ``run(tiny: bool = False) -> dict``."""
