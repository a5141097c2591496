"""The one world builder (regrasp.mujoco.world, issue "One world"): every rig's MuJoCo model is
made by ``build(Layout)`` — checked in the source (no other module assembles a world from the
pieces) and on the models it makes (holders, features, the perturbed world's numbers)."""

import ast
from pathlib import Path

import numpy as np
import pytest

import regrasp
from regrasp.mujoco.world import Layout, build, gravity
from regrasp.scene.perturbation import Perturbation

mujoco = pytest.importorskip("mujoco")

PKG = Path(__file__).resolve().parents[1] / "python" / "regrasp"
#: the pieces that make a world; only the builder (and the modules that define them) call them
PIECES = {"new_spec", "planar_spec", "add_object", "add_object3d", "add_planar_pads", "add_pads3d", "add_feature",
          "add_feature_geom", "add_feature_geoms", "add_grip_motors", "add_workcell_geoms"}
DEFINING = {"mujoco/model.py", "mujoco/spatial_parts.py", "mujoco/world.py"}


def piece_calls(root: Path = PKG) -> list:
    """(file, line, piece) of every call of a world piece outside the builder and its pieces."""
    out = []
    for p in sorted(root.rglob("*.py")):
        rel = p.relative_to(root).as_posix()
        if rel in DEFINING:
            continue
        for node in ast.walk(ast.parse(p.read_text())):
            if isinstance(node, ast.Call):
                f = node.func
                name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None)
                if name in PIECES:
                    out.append((rel, node.lineno, name))
    return out


def test_no_module_but_the_builder_assembles_a_world():
    assert piece_calls() == []


def test_the_check_finds_a_second_builder(tmp_path):
    pkg = tmp_path / "regrasp"
    (pkg / "execution").mkdir(parents=True)
    (pkg / "execution" / "rig.py").write_text("from ..mujoco import model as M\n\ndef f(s):\n    return M.new_spec('x', s)\n")
    assert piece_calls(pkg) == [("execution/rig.py", 4, "new_spec")]


def bodies(spec) -> dict:
    m = spec.compile()
    return {m.body(i).name: i for i in range(m.nbody)}, m


def test_holders_and_features_of_a_planar_world():
    s = regrasp.load_scene(regrasp.examples.path("t-shape"))
    names, m = bodies(build(Layout(s, [0.0, 0.0, 0.1], "gripper", pushers=("top",))))
    assert {"object", "gripper", "pad_left", "pad_right", "feature_top"} <= set(names)
    assert m.body_parentid[names["pad_left"]] == names["gripper"] and m.body_mocapid[names["feature_top"]] >= 0
    assert m.nu == 2 and np.allclose(m.opt.gravity, gravity(Layout(s, [0, 0, 0])))
    names, m = bodies(build(Layout(s, [0.0, 0.0, 0.0], "fixed", pushers=("top",), features="driven")))
    assert "gripper" not in names and m.body_parentid[names["pad_left"]] == 0  # the planner's view: pads fixed
    assert m.body_mocapid[names["feature_top"]] < 0 and m.body_jntnum[names["feature_top"]] == 3  # driven x, z, θ


def test_a_perturbed_3d_world_scales_what_it_says():
    s = regrasp.load_scene(regrasp.examples.path("block-3d"))
    start = np.asarray(s.task.start, float)
    p = Perturbation(finger_friction=0.8, mass=1.3, feature_friction=1.2)
    m0 = build(Layout(s, start, "gripper", pushers=tuple(s.pusher_names))).compile()
    m1 = build(Layout(s, start, "gripper", pushers=tuple(s.pusher_names), perturbation=p)).compile()
    obj = m0.body("object").id
    assert m1.body_mass[obj] == pytest.approx(1.3 * m0.body_mass[obj]) == pytest.approx(1.3 * s.mass)
    pads = [g for g in range(m0.ngeom) if m0.body(m0.geom_bodyid[g]).name.startswith("pad_")]
    feats = [g for g in range(m0.ngeom) if m0.body(m0.geom_bodyid[g]).name.startswith("feature_")]
    assert pads and feats
    assert np.allclose(m1.geom_friction[pads, 0], 0.8 * m0.geom_friction[pads, 0])
    assert np.allclose(m1.geom_friction[feats, 0], 1.2 * m0.geom_friction[feats, 0])


def test_a_workcell_world_is_in_the_world_frame_with_its_features_at_their_friction():
    from regrasp.execution import default_workcell

    s = regrasp.load_scene(regrasp.examples.path("block-xztheta"))
    wc = default_workcell(s)
    k = 0.9
    m = build(Layout(s, np.zeros(3), "gripper", workcell=wc, perturbation=Perturbation(feature_friction=k))).compile()
    assert np.allclose(m.opt.gravity, [0, 0, -s.gravity[1]])
    for f in wc.features:  # every feature's geoms at its friction times the perturbation's factor
        ids = [g for g in range(m.ngeom) if (m.geom(g).name or "").startswith(f.name)]
        assert ids and np.allclose(m.geom_friction[ids, 0], k * f.friction), f.name
    assert m.body_jntnum[m.body("gripper").id] == 4  # spatial: x, y, z and a ball


def test_a_robot_world_adds_the_object_and_nothing_of_a_hand():
    s = regrasp.load_scene(regrasp.examples.path("block-3d"))
    spec = mujoco.MjSpec()
    build(Layout(s, [0, 0, 0.5, 1, 0, 0, 0], "robot", object_rgba=(1, 0, 0, 1)), spec=spec,
          extra=lambda sp: sp.worldbody.add_geom(name="post", size=[0.01, 0, 0]))
    m = spec.compile()
    names = {m.body(i).name for i in range(m.nbody)}
    assert "object" in names and not any(n.startswith("pad_") for n in names) and m.nu == 0
    assert m.geom("post").id >= 0 and np.allclose(m.geom_rgba[m.body_geomadr[m.body("object").id]], [1, 0, 0, 1])


@pytest.mark.parametrize("kw, field", [({"holder": "hand"}, "holder"), ({"features": "flying"}, "features"),
                                        ({"pad": "soft"}, "pad")])
def test_a_bad_layout_is_refused_naming_the_field(kw, field):
    s = regrasp.load_scene(regrasp.examples.path("t-shape"))
    with pytest.raises(regrasp.ArgumentError) as e:
        Layout(s, [0, 0, 0], **kw)
    assert e.value.field == field


def test_creep_kept_at_its_old_path_with_a_warning():
    import regrasp.mujoco.model as M
    from regrasp.mujoco.world import creep

    with pytest.warns(DeprecationWarning, match="mujoco.model.creep"):
        old = M.creep
    assert old is creep
