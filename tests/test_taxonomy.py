"""regrasp.dexterity.taxonomy: the grasps of a box, a cube, a triangular prism and a 32-gon
cylinder counted by hand from their symmetry; every grasp puts the object between the pads; the
grasp distance is zero exactly up to symmetry and a metric; the taxonomy does not depend on where
the object's frame is; the closed-form hold margin against the worst of many sampled hand
orientations; the patch's torsion radius against a fine grid."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import regrasp
from regrasp import pose as P
from regrasp.dexterity import taxonomy as T
from regrasp.dexterity.taxonomy import (Grasp, box_vertices, extruded_vertices, grasp_distance, taxonomy,
                                        taxonomy_of)
from regrasp.errors import ArgumentError
from regrasp.robot.pads import HALF_WIDTH, LENGTH

from .conftest import EXAMPLES

MASS, FORCE, MU = 0.1, 5.0, 0.7  # kg, N per pad, the pads' friction
BOX = box_vertices([0.05, 0.03, 0.08])
CUBE = box_vertices([0.05, 0.05, 0.05])
SIDE = 0.06  # m, the prism's triangle
PRISM = extruded_vertices(np.array([[-SIDE / 2, 0.0], [SIDE / 2, 0.0], [0.0, SIDE * np.sqrt(3) / 2]])
                          - [0.0, SIDE * np.sqrt(3) / 6], 0.02)  # the triangle's centroid at the origin
RADIUS = 0.02  # m, the 32-gon's corners
CORNERS = np.arange(32) * np.pi / 16
CYLINDER = extruded_vertices(RADIUS * np.column_stack([np.cos(CORNERS), np.sin(CORNERS)]), 0.06)


def tax(V, com=None, **kw):
    return taxonomy(V, MASS, np.zeros(3) if com is None else com, FORCE, MU, **kw)


def turn(axis, angle) -> np.ndarray:
    """The pose (no translation) of a turn by ``angle`` [rad] about unit ``axis``."""
    return np.r_[0.0, 0.0, 0.0, np.cos(angle / 2), np.sin(angle / 2) * np.asarray(axis, float)]


quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(lambda q: np.linalg.norm(q) > 0.1) \
    .map(lambda q: np.asarray(q) / np.linalg.norm(q))
poses = st.tuples(st.lists(st.floats(-0.2, 0.2), min_size=3, max_size=3), quaternions).map(lambda t: np.r_[t[0], t[1]])


# --- counts ----------------------------------------------------------------------------------------


def test_box_has_three_face_pairs_and_18_grasps():
    # Per face pair: 2 orders x 4 edges x 2 (palm / fingertips) = 16 candidate turns, but an edge to
    # the palm is the opposite edge to the fingertips: 8 rotations (the face's normal onto ±y, one of
    # the 4 in-plane directions ±u, ±v onto +z). The box's 4 proper symmetries (identity, the half
    # turns about its axes) act freely on them: 8 / 4 = 2 distinct orientations (the region's long
    # side along z or along x). Offsets move the object, which no symmetry undoes: x 3.
    # 3 pairs (widths 0.05, 0.03, 0.08 <= 0.085) x 2 x 3 = 18.
    t = tax(BOX)
    pairs = T._antipodal(t.faces, 0.0, 0.085)
    assert sorted(t.faces[i].offset + t.faces[j].offset for i, j in pairs) == pytest.approx([0.03, 0.05, 0.08])
    assert len(t.grasps) == 18 and [g.name for g in t.grasps] == [f"g{i}" for i in range(18)]
    assert {frozenset(g.faces) for g in t.grasps} == {frozenset(p) for p in pairs}
    widths = sorted(g.width for g in t.grasps)
    assert widths == pytest.approx([0.03] * 6 + [0.05] * 6 + [0.08] * 6)
    assert len(tax(BOX, width_range=(0.0, 0.07)).grasps) == 12  # the 80 mm pair left out
    assert len(tax(BOX, offsets=(0.0,)).grasps) == 6


def test_cube_collapses_to_one_family():
    # 3 pairs x 8 rotations = 24 = the cube's proper symmetries: 1 orientation, x 3 offsets
    t = tax(CUBE)
    assert len(t.grasps) == 3 and len({g.faces for g in t.grasps}) == 1
    assert sorted(g.offset for g in t.grasps) == pytest.approx([-0.35 * 0.05, 0.0, 0.35 * 0.05])  # T.OFFSETS of 50 mm


def test_prism_grasps_on_its_triangles():
    # Only the triangles are antipodal (the rectangles' normals are 120° apart). 2 orders x 3 edges
    # x 2 (palm / fingertips; no two edges are parallel) = 12 rotations over the prism's 6 proper
    # symmetries (3 turns about y, 3 half turns swapping the triangles): 2 (an edge to the palm, a
    # corner to the palm), x 3 offsets = 6.
    t = tax(PRISM, com=PRISM.mean(axis=0))
    pairs = T._antipodal(t.faces, 0.0, np.inf)
    assert len(t.faces) == 5 and len(pairs) == 1
    assert t.faces[pairs[0][0]].offset + t.faces[pairs[0][1]].offset == pytest.approx(0.02)
    assert len(t.grasps) == 6 and all(g.width == pytest.approx(0.02) for g in t.grasps)
    sides = sorted(g.label.split(",")[1].strip() for g in t.grasps)
    assert sides == ["edge 0 to fingertips"] * 3 + ["edge 0 to palm"] * 3


def test_cylinder_32gon():
    # End faces (60 mm apart): 2 x 32 x 2 / 2 = 64 rotations over the 64 proper symmetries: 1, x 3.
    # Sides: 16 antipodal pairs at the inner diameter, 16 x 8 = 128 rotations over 64: 2, x 3.
    t = tax(CYLINDER)
    inner = 2 * RADIUS * np.cos(np.pi / 32)
    assert len(t.faces) == 34 and len(T._antipodal(t.faces, 0.0, 0.085)) == 17
    assert len(t.grasps) == 9
    assert sorted(g.width for g in t.grasps) == pytest.approx([inner] * 6 + [0.06] * 3)
    assert len(tax(CYLINDER, width_range=(0.0, 0.05)).grasps) == 6


# --- geometry ------------------------------------------------------------------------------------


@pytest.mark.parametrize("V", [BOX, CUBE, PRISM, CYLINDER], ids=["box", "cube", "prism", "cylinder"])
def test_every_grasp_puts_the_object_between_the_pads(V):
    t = tax(V)
    for g in t.grasps:
        y = P.transform(g.pose, t.vertices)[:, 1]
        assert y.min() == pytest.approx(-g.width / 2, abs=1e-12) and y.max() == pytest.approx(g.width / 2, abs=1e-12)
        left, right = (P.transform(g.pose, t.faces[i].polygon)[:, 1] for i in g.faces)
        assert np.allclose(left, g.width / 2, atol=1e-12) and np.allclose(right, -g.width / 2, atol=1e-12)
        region = T._region(t.faces, g.faces, g.pose, 1e-9)
        assert T._centroid(region) == pytest.approx([0.0, g.offset], abs=1e-12)  # + towards the palm
        f = g.offset / np.ptp(region[:, 1])  # the fraction of the region's extent along z
        assert min(abs(f - x) for x in T.OFFSETS) < 1e-9
        assert -np.pi < g.angle <= np.pi and np.isfinite([g.margin, g.torsion_k, g.patch_area]).all()


def test_angle_is_the_turn_between_grasps_on_the_same_faces():
    t = tax(PRISM)
    for g in t.grasps:
        for h in t.grasps:
            if g.faces == h.faces:
                turned = P.compose(P.planar_to_spatial([0.0, 0.0, h.angle - g.angle]), np.r_[0, 0, 0, g.pose[3:]])
                assert P.quat_angle(turned[3:], h.pose[3:]) < 1e-9


def test_offset_moves_the_object_towards_the_palm():
    t = tax(BOX)
    for g in t.grasps:
        assert P.transform(g.pose, np.zeros(3))[2] == pytest.approx(g.offset, abs=1e-12)  # the box's centre
        if g.patch_area == pytest.approx(T._area(T.PAD)):  # the pad's face covered: the patch is centred on it
            assert t.patch_centre(g) == pytest.approx([0.0, 0.0], abs=1e-12)
        elif g.offset == 0:
            assert t.patch_centre(g) == pytest.approx([0.0, 0.0], abs=1e-12)
    apart = Grasp.from_dict(dict(t.grasps[0].to_dict(), pose=[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], faces=[0, 1]))
    with pytest.raises(ArgumentError) as e:
        t.patch_centre(apart)  # faces 0 and 1 are not opposite
    assert e.value.field == "grasp"


# --- the grasp distance ------------------------------------------------------------------------------


@settings(max_examples=30, deadline=None)
@given(poses)
def test_grasp_distance_is_zero_up_to_symmetry(a):
    for axis in np.eye(3):
        assert grasp_distance(BOX, a, P.compose(a, turn(axis, np.pi))) < 1e-12
        assert grasp_distance(BOX, a, P.compose(a, turn(axis, np.pi / 2))) > 0.005
    assert grasp_distance(BOX, a, a) == 0.0


@settings(max_examples=50, deadline=None)
@given(poses, poses, poses)
def test_grasp_distance_is_a_metric(a, b, c):
    ab, bc, ac = grasp_distance(BOX, a, b), grasp_distance(BOX, b, c), grasp_distance(BOX, a, c)
    assert ab == pytest.approx(grasp_distance(BOX, b, a), abs=1e-15)
    assert ac <= ab + bc + 1e-12


def test_nearest_and_classify():
    t = tax(BOX)
    for g in t.grasps:
        assert t.nearest(g.pose) == (g.name, pytest.approx(0.0, abs=1e-12))
        assert t.classify(P.compose(g.pose, turn([0, 0, 1], np.pi)), 1e-6) == g.name  # the box's symmetry
    far = P.compose([0.0, 0.0, 0.2, 1.0, 0.0, 0.0, 0.0], t.grasps[0].pose)
    assert t.classify(far, 0.01) is None and t.nearest(far)[1] > 0.1


# --- invariance -----------------------------------------------------------------------------------


@settings(max_examples=15, deadline=None)
@given(st.sampled_from(["box", "prism"]), quaternions, st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3))
def test_taxonomy_does_not_depend_on_the_object_frame(name, q, p):
    V = {"box": BOX, "prism": PRISM}[name]
    motion = np.r_[p, q]
    a, b = tax(V, com=V.mean(axis=0)), tax(P.transform(motion, V), com=P.transform(motion, V.mean(axis=0)))
    def key(t):
        return sorted((round(g.width, 9), g.holds, round(g.margin, 9), round(g.offset, 9)) for g in t.grasps)

    assert len(a.grasps) == len(b.grasps) and key(a) == key(b)


# --- holding --------------------------------------------------------------------------------------


def sampled_load(t, g, com, mass=MASS, grip=FORCE, mu=MU, n=20000) -> float:
    """The worst (m g / 2μN)²-scaled ellipsoidal criterion over ``n`` random hand orientations:
    each pad takes half the weight's in-plane force and half its moment about the grasp axis
    through the patch's centroid; its square root."""
    R = P.quat_matrices(np.random.default_rng(0).normal(size=(n, 4)))
    gravity = -9.81 * R[:, 2, :]  # the world's gravity (0, 0, −g) in each hand frame: Rᵀ (0, 0, −g)
    c = t.patch_centre(g)
    r = P.transform(g.pose, com) - np.array([c[0], 0.0, c[1]])
    force = mass * np.hypot(gravity[:, 0], gravity[:, 2]) / 2
    torque = mass * (r[2] * gravity[:, 0] - r[0] * gravity[:, 2]) / 2
    return float(np.sqrt(np.max((force / (mu * grip)) ** 2 + (torque / (g.torsion_k * mu * grip)) ** 2)))


@pytest.mark.parametrize("V,com", [(BOX, [0.01, -0.005, 0.02]), (PRISM, [0.0, 0.0, 0.0]),
                                   (CYLINDER, [0.003, 0.01, 0.0])], ids=["box", "prism", "cylinder"])
def test_margin_is_the_worst_sampled_orientation(V, com):
    t = tax(V, com=np.asarray(com))
    for g in t.grasps:
        load = sampled_load(t, g, np.asarray(com))
        assert load == pytest.approx(1 - g.margin, rel=1e-3) and load <= 1 - g.margin + 1e-12
        assert g.holds == (g.margin >= 0)


def test_a_heavy_object_is_not_held():
    t = taxonomy(BOX, 1.0, np.zeros(3), 2.0, 0.5)  # m g = 9.8 N > 2 μ N = 2 N
    assert not any(g.holds for g in t.grasps) and all(g.margin < 0 for g in t.grasps)


def test_no_patch_no_hold():
    square = np.array([[0.0, 0.0], [0.01, 0.0], [0.01, 0.01], [0.0, 0.01]])
    off = T._hold(square + [0.02, 0.0], np.zeros(3), 0.01, MU, FORCE, 1e-9)  # beside the pad's face
    assert off == (False, -1.0, 0.0, 0.0)
    sliver = T._hold(square * [1.0, 1e-7] + [0.0, 0.01], np.zeros(3), 0.01, MU, FORCE, 1e-12)  # 1e-11 m²
    assert sliver == (False, -1.0, 0.0, 0.0)
    on = T._hold(square, np.zeros(3), 0.01, MU, FORCE, 1e-9)
    assert on[0] and on[3] == pytest.approx(1e-4)


def grid_mean_distance(polygon, c, n=1500) -> float:
    """The mean distance from ``c`` over the grid's points (n x n over the bounding box) inside
    the convex counter-clockwise ``polygon``."""
    lo, hi = polygon.min(axis=0), polygon.max(axis=0)
    x, z = np.meshgrid(*(np.linspace(a, b, n + 1)[:-1] + (b - a) / (2 * n) for a, b in zip(lo, hi)))
    inside = np.ones_like(x, bool)
    for a, b in zip(polygon, np.roll(polygon, -1, axis=0)):
        inside &= (b[0] - a[0]) * (z - a[1]) - (b[1] - a[1]) * (x - a[0]) >= 0
    return float(np.mean(np.hypot(x - c[0], z - c[1])[inside]))


def test_torsion_k_of_the_whole_pad():
    t = tax(BOX)
    full = [g for g in t.grasps if g.patch_area == pytest.approx(4 * HALF_WIDTH * LENGTH / 2)]
    assert full  # the 50 x 80 and 30 x 80 faces cover the pad at every offset with the long side along z
    k = grid_mean_distance(T.PAD, np.zeros(2))
    assert all(g.torsion_k == pytest.approx(k, rel=0.01) for g in full)
    # the closed form: over a quarter a x b, ∫∫ r dA = [2abd + a³ ln((b + d)/a) + b³ ln((a + d)/b)] / 6, d = √(a² + b²)
    a, b = HALF_WIDTH, LENGTH / 2
    d = np.hypot(a, b)
    quarter = (2 * a * b * d + a ** 3 * np.log((b + d) / a) + b ** 3 * np.log((a + d) / b)) / 6
    assert k == pytest.approx(quarter / (a * b), rel=1e-4)  # 11.6 mm


@pytest.mark.parametrize("polygon,c", [
    ([[0.0, 0.0], [0.03, 0.0], [0.01, 0.02]], None),
    ([[0.0, 0.0], [0.03, 0.0], [0.01, 0.02]], [0.012, 0.003]),  # off the centroid
    ([[0.0, 0.0], [0.02, -0.01], [0.04, 0.01], [0.03, 0.03], [0.005, 0.02]], None),
])
def test_mean_distance_against_a_grid(polygon, c):
    p = np.asarray(polygon, float)
    c = T._centroid(p) if c is None else np.asarray(c, float)
    assert T._mean_distance(p, c) == pytest.approx(grid_mean_distance(p, c), rel=1e-3)


# --- files and scenes -------------------------------------------------------------------------------


def test_grasp_dict_round_trip():
    for g in tax(PRISM).grasps + tax(BOX, lateral=(0.35,)).grasps:
        d = json.loads(json.dumps(g.to_dict()))
        assert Grasp.from_dict(d).to_dict() == g.to_dict()
    old = tax(BOX).grasps[0].to_dict()
    del old["lateral"]  # a file written before lateral grasps: centred across the fingers
    assert Grasp.from_dict(old).lateral == 0.0


def test_lateral_grasps_hold_the_object_off_its_centre_across_the_fingers():
    plain, side = tax(BOX), tax(BOX, lateral=(-0.35, 0.35))
    lateral = [g for g in side.grasps if g.lateral != 0]
    assert len(side.grasps) == len(plain.grasps) + len(lateral) and lateral
    for g in plain.grasps:  # every grasp of the default taxonomy is still there
        assert side.nearest(g.pose)[1] < 1e-9
    for g in lateral:
        centre = P.transform(g.pose, np.zeros(3))  # the box's centre: its region's centroid, in the pads' plane
        assert centre[[0, 2]] == pytest.approx([g.lateral, 0.0], abs=1e-12) and g.offset == 0
        assert "lateral" in g.label
    # a quarter turn about the contact centre hangs it along the fingers: an offset grasp (where
    # the pad's face is covered, so that the patch is centred on it whatever the offset)
    covered = [g for g in lateral if g.patch_area == pytest.approx(T._area(T.PAD))]
    assert covered
    for g in covered:
        c = side.patch_centre(g)
        for sign in (1, -1):
            turned = P.compose(np.r_[c[0], 0.0, c[1], 1.0, 0, 0, 0], P.compose(
                P.planar_to_spatial([0.0, 0.0, sign * np.pi / 2]), P.compose(np.r_[-c[0], 0.0, -c[1], 1.0, 0, 0, 0], g.pose)))
            name, d = side.nearest(turned)
            if d < 1e-9:
                assert side.grasp(name).lateral == 0 and side.grasp(name).offset != 0
                break
        else:
            raise AssertionError(f"{g.name}: no quarter turn reaches a grasp")


@pytest.mark.parametrize("key,value", [("pose", [0.0] * 7), ("pose", [0, 0, 0, 1, 0, 0]), ("faces", [1]),
                                       ("faces", [1, -2]), ("holds", 1), ("margin", float("nan")), ("name", 3),
                                       ("width", "0.05"), ("angle", None)])
def test_grasp_from_a_bad_dict_names_the_field(key, value):
    d = tax(BOX).grasps[0].to_dict()
    d[key] = value
    with pytest.raises(ArgumentError) as e:
        Grasp.from_dict(d)
    assert e.value.field == key
    del d[key]
    with pytest.raises(ArgumentError) as e:
        Grasp.from_dict(d)
    assert e.value.field == key
    with pytest.raises(ArgumentError) as e:
        Grasp.from_dict([1, 2])
    assert e.value.field == "grasp"


def test_taxonomy_of_a_scene():
    scene = regrasp.Scene3D.load(EXAMPLES / "block-3d.toml")  # a 50 x 12 x 80 mm box, 0.13 kg, 20 N, μ 0.6
    a = taxonomy_of(scene)
    b = taxonomy(box_vertices([0.05, 0.012, 0.08]), 0.13, np.zeros(3), 20.0, 0.6,
                 pad=T.pad_disc(float(scene._core.pad_radius)))  # the scene's pad, a disc
    assert [g.to_dict() for g in a.grasps] == [g.to_dict() for g in b.grasps] and len(a.grasps) == 18
    assert len(taxonomy_of(scene, offsets=(0.0,)).grasps) == 6


# --- bad input ------------------------------------------------------------------------------------


@pytest.mark.parametrize("field,value", [
    ("vertices", BOX[:3]), ("vertices", BOX[:, :2]), ("vertices", np.where(BOX > 0, np.nan, BOX)),
    ("vertices", [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]]), ("vertices", "box"),
    ("mass", 0.0), ("mass", -1.0), ("mass", float("nan")), ("mass", True),
    ("grip_force", 0.0), ("friction", -0.1), ("friction", "0.5"), ("gravity", -9.81), ("gravity", float("inf")),
    ("com", [0.0, 0.0]), ("com", [0.0, np.nan, 0.0]),
    ("width_range", (0.05, 0.01)), ("width_range", (-0.01, 0.05)), ("width_range", 0.085),
    ("offsets", (0.5,)), ("offsets", ()), ("offsets", (0.0, np.nan)), ("offsets", "abc"),
    ("lateral", (0.0,)), ("lateral", (0.5,)), ("lateral", (np.nan,)), ("lateral", "abc"), ("lateral", [[0.2]]),
])
def test_bad_arguments_name_the_field(field, value):
    kw = {"vertices": BOX, "mass": MASS, "com": np.zeros(3), "grip_force": FORCE, "friction": MU}
    kw[field] = value
    with pytest.raises(ArgumentError) as e:
        taxonomy(**kw)
    assert e.value.field == field


def test_bad_lookups_name_the_field():
    t = tax(BOX)
    with pytest.raises(ArgumentError, match="g17") as e:
        t.grasp("g99")
    assert e.value.field == "grasp"
    for pose, tolerance, field in [([0.0] * 6, 0.01, "pose"), ([0, 0, 0, 0, 0, 0, 0], 0.01, "pose"),
                                   (t.grasps[0].pose, -1.0, "tolerance")]:
        with pytest.raises(ArgumentError) as e:
            t.classify(pose, tolerance)
        assert e.value.field == field
    with pytest.raises(ArgumentError) as e:
        tax(BOX, width_range=(0.0, 0.01)).nearest(t.grasps[0].pose)
    assert e.value.field == "taxonomy"


def test_a_disc_pad_has_the_torsion_radius_of_a_uniform_disc():
    # k = 2/3 r for a uniformly pressed disc; the 64-gon is within 0.2 % of it
    r = 0.006
    t = taxonomy(box_vertices([0.05, 0.03, 0.08]), MASS, np.zeros(3), FORCE, MU, pad=T.pad_disc(r))
    centred = [g for g in t.grasps if abs(g.offset) < 1e-12]
    assert centred and all(g.torsion_k == pytest.approx(2 / 3 * r, rel=2e-3) for g in centred)
    assert all(g.patch_area == pytest.approx(np.pi * r * r, rel=2e-3) for g in centred)


def test_a_bad_pad_is_refused():
    with pytest.raises(ArgumentError) as e:
        taxonomy(CUBE, MASS, np.zeros(3), FORCE, MU, pad=[[0, 0], [1, 0]])
    assert e.value.field == "pad"
