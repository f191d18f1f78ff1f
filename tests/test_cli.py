"""The ``vipvflow`` command line as a whole: one ``--config`` option, no cli/commands import loop."""
import argparse
import ast
import subprocess
import sys
from pathlib import Path

import pytest

from vipvflow.cli import build_parser, main
from vipvflow.config import CONF_DIR

COMMANDS_DIR = Path(__file__).resolve().parents[1] / "src" / "vipvflow" / "commands"

#: every subcommand that reads a scenario, by its path of subcommand names
READS_SCENARIO = {
    ("config",), ("simulate",), ("economics",), ("track",), ("vecto", "cycle"), ("vecto", "job"),
    ("ingest", "city"), ("ingest", "gtfs"), ("ingest", "cams"),
}


def leaf_parsers(parser, path=()):
    """(path of subcommand names, parser) of every subcommand that has no subcommands."""
    subs = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    if not subs:
        yield path, parser
    for action in subs:
        for name, child in action.choices.items():
            yield from leaf_parsers(child, path + (name,))


def config_option(parser):
    found = [a for a in parser._actions if "--config" in a.option_strings]
    return found[0] if found else None


def test_one_config_option_for_every_scenario_reader():
    leaves = dict(leaf_parsers(build_parser()))
    with_config = {path for path, p in leaves.items() if config_option(p) is not None}
    assert with_config == READS_SCENARIO
    options = [config_option(leaves[path]) for path in sorted(READS_SCENARIO)]
    assert {tuple(o.option_strings) for o in options} == {("--config", "-c")}
    # one help text: only the default differs (simulate runs the demo by default)
    helps = {o.help.split("; default:")[0] for o in options}
    assert helps == {"scenario: a YAML file, or the name of a shipped scenario "
                     "(demo, luxembourg, paper)"}
    assert {o.default for o in options} == {None, "demo"}
    assert config_option(leaves[("simulate",)]).default == "demo"


def test_no_command_module_imports_the_cli():
    for path in sorted(COMMANDS_DIR.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                target = "." * node.level + (node.module or "")
                assert target not in ("..cli", "vipvflow.cli"), f"{path.name} imports {target}"
    # in a fresh interpreter: the ingest command (which registers subcommands) loads without cli
    code = ("import sys, argparse, vipvflow.commands.ingest as m; "
            "m.register(argparse.ArgumentParser().add_subparsers()); "
            "print('vipvflow.cli' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


def test_config_names_and_paths_resolve_alike(capsys):
    assert main(["config", "--config", "paper"]) == 0
    by_name = capsys.readouterr().out
    assert main(["config", "-c", str(CONF_DIR / "paper.yaml")]) == 0
    by_path = capsys.readouterr().out
    assert by_name == by_path
    assert "scenario: paper" in by_name


@pytest.mark.parametrize("argv", [
    ["config", "--config", "nosuch"],
    ["economics", "-c", "nosuch", "--yield-kwh-per-kwp", "1000"],
    ["ingest", "gtfs", "feed.zip", "--data-dir", "d", "-c", "nosuch"],
    ["vecto", "job", "--out", "j", "-c", "nosuch"],
])
def test_unknown_scenario_is_one_line(argv, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith(f"vipvflow {argv[0]}: error: nosuch: file not found")
    assert "demo, luxembourg, paper" in err
    assert list(tmp_path.iterdir()) == []


def all_parsers(parser, path=("vipvflow",)):
    """(path, parser) of the command and every subcommand, at any depth."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                yield from all_parsers(child, path + (name,))


def test_every_option_and_subcommand_has_help_text():
    missing = []
    for path, parser in all_parsers(build_parser()):
        for action in parser._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            if isinstance(action, argparse._SubParsersAction):
                helps = {c.dest: c.help for c in action._choices_actions}
                missing += [" ".join(path + (name,)) for name in action.choices if not helps.get(name)]
            elif not action.help or action.help == argparse.SUPPRESS:
                missing.append(f"{' '.join(path)} {'/'.join(action.option_strings) or action.dest}")
    assert not missing, missing


def test_db_help_states_the_servers_authentication():
    """``vipvflow db --help`` says what the server it starts really does: each pg_hba method
    of :data:`vipvflow.db.server.HBA` (password on TCP, trust on the private socket), the
    password file and where the server listens."""
    from vipvflow.db import server

    text = subprocess.run([sys.executable, "-m", "vipvflow.cli", "db", "--help"], capture_output=True,
                          text=True, check=True).stdout
    flat = " ".join(text.split())
    methods = {line.split()[-1] for line in server.HBA.splitlines() if line and not line.startswith("#")}
    assert methods == {"trust", "scram-sha-256"}
    assert "scram-sha-256" in flat and f"DIR/{server.PASSFILE}" in flat and "127.0.0.1 only" in flat
    assert "socket" in flat and "trusts the server's own user" in flat
    assert "trust authentication" not in flat


def _one_line_error(args):
    res = subprocess.run([sys.executable, "-m", "vipvflow.cli", *args], capture_output=True,
                         text=True, timeout=120)
    assert res.returncode == 2 and res.stdout == "", (res.stdout, res.stderr)
    lines = res.stderr.splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    return lines[0]


def test_app_on_a_busy_port_says_so_in_one_line_with_a_free_port(tmp_path):
    import re
    import socket

    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        line = _one_line_error(["app", str(tmp_path), "--port", str(port)])
        assert f"port {port} on 127.0.0.1 is in use" in line
        other = int(re.search(r"try --port (\d+)", line).group(1))
        with socket.socket() as s:
            s.bind(("127.0.0.1", other))          # the suggested port is free
    for bad in ("70000", "0", "http"):
        line = _one_line_error(["app", str(tmp_path), "--port", bad])
        assert line.startswith("vipvflow app: error: argument --port:") and "try 5006" in line
    line = _one_line_error(["app", str(tmp_path), "--host", "no-such-host.invalid"])
    assert "--host no-such-host.invalid: not an address of this machine" in line
    # a usage error of any command is one line too, naming the help
    line = _one_line_error(["simulate"])
    assert line == "vipvflow simulate: error: the following arguments are required: --year (see vipvflow simulate --help)"


def test_simulate_dashboard_port_option():
    from vipvflow.commands.simulate import scenario

    parser = build_parser()
    assert scenario(parser.parse_args(["simulate", "--year", "2024"])).dask.dashboard_port == 8787
    args = parser.parse_args(["simulate", "--year", "2024", "--dashboard-port", "8799"])
    assert scenario(args).dask.dashboard_port == 8799
    assert scenario(parser.parse_args(["simulate", "--year", "2024", "--dashboard-port", "0"])
                    ).dask.dashboard_port is None                 # any free port
    line = _one_line_error(["simulate", "--year", "2024", "--dashboard-port", "99999"])
    assert "--dashboard-port: '99999' is not a port number (0..65535): try 8787" in line
