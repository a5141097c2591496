//! Spatial scenes (TOML, `dimension = 3`): an object that is a box, a convex mesh or a sphere,
//! a parallel-jaw grasp with circular pads, gravity, pushers and fixed features as rigid point
//! sets (point, line or patch contacts) or as planes (the ground, a wall: a rolling contact,
//! wherever the object touches the plane), and the task as 3-D poses.
//!
//! ```toml
//! dimension = 3
//! name = "block-pivot-3d"
//!
//! [object]
//! shape = "box"                    # or "mesh" with mesh = "part.obj" (convex, object frame),
//!                                  # or "sphere" with radius = 0.03 (centred on the frame)
//! size = [0.05, 0.012, 0.08]       # box: full size along the object's x, y, z [m]
//! mass = 0.13
//! # com = [0, 0, 0]                # default: the volume centroid
//!
//! [grasp]                          # fingers close along the gripper's Y axis
//! force = 20.0
//! friction = 0.6
//! pad_radius = 0.007
//!
//! [gravity]
//! direction = [0.0, 0.0, -1.0]     # gripper frame
//! g = 9.81
//!
//! [[pushers]]
//! name = "ground"
//! friction = 0.5
//! points = [[-0.025, -0.006, -0.04], [0.025, -0.006, -0.04], [0.025, 0.006, -0.04]]  # object frame
//! normal = [0.0, 0.0, 1.0]         # object frame, the direction the pusher pushes
//!
//! [[pushers]]                      # a plane: touches the object wherever it is lowest along
//! name = "floor"                   # `normal`, so the contact point moves over the object as it
//! friction = 0.8                   # rolls (a sphere on the ground); no `points`
//! plane = true
//! normal = [0.0, 0.0, 1.0]         # gripper frame (a floor: opposite to gravity)
//!
//! [task]
//! start = [0, 0, 0, 1, 0, 0, 0]    # [x, y, z, qw, qx, qy, qz]: object frame in the gripper frame
//! goal = [0, 0, 0, 1, 0, 0, 0]
//! tolerance = [0.001, 0.001, 0.001, 0.0175]   # position components, then the rotation angle
//! ```

use crate::error::{Error, Result};
use crate::scene::bounds;
pub use crate::pose::spatial::{from_array as pose_from_array, to_array as pose_to_array};
use nalgebra::{Isometry3, Matrix3, Vector3};

pub type V3 = Vector3<f64>;

/// A closed convex triangle mesh (object frame).
#[derive(Clone, Debug)]
pub struct ConvexMesh {
    pub vertices: Vec<V3>,
    pub triangles: Vec<[usize; 3]>,
    /// Outward unit normal and offset of each face plane: `n·x ≤ d` inside.
    pub planes: Vec<(V3, f64)>,
}

impl ConvexMesh {
    /// An icosphere of radius `r` (panics for a radius outside [`bounds::SIZE`]; scene files
    /// go through [`Self::try_icosphere`]).
    pub fn icosphere(r: f64, levels: usize) -> Self {
        Self::try_icosphere(r, levels).expect("an icosphere of a radius within bounds::SIZE is a convex mesh")
    }

    /// A box of full sizes `s`, centred at the origin (panics for sides outside
    /// [`bounds::SIZE`]; scene files go through [`Self::try_cuboid`]).
    pub fn cuboid(s: &V3) -> Self {
        Self::try_cuboid(s).expect("a box with sides within bounds::SIZE is a convex mesh")
    }

    /// An icosphere of radius `r`: an icosahedron subdivided `levels` (at most 4) times, vertices
    /// on the sphere (a drawing of a sphere; 20·4^levels triangles).
    pub fn try_icosphere(r: f64, levels: usize) -> std::result::Result<Self, String> {
        if !(r.is_finite() && r > 0.0) || levels > 4 {
            return Err(format!("an icosphere needs a positive finite radius and at most 4 levels (got {r}, {levels})"));
        }
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let mut v: Vec<V3> = [
            [-1.0, t, 0.0], [1.0, t, 0.0], [-1.0, -t, 0.0], [1.0, -t, 0.0], [0.0, -1.0, t], [0.0, 1.0, t],
            [0.0, -1.0, -t], [0.0, 1.0, -t], [t, 0.0, -1.0], [t, 0.0, 1.0], [-t, 0.0, -1.0], [-t, 0.0, 1.0],
        ]
        .iter()
        .map(|a| V3::new(a[0], a[1], a[2]).normalize())
        .collect();
        let mut f: Vec<[usize; 3]> = vec![
            [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
            [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
        ];
        for _ in 0..levels {
            let mut mid = std::collections::HashMap::new();
            let mut m = |a: usize, b: usize, v: &mut Vec<V3>| -> usize {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    v.push(((v[a] + v[b]) / 2.0).normalize());
                    v.len() - 1
                })
            };
            f = f
                .iter()
                .flat_map(|&[a, b, c]| {
                    let (ab, bc, ca) = (m(a, b, &mut v), m(b, c, &mut v), m(c, a, &mut v));
                    [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
                })
                .collect();
        }
        Self::new(v.into_iter().map(|x| x * r).collect(), f)
    }

    /// A box of full sizes `s`, centred at the origin.
    pub fn try_cuboid(s: &V3) -> std::result::Result<Self, String> {
        if !s.iter().all(|x| x.is_finite() && *x > 0.0) {
            return Err(format!("a box needs positive finite sides (got {:?})", s.as_slice()));
        }
        let h = s / 2.0;
        let v: Vec<V3> = (0..8)
            .map(|i| V3::new(if i & 1 == 0 { -h.x } else { h.x }, if i & 2 == 0 { -h.y } else { h.y }, if i & 4 == 0 { -h.z } else { h.z }))
            .collect();
        // faces as outward-oriented triangles
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut t = Vec::new();
        for q in quads {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        Self::new(v, t)
    }

    /// Validates a closed convex mesh with outward-oriented triangles.
    pub fn new(vertices: Vec<V3>, triangles: Vec<[usize; 3]>) -> std::result::Result<Self, String> {
        if vertices.len() < 4 || triangles.len() < 4 {
            return Err("a closed mesh needs at least 4 vertices and 4 triangles".into());
        }
        if vertices.len() > bounds::MAX_MESH_VERTICES || triangles.len() > bounds::MAX_MESH_TRIANGLES {
            return Err(format!(
                "has {} vertices and {} triangles; at most {} and {} are allowed",
                vertices.len(),
                triangles.len(),
                bounds::MAX_MESH_VERTICES,
                bounds::MAX_MESH_TRIANGLES
            ));
        }
        if vertices.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
            return Err("a vertex has a non-finite coordinate".into());
        }
        let scale = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        if !(scale.is_finite() && scale > 0.0) {
            return Err("the vertices' distances from the origin overflow or are all zero".into());
        }
        let mut planes = Vec::with_capacity(triangles.len());
        for (k, t) in triangles.iter().enumerate() {
            if t.iter().any(|&i| i >= vertices.len()) {
                return Err(format!("triangle {k} refers to a missing vertex"));
            }
            let (a, b, c) = (vertices[t[0]], vertices[t[1]], vertices[t[2]]);
            let n = (b - a).cross(&(c - a));
            if n.norm() <= 1e-14 * scale * scale {
                return Err(format!("triangle {k} is degenerate"));
            }
            let n = n.normalize();
            planes.push((n, n.dot(&a)));
        }
        // closed and consistently oriented: each directed edge once, and its reverse once
        let mut edges: Vec<(usize, usize)> = triangles.iter().flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])]).collect();
        edges.sort_unstable();
        if let Some(w) = edges.windows(2).find(|w| w[0] == w[1]) {
            return Err(format!("the edge between vertices {} and {} is used twice in the same direction (triangles not consistently oriented, or more than two at an edge)", w[0].0 + 1, w[0].1 + 1));
        }
        if let Some(&(a, b)) = edges.iter().find(|&&(a, b)| edges.binary_search(&(b, a)).is_err()) {
            return Err(format!("the mesh is not closed: the edge between vertices {} and {} borders one triangle only", a + 1, b + 1));
        }
        let m = Self { vertices, triangles, planes };
        let vol = m.mass_properties().0;
        if !(vol > 0.0 && vol.is_finite()) {
            return Err("the triangles are not oriented outwards (negative volume)".into());
        }
        for (k, (n, d)) in m.planes.iter().enumerate() {
            if m.vertices.iter().any(|v| n.dot(v) - d > 1e-9 * scale) {
                return Err(format!("the mesh is not convex (a vertex lies outside the plane of triangle {k})"));
            }
        }
        Ok(m)
    }

    /// Reads a Wavefront OBJ file (`v` and `f` lines; polygons are fanned into triangles) of one
    /// convex mesh.
    pub fn from_obj(text: &str) -> std::result::Result<Self, String> {
        let (v, parts) = read_obj(text)?;
        Self::new(v, parts.into_iter().flat_map(|(_, t)| t).collect())
    }

    /// The convex parts of a Wavefront OBJ file: each object or group (`o`, `g` lines) with
    /// faces is one closed convex mesh (one part when there are no such lines).
    pub fn parts_from_obj(text: &str) -> std::result::Result<Vec<Self>, String> {
        let (v, parts) = read_obj(text)?;
        let many = parts.len() > 1;
        parts
            .into_iter()
            .enumerate()
            .map(|(k, (name, t))| {
                // the part's own vertices, renumbered
                let mut used: Vec<usize> = t.iter().flatten().copied().collect();
                used.sort_unstable();
                used.dedup();
                if let Some(&i) = used.iter().find(|&&i| i >= v.len()) {
                    return Err(format!("part {k} ({name}): a face refers to vertex {} of {}", i + 1, v.len()));
                }
                let at = |i: usize| used.binary_search(&i).unwrap_or(0);
                let tri = t.iter().map(|f| [at(f[0]), at(f[1]), at(f[2])]).collect();
                Self::new(used.iter().map(|&i| v[i]).collect(), tri).map_err(|e| if many { format!("part {k} ({name}): {e}") } else { e })
            })
            .collect()
    }

    /// The convex hull of `points` (parry's quickhull), triangles outward.
    pub fn hull(points: &[V3]) -> std::result::Result<Self, String> {
        use parry3d_f64::math::Vector;
        let pts: Vec<Vector> = points.iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let (v, t) = parry3d_f64::transformation::try_convex_hull(&pts).map_err(|e| format!("no convex hull: {e:?}"))?;
        let v: Vec<V3> = v.iter().map(|p| V3::new(p.x, p.y, p.z)).collect();
        let c = v.iter().fold(V3::zeros(), |a, p| a + p) / v.len().max(1) as f64;
        // each triangle turned to face away from the hull's interior (its vertices' mean)
        let t = t
            .iter()
            .map(|f| {
                let [a, b, d] = [f[0] as usize, f[1] as usize, f[2] as usize];
                if (v[b] - v[a]).cross(&(v[d] - v[a])).dot(&(v[a] - c)) < 0.0 { [a, d, b] } else { [a, b, d] }
            })
            .collect();
        Self::new(v, t)
    }

    /// Volume, centroid and inertia about the centroid per unit density (divergence theorem
    /// over the tetrahedra from the origin).
    pub fn mass_properties(&self) -> (f64, V3, Matrix3<f64>) {
        let mut vol = 0.0;
        let mut c = V3::zeros();
        let mut cov = Matrix3::zeros();
        // canonical tetrahedron covariance
        let canon = Matrix3::new(2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0, 1.0, 2.0) / 120.0;
        for t in &self.triangles {
            let (a, b, d) = (self.vertices[t[0]], self.vertices[t[1]], self.vertices[t[2]]);
            let m = Matrix3::from_columns(&[a, b, d]);
            let det = m.determinant();
            vol += det / 6.0;
            c += (a + b + d) * det / 24.0;
            cov += m * canon * m.transpose() * det;
        }
        let com = c / vol;
        // covariance about the centroid, then inertia = tr(C) I − C
        let cov_c = cov - com * com.transpose() * vol;
        let inertia = Matrix3::identity() * cov_c.trace() - cov_c;
        (vol, com, inertia / vol)
    }

    /// Signed distance of `p` to the surface (positive outside; exact where a face is closest).
    pub fn signed_distance(&self, p: &V3) -> f64 {
        self.planes.iter().map(|(n, d)| n.dot(p) - d).fold(f64::NEG_INFINITY, f64::max)
    }
}

/// A pusher or fixed feature: a rigid set of points with a common normal (object frame), or a
/// plane (`plane`: `normal` in the gripper frame, `points` empty) that touches the object where
/// it is lowest along the normal.
#[derive(Clone, Debug)]
pub struct Pusher3 {
    pub name: String,
    pub friction: f64,
    pub points: Vec<V3>,
    pub normal: V3,
    pub plane: bool,
}

#[derive(Clone, Debug)]
pub struct Scene3 {
    pub name: String,
    /// The object's surface: exact for a box or a convex mesh, a drawing (an icosphere) for a
    /// sphere; for an object of several convex parts their convex hull (where a plane or a pad
    /// touches the object).
    pub mesh: ConvexMesh,
    /// A non-convex object's convex parts (their union is the object); empty for a convex one.
    pub parts: Vec<ConvexMesh>,
    /// A sphere's radius (centred on the object frame's origin): its exact surface.
    pub sphere: Option<f64>,
    pub mass: f64,
    pub com: V3,
    /// Inertia about the centre of mass [kg m²].
    pub inertia: Matrix3<f64>,
    pub grip_force: f64,
    pub grip_friction: f64,
    pub pad_radius: f64,
    pub gravity: V3,
    pub pushers: Vec<Pusher3>,
    pub start: Isometry3<f64>,
    pub goal: Isometry3<f64>,
    pub tolerance: [f64; 4],
    /// Characteristic length [m] (radius of gyration).
    pub length: f64,
    /// What the loader changed in the file's values (pusher points snapped onto the surface).
    pub notes: Vec<String>,
}

/// Signed distance to the object's surface: the sphere's exactly, else the mesh's.
pub(crate) fn surface_distance(mesh: &ConvexMesh, parts: &[ConvexMesh], sphere: Option<f64>, p: &V3) -> f64 {
    match sphere {
        Some(r) => p.norm() - r,
        // the union of the parts: exact outside, a bound inside
        None if !parts.is_empty() => parts.iter().map(|m| m.signed_distance(p)).fold(f64::INFINITY, f64::min),
        None => mesh.signed_distance(p),
    }
}

/// The error of `pose` to `goal` `[dx, dy, dz, angle]` (m, m, m, rad; the angle of the relative
/// rotation, in [0, π]) and whether each is within `tolerance` `[x, y, z, angle]`: the one test
/// of "is it at the goal?" for 3-D poses.
pub fn goal_error(pose: &Isometry3<f64>, goal: &Isometry3<f64>, tolerance: &[f64; 4]) -> ([f64; 4], bool) {
    let d = pose.translation.vector - goal.translation.vector;
    let angle = goal.rotation.angle_to(&pose.rotation);
    let e = [d.x, d.y, d.z, angle];
    (e, e.iter().zip(tolerance).all(|(x, t)| x.abs() <= *t))
}

impl Scene3 {
    /// What the loader changed in the file's values (pusher points snapped onto the surface).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// Signed distance of object-frame point `p` to the object's surface (positive outside).
    pub fn signed_distance(&self, p: &V3) -> f64 {
        surface_distance(&self.mesh, &self.parts, self.sphere, p)
    }

    /// The object's points lowest along `n` (object frame): where a plane with normal `n`
    /// touches it — a sphere's one point, a mesh's vertex, edge or face (its vertices within
    /// `1e-5` of the object's size of the lowest, so a face tilted by solver round-off stays a
    /// face).
    pub fn lowest_points(&self, n: &V3) -> Vec<V3> {
        self.plane_contacts(n, None, 1e-5 * self.size())
    }

    /// The object's points within `reach` of the plane with normal `n` through `on` (object
    /// frame; default: the plane touching the object's lowest point), with a mesh's every vertex
    /// considered (a vertex tipping towards the plane is found before it crosses it).
    pub fn plane_contacts(&self, n: &V3, on: Option<&V3>, reach: f64) -> Vec<V3> {
        let n = n.normalize();
        if let Some(r) = self.sphere {
            return vec![-n * r];
        }
        let low = match on {
            Some(p) => n.dot(p),
            None => self.mesh.vertices.iter().map(|v| v.dot(&n)).fold(f64::INFINITY, f64::min),
        };
        self.mesh.vertices.iter().filter(|v| v.dot(&n) < low + reach).cloned().collect()
    }

    /// The object's largest distance from its frame's origin.
    pub fn size(&self) -> f64 {
        self.sphere.unwrap_or_else(|| self.mesh.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max))
    }

    /// The contact points and normal (object frame) of pusher `p` brought against the object at
    /// pose `pose`: a rigid pusher's own points, a plane's lowest points of the object.
    pub fn pusher_contacts(&self, p: usize, pose: &Isometry3<f64>) -> (Vec<V3>, V3) {
        let pz = &self.pushers[p];
        if pz.plane {
            let n = pose.rotation.inverse() * pz.normal;
            (self.lowest_points(&n), n)
        } else {
            (pz.points.clone(), pz.normal)
        }
    }

    pub fn pusher_index(&self, name: &str) -> Result<usize> {
        self.pushers.iter().position(|p| p.name == name).ok_or_else(|| {
            let names: Vec<&str> = self.pushers.iter().map(|p| p.name.as_str()).collect();
            Error::arg("pusher", format!("no pusher named `{name}` (the scene has {names:?})"))
        })
    }

    /// Whether both pads touch the object at `pose` (a face: at least 6 of the pad's 8 ring points
    /// on it; an edge or a vertex: itself).
    pub fn pads_on(&self, pose: &Isometry3<f64>) -> bool {
        self.pad_contacts(pose).iter().all(|p| !p.is_empty() && (p.len() >= 6 || p.len() <= 2))
    }

    /// Contact points (object frame) of the two pads (left: +Y, right: −Y) at pose `pose`: the
    /// object's extreme points along ±Y of the gripper; a face parallel to the pad gives the
    /// pad's ring of points that lie on the face (a patch), an edge or a vertex gives itself.
    pub fn pad_contacts(&self, pose: &Isometry3<f64>) -> [Vec<V3>; 2] {
        let inv = pose.inverse();
        let mut out: [Vec<V3>; 2] = [Vec::new(), Vec::new()];
        if let Some(r) = self.sphere {
            // a sphere pressed by a soft pad: the pad's ring of points on the tangent plane at
            // the sphere's extreme point (the pad radius is the contact patch's)
            for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
                // the pad (centred on the gripper's Y axis) touches the ball only if the ball's
                // extreme point lies on it
                let c = pose.translation.vector + V3::new(0.0, sign * r, 0.0);
                if c.x.hypot(c.z) > self.pad_radius {
                    continue;
                }
                let tip = inv.rotation * V3::new(0.0, sign * r, 0.0);
                let (t1, t2) = (inv.rotation * V3::x(), inv.rotation * V3::z());
                for k in 0..8 {
                    let a = std::f64::consts::PI * 2.0 * (k as f64 + 0.5) / 8.0;
                    let rho = 2.0 / 3.0 * self.pad_radius;
                    out[side].push(tip + t1 * (rho * a.cos()) + t2 * (rho * a.sin()));
                }
            }
            return out;
        }
        let size = self.mesh.vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        for (side, sign) in [(0usize, 1.0), (1, -1.0)] {
            // pad normal (pointing into the object) is −sign·Y; the object's extreme along sign·Y
            let dir = inv.rotation * V3::new(0.0, sign, 0.0);
            let top = self.mesh.vertices.iter().map(|v| v.dot(&dir)).fold(f64::NEG_INFINITY, f64::max);
            let extreme: Vec<V3> = self.mesh.vertices.iter().filter(|v| v.dot(&dir) > top - 1e-6 * size).cloned().collect();
            if extreme.len() >= 3 {
                // a face: pad ring points projected on the face plane, kept if on the face
                for k in 0..8 {
                    let a = std::f64::consts::PI * 2.0 * (k as f64 + 0.5) / 8.0;
                    let rho = 2.0 / 3.0 * self.pad_radius;
                    let pg = nalgebra::Point3::new(rho * a.cos(), 0.0, rho * a.sin());
                    let po = inv * pg;
                    let on_face = po.coords + dir * (top - po.coords.dot(&dir));
                    if self.signed_distance(&on_face) <= 1e-6 * size {
                        out[side].push(on_face);
                    }
                }
            } else {
                out[side] = extreme;
            }
        }
        out
    }
}

/// The vertices of an OBJ text and its faces (fanned into triangles, 0-based vertex indices)
/// grouped by the `o`/`g` lines before them, with the groups' names; groups without faces are
/// dropped.
fn read_obj(text: &str) -> std::result::Result<(Vec<V3>, Vec<(String, Vec<[usize; 3]>)>), String> {
    let mut v = Vec::new();
    let mut parts: Vec<(String, Vec<[usize; 3]>)> = vec![("unnamed".into(), Vec::new())];
    for (ln, line) in text.lines().enumerate() {
        let mut it = line.split_whitespace();
        match it.next() {
            Some("v") => {
                let c: Vec<f64> = it.take(3).map(|x| x.parse::<f64>()).collect::<std::result::Result<_, _>>()
                    .map_err(|e| format!("line {}: {e}", ln + 1))?;
                if c.len() != 3 {
                    return Err(format!("line {}: a vertex needs 3 coordinates", ln + 1));
                }
                if let Some(x) = c.iter().find(|x| !(x.is_finite() && x.abs() <= bounds::COORD.hi)) {
                    return Err(format!("line {}: a coordinate must be finite and within {} m (got {x})", ln + 1, bounds::COORD.hi));
                }
                if v.len() == bounds::MAX_MESH_VERTICES {
                    return Err(format!("line {}: more than {} vertices (the most a mesh may have)", ln + 1, bounds::MAX_MESH_VERTICES));
                }
                v.push(V3::new(c[0], c[1], c[2]));
            }
            Some(kw @ ("o" | "g")) => {
                let name = it.collect::<Vec<_>>().join(" ");
                parts.push((format!("`{kw} {name}`"), Vec::new()));
            }
            Some("f") => {
                let idx: Vec<usize> = it
                    .map(|x| x.split('/').next().unwrap_or("").parse::<isize>())
                    .collect::<std::result::Result<Vec<_>, _>>()
                    .map_err(|e| format!("line {}: {e}", ln + 1))?
                    .into_iter()
                    .map(|i| if i < 0 { (v.len() as isize + i) as usize } else { (i - 1) as usize })
                    .collect();
                if idx.len() < 3 {
                    return Err(format!("line {}: a face needs 3 vertices", ln + 1));
                }
                let t = &mut parts.last_mut().expect("one group at least").1;
                for k in 1..idx.len() - 1 {
                    t.push([idx[0], idx[k], idx[k + 1]]);
                }
            }
            _ => {}
        }
    }
    parts.retain(|(_, t)| !t.is_empty());
    Ok((v, parts))
}
