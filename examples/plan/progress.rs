//! Progress on stderr for runs longer than a second: nothing for a quick
//! run, then one line per step (`plan: track 3 of 5, 2.4 s`). Shown when
//! stderr is a terminal, or always with `PLAN_PROGRESS=1` (never with
//! `PLAN_PROGRESS=0`), so that scripts reading stderr see only warnings
//! and errors.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

pub struct Progress {
    what: &'static str,
    start: Instant,
    on: bool,
}

impl Progress {
    /// Starts timing `what` (the command's name, e.g. `plan`).
    pub fn new(what: &'static str) -> Self {
        let on = match std::env::var("PLAN_PROGRESS").as_deref() {
            Ok("1") => true,
            Ok("0") => false,
            _ => std::io::stderr().is_terminal(),
        };
        Self {
            what,
            start: Instant::now(),
            on,
        }
    }

    /// Reports step `done` of `total` (`unit`: "track", "run") once the
    /// run has taken more than a second.
    pub fn step(&self, unit: &str, done: usize, total: usize) {
        let t = self.start.elapsed();
        if self.on && t > Duration::from_secs(1) {
            eprintln!(
                "{}: {unit} {done} of {total}, {:.1} s",
                self.what,
                t.as_secs_f64()
            );
        }
    }
}
