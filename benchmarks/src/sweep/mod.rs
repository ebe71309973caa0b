//! Robustness sweeps (`sfp bench`): views × axes × methods × noise seeds.

pub mod row;
