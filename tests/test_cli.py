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
