//! Sweeps, statistics and reports over rendered views and reconstructions.

pub mod demo;
pub mod report;
pub mod runs;
pub mod sheet;
pub mod sweep;
pub mod table;
