//! The least-squares machinery every method shares: unknowns over a mask
//! (`domain`), finite-difference rows (`operators`), the normal equations
//! and their sparse Cholesky solver (`lsq`, `cholesky`, `substructure`,
//! `ordering`), the height-from-polarization system (`system`) and normal
//! integration (`integrate`).

pub(crate) mod cholesky;
pub mod domain;
pub mod integrate;
pub mod lsq;
pub mod operators;
pub mod ordering;
pub(crate) mod slots;
pub(crate) mod substructure;
pub mod system;
