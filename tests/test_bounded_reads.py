"""Every input file is read with a bound (regrasp.files.read_text, issue "Hardening, second
round"): an endless stream (/dev/zero) or a file over MAX_FILE_BYTES is refused naming the
field, after reading no more than the bound — through the API and the CLI (exit 2, no
traceback)."""

import os
import resource
import subprocess
import sys

import pytest

import regrasp
from regrasp import files
from regrasp.dexterity.graph import GraspGraph
from regrasp.dexterity.objects import load_object
from regrasp.workcell import Workcell

ZERO = "/dev/zero"
pytestmark = pytest.mark.skipif(not os.path.exists(ZERO), reason="needs /dev/zero")

READERS = [(lambda p: regrasp.load_scene(p), "path"), (lambda p: regrasp.Plan.load(p), "plan"),
           (Workcell.load, "workcell"), (GraspGraph.load, "graph"), (load_object, "object")]


@pytest.mark.parametrize("read, field", READERS)
def test_an_endless_stream_is_refused_naming_the_field(read, field):
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # KiB
    with pytest.raises(regrasp.ArgumentError) as e:
        read(ZERO)
    assert e.value.field == field and "more than" in str(e.value)
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    assert grown < 4 * files.MAX_FILE_BYTES / 1024  # bounded: a few times the limit at most, never the stream


@pytest.mark.parametrize("read, field", READERS)
def test_a_file_over_the_bound_is_refused_and_one_at_it_is_read(read, field, tmp_path, monkeypatch):
    monkeypatch.setattr(files, "MAX_FILE_BYTES", 64)
    big = tmp_path / "big.toml"
    big.write_text("# " + "x" * 100 + "\n")
    with pytest.raises(regrasp.ArgumentError) as e:
        read(big)
    assert e.value.field == field and "more than 64 bytes" in str(e.value)
    assert files.read_text(tmp_path / "big.toml", "f", limit=103) == big.read_text()


def test_text_that_is_not_utf8_is_refused_naming_the_field(tmp_path):
    p = tmp_path / "s.toml"
    p.write_bytes(b"name = '\xff'\n")
    with pytest.raises(regrasp.ArgumentError) as e:
        regrasp.load_scene(p)
    assert e.value.field == "path" and "UTF-8" in str(e.value)


@pytest.mark.parametrize("args, field", [
    (["plan", ZERO], "scene"),
    (["simulate", "{scene}", "--plan", ZERO], "plan"),
    (["regrasp-sequence", ZERO, "--from", "g0", "--to", "g1"], "graph"),
])
def test_the_cli_refuses_an_endless_stream_with_exit_2(args, field):
    scene = str(regrasp.examples.path("block-low-friction"))
    r = subprocess.run([sys.executable, "-m", "regrasp", *[a.format(scene=scene) for a in args]],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 2 and f"`{field}`" in r.stderr and "Traceback" not in r.stderr, r.stderr
