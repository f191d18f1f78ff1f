"""The Python API: a scenario simulated, and a finished run read back as typed tables.

Four names are the surface (re-exported by :mod:`vipvflow`)::

    import vipvflow

    cfg = vipvflow.load_config("demo")              # a shipped scenario or your YAML
    run = vipvflow.simulate(cfg, year=2024)         # -> vipvflow.Run
    run = vipvflow.open_run("out/demo/2024")        # a finished run, from any directory
    model = vipvflow.TripModel(run.path)            # one trip recomputed for any settings

A :class:`Run` gives each output file as a DataFrame (``segments`` and ``segment_month`` as
GeoDataFrames in the city's CRS) with its columns typed as the data dictionary says: dates
(``service_date``, ``month``; ``date32`` in the files) as ``datetime64`` at local midnight,
instants (``*_utc``) as ``datetime64[us, UTC]``; ``run.files`` names the files for other
readers (DuckDB, QGIS, Arrow), ``run.columns(name)`` gives every column's unit and meaning.
docs/api.md is a worked example.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from .config import Config, load_config
from .simulation.dictionary import DATE, INSTANT, OUTPUTS, describe

__all__ = ["Run", "open_run", "simulate", "load_config"]

#: output files read as GeoDataFrames
GEO_OUTPUTS = ("segments", "segment_month")


@dataclass(frozen=True)
class Run:
    """A finished run folder (``out/<scenario>/<year>/``).

    Attributes
    ----------
    path : Path
        The run folder (absolute).
    data_dir : Path or None
        Its data dir (ingested inputs), found as :func:`open_run` finds it.
    manifest : dict
        ``manifest.json``: configuration, input checksums, versions, timings.
    summary : dict
        ``summary.json``: the fleet-year (keys and units in docs/outputs.md, or
        ``vipvflow.simulation.dictionary.SUMMARY``).
    files : dict of str to Path
        Each output file by its name (``"trip_energy"`` -> ``.../trip_energy.parquet``).
    """

    path: Path
    data_dir: Path | None
    manifest: dict
    summary: dict
    files: dict = field(repr=False)

    @property
    def config(self) -> Config:
        """The run's configuration (validated again from its manifest)."""
        return Config.model_validate(self.manifest["config"])

    @property
    def year(self) -> int:
        return int(self.manifest["year"])

    def table(self, name: str, columns: list[str] | None = None) -> pd.DataFrame:
        """One output file as a DataFrame (a GeoDataFrame for ``segments`` and
        ``segment_month``), dates and instants typed.

        Parameters
        ----------
        name : str
            An output's name: ``trip_energy``, ``segments``, ``segment_month``,
            ``route_month``, ``block_day``, ``monthly``, ``ranking``, ``hourly_pattern``.
        columns : list of str, optional
            Read only these (a GeoDataFrame needs its ``geometry`` among them).

        Returns
        -------
        pandas.DataFrame or geopandas.GeoDataFrame
            Columns of unit ``date`` as ``datetime64`` (local calendar day, midnight, no time
            zone), of unit ``timestamp (UTC)`` as ``datetime64[us, UTC]``; the others as in
            the file.
        """
        if name not in self.files:
            raise KeyError(f"{name!r} is not an output of a run (outputs: {', '.join(self.files)})")
        path = self.files[name]
        if name in GEO_OUTPUTS and (columns is None or "geometry" in columns):
            import geopandas as gpd

            df = gpd.read_parquet(path, columns=columns)
        else:
            df = pd.read_parquet(path, columns=columns)
        for col in df.columns:
            entry = describe(name, col)
            if entry is None:
                continue
            if entry.unit == DATE:
                df[col] = pd.to_datetime(df[col])
            elif entry.unit == INSTANT:
                df[col] = pd.to_datetime(df[col], utc=True)
        return df

    def columns(self, name: str) -> pd.DataFrame:
        """The data dictionary of one output: ``column, unit, description``, in file order."""
        return pd.DataFrame([{"column": c, "unit": describe(name, c).unit,
                              "description": describe(name, c).meaning}
                             for c in OUTPUTS[name].columns])

    # one property per output file, for tab completion
    trip_energy = property(lambda self: self.table("trip_energy"),
                           doc="Per trip and service date: PV, consumption, coverage, SoC at departure.")
    segments = property(lambda self: self.table("segments"),
                        doc="GeoDataFrame: the 10 m segments, their geometry factors and their year.")
    segment_month = property(lambda self: self.table("segment_month"),
                             doc="GeoDataFrame: per segment and month (irradiation, kWh, shading loss).")
    route_month = property(lambda self: self.table("route_month"),
                           doc="Per route, direction and month, with the routes' names.")
    block_day = property(lambda self: self.table("block_day"),
                         doc="Per vehicle block and day: PV by time of day, SoC, feasibility, grid energy.")
    monthly = property(lambda self: self.table("monthly"), doc="The fleet per month.")
    ranking = property(lambda self: self.table("ranking"),
                       doc="Blocks and routes ranked by grid energy avoided per kWp.")
    hourly_pattern = property(lambda self: self.table("hourly_pattern"),
                              doc="Mean roof irradiance by local hour and month.")


def open_run(path) -> Run:
    """A finished run, from any working directory.

    Parameters
    ----------
    path : str or Path
        The run folder, ``out/<scenario>/<year>`` (relative to the working directory, or
        absolute).

    Returns
    -------
    Run

    Raises
    ------
    vipvflow.errors.InputError
        One line naming what is missing (the folder, its manifest, its summary).
    """
    import json

    from .errors import InputError
    from .simulation.rundir import open_run as open_folder

    folder = open_folder(path, needs=())
    summary_path = folder.path / "summary.json"
    if not summary_path.is_file():
        raise InputError(f"{folder.path}: the run did not finish (no summary.json); run the "
                         "same simulate again to resume it")
    files = {name: folder.path / f"{name}.parquet" for name in OUTPUTS}
    return Run(folder.path, folder.data_dir, folder.manifest, json.loads(summary_path.read_text()),
               files)


def simulate(config: Config | str | Path | None = "demo", year: int = 2024, *, out=None,
             scheduler: str | None = None, workers: int | None = None, quiet: bool = False,
             force: bool = False) -> Run:
    """Simulate a scenario's year (``vipvflow simulate``) and open its run.

    Parameters
    ----------
    config : Config, str or Path
        A configuration (:func:`load_config`), a scenario YAML, or a shipped scenario's name
        (default ``"demo"``: the embedded demo town, generated when missing).
    year : int
        The calendar year.
    out : str or Path, optional
        Folder for the scenario's relative ``data_dir`` and ``out_dir`` (and the demo's
        generated inputs) instead of the working directory (``--out``).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); default a LocalCluster.
    workers : int, optional
        The LocalCluster's worker processes (default: one per core).
    quiet : bool
        No progress bars or progress lines.
    force : bool
        Replace a run of another configuration in the run folder.

    Returns
    -------
    Run

    Notes
    -----
    The LocalCluster's workers are processes: in a script, call this under
    ``if __name__ == "__main__":`` (they import the script's main module); in Jupyter or
    ``python -c`` nothing is needed.
    """
    from .commands.simulate import under
    from .progress import quiet as is_quiet, set_quiet
    from .simulation import run_simulation

    cfg = config if isinstance(config, Config) else load_config(config)
    if out is not None:
        source = getattr(cfg, "_source", None)
        cfg = Config.model_validate(_merge(cfg.model_dump(), under(cfg, Path(out))))
        if source is not None:
            cfg._source = source
    was = is_quiet()
    set_quiet(quiet)
    try:
        run_dir = run_simulation(cfg, year, scheduler=scheduler, n_workers=workers, force=force,
                                 say=(lambda *a, **k: None) if quiet else print)
    finally:
        set_quiet(was)
    return open_run(run_dir)


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out
