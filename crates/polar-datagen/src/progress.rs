//! Progress reporting: an indicatif bar with ETA on a terminal, plain lines otherwise
//! (log files of cluster jobs), nothing in quiet mode.

use std::io::IsTerminal;
use std::sync::Mutex;
use std::time::Instant;

use indicatif::{ProgressBar, ProgressStyle};

/// How to show progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// A bar if stderr is a terminal, else plain lines.
    Auto,
    /// Plain lines on stderr.
    Plain,
    /// Nothing.
    Quiet,
}

/// A running progress display.
pub struct ProgressHandle {
    bar: Option<ProgressBar>,
    plain: Option<Mutex<Plain>>,
}

struct Plain {
    start: Instant,
    done: u64,
    total: u64,
    already: u64,
}

impl Progress {
    /// Starts a display for `todo` samples, `already` of the shard being done before.
    pub fn start(self, todo: u64, already: u64) -> ProgressHandle {
        let terminal = std::io::stderr().is_terminal();
        match self {
            Progress::Auto if terminal => {
                let bar = ProgressBar::new(todo);
                let style = ProgressStyle::with_template(
                    "{bar:40} {pos}/{len} samples, {elapsed} elapsed, ETA {eta} {msg}",
                )
                .unwrap_or_else(|_| ProgressStyle::default_bar());
                bar.set_style(style);
                ProgressHandle {
                    bar: Some(bar),
                    plain: None,
                }
            }
            Progress::Quiet => ProgressHandle {
                bar: None,
                plain: None,
            },
            _ => {
                eprintln!("{todo} samples to make ({already} already done)");
                let plain = Plain {
                    start: Instant::now(),
                    done: 0,
                    total: todo,
                    already,
                };
                ProgressHandle {
                    bar: None,
                    plain: Some(Mutex::new(plain)),
                }
            }
        }
    }
}

impl ProgressHandle {
    /// One sample finished.
    pub fn tick(&self, id: &str, seconds: f64) {
        if let Some(bar) = &self.bar {
            bar.set_message(id.to_owned());
            bar.inc(1);
        }
        if let Some(p) = &self.plain {
            let mut p = p.lock().unwrap_or_else(|e| e.into_inner());
            p.done += 1;
            let elapsed = p.start.elapsed().as_secs_f64();
            let eta = elapsed / p.done as f64 * (p.total - p.done) as f64;
            eprintln!(
                "[{}/{}] {id} {seconds:.2} s; elapsed {elapsed:.0} s, ETA {eta:.0} s ({} resumed)",
                p.done, p.total, p.already
            );
        }
    }

    /// All samples finished.
    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}
