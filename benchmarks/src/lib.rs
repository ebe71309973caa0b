//! Sweeps, statistics and reports over rendered views and reconstructions.

pub mod csv;
pub mod dataset;
pub mod demo;
pub mod report;
pub mod row;
pub mod sheet;
pub mod sweep;
