"""The documentation site builds without network or warnings (``mkdocs build --strict``) and its
API pages are generated from the docstrings: each stage's page holds that stage's names.

Skipped when mkdocs or mkdocstrings-python is not installed (both are in the ``dev`` extra).
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from .conftest import ROOT

pytest.importorskip("mkdocs", reason="mkdocs is not installed (pip install mkdocs mkdocstrings-python)")
pytest.importorskip("mkdocstrings_handlers.python", reason="mkdocstrings-python is not installed")

#: page of the site -> names its generated API must show (anchors of mkdocstrings' headings).
EXPECTED = {
    "api/pose": ["regrasp._core.se3_log", "regrasp._core.se3_integrate"],
    "api/mechanics": ["regrasp.scene.planar.Scene.motion_cone", "regrasp.scene.spatial.Scene3D.plan",
                      "regrasp.scene.load_scene"],
    "api/cones": ["regrasp.scene.planar.MotionCone.contains", "regrasp.scene.planar.MotionConeBatch",
                  "regrasp._core.MotionCone.grip_force_range"],
    "api/dynamics": ["regrasp.sim.quasistatic.simulate_push", "regrasp._core.MncpProblem.solve_forward"],
    "api/planning": ["regrasp.planning.plan.plan", "regrasp.planning.plan.Plan.save"],
    "api/control": ["regrasp.control.loop.control", "regrasp._core.Mpc.step"],
    "api/execution": ["regrasp.mujoco.spatial.execute_plan3d", "regrasp.mujoco.push.simulate_push"],
    "api/visualization": ["regrasp.viz.viewer.write_html"],
    "api/files-errors": ["regrasp.errors.ArgumentError", "regrasp.files.write_text"],
    "api/dexterity": ["regrasp.dexterity.graph.build_graph", "regrasp.dexterity.taxonomy.taxonomy"],
}


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)], cwd=ROOT,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    return out


@pytest.mark.parametrize("page", sorted(EXPECTED))
def test_stage_page_shows_its_api(site, page):
    html = (site / page / "index.html").read_text()
    missing = [n for n in EXPECTED[page] if f'id="{n}"' not in html]
    assert not missing, f"{page}: no {missing}"


def test_docstrings_and_units_reach_the_pages(site):
    """The text is the docstrings' (a unit included), not just the names."""
    html = (site / "api" / "cones" / "index.html").read_text()
    assert "Per-finger grip-force range (min, max) [N]" in html


def test_properties_made_by_core_property_show_their_description(site):
    """The site imports the modules (``force_inspection``), so the descriptions that
    ``core_property`` gives its properties reach the page, as they reach ``help()``."""
    import regrasp

    html = (site / "api" / "mechanics" / "index.html").read_text()
    assert regrasp.Scene.pusher_names.__doc__ in html


def test_contract_pages_are_in_the_site(site):
    for page in ("scene-file", "plan-file", "cli"):
        assert (site / page / "index.html").exists(), page
    assert "the user-facing contract" in (site / "index.html").read_text()
