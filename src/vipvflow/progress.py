"""Progress of the long stages (demo generation, CityGML ingest, the map, the reduce).

On a terminal a :mod:`tqdm` bar (rate, ETA); when the stream is not a terminal (``make
simulate > log``), or a terminal that reports no width (0 columns: some CI runners, ``docker
exec`` without a tty size, serial consoles; a bar there is drawn as blank lines), a plain
line every ``every_s`` seconds and one at the end, so a log reads line by line without
carriage returns; nothing with ``--quiet`` (:func:`set_quiet`).
"""
from __future__ import annotations

import gzip
import io
import sys
import time
import zipfile
from pathlib import Path

_QUIET = False
PLAIN_EVERY_S = 10.0


def set_quiet(quiet: bool) -> None:
    """Switch every progress display of this process off (``--quiet``) or on."""
    global _QUIET
    _QUIET = bool(quiet)


def quiet() -> bool:
    return _QUIET


def _hms(seconds: float) -> str:
    s = int(round(max(seconds, 0.0)))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


def _amount(x: float, unit: str) -> str:
    if unit == "B":
        for scale, name in ((1e9, "GB"), (1e6, "MB"), (1e3, "kB")):
            if x >= scale:
                return f"{x / scale:.1f} {name}"
        return f"{x:.0f} B"
    return f"{x:,.0f} {unit}"


class Progress:
    """One stage's progress towards *total* (``None``: unknown) in *unit*.

    Use as a context manager; :meth:`update` adds, :meth:`advance_to` sets the amount done;
    *postfix* is extra text (per-route kWh, passes/s) shown with the bar or line.
    """

    def __init__(self, desc: str, total: float | None, unit: str = "it", stream=None,
                 every_s: float | None = None):
        self.desc, self.total, self.unit = desc, total, unit
        self.stream = stream if stream is not None else sys.stderr
        self.every_s = PLAIN_EVERY_S if every_s is None else every_s
        self.n = 0.0
        self.postfix = ""
        self.t0 = self._last = time.perf_counter()
        self.enabled = not _QUIET
        self.bar = None
        if self.enabled and _isatty(self.stream) and terminal_columns(self.stream) != 0:
            from tqdm import tqdm

            self.bar = tqdm(total=total, desc=desc, unit=unit, file=self.stream, leave=True,
                            unit_scale=unit == "B", unit_divisor=1000, dynamic_ncols=True,
                            mininterval=0.5)

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, exc_type, *exc) -> None:
        self.close(failed=exc_type is not None)

    def update(self, n: float = 1, postfix: str | None = None) -> None:
        self.advance_to(self.n + n, postfix)

    def advance_to(self, n: float, postfix: str | None = None) -> None:
        if postfix is not None:
            self.postfix = postfix
        step, self.n = n - self.n, n
        if float(step).is_integer():
            step = int(step)
        if not self.enabled:
            return
        if self.bar is not None:
            if postfix is not None:
                self.bar.set_postfix_str(postfix, refresh=False)
            self.bar.update(step)
            return
        now = time.perf_counter()
        if now - self._last >= self.every_s:
            self._last = now
            self._line()

    def line(self) -> str:
        """The plain line of the current state (what a log gets)."""
        elapsed = time.perf_counter() - self.t0
        rate = self.n / elapsed if elapsed > 0 else 0.0
        if not self.total:
            text = f"{self.desc}: {_amount(self.n, self.unit)}"
        elif self.unit == "B":
            text = (f"{self.desc}: {_amount(self.n, 'B')} of {_amount(self.total, 'B')} "
                    f"({100 * self.n / self.total:.0f} %)")
        else:
            text = (f"{self.desc}: {self.n:,.0f} of {_amount(self.total, self.unit)} "
                    f"({100 * self.n / self.total:.0f} %)")
        text += f", {_hms(elapsed)} elapsed"
        if self.total and 0 < self.n < self.total and rate > 0:
            text += f", ETA {_hms((self.total - self.n) / rate)}"
        if self.postfix:
            text += f"; {self.postfix}"
        return text

    def _line(self) -> None:
        print(self.line(), file=self.stream, flush=True)
        self._printed = (self.n, self.postfix)

    def close(self, failed: bool = False) -> None:
        """End the bar; in a log, the final line (none when the stage *failed*: its error
        is then the one line the user reads)."""
        if not self.enabled:
            return
        if self.bar is not None:
            if self.postfix:
                self.bar.set_postfix_str(self.postfix, refresh=False)
            self.bar.close()
        elif not failed and getattr(self, "_printed", None) != (self.n, self.postfix):
            self._line()
        self.enabled = False


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


def terminal_columns(stream) -> int | None:
    """The width of the terminal *stream* writes to: its window size, else ``$COLUMNS``
    when the terminal reports 0 columns; ``None`` when it cannot be asked (no file
    descriptor), 0 when it has no width."""
    import os

    try:
        columns = os.get_terminal_size(stream.fileno()).columns
    except (AttributeError, OSError, ValueError, io.UnsupportedOperation):
        return None
    if columns > 0:
        return columns
    env = os.environ.get("COLUMNS", "")
    return int(env) if env.isdigit() and int(env) > 0 else 0


class MapProgress(Progress):
    """The map's progress: partitions done, passes per second and, per route, the kWh so far
    (the routes with most energy first)."""

    def __init__(self, total: int, stream=None, max_routes: int = 4, every_s: float | None = None):
        super().__init__("map", total, unit="partitions", stream=stream, every_s=every_s)
        self.max_routes = max_routes
        self.passes = 0
        self.routes: dict[str, float] = {}

    def add(self, res: dict) -> None:
        """Count one finished partition's summary (``passes``, ``kwh_by_route``)."""
        self.passes += int(res.get("passes", 0))
        for route, kwh in res.get("kwh_by_route", {}).items():
            self.routes[route] = self.routes.get(route, 0.0) + kwh
        elapsed = max(time.perf_counter() - self.t0, 1e-9)
        top = sorted(self.routes.items(), key=lambda kv: -kv[1])[:self.max_routes]
        text = f"{self.passes / elapsed / 1e6:.2f} M passes/s"
        if top:
            text += ", route kWh " + " ".join(f"{r}: {kwh:,.0f}" for r, kwh in top)
            if len(self.routes) > self.max_routes:
                text += f" (+{len(self.routes) - self.max_routes} routes)"
        self.update(1, text)


def citygml_bytes(paths) -> int:
    """Bytes :func:`file_position` counts through for these CityGML inputs: the file size
    (.gml, .xml, compressed .gz) or the GML members' uncompressed sizes (.zip)."""
    total = 0
    for path in map(Path, paths):
        if not path.is_file():
            continue
        if path.suffix.lower() == ".zip":
            try:
                with zipfile.ZipFile(path) as zf:
                    total += sum(i.file_size for i in zf.infolist()
                                 if i.filename.lower().endswith((".gml", ".xml", ".citygml")))
            except (zipfile.BadZipFile, OSError):
                total += path.stat().st_size    # the reader reports the broken file
        else:
            total += path.stat().st_size
    return total


def file_position(fh) -> int:
    """How far a reader has got in an open CityGML input, in :func:`citygml_bytes`' bytes:
    the compressed position of a .gz, the position in the file or zip member otherwise."""
    try:
        if isinstance(fh, gzip.GzipFile):
            return int(fh.fileobj.tell())
        return int(fh.tell())
    except (AttributeError, OSError, ValueError):
        return 0


class FolderProgress:
    """Progress of a stage that writes files into *folder* (the reduce): counts the files
    written there since it started and names the latest, polled by a thread every
    *poll_s*; the stage itself needs no hooks."""

    def __init__(self, desc: str, folder, stream=None, poll_s: float = 0.5,
                 every_s: float | None = None):
        import threading

        self.folder = Path(folder)
        self.progress = Progress(desc, None, unit="files", stream=stream, every_s=every_s)
        self.poll_s = poll_s
        self._start = time.time() - 1e-3
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, daemon=True, name=f"progress-{desc}")

    def __enter__(self) -> "FolderProgress":
        if self.progress.enabled:
            self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join()
        self._poll()
        self.progress.close()

    def _poll(self) -> None:
        try:
            new = [(p.stat().st_mtime, p.name) for p in self.folder.iterdir()
                   if p.is_file() and not p.name.startswith(".") and not p.name.endswith(".tmp")
                   and p.stat().st_mtime >= self._start]
        except OSError:
            return
        if new and len(new) != self.progress.n:
            self.progress.advance_to(len(new), f"last {max(new)[1]}")

    def _watch(self) -> None:
        while not self._stop.wait(self.poll_s):
            self._poll()
