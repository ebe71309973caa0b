//! `--shard K/N`: a deterministic 1/N of a sweep's rows, so a cluster's job
//! array (one shard per task) or GNU parallel on one machine share a sweep
//! without talking to each other.
//!
//! The unit is the noise-free render ([`super::plan::Group`]): render groups
//! are dealt round-robin in plan order, so each render is made by exactly
//! one shard and shards get nearly equal work (groups of one sweep have
//! equally many rows).

use sfp_core::{Error, Result};
use std::fmt;
use std::str::FromStr;

/// Shard `index` (1-based) of `count`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole sweep.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Whether render group `group` (its position in the plan) is this shard's.
    pub fn owns(&self, group: usize) -> bool {
        group % self.count == self.index - 1
    }
}

impl FromStr for Shard {
    type Err = Error;

    fn from_str(s: &str) -> Result<Shard> {
        let bad = || {
            Error::invalid(format!(
                "shard {s:?}: expected K/N with 1 ≤ K ≤ N, e.g. 2/8"
            ))
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_disjoint_complete_and_balanced() {
        for count in 1..=7 {
            let shards: Vec<Shard> = (1..=count)
                .map(|k| format!("{k}/{count}").parse().unwrap())
                .collect();
            let mut sizes = vec![0; count];
            for group in 0..100 {
                let owners: Vec<usize> = (0..count).filter(|&s| shards[s].owns(group)).collect();
                assert_eq!(owners.len(), 1, "group {group} of {count} shards");
                sizes[owners[0]] += 1;
                // Deterministic: the same answer every time.
                assert!(shards[owners[0]].owns(group));
            }
            let (lo, hi) = (sizes.iter().min().unwrap(), sizes.iter().max().unwrap());
            assert!(hi - lo <= 1, "{sizes:?}");
        }
    }

    #[test]
    fn bad_shards_are_refused() {
        for s in ["0/3", "4/3", "1", "a/b", "1/0", ""] {
            let err = s.parse::<Shard>().unwrap_err().to_string();
            assert!(err.contains("K/N"), "{s}: {err}");
        }
        assert_eq!("2/8".parse::<Shard>().unwrap().to_string(), "2/8");
    }
}
