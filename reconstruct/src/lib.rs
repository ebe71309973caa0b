//! Shape-from-polarization reconstruction, in layers: the shared
//! least-squares machinery (`solver`), what every method reads and shares
//! (`input`, `light`, `prior`, `regions`, `noise`, `normal`, and `system`,
//! the height-from-polarization rows built from them), the baselines
//! (`methods`), SMSfP and its parts (`smsfp`), what a method declares
//! about itself and reports (`method`, `options`, `method_record`), and
//! the registry, its listing, the run record and the result folder every
//! caller goes through (`registry`, `listing`, `run_record`, `output`).

pub mod beyond_diffuse;
pub mod input;
pub mod light;
pub mod listing;
pub mod method;
pub mod method_record;
pub mod methods;
pub mod noise;
pub mod normal;
pub mod options;
pub mod output;
mod parity_union;
pub mod prior;
pub mod reflected_surroundings;
pub mod registry;
pub mod run_record;
pub mod smsfp;
pub mod solver;
pub mod specular;
pub mod specular_share;
pub mod system;
#[cfg(test)]
mod test_support;

// The layers' modules at the crate root too: one short path for each
// concept (`crate::lsq`, `sfp_reconstruct::smith`), whatever folder holds it.
pub use methods::{atkinson, mahmoud, smith};
pub use smsfp::{guided_filter, mfcp, parg};
pub(crate) use solver::{cholesky, substructure, task};
pub use solver::{domain, integrate, lsq, operators, ordering};

// Connected regions live in core (the import's automatic mask uses them too).
pub use sfp_core::regions;

pub use input::Input;
pub use method::{Method, Reconstruction};
pub use registry::MethodConfig;
