"""The user-facing contract of docs/ against the code: scene keys (docs/scene-file.md), plan files
(docs/plan-file.md) and the command line (docs/cli.md).

Only the `regrasp` command and the top-level `regrasp` API are used, so that these tests hold
however the package is laid out inside.
"""

from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import sys
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import pytest

import regrasp

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
EXAMPLES = ROOT / "examples"
SCENE_EXAMPLES = sorted(EXAMPLES.glob("*.toml"))


# --- helpers ---------------------------------------------------------------------------------

def regrasp_command() -> list[str]:
    """The installed `regrasp` console script (the one next to this interpreter first)."""
    exe = Path(sys.executable).with_name("regrasp")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("regrasp")
    if found:
        return [found]
    # the console script's entry point, wherever the package keeps it
    return [sys.executable, "-c", "import sys; from importlib.metadata import entry_points; "
            "sys.exit(next(iter(entry_points(group='console_scripts', name='regrasp'))).load()())"]


def cli(*args, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run(regrasp_command() + [str(a) for a in args], capture_output=True, text=True,
                          timeout=timeout, cwd=ROOT)


def cli_many(arg_lists: list) -> list[subprocess.CompletedProcess]:
    """Several `regrasp` runs at once (each pays the interpreter's start-up)."""
    with ThreadPoolExecutor(max_workers=8) as ex:
        return list(ex.map(lambda a: cli(*a), arg_lists))


def _cells(line: str) -> list[str]:
    inner = line.strip()[1:-1]
    return [c.strip().replace("\\|", "|") for c in re.split(r"(?<!\\)\|", inner)]


def md_tables(path: Path) -> list[tuple[str, list[str], list[list[str]]]]:
    """Every table of a markdown file: (the heading above it, header cells, rows of cells)."""
    lines = path.read_text().splitlines()
    out, heading, i = [], "", 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("#"):
            heading = line.lstrip("#").strip()
        if line.startswith("|") and i + 1 < len(lines) and re.fullmatch(r"\|[-| :]+\|", lines[i + 1].strip()):
            header, rows = _cells(line), []
            i += 2
            while i < len(lines) and lines[i].startswith("|"):
                rows.append(_cells(lines[i]))
                i += 1
            out.append((heading, header, rows))
            continue
        i += 1
    return out


def code_names(cell: str) -> list[str]:
    """The `code` spans of a table cell."""
    return re.findall(r"`([^`]+)`", cell)


def documented(path: Path, first_column: str) -> dict[str, list[str]]:
    """Rows of the tables whose first header cell is ``first_column``, by the key in their first cell."""
    rows = {}
    for _, header, body in md_tables(path):
        if header[0] == first_column:
            for r in body:
                (key,) = code_names(r[0])
                assert key not in rows, f"{path.name}: `{key}` is documented twice"
                rows[key] = r
    assert rows, f"{path.name} has no table headed {first_column!r}"
    return rows


def dotted_keys(d: dict, prefix: str = "") -> set[str]:
    """Every key of a parsed TOML document as a dotted path (`pushers[].name` for an array of tables)."""
    out = set()
    for k, v in d.items():
        key = f"{prefix}{k}"
        out.add(key)
        if isinstance(v, dict):
            out |= dotted_keys(v, key + ".")
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for x in v:
                out |= dotted_keys(x, key + "[].")
    return out


def is_3d(path: Path) -> bool:
    return tomllib.loads(path.read_text()).get("dimension") == 3


PLANAR_KEYS = "planar key"
KEYS_3D = "3-D key"


# --- scene files -----------------------------------------------------------------------------

def test_the_scene_docs_document_both_kinds():
    planar = documented(DOCS / "scene-file.md", PLANAR_KEYS)
    spatial = documented(DOCS / "scene-file.md", KEYS_3D)
    for k in ("name", "object.outline", "grasp.force", "pushers[].points", "task.tolerance", "uncertainty.mass"):
        assert k in planar
    for k in ("dimension", "object.shape", "object.mesh", "object.radius", "pushers[].plane", "task.start"):
        assert k in spatial
    # every row: key | type | unit | default | constraints, none left empty
    for rows in (planar, spatial):
        for key, r in rows.items():
            assert len(r) == 5 and all(r), f"scene-file.md: the row of `{key}` is incomplete: {r}"


@pytest.mark.parametrize("path", SCENE_EXAMPLES, ids=lambda p: p.name)
def test_every_example_uses_only_documented_keys(path):
    keys = dotted_keys(tomllib.loads(path.read_text()))
    docs = documented(DOCS / "scene-file.md", KEYS_3D if is_3d(path) else PLANAR_KEYS)
    undocumented = sorted(keys - set(docs))
    assert not undocumented, f"{path.name} uses keys that docs/scene-file.md does not document: {undocumented}"
    # and it is a valid scene
    (regrasp.Scene3D if is_3d(path) else regrasp.Scene).load(path)


# (example, table header line or None for the top level, dotted prefix of that table's keys)
_SECTIONS = [(None, ""), ("[object]", "object."), ("[grasp]", "grasp."), ("[gravity]", "gravity."),
             ("[[pushers]]", "pushers[]."), ("[task]", "task.")]
TABLES = [(ex, h, p) for ex in ("block-low-friction.toml", "offset-3d.toml") for h, p in _SECTIONS] + [
    ("block-on-incline.toml", "[surface]", "surface."),
    ("block-fixtureless.toml", "[uncertainty]", "uncertainty."),
]


def _accepted_keys(example: str, header: str | None) -> set[str]:
    """The keys the loader accepts in one table: an unknown key's error lists them."""
    path = EXAMPLES / example
    text = path.read_text()
    bad = "zz_not_a_key = 1"
    if header is None:
        text = bad + "\n" + text
    else:
        pat = re.compile(r"^" + re.escape(header) + r"[^\n]*$", re.M)
        assert pat.search(text), f"{example} has no {header}"
        text = pat.sub(lambda m: m.group(0) + "\n" + bad, text, count=1)
    with pytest.raises(regrasp.SceneError) as e:
        if is_3d(path):
            regrasp.Scene3D.from_toml(text, EXAMPLES)
        else:
            regrasp.Scene.from_toml(text)
    msg = str(e.value)
    assert "zz_not_a_key" in msg and "expected" in msg, msg
    return set(re.findall(r"`(\w+)`", msg.split("expected", 1)[1]))


@pytest.mark.parametrize("example,header,prefix", TABLES, ids=lambda x: str(x))
def test_the_loaders_accept_exactly_the_documented_keys(example, header, prefix):
    docs = documented(DOCS / "scene-file.md", KEYS_3D if is_3d(EXAMPLES / example) else PLANAR_KEYS)
    in_table = {k[len(prefix):] for k in docs if k.startswith(prefix) and "." not in k[len(prefix):]
                and "[]" not in k[len(prefix):]}
    accepted = _accepted_keys(example, header)
    kind = "3-D" if is_3d(EXAMPLES / example) else "planar"
    assert accepted == in_table, (
        f"{header or 'top level'} of a {kind} scene: accepted but undocumented {sorted(accepted - in_table)}, "
        f"documented but rejected {sorted(in_table - accepted)}")


def test_an_unknown_key_is_an_error_that_names_it_and_the_cli_exits_2(tmp_path):
    text = (EXAMPLES / "block-low-friction.toml").read_text().replace("pad_radius", "pad_radus")
    bad = tmp_path / "typo.toml"
    bad.write_text(text)
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.Scene.load(bad)
    assert "pad_radus" in str(e.value) and e.value.field is not None
    missing = tmp_path / "missing.toml"
    missing.write_text((EXAMPLES / "offset-3d.toml").read_text().replace("mass = 0.130", ""))
    with pytest.raises(regrasp.SceneError) as e:
        regrasp.Scene3D.load(missing)
    assert e.value.field == "object.mass"
    r1, r2 = cli_many([["plan", bad], ["plan", missing]])
    assert r1.returncode == 2 and "pad_radus" in r1.stderr, r1.stderr
    assert r2.returncode == 2 and "object.mass" in r2.stderr, r2.stderr


# --- plan files ------------------------------------------------------------------------------

_SCALAR_TYPES = {
    "str": lambda v: isinstance(v, str),
    "bool": lambda v: isinstance(v, bool),
    "int": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "float": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v),
    "str|null": lambda v: v is None or isinstance(v, str),
    "object[]": lambda v: isinstance(v, list) and all(isinstance(x, dict) for x in v),
}


def _type_ok(v, t: str) -> bool:
    """Whether ``v`` has the JSON type ``t`` written in docs/plan-file.md (written out here, not
    taken from the package, so that the check is independent of the code it checks)."""
    if t in _SCALAR_TYPES:
        return _SCALAR_TYPES[t](v)
    m = re.fullmatch(r"float\[(\d*)\]", t)
    if m:
        return isinstance(v, list) and (m[1] == "" or len(v) == int(m[1])) and all(_type_ok(x, "float") for x in v)
    raise AssertionError(f"docs/plan-file.md: unknown type {t!r}")


def _strict_json(text: str):
    def no_constant(c):
        raise AssertionError(f"the plan file holds {c}, which is not JSON")

    return json.loads(text, parse_constant=no_constant)


def check_plan(plan: dict, header: str) -> None:
    """``plan`` has exactly the keys of the table headed ``header``, with their types."""
    rows = documented(DOCS / "plan-file.md", header)
    spec = {k: (code_names(r[1])[0], r[2]) for k, r in rows.items()}
    assert all(p in ("always", "steps", "unreachable", "found") for _, p in spec.values())
    unreachable = plan.get("stop_reason") == "unreachable"  # a `reason` only then
    present = {"unreachable": unreachable, "found": plan.get("found") is True}  # `first_*` only with a plan
    top = {k for k, (_, p) in spec.items() if "[]." not in k and present.get(p, True)}
    entry = {k.split("[].", 1)[1]: v for k, v in spec.items() if k.startswith("path[].")}
    assert set(plan) == top, f"keys: written but undocumented {sorted(set(plan) - top)}, " \
                             f"documented but not written {sorted(top - set(plan))}"
    for k in top:
        assert _type_ok(plan[k], spec[k][0]), f"`{k}` = {plan[k]!r} is not {spec[k][0]}"
    assert len(plan["path"]) >= 1
    for i, step in enumerate(plan["path"]):
        want = {k for k, (_, present) in entry.items() if present == "always" or i > 0}
        assert set(step) == want, f"path[{i}] has keys {sorted(step)}, documented {sorted(want)}"
        for k in step:
            assert _type_ok(step[k], entry[k][0]), f"path[{i}].{k} = {step[k]!r} is not {entry[k][0]}"
        assert (step["pusher"] is None) == (i == 0), f"path[{i}].pusher = {step['pusher']!r}"
    assert plan["stop_reason"] in ("goal_reached", "time_limit", "node_limit", "iteration_limit", "unreachable")
    assert plan["found"] == (plan["stop_reason"] == "goal_reached")


@pytest.fixture(scope="module")
def written_plans(tmp_path_factory):
    """Plans written by `regrasp plan --out`: planar and 3-D found, planar not found."""
    d = tmp_path_factory.mktemp("plans")
    text = (EXAMPLES / "block-low-friction.toml").read_text()
    parts = text.split("[[pushers]]")
    top = [p for p in parts[1:] if 'name = "top"' in p][0]
    (d / "top-only.toml").write_text(parts[0] + "[[pushers]]" + top)  # can only push down; the goal is up
    (d / "weak.toml").write_text(text.replace("force = 20.0", "force = 3.6"))  # holds the task, not a pad far off
    # the 3-D block at 2 N: it holds at the start, not 18 mm off its centre of mass
    weak3 = (EXAMPLES / "block-3d.toml").read_text().replace("force = 20.0", "force = 2.0")
    (d / "weak-3d.toml").write_text(re.sub(r"(?m)^goal = .*$", "goal = [0.018, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]", weak3))
    runs = cli_many([
        ["plan", EXAMPLES / "t-shape.toml", "--out", d / "planar.json", "--time-limit", "5"],
        ["plan", EXAMPLES / "offset-3d.toml", "--out", d / "3d.json", "--time-limit", "5"],
        ["plan", ROOT / "benches" / "scenes" / "u-shape.toml", "--out", d / "none.json", "--time-limit", "0.002"],
        ["plan", EXAMPLES / "t-shape.toml", "--time-limit", "5", "--json"],
        ["plan", ROOT / "benches" / "scenes" / "neck-unreachable.toml", "--out", d / "unreachable.json"],
        ["plan", d / "weak.toml", "--goal", "0.0175,0,0", "--out", d / "cannot-hold.json"],
        ["plan", d / "top-only.toml", "--out", d / "one-way.json"],
        ["plan", d / "weak-3d.toml", "--out", d / "cannot-hold-3d.json"],
    ])
    return d, runs


def _written(written_plans, k: int, file: str, kind: str, scene: str) -> dict:
    """Plan file `file` written by run `k`: it succeeded, has the documented keys, found a path."""
    d, runs = written_plans
    assert runs[k].returncode == 0, runs[k].stderr
    plan = _strict_json((d / file).read_text())
    check_plan(plan, kind)
    assert plan["found"] and plan["scene"] == scene and len(plan["path"]) >= 2
    return plan


def test_a_planar_plan_file_has_exactly_the_documented_keys(written_plans):
    _, runs = written_plans
    plan = _written(written_plans, 0, "planar.json", "planar plan key", "t-shape")
    assert all(len(k["pose"]) == 3 for k in plan["path"])
    assert len(plan["step_margins"]) == len(plan["path"]) - 1
    assert plan["valid"] == all(m >= -1e-9 for m in plan["step_margins"])
    # --json prints the same object
    assert runs[3].returncode == 0, runs[3].stderr
    check_plan(_strict_json(runs[3].stdout), "planar plan key")


def _not_found(written_plans, k: int, file: str, says: str) -> dict:
    """Plan file `file` written by run `k`, which found no plan: exit 1, `says` on stderr, the documented keys."""
    d, runs = written_plans
    assert runs[k].returncode == 1, runs[k].stdout + runs[k].stderr
    assert says in runs[k].stderr
    plan = _strict_json((d / file).read_text())
    check_plan(plan, "planar plan key")
    assert plan["found"] is False and plan["stop_reason"] != "goal_reached"
    return plan


def test_a_plan_not_found_is_written_with_the_documented_keys_and_exits_1(written_plans):
    plan = _not_found(written_plans, 2, "none.json", "no plan found")
    assert plan["stop_reason"] == "time_limit" and "reason" not in plan


def test_an_unreachable_goal_is_written_with_its_reason_and_exits_1(written_plans):
    # two lobes joined by a neck narrower than the pad: decided before any search
    plan = _not_found(written_plans, 4, "unreachable.json", "no plan found: unreachable: the pad's centre must stay")
    assert plan["stop_reason"] == "unreachable" and "different parts" in plan["reason"]
    assert plan["planning_time_s"] < 1.0 and len(plan["path"]) == 1
    from regrasp.planning.plan import Plan

    assert Plan.from_json(plan).reason == plan["reason"]  # read back


def test_a_goal_the_grasp_cannot_hold_is_unreachable_and_exits_1(written_plans):
    plan = _not_found(written_plans, 5, "cannot-hold.json", "no plan found: unreachable: the grasp cannot hold")
    assert plan["stop_reason"] == "unreachable" and "within the goal's tolerance" in plan["reason"]
    assert plan["planning_time_s"] < 1.0 and len(plan["path"]) == 1


def test_a_3d_plan_file_has_exactly_the_documented_keys(written_plans):
    plan = _written(written_plans, 1, "3d.json", "3-D plan key", "offset-3d")
    assert plan["propagation"] == "mncp_inverse"
    for k in plan["path"]:
        assert abs(math.sqrt(sum(x * x for x in k["pose"][3:])) - 1) < 1e-6, "poses carry unit quaternions"


def test_the_written_plans_replay_and_print_the_documented_json(written_plans):
    d, _ = written_plans
    r2, r3 = cli_many([
        ["simulate", EXAMPLES / "t-shape.toml", "--plan", d / "planar.json", "--json"],
        ["simulate", EXAMPLES / "offset-3d.toml", "--plan", d / "3d.json", "--json"],
    ])
    keys = set(documented_json_keys("regrasp simulate")[0])
    for r in (r2, r3):
        assert r.returncode == 0, r.stdout + r.stderr
        out = json.loads(r.stdout)
        assert set(out) == keys and out["success"] is True
    assert json.loads(r3.stdout)["max_pusher_slip"] is None


# --- the command line ------------------------------------------------------------------------

def cli_sections() -> dict[str, list[tuple[list[str], list[list[str]]]]]:
    """The tables of docs/cli.md by the subcommand of their section (`## regrasp SUB`)."""
    out: dict = {}
    for heading, header, rows in md_tables(DOCS / "cli.md"):
        m = re.fullmatch(r"`regrasp ([\w-]+)`", heading)
        if m:
            out.setdefault(m[1], []).append((header, rows))
    return out


def documented_options(sub: str) -> set[str]:
    opts = set()
    for header, rows in cli_sections()[sub]:
        if header[0] == "option":
            for r in rows:
                (cell,) = code_names(r[0])
                if cell.startswith("-"):
                    opts.add(cell.split()[0])
    return opts


def documented_json_keys(section: str) -> list[list[str]]:
    """The key tables (header `key`) of one section of docs/cli.md, each as a list of keys."""
    sub = section.removeprefix("regrasp ")
    return [[k for r in rows for k in code_names(r[0])] for header, rows in cli_sections()[sub] if header[0] == "key"]


def help_options(text: str) -> set[str]:
    """Option strings of an argparse help text (its options section)."""
    opts = set()
    for line in text.splitlines():
        if re.match(r"^\s{2}-", line):
            head = re.split(r"\s{2,}", line.strip())[0]
            opts |= set(re.findall(r"(?:^|,\s)(--?[A-Za-z][\w-]*)", head))
    return opts - {"-h", "--help"}


@pytest.fixture(scope="module")
def helps():
    top = cli("--help")
    assert top.returncode == 0, top.stderr
    m = re.search(r"\{([\w,-]+)\}", top.stdout)
    assert m, top.stdout
    subs = m[1].split(",")
    runs = cli_many([[s, "--help"] for s in subs])
    for s, r in zip(subs, runs):
        assert r.returncode == 0, f"regrasp {s} --help: {r.stderr}"
    return {s: r.stdout for s, r in zip(subs, runs)}


def test_every_subcommand_is_documented_and_every_documented_one_exists(helps):
    documented_subs = set(cli_sections())
    assert set(helps) == documented_subs, (
        f"undocumented subcommands {sorted(set(helps) - documented_subs)}, "
        f"documented but missing {sorted(documented_subs - set(helps))}")
    for s in helps:
        assert any(h[0] == "option" for h, _ in cli_sections()[s]), f"docs/cli.md: `regrasp {s}` has no option table"


def test_every_option_is_documented_and_every_documented_option_exists(helps):
    problems = []
    for s, text in helps.items():
        have, docs = help_options(text), documented_options(s)
        if have - docs:
            problems.append(f"regrasp {s}: undocumented {sorted(have - docs)}")
        if docs - have:
            problems.append(f"regrasp {s}: documented but not an option {sorted(docs - have)}")
    assert not problems, "; ".join(problems)
    assert "--out" in documented_options("plan") and "--pose" in documented_options("cone")


def test_the_exit_statuses_are_documented():
    rows = {r[0]: r[1] for _, h, body in md_tables(DOCS / "cli.md") if h == ["status", "meaning"] for r in body}
    assert set(rows) == {"0", "1", "2"}
    assert "success" in rows["0"] and "cannot be done" in rows["1"] and "invalid input" in rows["2"]


def test_cone_json_prints_the_documented_keys():
    r, bad = cli_many([
        ["cone", EXAMPLES / "block-low-friction.toml", "--pose", "0,0,0", "--pusher", "left", "--json"],
        ["cone", EXAMPLES / "block-low-friction.toml", "--pose", "0,0", "--pusher", "left"],
    ])
    assert r.returncode == 0, r.stderr
    (keys,) = documented_json_keys("regrasp cone")
    assert set(json.loads(r.stdout)) == set(keys)
    assert bad.returncode == 2 and "--pose" in bad.stderr, bad.stderr


def test_a_goal_no_push_can_move_towards_is_unreachable_and_exits_1(written_plans):
    # only the top pusher (it pushes the block down in the grasp, as gravity does); the goal is up
    plan = _not_found(written_plans, 6, "one-way.json", "no plan found: unreachable: no push can move the pad's centre")
    assert plan["stop_reason"] == "unreachable" and "the planner's range" in plan["reason"]
    assert plan["planning_time_s"] < 1.0 and len(plan["path"]) == 1


def test_a_3d_goal_the_pads_cannot_hold_is_unreachable_and_exits_1(written_plans):
    d, runs = written_plans
    assert runs[7].returncode == 1 and "no plan found: unreachable: the grasp cannot hold" in runs[7].stderr, runs[7].stderr
    plan = _strict_json((d / "cannot-hold-3d.json").read_text())
    check_plan(plan, "3-D plan key")
    assert plan["stop_reason"] == "unreachable" and "within the goal's tolerance" in plan["reason"]
    assert plan["planning_time_s"] < 1.0 and len(plan["path"]) == 1 and plan["found"] is False
