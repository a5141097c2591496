"""The object against the workcell's bodies along a world motion (regrasp.execution.collision,
regrasp.workcell.shapes), checked independently with MuJoCo's own signed distance between the
geoms (mj_geomDistance): the object's convex pieces as meshes, the bodies as MuJoCo geoms."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import ArgumentError, ExecutionError
from regrasp.execution import world_motion
from regrasp.execution import collision as C
from regrasp.execution.motion_check import PENETRATION_LIMIT
from regrasp.execution.world_motion import GRIPPER_ENVELOPE, GRIPPER_RADIUS
from regrasp.execution import default_workcell
from regrasp.workcell import Workcell, shapes
from regrasp.workcell.description import Feature
from regrasp.workcell.shapes import EDGE_RADIUS, PLATE_DEPTH, TABLE_DEPTH

from .conftest import plan_of, rotation_matrix as rot

mujoco = pytest.importorskip("mujoco")


def task_examples():
    out = []
    for p in sorted(regrasp.examples.ROOT.glob("*.toml")):
        s = regrasp.load_scene(p)
        if (s.dimension == 3 or s.kind == "grasp") and s.task is not None:
            out.append(p.stem)
    return out


def mujoco_rig(scene, workcell):
    """A MuJoCo model with the workcell's bodies (from shapes()) and the object on a mocap body:
    a planar object as its outline's convex pieces extruded ±6 mm, a 3-D one as its sphere or convex parts."""
    from regrasp.mujoco.model import THICKNESS, convex_pieces

    spec = mujoco.MjSpec()
    for s in shapes(workcell):
        spec.worldbody.add_geom(name=s.name, type=getattr(mujoco.mjtGeom, f"mjGEOM_{s.kind.upper()}"),
                                size=list(s.size) + [0.0] * (3 - len(s.size)), pos=s.pose[:3], quat=s.pose[3:])
    body = spec.worldbody.add_body(name="object", mocap=True)
    if scene.dimension == 2:
        for k, piece in enumerate(convex_pieces(np.asarray(scene.outline, float))):
            v = [(p[0], y, p[1]) for p in piece for y in (-THICKNESS / 2, THICKNESS / 2)]
            spec.add_mesh(name=f"piece{k}", uservert=np.ravel(v).tolist())
            body.add_geom(name=f"object{k}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"piece{k}")
    elif scene._core.sphere is not None:
        body.add_geom(name="object0", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[scene._core.sphere, 0, 0])
    else:  # its convex parts (the mesh alone for a convex object)
        for k, (v, _) in enumerate(scene.parts()):
            spec.add_mesh(name=f"piece{k}", uservert=np.ravel(np.asarray(v, float)).tolist())
            body.add_geom(name=f"object{k}", type=mujoco.mjtGeom.mjGEOM_MESH, meshname=f"piece{k}")
    m = spec.compile()
    return m, mujoco.MjData(m)


def mujoco_depths(scene, workcell, poses, reach=0.3):
    """MuJoCo's penetration [m] (minus its signed distance, within ``reach``) of the object at each
    world pose in each body of shapes(workcell): (n, bodies)."""
    m, d = mujoco_rig(scene, workcell)
    names = [s.name for s in shapes(workcell)]
    obj = [i for i in range(m.ngeom) if m.geom(i).name.startswith("object")]
    out = np.full((len(poses), len(names)), -reach)
    for j, W in enumerate(poses):
        d.mocap_pos[0], d.mocap_quat[0] = W[:3], W[3:]
        mujoco.mj_kinematics(m, d)
        for i, n in enumerate(names):
            g = m.geom(n).id
            out[j, i] = max(-mujoco.mj_geomDistance(m, d, o, g, reach, None) for o in obj)
    return out


def body_of(feature, names):
    return next(n for n in names if feature == n or feature.startswith(n + "."))


@pytest.mark.parametrize("name", task_examples())
def test_every_example_moves_clear_of_the_workcell_by_mujocos_distances(name):
    """Each bundled example with a task gets a world motion in its default workcell, and MuJoCo
    finds the object, at every sample, at most PENETRATION_LIMIT into the feature of a push during
    its approach, push and retreat and out of every other body (and out of all in transfers)."""
    scene, plan = plan_of(name)
    if name == "pivot-90-3d":
        # the quarter turn's last push is by the patch under the block, turned 77° with it in the
        # grasp: only a face tilted as much could serve it, and the default workcell has none
        with pytest.raises(ExecutionError, match=r"no feature of workcell `default-pivot-90-3d` serves .*max_tilt") as e:
            world_motion(scene, plan)
        assert e.value.pusher in scene.pusher_names and f"pusher `{e.value.pusher}`" in str(e.value)
        return
    m = world_motion(scene, plan)
    D = mujoco_depths(scene, m.workcell, m.object)
    names = [s.name for s in shapes(m.workcell)]
    allowed = np.full(D.shape, 2e-5)                                  # MuJoCo's tolerance
    for a in m.assignments:
        allowed[m.push == a.index, names.index(body_of(a.feature, names))] = PENETRATION_LIMIT + 2e-5
    worst = np.unravel_index(np.argmax(D - allowed), D.shape)
    assert np.all(D <= allowed), (name, m.labels[worst[0]], names[worst[1]], D[worst])
    # ours agrees with MuJoCo's where either finds the object close (within 1 mm: the spacing)
    ours = C.depths(C.solid(scene), shapes(m.workcell), m.object)
    near = (D > -1e-3) | (ours > -1e-3)
    assert np.all(np.abs(np.maximum(ours, -1e-3) - np.maximum(D, -1e-3))[near] <= 1e-3)
    # the transfers at the safe height keep the object above every body
    top = m.workcell.top()
    assert m.safe_height >= top + m.timing.clearance + GRIPPER_RADIUS - 1e-12
    high = np.isclose(m.gripper[:, 2], m.safe_height)
    assert high.any() and np.all(D[high] < -m.timing.clearance + 1e-9)


def obstacle_at(point, friction=0.0, side=0.01):
    """A block no pusher can use (friction 0) of ``side`` [m] centred at world ``point``."""
    return Feature("obstacle", "block", [*point, 1.0, 0, 0, 0], friction, [side] * 3, index=9)


def only_the_contacts_used(m):
    """A workcell with the table and, for each contact a motion used, one feature just there
    (an edge, a corner or a face at its contact frame): one choice per push."""
    cs = {c.name: c for c in m.workcell.contacts()}
    out = []
    for a in m.assignments:
        c = cs[a.feature]
        if c.name == "table" or any(f.name == f"at{c.name}" for f in out):
            continue
        kw = ({"length": c.length} if c.kind == "edge" else {"size": 2 * c.extent} if c.kind == "face" else {})
        out.append(Feature(f"at{c.name}", c.kind, a.frame, c.friction, index=len(out), **kw))
    return Workcell("used", m.workcell.table, tuple(out), m.workcell.robot)


def centre_at(scene, m, label, top):
    """The object's centre at the middle sample labelled ``label`` whose centre is below ``top``
    [m] (an obstacle higher up would raise the safe height, and the transfers with it)."""
    centres = regrasp.pose.transform_rows(m.object, C.solid(scene).points.mean(axis=0)[None])[:, 0]
    js = [i for i, lab in enumerate(m.labels) if lab == label and centres[i, 2] < top - 0.01]
    return centres[js[len(js) // 2]]


@pytest.mark.parametrize("label", ["push", "transfer", "approach"])
def test_a_motion_through_a_feature_is_refused_naming_it(label):
    """An obstacle put where the object passes during a push, a transfer or an approach, in a
    workcell that offers each push one contact: the motion is refused naming the push (or the
    transfer to it) where MuJoCo first finds the object in the obstacle, and the obstacle."""
    scene, plan = plan_of("block-low-friction")
    cell = only_the_contacts_used(world_motion(scene, plan))
    m = world_motion(scene, plan, cell)
    centre = centre_at(scene, m, label, cell.top())
    w = Workcell(cell.name, cell.table, cell.features + (obstacle_at(centre),), cell.robot)
    with pytest.raises(ExecutionError) as e:
        world_motion(scene, plan, w)
    msg = str(e.value)
    assert "feature `obstacle`" in msg and "mm deep" in msg, msg
    # MuJoCo's first sample with the object in the obstacle names the segment refused
    D = mujoco_depths(scene, w, m.object)[:, [s.name for s in shapes(w)].index("obstacle")]
    first = int(np.argmax(D > 1e-4))
    assert D[first] > 1e-4
    lab = m.labels[first]
    k = (next(a for a in m.assignments if np.any(m.push[first:] == a.index)) if m.push[first] < 0
         else m.assignments[m.push[first]])
    assert msg.startswith(f"the transfer to push {k.index}" if lab == "transfer" else f"push {k.index}"), (lab, msg)
    assert ("in its approach" in msg) == (lab == "approach")
    assert e.value.field == f"plan.path[{k.first + 1}].pusher"
    seg = [i for i in range(len(m.labels)) if m.labels[i] == lab and m.push[i] == m.push[first]]
    # the depth said is the deepest point of either solid in the other: at most the distance
    # that separates them (MuJoCo's penetration), and here more than 1 mm
    said = float(msg.split("mm deep")[0].split(",")[-1]) * 1e-3
    assert 1e-3 < said <= D[seg].max() + 2e-4, (said, D[seg].max())


def test_a_push_whose_feature_is_blocked_takes_another_one():
    """The default workcell offers a push several block edges: with an obstacle where the object
    pushes on the first choice, the push is rendered on another edge, clear of the obstacle by
    MuJoCo's distances."""
    scene, plan = plan_of("block-low-friction")
    cell = default_workcell(scene)
    m = world_motion(scene, plan, cell)
    w = Workcell(cell.name, cell.table, cell.features + (obstacle_at(centre_at(scene, m, "push", cell.top())),),
                 cell.robot)
    m2 = world_motion(scene, plan, w)
    assert [a.feature for a in m2.assignments] != [a.feature for a in m.assignments]
    D = mujoco_depths(scene, w, m2.object)[:, [s.name for s in shapes(w)].index("obstacle")]
    assert D.max() < 2e-5


def test_shapes_are_the_documented_bodies():
    """The table's slab under its top, a block's box, a face's plate behind it, an edge's bar and a
    corner's ball just behind the feature (checked with 4 x 4 algebra of the feature's pose)."""
    scene, _ = plan_of("pivot-3d")
    cell = default_workcell(scene)
    cell = Workcell(cell.name, cell.table, cell.features + (
        Feature("post", "corner", [0.7, -0.25, 0.85, 1, 0, 0, 0], 0.5, index=3),), cell.robot)
    S = {s.name: s for s in shapes(cell)}
    assert list(S) == ["table"] + [f.name for f in cell.features]
    t = S["table"]
    assert t.kind == "box" and t.pose[2] + t.size[2] == pytest.approx(cell.table.height)
    assert 2 * t.size[2] == pytest.approx(TABLE_DEPTH) and np.allclose(2 * t.size[:2], cell.table.size)
    for f in cell.features:
        s, R = S[f.name], rot(f.pose[3:])
        if f.kind == "block":
            assert s.kind == "box" and np.allclose(s.pose, f.pose) and np.allclose(2 * s.size, f.size)
        elif f.kind == "face":      # the plate's front face is the feature's rectangle
            assert s.kind == "box" and np.allclose(2 * s.size, [*f.size, PLATE_DEPTH])
            assert np.allclose(s.pose[:3] + rot(s.pose[3:])[:, 2] * s.size[2], f.pose[:3])
        elif f.kind == "edge":      # the bar's surface runs along the edge: its ends and middle at depth 0
            ends = f.pose[:3] + np.outer([-0.5, 0, 0.5], R[:, 0] * f.length)
            assert s.kind == "capsule" and np.allclose(s.depth(ends), 0, atol=1e-12)
            assert s.size[0] == EDGE_RADIUS and np.allclose(rot(s.pose[3:])[:, 2] @ R[:, 0], 1)
            assert s.depth(f.pose[:3] + 1e-4 * R[:, 2]) < 0 < s.depth(f.pose[:3] - 1e-4 * R[:, 2])  # behind it
        else:
            assert s.kind == "sphere" and s.depth(f.pose[:3]) == pytest.approx(0, abs=1e-12)
            assert s.depth(f.pose[:3] - 1e-4 * R[:, 2]) > 0
    # Shape.depth against MuJoCo's distance of a tiny sphere, at random points near each body
    rng = np.random.default_rng(0)
    spec = mujoco.MjSpec()
    for s in S.values():
        spec.worldbody.add_geom(name=s.name, type=getattr(mujoco.mjtGeom, f"mjGEOM_{s.kind.upper()}"),
                                size=list(s.size) + [0.0] * (3 - len(s.size)), pos=s.pose[:3], quat=s.pose[3:])
    probe = spec.worldbody.add_body(name="probe", mocap=True)
    probe.add_geom(name="probe", type=mujoco.mjtGeom.mjGEOM_SPHERE, size=[1e-6, 0, 0])
    mm = spec.compile()
    d = mujoco.MjData(mm)
    for s in S.values():
        scale = np.minimum(s.size[:3] if s.kind == "box" else [s.bound] * 3, 0.05)
        for p in rng.normal(size=(30, 3)) * 1.5 * np.max(scale):
            x = s.pose[:3] + p
            d.mocap_pos[0] = x
            mujoco.mj_kinematics(mm, d)
            dist = mujoco.mj_geomDistance(mm, d, mm.geom("probe").id, mm.geom(s.name).id, 1.0, None) + 1e-6
            assert s.depth(x) == pytest.approx(-dist, abs=1e-6), (s.name, x)


SCENES = ["t-shape", "block-3d", "ball-roll-3d", "prism-3d"]


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(SCENES), st.integers(0, 4), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1),
       st.floats(0, 0.05), st.floats(-np.pi, np.pi), st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
def test_an_object_moved_beyond_a_bodys_plane_never_collides_with_it(name, which, ux, uy, uz, gap, angle, ax, ay, az):
    """Property: move the object (any orientation) along any direction u until all of it lies
    beyond the body's farthest point along u, by any further gap: no depth is reported."""
    u, axis = np.array([ux, uy, uz]), np.array([ax, ay, az])
    if np.linalg.norm(u) < 0.1 or np.linalg.norm(axis) < 0.1:
        return
    u, axis = u / np.linalg.norm(u), axis / np.linalg.norm(axis)
    scene = regrasp.load_scene(regrasp.examples.path(name))
    cell = default_workcell(scene)
    cell = Workcell(cell.name, cell.table, cell.features + (
        Feature("post", "corner", [0.7, -0.25, 0.85, 1, 0, 0, 0], 0.5, index=3),), cell.robot)
    s = shapes(cell)[1:][which % (len(cell.features))]
    body = C.solid(scene)
    q = np.r_[np.cos(angle / 2), np.sin(angle / 2) * axis]
    R = rot(q)
    # the body's support along u, computed from its definition
    if s.kind == "box":
        h = s.pose[:3] @ u + np.abs(rot(s.pose[3:]).T @ u) @ s.size
    elif s.kind == "capsule":
        h = s.pose[:3] @ u + abs(rot(s.pose[3:])[:, 2] @ u) * s.size[1] + s.size[0]
    else:
        h = s.pose[:3] @ u + s.size[0]
    # the object's support along -u (its lowest point along u), from its vertices or sphere
    if body.sphere > 0:
        low = -body.sphere
    else:
        low = (body.points @ R.T @ u).min()
    x = s.pose[:3] + (h - s.pose[:3] @ u - low + gap) * u
    D = C.depths(body, [s], np.r_[x, q][None])[0, 0]
    assert D <= 1e-9, (name, s.name, D)


@pytest.mark.parametrize("name, envelope", [("t-shape", 0.0), ("t-shape", GRIPPER_ENVELOPE), ("t-shape", 0.3),
                                            ("block-3d", GRIPPER_ENVELOPE)])
def test_transfers_at_the_safe_height_keep_the_gripper_body_clear(name, envelope):
    """At the safe height the gripper's body (a capsule ``envelope`` long along the gripper's +z,
    of radius GRIPPER_RADIUS) is at least the clearance from every body (MuJoCo's distance from
    that capsule at each transfer sample there), and the safe height is the workcell's top +
    clearance + the larger of the object's reach and the body's drop below the origin."""
    scene, plan = plan_of(name)
    m = world_motion(scene, plan, envelope=envelope)
    reach = max(np.linalg.norm(regrasp.pose.transform(q, C.solid(scene).points), axis=1).max() for q in m.in_hand)
    drop = max(GRIPPER_RADIUS + max(0.0, -envelope * regrasp.pose.quat_rotate(g[3:], [0, 0, 1.0])[2]) for g in m.gripper)
    assert m.safe_height == pytest.approx(m.workcell.top() + m.timing.clearance + max(reach, drop), abs=2e-3)
    spec = mujoco.MjSpec()
    for s in shapes(m.workcell):
        spec.worldbody.add_geom(name=s.name, type=getattr(mujoco.mjtGeom, f"mjGEOM_{s.kind.upper()}"),
                                size=list(s.size) + [0.0] * (3 - len(s.size)), pos=s.pose[:3], quat=s.pose[3:])
    body = spec.worldbody.add_body(name="gripper", mocap=True)
    body.add_geom(name="gripper", type=mujoco.mjtGeom.mjGEOM_CAPSULE, fromto=[0, 0, 0, 0, 0, max(envelope, 1e-6)],
                  size=[GRIPPER_RADIUS, 0, 0])
    mm = spec.compile()
    d = mujoco.MjData(mm)
    lab = np.array(m.labels)
    high = np.flatnonzero((lab == "transfer") & (m.gripper[:, 2] >= m.safe_height - 0.06))
    assert len(high) > 2
    for j in high:
        d.mocap_pos[0], d.mocap_quat[0] = m.gripper[j, :3], m.gripper[j, 3:]
        mujoco.mj_kinematics(mm, d)
        for s in shapes(m.workcell):
            dist = mujoco.mj_geomDistance(mm, d, mm.geom("gripper").id, mm.geom(s.name).id, 1.0, None)
            assert dist >= m.timing.clearance - 1e-9, (s.name, j, dist)


@pytest.mark.parametrize("value", [None, -0.1, float("nan"), 11.0, True, "0.1"])
def test_a_bad_envelope_is_refused_naming_it(value):
    scene, plan = plan_of("block-low-friction")
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, plan, envelope=value)
    assert e.value.field == "envelope"


def test_a_start_pose_in_a_feature_is_refused_naming_start():
    scene, plan = plan_of("block-low-friction")
    block = default_workcell(scene).feature("fixture")
    with pytest.raises(ArgumentError) as e:
        world_motion(scene, plan, start=[*block.pose[:3], 1, 0, 0, 0])
    assert e.value.field == "start" and "feature `fixture`" in str(e.value)


@pytest.mark.parametrize("name", ["t-shape", "block-xztheta"])
def test_a_lamina_is_bounded_across_its_plane(name):
    """Every convex piece of a planar object holds its two faces at ±THICKNESS/2 (also when an
    outline's first three points are in a line, as t-shape's bar): a point off the plane is
    outside by its distance from the face."""
    so = C.solid(regrasp.load_scene(regrasp.examples.path(name)))
    for A, b in so.pieces:
        y = A[np.abs(A[:, 1]) > 0.5]
        assert len(y) == 2 and np.allclose(sorted(y[:, 1]), [-1, 1])
    off = np.array([[0.0, 0.5, 0.0], [0.0, -0.2, 0.01]])
    assert np.allclose(so.distance(off), np.abs(off[:, 1]) - 0.006)


def test_a_sphere_depth_is_exact_at_any_orientation():
    """ball-roll-3d's ball pushed 2 mm into the table is 2 mm deep whatever its orientation."""
    scene = regrasp.load_scene(regrasp.examples.path("ball-roll-3d"))
    so = C.solid(scene)
    wc = default_workcell(scene)
    table = shapes(wc)[0]
    r = so.sphere
    rng = np.random.default_rng(0)
    q = rng.normal(size=(5, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    W = np.c_[np.tile([0.5, 0.0, wc.table.height + r - 0.002], (5, 1)), q]
    assert np.allclose(C.depths(so, [table], W)[:, 0], 0.002, atol=1e-12)
