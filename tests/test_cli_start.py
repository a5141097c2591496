"""The CLI's start: only the chosen command's group is imported (cli.GROUPS), and the parser built
for one command is the one the full parser has. The speed itself is measured by `regrasp bench`
("CLI start"), not here."""

from __future__ import annotations

import argparse
import importlib
import json
import subprocess
import sys

import pytest

from regrasp import cli

#: modules that a command's start must not import unless it is that command's work
HEAVY = ("mujoco", "matplotlib", "scipy", "casadi", "networkx", "mink", "pydrake", "ray", "toppra",
         "regrasp.execution", "regrasp.bench", "regrasp.dexterity", "regrasp.mujoco", "regrasp.robot")


def _subparsers(ap):
    (sub,) = [a for a in ap._actions if isinstance(a, argparse._SubParsersAction)]
    return sub.choices


def test_groups_name_every_command_in_the_order_of_the_help():
    full = _subparsers(cli.build_parser())
    assert list(full) == list(cli.GROUPS)
    for group in dict.fromkeys(cli.GROUPS.values()):
        ap = argparse.ArgumentParser()
        sub = ap.add_subparsers(parser_class=cli.Parser)
        importlib.import_module(f"regrasp.cli.{group}").add_parsers(sub)
        assert list(sub.choices) == [c for c, g in cli.GROUPS.items() if g == group], group


@pytest.mark.parametrize("cmd", list(cli.GROUPS))
def test_the_parser_of_one_command_is_the_full_parsers(cmd):
    alone = _subparsers(cli.build_parser(cmd))
    assert list(alone) == [c for c, g in cli.GROUPS.items() if g == cli.GROUPS[cmd]]
    assert alone[cmd].format_help() == _subparsers(cli.build_parser())[cmd].format_help()


@pytest.mark.parametrize("argv, cmd", [
    (["plan", "x.toml"], "plan"), (["-q", "-v", "execute", "--help"], "execute"), (["--version"], ""),
    ([], ""), (["-h", "plan"], None), (["bogus"], None), (["-q", "x.toml"], None),
])
def test_the_chosen_command(argv, cmd):
    assert cli.chosen(argv) == cmd


def _imported(*argv: str) -> set:
    code = ("import sys, json\nfrom regrasp.cli import main\n"
            "try:\n    main(%r)\nexcept SystemExit:\n    pass\n"
            "print('MODULES' + json.dumps(sorted(sys.modules)))" % (list(argv),))
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120).stdout
    return set(json.loads(out.split("MODULES")[-1]))


@pytest.mark.parametrize("argv", [("--version",), ("plan", "--help"), ("cone", "--help")])
def test_a_command_imports_its_group_only(argv):
    mods = _imported(*argv)
    groups = {f"regrasp.cli.{g}" for g in cli.GROUPS.values()}
    mine = {f"regrasp.cli.{cli.GROUPS[argv[0]]}"} if argv[0] in cli.GROUPS else set()
    assert groups & mods == mine, sorted(groups & mods)
    heavy = sorted(m for m in mods if m.split(".")[0] in HEAVY or m.startswith(HEAVY[-5:]))
    assert not heavy, heavy


def test_the_help_of_regrasp_imports_every_group():
    mods = _imported("--help")
    assert {f"regrasp.cli.{g}" for g in cli.GROUPS.values()} <= mods


def test_import_regrasp_imports_nothing_heavy():
    code = "import sys, json, regrasp\nprint('MODULES' + json.dumps(sorted(sys.modules)))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120).stdout
    mods = json.loads(out.split("MODULES")[-1])
    heavy = sorted(m for m in mods if m.split(".")[0] in HEAVY or m.startswith(HEAVY[-5:]) or m.startswith("regrasp.cli"))
    assert not heavy, heavy
