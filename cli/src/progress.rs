//! Progress of a long command: a bar on a terminal, and plain lines where
//! stderr is a log file or a pipe (a cluster job's log, `2> log`), where a
//! bar draws nothing: the first update, then one line every
//! [`LINE_EVERY`], and the last.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Time between two plain lines.
const LINE_EVERY: Duration = Duration::from_secs(10);

pub struct Progress {
    bar: ProgressBar,
    /// What is counted ("rows", "views").
    unit: &'static str,
    /// When the last plain line was printed; `None` on a terminal.
    plain: Option<Mutex<Option<Instant>>>,
}

impl Progress {
    /// A bar of `len` `unit`s drawn with `template` (indicatif's format).
    pub fn new(len: u64, template: &str, unit: &'static str) -> Progress {
        let style = ProgressStyle::with_template(template).expect("valid progress template");
        Progress {
            bar: ProgressBar::new(len).with_style(style),
            unit,
            plain: (!std::io::stderr().is_terminal()).then(|| Mutex::new(None)),
        }
    }

    /// The bar itself, for what only a terminal shows.
    pub fn bar(&self) -> &ProgressBar {
        &self.bar
    }

    /// `done` of `total` (when known), now doing `message`.
    pub fn set(&self, done: u64, total: Option<u64>, message: &str) {
        if let Some(total) = total {
            self.bar.set_length(total);
        }
        self.bar.set_position(done);
        self.bar.set_message(message.to_string());
        self.line(false);
    }

    /// One more done, now doing `message` (unchanged when `None`).
    pub fn inc(&self, message: Option<&str>) {
        self.bar.inc(1);
        if let Some(m) = message {
            self.bar.set_message(m.to_string());
        }
        self.line(false);
    }

    /// Clears the bar, or prints the last line.
    pub fn finish(&self) {
        self.line(true);
        self.bar.finish_and_clear();
    }

    fn line(&self, last: bool) {
        let Some(printed) = &self.plain else {
            return;
        };
        let mut printed = printed.lock().unwrap_or_else(|e| e.into_inner());
        if last || printed.is_none_or(|t| t.elapsed() >= LINE_EVERY) {
            let (done, total) = (self.bar.position(), self.bar.length().unwrap_or(0));
            eprintln!(
                "progress: {done}/{total} {} {} [{:.0} s]",
                self.unit,
                self.bar.message(),
                self.bar.elapsed().as_secs_f64()
            );
            *printed = Some(Instant::now());
        }
    }
}
