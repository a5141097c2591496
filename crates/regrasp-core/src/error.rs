//! The closed set of errors the core reports. Every error names what is wrong and where.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum Error {
    /// A scene value is missing or invalid; `field` is its dotted path (`grasp.force`).
    #[error("scene field `{field}`: {message}")]
    Scene { field: String, message: String },

    /// A call argument is invalid (`name` is the argument, e.g. `twist` or `pose`).
    #[error("invalid `{name}`: {message}")]
    InvalidArgument { name: String, message: String },

    /// The support (finger pads or surface) cannot balance gravity alone at this pose: the
    /// gravity wrench lies outside the limit surface (`ratio` = its ellipsoidal norm, must be < 1).
    #[error(
        "the grasp cannot hold the object against gravity at pose [{:.6}, {:.6}, {:.6}]: gravity needs {ratio:.3}x the friction the support can give (increase `grasp.force` or `grasp.friction`)",
        pose[0], pose[1], pose[2]
    )]
    GraspCannotHold { pose: [f64; 3], ratio: f64 },

    /// The caller's interrupt poll asked to stop (Ctrl-C; see [`crate::interrupt`]).
    #[error("interrupted")]
    Interrupted,
}

impl Error {
    pub fn scene(field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Scene { field: field.into(), message: message.into() }
    }
    pub fn arg(name: impl Into<String>, message: impl Into<String>) -> Self {
        Error::InvalidArgument { name: name.into(), message: message.into() }
    }
}

pub type Result<T> = std::result::Result<T, Error>;
