//! The least-squares machinery every method shares: unknowns over a mask
//! (`domain`), finite-difference rows (`operators`), the normal equations
//! and their sparse Cholesky solver (`lsq`, `plan`, `cholesky`,
//! `substructure`, `ordering`, over the row layout of `slots`; `task`
//! prepares one beside other work; `memory` what they may use), normal
//! integration (`integrate`) and sums in a fixed order (`ordered_sum`).
//! Pure numerics: the height-from-polarization system that builds its rows
//! from the data (`crate::system`) sits one layer up, beside the input,
//! light and prior it reads.

pub(crate) mod cholesky;
pub(crate) mod conjugate_gradient;
pub mod domain;
pub mod integrate;
pub mod lsq;
pub mod memory;
pub(crate) mod mixed;
pub(crate) mod multigrid;
pub mod operators;
pub mod ordered_sum;
pub mod ordering;
pub(crate) mod pieces;
pub(crate) mod plan;
pub(crate) mod slots;
pub(crate) mod substructure;
pub(crate) mod task;
