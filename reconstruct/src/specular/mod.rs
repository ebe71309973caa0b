//! Specular reflection in the data: how much of a mask the diffuse model
//! cannot explain (`beyond_diffuse`) and which way its occluding contour
//! is polarized (`limb`), the `specular` option every method
//! shares and the labelling it makes (`model`), the intensity at which
//! reflected surroundings cancel the diffuse polarization (`surroundings`),
//! each pixel's specular share under a method's normals (`share`), and
//! the surface fit under the mixed reflection model (`mixture`, `fit`)
//! with the shading of its diffuse part (`shading`) and the sign of a
//! compact light reflected by rough facets (`reflected_light`).

pub mod beyond_diffuse;
pub mod fit;
pub mod limb;
pub mod mixture;
pub mod model;
pub mod pyramid;
pub mod reflected_light;
pub mod shading;
pub mod share;
pub mod surroundings;
