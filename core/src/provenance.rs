//! Where a result came from: the software, the time and the exact input, so
//! that a result can be traced and never scored against another view.

use crate::view::{View, ViewInput};
use crate::{COMMIT, SOFTWARE_VERSION};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

/// The view a result was made from, as `run.json` records it: `sfp eval`
/// refuses to score the result against a view with another input.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ViewRecord {
    /// The view folder, when the view was read from one.
    pub path: Option<String>,
    /// [`input_hash`] of the view's input.
    pub input_hash: String,
    /// Width and height, pixels.
    pub size: [usize; 2],
}

impl ViewRecord {
    /// The record of `view` (hashes its input).
    pub fn of(view: &View) -> ViewRecord {
        let (w, h) = view.input.size();
        ViewRecord {
            path: view.source.as_ref().map(|p| p.display().to_string()),
            input_hash: input_hash(&view.input),
            size: [w, h],
        }
    }
}

/// The software that made a result: version and commit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Software {
    pub version: String,
    pub commit: String,
}

impl Software {
    /// This build.
    pub fn this() -> Software {
        Software {
            version: SOFTWARE_VERSION.to_string(),
            commit: COMMIT.to_string(),
        }
    }
}

/// SHA-256 (hex) of a view's input content: size, bit depth, the four
/// polarizer images and the mask. Decoded pixels, not file bytes, so the
/// same capture written by another PNG encoder has the same hash.
pub fn input_hash(input: &ViewInput) -> String {
    let mut h = Sha256::new();
    let (w, h_px) = input.size();
    h.update((w as u64).to_le_bytes());
    h.update((h_px as u64).to_le_bytes());
    h.update([input.bits]);
    for pol in &input.pol {
        for v in pol.data() {
            h.update(v.to_le_bytes());
        }
    }
    match &input.mask {
        Some(mask) => {
            h.update([1]);
            h.update(mask.data().iter().map(|&m| u8::from(m)).collect::<Vec<_>>());
        }
        None => h.update([0]),
    }
    h.finalize().iter().map(|b| format!("{b:02x}")).collect()
}

/// The current time, UTC, RFC 3339 to the second.
pub fn now() -> String {
    humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::{AnalyticScene, Shape};

    #[test]
    fn the_input_hash_follows_the_content_only() {
        let view = |size| {
            AnalyticScene {
                shape: Shape::Sphere,
                size,
                ..AnalyticScene::default()
            }
            .render()
            .unwrap()
        };
        let a = view(24).input;
        assert_eq!(input_hash(&a), input_hash(&view(24).input));
        assert_eq!(input_hash(&a).len(), 64);
        let mut b = a.clone();
        *b.pol[2].get_mut(12, 12) += 1;
        assert_ne!(input_hash(&a), input_hash(&b));
        let mut c = a.clone();
        c.mask = None;
        assert_ne!(input_hash(&a), input_hash(&c));
        assert_ne!(input_hash(&a), input_hash(&view(25).input));
    }
}
