//! Robustness sweeps (`sfp bench`): views × axes × methods × noise seeds.
//!
//! A sweep file ([`file`](mod@file)) expands into a plan of rows ([`plan`]); each
//! distinct noise-free render is made once and cached ([`cache`]), each noise
//! seed is a cheap exposure of its Stokes ([`exposure`]), and every row is
//! appended to the result files as soon as it is done ([`results`]), so a
//! killed sweep resumes where it stopped. [`shard`] splits a sweep for job
//! arrays and [`merge`] joins the shards' folders. A method may be one's
//! own program ([`command_method`]). Format and usage:
//! `benchmarks/README.md`.

pub mod axes;
pub mod cache;
pub mod command_method;
pub mod exposure;
pub mod file;
pub mod in_order;
pub mod oracle;
pub mod plan;
pub mod provenance;
pub mod results;
pub mod shard;

use crate::row::{Estimates, Row, Timing};
use file::{Runner, Sweep};
use plan::{Origin, Plan, PlannedRow};
use provenance::PROVENANCE_JSON;
use rayon::prelude::*;
use results::Results;
use sfp_core::collection::{self, Collection};
use sfp_core::metrics::Metrics;
use sfp_core::oracle::oracles_of;
use sfp_core::view::{View, ViewInput};
use sfp_core::{Error, Result, io};
use sfp_reconstruct::input::Input;
use sfp_reconstruct::registry;
use shard::Shard;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The sweep file, copied verbatim into the output folder.
pub const SWEEP_TOML: &str = "sweep.toml";
/// Every row key of the whole (unsharded) plan, one per line, in plan order:
/// how a merge orders the shards' rows.
pub const PLAN_TXT: &str = "plan.txt";

/// Where a run is, for a progress bar.
pub struct Progress<'a> {
    /// Rows of this shard done (including those done by an earlier run).
    pub done: usize,
    /// Rows of this shard.
    pub total: usize,
    /// What is being done now.
    pub message: &'a str,
}

/// What one run did, with its time split as in `timings.csv`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    /// Rows of this shard.
    pub rows: usize,
    /// Rows already done by an earlier run.
    pub skipped: usize,
    /// Rows computed now, and how many of them failed.
    pub computed: usize,
    pub failed: usize,
    /// Rows of the folder dropped on resuming (repeated, conflicting, in no
    /// plan, or failed by the system) and so redone.
    pub dropped: usize,
    /// Rows left undone because the system refused a read or write.
    pub undone: usize,
    /// Noise-free renders made now, and their time.
    pub renders: usize,
    pub render_seconds: f64,
    pub noise_seconds: f64,
    pub reconstruct_seconds: f64,
    pub overhead_seconds: f64,
    /// Wall time of the run.
    pub seconds: f64,
}

/// Runs `shard` of `sweep` into `out`, skipping rows already there, calling
/// `progress` before each row and once at the end.
pub fn run(
    sweep: &Sweep,
    out: &Path,
    shard: Shard,
    progress: &dyn Fn(Progress),
) -> Result<Summary> {
    let start = Instant::now();
    let plan = Plan::new(sweep)?;
    let _claim = collection::claim(out, Collection::Sweep)?;
    prepare(sweep, &plan, out, shard)?;
    let axes: Vec<String> = sweep.axes.keys().cloned().collect();
    let mine: Vec<usize> = (0..plan.groups.len()).filter(|&g| shard.owns(g)).collect();
    let keys: Vec<String> = mine
        .iter()
        .flat_map(|&g| plan.groups[g].exposures.iter())
        .flat_map(|e| e.rows.iter().map(|r| r.key.clone()))
        .collect();
    let planned = keys.iter().map(String::as_str).collect();
    let mut results = Results::open(out, &axes, &planned)?;
    let mut summary = Summary {
        rows: keys.len(),
        skipped: keys.iter().filter(|k| results.contains(k)).count(),
        dropped: results.dropped,
        ..Summary::default()
    };
    // The first failure the system caused, and how many rows it left undone.
    let mut system_failure: Option<String> = None;
    let mut done = summary.skipped;
    let mut last_append = 0.0;
    for &g in &mine {
        let group = &plan.groups[g];
        let view = &plan.views[group.view];
        // The group's rows still to do, with the index of their exposure.
        let jobs: Vec<(usize, &PlannedRow)> = group
            .exposures
            .iter()
            .enumerate()
            .flat_map(|(e, exposure)| exposure.rows.iter().map(move |r| (e, r)))
            .filter(|(_, r)| !results.contains(&r.key))
            .collect();
        if jobs.is_empty() {
            continue;
        }
        progress(Progress {
            done,
            total: summary.rows,
            message: &format!("{}/{}: noise-free view", view.dataset, view.view),
        });
        let load_start = Instant::now();
        let cached = cache::noise_free(view, group, out);
        if let Ok(c) = &cached
            && let Some(seconds) = c.rendered
        {
            summary.renders += 1;
            summary.render_seconds += seconds;
        }
        // Reading the cache is per-row overhead; rendering is counted apart.
        let load_seconds = load_start.elapsed().as_secs_f64()
            - cached.as_ref().ok().and_then(|c| c.rendered).unwrap_or(0.0);
        let load_share = load_seconds / jobs.len() as f64;
        let view_index = match &group.origin {
            Origin::Rendered { view_index, .. } => *view_index,
            _ => 0,
        };
        // The noisy inputs, each shared by its exposure's rows, with each
        // row's share of the exposing time.
        let inputs: Vec<(NoisyInput, f64)> = group
            .exposures
            .par_iter()
            .enumerate()
            .map(|(e, exposure)| {
                let rows = jobs.iter().filter(|(j, _)| *j == e).count();
                if rows == 0 {
                    return (Err(Failure::skipped()), 0.0);
                }
                let commands = jobs
                    .iter()
                    .any(|(j, r)| *j == e && matches!(r.runner, Runner::Command(_)));
                let start = Instant::now();
                let input = match &cached {
                    Err(e) => Err(Failure::of(e)),
                    Ok(c) => match &exposure.sensor {
                        Some(sensor) => {
                            exposure::noisy_view_input(&c.view, sensor, exposure.seed, view_index)
                                .map(Cow::Owned)
                        }
                        None => Ok(Cow::Borrowed(&c.view.input)),
                    }
                    .and_then(|codes| {
                        Ok(Exposed {
                            view: &c.view,
                            input: Input::from_view(&codes)?,
                            codes: commands.then_some(codes),
                        })
                    })
                    .map_err(|e| Failure::of(&e)),
                };
                (input, start.elapsed().as_secs_f64() / rows as f64)
            })
            .collect();
        progress(Progress {
            done,
            total: summary.rows,
            message: &format!("{}/{}: {} rows", view.dataset, view.view, jobs.len()),
        });
        // The group's rows run in parallel on the current rayon pool, each
        // method's own parallelism nested in the same pool, so both levels
        // share the cores and no thread waits for a small image's work. The
        // rows are recorded in plan order, each as soon as those before it
        // are, so the result files do not depend on the number of threads
        // and a stopped sweep keeps every row it recorded.
        let compute = |k: usize| {
            let (e, planned) = jobs[k];
            compute_row(planned, &inputs[e], out)
        };
        let record = |computed: Computed| -> Result<()> {
            let planned = computed.planned;
            // Not a result: left out, so the next run redoes it.
            if let Some(Failure {
                message,
                system: true,
            }) = &computed.error
            {
                system_failure.get_or_insert_with(|| message.clone());
                summary.undone += 1;
                done += 1;
                return Ok(());
            }
            let error = computed.error.map(|f| f.message);
            summary.failed += usize::from(error.is_some());
            let row = Row {
                key: planned.key.clone(),
                dataset: view.dataset.clone(),
                view: view.view.clone(),
                object: view.object.clone(),
                axes: planned.axes.clone(),
                method: planned.method.clone(),
                config: planned.runner.to_value(),
                seed: planned.seed,
                metrics: computed.metrics,
                estimates: computed.estimates,
                error,
                view_dir: cached
                    .as_ref()
                    .map(|c| c.view_dir.clone())
                    .unwrap_or_default(),
                pictures: planned.pictures.clone(),
                exit_status: computed.exit_status,
                stderr_tail: computed.stderr_tail,
            };
            // A row's own append is timed after its timing line is
            // written: it goes into the next row's overhead (and the
            // summary's).
            let timing = Timing {
                key: planned.key.clone(),
                method: planned.method.clone(),
                pixels: computed.pixels,
                noise_seconds: computed.noise_seconds,
                reconstruct_seconds: computed.reconstruct_seconds,
                overhead_seconds: computed.seconds - computed.reconstruct_seconds
                    + load_share
                    + last_append,
            };
            summary.noise_seconds += timing.noise_seconds;
            summary.reconstruct_seconds += timing.reconstruct_seconds;
            summary.overhead_seconds += timing.overhead_seconds - last_append;
            let append_start = Instant::now();
            results.append(row, timing)?;
            last_append = append_start.elapsed().as_secs_f64();
            summary.overhead_seconds += last_append;
            summary.computed += 1;
            done += 1;
            Ok(())
        };
        in_order::compute_in_order(jobs.len(), compute, record)?;
    }
    results.finish(&keys)?;
    summary.seconds = start.elapsed().as_secs_f64();
    progress(Progress {
        done,
        total: summary.rows,
        message: "done",
    });
    if let Some(first) = system_failure {
        return Err(Error::io(
            out,
            std::io::Error::other(format!(
                "{} rows were not done because the system refused a read or write (the \
                 first: {first}); run the same command again to do them",
                summary.undone
            )),
        ));
    }
    Ok(summary)
}

/// Why a row has no result, and whether the system caused it (then it is
/// no result and is redone by the next run).
#[derive(Clone)]
struct Failure {
    message: String,
    system: bool,
}

impl Failure {
    fn of(e: &Error) -> Failure {
        Failure {
            message: e.to_string(),
            system: matches!(e, Error::Io { .. }),
        }
    }

    /// The input of an exposure with no row to do: never read.
    fn skipped() -> Failure {
        Failure {
            message: "no row of this exposure is to be done".into(),
            system: false,
        }
    }
}

/// An exposure's input for the methods, with the view it came from and,
/// when a command method is to be given them, the polarizer codes it was
/// read from.
struct Exposed<'v> {
    view: &'v View,
    input: Input,
    codes: Option<Cow<'v, ViewInput>>,
}

/// An exposure's input, or why there is none.
type NoisyInput<'v> = std::result::Result<Exposed<'v>, Failure>;

/// One row reconstructed and scored, before it is recorded.
struct Computed<'p> {
    planned: &'p PlannedRow,
    metrics: Option<Metrics>,
    estimates: Option<Estimates>,
    error: Option<Failure>,
    /// A command method's exit code and, when it failed, its stderr's end.
    exit_status: Option<i32>,
    stderr_tail: Option<String>,
    /// The row's share of exposing its input.
    noise_seconds: f64,
    reconstruct_seconds: f64,
    pixels: usize,
    /// The whole row, reconstruction and scoring.
    seconds: f64,
}

/// Runs `planned` on its exposure's input (and the row's share of exposing
/// it), writing its pictures under `out` when the plan keeps them.
fn compute_row<'p>(
    planned: &'p PlannedRow,
    (input, noise_seconds): &(NoisyInput, f64),
    out: &Path,
) -> Computed<'p> {
    let start = Instant::now();
    let mut computed = Computed {
        planned,
        metrics: None,
        estimates: None,
        error: None,
        exit_status: None,
        stderr_tail: None,
        noise_seconds: *noise_seconds,
        reconstruct_seconds: 0.0,
        pixels: 0,
        seconds: 0.0,
    };
    match (input, &planned.runner) {
        (Err(e), _) => computed.error = Some(e.clone()),
        (Ok(exposed), Runner::Registered(config)) => {
            let (v, input) = (exposed.view, &exposed.input);
            let outcome = match &planned.pictures {
                Some(dir) => registry::run_with_input(v, input, config, &out.join(dir)),
                None => registry::evaluate_with_input(v, input, config),
            };
            computed.pixels = input.mask.count();
            match outcome {
                Ok(o) => {
                    computed.metrics = o.metrics;
                    computed.estimates = Estimates::of(&o.reconstruction.run, v.meta.as_ref());
                    computed.reconstruct_seconds = o.seconds;
                    computed.pixels = o.pixels;
                }
                Err(e) => computed.error = Some(Failure::of(&e)),
            }
        }
        (Ok(exposed), Runner::Oracle(oracle)) => {
            let (v, input) = (exposed.view, &exposed.input);
            computed.pixels = input.mask.count();
            let eta = oracle.eta.expect("a planned oracle has the view's η");
            if let (Some(gt), Some(mask)) = (v.gt.as_ref(), v.scored_mask()) {
                match oracles_of(&input.dop, &input.aop, &gt.normals, &mask, eta) {
                    Ok(o) => computed.metrics = Some(o.of(oracle.model).clone()),
                    Err(e) => computed.error = Some(Failure::of(&e)),
                }
            }
        }
        (Ok(exposed), Runner::Command(command)) => {
            let codes = exposed.codes.as_deref().expect("kept for command rows");
            let work = out.join(command_method::WORK).join(&planned.key);
            let pictures = planned.pictures.as_ref().map(|p| out.join(p));
            computed.pixels = exposed.input.mask.count();
            match command.run(exposed.view, codes, &work, pictures.as_deref()) {
                Ok(run) => {
                    computed.metrics = run.metrics;
                    computed.error = run.error.map(|message| Failure {
                        message,
                        system: false,
                    });
                    computed.exit_status = run.exit_status;
                    computed.stderr_tail = run.stderr_tail;
                    computed.reconstruct_seconds = run.seconds;
                }
                Err(e) => computed.error = Some(Failure::of(&e)),
            }
        }
    }
    computed.seconds = start.elapsed().as_secs_f64();
    computed
}

/// Creates `out` with `sweep.toml`, `plan.txt` and `provenance.json`, or
/// checks that the folder holds the same sweep and shard (resuming).
fn prepare(sweep: &Sweep, plan: &Plan, out: &Path, shard: Shard) -> Result<()> {
    let old_sweep = out.join(SWEEP_TOML);
    if old_sweep.exists() {
        let old = std::fs::read_to_string(&old_sweep).map_err(|e| Error::io(&old_sweep, e))?;
        if old != sweep.text {
            return Err(Error::file(
                &old_sweep,
                format!(
                    "this folder holds the results of another sweep (its sweep.toml differs \
                     from {}): give another --out, or delete the folder",
                    sweep.path.display()
                ),
            ));
        }
        let old_provenance = out.join(PROVENANCE_JSON);
        let old_shard = recorded_shard(out)?;
        if old_shard != shard.to_string() {
            return Err(Error::file(
                &old_provenance,
                format!(
                    "this folder holds shard {old_shard} of the sweep, not {shard}: give each \
                     shard its own --out"
                ),
            ));
        }
    }
    // sweep.toml last: a folder that has it has the others.
    let provenance = provenance::record(&shard.to_string());
    io::write_atomic(
        &out.join(PROVENANCE_JSON),
        &serde_json::to_vec_pretty(&provenance).expect("provenance serialises"),
    )?;
    let plan_keys: String = plan.rows().map(|r| format!("{}\n", r.key)).collect();
    io::write_atomic(&out.join(PLAN_TXT), plan_keys.as_bytes())?;
    io::write_atomic(&old_sweep, sweep.text.as_bytes())
}

/// The shard (`K/N`, or `merged`) a sweep folder's `provenance.json`
/// records: an unreadable record is an error, as the shard check would
/// otherwise let another shard's run mix its rows in.
fn recorded_shard(dir: &Path) -> Result<String> {
    let path = dir.join(PROVENANCE_JSON);
    let bytes = std::fs::read(&path).map_err(|e| Error::io(&path, e))?;
    serde_json::from_slice::<serde_json::Value>(&bytes)
        .ok()
        .and_then(|p| p["shard"].as_str().map(str::to_string))
        .ok_or_else(|| {
            Error::file(
                &path,
                "is not a sweep's provenance record (no \"shard\"): the folder cannot be \
                 resumed safely; give another --out",
            )
        })
}

/// What [`merge`] did.
#[derive(Clone, Debug, PartialEq)]
pub struct Merged {
    /// Rows in the merged folder.
    pub rows: usize,
    /// Rows of the plan that no shard has.
    pub missing: usize,
}

/// Merges the sweep folders `dirs` (shards of one sweep) into `out`: the
/// rows of all, in plan order, and their cached views and pictures
/// (hard-linked where possible). The same sweep and plan are required; a
/// shard with a torn last row must be re-run first. With `complete`, a plan
/// row none of the folders has is an error, before anything is written
/// (a job scheduler's merge after a failed task).
pub fn merge(dirs: &[PathBuf], out: &Path, complete: bool) -> Result<Merged> {
    let Some(first) = dirs.first() else {
        return Err(Error::invalid("merge needs at least one sweep folder"));
    };
    let read = |dir: &Path, name: &str| {
        let path = dir.join(name);
        std::fs::read_to_string(&path).map_err(|e| {
            Error::file(
                &path,
                format!("cannot read ({e}): is {} a sweep folder?", dir.display()),
            )
        })
    };
    let sweep_text = read(first, SWEEP_TOML)?;
    let plan_text = read(first, PLAN_TXT)?;
    let out_abs = std::path::absolute(out).map_err(|e| Error::io(out, e))?;
    for dir in dirs {
        let dir_abs = std::path::absolute(dir).map_err(|e| Error::io(dir, e))?;
        if out_abs.starts_with(&dir_abs) {
            return Err(Error::file(
                out,
                format!(
                    "the merged folder must be outside its inputs, and it is inside {}",
                    dir.display()
                ),
            ));
        }
    }
    let _claim = collection::claim(out, Collection::Sweep)?;
    // Only an earlier merge of the same sweep is replaced: another sweep's
    // folder, or a shard's, keeps its rows.
    if out.join(SWEEP_TOML).exists() {
        let merged = recorded_shard(out).is_ok_and(|s| s == "merged");
        if !merged || read(out, SWEEP_TOML)? != sweep_text {
            return Err(Error::file(
                out,
                "holds another sweep or a shard's rows, not an earlier merge of this sweep: \
                 give a new folder as the merged --out",
            ));
        }
    }
    let (mut rows, mut timings) = (Vec::new(), Vec::new());
    let mut seen = std::collections::HashMap::new();
    let planned = plan_text.lines().collect();
    for dir in dirs {
        if read(dir, SWEEP_TOML)? != sweep_text || read(dir, PLAN_TXT)? != plan_text {
            return Err(Error::file(
                &dir.join(SWEEP_TOML),
                format!(
                    "a different sweep from {}'s: cannot merge them",
                    first.display()
                ),
            ));
        }
        let (dir_rows, _) = results::read_rows(&dir.join(results::RESULTS_JSONL), true)?;
        for row in results::keep_trusted(dir_rows, &planned) {
            match seen.get(&row.key) {
                Some(other) if other == &row => continue,
                Some(_) => {
                    return Err(Error::file(
                        &dir.join(results::RESULTS_JSONL),
                        format!(
                            "row {} differs from the same row in another folder",
                            row.key
                        ),
                    ));
                }
                None => {
                    seen.insert(row.key.clone(), row.clone());
                    rows.push(row);
                }
            }
        }
        timings.extend(results::read_timings(&dir.join(results::TIMINGS_CSV)));
    }
    let order: Vec<String> = plan_text.lines().map(str::to_string).collect();
    let missing = order.iter().filter(|k| !seen.contains_key(*k)).count();
    if complete && missing > 0 {
        return Err(Error::invalid(format!(
            "{missing} of the sweep's {} rows are in none of the folders: re-run the shards \
             that failed or did not finish, then merge",
            order.len()
        )));
    }
    for dir in dirs {
        for tree in ["views", "pictures"] {
            link_tree(&dir.join(tree), &out.join(tree))?;
        }
    }
    let mut kept = std::collections::HashSet::new();
    timings.retain(|t| kept.insert(t.key.clone()));
    results::sort_by_plan(&mut rows, &mut timings, &order);
    let sweep = Sweep::from_toml(&sweep_text, &first.join(SWEEP_TOML))?;
    let axes: Vec<String> = sweep.axes.keys().cloned().collect();
    io::write_atomic(&out.join(SWEEP_TOML), sweep_text.as_bytes())?;
    io::write_atomic(&out.join(PLAN_TXT), plan_text.as_bytes())?;
    let mut provenance: serde_json::Value = serde_json::from_str(&read(first, PROVENANCE_JSON)?)
        .map_err(|e| Error::file(&first.join(PROVENANCE_JSON), e.to_string()))?;
    provenance["shard"] = "merged".into();
    provenance["merged_from"] = dirs
        .iter()
        .map(|d| d.display().to_string())
        .collect::<Vec<_>>()
        .into();
    io::write_atomic(
        &out.join(PROVENANCE_JSON),
        &serde_json::to_vec_pretty(&provenance).expect("provenance serialises"),
    )?;
    results::write_all(out, &axes, &rows, &timings)?;
    Ok(Merged {
        rows: rows.len(),
        missing,
    })
}

/// Hard-links (or copies, across file systems) every file under `from` to
/// the same place under `to`, keeping files already there.
fn link_tree(from: &Path, to: &Path) -> Result<()> {
    if !from.is_dir() {
        return Ok(());
    }
    std::fs::create_dir_all(to).map_err(|e| Error::io(to, e))?;
    for entry in std::fs::read_dir(from).map_err(|e| Error::io(from, e))? {
        let entry = entry.map_err(|e| Error::io(from, e))?;
        let (src, dst) = (entry.path(), to.join(entry.file_name()));
        if src.is_dir() {
            link_tree(&src, &dst)?;
        } else if !dst.exists() && std::fs::hard_link(&src, &dst).is_err() {
            std::fs::copy(&src, &dst).map_err(|e| Error::io(&dst, e))?;
        }
    }
    Ok(())
}
