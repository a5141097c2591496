//! Many poses / twists in one call, spread over threads (rayon), writing into flat output
//! buffers (no allocation per entry). Each entry gets a [`Status`]; a bad entry never stops the
//! others.

use crate::mechanics::geometry::Vec3;
use crate::cones::motion_cone::{project_exact, SupportFrame};
use crate::scene::planar::Scene;
use rayon::prelude::*;

/// Outcome of one batch entry.
#[repr(u8)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    Ok = 0,
    /// A pose or twist component is NaN or infinite.
    NonFinite = 1,
    /// The finger pad is not entirely on the object at this pose.
    Inadmissible = 2,
    /// The grasp cannot hold the object against gravity at this pose.
    CannotHold = 3,
    /// The twist is zero.
    ZeroTwist = 4,
}

impl Status {
    pub fn message(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::NonFinite => "a component is not finite",
            Status::Inadmissible => "pose is not admissible: the finger pad is not entirely on the object",
            Status::CannotHold => "the grasp cannot hold the object against gravity at this pose",
            Status::ZeroTwist => "twist is zero",
        }
    }
}

/// Rows per parallel task.
const CHUNK: usize = 1024;

fn frame_or_status(scene: &Scene, q: &[f64; 3]) -> Result<SupportFrame, Status> {
    if !q.iter().all(|x| x.is_finite()) {
        return Err(Status::NonFinite);
    }
    if !scene.admissible(q) {
        return Err(Status::Inadmissible);
    }
    let f = scene.frame(q);
    if !(f.hold_ratio < 1.0) {
        return Err(Status::CannotHold);
    }
    Ok(f)
}

/// Polyhedral generators (or gravity-free generators) of `pusher` at each pose, written to
/// `out` (`k` unit twists of 3 numbers per pose, k = number of edges). Panics if the buffers
/// have the wrong length.
pub fn generators_into(
    scene: &Scene,
    poses: &[[f64; 3]],
    pusher: usize,
    gravity_free: bool,
    out: &mut [f64],
    status: &mut [Status],
) {
    let model = &scene.pushers[pusher].model;
    let k = model.edges.len();
    let m = scene.metric();
    assert_eq!(out.len(), poses.len() * k * 3);
    assert_eq!(status.len(), poses.len());
    let work = |(q, (o, st)): (&[f64; 3], (&mut [f64], &mut Status))| {
        let frame = if gravity_free {
            if !q.iter().all(|x| x.is_finite()) {
                Err(Status::NonFinite)
            } else if !scene.admissible(q) {
                Err(Status::Inadmissible)
            } else {
                Ok(scene.frame(q))
            }
        } else {
            frame_or_status(scene, q)
        };
        match frame {
            Err(s) => {
                *st = s;
                o.fill(0.0);
            }
            Ok(f) => {
                *st = Status::Ok;
                for (j, e) in model.edges.iter().enumerate() {
                    let v = if gravity_free { Some(f.gravity_free_ray(&e.wrench, &m)) } else { f.ray(&e.wrench, &m) };
                    let v = v.unwrap_or_else(Vec3::zeros);
                    o[3 * j..3 * j + 3].copy_from_slice(v.as_slice());
                }
            }
        }
    };
    poses
        .par_iter()
        .zip(out.par_chunks_mut(k * 3).zip(status.par_iter_mut()))
        .with_min_len(CHUNK)
        .for_each(work);
}

/// Exact test of twist `i` at pose `i`: feasibility, margin and the active limit's label index
/// (see [`crate::mechanics::friction_cone::ContactLimit`]; written as its `label()` by callers).
#[allow(clippy::too_many_arguments)]
pub fn classify_into(
    scene: &Scene,
    poses: &[[f64; 3]],
    twists: &[[f64; 3]],
    pusher: usize,
    feasible: &mut [bool],
    margin: &mut [f64],
    limit: &mut [crate::mechanics::friction_cone::ContactLimit],
    status: &mut [Status],
) {
    let model = &scene.pushers[pusher].model;
    let n = poses.len();
    assert!(twists.len() == n && feasible.len() == n && margin.len() == n && limit.len() == n && status.len() == n);
    (0..n)
        .into_par_iter()
        .zip(feasible.par_iter_mut())
        .zip(margin.par_iter_mut())
        .zip(limit.par_iter_mut())
        .zip(status.par_iter_mut())
        .with_min_len(CHUNK)
        .for_each(|((((i, fe), ma), li), st)| {
            let v = Vec3::from(twists[i]);
            let f = match frame_or_status(scene, &poses[i]) {
                Ok(f) if v.iter().all(|x| x.is_finite()) => f,
                Ok(_) => {
                    *st = Status::NonFinite;
                    return;
                }
                Err(s) => {
                    *st = s;
                    return;
                }
            };
            if v.amax() == 0.0 {
                *st = Status::ZeroTwist;
                return;
            }
            let c = f.classify(model, &v);
            *fe = c.feasible;
            *ma = c.margin;
            *li = c.limit;
            *st = Status::Ok;
        });
}

/// Closest feasible twist to twist `i` at pose `i` (exact cone), written to `out` (n × 3).
pub fn project_into(
    scene: &Scene,
    poses: &[[f64; 3]],
    twists: &[[f64; 3]],
    pusher: usize,
    out: &mut [f64],
    status: &mut [Status],
) {
    let model = &scene.pushers[pusher].model;
    let n = poses.len();
    assert!(twists.len() == n && out.len() == 3 * n && status.len() == n);
    out.par_chunks_mut(3).zip(status.par_iter_mut()).enumerate().with_min_len(64).for_each(|(i, (o, st))| {
        let v = Vec3::from(twists[i]);
        match frame_or_status(scene, &poses[i]) {
            Ok(_) if !v.iter().all(|x| x.is_finite()) => *st = Status::NonFinite,
            Ok(f) => {
                o.copy_from_slice(project_exact(&f, model, &v).as_slice());
                *st = Status::Ok;
            }
            Err(s) => *st = s,
        }
    });
}
