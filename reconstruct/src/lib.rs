//! Shape-from-polarization reconstruction: shared machinery (input
//! preparation, finite-difference operators, the sparse least-squares solver,
//! light estimation, the boundary convexity prior, normal integration) and one
//! file per method.

pub mod atkinson;
pub mod input;
pub mod method;

pub use input::Input;
pub use method::{Method, Reconstruction};
