//! What a call commits beyond its first depth: a continuation with its
//! certificate (`commit.rs`), as chosen, searched for (`search.rs`) or
//! taken off a knife edge (`knife.rs`).

use super::certify::Certificate;
use super::planner::MAX_TRACKS;

/// A continuation with its certificate.
#[derive(Clone, Copy, Debug)]
pub(super) struct Chosen<const N: usize> {
    pub(super) depths: [f32; MAX_TRACKS],
    pub(super) len: usize,
    pub(super) cert: Certificate,
    /// Whether it was found on the search path (not the candidate itself).
    pub(super) searched: bool,
    /// Whether it is the previous call's continuation, its certificate
    /// known (the candidate was no better).
    pub(super) previous: bool,
}

impl<const N: usize> Chosen<N> {
    /// The continuation `depths` (`len` tracks) with its certificate,
    /// neither searched for nor the previous one.
    pub(super) fn new(depths: [f32; MAX_TRACKS], len: usize, cert: Certificate) -> Self {
        Self {
            depths,
            len,
            cert,
            searched: false,
            previous: false,
        }
    }
}
