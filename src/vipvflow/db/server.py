"""A local PostgreSQL + PostGIS cluster for mirroring runs (``make db``) and for the tests,
or a Citus coordinator with workers on this machine.

The server lives in one folder: ``<dir>/pgdata`` (data), ``<dir>/socket`` (unix socket),
``<dir>/pgpass`` (the password), ``<dir>/postgresql.log`` and ``<dir>/server.json`` (port and
DSN of the running server).  Only the user running the server can open its unix socket (folder
and socket mode 0700; connections there are trusted); on TCP it listens on 127.0.0.1 only and
asks for the password of the ``postgres`` role, generated on first start, printed once and
kept in ``<dir>/pgpass`` (``.pgpass`` format, mode 0600).  The DSN ``start`` returns names that
file (``?passfile=``) instead of holding the password.

With ``citus_workers=N`` the folder holds a Citus cluster: the coordinator as above and N
workers in ``<dir>/worker<i>/`` (each its own ``pgdata``, ``socket``, log and port), every node
with ``shared_preload_libraries = 'citus'``, on 127.0.0.1 only, with the same rules and the
one password of ``<dir>/pgpass``.  The nodes reach each other over 127.0.0.1 with that
password: every server process has ``PGPASSFILE=<dir>/pgpass`` (the file belongs to the
server's user).  Database ``vipvflow`` has the citus and postgis extensions on every node and
the workers registered on the coordinator.  ``<dir>/cluster.json`` records the number of
workers and each node's port: a node restarts on its port when it is free, else on another,
and the coordinator's node list follows.

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
#: a Citus node's loopback address (the nodes' names in ``pg_dist_node``)
LOOPBACK = "127.0.0.1"


class ServerError(VipvError):
    """The local PostgreSQL server could not be found, started or stopped."""


@dataclass(frozen=True)
class LocalServer:
    """A running local server (a Citus coordinator when it has *workers*): where it lives
    and how to reach it."""

    dir: Path
    port: int
    dsn: str
    workers: tuple[LocalServer, ...] = ()
    passfile: Path | None = None  # the cluster's password file (default <dir>/pgpass)

    def dsn_of(self, database: str) -> str:
        """The DSN of *database* on this server (TCP, password from the password file)."""
        return _dsn(self.passfile or self.dir / PASSFILE, self.port, database)

    @property
    def admin_dsn(self) -> str:
        return self.dsn_of("postgres")

    @property
    def nodes(self) -> tuple[LocalServer, ...]:
        """This server and its workers."""
        return (self,) + self.workers


def _dsn(passfile: Path, port: int, database: str) -> str:
    from urllib.parse import quote

    return (f"postgresql://{SERVER_USER}@{LOOPBACK}:{port}/{database}"
            f"?passfile={quote(str(passfile), safe='/')}")


#: the password file of a cluster folder (``.pgpass`` format)
PASSFILE = "pgpass"
#: the layout of a Citus cluster folder (number of workers, each node's last port)
CLUSTER_FILE = "cluster.json"

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
        s.bind((LOOPBACK, 0))
        return s.getsockname()[1]


def _port_is_free(port: int) -> bool:
    """Whether a server could listen on *port* (as PostgreSQL does, with SO_REUSEADDR: a port
    in TIME_WAIT after a stop is free)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((LOOPBACK, port))
        except OSError:
            return False
    return True


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


def _run(cmd: list[str], cwd: Path, what: str, env: dict[str, str] | None = None) -> str:
    prefix = ["env"] + [f"{k}={v}" for k, v in env.items()] if env else []
    proc = subprocess.run(_as_server_user() + prefix + cmd, cwd=cwd, capture_output=True,
                          text=True)
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
        if not _traversable_by(parent, pw):
            raise ServerError(f"{parent} is not traversable by the '{SERVER_USER}' user; "
                              f"put the database folder elsewhere (e.g. under /tmp)")


def _traversable_by(folder: Path, pw: pwd.struct_passwd) -> bool:
    """Whether the user *pw* may enter *folder* (owner, group or other execute bit)."""
    st = folder.stat()
    if st.st_uid == pw.pw_uid:
        return bool(st.st_mode & 0o100)
    if st.st_gid in os.getgrouplist(pw.pw_name, pw.pw_gid):
        return bool(st.st_mode & 0o010)
    return bool(st.st_mode & 0o001)


def _conf(port: int, socket_dir: Path, durable: bool, citus: bool = False) -> str:
    lines = [
        f"listen_addresses = '{LOOPBACK}'",
        f"port = {port}",
        f"unix_socket_directories = '{socket_dir}'",
        "unix_socket_permissions = 0700",
        "password_encryption = 'scram-sha-256'",
        f"max_connections = {100 if citus else 30}",
        "shared_buffers = 64MB",
        "max_wal_size = 1GB",
        "logging_collector = off",
    ]
    if citus:
        lines += [
            "shared_preload_libraries = 'citus'",
            # two-phase commit of writes that span nodes; a maintenance daemon per database
            "max_prepared_transactions = 100",
            "max_worker_processes = 32",
            # connections to itself and the node names in pg_dist_node: loopback, over IPv4
            f"citus.local_hostname = '{LOOPBACK}'",
            # no daily usage report to Citus's servers (only a Citus built with libcurl sends it)
            "citus.enable_statistics_collection = off",
        ]
    if not durable:  # a test server: speed over crash safety
        lines += ["fsync = off", "synchronous_commit = off", "full_page_writes = off"]
    return "\n".join(lines) + "\n"


def _node_running(bindir: Path, dir: Path) -> bool:
    if not (dir / "pgdata" / "PG_VERSION").exists():
        return False
    proc = subprocess.run(_as_server_user() + [str(bindir / "pg_ctl"), "status", "-D",
                                               str(dir / "pgdata")],
                          cwd=dir, capture_output=True, text=True)
    return proc.returncode == 0


def _read_cluster(dir: Path) -> dict | None:
    try:
        return json.loads((dir / CLUSTER_FILE).read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        raise ServerError(f"{dir / CLUSTER_FILE}: unreadable ({exc})") from None


def _worker_dirs(dir: Path, n: int) -> list[Path]:
    return [dir / f"worker{i}" for i in range(1, n + 1)]


def status(dir: str | Path) -> LocalServer | None:
    """The server (coordinator) running from *dir*, or None."""
    dir = Path(dir).resolve()
    info_file = dir / "server.json"
    bindir = find_bindir()
    if not info_file.exists() or bindir is None or not _node_running(bindir, dir):
        return None
    info = json.loads(info_file.read_text())
    workers = tuple(LocalServer(dir=Path(w["dir"]), port=int(w["port"]),
                                dsn=_dsn(dir / PASSFILE, int(w["port"]), DATABASE),
                                passfile=dir / PASSFILE)
                    for w in info.get("workers", []))
    return LocalServer(dir=dir, port=int(info["port"]), dsn=info["dsn"], workers=workers)


def start(dir: str | Path, port: int | None = None, durable: bool = True,
          say=print, citus_workers: int | None = None) -> LocalServer:
    """Start (creating on first use) the server in *dir*; returns its DSN and port.

    Creates the database ``vipvflow`` with the PostGIS extension. Starting an already running
    server returns it unchanged.

    Parameters
    ----------
    citus_workers : int, optional
        Make *dir* a Citus cluster of a coordinator and this many workers (``>= 1``); the
        number is kept, so a later start without it starts the same cluster. None: what
        *dir* holds (a plain server when new).
    """
    import psycopg

    dir = Path(dir).resolve()
    cluster = _read_cluster(dir)
    n_workers = _workers_wanted(dir, cluster, citus_workers)
    running = status(dir)
    bindir = find_bindir()
    if running and (bindir is None or all(_node_running(bindir, w.dir) for w in running.workers)):
        say(f"PostgreSQL already running from {dir} on port {running.port}")
        return running
    if bindir is None:
        raise ServerError("PostgreSQL server programs (initdb, pg_ctl) not found; install "
                          "postgresql-15 and postgresql-15-postgis-3 or set VIPVFLOW_PG_BINDIR")
    if not postgis_available(bindir):
        raise ServerError(f"PostGIS is not installed for the PostgreSQL in {bindir}; install "
                          f"postgresql-{bindir.parent.name}-postgis-3")
    citus = n_workers > 0
    if citus:
        from . import citus as citus_build

        pg = citus_build.pg_install(bindir)
        if citus_build.installed(pg) is None:
            raise ServerError(citus_build.how_to_get(pg))
    passfile = dir / PASSFILE
    node_dirs = [dir] + _worker_dirs(dir, n_workers)
    ports = list((cluster or {}).get("ports", []))
    if citus and port and ports and port != ports[0]:
        raise ServerError(f"the Citus cluster in {dir} runs its coordinator on port {ports[0]} "
                          f"(its nodes keep their ports), not {port}")
    started, newly = [], []
    try:
        for i, node_dir in enumerate(node_dirs):
            if _node_running(bindir, node_dir):
                started.append(_running_port(node_dir))
                continue
            recorded = ports[i] if i < len(ports) else None
            if recorded is not None and not _port_is_free(recorded):
                raise ServerError(
                    f"port {recorded} of {node_dir.name if i else 'the coordinator'} of the Citus "
                    f"cluster in {dir} is in use by another program (a cluster's nodes keep "
                    "their ports, which its node list holds): stop that program and start again")
            wanted = recorded or (port if i == 0 else None)
            started.append(_start_node(node_dir, bindir, wanted, durable, citus, passfile, say))
            newly.append(node_dir)
            if citus:  # recorded at once: a start that fails later leaves a known layout
                (dir / CLUSTER_FILE).write_text(json.dumps({
                    "citus_workers": n_workers, "ports": started + ports[len(started):]}))
        workers = tuple(LocalServer(dir=d, port=p, dsn=_dsn(passfile, p, DATABASE), passfile=passfile)
                        for d, p in zip(node_dirs[1:], started[1:]))
        server = LocalServer(dir=dir, port=started[0], dsn=_dsn(passfile, started[0], DATABASE),
                             workers=workers)
        password = _ensure_password(server)
        if password:
            say(f"password of the '{SERVER_USER}' role on {LOOPBACK} (shown once; kept in "
                f"{passfile}, mode 0600, which the DSN names): {password}")
        for w in workers:
            _set_password(w, _read_password(passfile))
        create_database(server, DATABASE)
    except psycopg.Error as exc:
        for node_dir in reversed(newly):
            _stop_node(bindir, node_dir)
        raise ServerError(f"setting up database {DATABASE} in {dir} failed: "
                          f"{' '.join(str(exc).split())}") from None
    except BaseException:
        for node_dir in reversed(newly):   # no half-started cluster left behind
            _stop_node(bindir, node_dir)
        raise
    (dir / "server.json").write_text(json.dumps({
        "port": server.port, "dsn": server.dsn,
        "workers": [{"dir": str(w.dir), "port": w.port} for w in workers]}))
    if citus:
        say(f"Citus coordinator on {LOOPBACK}:{server.port} with {n_workers} worker(s) on "
            + ", ".join(str(w.port) for w in workers) + f", running from {dir}")
    else:
        say(f"PostgreSQL {bindir.parent.name} + PostGIS running from {dir} on "
            f"{LOOPBACK}:{server.port}")
    return server


def _workers_wanted(dir: Path, cluster: dict | None, citus_workers: int | None) -> int:
    """The number of Citus workers of *dir* (0: a plain server), checked against what the
    folder already holds."""
    if citus_workers is not None and citus_workers < 0:
        raise ServerError(f"--citus-workers must be 0 or more, not {citus_workers}")
    if cluster is not None:
        have = int(cluster["citus_workers"])
        if citus_workers is not None and citus_workers != have:
            raise ServerError(f"{dir} holds a Citus cluster of {have} worker(s), not "
                              f"{citus_workers}: start it without --citus-workers, or use "
                              "another --dir")
        return have
    if citus_workers and (dir / "pgdata" / "PG_VERSION").exists():
        raise ServerError(f"{dir} holds a plain PostgreSQL server: use another --dir for a "
                          "Citus cluster")
    return citus_workers or 0


def _running_port(node_dir: Path) -> int:
    conf = (node_dir / "pgdata" / "vipvflow.conf").read_text()
    return int(next(line.split("=")[1] for line in conf.splitlines()
                    if line.startswith("port =")))


def _start_node(dir: Path, bindir: Path, port: int | None, durable: bool, citus: bool,
                passfile: Path, say) -> int:
    """Create (first time) and start the server of one folder; returns its port.

    *port*: the port to use (not changed behind the user's back); None: a free one.
    """
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
        (pgdata / "vipvflow.conf").write_text(_conf(use_port, socket_dir, durable, citus))
        (pgdata / "pg_hba.conf").write_text(HBA)
        _give_to_server_user(dir)
        try:
            _run([str(bindir / "pg_ctl"), "start", "-D", str(pgdata), "-w", "-t", "60",
                  "-l", str(dir / "postgresql.log")], dir, "pg_ctl start",
                 env={"PGPASSFILE": str(passfile)})
            return use_port
        except ServerError:
            if port is not None or attempt == 2:
                log_tail = _log_tail(dir)
                raise ServerError(f"PostgreSQL did not start on port {use_port}: {log_tail}") from None
    raise AssertionError("unreachable")


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


def _read_password(passfile: Path) -> str:
    return passfile.read_text().split("\n")[0].rsplit(":", 1)[1]


def _set_password(server: LocalServer, password: str) -> None:
    import psycopg
    from psycopg import sql

    with psycopg.connect(**_socket(server, "postgres"), autocommit=True, connect_timeout=10) as conn:
        conn.execute(sql.SQL("ALTER ROLE {} PASSWORD {}").format(
            sql.Identifier(SERVER_USER), sql.Literal(password)))


def _ensure_password(server: LocalServer) -> str | None:
    """Give the ``postgres`` role a generated password kept in ``<dir>/pgpass`` (mode 0600,
    the server's user's: the nodes of a cluster read it), unless the file exists; returns the
    new password, or None."""
    passfile = server.dir / PASSFILE
    if passfile.is_file():
        return None
    password = secrets.token_urlsafe(24)
    fd = os.open(passfile, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(f"{LOOPBACK}:*:*:{SERVER_USER}:{password}\nlocalhost:*:*:{SERVER_USER}:{password}\n")
    try:
        if os.geteuid() == 0:
            pw = pwd.getpwnam(SERVER_USER)
            os.chown(passfile, pw.pw_uid, pw.pw_gid)
        _set_password(server, password)
    except BaseException:
        passfile.unlink(missing_ok=True)
        raise
    return password


def _connect_socket(server: LocalServer, database: str, timeout_s: float = 30):
    """An autocommit connection over the unix socket, retried while the server starts up."""
    import psycopg

    deadline = time.monotonic() + timeout_s
    while True:
        try:
            return psycopg.connect(**_socket(server, database), autocommit=True, connect_timeout=5)
        except psycopg.OperationalError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.2)


def create_database(server: LocalServer, database: str, postgis: bool = True) -> None:
    """Create *database* (when missing) with PostGIS; on a Citus cluster on every node, with
    the citus extension first, and register the coordinator and the workers in it.

    *postgis* False leaves PostGIS to the mirror (which creates it on the coordinator; Citus
    creates it on the workers)."""
    from psycopg import sql

    citus = bool(server.workers)
    for node in server.nodes:
        with _connect_socket(server=node, database="postgres") as conn:
            if not conn.execute("SELECT 1 FROM pg_database WHERE datname = %s",
                                (database,)).fetchone():
                conn.execute(sql.SQL("CREATE DATABASE {}").format(sql.Identifier(database)))
        with _connect_socket(node, database) as conn:
            have = {r[0] for r in conn.execute("SELECT extname FROM pg_extension")}
            # (a worker that holds Citus metadata refuses CREATE EXTENSION, even IF NOT EXISTS)
            for ext in ("citus",) * citus + ("postgis",) * postgis:
                if ext not in have:
                    conn.execute(sql.SQL("CREATE EXTENSION {}").format(sql.Identifier(ext)))
    if not citus:
        return
    with _connect_socket(server, database) as conn:
        conn.execute("SELECT citus_set_coordinator_host(%s, %s)", (LOOPBACK, server.port))
        known = {r[0] for r in conn.execute(
            "SELECT nodeport FROM pg_dist_node WHERE groupid <> 0 AND nodename = %s", (LOOPBACK,))}
        for w in server.workers:
            if w.port not in known:
                conn.execute("SELECT citus_add_node(%s, %s)", (LOOPBACK, w.port))


def drop_database(server: LocalServer, database: str) -> None:
    """Drop *database* on every node of the server (the coordinator first)."""
    from psycopg import sql

    for node in server.nodes:
        with _connect_socket(node, "postgres") as conn:
            conn.execute(sql.SQL("DROP DATABASE IF EXISTS {} WITH (FORCE)").format(
                sql.Identifier(database)))


def _stop_node(bindir: Path, node_dir: Path) -> bool:
    """Stop the server of one folder (fast shutdown); False when it was not running."""
    if not _node_running(bindir, node_dir):
        return False
    _run([str(bindir / "pg_ctl"), "stop", "-D", str(node_dir / "pgdata"), "-m", "fast", "-w"],
         node_dir, "pg_ctl stop")
    return True


def stop(dir: str | Path, say=print) -> bool:
    """Stop the server running from *dir* (fast shutdown), and a Citus cluster's workers;
    False if none was running."""
    dir = Path(dir).resolve()
    bindir = find_bindir()
    cluster = _read_cluster(dir) if dir.is_dir() else None
    nodes = [dir] + _worker_dirs(dir, int(cluster["citus_workers"]) if cluster else 0)
    stopped = []
    for node_dir in nodes if bindir is not None else []:
        if _stop_node(bindir, node_dir):
            stopped.append(node_dir)
    (dir / "server.json").unlink(missing_ok=True)
    if not stopped:
        say(f"no PostgreSQL running from {dir}")
        return False
    if cluster:
        say(f"Citus cluster stopped ({dir}: coordinator and {len(nodes) - 1} worker(s), "
            f"{len(stopped)} node(s) were running)")
    else:
        say(f"PostgreSQL stopped ({dir})")
    return True
