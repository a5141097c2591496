//! Infeasibility certificates: planar regrasps decided unreachable before any search.
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

use crate::mechanics::geometry::Vec2;
use crate::scene::Scene;
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
