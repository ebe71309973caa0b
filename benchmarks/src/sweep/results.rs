//! The result files of a sweep folder: `results.jsonl` (one [`Row`] per
//! line, the record resuming trusts), `results.csv` (the same rows
//! flattened) and `timings.csv` ([`Timing`]).
//!
//! Rows are appended and flushed one by one, so a killed sweep loses at most
//! the row it was writing. On reopening, complete lines are kept and a torn
//! last line (no newline, or not a whole row) is dropped and redone; the CSV
//! files are rewritten from the kept rows. Rows that cannot be trusted are
//! dropped on reopening and so redone ([`keep_trusted`]). When a run ends, every file is
//! rewritten in plan order, so the same sweep always gives the same bytes,
//! however often it was interrupted, and a merge of shards gives the bytes
//! of the unsharded run.

use crate::csv;
use crate::row::{AxisValue, Row, Timing};
use sfp_core::{Error, Result, io};
use std::collections::{HashMap, HashSet};
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub const RESULTS_JSONL: &str = "results.jsonl";
pub const RESULTS_CSV: &str = "results.csv";
pub const TIMINGS_CSV: &str = "timings.csv";

const METRIC_COLUMNS: [&str; 8] = [
    "mae_deg",
    "rmse_deg",
    "median_deg",
    "acc_11_25",
    "acc_22_5",
    "acc_30",
    "pixels",
    "missing",
];

const TIMING_HEADER: &str = "key,method,pixels,noise_seconds,reconstruct_seconds,overhead_seconds";

/// The result files of one folder, open for appending.
pub struct Results {
    dir: PathBuf,
    axes: Vec<String>,
    rows: Vec<Row>,
    timings: Vec<Timing>,
    done: HashSet<String>,
    files: [BufWriter<File>; 3],
    /// Rows of the file dropped on opening, to be redone.
    pub dropped: usize,
}

impl Results {
    /// Opens `dir`'s result files (the CSV columns: `axes`, sorted), keeping
    /// the complete rows already there that [`keep_trusted`] keeps of the
    /// rows `planned`.
    pub fn open(dir: &Path, axes: &[String], planned: &HashSet<&str>) -> Result<Results> {
        let (rows, _torn) = read_rows(&dir.join(RESULTS_JSONL), false)?;
        let read = rows.len();
        let rows = keep_trusted(rows, planned);
        let dropped = read - rows.len();
        let done: HashSet<String> = rows.iter().map(|r| r.key.clone()).collect();
        let timings: Vec<Timing> = read_timings(&dir.join(TIMINGS_CSV))
            .into_iter()
            .filter(|t| done.contains(&t.key))
            .collect();
        write_all(dir, axes, &rows, &timings)?;
        let append = |name: &str| -> Result<BufWriter<File>> {
            let path = dir.join(name);
            let file = OpenOptions::new()
                .append(true)
                .open(&path)
                .map_err(|e| Error::io(&path, e))?;
            Ok(BufWriter::new(file))
        };
        Ok(Results {
            dir: dir.to_path_buf(),
            axes: axes.to_vec(),
            files: [
                append(RESULTS_JSONL)?,
                append(RESULTS_CSV)?,
                append(TIMINGS_CSV)?,
            ],
            rows,
            timings,
            done,
            dropped,
        })
    }

    /// Whether the row `key` is already there.
    pub fn contains(&self, key: &str) -> bool {
        self.done.contains(key)
    }

    /// Appends one row to the three files and flushes them.
    pub fn append(&mut self, row: Row, timing: Timing) -> Result<()> {
        let lines = [
            format!("{}\n", row_json(&row)),
            csv_line(&row, &self.axes),
            timing_line(&timing),
        ];
        let names = [RESULTS_JSONL, RESULTS_CSV, TIMINGS_CSV];
        for ((file, line), name) in self.files.iter_mut().zip(lines).zip(names) {
            let path = self.dir.join(name);
            file.write_all(line.as_bytes())
                .and_then(|()| file.flush())
                .map_err(|e| Error::io(&path, e))?;
        }
        self.done.insert(row.key.clone());
        self.rows.push(row);
        self.timings.push(timing);
        Ok(())
    }

    /// Rewrites the files with the rows in the order of `order` (row keys).
    pub fn finish(self, order: &[String]) -> Result<()> {
        let Results {
            dir,
            axes,
            mut rows,
            mut timings,
            files,
            ..
        } = self;
        drop(files);
        sort_by_plan(&mut rows, &mut timings, order);
        write_all(&dir, &axes, &rows, &timings)
    }
}

/// The rows worth keeping, in their order: one of each repeated identical
/// row; none of a key with different rows (two writers: which is right is
/// unknown, so it is redone); none whose key is not `planned`; none that
/// failed because the system refused a read or write (a full disk: worth a
/// retry, unlike a method's own failure, which is a result).
pub fn keep_trusted(rows: Vec<Row>, planned: &HashSet<&str>) -> Vec<Row> {
    let mut first: HashMap<String, Row> = HashMap::new();
    let mut conflicting = HashSet::new();
    for row in &rows {
        match first.get(&row.key) {
            Some(seen) if seen != row => {
                conflicting.insert(row.key.clone());
            }
            Some(_) => {}
            None => {
                first.insert(row.key.clone(), row.clone());
            }
        }
    }
    let mut kept = HashSet::new();
    rows.into_iter()
        .filter(|r| {
            planned.contains(r.key.as_str())
                && !conflicting.contains(&r.key)
                && !r.error.as_deref().is_some_and(is_system_failure)
                && kept.insert(r.key.clone())
        })
        .collect()
}

/// Whether a row's error is the operating system's refusal, as the standard
/// library prints it ("No space left on device (os error 28)").
pub fn is_system_failure(error: &str) -> bool {
    error.contains("(os error ")
}

/// Orders rows and timings as `order` lists their keys (others last, by key).
pub fn sort_by_plan(rows: &mut [Row], timings: &mut [Timing], order: &[String]) {
    let position: HashMap<&str, usize> = order
        .iter()
        .enumerate()
        .map(|(i, k)| (k.as_str(), i))
        .collect();
    let at = |key: &str| {
        (
            position.get(key).copied().unwrap_or(usize::MAX),
            key.to_string(),
        )
    };
    rows.sort_by_key(|r| at(&r.key));
    timings.sort_by_key(|t| at(&t.key));
}

/// Writes the three files from scratch (atomically each).
pub fn write_all(dir: &Path, axes: &[String], rows: &[Row], timings: &[Timing]) -> Result<()> {
    let jsonl: String = rows.iter().map(|r| format!("{}\n", row_json(r))).collect();
    io::write_atomic(&dir.join(RESULTS_JSONL), jsonl.as_bytes())?;
    let mut csv = csv_header(axes);
    csv.extend(rows.iter().map(|r| csv_line(r, axes)));
    io::write_atomic(&dir.join(RESULTS_CSV), csv.as_bytes())?;
    let mut text = format!("{TIMING_HEADER}\n");
    text.extend(timings.iter().map(timing_line));
    io::write_atomic(&dir.join(TIMINGS_CSV), text.as_bytes())
}

fn row_json(row: &Row) -> String {
    serde_json::to_string(row).expect("rows serialise")
}

/// The rows of a `results.jsonl` (none when it does not exist) and whether
/// its last line was torn. A torn last line is dropped, or an error when
/// `strict`; a bad line before the last is always an error naming it.
pub fn read_rows(path: &Path, strict: bool) -> Result<(Vec<Row>, bool)> {
    let text = match std::fs::read(path) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok((Vec::new(), false)),
        Err(e) => return Err(Error::io(path, e)),
    };
    let mut rows = Vec::new();
    let mut torn = false;
    let mut lines = text.split_inclusive(|&b| b == b'\n').enumerate().peekable();
    while let Some((i, line)) = lines.next() {
        let last = lines.peek().is_none();
        let complete = line.ends_with(b"\n");
        match serde_json::from_slice::<Row>(line) {
            Ok(row) if complete => rows.push(row),
            _ if last => torn = true,
            Err(e) => {
                return Err(Error::file(
                    path,
                    format!("line {}: not a result row ({e})", i + 1),
                ));
            }
            Ok(_) => unreachable!("only the last line lacks a newline"),
        }
    }
    if torn && strict {
        return Err(Error::file(
            path,
            "the last row is incomplete (the run was interrupted): run it again to complete it",
        ));
    }
    Ok((rows, torn))
}

/// The timing rows of a `timings.csv` that parse (none when it is missing).
pub fn read_timings(path: &Path) -> Vec<Timing> {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    text.lines()
        .skip(1)
        .filter_map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            let [key, method, pixels, noise, reconstruct, overhead] = f[..] else {
                return None;
            };
            Some(Timing {
                key: key.to_string(),
                method: method.to_string(),
                pixels: pixels.parse().ok()?,
                noise_seconds: noise.parse().ok()?,
                reconstruct_seconds: reconstruct.parse().ok()?,
                overhead_seconds: overhead.parse().ok()?,
            })
        })
        .collect()
}

fn timing_line(t: &Timing) -> String {
    format!(
        "{},{},{},{},{},{}\n",
        t.key, t.method, t.pixels, t.noise_seconds, t.reconstruct_seconds, t.overhead_seconds
    )
}

/// The header of `results.csv`.
pub fn csv_header(axes: &[String]) -> String {
    let mut cols: Vec<&str> = vec!["key", "dataset", "view", "object"];
    cols.extend(axes.iter().map(String::as_str));
    cols.extend(["method", "seed"]);
    cols.extend(METRIC_COLUMNS);
    // Added after `error`, so the columns before keep their places.
    cols.extend(["error", "exit_status", "stderr_tail"]);
    format!("{}\n", cols.join(","))
}

/// One row of `results.csv`: numbers in Rust's shortest round-trip form,
/// empty cells for an axis the row lacks and for missing metrics.
pub fn csv_line(row: &Row, axes: &[String]) -> String {
    let mut cells: Vec<String> = vec![
        row.key.clone(),
        row.dataset.clone(),
        row.view.clone(),
        row.object.clone(),
    ];
    cells.extend(axes.iter().map(|a| {
        row.axes
            .get(a)
            .map(AxisValue::to_string)
            .unwrap_or_default()
    }));
    cells.push(row.method.clone());
    cells.push(row.seed.to_string());
    match &row.metrics {
        Some(m) => cells.extend([
            m.mae_deg.to_string(),
            m.rmse_deg.to_string(),
            m.median_deg.to_string(),
            m.acc_11_25.to_string(),
            m.acc_22_5.to_string(),
            m.acc_30.to_string(),
            m.pixels.to_string(),
            m.missing.to_string(),
        ]),
        None => cells.extend(std::iter::repeat_n(String::new(), METRIC_COLUMNS.len())),
    }
    cells.push(row.error.clone().unwrap_or_default());
    cells.push(row.exit_status.map(|s| s.to_string()).unwrap_or_default());
    cells.push(row.stderr_tail.clone().unwrap_or_default());
    let quoted: Vec<String> = cells.iter().map(|c| csv::field(c)).collect();
    format!("{}\n", quoted.join(","))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn row(key: &str, error: Option<&str>) -> Row {
        Row {
            key: key.into(),
            dataset: "d".into(),
            view: "v".into(),
            object: "o".into(),
            axes: BTreeMap::from([("eta".to_string(), AxisValue::Number(1.5))]),
            method: "smith".into(),
            config: serde_json::json!({"method": "smith"}),
            seed: 0,
            metrics: None,
            error: error.map(str::to_string),
            view_dir: "views/x".into(),
            pictures: None,
            estimates: None,
            exit_status: None,
            stderr_tail: None,
        }
    }

    fn timing(key: &str) -> Timing {
        Timing {
            key: key.into(),
            method: "smith".into(),
            pixels: 10,
            noise_seconds: 0.5,
            reconstruct_seconds: 1.25,
            overhead_seconds: 0.0625,
        }
    }

    fn planned<'a>(keys: &[&'a str]) -> HashSet<&'a str> {
        keys.iter().copied().collect()
    }

    #[test]
    fn untrusted_rows_are_dropped_and_redone() {
        let dir = tempfile::tempdir().unwrap();
        let axes = ["eta".to_string()];
        let mut r = Results::open(dir.path(), &axes, &planned(&[])).unwrap();
        let mut b_other = row("b", None);
        b_other.seed = 7;
        for (row, key) in [
            (row("a", None), "a"),
            (row("a", None), "a"),
            (row("b", None), "b"),
            (b_other, "b"),
            (row("stray", None), "stray"),
            (
                row("full", Some("x.png: No space left on device (os error 28)")),
                "full",
            ),
            (row("failed", Some("the mask is empty")), "failed"),
        ] {
            r.append(row, timing(key)).unwrap();
        }
        drop(r);
        let keys = planned(&["a", "b", "full", "failed"]);
        let r = Results::open(dir.path(), &axes, &keys).unwrap();
        assert_eq!(r.dropped, 5);
        // A duplicate is kept once; a method's failure is a result.
        assert!(r.contains("a") && r.contains("failed"));
        // Conflicting rows, a row in no plan and a full disk are redone.
        assert!(!r.contains("b") && !r.contains("stray") && !r.contains("full"));
        let (rows, _) = read_rows(&dir.path().join(RESULTS_JSONL), true).unwrap();
        assert_eq!(rows.len(), 2);
    }

    #[test]
    fn csv_quotes_what_needs_it() {
        let line = csv_line(
            &row("k", Some("bad, \"very\"")),
            &["eta".into(), "x".into()],
        );
        assert_eq!(
            line,
            "k,d,v,o,1.5,,smith,0,,,,,,,,,\"bad, \"\"very\"\"\",,\n"
        );
        assert_eq!(
            csv_header(&["eta".into()]),
            "key,dataset,view,object,eta,method,seed,mae_deg,rmse_deg,median_deg,acc_11_25,\
             acc_22_5,acc_30,pixels,missing,error,exit_status,stderr_tail\n"
        );
    }

    #[test]
    fn a_torn_last_line_is_dropped_and_redone() {
        let dir = tempfile::tempdir().unwrap();
        let axes = ["eta".to_string()];
        let mut r = Results::open(dir.path(), &axes, &planned(&["a", "b", "c"])).unwrap();
        for k in ["a", "b", "c"] {
            r.append(row(k, None), timing(k)).unwrap();
        }
        drop(r);
        let path = dir.path().join(RESULTS_JSONL);
        let full = std::fs::read(&path).unwrap();
        std::fs::write(&path, &full[..full.len() - 7]).unwrap();
        let r = Results::open(dir.path(), &axes, &planned(&["a", "b", "c"])).unwrap();
        assert!(r.contains("b") && !r.contains("c"));
        assert_eq!(read_timings(&dir.path().join(TIMINGS_CSV)).len(), 2);
        let csv = std::fs::read_to_string(dir.path().join(RESULTS_CSV)).unwrap();
        assert_eq!(csv.lines().count(), 3);
        // A bad line in the middle is not a torn line: an error naming it.
        let mut broken = full.clone();
        broken[3] = b'#';
        std::fs::write(&path, &broken).unwrap();
        let err = read_rows(&path, false).unwrap_err().to_string();
        assert!(
            err.contains("results.jsonl") && err.contains("line 1"),
            "{err}"
        );
        std::fs::write(&path, &full[..full.len() - 1]).unwrap();
        assert!(read_rows(&path, true).is_err());
        assert_eq!(
            read_rows(&path, false).unwrap(),
            (vec![row("a", None), row("b", None)], true)
        );
    }

    #[test]
    fn metrics_read_back_print_the_same_bytes() {
        let mut r = row("k", None);
        r.metrics = Some(sfp_core::metrics::Metrics {
            mae_deg: 10.691440526053219,
            rmse_deg: 0.1 + 0.2,
            median_deg: 1e-300,
            acc_11_25: 66.02760736196319,
            acc_22_5: 98.15950920245399,
            acc_30: 100.0,
            pixels: 2608,
            missing: 0,
            specular: None,
        });
        let back: Row = serde_json::from_str(&row_json(&r)).unwrap();
        assert_eq!(csv_line(&back, &[]), csv_line(&r, &[]));
    }

    #[test]
    fn timings_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        write_all(dir.path(), &[], &[], &[timing("a"), timing("b")]).unwrap();
        assert_eq!(
            read_timings(&dir.path().join(TIMINGS_CSV)),
            [timing("a"), timing("b")]
        );
    }
}
