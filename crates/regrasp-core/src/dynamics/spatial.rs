//! Spatial scenes as complementarity problems ([`crate::dynamics::mncp`]) and their time stepping.
//!
//! The object's twist is the body twist `[v, ω]` (object frame, about the object-frame origin).
//! Finger pads are the contact points of [`Scene3::pad_contacts`] with equal shares of the grip
//! force and Coulomb discs in the pad plane (the force-controlled fingers follow the object
//! along the grasp axis, so the normal force is given, not the normal velocity). A pusher is a
//! rigid point set with unilateral contacts and Coulomb cones (two tangent directions); a plane
//! pusher touches the object where it is lowest along the plane's normal at each time step
//! (the contact point moves over the object as it rolls).

use crate::dynamics::mncp::{Contact, Problem, Settings, Side};
use crate::dynamics::stepping::{check_step_motion, march, pusher_at, solve_step, step_count, within_reach, PusherContacts};
use crate::error::{Error, Result};
pub use crate::pose::spatial::integrate;
use crate::pose::spatial::{skew, twist_in};
use crate::scene::spatial::{pose_to_array, Scene3, V3};
use nalgebra::{DMatrix, DVector, Isometry3, Matrix3, Point3};

/// Two unit tangents completing `n` to an orthonormal frame.
fn tangents(n: &V3) -> (V3, V3) {
    let a = if n.x.abs() < 0.9 { V3::x() } else { V3::y() };
    let t1 = n.cross(&a).normalize();
    (t1, n.cross(&t1))
}

/// Row `[dᵀ, (r × d)ᵀ]`: the velocity along `d` of object point `r` for body twist `[v, ω]`.
fn row(r: &V3, d: &V3) -> [f64; 6] {
    let m = r.cross(d);
    [d.x, d.y, d.z, m.x, m.y, m.z]
}

/// Tangent rows `[row(r, t1); row(r, t2)]` of object point `r`.
fn tangent_rows(r: &V3, (t1, t2): &(V3, V3)) -> DMatrix<f64> {
    let mut jt = DMatrix::zeros(2, 6);
    jt.row_mut(0).copy_from_slice(&row(r, t1));
    jt.row_mut(1).copy_from_slice(&row(r, t2));
    jt
}

/// The problem at pose `pose`, with pusher contacts at object-frame points `points` (gaps
/// `gaps`, common normal `normal`, friction `mu`), over a step `h`: the pads' and the pusher's
/// contacts, and the quasi-static Newton–Euler terms (eq 3.13).
pub fn problem(
    scene: &Scene3,
    pose: &Isometry3<f64>,
    pusher: Option<(f64, &[V3], &[f64], V3)>,
    h: f64,
    speed: f64,
) -> Result<Problem> {
    let mut contacts = finger_contacts(scene, pose)?;
    if let Some((mu, points, gaps, normal)) = pusher {
        let n = normal.normalize();
        let t = tangents(&n);
        for (k, (r, g)) in points.iter().zip(gaps).enumerate() {
            let jn = DVector::from_row_slice(&row(r, &n));
            contacts.push(Contact::pusher_point(format!("pusher[{k}]"), mu, jn, tangent_rows(r, &t), *g));
        }
    }
    let (mass, wrench) = mass_and_gravity(scene, pose);
    Ok(Problem {
        dim: 6,
        mass: mass / h,
        wrench,
        contacts,
        h,
        force_scale: 2.0 * scene.grip_force * scene.grip_friction + scene.mass * scene.gravity.norm(),
        velocity_scale: speed,
        length: scene.length,
    })
}

/// The finger pads' contact points at pose `pose` with equal shares of the grip force (eq 3.5)
/// and Coulomb discs in the pad plane; an error when a pad does not touch the object.
fn finger_contacts(scene: &Scene3, pose: &Isometry3<f64>) -> Result<Vec<Contact>> {
    let mut contacts = Vec::new();
    let inv_rot = pose.rotation.inverse();
    for (side, pts) in scene.pad_contacts(pose).iter().enumerate() {
        if pts.is_empty() {
            return Err(Error::arg("pose", format!("finger pad {side} does not touch the object")));
        }
        let sign = if side == 0 { 1.0 } else { -1.0 };
        let n = inv_rot * V3::new(0.0, -sign, 0.0);
        let t = tangents(&n);
        let share = scene.grip_force / pts.len() as f64;
        for (k, r) in pts.iter().enumerate() {
            let jn = DVector::from_row_slice(&row(r, &n));
            contacts.push(Contact::fixed_normal(format!("finger{side}[{k}]"), Side::Finger, share, scene.grip_friction, jn, tangent_rows(r, &t)));
        }
    }
    Ok(contacts)
}

/// The mass matrix `M` about the object-frame origin and the gravity wrench, object frame. The
/// fingers' normal forces are given: they must not push the object along the grasp axis on
/// their own (equal and opposite totals), their moments are balanced by the pad frictions.
fn mass_and_gravity(scene: &Scene3, pose: &Isometry3<f64>) -> (DMatrix<f64>, DVector<f64>) {
    let m = scene.mass;
    let c = scene.com;
    let cx = skew(&c);
    let mut mass = DMatrix::zeros(6, 6);
    mass.view_mut((0, 0), (3, 3)).copy_from(&(Matrix3::identity() * m));
    mass.view_mut((0, 3), (3, 3)).copy_from(&(-cx * m));
    mass.view_mut((3, 0), (3, 3)).copy_from(&(cx * m));
    mass.view_mut((3, 3), (3, 3)).copy_from(&(scene.inertia - cx * cx * m));
    let f = pose.rotation.inverse() * (scene.gravity * m);
    let tq = c.cross(&f);
    (mass, DVector::from_row_slice(&[f.x, f.y, f.z, tq.x, tq.y, tq.z]))
}

/// The problem of pusher `pusher` in contact at pose `pose` (its scene points, or for a plane
/// the object's lowest points, [`Scene3::pusher_contacts`]).
pub fn push_problem(scene: &Scene3, pose: &Isometry3<f64>, pusher: usize, h: f64) -> Result<Problem> {
    let p = pusher_at(&scene.pushers, pusher)?;
    let (points, normal) = scene.pusher_contacts(pusher, pose);
    let gaps = vec![0.0; points.len()];
    problem(scene, pose, Some((p.friction, &points, &gaps, normal)), h, 0.01)
}

/// A recorded 3-D push.
#[derive(Clone, Debug, Default)]
pub struct Trajectory3 {
    pub t: Vec<f64>,
    pub pose: Vec<[f64; 7]>,
    pub twist: Vec<[f64; 6]>,
    pub pusher_slip: Vec<f64>,
    pub pusher_contacts: Vec<usize>,
    pub pusher_sticking: Vec<usize>,
    pub residual: Vec<f64>,
}

/// Simulates a push in 3-D: the pusher starts at its scene points with the object at `start`
/// and moves with constant body twist `u` (its frame = the object frame at the start), in steps
/// of `dt` (explicit time stepping, thesis §3.2.3). A plane starts touching the object's lowest
/// points; at each step its contacts are the object's lowest points along its current normal,
/// with their gaps to it.
pub fn simulate_push(
    scene: &Scene3,
    start: &Isometry3<f64>,
    pusher: usize,
    u: &[f64; 6],
    duration: f64,
    dt: f64,
    settings: &Settings,
) -> Result<Trajectory3> {
    let steps = step_count(duration, dt)?;
    let pz = pusher_at(&scene.pushers, pusher)?;
    let speed = V3::new(u[0], u[1], u[2]).norm() + V3::new(u[3], u[4], u[5]).norm() * scene.length;
    check_step_motion(speed, dt, scene.length)?;
    let reach = 0.002 + 2.0 * dt * speed;
    let mut tr = Trajectory3::default();
    // in the pusher's frame (the object frame at the start): its points (or a point of the
    // plane) and its normal
    let (points0, normal0) = scene.pusher_contacts(pusher, start);
    march(steps, dt, *start, u, integrate, |t, q, qp| {
        let rel = q.inverse() * qp;
        let normal = rel.rotation * normal0;
        let (pts, gaps) = if pz.plane {
            let on = (rel * Point3::from(points0[0])).coords;
            let candidates = scene.plane_contacts(&normal, Some(&on), reach).into_iter().map(|r| (r, normal.dot(&(r - on))));
            within_reach(candidates, reach)
        } else {
            let candidates = points0.iter().map(|p| (rel * Point3::from(*p)).coords).map(|r| (r, scene.signed_distance(&r)));
            within_reach(candidates, reach)
        };
        let prob = problem(scene, q, Some((pz.friction, &pts, &gaps, normal)), dt, speed.max(1e-3))?;
        let sol = solve_step(&prob, &twist_in(&rel, u), settings, t)?;
        let v: [f64; 6] = std::array::from_fn(|i| sol.twist[i]);
        let pc = PusherContacts::of(&prob, &sol);
        tr.t.push(t);
        tr.pose.push(pose_to_array(q));
        tr.twist.push(v);
        tr.pusher_slip.push(pc.slip);
        tr.pusher_contacts.push(pc.touching);
        tr.pusher_sticking.push(pc.sticking);
        tr.residual.push(sol.residuals.max());
        Ok(v)
    })?;
    Ok(tr)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::mncp;
    use crate::dynamics::planar::{Options, SupportModel};
    use nalgebra::{Translation3, UnitQuaternion};
    use crate::Scene;

    /// A 3-D test scene named `name`: the `[object]` table's keys, a grasp `[force, friction, pad
    /// radius]`, the `[[pushers]]` tables, and a task holding the start within `tol` metres.
    fn scene3(name: &str, object: &str, [force, friction, pad]: [f64; 3], pushers: &str, tol: f64) -> Scene3 {
        let toml = format!(
            "dimension = 3\nname = \"{name}\"\n[object]\n{object}\n\
             [grasp]\nforce = {force:?}\nfriction = {friction:?}\npad_radius = {pad:?}\n{pushers}\n\
             [task]\nstart = [0, 0, 0, 1, 0, 0, 0]\ngoal = [0, 0, 0, 1, 0, 0, 0]\ntolerance = [{tol:?}, {tol:?}, {tol:?}, 0.0175]\n"
        );
        Scene3::from_toml_str(&toml, None).unwrap()
    }

    /// The planar example's block as a box, with pushers `pushers`.
    fn block3(pushers: &str) -> Scene3 {
        scene3("block-3d", "shape = \"box\"\nsize = [0.05, 0.012, 0.08]\nmass = 0.13", [20.0, 0.6, 0.007], pushers, 0.001)
    }

    /// A line pusher at the box's left face.
    const LEFT: &str =
        "[[pushers]]\nname = \"left\"\nfriction = 0.25\npoints = [[-0.025, 0.0, -0.03], [-0.025, 0.0, 0.03]]\nnormal = [1.0, 0.0, 0.0]";

    /// A plane pusher under the object (normal up) with friction `mu`.
    fn floor(mu: f64) -> String {
        format!("[[pushers]]\nname = \"floor\"\nfriction = {mu:?}\nplane = true\nnormal = [0.0, 0.0, 1.0]")
    }

    /// A ball held by two pads, over a floor.
    fn ball3() -> Scene3 {
        scene3("ball", "shape = \"sphere\"\nradius = 0.035\nmass = 0.058", [2.5, 0.5, 0.006], &floor(0.9), 0.002)
    }

    #[test]
    fn box_mass_properties() {
        let m = crate::scene::spatial::ConvexMesh::cuboid(&V3::new(0.2, 0.4, 0.6));
        let (vol, c, i) = m.mass_properties();
        assert!((vol - 0.048).abs() < 1e-12 && c.norm() < 1e-12);
        // unit density: I_xx = V (b² + c²) / 12
        assert!((i[(0, 0)] - (0.16 + 0.36) / 12.0).abs() < 1e-12, "{i}");
        assert!((i[(2, 2)] - (0.04 + 0.16) / 12.0).abs() < 1e-12);
        assert!(i[(0, 1)].abs() < 1e-12);
        let cube = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 3 4 8 7\nf 1 5 8 4\nf 2 3 7 6\n";
        let m = crate::scene::spatial::ConvexMesh::from_obj(cube).unwrap();
        let (vol, c, _) = m.mass_properties();
        assert!((vol - 1.0).abs() < 1e-12 && (c - V3::new(0.5, 0.5, 0.5)).norm() < 1e-12);
        // a dent makes it non-convex
        let dented = cube.replace("v 1 1 1", "v 0.4 0.4 0.4");
        assert!(crate::scene::spatial::ConvexMesh::from_obj(&dented).is_err());
    }

    /// A planar push of a box in 3-D gives the planar model's answer (same pad points).
    #[test]
    fn planar_case_matches_the_planar_model() {
        let s3 = block3(LEFT);
        let s2 = Scene::from_toml_str(include_str!("../../../../examples/block-low-friction.toml")).unwrap();
        let opts = Options { support: SupportModel::Points { rings: 0, points: 8, merge_fingers: false }, ..Options::default() };
        let i2 = s2.pusher_index("left").unwrap();
        let i3 = s3.pusher_index("left").unwrap();
        for u2 in [[0.01, 0.0, 0.0], [0.01, 0.002, 0.1], [0.002, 0.01, 0.0], [0.005, -0.004, -0.4]] {
            let out2 = crate::dynamics::planar::push_outcome(&s2, &[0.0, 0.0, 0.0], i2, &crate::mechanics::geometry::Vec3::from(u2), &opts).unwrap();
            // planar [vx, vz, ω] (ω counter-clockwise in the X-Z drawing) = spatial [vx, 0, vz, 0, −ω, 0]
            let u3 = [u2[0], 0.0, u2[1], 0.0, -u2[2], 0.0];
            let p3 = push_problem(&s3, &Isometry3::identity(), i3, 1.0).unwrap();
            let sol = mncp::solve_forward(&p3, &DVector::from_row_slice(&u3), &Settings::default()).unwrap();
            assert!(sol.residuals.max() < 1e-6);
            let v3 = [sol.twist[0], sol.twist[2], -sol.twist[4]];
            let v2 = out2.solution.twist;
            for k in 0..3 {
                assert!((v3[k] - v2[k]).abs() < 1e-7 * (1.0 + v2[k].abs()), "{u2:?}: 3-D {v3:?} vs planar {v2}");
            }
            assert!(sol.twist[1].abs() < 1e-9 && sol.twist[3].abs() < 1e-7 && sol.twist[5].abs() < 1e-7, "{}", sol.twist);
        }
    }

    #[test]
    fn time_stepping_moves_the_box_with_a_sticking_pusher() {
        let s3 = block3(LEFT);
        let tr = simulate_push(&s3, &Isometry3::identity(), 0, &[0.01, 0.0, 0.0, 0.0, 0.0, 0.0], 1.0, 0.1, &Settings::default()).unwrap();
        let last = tr.pose.last().unwrap();
        assert!((last[0] - 0.01).abs() < 1e-6 && last[2].abs() < 1e-6, "{last:?}");
        assert!(tr.residual.iter().all(|r| *r < 1e-6));
        assert!(tr.pusher_sticking.iter().all(|n| *n == 2));
    }

    #[test]
    fn icosphere_is_a_closed_convex_sphere() {
        let m = crate::scene::spatial::ConvexMesh::icosphere(0.02, 2);
        assert_eq!(m.triangles.len(), 320);
        assert!(m.vertices.iter().all(|v| (v.norm() - 0.02).abs() < 1e-12));
        let (vol, c, _) = m.mass_properties();
        let ball = 4.0 / 3.0 * std::f64::consts::PI * 0.02f64.powi(3);
        assert!(vol < ball && vol > 0.95 * ball && c.norm() < 1e-9, "{vol} vs {ball}");
    }

    /// A plane touches the object where it is lowest along its normal: a sphere's one point, a
    /// box's face (4 vertices) or edge (2).
    #[test]
    fn planes_touch_the_lowest_points() {
        let ball = ball3();
        let q = Isometry3::from_parts(Translation3::new(0.001, 0.0, 0.002), UnitQuaternion::from_scaled_axis(V3::new(0.3, 0.7, -0.2)));
        let (pts, n) = ball.pusher_contacts(0, &q);
        assert_eq!(pts.len(), 1);
        // in the gripper frame: straight below the centre, normal up
        assert!(((q.rotation * pts[0]) - V3::new(0.0, 0.0, -0.035)).norm() < 1e-12 && ((q.rotation * n) - V3::z()).norm() < 1e-12);
        let boxy = block3(&format!("{}\n{LEFT}", floor(0.5)));
        assert_eq!(boxy.pusher_contacts(0, &Isometry3::identity()).0.len(), 4);
        let tilted = Isometry3::from_parts(Translation3::identity(), UnitQuaternion::from_scaled_axis(V3::new(0.0, 0.3, 0.0)));
        assert_eq!(boxy.pusher_contacts(0, &tilted).0.len(), 2);
        // a floor rising under the box lifts it on its whole face: 4 contacts, all sticking
        let tr = simulate_push(&boxy, &Isometry3::identity(), 0, &[0.0, 0.0, 0.005, 0.0, 0.0, 0.0], 1.0, 0.1, &Settings::default()).unwrap();
        assert!(tr.residual.iter().all(|r| *r < 1e-6) && tr.pusher_sticking.iter().all(|n| *n == 4), "{:?}", tr.pusher_sticking);
        assert!((tr.pose.last().unwrap()[2] - 0.005).abs() < 1e-6);
        // the ball off its pads: a pad touches only where the ball's extreme point is on it
        let off = Isometry3::from_parts(Translation3::new(0.0, 0.0, 0.007), UnitQuaternion::identity());
        assert!(ball.pad_contacts(&off).iter().all(|c| c.is_empty()));
        assert!(!ball.pads_on(&off) && ball.pads_on(&q));
    }

    /// The floor moving under the held ball rolls it: the ball turns about the grasp axis by
    /// the floor's travel over its radius (less the pads' yielding), every step meets the
    /// complementarity conditions, the floor contact sticks, and the contact point moves over
    /// the ball (it is always the lowest point).
    #[test]
    fn a_floor_rolls_the_ball() {
        let ball = ball3();
        let q0 = Isometry3::identity();
        let w = 0.2;
        let u = crate::planning::spatial::pusher_motion(&ball, &q0, 0, &[0.0, 0.0, 0.0, 0.0, w, 0.0]);
        // a level floor: no rotation; it slides at the contact point's speed and presses a little
        assert!(u[3].abs() + u[4].abs() + u[5].abs() < 1e-15);
        assert!((u[0] + w * 0.035).abs() < 1e-12 && (u[2] - crate::planning::spatial::PLANE_PRESS * w * 0.035).abs() < 1e-12, "{u:?}");
        let tr = simulate_push(&ball, &q0, 0, &u, 1.0, 0.1, &Settings::default()).unwrap();
        assert!(tr.residual.iter().all(|r| *r < 1e-6), "{:?}", tr.residual);
        assert!(tr.pusher_sticking.iter().all(|n| *n == 1), "{:?}", tr.pusher_sticking);
        let end = crate::scene::spatial::pose_from_array("pose", tr.pose.last().unwrap()).unwrap();
        let (axis, ang) = end.rotation.axis_angle().unwrap();
        assert!((axis.y - 1.0).abs() < 1e-6 && ang > 0.9 * w && ang < 1.1 * w, "{axis:?} {ang}");
        // the material point first touched has turned up, off the floor, by R (1 - cos θ) (a
        // rigid point pusher fixed on it would have lost contact), yet the floor kept a sticking
        // contact at every step: the contact point moved over the ball
        let c0 = ball.pusher_contacts(0, &q0).0[0];
        let lift = (end.rotation * c0).z + 0.035;
        assert!((lift - 0.035 * (1.0 - ang.cos())).abs() < 1e-6 && lift > 1e-4, "{lift}");
        assert!(tr.pusher_contacts.iter().all(|n| *n == 1));
    }

    #[test]
    fn exp_map_composes() {
        let p = integrate(&Isometry3::identity(), &[0.0, 0.0, 1.0, 0.0, std::f64::consts::PI, 0.0], 1.0);
        // a half turn about y while moving along z: a semicircle of diameter 2/π in x
        assert!((p.translation.x - 2.0 / std::f64::consts::PI).abs() < 1e-12, "{p}");
    }
}
