//! A method of one's own in a sweep: a `[[methods]]` entry with a
//! `command` (format in `benchmarks/README.md`). Each row writes its noisy
//! input as a view folder holding `input/` alone (no ground truth, no
//! `meta.json`), runs the command on it with an empty result folder, and
//! scores the normals it left there (`core::prediction`) as a built-in
//! method's are: over the view's scored mask, conventions.md §4.

use sfp_core::folder::{self, Kind};
use sfp_core::metrics::{Metrics, evaluate};
use sfp_core::prediction::{self, Axes};
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::{View, ViewInput};
use sfp_core::{Error, NormalMap, Result};
use std::fs::File;
use std::io::{Read, Seek, SeekFrom};
use std::os::unix::process::{CommandExt, ExitStatusExt};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The folder of the sweep folder that holds each command row's work
/// folder, `commands/<row key>/` (`view/`, `out/`, `stdout.txt`,
/// `stderr.txt`): removed when the row is scored, kept when it failed.
pub const WORK: &str = "commands";

/// The variables of the sweep's environment the command is given; nothing
/// else leaks into it (a sweep's results should not depend on the shell it
/// was started from).
pub const KEPT_ENV: [&str; 3] = ["PATH", "HOME", "LANG"];

/// Lines of a failed command's stderr kept in its row.
pub const STDERR_LINES: usize = 20;

/// The most bytes of stderr read for its tail: a row stays small whatever
/// the command printed.
const STDERR_BYTES: u64 = 8192;

/// How often a running command is checked on.
const POLL: Duration = Duration::from_millis(10);

/// One command runs at a time: a learned method usually takes the whole GPU
/// or every core, and two of them beside each other would fail or measure
/// each other. Built-in rows go on beside it.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// A `[[methods]]` entry's own program.
#[derive(Clone, Debug, PartialEq)]
pub struct CommandMethod {
    /// The program and its arguments; `{view}` and `{out}` in any of them
    /// are replaced by the row's view folder and result folder.
    pub command: Vec<String>,
    /// The frame of the normals it writes.
    pub axes: Axes,
    /// Seconds it may run before its process group is killed.
    pub timeout_s: f64,
    /// Where it runs: the sweep file's folder, so that a relative path in
    /// the command means what it does beside the file.
    pub dir: PathBuf,
}

/// A command row: its figures, or why it has none.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CommandRun {
    /// Against the view's ground truth; `None` without it or on failure.
    pub metrics: Option<Metrics>,
    /// Why the row failed (a non-zero exit, a timeout, no or a bad prediction).
    pub error: Option<String>,
    /// The command's exit code, when it exited.
    pub exit_status: Option<i32>,
    /// The last lines of its stderr, when the row failed.
    pub stderr_tail: Option<String>,
    /// Wall time of the command alone.
    pub seconds: f64,
}

/// How the process ended.
enum Ended {
    Exited(ExitStatus),
    TimedOut,
    NotStarted(String),
}

impl CommandMethod {
    /// The entry as rows record it (`Row::config`) and row keys hash it;
    /// the folder it runs in is not part of it (a moved sweep keeps its rows).
    pub fn to_value(&self) -> serde_json::Value {
        serde_json::json!({
            "command": self.command,
            "axes": self.axes.name(),
            "timeout_s": self.timeout_s,
        })
    }

    /// Runs the command on `input` (the row's noisy input) in the work
    /// folder `work` and scores its prediction against `view`'s ground
    /// truth; with `pictures`, the prediction (in our frame) and its error
    /// map are kept there as a result folder for the report's grids. An
    /// `Err` is the system's (a folder not written); the command's own
    /// failures are the row's, in [`CommandRun::error`].
    pub fn run(
        &self,
        view: &View,
        input: &ViewInput,
        work: &Path,
        pictures: Option<&Path>,
    ) -> Result<CommandRun> {
        let work = std::path::absolute(work).map_err(|e| Error::io(work, e))?;
        if work.exists() {
            // Left by a run killed during this row.
            std::fs::remove_dir_all(&work).map_err(|e| Error::io(&work, e))?;
        }
        let (view_dir, out_dir) = (work.join("view"), work.join("out"));
        input.write(&view_dir)?;
        std::fs::create_dir_all(&out_dir).map_err(|e| Error::io(&out_dir, e))?;
        let (ended, seconds) = self.execute(&view_dir, &out_dir, &work)?;
        let exit_status = match &ended {
            Ended::Exited(status) => status.code(),
            _ => None,
        };
        let prediction = match ended {
            Ended::Exited(status) if status.success() => self.prediction(&out_dir, input),
            Ended::Exited(status) => Err(match status.signal() {
                Some(signal) => format!("the command was killed by signal {signal}"),
                None => format!(
                    "the command exited with status {}",
                    status.code().unwrap_or_default()
                ),
            }),
            Ended::TimedOut => Err(format!(
                "the command ran past timeout_s = {} s and was killed with its process group",
                self.timeout_s
            )),
            Ended::NotStarted(why) => Err(why),
        };
        let mut run = CommandRun {
            exit_status,
            seconds,
            ..CommandRun::default()
        };
        match prediction {
            Ok(normals) => {
                run.metrics = score(view, &normals, pictures)?;
                std::fs::remove_dir_all(&work).map_err(|e| Error::io(&work, e))?;
            }
            Err(why) => {
                let kept = Path::new(WORK).join(work.file_name().unwrap_or_default());
                run.error = Some(format!("{why} (its folder: {})", kept.display()));
                run.stderr_tail = tail(&work.join("stderr.txt"));
            }
        }
        Ok(run)
    }

    /// Starts the command on `view_dir` and `out_dir` with a clean
    /// environment and its output in files of `work`, and waits for it to
    /// end or time out (seconds counted from its start).
    fn execute(&self, view_dir: &Path, out_dir: &Path, work: &Path) -> Result<(Ended, f64)> {
        let text = |p: &Path| {
            p.to_str().map(str::to_string).ok_or_else(|| {
                Error::file(
                    p,
                    "the path is not UTF-8: it cannot be put into the command",
                )
            })
        };
        let (view_text, out_text) = (text(view_dir)?, text(out_dir)?);
        let args: Vec<String> = self
            .command
            .iter()
            .map(|a| a.replace("{view}", &view_text).replace("{out}", &out_text))
            .collect();
        let program = Path::new(&args[0]);
        // A bare name is looked up in PATH; a relative path is the sweep
        // file's, as every other path of the file.
        let program = if program.is_relative() && program.components().count() > 1 {
            self.dir.join(program)
        } else {
            program.to_path_buf()
        };
        let log = |name: &str| {
            let path = work.join(name);
            File::create(&path).map_err(|e| Error::io(&path, e))
        };
        let mut command = Command::new(&program);
        command
            .args(&args[1..])
            .current_dir(&self.dir)
            .env_clear()
            .envs(
                KEPT_ENV
                    .iter()
                    .filter_map(|k| std::env::var_os(k).map(|v| (k, v))),
            )
            .env("SFP_VIEW", view_dir)
            .env("SFP_OUT", out_dir)
            .stdin(Stdio::null())
            // Files, not pipes: what the command starts and leaves behind
            // cannot block the sweep on a pipe it holds open.
            .stdout(log("stdout.txt")?)
            .stderr(log("stderr.txt")?)
            // Its own process group, whose id is its own: on a timeout the
            // whole group is killed, as killing the child alone would leave
            // what it started (a shell's commands, a Python's workers)
            // running and writing into `{out}`.
            .process_group(0);
        let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        let start = Instant::now();
        let mut child = match command.spawn() {
            Ok(child) => child,
            Err(e) => return Ok((Ended::NotStarted(not_started(&program, &e)), 0.0)),
        };
        let timeout = Duration::try_from_secs_f64(self.timeout_s).unwrap_or(Duration::MAX);
        loop {
            match child.try_wait() {
                Ok(Some(status)) => return Ok((Ended::Exited(status), seconds(start))),
                Ok(None) if start.elapsed() >= timeout => {
                    kill_group(&mut child);
                    return Ok((Ended::TimedOut, seconds(start)));
                }
                Ok(None) => std::thread::sleep(POLL),
                Err(e) => {
                    kill_group(&mut child);
                    return Err(Error::io(work, e));
                }
            }
        }
    }

    /// The prediction the command left in `out_dir`, in our frame, of the
    /// view's size.
    fn prediction(
        &self,
        out_dir: &Path,
        input: &ViewInput,
    ) -> std::result::Result<NormalMap, String> {
        let Some(file) = prediction::in_folder(out_dir) else {
            return Err(format!(
                "the command exited with status 0 but left no prediction in {{out}} (expected \
                 one of {})",
                prediction::FILE_NAMES.join(", ")
            ));
        };
        let normals = prediction::read(&file, self.axes).map_err(|e| e.to_string())?;
        let ((w, h), (vw, vh)) = (normals.size(), input.size());
        if (w, h) != (vw, vh) {
            return Err(format!(
                "{}: is {w}×{h} pixels but the view is {vw}×{vh}",
                file.display()
            ));
        }
        Ok(normals)
    }
}

/// The figures of `normals` as a built-in method's in a sweep: against the
/// view's ground truth over its scored mask (`None` without ground truth),
/// kept with the error map in `pictures` when given.
fn score(view: &View, normals: &NormalMap, pictures: Option<&Path>) -> Result<Option<Metrics>> {
    let scored = view.gt.as_ref().zip(view.scored_mask());
    let metrics = scored
        .as_ref()
        .map(|(gt, mask)| evaluate(normals, &gt.normals, mask))
        .transpose()?;
    if let Some(dir) = pictures {
        folder::replace(dir, Kind::Result, |d| {
            let result = ResultFolder::new(d);
            result.write_normals(normals)?;
            match (&scored, &metrics) {
                (Some((gt, mask)), Some(m)) => {
                    result.write_evaluation(normals, &gt.normals, mask, m)
                }
                _ => Ok(()),
            }
        })?;
    }
    Ok(metrics)
}

fn seconds(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// Kills the process group `child` leads, then the child itself (should
/// `kill` be missing), and reaps it.
fn kill_group(child: &mut Child) {
    let _ = Command::new("kill")
        .args(["-s", "KILL", "--", &format!("-{}", child.id())])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
    let _ = child.kill();
    let _ = child.wait();
}

/// Why `program` did not start, without the system's error number: a
/// missing program is the row's failure, not the system's refusal that a
/// resumed sweep retries (`results::is_system_failure`).
fn not_started(program: &Path, e: &std::io::Error) -> String {
    let why = match e.kind() {
        std::io::ErrorKind::NotFound => "not found (give its path, or put it on PATH)".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied (is it executable?)".into(),
        kind => kind.to_string(),
    };
    format!("the command {} could not start: {why}", program.display())
}

/// The last [`STDERR_LINES`] lines of the file `path` (`None` when empty).
fn tail(path: &Path) -> Option<String> {
    let mut file = File::open(path).ok()?;
    let len = file.metadata().ok()?.len();
    file.seek(SeekFrom::Start(len.saturating_sub(STDERR_BYTES)))
        .ok()?;
    let mut bytes = Vec::new();
    file.read_to_end(&mut bytes).ok()?;
    let text = String::from_utf8_lossy(&bytes);
    let lines: Vec<&str> = text.trim_end().lines().collect();
    let tail = lines[lines.len().saturating_sub(STDERR_LINES)..].join("\n");
    (!tail.trim().is_empty()).then_some(tail)
}
