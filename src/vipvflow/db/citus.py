"""Citus for the local cluster (``vipvflow db citus``, ``make citus``): the installed
extension, or one built from a Citus source tarball and installed into the server.

Citus is a PostgreSQL extension (AGPL-3.0) that runs inside the server; nothing of it is part
of vipvflow. The server needs ``citus.so`` in its ``pkglibdir`` and ``citus.control`` in its
``sharedir/extension``. When they are there, that Citus is used. Otherwise, given a source
tarball (``citus-<version>.tar.gz``, e.g. ``git archive`` of a release tag), :func:`ensure`
builds it against the server's headers (``pg_config``) and installs it, which needs write
access to those folders (root). The build:

- unpacks the tarball into a temporary folder of the cache (``$VIPVFLOW_CACHE_DIR``, else
  ``$XDG_CACHE_HOME/vipvflow``, else ``~/.cache/vipvflow``), outside any repository;
- resolves the one conflict of Citus 13.x with PostgreSQL 15.20's headers (see
  :func:`patch_source`) in that unpacked copy;
- runs ``./configure --without-libcurl`` (no usage statistics sent to Citus's servers: the
  cluster stays offline) and ``make`` without LLVM bitcode (the server's JIT inlining of
  Citus code is not needed; measured in one run on the loaded 2-core machine: 161 s without,
  322 s with it), then ``make install DESTDIR=<stage>``;
- keeps the staged files under ``<cache>/citus/<tarball>-pg<version>-<digest>/``, so a second
  install (another machine state, a reinstalled server package) copies them without building.

Building needs the server headers and the libraries Citus links (Debian:
:data:`BUILD_PACKAGES`); a missing one is reported in one line naming the packages.
"""
from __future__ import annotations

import glob
import hashlib
import json
import os
import re
import shutil
import subprocess
import tarfile
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from .server import ServerError, find_bindir

#: Debian packages the build needs beyond the server (``{major}``: the server's major version)
BUILD_PACKAGES = ("postgresql-server-dev-{major}", "liblz4-dev", "libzstd-dev", "libkrb5-dev",
                  "libssl-dev", "libselinux1-dev", "libxslt1-dev", "libpam0g-dev",
                  "libreadline-dev")
#: bump when the build recipe changes: a new cache entry is built
RECIPE = 1
CONFIGURE_ARGS = ("--without-libcurl",)
MAKE_ARGS = ("with_llvm=no",)


class CitusError(ServerError):
    """Citus is not installed and cannot be built or installed here (the message says why)."""


@dataclass(frozen=True)
class PgInstall:
    """Where a PostgreSQL server keeps its extensions."""

    bindir: Path
    version: str            # e.g. "15.20"
    major: str              # e.g. "15"
    pkglibdir: Path         # the shared libraries (citus.so)
    sharedir: Path          # extension/ (citus.control, citus--*.sql)
    includedir_server: Path  # postgres.h: present with the server's development package

    @property
    def build_packages(self) -> list[str]:
        return [p.format(major=self.major) for p in BUILD_PACKAGES]


def pg_install(bindir: Path | None = None) -> PgInstall:
    """The PostgreSQL of :func:`~vipvflow.db.server.find_bindir` (or *bindir*), from its
    ``pg_config``."""
    bindir = bindir or find_bindir()
    if bindir is None or not (bindir / "pg_config").is_file():
        raise CitusError("PostgreSQL server programs (initdb, pg_ctl, pg_config) not found; "
                         "install postgresql-15 and postgresql-15-postgis-3 or set "
                         "VIPVFLOW_PG_BINDIR")
    out = subprocess.run([str(bindir / "pg_config"), "--version", "--pkglibdir", "--sharedir",
                          "--includedir-server"], capture_output=True, text=True)
    lines = out.stdout.splitlines()
    if out.returncode != 0 or len(lines) != 4:
        raise CitusError(f"{bindir / 'pg_config'} failed: {' '.join(out.stderr.split())[-300:]}")
    m = re.search(r"PostgreSQL (\d+)\.(\d+)", lines[0])
    if not m:
        raise CitusError(f"{bindir / 'pg_config'}: unexpected version {lines[0]!r}")
    return PgInstall(bindir=bindir, version=f"{m[1]}.{m[2]}", major=m[1],
                     pkglibdir=Path(lines[1]), sharedir=Path(lines[2]),
                     includedir_server=Path(lines[3]))


def installed(pg: PgInstall) -> str | None:
    """The version of the Citus extension installed for *pg* (``citus.control``'s
    ``default_version``), or None."""
    control = pg.sharedir / "extension" / "citus.control"
    if not (control.is_file() and (pg.pkglibdir / "citus.so").is_file()):
        return None
    m = re.search(r"default_version\s*=\s*'([^']+)'", control.read_text())
    return m[1] if m else "unknown version"


def how_to_get(pg: PgInstall) -> str:
    """One line: how a user gets Citus for this server."""
    return (f"Citus is not installed for PostgreSQL {pg.version} ({pg.pkglibdir}/citus.so): "
            f"install Citus's package postgresql-{pg.major}-citus-13.x (from Citus's package "
            "repository, on a machine with internet access), or build it from Citus's source "
            "as root: `vipvflow db citus --source citus-13.x.tar.gz` (in a clone: `make citus "
            "CITUS_SOURCE=...`)")


def find_tarball(source: str | Path) -> Path:
    """*source* itself when it is a file, else the newest ``citus-*.tar.gz`` in that folder."""
    source = Path(source).resolve()
    if source.is_file():
        return source
    if source.is_dir():
        found = sorted(glob.glob(str(source / "citus-*.tar.gz")), key=_version_key)
        if found:
            return Path(found[-1])
        raise CitusError(f"{source}: no citus-*.tar.gz in this folder")
    raise CitusError(f"{source}: no such file or folder (the Citus source tarball)")


def _version_key(path: str) -> tuple[int, ...]:
    return tuple(int(n) for n in re.findall(r"\d+", Path(path).name))


def cache_dir() -> Path:
    """The user's cache for built Citus trees (never inside a repository)."""
    env = os.environ.get("VIPVFLOW_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "vipvflow"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def build_key(tarball: Path, pg: PgInstall) -> str:
    """Name of the cache entry of *tarball* built for *pg* with this recipe."""
    recipe = json.dumps([RECIPE, CONFIGURE_ARGS, MAKE_ARGS, pg.version, str(pg.pkglibdir),
                         str(pg.sharedir)])
    digest = hashlib.sha256((_sha256(tarball) + recipe).encode()).hexdigest()[:12]
    name = tarball.name.removesuffix(".tar.gz")
    return f"{name}-pg{pg.version}-{digest}"


#: Citus 13.x's own copy of ``have_createdb_privilege`` (pg_version_compat.h, PostgreSQL < 16)
_COMPAT_HEADER = "src/include/pg_version_compat.h"
_OWN_DEFINITION = "static inline bool\nhave_createdb_privilege(void)\n"
_RENAME = "#define have_createdb_privilege citus_have_createdb_privilege\n"


def patch_source(src: Path) -> bool:
    """Resolve Citus 13.x's conflict with PostgreSQL 15.20's headers in the unpacked *src*.

    For PostgreSQL 15, Citus defines its own ``static inline bool have_createdb_privilege(void)``
    in ``pg_version_compat.h`` (the server's function was static before 16). PostgreSQL 15.20
    exports ``have_createdb_privilege`` from ``commands/dbcommands.h``, so a file including both
    fails with "static declaration follows non-static declaration". Citus's copy is renamed to
    ``citus_have_createdb_privilege`` (a macro ahead of it), so both coexist and the build
    works against the headers of 15.20 and of earlier 15.x alike; the two functions are the
    same check (superuser or ``rolcreatedb``).

    Returns True when patched, False when already patched; :class:`CitusError` when the
    header is not the expected one (another Citus version: then no patch is applied).
    """
    header = src / _COMPAT_HEADER
    try:
        text = header.read_text()
    except OSError as exc:
        raise CitusError(f"{header}: unreadable ({exc.strerror}); is this a Citus source tree?") from None
    if _RENAME + _OWN_DEFINITION in text:
        return False
    count = text.count(_OWN_DEFINITION)
    if count == 0:
        return False  # this Citus has no copy of its own: nothing conflicts
    if count != 1:
        raise CitusError(f"{header}: {count} definitions of have_createdb_privilege, expected "
                         "one; the build's header fix does not know this Citus version")
    header.write_text(text.replace(_OWN_DEFINITION, _RENAME + _OWN_DEFINITION))
    return True


def _check_build_tools(pg: PgInstall) -> None:
    missing = []
    if not (pg.includedir_server / "postgres.h").is_file():
        missing.append(f"the PostgreSQL {pg.major} server headers ({pg.includedir_server}/postgres.h)")
    for tool in ("gcc", "make"):
        if shutil.which(tool) is None:
            missing.append(tool)
    if missing:
        raise CitusError(f"building Citus needs {', '.join(missing)}: install them (Debian: "
                         f"apt-get install gcc make {' '.join(pg.build_packages)})")


def _step(cmd: list[str], cwd: Path, log: Path, what: str) -> None:
    with open(log, "ab") as f:
        f.write(f"\n$ {' '.join(cmd)}\n".encode())
        f.flush()
        proc = subprocess.run(cmd, cwd=cwd, stdout=f, stderr=subprocess.STDOUT)
    if proc.returncode != 0:
        tail = [line for line in log.read_text(errors="replace").splitlines()
                if "error" in line.lower()][-2:]
        raise CitusError(f"building Citus: {what} failed ({proc.returncode}); log {log}: "
                         + (" | ".join(" ".join(t.split())[-300:] for t in tail) or "see the log"))


def build(tarball: Path, pg: PgInstall, cache: Path | None = None, say=print) -> Path:
    """Build Citus from *tarball* for *pg*; returns the staged tree (``<stage>/usr/...``),
    reused from the cache when this tarball was built for this server before."""
    cache = (cache or cache_dir()) / "citus"
    stage = cache / build_key(tarball, pg)
    if (stage / "BUILD.json").is_file():
        say(f"Citus build cached in {stage}")
        return stage
    _check_build_tools(pg)
    cache.mkdir(parents=True, exist_ok=True)
    log = cache / f"{stage.name}.log"
    log.unlink(missing_ok=True)
    t0 = time.monotonic()
    say(f"building Citus from {tarball} for PostgreSQL {pg.version} (log {log}) ...")
    with tempfile.TemporaryDirectory(prefix=".build-", dir=cache) as work:
        work = Path(work)
        with tarfile.open(tarball) as tar:
            tar.extractall(work / "src", filter="data")
        tops = [p for p in (work / "src").iterdir() if p.is_dir()]
        src = tops[0] if len(tops) == 1 else work / "src"
        if not (src / "configure").is_file():
            raise CitusError(f"{tarball}: no configure script at its top; not a Citus source tarball")
        if patch_source(src):
            say(f"  {_COMPAT_HEADER}: Citus's own have_createdb_privilege renamed "
                "(PostgreSQL 15.20 exports one)")
        jobs = str(max(1, os.cpu_count() or 1))
        _step(["./configure", *CONFIGURE_ARGS, f"PG_CONFIG={pg.bindir / 'pg_config'}"],
              src, log, "configure")
        _step(["make", f"-j{jobs}", *MAKE_ARGS], src, log, "make")
        staged = work / "stage"
        _step(["make", "install", *MAKE_ARGS, f"DESTDIR={staged}"], src, log, "make install")
        seconds = round(time.monotonic() - t0, 1)
        (staged / "BUILD.json").write_text(json.dumps({
            "tarball": str(tarball), "sha256": _sha256(tarball), "postgresql": pg.version,
            "configure": list(CONFIGURE_ARGS), "make": list(MAKE_ARGS), "seconds": seconds,
            "built": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}, indent=2))
        shutil.rmtree(stage, ignore_errors=True)
        staged.rename(stage)
    say(f"built Citus in {seconds:.0f} s; kept in {stage}")
    return stage


def staged_files(stage: Path) -> list[tuple[Path, Path]]:
    """(staged file, installed path) of a staged build."""
    return [(p, Path("/") / p.relative_to(stage)) for p in sorted(stage.rglob("*"))
            if p.is_file() and p.name != "BUILD.json"]


def check_installable(pg: PgInstall) -> None:
    """:class:`CitusError` unless this process may write the server's extension folders."""
    for folder in (pg.pkglibdir, pg.sharedir / "extension"):
        if not os.access(folder, os.W_OK):
            raise CitusError(f"installing Citus into {folder} needs root: run `sudo vipvflow db "
                             f"citus --source ...` (or `sudo make citus`); until then the Citus "
                             "cluster and its tests are unavailable")


def install(stage: Path, pg: PgInstall) -> int:
    """Copy a staged build into the server's folders; returns the number of files.

    Each file is written under a temporary name and renamed over the old one, so a server
    that has ``citus.so`` loaded keeps its mapping.
    """
    check_installable(pg)
    files = staged_files(stage)
    for src, dest in files:
        dest.parent.mkdir(parents=True, exist_ok=True)
        tmp = dest.with_name(f".{dest.name}.vipvflow-tmp")
        shutil.copy2(src, tmp)
        os.replace(tmp, dest)
    return len(files)


def ensure(source: str | Path | None = None, say=print, bindir: Path | None = None) -> str:
    """Make Citus available to the local server: the installed one, else built from *source*
    (a tarball, or a folder holding ``citus-*.tar.gz``) and installed. Returns its version.

    Raises :class:`CitusError` with one line saying what is missing.
    """
    pg = pg_install(bindir)
    version = installed(pg)
    if version:
        say(f"Citus {version} installed for PostgreSQL {pg.version} ({pg.pkglibdir / 'citus.so'})")
        return version
    if source is None:
        raise CitusError(how_to_get(pg))
    tarball = find_tarball(source)
    check_installable(pg)             # before a build that could not be installed
    stage = build(tarball, pg, say=say)
    n = install(stage, pg)
    version = installed(pg)
    if version is None:
        raise CitusError(f"the build in {stage} installed no citus.control / citus.so")
    say(f"Citus {version} installed for PostgreSQL {pg.version} ({n} files from {stage})")
    return version
