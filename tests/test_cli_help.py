"""The command line's help: every option has a text and shows its default, every command a
description and an example; `--version`; the scene's pushers in `--pusher`'s help and errors."""

from __future__ import annotations

import argparse
import contextlib
import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

import regrasp
from regrasp.cli import build_parser

from .conftest import run_cli as run

ROOT = Path(__file__).resolve().parents[1]
T_SHAPE = ROOT / "examples" / "t-shape.toml"
PIVOT = ROOT / "examples" / "pivot-3d.toml"


def commands() -> dict[str, argparse.ArgumentParser]:
    ap = build_parser()
    (sub,) = [a for a in ap._actions if isinstance(a, argparse._SubParsersAction)]
    return {"": ap, **sub.choices}




def flat(text: str) -> str:
    """Help text with its line breaks (and the hyphens argparse breaks words at) undone."""
    return re.sub(r"\s+", " ", re.sub(r"-\n\s+", "-", text))


CMDS = commands()


@pytest.mark.parametrize("name", sorted(CMDS))
def test_every_option_has_help_and_shows_its_default(name):
    p = CMDS[name]
    fmt = p._get_formatter()
    for action in p._actions:
        if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
            continue
        where = f"regrasp {name} {'/'.join(action.option_strings) or action.dest}"
        assert action.help and action.help.strip(), f"{where}: no help text"
        text = fmt._expand_help(action) if action.option_strings else action.help
        d = action.default
        if action.option_strings and d not in (None, False, argparse.SUPPRESS):
            assert f"default: {d}" in text, f"{where}: help {text!r} does not show default {d!r}"
        if action.option_strings and action.nargs != 0 and not action.required:
            assert "default" in text, f"{where}: help {text!r} does not say what applies when it is not given"


@pytest.mark.parametrize("name", sorted(set(CMDS) - {""}))
def test_every_command_has_a_description_an_example_and_help_that_exits_0(name):
    p = CMDS[name]
    assert p.description and len(p.description.splitlines()) == 1, f"regrasp {name}: no one-line description"
    assert p.epilog and f"regrasp {name}" in p.epilog, f"regrasp {name}: no example in the epilog"
    status, out, err = run(name, "--help")
    assert status == 0, err
    assert "example:" in out and p.description in flat(out)
    # the defaults stated once, in the Rust settings, reach the help
    if name == "plan":
        assert f"(default: {regrasp.planner_defaults(2)['time_limit']})" in flat(out)


def test_the_defaults_come_from_the_core_settings():
    from regrasp import _core

    helps = {a.dest: a.help for a in CMDS["control"]._actions}
    assert f"(default: {_core.mpc_defaults()['horizon']})" in helps["horizon"]
    assert f"(default: {_core.mpc_defaults()['dt']})" in helps["dt"]


def test_the_defaults_come_from_the_api():
    """Each option's default is the one of the function the command calls (stated there once)."""
    import inspect

    from regrasp import _core, bench
    from regrasp.reference.approx_error import approximation_report
    from regrasp.sim import quasistatic
    from regrasp.mujoco.validation import validate

    def api(fn, name):
        return inspect.signature(fn).parameters[name].default

    def default(cmd, dest):
        return next(a for a in CMDS[cmd]._actions if a.dest == dest).default

    assert default("validate", "pushes") == api(validate, "pushes")
    assert default("validate", "seed") == api(validate, "seed")
    # push --dt: min(DT, --duration), in the CLI as in the API
    assert default("push", "dt") is None and api(quasistatic.simulate_push, "dt") is None
    assert f"(default: min({quasistatic.DT}, --duration))" in next(a.help for a in CMDS["push"]._actions if a.dest == "dt")
    assert [float(f) for f in default("approx-error", "forces").split(",")] == list(api(approximation_report, "forces"))
    assert default("approx-error", "samples") == api(approximation_report, "samples")
    assert default("control", "seed") == _core.mpc_defaults()["seed"]
    helps = {a.dest: a.help for a in CMDS["bench"]._actions}
    assert f"(default: {bench.CONES:,})" in helps["n"] and f"{bench.QUICK['n']:,} cones" in helps["quick"]


@pytest.mark.parametrize("name", sorted(CMDS))
def test_the_examples_work_from_any_folder(name):
    """The epilogs name no file of the repository (absent after pip install): a scene file they
    use is a bundled example, and they say how to copy it here."""
    epilog = CMDS[name].epilog
    assert "examples/" not in epilog, epilog
    for scene in set(re.findall(r"(?<![\w/.-])([\w-]+)\.toml\b", epilog)) - {"NAME"}:
        assert scene in regrasp.examples.names(), (scene, epilog)
        assert re.search(rf"regrasp examples ({scene}|NAME) --copy", epilog), epilog


def test_version_prints_the_package_and_core_versions():
    status, out, _ = run("--version")
    assert status == 0
    assert re.fullmatch(rf"regrasp {re.escape(regrasp.__version__)} \(core \S+: \S+, \S+; \w+ \d+\.\d+\)\n", out), out
    r = subprocess.run([sys.executable, "-m", "regrasp.cli", "--version"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0 and r.stdout == out


@pytest.mark.parametrize("cmd", ["cone", "push"])
def test_the_pusher_help_lists_the_pushers_of_a_scene_given_before_help(cmd):
    status, out, _ = run(cmd, str(T_SHAPE), "--help")
    assert status == 0
    names = regrasp.load_scene(T_SHAPE).pusher_names
    assert f"pushers of {T_SHAPE}: {', '.join(names)}" in flat(out)
    status, out, _ = run(cmd, "--help")  # no scene: it says how to see them
    assert status == 0 and "lists the scene's pushers" in flat(out) and "pushers of" not in flat(out)


def test_an_unknown_pusher_is_invalid_input_listing_the_scene_pushers(tmp_path):
    cases = [("cone", T_SHAPE, ["--pose", "0,0,0"]),
             ("push", T_SHAPE, ["--pose", "0,0,0", "--twist", "0,-0.01,0"]),
             ("push", PIVOT, ["--pose", "0,0,0,1,0,0,0", "--twist", "0,0,0,0,0,0"])]
    for cmd, scene, rest in cases:
        status, out, err = run(cmd, str(scene), "--pusher", "nope", *rest)
        names = regrasp.load_scene(scene).pusher_names
        assert status == 2, (cmd, scene, err)
        assert "`--pusher`" in err and ", ".join(names) in err, err
        assert "Traceback" not in err and out == ""


def test_a_plan_with_an_unknown_pusher_is_invalid_input_listing_the_scene_pushers(tmp_path):
    status, _, err = run("plan", T_SHAPE, "--out", tmp_path / "p.json", "--seed", "0")
    assert status == 0, err
    plan = json.loads((tmp_path / "p.json").read_text())
    plan["path"][1]["pusher"] = "nope"
    (tmp_path / "p.json").write_text(json.dumps(plan))
    status, _, err = run("simulate", T_SHAPE, "--plan", tmp_path / "p.json")
    names = regrasp.load_scene(T_SHAPE).pusher_names
    assert status == 2 and "pusher" in err and ", ".join(names) in err, err


@pytest.mark.parametrize("name", sorted(CMDS))
def test_one_help_style_defaults_with_a_colon_and_required_options_flagged(name):
    """Every help says ``(default: X)``, never ``(default X)``; a required option says
    ``(required)``, an optional one does not."""
    status, out, err = run(*([name] if name else []), "--help")
    assert status == 0, err
    text = flat(out)
    assert not re.search(r"\(default(?!:)", text), f"regrasp {name}: {text}"
    for action in CMDS[name]._actions:
        if not action.option_strings or isinstance(action, argparse._HelpAction):
            continue
        shown = flat(CMDS[name]._get_formatter()._get_help_string(action))
        assert ("(required)" in shown) == bool(action.required), (name, action.option_strings, shown)


def test_the_pusher_help_names_its_command():
    for cmd in ("cone", "push"):
        status, out, _ = run(cmd, "--help")
        assert status == 0 and f"`regrasp {cmd} SCENE --help` lists the scene's pushers" in flat(out), out
        assert "regrasp COMMAND SCENE" not in flat(out)


def test_bare_regrasp_names_command_and_lists_the_commands():
    status, out, err = run()
    assert status == 2 and out == ""
    assert "COMMAND" in err and "cmd" not in err.replace("COMMAND", ""), err
    assert all(name in err for name in set(CMDS) - {""}), err
    assert "COMMAND" in CMDS[""].format_usage()


def test_the_noise_help_says_the_units_the_code_uses():
    """--noise: SIGMA [m] in x and z, SIGMA/L [rad] in theta (regrasp.control.loop measures so),
    in the help and in docs/cli.md."""
    helps = {a.dest: flat(a.help) for a in CMDS["control"]._actions}
    assert "[m]" in helps["noise"] and "/L [rad]" in helps["noise"], helps["noise"]
    doc = (ROOT / "docs" / "cli.md").read_text()
    row = next(line for line in doc.splitlines() if line.startswith("| `--noise"))
    assert "[m] in x and z" in row and "/L [rad]" in row, row


def test_the_control_example_succeeds_on_the_bundled_scene_with_its_own_plan(tmp_path):
    """The command line in `regrasp control --help` runs end to end (exit 0) on the bundled
    t-shape with the plan `regrasp plan` writes for it."""
    (line,) = [ln.strip() for ln in CMDS["control"].epilog.splitlines() if ln.strip().startswith("regrasp control")]
    argv = line.split()[1:]
    plan = argv[argv.index("--plan") + 1]
    assert run("examples", "t-shape", "--copy", tmp_path)[0] == 0
    with contextlib.chdir(tmp_path):
        status, _, err = run("plan", "t-shape.toml", "--out", plan)
        assert status == 0, err
        status, out, err = run(*argv)
    assert status == 0, (line, out, err)
    assert "success" in out


@pytest.mark.parametrize("name, hint", [("t-shape.toml", "`regrasp examples t-shape --copy .` writes it here"),
                                        ("nothing-like-it.toml", "`regrasp examples` lists the bundled scenes")])
def test_a_missing_scene_names_the_argument_and_says_how_to_get_one(tmp_path, name, hint):
    with contextlib.chdir(tmp_path):
        status, out, err = run("plan", name)
    assert status == 2 and out == ""
    assert "invalid `scene`" in err and "`path`" not in err and hint in err, err
    status, _, err = run("approx-error", tmp_path / "examples" / "t-shape.toml")
    assert status == 2 and "invalid `scene`" in err and "t-shape --copy ." in err, err
