//! Reading a sweep folder: `results.jsonl` (required), `timings.csv`,
//! `sweep.toml` and `provenance.json` (each optional: the report says what
//! is missing instead of failing).

use crate::row::{Row, Timing};
use serde::{Deserialize, Serialize};
use sfp_core::{Error, Result};
use std::collections::BTreeMap;
use std::path::Path;

/// Where and how a sweep ran (`provenance.json`); every field optional and
/// shown as written (a number or a text).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    pub version: Option<String>,
    pub commit: Option<String>,
    pub crates: BTreeMap<String, String>,
    pub cpu: Option<String>,
    pub threads: Option<String>,
    pub started: Option<String>,
}

impl Provenance {
    /// Reads the fields it knows from any JSON object; other fields and
    /// other shapes are ignored.
    pub fn from_json(value: &serde_json::Value) -> Provenance {
        let text = |v: &serde_json::Value| match v {
            serde_json::Value::Null => None,
            serde_json::Value::String(s) => Some(s.clone()),
            other => Some(other.to_string()),
        };
        let field = |name: &str| value.get(name).and_then(text);
        let crates = value
            .get("crates")
            .and_then(|c| c.as_object())
            .map(|m| {
                m.iter()
                    .map(|(k, v)| (k.clone(), text(v).unwrap_or_default()))
                    .collect()
            })
            .unwrap_or_default();
        Provenance {
            version: field("version"),
            commit: field("commit"),
            crates,
            cpu: field("cpu"),
            threads: field("threads"),
            started: field("started"),
        }
    }
}

/// Everything the report reads from a sweep folder.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SweepFiles {
    pub rows: Vec<Row>,
    pub timings: Option<Vec<Timing>>,
    pub sweep_toml: Option<String>,
    pub provenance: Option<Provenance>,
    /// What was missing or unreadable, in words for the report.
    pub notes: Vec<String>,
}

/// Reads the sweep folder `dir`. Only `results.jsonl` is required; a bad
/// line in it is an error naming the line.
pub fn read(dir: &Path) -> Result<SweepFiles> {
    let path = dir.join("results.jsonl");
    let text = std::fs::read_to_string(&path).map_err(|e| Error::read(&path, e))?;
    let mut rows = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let row: Row = serde_json::from_str(line)
            .map_err(|e| Error::file(&path, format!("line {}: not a row: {e}", i + 1)))?;
        rows.push(row);
    }
    let mut notes = Vec::new();
    let timings = match std::fs::read_to_string(dir.join("timings.csv")) {
        Ok(text) => match parse_timings(&text) {
            Ok(t) => Some(t),
            Err(e) => {
                notes.push(format!(
                    "timings.csv is unreadable ({e}): no times are shown."
                ));
                None
            }
        },
        Err(_) => {
            notes.push("timings.csv is missing: no times are shown.".into());
            None
        }
    };
    let sweep_toml = std::fs::read_to_string(dir.join("sweep.toml")).ok();
    if sweep_toml.is_none() {
        notes.push("sweep.toml is missing: the sweep file cannot be shown.".into());
    }
    let provenance = match std::fs::read(dir.join("provenance.json")) {
        Ok(bytes) => match serde_json::from_slice::<serde_json::Value>(&bytes) {
            Ok(v) => Some(Provenance::from_json(&v)),
            Err(e) => {
                notes.push(format!("provenance.json is unreadable: {e}."));
                None
            }
        },
        Err(_) => {
            notes.push(
                "provenance.json is missing: commit, crate versions, CPU and threads are unknown."
                    .into(),
            );
            None
        }
    };
    Ok(SweepFiles {
        rows,
        timings,
        sweep_toml,
        provenance,
        notes,
    })
}

/// Splits one CSV line into fields (double-quoted fields may hold commas
/// and doubled quotes).
pub fn csv_fields(line: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        let field = fields.last_mut().expect("one field at least");
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(String::new()),
            (c, _) => field.push(c),
        }
    }
    fields
}

/// `timings.csv`: a header naming the [`Timing`] fields, then one line per
/// row (columns found by name, so their order may change).
pub fn parse_timings(text: &str) -> std::result::Result<Vec<Timing>, String> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header = csv_fields(lines.next().ok_or("no header line")?);
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h.trim() == name)
            .ok_or(format!("no '{name}' column"))
    };
    let cols = [
        col("key")?,
        col("method")?,
        col("pixels")?,
        col("noise_seconds")?,
        col("reconstruct_seconds")?,
        col("overhead_seconds")?,
    ];
    lines
        .enumerate()
        .map(|(i, line)| {
            let f = csv_fields(line);
            let get = |k: usize| {
                f.get(cols[k])
                    .map(|s| s.trim())
                    .ok_or(format!("line {}: too few fields", i + 2))
            };
            let num = |k: usize| -> std::result::Result<f64, String> {
                get(k)?
                    .parse::<f64>()
                    .map_err(|e| format!("line {}: {e}", i + 2))
            };
            Ok(Timing {
                key: get(0)?.to_string(),
                method: get(1)?.to_string(),
                pixels: get(2)?
                    .parse()
                    .map_err(|e| format!("line {}: {e}", i + 2))?,
                noise_seconds: num(3)?,
                reconstruct_seconds: num(4)?,
                overhead_seconds: num(5)?,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timings_are_read_by_column_name() {
        let t = parse_timings(
            "method,key,pixels,noise_seconds,reconstruct_seconds,overhead_seconds\n\
             \"smsfp, v2\",k1,100,0.5,2.25,0.1\n",
        )
        .unwrap();
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].method, "smsfp, v2");
        assert_eq!(t[0].key, "k1");
        assert_eq!(t[0].reconstruct_seconds, 2.25);
        assert!(parse_timings("key,method\n").is_err());
    }

    #[test]
    fn missing_optional_files_become_notes() {
        let dir = tempfile::tempdir().unwrap();
        assert!(read(dir.path()).is_err());
        std::fs::write(dir.path().join("results.jsonl"), "\n").unwrap();
        let s = read(dir.path()).unwrap();
        assert!(s.rows.is_empty() && s.timings.is_none() && s.provenance.is_none());
        assert_eq!(s.notes.len(), 3, "{:?}", s.notes);
        std::fs::write(
            dir.path().join("provenance.json"),
            r#"{"commit": "abc", "threads": 2, "crates": {"faer": "0.24"}, "extra": [1]}"#,
        )
        .unwrap();
        let p = read(dir.path()).unwrap().provenance.unwrap();
        assert_eq!(p.commit.as_deref(), Some("abc"));
        assert_eq!(p.threads.as_deref(), Some("2"));
        assert_eq!(p.crates["faer"], "0.24");
        assert_eq!(p.cpu, None);
        std::fs::write(dir.path().join("results.jsonl"), "{oops\n").unwrap();
        let e = read(dir.path()).unwrap_err().to_string();
        assert!(e.contains("line 1"), "{e}");
    }
}
