//! The end of a BFGS run that only crawls: **slivers** and **crawls**.
//!
//! A step the line search had to cut below 1/64 of the direction, twice
//! in a row, ends the run ([`super::Status::LineSearchFailed`]): `J` is
//! not smooth at the step's scale (a depth loop that integrates
//! conditionally makes it a sawtooth of teeth centimetres wide,
//! `plan/polish.rs`), every longer step lands past a jump, and the run
//! would crawl a few parts in 10⁵ of `J` an iteration at the cost of a
//! dozen halvings each.
//!
//! A step cut below a quarter of the direction that gains less than ten
//! times the 3.14b threshold (a **crawl**) counts as a sliver too: where
//! `J` jumps up just ahead (not a kink, which the vee caps: `vee.rs`),
//! every first trial lands past the jump at the smooth side's minimum,
//! the interpolation cuts it to a tenth, and the run closes on the jump a
//! tenth of the way an iteration, gaining 2e-5 of `J` each (11 iterations
//! on `check_planner.py --seed 2977 --vehicle
//! tools/reference/vehicles/fast.toml`, `unseen_2977_2` track 1; the
//! polish then reads past the jump).
//!
//! After a sliver, a step of any length that gains less than that carries
//! the crawl on: where the direction itself has shrunk to centimetres, a
//! full step between two slivers had reset their count (11 iterations on
//! `--seed 3196 --vehicle tools/reference/vehicles/fast.toml`,
//! `unseen_3196_2` track 5, unconstrained; 9 now).

/// A step shorter than this share of the direction is a sliver (module
/// docs): six halvings of the line search.
const SLIVER: f32 = 1.0 / 64.0;

/// A step shorter than this share of the direction that gains less than
/// [`CRAWL`] stopping thresholds is a crawl, counted as a sliver (module
/// docs).
const SHORT: f32 = 0.25;

/// How many 3.14b thresholds a short step must gain not to be a crawl.
const CRAWL: f32 = 10.0;

/// Slivers (and crawls) in a row that end the run.
const ENDS: u32 = 2;

/// The slivers and crawls of a run in a row so far.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Slivers(u32);

impl Slivers {
    /// Counts the step just taken: `step` and `along` the lengths (m) of
    /// the step and of its direction, `gain` the fall of `J` it made and
    /// `threshold` the 3.14b threshold at its end (m³).
    pub(crate) fn record(&mut self, (step, along): (f32, f32), (gain, threshold): (f32, f32)) {
        let little = gain <= CRAWL * threshold;
        let crawl = (step < SHORT * along || self.0 > 0) && little;
        self.0 = if step < SLIVER * along || crawl {
            self.0.saturating_add(1)
        } else {
            0
        };
    }

    /// Whether the run ends here (module docs).
    pub(crate) fn end(&self) -> bool {
        self.0 >= ENDS
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_slivers_or_crawls_in_a_row_end_a_run() {
        let threshold = 1.0;
        // A sliver, then a full step that gains much: the count restarts.
        let mut s = Slivers::default();
        s.record((0.01, 1.0), (100.0, threshold));
        s.record((1.0, 1.0), (100.0, threshold));
        s.record((0.01, 1.0), (100.0, threshold));
        assert!(!s.end());
        // Two slivers in a row end it.
        s.record((0.01, 1.0), (100.0, threshold));
        assert!(s.end());
        // A short step gaining little is a crawl; a full one is not,
        // unless it follows a sliver.
        let mut s = Slivers::default();
        s.record((0.2, 1.0), (5.0, threshold));
        s.record((0.2, 1.0), (5.0, threshold));
        assert!(s.end());
        let mut s = Slivers::default();
        s.record((1.0, 1.0), (5.0, threshold));
        s.record((1.0, 1.0), (5.0, threshold));
        assert!(!s.end());
        s.record((0.01, 1.0), (100.0, threshold));
        s.record((1.0, 1.0), (5.0, threshold));
        assert!(s.end());
    }
}
