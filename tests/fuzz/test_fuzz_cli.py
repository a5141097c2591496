"""Fuzz: the `regrasp` command with bad invocations (bad numbers and vectors, missing files,
folders as files, unwritable outputs, plan files that are not JSON objects, unknown pushers,
conflicting flags). In-process through ``regrasp.cli.main`` for most cases, a few through a
real process. Every run: exit 0, 1 or 2 and no traceback; input that is certainly invalid
exits 2 with the option named on stderr; a failed run leaves an existing output untouched; no
NaN/inf in printed JSON."""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

import regrasp
from regrasp import cli

from . import harness
from .harness import fuzz_settings, non_finite, run
from .strategies import EXAMPLES

ROOT = Path(__file__).resolve().parents[2]
SENTINEL = "an existing output, not to be lost\n"

#: valid invocations; {scene} {scene3} {plan} {plan3} {out} are filled per case
TEMPLATES = {
    "cone": ["cone", "{scene}", "--pose", "0,0,0", "--pusher", "left", "--twist", "0.01,0,0", "--json"],
    "plan": ["plan", "{scene}", "--time-limit", "0.2", "--seed", "0", "--out", "{out}", "--json"],
    "plan3": ["plan", "{scene3}", "--time-limit", "0.5", "--seed", "0", "--out", "{out}"],
    "push": ["push", "{scene}", "--pose", "0,0,0", "--pusher", "bottom", "--twist", "0,0.01,0", "--duration", "0.1",
             "--dt", "0.05", "--json"],
    "push3": ["push", "{scene3}", "--pose", "0,0,0,1,0,0,0", "--pusher", "ground", "--twist", "0,0,0.001,0,0,0",
              "--duration", "0.1", "--dt", "0.05", "--json"],
    "validate": ["validate", "{scene}", "--pushes", "5", "--seed", "0", "--json"],
    "simulate": ["simulate", "{scene}", "--plan", "{plan}", "--json"],
    "approx": ["approx-error", "{scene}", "--samples", "50", "--forces", "5,20", "--json"],
}

POSITIVE = ["nan", "inf", "-inf", "-1", "0", "abc", "", "1,2", "-0", "0x1p3"]
VEC = ["nan,0,0", "0,0", "0,0,0,0", "a,b,c", "", ",,", "inf,0,0", "0,0,-inf", "1e999,0,0"]
VEC7 = ["nan,0,0,1,0,0,0", "0,0,0", "0,0,0,0,0,0,0", "0,0,0,1,0,0", "a,0,0,1,0,0,0", ""]
VEC6 = ["nan,0,0,0,0,0", "0,0,0", "0,0,0,0,0,0,0", "inf,0,0,0,0,0"]
COUNT = ["-1", "0", "1.5", "abc", "", "nan", "100000000000000000000000"]
NAMES = ["nope", "", " ", "LEFT"]

#: option -> (bad values that must be rejected, values that may be valid, name to find on stderr)
OPTIONS = {
    "--pose": (VEC, ["1e300,0,0", "1,1,1"], "pose"),
    "--twist": (VEC, ["1e300,0,0", "0,0,0"], "twist"),
    "--pusher": (NAMES, [], "pusher"),
    "--duration": (POSITIVE, ["1e300", "1e-300"], "duration"),
    "--dt": (POSITIVE, ["1e300", "1e-300"], "dt"),
    "--time-limit": (["nan", "-1", "abc", "", "-inf"], ["0", "1e-300", "inf"], "time-limit"),
    "--seed": (["-1", "1.5", "abc", "", "nan", str(2**64)], [str(2**64 - 1)], "seed"),
    "--pushes": (COUNT, ["100000000"], "pushes"),
    "--samples": (COUNT, [], "samples"),
    "--forces": (["nan", "-5", "0", "a", "", "5,,20", "inf"], ["1e300"], "forces"),
}


def _files(base: Path) -> dict:
    """The inputs of one case, as copies in a fresh folder (a run may not harm the examples)."""
    scene = base / "scene.toml"
    shutil.copy(EXAMPLES / "block-low-friction.toml", scene)
    scene3 = base / "scene3.toml"
    shutil.copy(EXAMPLES / "pivot-3d.toml", scene3)
    plan = base / "plan.json"
    plan.write_text(json.dumps(PLAN2))
    out = base / "out.json"
    out.write_text(SENTINEL)
    return {"scene": str(scene), "scene3": str(scene3), "plan": str(plan), "out": str(out), "base": str(base)}


PLAN2 = regrasp.plan(regrasp.load_scene(EXAMPLES / "block-low-friction.toml"), seed=0, time_limit=1.0).to_json()


def fill(argv: list, files: dict) -> list:
    return [a.format(**files) for a in argv]


def run_main(argv: list) -> tuple[int, str, str]:
    """``regrasp argv`` in this process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = cli.main(argv)
        except SystemExit as e:  # argparse: usage errors exit 2
            status = e.code if isinstance(e.code, int) else 2
    return status, out.getvalue(), err.getvalue()


def judge(family: str, argv: list, result, must: str | None, out_path: str | None, outputs=()) -> None:
    """Exit status, message and outputs of one run (``must``: the option that is certainly bad;
    ``outputs``: files the run may write, each checked for NaN/inf when written)."""
    what = "regrasp " + " ".join(argv)
    if result is None:  # an exception escaped main: already recorded by run()
        return
    status, out, err = result
    if "Traceback" in err or "Traceback" in out:
        harness.RECORDER.fail("traceback", family, what, err)
    if "internal error" in err:
        harness.RECORDER.fail("internal", family, what, err)
    if status not in (0, 1, 2):
        harness.RECORDER.fail("exit_status", family, what, f"exit {status}\n{err}")
    if must is not None:
        if status != 2:
            harness.RECORDER.fail("accepted", family, what, f"exit {status} for a bad {must}\n{err}")
        elif must not in err:
            harness.RECORDER.fail("wrong_field", family, what, f"stderr does not name {must}:\n{err}")
    if status == 2 and not err.strip():
        harness.RECORDER.fail("no_field", family, what, "exit 2 with nothing on stderr")
    if status != 0 and out_path and Path(out_path).read_text() != SENTINEL:
        harness.RECORDER.fail("clobbered", family, what, f"exit {status} but {out_path} was replaced")
    if "--json" in argv and out.strip():  # whatever the status: a JSON answer has no NaN
        bad = text_non_finite(out, json_text=status == 0)
        if bad:
            harness.RECORDER.fail("nan", family, what, f"printed JSON: {bad}")
    for f in [out_path, *outputs]:
        if f and Path(f).is_file() and Path(f).stat().st_size and Path(f).read_text(errors="replace") != SENTINEL:
            bad = text_non_finite(Path(f).read_text(errors="replace"), json_text=f.endswith(".json"))
            if bad:
                harness.RECORDER.fail("nan", family, what, f"{f}: {bad}")


_NON_FINITE = re.compile(r"\b(NaN|-?Infinity|nan|-?inf)\b")


def text_non_finite(text: str, json_text: bool) -> str | None:
    """Where an output holds NaN or inf: its JSON's path (``json_text``: it must be JSON), else
    the first NaN/Infinity token in the text."""
    if json_text:
        try:
            return non_finite(json.loads(text))
        except json.JSONDecodeError as e:
            return f"not JSON: {e}"
    m = _NON_FINITE.search(text)
    return None if m is None else f"{m.group(0)!r} at {m.start()}: {text[max(0, m.start() - 60):m.end() + 20]!r}"


@st.composite
def bad_invocation(draw):
    """(template name, argv with one option replaced, the option when it is certainly bad)."""
    name = draw(st.sampled_from(sorted(n for n, t in TEMPLATES.items() if any(a in OPTIONS for a in t))))
    argv = list(TEMPLATES[name])
    opts = [i for i, a in enumerate(argv) if a in OPTIONS]
    i = draw(st.sampled_from(opts))
    must_values, maybe_values, shown = OPTIONS[argv[i]]
    if argv[i] == "--pose" and name.endswith("3"):
        must_values, maybe_values = VEC7, []
    if argv[i] == "--twist" and name.endswith("3"):
        must_values, maybe_values = VEC6, []
    value = draw(st.one_of(st.sampled_from(must_values + maybe_values),
                           st.lists(st.floats(), min_size=1, max_size=8).map(lambda v: ",".join(map(str, v)))))
    argv[i + 1] = value
    argv[i] = f"{argv[i]}={value}"  # values starting with '-' need the = form
    del argv[i + 1]
    return name, argv, shown if value in must_values else None


@fuzz_settings(100, 1500)
@given(case=bad_invocation())
def test_bad_option_value(case, tmp_path_factory):
    name, argv, must = case
    files = _files(tmp_path_factory.mktemp("cli"))
    argv = fill(argv, files)
    r = run(f"cli.{name}", "regrasp " + " ".join(argv), lambda: run_main(argv))
    judge(f"cli.{name}", argv, r, must, files["out"] if "{out}" in " ".join(TEMPLATES[name]) else None)


#: files that are not what an option wants: (description, how to make it in a folder)
def _bad_files(base: Path) -> dict:
    d = {}
    for text, label in (("[]", "json-list"), ("1", "json-number"), ('"x"', "json-string"), ("null", "json-null"),
                        ("{", "bad-json"), ("{}", "json-empty-object"), ('{"path": 1}', "json-path-number"),
                        ("", "empty"), ("\xff\xfe", "binary")):
        p = base / f"{label}.json"
        p.write_text(text, errors="surrogateescape") if label != "binary" else p.write_bytes(b"\xff\xfe\x00")
        d[label] = str(p)
    d["missing"] = str(base / "missing.json")
    d["folder"] = str(base)
    d["toml-as-plan"] = str(EXAMPLES / "t-shape.toml")
    return d


FILE_CASES = [  # (argv with {bad}, the option named on stderr)
    (["simulate", "{scene}", "--plan", "{bad}"], "plan"),
    (["control", "{scene}", "--plan", "{bad}", "--json"], "plan"),
    (["cone", "{bad}", "--pose", "0,0,0", "--pusher", "left"], None),
    (["plan", "{bad}", "--time-limit", "0.1"], None),
]


@fuzz_settings(40, 400)
@given(case=st.sampled_from(FILE_CASES), which=st.sampled_from(
    ["json-list", "json-number", "json-string", "json-null", "bad-json", "json-empty-object", "json-path-number",
     "empty", "binary", "missing", "folder", "toml-as-plan"]))
def test_bad_input_file(case, which, tmp_path_factory):
    argv, shown = case
    base = tmp_path_factory.mktemp("cli")
    files = _files(base) | {"bad": _bad_files(base)[which]}
    argv = fill(argv, files)
    r = run("cli.input-file", "regrasp " + " ".join(argv), lambda: run_main(argv))
    judge("cli.input-file", argv, r, shown if which != "toml-as-plan" or shown else None, None)


OUTPUT_CASES = [
    ["plan", "{scene}", "--time-limit", "0.2", "--out", "{o}"],
    ["plan", "{scene}", "--time-limit", "0.2", "--plot", "{o}"],
    ["plan", "{scene}", "--time-limit", "0.2", "--out", "{out}", "--plot", "{o}"],
    ["plan", "{scene3}", "--time-limit", "0.5", "--html", "{o}"],
    ["cone", "{scene}", "--pose", "0,0,0", "--pusher", "left", "--plot", "{o}"],
]
#: output paths that cannot be written (a missing folder may be made: the CLI's choice, not an error)
BAD_OUTPUTS = {"missing-folder": "{base}/missing/x.out", "folder": "{base}", "proc": "/proc/regrasp-fuzz/x",
               "scene-itself": "{self}", "empty": ""}
MAY_WORK = ("missing-folder", "scene-itself")


@fuzz_settings(25, 300)
@given(argv=st.sampled_from(OUTPUT_CASES), which=st.sampled_from(sorted(BAD_OUTPUTS)))
def test_unwritable_output(argv, which, tmp_path_factory):
    files = _files(tmp_path_factory.mktemp("cli"))
    scene_before = {k: Path(files[k]).read_bytes() for k in ("scene", "scene3")}
    bad = BAD_OUTPUTS[which].replace("{self}", argv[1])  # the command's own scene file
    argv = [a.replace("{o}", bad) for a in argv]
    argv = fill(argv, files)
    what = "regrasp " + " ".join(argv)
    r = run("cli.output", what, lambda: run_main(argv), timeout=30)
    opt = next(a for a in argv if a in ("--out", "--plot", "--html") and argv[argv.index(a) + 1] != files["out"])
    judge("cli.output", argv, r, None if which in MAY_WORK and (which != "scene-itself" or opt != "--out") else opt.lstrip("-"),
          files["out"] if files["out"] in argv else None)
    for k, before in scene_before.items():
        if Path(files[k]).read_bytes() != before:
            harness.RECORDER.fail("clobbered", "cli.output", what, f"the input {files[k]} was overwritten")


CONFLICTS = [
    ["plan", "{scene}", "--robust", "--fixtureless", "--time-limit", "0.1"],
    ["plan", "{scene3}", "--robust", "--time-limit", "0.1"],
    ["bench", "--quick", "-n", "5"],  # -n has no effect with --quick: refused (plan --html now views planar plans)
    ["plan", "{scene}", "--start", "0,0,0", "--time-limit", "0.1", "--propagation", "nope"],
    ["plan", "{scene}", "--uncertainty", "0.1,0.1,0.1,1.5", "--time-limit", "0.1"],
    ["cone", "{scene3}", "--pose", "0,0,0", "--pusher", "ground"],
    ["push", "{scene3}", "--pose", "0,0,0", "--pusher", "ground", "--twist", "0,0,0"],
    ["push", "{scene3}", "--pose", "0,0,0,1,0,0,0", "--pusher", "ground", "--twist", "0,0,0,0,0,0", "--duration", "0"],
    ["push", "{scene}", "--pose", "0,0,0", "--pusher", "bottom", "--twist", "1e6,1e6,1e6", "--duration", "0.1"],
    ["simulate", "{scene3}", "--plan", "{plan}"],
    ["validate", "{scene}", "--pushes", "100000000", "--engines", "nope"],
    ["validate", "{scene3}", "--pushes", "5"],
    ["approx-error", "{scene3}", "--samples", "5"],
]


@pytest.mark.parametrize("argv", CONFLICTS, ids=lambda a: " ".join(a)[:60])
def test_conflicting_or_mismatched(argv, tmp_path):
    """Flags that do not go together, or a command for the other dimension: exit 2, no traceback."""
    files = _files(tmp_path)
    argv = fill(argv, files)
    r = run("cli.conflict", "regrasp " + " ".join(argv), lambda: run_main(argv), timeout=30)
    judge("cli.conflict", argv, r, None, None)
    assert r is None or r[0] in (1, 2), r


# --- a few through a real process: what the user sees on stderr -------------------------------

def _regrasp(args: list, timeout: float = 60, shell_tail: str = "") -> subprocess.CompletedProcess:
    cmd = [sys.executable, "-m", "regrasp.cli", *args]
    if shell_tail:
        import shlex

        return subprocess.run(" ".join(map(shlex.quote, cmd)) + shell_tail, shell=True, capture_output=True,
                              text=True, timeout=timeout, cwd=ROOT)
    return subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, cwd=ROOT)


PROCESS_CASES = [
    (["cone", "{scene}", "--pose=nan,0,0", "--pusher", "left"], "", 2),
    (["plan", "{scene}", "--time-limit", "0.2", "--out", "/proc/regrasp-fuzz/plan.json"], "", 2),
    (["plan", "{scene}", "--time-limit", "0.2", "--plot", "/proc/regrasp-fuzz/x.png"], "", 2),
    (["simulate", "{scene}", "--plan", "{bad}"], "", 2),
    (["plan", "{scene}", "--time-limit", "0.2", "--json"], " | head -c 1", None),
    (["validate", "{scene}", "--pushes", "3", "--json"], " | head -c 1", None),
    (["validate", "{scene}", "--pushes", "100000000"], "", None),
]


@pytest.mark.parametrize("argv,tail,status", PROCESS_CASES, ids=lambda a: str(a)[:50])
def test_real_process_no_traceback(argv, tail, status, tmp_path):
    files = _files(tmp_path)
    (tmp_path / "list.json").write_text("[]")
    files["bad"] = str(tmp_path / "list.json")
    argv = fill(argv, files)
    what = "regrasp " + " ".join(argv) + tail
    harness.RECORDER.case("cli.process")
    try:
        p = _regrasp(argv, timeout=60, shell_tail=tail)
    except subprocess.TimeoutExpired:
        harness.RECORDER.fail("hang", "cli.process", what, "ran past 60 s")
        return
    if "Traceback" in p.stderr or "Error" in p.stderr.split(":")[0]:
        harness.RECORDER.fail("traceback", "cli.process", what, p.stderr)
    if status is not None and p.returncode != status:
        harness.RECORDER.fail("exit_status", "cli.process", what, f"exit {p.returncode}, expected {status}\n{p.stderr}")
