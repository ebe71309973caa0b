//! Specular reflection in the data: how much of a mask the diffuse model
//! cannot explain (`beyond_diffuse`), the `specular` option every method
//! shares and the labelling it makes (`model`), the intensity at which
//! reflected surroundings cancel the diffuse polarization (`surroundings`),
//! and each pixel's specular share under a method's normals (`share`).

pub mod beyond_diffuse;
pub mod model;
pub mod share;
pub mod surroundings;
