//! Infeasibility certificates: regrasps decided unreachable before any search (planar; in 3-D,
//! a goal the pads cannot hold, [`cannot_hold3`]).
//!
//! Wherever the grasp is, the whole finger pad lies on the object, so the pad's centre (object
//! frame) stays in the outline eroded by the radius r of the largest disc inside the pad — for
//! a disc pad exactly the admissible set at every θ, for a rectangle a superset of it (a pad
//! that fits holds its inscribed disc). A push moves that centre continuously, so it never
//! leaves the connected component of the eroded outline it starts in: a goal whose pad centre,
//! anywhere within the goal tolerance, lies in another component is unreachable (e.g. two lobes
//! joined by a neck narrower than the pad). The erosion is `geo`'s buffer (i_overlay) with bevel
//! joins (a chord across each arc about a reflex vertex: the set only grows), of the outline
//! simplified by Ramer–Douglas–Peucker within ε = [`SIMPLIFY`]·r (the buffer's cost grows
//! steeply with the vertices: 0.04 s at 1,000, 5 s at 10,000), by [`ERODE`]·r − 2ε: every
//! shortening only enlarges the set, so the certificate errs towards "reachable", never the other
//! way.
//!
//! A goal where the grasp cannot hold the object against gravity is unreachable too: the object
//! cannot rest there ([`cannot_hold`]). So is a goal whose pad centre lies, beyond its
//! tolerance, in a direction no push can move the pad's centre: when the pushers' friction cones
//! and gravity over the planner's turn range all push it within less than a half-plane
//! ([`blocked`], [`one_way`]), or, with gravity weighed against the pads' friction, when no push
//! can move it along the goal's direction at any pose ([`never_along`]).

use crate::mechanics::geometry::{Vec2, Vec3};
use crate::scene::planar::Support;
use crate::scene::Scene;
use crate::scene::spatial::Scene3;
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use geo::algorithm::buffer::{BufferStyle, LineJoin};
use geo::{Buffer, Contains, Distance, Euclidean, LineString, MultiPolygon, Point, Polygon, Simplify, Validation};

/// The share of the pad's inscribed radius by which the outline is eroded (below 1: a margin for
/// the buffer's rounding).
pub const ERODE: f64 = 0.98;
/// The outline's simplification tolerance, a share of the pad's inscribed radius.
pub const SIMPLIFY: f64 = 0.01;
/// The most vertices the buffer is run on when the simplified outline is not a valid polygon
/// (the original is then used; beyond this, no certificate).
pub const MAX_VERTICES: usize = 1000;

/// Why no plan can take the object from `start` to `goal` (poses `[x, z, θ]`, goal tolerance
/// `tol` per component, m, m, rad), when the pad's region decides it; None when it does not
/// (the search must answer).
pub fn unreachable(scene: &Scene, start: &[f64; 3], goal: &[f64; 3], tol: &[f64; 3]) -> Option<String> {
    let (cs, r) = scene.pad_disc(start)?;
    let (cg, _) = scene.pad_disc(goal)?;
    let region = pad_region(scene, r, LineJoin::Bevel)?;
    let point = |c: &Vec2| Point::new(c.x, c.y);
    let part = region.0.iter().find(|p| p.contains(&point(&cs)))?;
    // how far the goal region's pad centres reach from the goal's: the tolerance's translation,
    // and its turn swinging the centre, |c| ≤ |t| + |Δt|, by at most that many radians
    let shift = tol[0].hypot(tol[1]);
    let slack = shift + (goal[0].hypot(goal[1]) + shift) * tol[2];
    let gap = Euclidean.distance(part, &point(&cg));
    (gap > slack + 1e-9).then(|| {
        format!(
            "the pad's centre must stay where the whole pad ({:.2} mm across at its narrowest) lies on the object: \
             inside the outline shrunk by {:.2} mm, which splits into {} parts; the start's pad centre \
             ({:.2}, {:.2}) mm and the goal's ({:.2}, {:.2}) mm lie in different parts, the goal's \
             {:.2} mm beyond the start's part (the goal tolerance reaches {:.2} mm)",
            2e3 * r, 1e3 * r, region.0.len(), 1e3 * cs.x + 0.0, 1e3 * cs.y + 0.0, 1e3 * cg.x + 0.0, 1e3 * cg.y + 0.0, 1e3 * gap, 1e3 * slack
        )
    })
}

/// Grid points per axis of the goal's tolerance box where [`cannot_hold`] evaluates the grasp.
pub const HOLD_GRID: usize = 5;

/// Why the object cannot end within the goal's tolerance `tol` of `goal` (`[x, z, θ]`, m, m,
/// rad): the support holds it nowhere there. The hold ratio (≥ 1: the support's friction cannot
/// carry the weight) is evaluated on a [`HOLD_GRID`]³ grid of the box and must exceed 1
/// everywhere by the largest change between neighbouring grid points. At a fixed turn the ratio
/// is the norm of an affine function of the pad's position (convex: between grid points it stays
/// above the plane through them, within that change of their values), and it varies slowly with
/// the turn, so the answer errs towards "reachable" (checked against a 21³ grid in the tests);
/// None when some pose may hold.
pub fn cannot_hold(scene: &Scene, goal: &[f64; 3], tol: &[f64; 3]) -> Option<String> {
    if tol.iter().all(|&t| t == 0.0) {
        let h = scene.hold_ratio(goal);
        return (h >= 1.0).then(|| hold_reason(h));
    }
    let n = HOLD_GRID;
    let at = |k: usize, i: usize| goal[k] + tol[k] * (2.0 * i as f64 / (n - 1) as f64 - 1.0);
    let mut h = vec![0.0; n * n * n];
    let idx = |i: usize, j: usize, k: usize| (i * n + j) * n + k;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                h[idx(i, j, k)] = scene.hold_ratio(&[at(0, i), at(1, j), at(2, k)]);
            }
        }
    }
    if !h.iter().all(|x| x.is_finite()) {
        return None;
    }
    let mut step: f64 = 0.0;
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let here = h[idx(i, j, k)];
                for (a, b, c) in [(i + 1, j, k), (i, j + 1, k), (i, j, k + 1)] {
                    if a < n && b < n && c < n {
                        step = step.max((h[idx(a, b, c)] - here).abs());
                    }
                }
            }
        }
    }
    let low = h.iter().copied().fold(f64::INFINITY, f64::min);
    (low >= 1.0 + step).then(|| hold_reason(low))
}

fn hold_reason(ratio: f64) -> String {
    format!(
        "the grasp cannot hold the object against gravity anywhere within the goal's tolerance: the weight needs at \
         least {:.0} % of what the support's friction can carry there (the grip force or the friction too low for that pose)",
        100.0 * ratio
    )
}

/// The pad centres' region: the outline eroded by a little less than `r` (see the module's
/// notes), the arcs about reflex corners joined by `join`; None when the outline is too large to
/// erode quickly.
pub(crate) fn pad_region(scene: &Scene, r: f64, join: LineJoin<f64>) -> Option<MultiPolygon<f64>> {
    let ring: Vec<(f64, f64)> = scene.outline.vertices().iter().map(|v| (v.x, v.y)).collect();
    let outline = Polygon::new(LineString::from(ring), vec![]);
    let eps = SIMPLIFY * r;
    let simple = outline.simplify(eps);
    let small = |p: &Polygon<f64>| p.exterior().0.len() <= MAX_VERTICES; // the validity test is quadratic too
    let (shape, eps) = if small(&simple) && simple.is_valid() { (simple, eps) } else { (outline, 0.0) };
    if !small(&shape) {
        return None;
    }
    Some(shape.buffer_with_style(BufferStyle::new(-(ERODE * r - 2.0 * eps)).line_join(join)))
}

/// The directions the pad's centre can never move in (object frame), as an arc of unit
/// vectors `d` with `d·u ≤ 0` for every velocity `u` of the pad's centre, at every turn in
/// `turn` (rad): its middle angle and half-width (rad). None when every direction is possible.
///
/// On the grasp's ellipsoidal limit surface (eq 3.7), the object's velocity at the pad's centre
/// is `B_ff` times the force on it (pushers' plus gravity's; `B` has no force–moment coupling for
/// the disc and rectangle pads; on a disc's exact surface the two are parallel), so the pad's centre moves along `−B_ff (f_p + f_g)`: within the
/// cone of the pushers' Coulomb edges `−f` and of gravity's directions `−Rᵀ(θ) d` over the turn,
/// each widened by the angle `B_ff`'s anisotropy can bend a vector. When that cone is pointed
/// (narrower than π), the directions at least 90° from all of it are blocked.
pub fn blocked(scene: &Scene, turn: [f64; 2]) -> Option<(f64, f64)> {
    let Support::Grasp(g) = &scene.support else { return None };
    let b = &g.limit_surface.b;
    let (beta, coupling, aniso) = match &g.exact {
        // an axisymmetric pad's force is along its centre's velocity (mirror symmetry)
        Some(e) if e.region().axisymmetric() => (1.0, 0.0, 0.0),
        Some(_) => return None,
        None => (0.5 * (b[(0, 0)] + b[(1, 1)]), b[(0, 2)].abs() + b[(1, 2)].abs(), (0.5 * (b[(0, 0)] - b[(1, 1)])).hypot(b[(0, 1)])),
    };
    if !(beta > 0.0) || coupling > 1e-9 * beta || aniso >= 0.5 * beta || !turn.iter().all(|t| t.is_finite()) {
        return None;
    }
    let bend = (aniso / beta).asin() + 1e-9;
    // velocity directions of the pad's centre: arcs [a, a + w]
    let mut arcs: Vec<(f64, f64)> = Vec::new();
    for p in &scene.pushers {
        for e in p.contact.edge_wrenches() {
            let f = Vec2::new(e.wrench.x, e.wrench.y);
            if f.norm() > 0.0 {
                arcs.push(((-f.y).atan2(-f.x) - bend, 2.0 * bend));
            }
        }
    }
    if gravity_in_plane(scene) {
        let a = (-scene.gravity_dir.y).atan2(-scene.gravity_dir.x); // −d; Rᵀ(θ) turns it by −θ
        arcs.push((a - turn[1] - bend, turn[1] - turn[0] + 2.0 * bend));
    }
    let mut angles: Vec<f64> = Vec::new();
    for (a, w) in arcs {
        if w >= std::f64::consts::PI {
            return None;
        }
        let n = (w / 0.25).ceil() as usize + 1; // samples 0.25 rad apart at most: no gap inside an arc
        angles.extend((0..n).map(|k| (a + w * k as f64 / (n - 1).max(1) as f64).rem_euclid(std::f64::consts::TAU)));
    }
    if angles.is_empty() {
        return None;
    }
    angles.sort_by(f64::total_cmp);
    // the largest gap between neighbouring directions: the velocities lie in its complement
    let (mut gap, mut after) = (angles[0] + std::f64::consts::TAU - angles[angles.len() - 1], angles[0]);
    for w in angles.windows(2) {
        if w[1] - w[0] > gap {
            (gap, after) = (w[1] - w[0], w[1]);
        }
    }
    let span = std::f64::consts::TAU - gap;
    (span < std::f64::consts::PI - 1e-9).then(|| (after + 0.5 * span + std::f64::consts::PI, 0.5 * (std::f64::consts::PI - span)))
}

/// Why no plan whose turn stays within `turn` (rad: the range the planner samples, the start's
/// and the goal's turns widened by `theta_margin`) can take the pad's centre from the start's to
/// the goal's: it would have to move in a direction no push can move it ([`blocked`]) by more
/// than the goal tolerance `tol` allows; None when that does not decide it. Without in-plane
/// gravity the turn does not matter and the answer holds for every plan; with it, a plan turning
/// the object further (gravity then pulls another way in the object's frame) is not excluded.
pub fn one_way(scene: &Scene, start: &[f64; 3], goal: &[f64; 3], tol: &[f64; 3], turn: [f64; 2]) -> Option<String> {
    let (cs, _) = scene.pad_disc(start)?;
    let (cg, _) = scene.pad_disc(goal)?;
    let delta = cg - cs;
    let shift = tol[0].hypot(tol[1]);
    let slack = shift + (goal[0].hypot(goal[1]) + shift) * tol[2];
    let within = |any_turn: bool| {
        if !gravity_in_plane(scene) {
            String::new()
        } else if any_turn {
            " at any turn in the grasp (the object's weight, against the pads' friction, cannot turn the pushes' forces that far)".to_string()
        } else {
            format!(
                " while the object's turn in the grasp stays within {:.3}..{:.3} rad (the planner's range, the start's and the goal's \
                 turns widened by theta_margin: widen it to consider larger turns, which let gravity pull another way)",
                turn[0], turn[1]
            )
        }
    };
    let say = |d: Vec2, any_turn: bool| {
        format!(
            "no push can move the pad's centre along ({:.3}, {:.3}) in the object's frame{} (the pushers' friction cones and \
             gravity all push it the other way), and the goal needs {:.2} mm of it (the goal tolerance reaches {:.2} mm)",
            d.x + 0.0, d.y + 0.0, within(any_turn), 1e3 * d.dot(&delta), 1e3 * slack
        )
    };
    if let Some((mid, half)) = blocked(scene, turn) {
        // the blocked direction closest to Δ: its angle clamped into the arc
        let off = (delta.y.atan2(delta.x) - mid + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let a = mid + off.clamp(-half, half);
        let d = Vec2::new(a.cos(), a.sin());
        if d.dot(&delta) > slack + 1e-9 {
            return Some(say(d, false));
        }
    }
    // gravity weighed against the pads' friction: along Δ, then turned from it by up to 60°
    if !(delta.norm() > slack + 1e-9) {
        return None;
    }
    let along = delta.y.atan2(delta.x);
    let corners = pad_corners(scene)?;
    for (k, any_turn) in [(0, true), (0, false), (1, false), (-1, false), (2, false), (-2, false), (3, false), (-3, false)] {
        let a = along + k as f64 * std::f64::consts::PI / 9.0;
        let d = Vec2::new(a.cos(), a.sin());
        let range = if any_turn { [-std::f64::consts::PI, std::f64::consts::PI] } else { turn };
        if d.dot(&delta) > slack + 1e-9 && never_along_from(scene, &d, range, &corners) {
            return Some(say(d, any_turn));
        }
    }
    None
}

/// The turn grid of [`never_along`] [rad]: between neighbouring turns the load is bounded by its
/// Lipschitz constant.
pub const TURN_STEP: f64 = 0.005;

/// The most poses (corners × turns) [`never_along`] evaluates; beyond it the answer is "not
/// shown" (a few tenths of a second of work at most before the search).
pub const MAX_POSES: usize = 200_000;

/// The vertices of the convex hull of the pad centres' region ([`pad_region`], or the outline
/// when it is too large to erode): a convex function of the pad's centre is largest at one.
fn pad_corners(scene: &Scene) -> Option<Vec<Vec2>> {
    use geo::ConvexHull;
    let (_, r) = scene.pad_disc(&[0.0; 3])?;
    let hull = match pad_region(scene, r, LineJoin::Bevel) {
        Some(region) => region.convex_hull(),
        None => {
            let ring: Vec<(f64, f64)> = scene.outline.vertices().iter().map(|v| (v.x, v.y)).collect();
            Polygon::new(LineString::from(ring), vec![]).convex_hull()
        }
    };
    Some(hull.exterior().0.iter().map(|c| Vec2::new(c.x, c.y)).collect())
}

/// Whether no push can move the pad's centre along the unit direction `d` (object frame) at any
/// turn within `turn` (rad), gravity weighed against the pads' friction; false when that is not
/// shown (or the pad is not isotropic: disc pads only).
///
/// The pad's centre moves along `−f` (`f = f_g + f_p`, the force on the object; an isotropic pad
/// without force–moment coupling), and only while the load `w_g + t·p` is on the limit surface
/// (`‖·‖ = 1`, the grasp's norm at the pad's centre `c`; `‖w_g‖ < 1` where it holds). With every
/// pusher edge `eᵢ = (fᵢ, mᵢ)` having `d·fᵢ > 0`, write pushes as `p = Σλᵢêᵢ`, `êᵢ = eᵢ/(d·fᵢ)`,
/// `Σλᵢ = 1`: `d·f` grows along the ray and is 0 at `t₀ = g = max(0, −d·f_g)`, so the pad moves
/// along `d` only if the ray leaves the surface before `t₀`, i.e. `‖w_g + g·p‖ > 1`. That norm
/// is convex in `λ` (largest at an edge) and in `c` (largest at a vertex of the convex hull of the
/// pad centres' region, [`pad_region`]); over the turn it is checked every [`TURN_STEP`] with the margin its
/// Lipschitz constant allows (`|f_g|` times the norm's force and moment gains and the arms).
pub fn never_along(scene: &Scene, d: &Vec2, turn: [f64; 2]) -> bool {
    pad_corners(scene).is_some_and(|corners| never_along_from(scene, d, turn, &corners))
}

/// [`never_along`] over the pad centres' hull `corners`.
fn never_along_from(scene: &Scene, d: &Vec2, turn: [f64; 2], corners: &[Vec2]) -> bool {
    let Support::Grasp(g) = &scene.support else { return false };
    let b = &g.limit_surface.b;
    let isotropic = match &g.exact {
        Some(e) => e.region().axisymmetric(),
        None => (b[(0, 0)] - b[(1, 1)]).abs() <= 1e-12 * b[(0, 0)].abs() && b[(0, 1)] == 0.0 && b[(0, 2)] == 0.0 && b[(1, 2)] == 0.0,
    };
    if !isotropic || !turn.iter().all(|t| t.is_finite()) || turn[1] < turn[0] {
        return false;
    }
    let mut edges: Vec<Vec3> = Vec::new();
    for p in &scene.pushers {
        for e in p.contact.edge_wrenches() {
            let s = d.x * e.wrench.x + d.y * e.wrench.y;
            if !(s > 1e-12 * e.wrench.xy().norm()) {
                return false; // this edge alone moves the pad's centre along d (or across it)
            }
            edges.push(e.wrench / s);
        }
    }
    let f0 = scene.frame(&[0.0; 3]);
    // the norm of a wrench given at the object's origin, at frame `f`'s pad centre
    let load = |f: &crate::cones::motion_cone::SupportFrame, w: &Vec3| {
        let u = f.js_inv.tr_mul(w);
        match &f.exact {
            Some((surface, s)) => surface.gauge(&(u / *s)),
            None => u.dot(&(f.a * u)).sqrt(),
        }
    };
    let (nf, nm) = (load(&f0, &Vec3::new(1.0, 0.0, 0.0)), load(&f0, &Vec3::new(0.0, 0.0, 1.0)));
    let weight = f0.gravity.xy().norm();
    let turns = ((turn[1] - turn[0]) / TURN_STEP).ceil().max(1.0);
    if corners.len() as f64 * (turns + 1.0) > MAX_POSES as f64 {
        return false; // checked as floats: a huge turn range must not overflow the count
    }
    let n = turns as usize;
    let step = (turn[1] - turn[0]) / n as f64;
    let cross = |a: &Vec2, b: &Vec3| a.x * b.y - a.y * b.x;
    for c in corners {
        // the load's Lipschitz constant in the turn, per edge: |f_g| (nf (1 + |f̂|) + nm (|com − c| + |m̂ − c × f̂|))
        let lip: Vec<f64> = edges
            .iter()
            .map(|e| weight * (nf * (1.0 + e.xy().norm()) + nm * ((scene.com - c).norm() + (e.z - cross(c, e)).abs())))
            .collect();
        for k in 0..=n {
            let th = turn[0] + step * k as f64;
            let (sn, cs) = th.sin_cos();
            // the pose whose pad centre is c at turn θ: c = −Rᵀ(θ) t
            let t = -Vec2::new(cs * c.x - sn * c.y, sn * c.x + cs * c.y);
            let f = scene.frame(&[t.x, t.y, th]);
            let gd = (-d.dot(&f.gravity.xy())).max(0.0);
            for (e, l) in edges.iter().zip(&lip) {
                if load(&f, &(f.gravity + e * gd)) + 0.5 * step * l > 1.0 {
                    return false;
                }
            }
        }
    }
    true
}

/// Whether gravity pulls in the object's plane (it then depends on the turn).
fn gravity_in_plane(scene: &Scene) -> bool {
    scene.mass * scene.g_plane() > 0.0 && scene.gravity_dir.norm() > 0.0
}

/// 3-D: how much of the pads' friction the object's weight needs at `pose` (gripper frame): the
/// least factor `s` on the pads' Coulomb coefficients at which friction forces inside every pad
/// point's disc (radius `s μ N`) hold the object at rest against gravity and the pads' normal
/// forces (eq 3.13 at a zero twist) — one second-order cone program (clarabel) minimizing `s`;
/// < 1: the grasp holds. None when the pads do not both touch there (or a pad is not a point
/// set); infinity when no friction would hold it (e.g. gravity along the grasp axis).
pub fn hold_ratio3(scene: &Scene3, pose: &Isometry3<f64>) -> Option<f64> {
    use crate::dynamics::mncp::{FrictionLaw, NormalLaw};
    use clarabel::algebra::CscMatrix;
    use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
    if !scene.pads_on(pose) {
        return None;
    }
    let p = crate::dynamics::spatial::problem(scene, pose, None, 1.0, 0.01).ok()?;
    let (d, fs) = (p.dim, p.force_scale);
    let mut laws = Vec::with_capacity(p.contacts.len());
    for c in &p.contacts {
        match (&c.normal, &c.friction) {
            (NormalLaw::Fixed(n), FrictionLaw::Coulomb(mu)) => laws.push((*n, *mu)),
            _ => return None,
        }
    }
    let nf: usize = p.contacts.iter().map(|c| c.tangent_dim()).sum();
    let n = nf + 1; // the friction forces (in units of the force scale), then s
    // balance: Σ J_tᵀ f = −(w + Σ J_n N)
    let mut rhs = -&p.wrench;
    for (c, (nn, _)) in p.contacts.iter().zip(&laws) {
        rhs -= &c.jn * *nn;
    }
    let rows = d + nf + p.contacts.len();
    let mut a = vec![vec![0.0; n]; rows];
    let mut b = vec![0.0; rows];
    let mut cones = vec![SupportedConeT::ZeroConeT(d)];
    let mut col = 0;
    let mut row = d;
    for (c, (nn, mu)) in p.contacts.iter().zip(&laws) {
        let k = c.tangent_dim();
        for i in 0..d {
            for j in 0..k {
                a[i][col + j] = c.jt[(j, i)];
            }
        }
        // (μ N s, f) in the second-order cone: z = b − A x
        a[row][nf] = -mu * nn / fs;
        for j in 0..k {
            a[row + 1 + j][col + j] = -1.0;
        }
        cones.push(SupportedConeT::SecondOrderConeT(k + 1));
        row += k + 1;
        col += k;
    }
    for i in 0..d {
        b[i] = rhs[i] / fs;
    }
    let mut q = vec![0.0; n];
    q[nf] = 1.0;
    let pm = CscMatrix::zeros((n, n));
    let cfg = DefaultSettings { verbose: false, tol_gap_abs: 1e-10, tol_gap_rel: 1e-10, tol_feas: 1e-10, ..DefaultSettings::default() };
    let mut solver = DefaultSolver::new(&pm, &q, &CscMatrix::from(&a), &b, &cones, cfg).ok()?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            let s = solver.solution.x[nf];
            s.is_finite().then_some(s.max(0.0))
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => Some(f64::INFINITY),
        _ => None,
    }
}

/// 3-D: why the object cannot end within the goal's tolerance `tol` (`[x, y, z]` m, angle rad) of
/// `goal`: the pads hold it nowhere there. Decided only when the goal itself cannot hold and the
/// start can (otherwise the model's holding is not the question). The hold ratio
/// ([`hold_ratio3`]) is evaluated on a grid of the tolerance region: the goal's translation
/// ±`tol` along each axis (3³) at its rotation turned about the grasp axis by 0 and ±`tol[3]`,
/// and about the two others by ±`tol[3]` and ±`tol[3]`/2 (a turn out of the pads' plane makes the
/// pads touch an edge or a corner instead of a face: another contact, another family of poses).
/// In each family (the same pad contacts) the ratio must exceed 1 by the family's largest change
/// between neighbouring grid poses; the answer errs towards "reachable" (checked against a finer grid in
/// the tests); None when some pose may hold.
pub fn cannot_hold3(scene: &Scene3, start: &Isometry3<f64>, goal: &Isometry3<f64>, tol: &[f64; 4]) -> Option<String> {
    // the usual case at the cost of one cone program: the goal holds
    if hold_ratio3(scene, goal)? < 1.0 || !(hold_ratio3(scene, start)? < 1.0) {
        return None;
    }
    let a = tol[3];
    let turn = |k: usize, x: f64| UnitQuaternion::from_scaled_axis(Vector3::ith(k, x));
    let turns = [
        turn(1, 0.0), turn(1, -a), turn(1, a),
        turn(0, -a), turn(0, -0.5 * a), turn(0, 0.5 * a), turn(0, a),
        turn(2, -a), turn(2, -0.5 * a), turn(2, 0.5 * a), turn(2, a),
    ];
    // neighbouring turns: about the grasp axis, and along each tilt
    let near = [(0, 1), (0, 2), (3, 4), (5, 6), (7, 8), (9, 10), (0, 4), (0, 5), (0, 8), (0, 9)];
    let mut grid = vec![(f64::INFINITY, [0usize; 2]); 27 * turns.len()];
    for (t, q) in turns.iter().enumerate() {
        for c in 0..27 {
            let shift = Vector3::new((c % 3) as f64 - 1.0, ((c / 3) % 3) as f64 - 1.0, (c / 9) as f64 - 1.0);
            let at = Isometry3::from_parts(
                (goal.translation.vector + shift.component_mul(&Vector3::new(tol[0], tol[1], tol[2]))).into(),
                q * goal.rotation,
            );
            let pads = scene.pad_contacts(&at);
            // a pose where the pads do not both touch is no goal: it holds nothing
            grid[t * 27 + c] = (hold_ratio3(scene, &at).unwrap_or(f64::INFINITY), [pads[0].len(), pads[1].len()]);
        }
    }
    // per family (the same pad contacts): its lowest ratio and largest change between neighbours
    let mut families: Vec<([usize; 2], f64, f64)> = Vec::new();
    for g in grid.iter().filter(|g| g.0.is_finite()) {
        match families.iter_mut().find(|f| f.0 == g.1) {
            Some(f) => f.1 = f.1.min(g.0),
            None => families.push((g.1, g.0, 0.0)),
        }
    }
    let mut pair = |a: (f64, [usize; 2]), b: (f64, [usize; 2])| {
        if a.0.is_finite() && b.0.is_finite() && a.1 == b.1 {
            if let Some(f) = families.iter_mut().find(|f| f.0 == a.1) {
                f.2 = f.2.max((a.0 - b.0).abs());
            }
        }
    };
    for t in 0..turns.len() {
        for c in 0..27 {
            let (x, y, z) = (c % 3, (c / 3) % 3, c / 9);
            let here = grid[t * 27 + c];
            if x < 2 { pair(here, grid[t * 27 + c + 1]) }
            if y < 2 { pair(here, grid[t * 27 + c + 3]) }
            if z < 2 { pair(here, grid[t * 27 + c + 9]) }
        }
    }
    for (t, u) in near {
        for c in 0..27 {
            pair(grid[t * 27 + c], grid[u * 27 + c]);
        }
    }
    let low = families.iter().map(|f| f.1).fold(f64::INFINITY, f64::min);
    (!families.is_empty() && families.iter().all(|f| f.1 >= 1.0 + f.2)).then(|| hold_reason(low))
}
