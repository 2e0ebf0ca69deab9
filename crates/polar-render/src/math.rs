//! The vector type every module of the renderer shares.

use nalgebra::Vector3;

/// A 3-vector in world space.
pub type Vec3 = Vector3<f64>;
