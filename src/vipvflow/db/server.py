"""A local PostgreSQL + PostGIS cluster for mirroring runs (``make db``) and for the tests.

The cluster lives in one folder: ``<dir>/pgdata`` (data), ``<dir>/socket`` (unix socket),
``<dir>/pgpass`` (the password), ``<dir>/postgresql.log`` and ``<dir>/server.json`` (port and
DSN of the running server).  Only the user running the server can open its unix socket (folder
and socket mode 0700; connections there are trusted); on TCP it listens on 127.0.0.1 only and
asks for the password of the ``postgres`` role, generated on first start, printed once and
kept in ``<dir>/pgpass`` (``.pgpass`` format, mode 0600).  The DSN ``start`` returns names that
file (``?passfile=``) instead of holding the password.

PostgreSQL refuses to run as root: when this process is root, every server program runs as the
``postgres`` system user (``runuser -u postgres``) and the folder is given to that user.
"""
from __future__ import annotations

import glob
import json
import os
import pwd
import secrets
import shutil
import socket
import subprocess
import time
from dataclasses import dataclass
from pathlib import Path

from ..errors import VipvError

DATABASE = "vipvflow"
SERVER_USER = "postgres"


class ServerError(VipvError):
    """The local PostgreSQL server could not be found, started or stopped."""


@dataclass(frozen=True)
class LocalServer:
    """A running local cluster: where it lives and how to reach it."""

    dir: Path
    port: int
    dsn: str

    def dsn_of(self, database: str) -> str:
        """The DSN of *database* on this server (TCP, password from ``<dir>/pgpass``)."""
        return _dsn(self.dir, self.port, database)

    @property
    def admin_dsn(self) -> str:
        return self.dsn_of("postgres")


def _dsn(dir: Path, port: int, database: str) -> str:
    from urllib.parse import quote

    return (f"postgresql://{SERVER_USER}@127.0.0.1:{port}/{database}"
            f"?passfile={quote(str(dir / PASSFILE), safe='/')}")


#: the password file of a cluster folder (``.pgpass`` format)
PASSFILE = "pgpass"

#: client authentication: the unix socket (mode 0700) trusts the server's user, TCP asks for
#: the password
HBA = """\
# written by vipvflow db start
local   all  all                 trust
host    all  all  127.0.0.1/32   scram-sha-256
host    all  all  ::1/128        scram-sha-256
"""


def find_bindir() -> Path | None:
    """Folder of ``initdb`` / ``pg_ctl``: ``$VIPVFLOW_PG_BINDIR``, else the newest
    ``/usr/lib/postgresql/<major>/bin``, else the ``PATH``; None when absent."""
    env = os.environ.get("VIPVFLOW_PG_BINDIR")
    candidates = [Path(env)] if env else []
    found = glob.glob("/usr/lib/postgresql/*/bin")
    found.sort(key=lambda p: int(Path(p).parent.name) if Path(p).parent.name.isdigit() else 0,
               reverse=True)
    candidates += [Path(p) for p in found]
    which = shutil.which("pg_ctl")
    if which:
        candidates.append(Path(which).parent)
    for c in candidates:
        if (c / "initdb").is_file() and (c / "pg_ctl").is_file():
            return c
    return None


def postgis_available(bindir: Path) -> bool:
    """Whether the PostGIS extension files are installed for this server's major version."""
    sharedir = subprocess.run([str(bindir / "pg_config"), "--sharedir"], capture_output=True,
                              text=True).stdout.strip() if (bindir / "pg_config").exists() else ""
    if not sharedir:
        sharedir = f"/usr/share/postgresql/{bindir.parent.name}"
    return bool(glob.glob(os.path.join(sharedir, "extension", "postgis.control")))


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _as_server_user() -> list[str]:
    """Command prefix that runs a program as the server's user."""
    if os.geteuid() != 0:
        return []
    try:
        pwd.getpwnam(SERVER_USER)
    except KeyError:
        raise ServerError(f"running as root and there is no '{SERVER_USER}' system user to run "
                          "PostgreSQL as (it refuses to run as root)") from None
    runuser = shutil.which("runuser") or "/usr/sbin/runuser"
    return [runuser, "-u", SERVER_USER, "--"]


def _run(cmd: list[str], cwd: Path, what: str) -> str:
    proc = subprocess.run(_as_server_user() + cmd, cwd=cwd, capture_output=True, text=True)
    if proc.returncode != 0:
        detail = " ".join((proc.stderr or proc.stdout).split())[-400:]
        raise ServerError(f"{what} failed ({proc.returncode}): {detail}")
    return proc.stdout


def _give_to_server_user(path: Path) -> None:
    if os.geteuid() != 0:
        return
    pw = pwd.getpwnam(SERVER_USER)
    for root, dirs, files in os.walk(path):
        for name in [root] + [os.path.join(root, n) for n in dirs + files]:
            os.chown(name, pw.pw_uid, pw.pw_gid)
    # every folder above must be traversable by that user
    for parent in path.resolve().parents:
        if not os.access(parent, os.X_OK) or not (parent.stat().st_mode & 0o001):
            raise ServerError(f"{parent} is not traversable by the '{SERVER_USER}' user; "
                              f"put the database folder elsewhere (e.g. under /tmp)")


def _conf(port: int, socket_dir: Path, durable: bool) -> str:
    lines = [
        "listen_addresses = '127.0.0.1'",
        f"port = {port}",
        f"unix_socket_directories = '{socket_dir}'",
        "unix_socket_permissions = 0700",
        "password_encryption = 'scram-sha-256'",
        "max_connections = 30",
        "shared_buffers = 64MB",
        "max_wal_size = 1GB",
        "logging_collector = off",
    ]
    if not durable:  # a test server: speed over crash safety
        lines += ["fsync = off", "synchronous_commit = off", "full_page_writes = off"]
    return "\n".join(lines) + "\n"


def status(dir: str | Path) -> LocalServer | None:
    """The server running from *dir*, or None."""
    dir = Path(dir).resolve()
    info_file = dir / "server.json"
    bindir = find_bindir()
    if not info_file.exists() or bindir is None:
        return None
    proc = subprocess.run(_as_server_user() + [str(bindir / "pg_ctl"), "status", "-D",
                                               str(dir / "pgdata")],
                          cwd=dir, capture_output=True, text=True)
    if proc.returncode != 0:
        return None
    info = json.loads(info_file.read_text())
    return LocalServer(dir=dir, port=int(info["port"]), dsn=info["dsn"])


def start(dir: str | Path, port: int | None = None, durable: bool = True,
          say=print) -> LocalServer:
    """Start (creating on first use) the cluster in *dir*; returns its DSN and port.

    Creates the database ``vipvflow`` with the PostGIS extension. Starting an already running
    cluster returns it unchanged.
    """
    dir = Path(dir).resolve()
    running = status(dir)
    if running:
        say(f"PostgreSQL already running from {dir} on port {running.port}")
        return running
    bindir = find_bindir()
    if bindir is None:
        raise ServerError("PostgreSQL server programs (initdb, pg_ctl) not found; install "
                          "postgresql-15 and postgresql-15-postgis-3 or set VIPVFLOW_PG_BINDIR")
    if not postgis_available(bindir):
        raise ServerError(f"PostGIS is not installed for the PostgreSQL in {bindir}; install "
                          f"postgresql-{bindir.parent.name}-postgis-3")
    pgdata, socket_dir = dir / "pgdata", dir / "socket"
    dir.mkdir(parents=True, exist_ok=True)
    socket_dir.mkdir(exist_ok=True)
    for private in (dir, socket_dir):        # the socket and the password: the server's user only
        os.chmod(private, 0o700)
    fresh = not (pgdata / "PG_VERSION").exists()
    if fresh:
        pgdata.mkdir(exist_ok=True)
        _give_to_server_user(dir)
        say(f"initdb {pgdata}")
        _run([str(bindir / "initdb"), "-D", str(pgdata), "-U", SERVER_USER, "--auth=trust",
              "-E", "UTF8", "--locale=C", "--no-sync"], dir, "initdb")
        with open(pgdata / "postgresql.conf", "a") as f:
            f.write("\ninclude_if_exists = 'vipvflow.conf'\n")
    for attempt in range(3):
        use_port = port or free_port()
        (pgdata / "vipvflow.conf").write_text(_conf(use_port, socket_dir, durable))
        (pgdata / "pg_hba.conf").write_text(HBA)
        _give_to_server_user(dir)
        try:
            _run([str(bindir / "pg_ctl"), "start", "-D", str(pgdata), "-w", "-t", "60",
                  "-l", str(dir / "postgresql.log")], dir, "pg_ctl start")
            break
        except ServerError:
            if port is not None or attempt == 2:  # a chosen port is not changed behind one's back
                log_tail = _log_tail(dir)
                raise ServerError(f"PostgreSQL did not start on port {use_port}: {log_tail}") from None
    server = LocalServer(dir=dir, port=use_port, dsn=_dsn(dir, use_port, DATABASE))
    password = _ensure_password(server)
    if password:
        say(f"password of the '{SERVER_USER}' role on 127.0.0.1 (shown once; kept in "
            f"{dir / PASSFILE}, mode 0600, which the DSN names): {password}")
    _create_database(server)
    (dir / "server.json").write_text(json.dumps({"port": use_port, "dsn": server.dsn}))
    say(f"PostgreSQL {bindir.parent.name} + PostGIS running from {dir} on 127.0.0.1:{use_port}")
    return server


def _log_tail(dir: Path) -> str:
    try:
        lines = (dir / "postgresql.log").read_text().strip().splitlines()
    except OSError:
        return "(no log)"
    return " | ".join(lines[-3:])


def _socket(server: LocalServer, database: str) -> dict:
    """Connection arguments of the unix socket (trusted: only the server's user opens it)."""
    return {"host": str(server.dir / "socket"), "port": server.port, "user": SERVER_USER,
            "dbname": database}


def _ensure_password(server: LocalServer) -> str | None:
    """Give the ``postgres`` role a generated password kept in ``<dir>/pgpass`` (mode 0600),
    unless the file exists; returns the new password, or None."""
    import psycopg
    from psycopg import sql

    passfile = server.dir / PASSFILE
    if passfile.is_file():
        return None
    password = secrets.token_urlsafe(24)
    fd = os.open(passfile, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(f"127.0.0.1:*:*:{SERVER_USER}:{password}\nlocalhost:*:*:{SERVER_USER}:{password}\n")
    try:
        with psycopg.connect(**_socket(server, "postgres"), autocommit=True, connect_timeout=10) as conn:
            conn.execute(sql.SQL("ALTER ROLE {} PASSWORD {}").format(
                sql.Identifier(SERVER_USER), sql.Literal(password)))
    except BaseException:
        passfile.unlink(missing_ok=True)
        raise
    return password


def _create_database(server: LocalServer) -> None:
    import psycopg

    deadline = time.monotonic() + 30
    while True:
        try:
            with psycopg.connect(**_socket(server, "postgres"), autocommit=True, connect_timeout=5) as conn:
                if not conn.execute("SELECT 1 FROM pg_database WHERE datname = %s",
                                    (DATABASE,)).fetchone():
                    conn.execute(f"CREATE DATABASE {DATABASE}")
            break
        except psycopg.OperationalError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)
    with psycopg.connect(server.dsn, autocommit=True, connect_timeout=5) as conn:
        conn.execute("CREATE EXTENSION IF NOT EXISTS postgis")


def stop(dir: str | Path, say=print) -> bool:
    """Stop the cluster running from *dir* (fast shutdown); False if none was running."""
    dir = Path(dir).resolve()
    bindir = find_bindir()
    if bindir is None or not (dir / "pgdata" / "PG_VERSION").exists() or status(dir) is None:
        say(f"no PostgreSQL running from {dir}")
        return False
    _run([str(bindir / "pg_ctl"), "stop", "-D", str(dir / "pgdata"), "-m", "fast", "-w"],
         dir, "pg_ctl stop")
    (dir / "server.json").unlink(missing_ok=True)
    say(f"PostgreSQL stopped ({dir})")
    return True
