//! The baselines, one file per method: Atkinson & Hancock 2006, Mahmoud et
//! al. 2012, Smith et al. 2016/2019. SMSfP has a folder of its own
//! (`smsfp`).

pub mod atkinson;
pub mod mahmoud;
pub mod smith;
