//! Shape-from-polarization reconstruction: shared machinery (input
//! preparation, finite-difference operators, the sparse least-squares solver,
//! light estimation, the boundary convexity prior, normal integration) and one
//! file per method.

pub mod atkinson;
mod cholesky;
pub mod domain;
pub mod guided_filter;
pub mod input;
pub mod integrate;
pub mod light;
pub mod lsq;
pub mod mahmoud;
pub mod method;
pub mod mfcp;
pub mod noise;
pub mod operators;
pub mod ordering;
pub mod output;
pub mod parg;
pub mod prior;
pub mod regions;
pub mod registry;
pub mod smith;
pub mod smsfp;
mod substructure;
pub mod system;

pub use input::Input;
pub use method::{Method, Reconstruction};
pub use registry::MethodConfig;
