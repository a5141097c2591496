//! The polyhedral motion cones of one push (thesis §3.3.2): the approximation spanned by one
//! ray per edge of the pusher's friction cone, or the gravity-free cone; projection onto them
//! and membership, both in the twist metric `diag(1, 1, L²)`. The exact cone is in
//! [`crate::cones::motion_cone`].

use crate::cones::motion_cone::{project_onto_generators, PlanarPush, MEMBERSHIP_TOL};
use crate::error::{Error, Result};
use crate::mechanics::geometry::Vec3;

/// Which polyhedral cone of a push.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Generators {
    /// The polyhedral approximation of the motion cone ([`PlanarPush::generators`]).
    Approx,
    /// The gravity-free cone ([`PlanarPush::gravity_free_generators`]).
    GravityFree,
}

impl Generators {
    /// Parses `"approx"` or `"gravity_free"`; the error names the argument `which`.
    pub fn parse(s: &str) -> Result<Self> {
        match s {
            "approx" => Ok(Generators::Approx),
            "gravity_free" => Ok(Generators::GravityFree),
            other => Err(Error::arg("which", format!("must be \"approx\" or \"gravity_free\", got {other:?}"))),
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Generators::Approx => "approx",
            Generators::GravityFree => "gravity_free",
        }
    }
}

/// The generators (unit twists) of cone `which` of `push`; the approximation fails when the
/// support cannot hold the object.
pub fn generators(push: &PlanarPush, which: Generators) -> Result<Vec<Vec3>> {
    match which {
        Generators::Approx => push.generators(),
        Generators::GravityFree => Ok(push.gravity_free_generators()),
    }
}

fn check_finite(v: &Vec3) -> Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(Error::arg("twist", "has a non-finite component"))
    }
}

/// The twist of cone `which` closest to `v` in the twist metric (zero when no generator makes
/// an acute angle with `v`).
pub fn project(push: &PlanarPush, v: &Vec3, which: Generators) -> Result<Vec3> {
    check_finite(v)?;
    let m = push.metric();
    let gens: Vec<Vec3> = generators(push, which)?.iter().map(|g| m.twist(g)).collect();
    let (p, _) = project_onto_generators(&gens, &m.twist(v));
    Ok(m.twist_inv(&p))
}

/// Whether each twist of `twists` lies in the polyhedral approximation (to [`MEMBERSHIP_TOL`]).
pub fn contains(push: &PlanarPush, twists: &[Vec3]) -> Result<Vec<bool>> {
    twists.iter().try_for_each(check_finite)?;
    let cone = push.polyhedral_cone()?;
    let m = push.metric();
    Ok(twists.iter().map(|v| cone.contains(&m.twist(v), MEMBERSHIP_TOL)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Scene;

    fn push() -> PlanarPush {
        let s = Scene::from_toml_str(include_str!("../../../../examples/block-low-friction.toml")).unwrap();
        let q = s.task.map(|t| t.start).unwrap();
        s.push(&q, 0).unwrap()
    }

    #[test]
    fn generators_project_onto_themselves_and_lie_in_their_cone() {
        let p = push();
        for which in [Generators::Approx, Generators::GravityFree] {
            assert_eq!(Generators::parse(which.label()), Ok(which));
            for g in generators(&p, which).unwrap() {
                let back = project(&p, &g, which).unwrap();
                assert!((back - g).norm() < 1e-9, "{which:?}: {g:?} -> {back:?}");
            }
        }
        let inside = generators(&p, Generators::Approx).unwrap();
        assert!(contains(&p, &inside).unwrap().iter().all(|&c| c));
    }

    #[test]
    fn projection_lands_in_the_cone_and_bad_input_is_an_argument_error() {
        let p = push();
        let gens = generators(&p, Generators::Approx).unwrap();
        let outside = -(gens.iter().sum::<Vec3>());
        let proj = project(&p, &outside, Generators::Approx).unwrap();
        assert!(proj.norm() < 1e-12 || contains(&p, &[proj]).unwrap()[0]);
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        assert!(matches!(project(&p, &nan, Generators::Approx), Err(Error::InvalidArgument { ref name, .. }) if name == "twist"));
        assert!(matches!(contains(&p, &[nan]), Err(Error::InvalidArgument { .. })));
        assert!(matches!(Generators::parse("exact"), Err(Error::InvalidArgument { ref name, .. }) if name == "which"));
    }
}
