//! Many poses / twists in one call, spread over threads (rayon).
//!
//! Each entry is independent: an invalid pose or a pose where the grasp cannot hold gives an
//! error for that entry only.

use crate::error::Result;
use crate::geometry::Vec3;
use crate::motion_cone::Classification;
use crate::scene::Scene;
use rayon::prelude::*;

/// Below this many entries the work stays on the calling thread.
const PAR_MIN: usize = 512;

fn map<T: Send, U: Sync>(items: &[U], f: impl Fn(&U) -> T + Sync + Send) -> Vec<T> {
    if items.len() < PAR_MIN {
        items.iter().map(f).collect()
    } else {
        items.par_iter().with_min_len(256).map(f).collect()
    }
}

/// Generators of the polyhedral motion cone at each pose.
pub fn generators(scene: &Scene, poses: &[[f64; 3]], pusher: usize) -> Vec<Result<Vec<Vec3>>> {
    map(poses, |q| scene.push(q, pusher)?.generators())
}

/// Generators of the gravity-free cone at each pose.
pub fn gravity_free_generators(scene: &Scene, poses: &[[f64; 3]], pusher: usize) -> Vec<Result<Vec<Vec3>>> {
    map(poses, |q| Ok(scene.push_unchecked(q, pusher)?.gravity_free_generators()))
}

/// Exact membership test of twist `i` at pose `i`.
pub fn classify(scene: &Scene, poses: &[[f64; 3]], twists: &[Vec3], pusher: usize) -> Vec<Result<Classification>> {
    let pairs: Vec<(&[f64; 3], &Vec3)> = poses.iter().zip(twists).collect();
    map(&pairs, |(q, v)| scene.push(q, pusher)?.classify(v))
}

/// Closest feasible twist to twist `i` at pose `i`.
pub fn project(scene: &Scene, poses: &[[f64; 3]], twists: &[Vec3], pusher: usize) -> Vec<Result<Vec3>> {
    let pairs: Vec<(&[f64; 3], &Vec3)> = poses.iter().zip(twists).collect();
    map(&pairs, |(q, v)| scene.push(q, pusher)?.project(v))
}
