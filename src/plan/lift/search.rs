//! The lifts of one earlier depth by doubling, for the escape of the
//! module above (`lift/mod.rs`): what they free of a later track, at its
//! own depth, its preferred depth or its deepest useful one, and the
//! starts made from them.

use crate::plan::bottom::deepest;
use crate::plan::objective::{PlanObjective, Stop};
use crate::plan::raise::{clearing, raised};
use crate::plan::scan::with_depth;
use crate::sim::{TrackScore, VehicleState};

/// Lifts tried for one track (the band, doubling): 128 bands at most,
/// so that a climb still rising at 32 bands is seen to saturate (the
/// lift before a saturated one, module docs).
const LIFTS: u32 = 8;

/// The far lift, in bands: the doubling's reach (module docs).
const FAR: f32 = 32.0;

/// The lifts of the walk along a held track's target, in bands (module
/// docs).
const WALKS: [f32; 2] = [1.0, 2.0];

/// The walk's lifts, in bands, where its first step goes past a jump of
/// the held track's least altitude (module docs).
const SHORT: [f32; 2] = [0.25, 0.5];

/// The most a walk's step deepens the held track, in what the lift freed
/// of its least altitude.
const REACH: f32 = 4.0;

/// The relative change of track `j`'s `J` between two lifts that tells
/// that its flight moved: its climb did not saturate.
const MOVED: f32 = 1e-4;

/// What is fixed while one later track's lift is sought.
#[derive(Clone, Copy)]
pub(super) struct Lift<const N: usize> {
    /// The state track `j` starts in.
    pub(super) at_j: VehicleState<N>,
    /// The lifted track and the later one.
    pub(super) j: usize,
    pub(super) g: usize,
    /// Their depths as the SQP left them, and depth `j`'s box floor, m.
    pub(super) zj: f32,
    pub(super) zg: f32,
    pub(super) lo: f32,
    /// Track `g`'s target altitude, the band `h_r − h_a` and the altitude
    /// that counts as a gain, m.
    pub(super) target: f32,
    pub(super) band: f32,
    pub(super) slack: f32,
    /// Track `g`'s preferred depth where it is held above it, m.
    pub(super) deep: Option<f32>,
}

/// The starts a lift search makes (`Lift::starts`).
pub(super) type Starts<const K: usize> = [Option<[f32; K]>; 4];

/// What the lifts by doubling found.
pub(super) enum Next<const K: usize> {
    /// A start with track `g` deepened by the altitude freed; and, where
    /// track `g` at its preferred depth does not clear its target at that
    /// lift, the start with the deepest depth `g` found that does (its
    /// least altitude may fall far slower than a metre per metre: a rise
    /// passed early in the track, before the dive).
    Freed([f32; K], Option<[f32; K]>),
    /// The lifts `(held, free)` (m) between which track `g` at its
    /// preferred depth first clears its target (`free` feasible), or
    /// `(held, held)` where the climb saturates first.
    Deep((f32, f32)),
    /// A freed start, where the same lift also clears track `g` at its
    /// preferred depth: its least altitude there is set by the earlier
    /// track (a saturated dive's plateau), not by its own depth.
    Both([f32; K], (f32, f32)),
    /// The lifts `(held, free)` (m) between which the far lift freed track
    /// `g` at its deep depth, past a plateau on which its least altitude
    /// was set by its own depth; and the plateau's end, as
    /// [`Next::Deep`]'s `(held, held)`.
    Far((f32, f32), (f32, f32)),
    Nothing,
}

impl<const N: usize> Lift<N> {
    /// Depth `j` lifted by the band, doubling: one or two flights of the
    /// two tracks per lift, and one for the far lift where track `g`
    /// settles on a plateau while track `j`'s flight moves (`lift/`'s
    /// module docs). With `past_freed`, a lift that frees track `g` at
    /// its own depth but not at its deep one does not end the search: the
    /// lifts go on for the deep depth alone (module docs), and there is
    /// no far lift.
    /// `first` gets track `g`'s least altitude at its own depth at the
    /// first lift (m; unchanged where it was not flown).
    pub(super) fn search<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        past_freed: bool,
        first: &mut f32,
    ) -> Result<Next<K>, Stop> {
        let mut plateau = None;
        let next = self.lifts(obj, z, (past_freed, first), &mut plateau)?;
        Ok(match (next, plateau) {
            (Next::Freed(start, _), Some(Next::Deep(l))) => Next::Both(start, l),
            (Next::Nothing, Some(end)) => end,
            (next, _) => next,
        })
    }

    /// The lifts of [`Lift::search`]; `plateau` gets the end at the first
    /// lift that left a dive's plateau the same (module docs).
    fn lifts<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        mut z: [f32; K],
        (past_freed, first): (bool, &mut f32),
        plateau: &mut Option<Next<K>>,
    ) -> Result<Next<K>, Stop> {
        let (j, g) = (self.j, self.g);
        let mut lift = self.band;
        let mut held = 0.0;
        // Track `g`'s least altitude at its preferred depth, last lift, m.
        let mut last = f32::NEG_INFINITY;
        // Track `j`'s `J` at the last lift, m³ (NaN: not flown).
        let mut last_j = f32::NAN;
        // Whether a lift freed track `g` at its own depth already.
        let mut passed = false;
        for n in 0..LIFTS {
            let up = crate::num::max(self.zj - lift, self.lo);
            z = with_depth(&z, j, up);
            z = with_depth(&z, g, self.zg);
            let freed = if passed {
                f32::NEG_INFINITY
            } else {
                let a = obj.least_at((&self.at_j, j), &z, g)?;
                if n == 0 {
                    *first = a;
                }
                a - self.target - self.band
            };
            // Track `g`'s least altitude at its deep depth this lift, where
            // the freeing branch flew it already.
            let mut flown = None;
            if freed >= 0.0 {
                match self.freeing(obj, &mut z, freed, (held, up), past_freed)? {
                    Ok(end) => return Ok(end),
                    Err(a) => (passed, flown) = (true, Some(a)),
                }
            }
            if let Some(p) = self.deep {
                z = with_depth(&z, g, p);
                let (a, own) = match flown {
                    Some(a) => (a, f32::NAN),
                    None => obj
                        .ends((&self.at_j, j), &z, g)
                        .map(|(sj, sg)| (sg.min_altitude(), sj.j()))?,
                };
                // (Track `j` flew otherwise than at the last lift.)
                let moved = (own - core::mem::replace(&mut last_j, own)).abs() > MOVED * own.abs();
                if a >= self.target {
                    return Ok(Next::Deep((held, self.zj - up)));
                }
                if a <= last + self.slack {
                    // The climb saturates, or track `g` settles on its
                    // own depth before its least altitude; below track
                    // `j`'s start, a dive, whose end is kept for where no
                    // later lift frees more (module docs).
                    let end = self.saturated(a, passed, held);
                    if up <= self.at_j.depth() {
                        return self.climb_end(obj, (z, up), end, moved && !past_freed);
                    }
                    if plateau.is_none() {
                        *plateau = Some(end);
                    }
                }
                last = a;
            }
            if up <= self.lo {
                // At the box's floor (the surface), track `g` at its deep
                // depth within the band of its target: the start, as a
                // saturated climb's (module docs).
                if last >= self.target - self.band {
                    return Ok(Next::Deep((self.zj - up, self.zj - up)));
                }
                break;
            }
            held = self.zj - up;
            lift *= 2.0;
        }
        Ok(Next::Nothing)
    }

    /// Where the lift to `up` (m, depth `j` of `z`, after the lift `held`,
    /// m) frees track `g` at its own depth by `freed` (m beyond the band):
    /// the end of the lifts, or, `past_freed`, track `g`'s least altitude
    /// at its deep depth (m; `z` left there) for the lifts to go on.
    fn freeing<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: &mut [f32; K],
        freed: f32,
        (held, up): (f32, f32),
        past_freed: bool,
    ) -> Result<Result<Next<K>, f32>, Stop> {
        let start = with_depth(z, self.g, self.zg + freed);
        let Some(p) = self.deep.filter(|&p| p > self.zg + freed) else {
            return Ok(Ok(Next::Freed(start, None)));
        };
        *z = with_depth(z, self.g, p);
        let a = obj.least_at((&self.at_j, self.j), z, self.g)?;
        if a >= self.target {
            return Ok(Ok(Next::Both(start, (held, self.zj - up))));
        }
        if !past_freed {
            let deeper = self.deepest(obj, *z, (self.zg + freed, p))?;
            return Ok(Ok(Next::Freed(start, Some(deeper))));
        }
        Ok(Err(a))
    }

    /// The end of the lifts where track `g`'s least altitude rose no more
    /// at the lift to `up` (m; `z`, track `g` at its deep depth): `end`,
    /// or, with `far` (track `j`'s flight moved), the far lift's lifts
    /// `(held, free)` (m) where it frees track `g` (module docs; one
    /// flight).
    fn climb_end<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        (z, up): ([f32; K], f32),
        end: Next<K>,
        far: bool,
    ) -> Result<Next<K>, Stop> {
        let to = crate::num::max(self.zj - FAR * self.band, self.lo);
        if let (Next::Deep(e), true) = (&end, far && to < up)
            && obj.least_at((&self.at_j, self.j), &with_depth(&z, self.j, to), self.g)?
                >= self.target
        {
            return Ok(Next::Far((self.zj - up, self.zj - to), *e));
        }
        Ok(end)
    }

    /// The end of the search where track `g`'s least altitude at its deep
    /// depth `a` (m) rises no more: the start at the lift `held` (m), or,
    /// past a freeing lift (`passed`), only where `a` is within the band
    /// of the target (module docs).
    fn saturated<const K: usize>(&self, a: f32, passed: bool, held: f32) -> Next<K> {
        if !passed || a >= self.target - self.band {
            Next::Deep((held, held))
        } else {
            Next::Nothing
        }
    }

    /// What the lifts `found` give from `z`: the lift (m) at which track
    /// `j`'s climb saturated short of freeing track `g` at its deep
    /// depth, if it did; and the freed start, the freed start's deepest
    /// depth `g`, the far lift's start and the deep one (module docs),
    /// narrowed where they are lifts.
    pub(super) fn starts<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        found: Next<K>,
    ) -> Result<(Option<f32>, Starts<K>), Stop> {
        let saturated = match found {
            Next::Deep((held, free)) | Next::Far(_, (held, free))
                if free <= held && held >= self.band =>
            {
                Some(held)
            }
            _ => None,
        };
        let starts = match found {
            Next::Freed(start, deeper) => [Some(start), deeper, None, None],
            Next::Deep(lifts) => [None, None, None, Some(self.narrowed(obj, z, lifts)?)],
            Next::Both(start, lifts) => {
                [Some(start), None, None, Some(self.narrowed(obj, z, lifts)?)]
            }
            Next::Far(lifts, end) => {
                let far = Some(self.narrowed(obj, z, lifts)?);
                [None, None, far, Some(self.narrowed(obj, z, end)?)]
            }
            Next::Nothing => [None; 4],
        };
        Ok((saturated, starts))
    }

    /// The walk along track `g`'s target of the module docs from `z`,
    /// `first` track `g`'s least altitude (m) at the first lift: depth `j`
    /// lifted to each of [`WALKS`] bands, or, where the first of those
    /// leaves the tail more than the band from feasible (past a jump of
    /// track `g`'s least altitude), of [`SHORT`] bands. The last step
    /// whose start is feasible within the band with the horizon's `J`
    /// lower than the last's, from `sqp` (m³) on.
    pub(super) fn walk<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        (z, first): ([f32; K], f32),
        (head, sqp): (&[TrackScore; K], f32),
    ) -> Result<Option<[f32; K]>, Stop> {
        let (best, past) = self.steps(obj, (z, Some(first)), WALKS, (head, sqp))?;
        if best.is_some() || !past {
            return Ok(best);
        }
        Ok(self.steps(obj, (z, None), SHORT, (head, sqp))?.0)
    }

    /// The steps of [`Lift::walk`] to `lifts` (bands): each depth `j`
    /// lifted there and depth `g` deepened by the secant's reach to its
    /// target (one flight, at most [`REACH`] times what was freed; one
    /// more for what was freed, but at the first lift where `first` has
    /// it), flown whole from `head` (one flight). The best start, and
    /// whether the first step's start was more than the band from
    /// feasible.
    fn steps<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        (z, first): ([f32; K], Option<f32>),
        lifts: [f32; 2],
        (head, sqp): (&[TrackScore; K], f32),
    ) -> Result<(Option<[f32; K]>, bool), Stop> {
        let (j, g) = (self.j, self.g);
        let (mut best, mut at) = (None::<([f32; K], f32)>, z);
        for (n, lift) in lifts.into_iter().enumerate() {
            let Some(&zg) = at.get(g) else {
                break;
            };
            let up = with_depth(&at, j, crate::num::max(self.zj - lift * self.band, self.lo));
            let a = match first.filter(|_| n == 0) {
                Some(a) => a,
                None => obj.least_at((&self.at_j, j), &up, g)?,
            };
            // What the lift freed (m), and what deepening by as much takes.
            let freed = a - self.target;
            if freed.is_nan() || freed <= self.slack {
                break;
            }
            let fell = a - obj.least_at((&self.at_j, j), &with_depth(&up, g, zg + freed), g)?;
            if fell.is_nan() || fell <= 0.0 {
                break;
            }
            let start = with_depth(&up, g, zg + (freed * freed / fell).min(REACH * freed));
            let (jz, v) = obj.tail_value(head, (&self.at_j, j), &start)?;
            if v > self.band {
                return Ok((best.map(|(start, _)| start), n == 0));
            }
            if jz.is_nan() || jz >= best.map_or(sqp, |(_, b)| b) {
                break;
            }
            (best, at) = (Some((start, jz)), start);
        }
        Ok((best.map(|(start, _)| start), false))
    }

    /// The start at track `g`'s deep depth (`self.deep`) with the least
    /// lift that frees it, if the lifts by doubling find one (or the climb
    /// saturates).
    fn deep_start<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
    ) -> Result<Option<[f32; K]>, Stop> {
        let mut first = f32::NAN;
        Ok(match self.search(obj, z, true, &mut first)? {
            Next::Deep(lifts) | Next::Both(_, lifts) | Next::Far(lifts, _) => {
                Some(self.narrowed(obj, z, lifts)?)
            }
            _ => None,
        })
    }

    /// `z` with depth `g` the deepest in `[clear, held]` (m) at which track
    /// `g` clears its target ([`Lift::clearing`]).
    fn deepest<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        ends: (f32, f32),
    ) -> Result<[f32; K], Stop> {
        let d = self.clearing(obj, &z, (self.g, |d| d), ends)?;
        Ok(with_depth(&z, self.g, d))
    }

    /// [`clearing`] for track `g` from the state track `j` starts in.
    fn clearing<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: &[f32; K],
        moved: (usize, impl Fn(f32) -> f32),
        ends: (f32, f32),
    ) -> Result<f32, Stop> {
        let from = (&self.at_j, self.j);
        clearing(obj, from, (self.g, self.target), (z, moved), ends)
    }

    /// Track `g` at its deepest useful depth (its deepest bottom less
    /// `h_r`, m; not below `hi`, m), where that is more than the gain's
    /// slack below the preferred one, or below track `g`'s own depth where
    /// it is not held more than the band above the preferred one (module
    /// docs): a start restarted from after the best one, since its `J`
    /// does not tell which ends better; with track `g + 1` repaired
    /// ([`Lift::repaired`], `next_lo`).
    pub(super) fn floor_start<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        (h_r, hi): (f32, f32),
        next_lo: Option<f32>,
    ) -> Result<[Option<[f32; K]>; 2], Stop> {
        let floor = deepest(&obj.sc, obj.track.saturating_add(self.g), h_r)
            .map(|p| p.min(hi))
            .filter(|&p| p > self.deep.unwrap_or(self.zg) + self.slack);
        let lowest = match floor {
            Some(p) => Lift {
                deep: Some(p),
                ..*self
            }
            .deep_start(obj, z)?,
            None => None,
        };
        let Some(lo) = next_lo else {
            return Ok([None, lowest]);
        };
        Ok(match self.short_next(obj, lowest)? {
            Some(short) => [Some(short), Some(self.raise_next(obj, short, lo)?)],
            None => [None, lowest],
        })
    }

    /// `start` (if any) with track `g + 1`'s depth raised, where the start
    /// leaves that track more than the band below its target
    /// ([`Lift::short_next`]), to the deepest depth found that clears it
    /// ([`Lift::raise_next`]).
    pub(super) fn repaired<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        start: Option<[f32; K]>,
        lo: Option<f32>,
    ) -> Result<Option<[f32; K]>, Stop> {
        let Some(lo) = lo else {
            return Ok(start);
        };
        match self.short_next(obj, start)? {
            Some(z) => Ok(Some(self.raise_next(obj, z, lo)?)),
            None => Ok(start),
        }
    }

    /// `start`, where it leaves track `g + 1` more than the band below its
    /// target (one flight of tracks `j..=g + 1`).
    fn short_next<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        start: Option<[f32; K]>,
    ) -> Result<Option<[f32; K]>, Stop> {
        let k = self.g.saturating_add(1);
        let Some(z) = start.filter(|z| k < obj.count && z.get(k).is_some()) else {
            return Ok(None);
        };
        let target = obj.target_of(k);
        let low = obj.least_at((&self.at_j, self.j), &z, k)? < target - self.band;
        Ok(low.then_some(z))
    }

    /// `z` with track `g + 1`'s depth raised to the deepest found that
    /// clears its target ([`raised`], not above `lo`, m; one flight of
    /// tracks `j..=g + 1` each), or as it is where none does.
    fn raise_next<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        lo: f32,
    ) -> Result<[f32; K], Stop> {
        let k = self.g.saturating_add(1);
        let target = obj.target_of(k);
        let from = (&self.at_j, self.j);
        let d = raised(obj, from, (&z, (k, k)), (target, self.band, lo))?;
        Ok(d.map_or(z, |d| with_depth(&z, k, d)))
    }

    /// The deepest depth's start `short` (one that leaves track `g + 1`
    /// more than the band below its target) with depth `g` retreated
    /// instead (module docs): the deepest depth `g` toward the SQP's, at
    /// least the band below it, at which track `g + 1` clears its target
    /// ([`NARROW`](super::raise::NARROW) bisections), with the least lift
    /// of depth `j` that frees track `g` there ([`Lift::narrowed`]). None
    /// where track `g + 1` does not clear it the band below the SQP's
    /// depth (one flight of tracks `j..=g + 1`).
    pub(super) fn retreated<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        short: Option<[f32; K]>,
    ) -> Result<Option<[f32; K]>, Stop> {
        let (g, k) = (self.g, self.g.saturating_add(1));
        let Some(z) = short else {
            return Ok(None);
        };
        let (Some(&zj), Some(&zg)) = (z.get(self.j), z.get(g)) else {
            return Ok(None);
        };
        let (target, from) = (obj.target_of(k), (&self.at_j, self.j));
        let clear = self.zg + self.band;
        if zg <= clear || obj.least_at(from, &with_depth(&z, g, clear), k)? < target {
            return Ok(None);
        }
        let d = clearing(obj, from, (k, target), (&z, (g, |d| d)), (clear, zg))?;
        let at = Lift {
            deep: Some(d),
            ..*self
        };
        Ok(Some(at.narrowed(obj, z, (0.0, self.zj - zj))?))
    }

    /// The start at track `g`'s preferred depth with the least lift in
    /// `(held, free]` that frees it, by [`NARROW`](super::raise::NARROW)
    /// bisections (one flight of the two tracks each) where `free > held`.
    pub(super) fn narrowed<const K: usize>(
        &self,
        obj: &mut PlanObjective<'_, N>,
        z: [f32; K],
        (held, mut free): (f32, f32),
    ) -> Result<[f32; K], Stop> {
        let z = with_depth(&z, self.g, self.deep.unwrap_or(self.zg));
        if free > held {
            free = self.clearing(obj, &z, (self.j, |lift| self.zj - lift), (free, held))?;
        }
        Ok(with_depth(&z, self.j, self.zj - free))
    }
}
