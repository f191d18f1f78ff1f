"""A DSN's password is never written or logged (issue 19); the database side is in test_db.py."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from vipvflow.db.server import free_port
from vipvflow.simulation.rundir import mask_dsn, masked_config

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("dsn, masked", [
    ("postgresql://u:secret@h/db", "postgresql://u:***@h/db"),
    ("postgres://bus-fleet:s3cr%40t@10.0.0.5:5433/vipvflow?sslmode=require",
     "postgres://bus-fleet:***@10.0.0.5:5433/vipvflow?sslmode=require"),
    ("postgresql://u@h:5432/db?password=secret&sslmode=disable",
     "postgresql://u@h:5432/db?password=***&sslmode=disable"),
    ("host=h port=5432 user=u password=secret dbname=db", "host=h port=5432 user=u password=*** dbname=db"),
    ("host=h password = 'se cret' dbname=db", "host=h password = *** dbname=db"),
    ("postgresql://u@h:5432/db", "postgresql://u@h:5432/db"),            # nothing to mask
    ("postgresql://h:5432/db", "postgresql://h:5432/db"),
    (None, None),
])
def test_mask_dsn(dsn, masked):
    assert mask_dsn(dsn) == masked


def test_masked_config_leaves_the_original():
    config = {"db": {"dsn": "postgresql://u:secret@h/db"}, "scenario": "x"}
    assert masked_config(config)["db"]["dsn"] == "postgresql://u:***@h/db"
    assert config["db"]["dsn"] == "postgresql://u:secret@h/db"


def test_password_dsn_written_nowhere(small_config, tmp_path):
    """A run given a DSN with a password, whose server is unreachable: the mirror fails in one
    line; neither the output folder nor the console holds the password."""
    conf = yaml.safe_load(Path(small_config).read_text())
    conf["out_dir"] = str(tmp_path / "out")
    path = tmp_path / "scenario.yaml"      # (the report names the file: no "secret" in its name)
    path.write_text(yaml.safe_dump(conf))
    dsn = f"postgresql://vipv:secret@127.0.0.1:{free_port()}/vipvflow"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    proc = subprocess.run([sys.executable, "-m", "vipvflow.cli", "simulate", "--config", str(path),
                           "--year", "2024", "--workers", "1", "--db", dsn],
                          capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 2, proc.stderr
    errors = [ln for ln in proc.stderr.splitlines() if "error" in ln.lower()]
    assert errors == [errors[-1]] and "cannot connect to PostgreSQL at vipv@127.0.0.1" in errors[-1]
    assert "secret" not in proc.stdout + proc.stderr
    out = tmp_path / "out"
    manifest = (out / "small" / "2024" / "manifest.json").read_text()
    assert "postgresql://vipv:***@127.0.0.1" in manifest             # recorded, masked
    leaks = [p for p in out.rglob("*") if p.is_file() and b"secret" in p.read_bytes()]
    assert leaks == []                                                 # grep -r secret out/


@pytest.mark.parametrize("dsn", [
    "postgresql//vipv:secret@127.0.0.1/db",                     # a typo: not a URI, not key=value
    "host=127.0.0.1 password=secret dbname",                    # key without a value
    f"postgresql://vipv:secret@127.0.0.1:{free_port()}/db",     # nobody listening
    "postgresql://vipv:secret@127.0.0.1:1/db?sslmode=bogus",
])
def test_database_errors_never_show_the_password(dsn):
    from vipvflow.db.mirror import DatabaseError, connect

    with pytest.raises(DatabaseError) as err:
        connect(dsn)
    message = str(err.value)
    assert "secret" not in message and "\n" not in message and message
