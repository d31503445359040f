//! The safe-set boundary of one variable: a bracketed root search on a
//! margin `g(z)` (for the planner, minimum altitude − certified altitude),
//! approached from the safe side (`g >= 0`).
//!
//! `g` is typically a hinge: flat where the track's lowest point is passed
//! before the vehicle reaches its reference, falling about a metre per
//! metre of reference depth beyond. So the first step (and any step after
//! an unsafe evaluation that gave no usable secant) moves from the unsafe
//! end by its deficit, which lands on the boundary on the sloped side;
//! then the secant through the two latest evaluations, and the Illinois
//! variant of regula falsi on the bracket when the secant falls outside it
//! (Dowell & Jarratt 1971). Each aims at half the tolerance above 0.
//!
//! A margin within the tolerance ends the search only where it shows the
//! boundary is near: a safe end whose margin differs from the safe end's
//! before. A safe side can be flat too (the least altitude set where the
//! depth does not act yet, at whatever margin the previous track's
//! boundary left it): a caller's safe end there, or a safe evaluation at
//! the same margin, may lie anywhere on that side, so the search goes on,
//! by the unit step where it lands inside the bracket, else by bisection;
//! where two unsafe evaluations have measured the unsafe side's slope, by
//! their secant instead. That holds for a safe end the unit step reached
//! too: where the sloped side falls faster than a metre per metre, the
//! unit step from the unsafe end lands short of the boundary, on the flat
//! side at its very margin (`check_planner.py --seed 2960 --vehicle
//! tools/reference/vehicles/fast.toml`, `unseen_2960_1` track 2,
//! constrained: a side falling 1.03 m per m sent the step from 102 m
//! beyond the boundary to 3.5 m short of it, where the search stopped, at
//! 1.078× the best safe `J`).

/// How far towards the unsafe end (of the bracket) a secant may land. A
/// wide bracket whose boundary lies near its unsafe end (a long flat safe
/// side) puts the secant's aim past 99 % of it; refused there, unit steps
/// that assume a slope of 1 crawled towards a boundary of slope 0.17 and
/// the search ran out of steps at its unmoved safe end (`check_planner.py
/// --seed 81`, h_r/h_a 30/20, `unseen_81_4` track 2: 4.7× the best safe).
const SECANT_REACH: f32 = 0.9999;

/// One end of a bracket: a point and its margin when known.
pub(crate) type End = (f32, Option<f32>);

/// What the search found.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Root<T> {
    /// The safe end, and what its evaluation returned when it was
    /// evaluated here (`None`: the caller's own `good` end, unmoved and
    /// given with its margin).
    pub z: f32,
    pub at: Option<T>,
    /// The safe end before it, with its payload, if the end moved.
    pub inner: Option<(f32, T)>,
}

/// Stopping rules: the safe end within `tol` of 0 (same unit as `g`), the
/// bracket under `width` (unit of `z`), or `steps` evaluations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RootTol {
    pub tol: f32,
    pub width: f32,
    pub steps: u32,
}

/// The state of the search between two evaluations.
struct Search {
    good: f32,
    /// The safe end's margin as evaluated (the stopping rule's).
    margin: f32,
    /// The safe end's margin as regula falsi weighs it (Illinois halves
    /// it while the other end moves).
    g_good: f32,
    bad: f32,
    g_bad: f32,
    /// The two latest evaluations `(z, g)`, newest first.
    latest: Option<((f32, f32), (f32, f32))>,
    /// Which end the last step kept (Illinois halves its value).
    kept_good: bool,
    kept_bad: bool,
    /// Whether the safe end may lie on a flat safe side (module docs):
    /// the caller's, or reached at its predecessor's very margin.
    flat: bool,
    /// Whether two safe evaluations have shown the safe side flat (at any
    /// margin, within the tolerance or above it).
    seen_flat: bool,
}

impl Search {
    /// Whether the safe end is within `tol` (m) of the boundary: its
    /// margin, and the boundary's distance by the bracket's chord (where
    /// the least altitude moves little with the depth, a margin within
    /// `tol` can be a long way off: `check_planner.py --seed 8080`,
    /// `unseen_8080_6`, 0.024 m of altitude per m of depth, stopped
    /// 0.13 m short of the boundary with `J` 0.6 % above it).
    fn near(&self, tol: f32) -> bool {
        let off = libm::fabsf(self.bad - self.good) * self.margin / (self.margin - self.g_bad);
        let far = off.partial_cmp(&tol) == Some(core::cmp::Ordering::Greater);
        self.margin <= tol && !self.flat && !far
    }

    /// Where to evaluate next, as a fraction of the way from `good` to
    /// `bad`.
    fn next_t(&self, step: u32, tol: f32) -> f32 {
        let (good, bad, g_good, g_bad) = (self.good, self.bad, self.g_good, self.g_bad);
        // Regula falsi, kept inside the middle 98 % of the bracket.
        let t = if g_good > 0.0 && g_bad < 0.0 && (g_good - g_bad).is_finite() {
            (g_good / (g_good - g_bad)).clamp(0.01, 0.99)
        } else {
            0.5
        };
        let width = libm::fabsf(good - bad);
        // The unit step from the unsafe end: its deficit plus half the
        // tolerance (the hinge's sloped side falls at unit slope).
        let unit = -g_bad + 0.5 * tol;
        let t_unit = (g_bad < 0.0 && unit < width).then(|| 1.0 - unit / width);
        let aim = |z: f32| (z - good) / (bad - good);
        // The secant, when it has two distinct margins and lands inside.
        let secant = self.latest.and_then(|((z1, g1), (z2, g2))| {
            let ts = aim(z1 + (0.5 * tol - g1) * (z1 - z2) / (g1 - g2));
            (libm::fabsf(g1 - g2) > 0.0 && ts > 0.01 && ts < SECANT_REACH).then_some(ts)
        });
        if self.flat && (self.margin <= tol || self.seen_flat) {
            // Probing a flat safe side: the unit step lands on the
            // boundary if the unsafe end is on the sloped side; where two
            // unsafe evaluations measured that side's slope, their secant
            // (unit steps on a slope of 0.08 crawled: `unseen_2101_3`).
            // Above the tolerance too, once seen flat: regula falsi, which
            // weighs the bracket by the small flat margin, crawled from
            // the safe end 1 % of the bracket a step and ran out of steps
            // 0.24 m short (`check_planner.py --seed 2208 --vehicle
            // tools/reference/vehicles/integ.toml`, `unseen_2208_3` track
            // 3, constrained: margin 0.047 m, `J` 1.010× the best safe).
            // Where those two aim outside the bracket, the unsafe side is
            // nearly flat and unit steps would crawl along it: bisect, as
            // below (`check_planner.py --seed 2705 --vehicle
            // tools/reference/vehicles/low.toml`, `unseen_2705_5` track 1:
            // 0.57 m steps on a side falling 0.001–0.1 m per m ran out
            // 1.8 m short, `J` 1.013× the best safe).
            let both_bad = self
                .latest
                .is_some_and(|((_, g1), (_, g2))| g1 < 0.0 && g2 < 0.0);
            return match (secant.filter(|_| both_bad), t_unit) {
                (Some(ts), _) => ts,
                (None, _) if both_bad => 0.5,
                (None, Some(tu)) if tu > 0.01 && tu < 0.999 => tu,
                _ => 0.5,
            };
        }
        // First, and whenever the newest evaluation was unsafe and gave no
        // usable secant: the unit step; but where the two latest were
        // unsafe and their secant lands outside the bracket (or they share
        // a margin), the unsafe side is flat or nearly so (the least
        // altitude set by a feature the depth hardly moves), and unit
        // steps would crawl along it: bisect. (Only an exactly equal
        // margin bisected before: on `check_planner.py --seed 2401
        // --vehicle tools/reference/vehicles/integ.toml`, `unseen_2401_3`
        // track 1, constrained, margins of −0.8603, −0.8597, −0.8588 m
        // sent unit steps of 0.87 m along a side falling 0.001 m per m,
        // and the steps ran out 8.4 m short: 1.28× the best safe `J`.)
        let newest_bad = self.latest.is_none_or(|((_, g1), _)| g1 < 0.0);
        let both_bad = self
            .latest
            .is_some_and(|((_, g1), (_, g2))| g1 < 0.0 && g2 < 0.0);
        match (secant, t_unit) {
            (_, Some(tu)) if step == 0 => tu,
            (Some(ts), _) => ts,
            (None, _) if both_bad => 0.5,
            (None, Some(tu)) if newest_bad => tu,
            _ => t,
        }
    }
}

/// Searches the boundary between a safe `good` end and an unsafe `bad`
/// one. `eval(z)` returns `g(z)` with a payload, or `Err` where it cannot
/// be evaluated (treated as unsafe, except at an unknown `good` end,
/// whose failure is returned).
///
/// # Errors
/// The error of evaluating `good`, when its margin was not given.
pub(crate) fn safe_boundary<T: Copy, E, F: FnMut(f32) -> Result<(f32, T), E>>(
    good: End,
    bad: End,
    rule: RootTol,
    mut eval: F,
) -> Result<Root<T>, E> {
    let mut at = None;
    let g_good = match good.1 {
        Some(g) => g,
        None => {
            let (g, p) = eval(good.0)?;
            at = Some(p);
            g
        }
    };
    let g_bad = match bad.1 {
        Some(g) => g,
        None => eval(bad.0).map_or(-1.0, |(g, _)| g),
    };
    let mut s = Search {
        good: good.0,
        margin: g_good,
        g_good,
        bad: bad.0,
        g_bad,
        latest: None,
        kept_good: false,
        kept_bad: false,
        flat: true,
        seen_flat: false,
    };
    let mut inner = None;
    for step in 0..rule.steps {
        if s.near(rule.tol) || libm::fabsf(s.good - s.bad) <= rule.width {
            break;
        }
        let t = s.next_t(step, rule.tol);
        let mid = s.good + t * (s.bad - s.good);
        let flown = eval(mid);
        let g_mid = flown.as_ref().map_or(f32::NEG_INFINITY, |(g, _)| *g);
        s.latest = g_mid
            .is_finite()
            .then(|| ((mid, g_mid), s.latest.map_or((s.bad, s.g_bad), |l| l.0)));
        match flown {
            Ok((g, p)) if g >= 0.0 => {
                if let Some(prev) = at {
                    inner = Some((s.good, prev));
                }
                s.good = mid;
                s.flat = g.to_bits() == s.margin.to_bits();
                s.seen_flat |= s.flat;
                s.margin = g;
                s.g_good = g;
                at = Some(p);
                if s.kept_bad {
                    s.g_bad *= 0.5;
                }
                s.kept_bad = true;
                s.kept_good = false;
            }
            r => {
                s.bad = mid;
                s.g_bad = r.map_or(-1.0, |(g, _)| g);
                if s.kept_good {
                    s.g_good *= 0.5;
                }
                s.kept_good = true;
                s.kept_bad = false;
            }
        }
    }
    Ok(Root {
        z: s.good,
        at,
        inner,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> RootTol {
        RootTol {
            tol: 0.02,
            width: 1e-3,
            steps: 16,
        }
    }

    /// A hinge: flat (margin 5) above 100 m, falling 1 m per m below.
    /// A margin flat at `flat` (m) up to `corner`, then falling `fall` m
    /// per unit of the argument.
    fn flat_then_falling(
        flat: f32,
        fall: f32,
        corner: f32,
    ) -> impl Fn(f32) -> Result<(f32, ()), ()> + Copy {
        move |t: f32| Ok((flat.min(flat - fall * (t - corner)), ()))
    }

    fn hinge(z: f32) -> Result<(f32, f32), ()> {
        Ok((5.0_f32.min(105.0 - z), z))
    }

    #[test]
    fn lands_on_the_sloped_side_of_a_hinge_in_one_step() {
        let mut n = 0;
        let r = safe_boundary((80.0, None), (150.0, None), rule(), |z| {
            n += 1;
            hinge(z)
        })
        .unwrap();
        let g = hinge(r.z).unwrap().0;
        assert!((0.0..=0.02).contains(&g), "{} -> {g}", r.z);
        // Both ends, then the unit step.
        assert_eq!(n, 3);
    }

    /// The unsafe side flat (a least altitude set beyond the boundary by a
    /// feature the depth does not move): unit steps would crawl 3.3 m at a
    /// time, and regula falsi's weighting of the safe end must not pass for
    /// its margin. (Before: stopped after 12 steps at the safe end, margin
    /// 28.2, the halved weight taken for the margin; `unseen_23_3` track 4
    /// of `check_planner.py --seed 23`.)
    #[test]
    fn bisects_a_flat_unsafe_side() {
        let f = |z: f32| -> Result<(f32, ()), ()> {
            Ok((if z <= 900.0 { 0.3 * (900.0 - z) } else { -3.3 }, ()))
        };
        let r = safe_boundary((806.0, None), (954.7, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!((0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    /// The safe side flat at a margin within the tolerance (the track's
    /// least altitude set at its start, where the previous track's boundary
    /// left it 0.0186 m above), falling 1 m per m beyond 909.14 m: the
    /// caller's safe end at 866.87 m is no boundary. (Before: answered it
    /// unmoved; `check_planner.py --seed 53` with a slower vehicle,
    /// `unseen_53_7` track 3, `J` 1.74× the best safe.)
    #[test]
    fn probes_a_flat_safe_side() {
        let f = |z: f32| -> Result<(f32, ()), ()> { Ok((0.0186_f32.min(909.16 - z), ())) };
        let r = safe_boundary((866.87, Some(0.0186)), (1086.6, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 909.1 && (0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    /// The safe side flat at a margin within the tolerance, the unsafe
    /// side falling faster than a metre per metre (1.034): the unit step
    /// from the unsafe end lands 3.5 m short of the boundary, on the flat
    /// side at its very margin, which is no boundary either. (Before:
    /// answered there; `check_planner.py --seed 2960 --vehicle
    /// tools/reference/vehicles/fast.toml`, `unseen_2960_1` track 2,
    /// constrained, `J` 1.078× the best safe.)
    #[test]
    fn a_unit_step_onto_the_flat_side_goes_on() {
        let f = flat_then_falling(0.007, 1.034, 977.96);
        let r = safe_boundary((852.18, Some(0.007)), (1080.29, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 977.9 && (0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    /// The same on a path parameter, where a unit step of the margin does
    /// not fit in the bracket: bisection finds the corner (the continuation
    /// search from its anchor, `search.rs`; before: stopped at the anchor).
    #[test]
    fn bisects_towards_a_flat_safe_sides_corner() {
        let f = flat_then_falling(0.0091, 475.0, 0.89);
        let r = safe_boundary((0.0, Some(0.0091)), (1.0, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 0.888 && g >= 0.0, "{} -> {g}", r.z);
    }

    /// A flat safe side above the tolerance (0.089 m) ending 1.7 m from
    /// the unsafe end of a 206 m bracket, the unsafe side falling 0.17 m
    /// per m: the secant's aim lies past 99 % of the bracket. (Before:
    /// unit steps crawled 0.2 m at a time and the search answered its
    /// unmoved safe end; `check_planner.py --seed 81`, h_r/h_a 30/20,
    /// `unseen_81_4` track 2, `J` 4.7× the best safe.)
    #[test]
    fn a_secant_may_land_near_the_unsafe_end() {
        let f = flat_then_falling(0.089, 0.17, 1014.9);
        let r = safe_boundary((810.38, Some(0.089)), (1016.59, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 1014.0 && g >= 0.0, "{} -> {g}", r.z);
    }

    /// A flat safe side above the tolerance (0.047 m) over 200 m, the
    /// unsafe side falling 1.6 m per m beyond 841.28 m (`unseen_2208_3`
    /// track 3; before: regula falsi crawled from the safe end and the
    /// steps ran out at 841.04 m).
    #[test]
    fn leaves_a_flat_safe_side_above_the_tolerance() {
        let f = flat_then_falling(0.047, 1.6, 841.28);
        let r = safe_boundary((638.62, Some(0.047)), (889.84, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 841.2 && g >= 0.0, "{} -> {g}", r.z);
    }

    /// The unsafe side nearly flat: falling from the boundary at 906.6 m
    /// towards −0.8603 m within tens of metres, then by under a
    /// millimetre a metre (`unseen_2401_3` track 1; before: unit steps of
    /// the deficit crawled from 924 m and the steps ran out at the safe
    /// end 898.1 m, 8.5 m short).
    #[test]
    fn bisects_a_nearly_flat_unsafe_side() {
        let f = |z: f32| -> Result<(f32, ()), ()> {
            let g = if z <= 906.6 {
                0.2 * (906.6 - z)
            } else {
                -0.8603 * (1.0 - libm::expf((906.6 - z) / 5.0))
            };
            Ok((g, ()))
        };
        let r = safe_boundary((838.58, Some(19.998)), (958.49, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!(r.z > 906.4 && (0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    /// A flat safe side within the tolerance (0.0129 m, from 1 083.2 m),
    /// the unsafe side falling from 1 086.45 m at 0.26 m per m, then
    /// ever slower, flat at −0.5622 m beyond 1 092.7 m (`check_planner.py
    /// --seed 2705 --vehicle tools/reference/vehicles/low.toml`,
    /// `unseen_2705_5` track 1, constrained; before: the unit steps of the
    /// deficit, 0.57 m each, crawled from 1 092 m, two unsafe secants
    /// aimed outside the bracket, and the steps ran out at the safe end
    /// 1 084.70 m, `J` 1.013× the best safe).
    #[test]
    fn bisects_a_nearly_flat_unsafe_side_beyond_a_flat_safe_one() {
        let f = |z: f32| -> Result<(f32, ()), ()> {
            let (flat, corner, floor) = (0.012_939, 1086.45, 1092.7);
            let g = if z <= 1074.82 {
                0.5119 + 0.2994 * (1074.82 - z)
            } else if z <= 1083.19 {
                flat + 0.0596 * (1083.19 - z)
            } else if z <= corner {
                flat
            } else if z <= floor {
                -0.5622 + 0.5751 * libm::powf((floor - z) / (floor - corner), 2.85)
            } else {
                -0.5622
            };
            Ok((g, ()))
        };
        let r = safe_boundary((1036.46, None), (1343.89, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        // (Within the 16 steps, 0.11 m short of the corner.)
        assert!(r.z > 1086.3 && (0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    #[test]
    fn stays_safe_on_a_smooth_margin() {
        let f = |z: f32| -> Result<(f32, ()), ()> { Ok((10.0 - 0.01 * z * z, ())) };
        let r = safe_boundary((0.0, None), (50.0, None), rule(), f).unwrap();
        let g = f(r.z).unwrap().0;
        assert!((0.0..=0.02).contains(&g), "{} -> {g}", r.z);
    }

    #[test]
    fn failed_evaluations_count_as_unsafe() {
        let f = |z: f32| {
            if z > 10.0 {
                Err(())
            } else {
                Ok((10.0 - z, ()))
            }
        };
        let r = safe_boundary((0.0, None), (20.0, None), rule(), f).unwrap();
        assert!(r.z <= 10.0 && r.z > 9.9, "{}", r.z);
        assert!(safe_boundary((11.0, None), (20.0, None), rule(), f).is_err());
    }
}
