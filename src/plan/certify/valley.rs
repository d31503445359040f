//! The floor between a line's sampled worlds (model contract §12).
//!
//! A track's least altitude over its flight is the least of its points':
//! as a bound moves, the point that sets it can jump from one place of
//! the track to another, and the track's least altitude is then the lower
//! of two branches, each smooth in the bound. Where one branch falls
//! towards a level and the other rises from the next, the least altitude
//! has a kink between the two levels, below both of them.
//! `check_certified.py --seed 3218 --bounds-kind motion` (`synthetic_098`,
//! `α_max` = 1.84° alone) measured one: track 6's least altitude 55.10 m
//! at `α` = −0.62°, between the levels −0.92° and −0.46° (about 56.0 m
//! each), 0.42 m below the reported certified altitude although that was
//! lowered by the vehicle margin.
//!
//! Along a *line* of [`World::corners`] (consecutive worlds, one bound's
//! levels, the others fixed), each interval between two adjacent levels
//! with a level on either side outside it is bounded by the crossing of
//! the two outer chords: the line through the two levels below it
//! (falling) and the line through the two above it (rising). Where both
//! branches are straight that is the kink's floor exactly (on
//! `synthetic_098`: 54.4 m); where they curve upward (a smooth valley) it
//! lies below it. A track's certified altitude is the least of its
//! flights' and these floors. The two intervals at a line's ends have a
//! level on one side only; with straight branches they hold no dip (the
//! corner's level is set by the branch through it, the other branch lies
//! above it there, so the lower of the two stays above both ends), and
//! they get no floor. Nor do the lines along a second declared bound or
//! along the speed: the vehicle margin is left for those.
//!
//! A line's flights are kept until its last one ([`LineRows`], in the
//! [`super::Tube`]: nine rows of 64 tracks, 2.3 KiB, which the
//! certificate's stack could not hold); a certificate
//! flies the world that was worst last time first, and that world's
//! altitudes are held until its line comes.

use core::cell::Cell;

use crate::sim::World;

use super::MAX_TRACKS;

/// Most worlds a line has (`α` or `w` declared alone: nine levels).
pub(super) const LINE: usize = 9;

/// Which bound a line of worlds varies.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Axis {
    /// No line: each world stands alone.
    None,
    /// The flight-path offset `α` (deg).
    Offset,
    /// The vertical current `w` (m/s).
    Current,
}

impl Axis {
    /// Where `w` lies along a line of this axis.
    fn along(self, w: &World) -> f32 {
        match self {
            Self::Offset => w.flight_path_offset,
            Self::Current => w.vertical_current,
            Self::None => 0.0,
        }
    }

    /// The bound a line of this axis holds fixed (with the speed).
    fn fixed(self, w: &World) -> f32 {
        match self {
            Self::Offset => w.vertical_current,
            Self::Current | Self::None => w.flight_path_offset,
        }
    }
}

/// The length of the lines `worlds` starts with and the bound they vary
/// (`(1, Axis::None)` where the first two worlds do not start one).
pub(super) fn line_of(worlds: &[World]) -> (usize, Axis) {
    let (Some(a), Some(b)) = (worlds.first(), worlds.get(1)) else {
        return (1, Axis::None);
    };
    let same = |x: f32, y: f32| x.to_bits() == y.to_bits();
    let axis = if !same(a.speed, b.speed) {
        Axis::None
    } else if same(a.flight_path_offset, b.flight_path_offset)
        && !same(a.vertical_current, b.vertical_current)
    {
        Axis::Current
    } else if same(a.vertical_current, b.vertical_current)
        && !same(a.flight_path_offset, b.flight_path_offset)
    {
        Axis::Offset
    } else {
        Axis::None
    };
    if axis == Axis::None {
        return (1, Axis::None);
    }
    let len = worlds
        .iter()
        .take_while(|w| same(w.speed, a.speed) && same(axis.fixed(w), axis.fixed(a)))
        .count();
    (len, axis)
}

/// The rows of the line being flown, one per level (m, per track), and
/// the first world's held for its line (module docs). Scratch: what it
/// holds between certificates means nothing.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct LineRows {
    rows: Cell<[[f32; MAX_TRACKS]; LINE]>,
    held: Cell<[f32; MAX_TRACKS]>,
}

impl Default for LineRows {
    /// Zeros (a memset): every row is emptied before a flight writes it.
    fn default() -> Self {
        Self {
            rows: Cell::new([[0.0; MAX_TRACKS]; LINE]),
            held: Cell::new([0.0; MAX_TRACKS]),
        }
    }
}

/// The cells of one row.
fn cells(row: &Cell<[f32; MAX_TRACKS]>) -> &[Cell<f32>] {
    let row: &Cell<[f32]> = row;
    row.as_slice_of_cells()
}

/// A certificate's flights, line by line, into the floors between their
/// levels.
pub(super) struct Lines<'a> {
    rows: &'a [Cell<[f32; MAX_TRACKS]>],
    held: &'a Cell<[f32; MAX_TRACKS]>,
    line: usize,
    axis: Axis,
    /// The worlds that lie on whole lines (the declared ones: a knife
    /// edge's branches come after them).
    lined: usize,
    /// The line being filled, and which of its levels are (bits).
    current: Option<usize>,
    filled: u32,
    /// The first world flown, where it is held for its line.
    held_at: Option<usize>,
    started: bool,
}

impl<'a> Lines<'a> {
    /// For a certificate of `worlds`, the last `branches` of them a knife
    /// edge's branches, kept in `keep`.
    pub fn new(keep: &'a LineRows, worlds: &[World], branches: usize) -> Self {
        let declared = worlds
            .get(..worlds.len().saturating_sub(branches))
            .unwrap_or(&[]);
        let (line, axis) = line_of(declared);
        let lines = declared.len().checked_div(line).unwrap_or(0);
        let useful = axis != Axis::None && (4..=LINE).contains(&line);
        let rows: &Cell<[[f32; MAX_TRACKS]]> = &keep.rows;
        Self {
            rows: rows.as_slice_of_cells(),
            held: &keep.held,
            line,
            axis,
            lined: if useful {
                lines.saturating_mul(line)
            } else {
                0
            },
            current: None,
            filled: 0,
            held_at: None,
            started: false,
        }
    }

    /// The line and level of world `i`, if it lies on a line.
    fn place(&self, i: usize) -> Option<(usize, usize)> {
        if i >= self.lined {
            return None;
        }
        Some((i.checked_div(self.line)?, i.checked_rem(self.line)?))
    }

    /// The row world `i`'s flight writes its per-track altitudes into
    /// (m), emptied; `None` where it lies on no line. Where `i` starts
    /// another line, the line before is closed first: its floors lower
    /// `per_track` (the first `tracks`), and their least on the first
    /// track and on any are returned (m; `+inf`: none).
    pub fn slot(
        &mut self,
        i: usize,
        worlds: &[World],
        (tracks, per_track): (usize, &mut [f32; MAX_TRACKS]),
    ) -> (Option<&'a [Cell<f32>]>, (f32, f32)) {
        let mut floors = (f32::INFINITY, f32::INFINITY);
        let Some((l, p)) = self.place(i) else {
            return (None, floors);
        };
        if !core::mem::replace(&mut self.started, true) && l != 0 {
            self.held_at = Some(i);
            self.held.set([f32::INFINITY; MAX_TRACKS]);
            return (Some(cells(self.held)), floors);
        }
        if self.current != Some(l) {
            floors = self.close(worlds, (tracks, per_track));
            self.current = Some(l);
            self.filled = 0;
            if let Some((hl, hp)) = self.held_at.and_then(|h| self.place(h))
                && hl == l
                && let Some(row) = self.rows.get(hp)
            {
                row.set(self.held.get());
                self.filled |= 1 << hp;
            }
        }
        let Some(row) = self.rows.get(p) else {
            return (None, floors);
        };
        row.set([f32::INFINITY; MAX_TRACKS]);
        self.filled |= bit(p);
        (Some(cells(row)), floors)
    }

    /// After the last world: the line being filled closed ([`Lines::slot`]).
    pub fn finish(
        &mut self,
        worlds: &[World],
        (tracks, per_track): (usize, &mut [f32; MAX_TRACKS]),
    ) -> (f32, f32) {
        self.close(worlds, (tracks, per_track))
    }

    /// The floors between the levels of the line being filled, where
    /// every level of it flew: they lower `per_track` (the first
    /// `tracks`); their least on the first track and on any (m).
    fn close(
        &mut self,
        worlds: &[World],
        (tracks, per_track): (usize, &mut [f32; MAX_TRACKS]),
    ) -> (f32, f32) {
        let mut floors = (f32::INFINITY, f32::INFINITY);
        let Some(l) = self.current.take() else {
            return floors;
        };
        let base = l.saturating_mul(self.line);
        let Some(ws) = worlds.get(base..base.saturating_add(self.line)) else {
            return floors;
        };
        if self.filled != bit(self.line).wrapping_sub(1) {
            return floors;
        }
        // The levels in ascending order along the line.
        let mut order = [0_usize; LINE];
        let Some(o) = order.get_mut(..ws.len()) else {
            return floors;
        };
        o.iter_mut().enumerate().for_each(|(k, p)| *p = k);
        let x = |p: usize| ws.get(p).map_or(f32::NAN, |w| self.axis.along(w));
        for _ in 0..o.len() {
            for k in 1..o.len() {
                if let Some([p, q]) = o.get_mut(k.saturating_sub(1)..=k)
                    && x(*q) < x(*p)
                {
                    core::mem::swap(p, q);
                }
            }
        }
        for q in o.windows(4) {
            let &[a, b, c, d] = q else {
                continue;
            };
            let (Some(ra), Some(rb), Some(rc), Some(rd)) = (
                self.rows.get(a),
                self.rows.get(b),
                self.rows.get(c),
                self.rows.get(d),
            ) else {
                continue;
            };
            let (ra, rb, rc, rd) = (cells(ra), cells(rb), cells(rc), cells(rd));
            let rows = ra.iter().zip(rb).zip(rc).zip(rd).zip(per_track.iter_mut());
            for (j, ((((ha, hb), hc), hd), f)) in rows.take(tracks).enumerate() {
                let pts = [(a, ha), (b, hb), (c, hc), (d, hd)].map(|(p, h)| (x(p), h.get()));
                let v = crossing(pts);
                *f = f.min(v);
                floors.1 = floors.1.min(v);
                if j == 0 {
                    floors.0 = floors.0.min(v);
                }
            }
        }
        floors
    }
}

/// Bit `p` of a line's levels (none past 31).
fn bit(p: usize) -> u32 {
    u32::try_from(p)
        .ok()
        .and_then(|p| 1_u32.checked_shl(p))
        .unwrap_or(0)
}

/// The floor between the middle two of four points `(x, h)` ascending in
/// `x`: the crossing of the chord through the first two (falling) and the
/// chord through the last two (rising) where it lies between them; else
/// `+inf` (module docs).
fn crossing([(xa, a), (xb, b), (xc, c), (xd, d)]: [(f32, f32); 4]) -> f32 {
    let (fall, rise, gap) = (xb - xa, xd - xc, xc - xb);
    if !(fall > 0.0 && rise > 0.0 && gap > 0.0) {
        return f32::INFINITY;
    }
    let (left, right) = ((b - a) / fall, (d - c) / rise);
    if !(left < 0.0 && right > 0.0) {
        return f32::INFINITY;
    }
    // b + left t = c + right (t − gap), 0 < t < gap.
    let t = (c - b - right * gap) / (left - right);
    let v = b + left * t;
    if t > 0.0 && t < gap && v.is_finite() {
        v
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Falling 2 m a unit to `x` = 1.6, then rising 1 m a unit: least
    /// 10 m there.
    fn kink(x: f32) -> f32 {
        10.0 + if x < 1.6 { 2.0 * (1.6 - x) } else { x - 1.6 }
    }

    /// Two straight branches crossing between the middle levels: their
    /// crossing exactly; a valley that does not fall into the interval or
    /// a failed flight: none.
    #[test]
    fn the_floor_is_the_crossing_of_the_outer_chords() {
        let pts = |xs: [f32; 4]| xs.map(|x| (x, kink(x)));
        let v = crossing(pts([0.0, 1.0, 2.0, 3.0]));
        assert!((v - 10.0).abs() < 1e-5, "{v}");
        assert_eq!(crossing(pts([-1.0, 0.0, 1.0, 2.0])), f32::INFINITY);
        let bad = [(0.0, f32::NEG_INFINITY), (1.0, 2.0), (2.0, 1.0), (3.0, 2.0)];
        assert_eq!(crossing(bad), f32::INFINITY);
    }

    /// Two lines of five levels in [`World::corners`]' order (the corners
    /// first), flown in a certificate's order (the last worst world
    /// first, the rest in order), wherever that world stands: each line's
    /// floor; a line cut short by branches, or one left unfinished: none.
    #[test]
    fn each_lines_floor_whatever_flew_first() {
        let level = [4.0, 0.0, 3.0, 1.0, 2.0];
        let world = |i: usize| World {
            speed: 1.5,
            flight_path_offset: level[i % 5],
            vertical_current: if i < 5 { 0.0 } else { 0.1 },
        };
        let worlds: [World; 10] = core::array::from_fn(world);
        assert_eq!(line_of(&worlds), (5, Axis::Offset));
        // The second line: 1 m higher.
        let h = |i: usize| kink(level[i % 5]) + if i < 5 { 0.0 } else { 1.0 };
        let keep = LineRows::default();
        for start in 0..10 {
            let order = core::iter::once(start).chain((0..10).filter(|&i| i != start));
            let mut lines = Lines::new(&keep, &worlds, 0);
            let mut per_track = [f32::INFINITY; MAX_TRACKS];
            let mut least = f32::INFINITY;
            for i in order {
                let (row, floors) = lines.slot(i, &worlds, (1, &mut per_track));
                least = least.min(floors.1);
                let row = row.unwrap_or(&[]);
                if let Some(c) = row.first() {
                    c.set(h(i));
                }
                per_track
                    .iter_mut()
                    .zip(row)
                    .for_each(|(p, c)| *p = p.min(c.get()));
            }
            least = least.min(lines.finish(&worlds, (1, &mut per_track)).1);
            assert!((least - 10.0).abs() < 1e-5, "start {start}: {least}");
            assert_eq!(least, per_track[0]);
        }
        // Branches after the first three: no whole line.
        let mut lines = Lines::new(&keep, &worlds[..5], 2);
        let mut per_track = [f32::INFINITY; MAX_TRACKS];
        for i in 0..5 {
            let (row, floors) = lines.slot(i, &worlds, (1, &mut per_track));
            assert!(row.is_none() && floors.1 == f32::INFINITY);
        }
        // A line with a level not flown: no floor.
        let mut lines = Lines::new(&keep, &worlds, 0);
        for i in [0, 1, 2, 3] {
            let (row, _) = lines.slot(i, &worlds, (1, &mut per_track));
            if let Some(c) = row.unwrap_or(&[]).first() {
                c.set(h(i));
            }
        }
        assert_eq!(lines.finish(&worlds, (1, &mut per_track)).1, f32::INFINITY);
    }
}
