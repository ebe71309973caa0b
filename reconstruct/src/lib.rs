//! Shape-from-polarization reconstruction, in layers: the shared
//! least-squares machinery (`solver`), what every method reads and shares
//! (`input`, `light`, `prior`, `regions`, `noise`, `normal`, and `system`,
//! the height-from-polarization rows built from them), the baselines
//! (`methods`), SMSfP and its parts (`smsfp`), what a method declares
//! about itself and reports (`method`, `options`, `shared_options`,
//! `method_record`), and
//! the registry, its listing, the run record and the result folder every
//! caller goes through (`registry`, `listing`, `run_record`, `output`).

pub mod capture_import;
pub mod dome;
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
pub mod registry;
pub mod run_record;
pub mod shared_options;
pub mod smsfp;
pub mod solver;
pub mod specular;
pub mod stage;
pub mod switch;
pub mod system;
#[cfg(test)]
mod test_support;
