//! The simulation and its tangent pass: `Scenario::simulate` and
//! `Scenario::evaluate_tracks::<3>` fly one to three tracks of a fuzzed
//! line at arbitrary reference depths (plausible, or any `f32`) from an
//! arbitrary start state, with an arbitrary penalty altitude.
//!
//! Checked: both return a typed error or only finite values (scores,
//! `J ≥ 0`, violation `≥ 0`, minimum altitude, gradients, end state); every
//! sample handed to the observer is finite, never moves back along the
//! track (f32 positions far from 0 may repeat) and carries the reference
//! depth of its track; the tangent pass flies the
//! very flight of the plain one (same scores and end state, bit for bit),
//! and fails only where the plain one fails or a gradient is not finite.

use arbitrary::Arbitrary;
use auvnav::{Scenario, SimError, TrackScore, VehicleState};

use crate::known;
use crate::line::{
    Line, LineIn, MissionIn, PHYSICAL_LENGTH, StartIn, Val, VehicleIn, c_auv4, state_is_finite,
    state_is_physical, within,
};

/// One fuzzer input.
#[derive(Arbitrary, Debug)]
pub struct Input {
    pub vehicle: VehicleIn,
    pub mission: MissionIn,
    pub line: LineIn,
    pub start: StartIn,
    /// First track (modulo the number of tracks + 1).
    pub first_track: u8,
    /// Tracks flown (1 + `count % 3`; past the end is `TrackRange`).
    pub count: u8,
    /// Reference depths: about the default start depth (± the line's
    /// length) when scaled.
    pub depths: [Val; 3],
    /// Penalty altitude (a fraction of `h_r` when scaled).
    pub penalty: Option<Val>,
}

/// What one execution did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The vehicle, line or mission was rejected (or too long to fly).
    Rejected,
    /// Both passes failed with this error.
    Error(SimError),
    /// The plain pass flew, the tangent pass found a non-finite gradient.
    GradientDiverged,
    /// Both flew.
    Flown,
}

/// Runs one input.
pub fn run(data: &[u8]) -> Outcome {
    let Ok(input) = Input::arbitrary_take_rest(arbitrary::Unstructured::new(data)) else {
        return Outcome::Rejected;
    };
    run_input(&input)
}

/// Runs one decoded input.
pub fn run_input(input: &Input) -> Outcome {
    match &input.vehicle {
        VehicleIn::CAuv4 => with_line(*c_auv4(), input),
        VehicleIn::Tuned(t) => match t.vehicle() {
            Some(v) => with_line(v, input),
            None => Outcome::Rejected,
        },
    }
}

fn with_line<const N: usize>(vehicle: auvnav::Vehicle<N>, input: &Input) -> Outcome {
    let Some(line) = Line::new(vehicle, &input.line, &input.mission) else {
        return Outcome::Rejected;
    };
    let Some(sc) = line.scenario() else {
        return Outcome::Rejected;
    };
    let mut physical = line.physical;
    let sc = match input.penalty {
        None => sc,
        Some(v) => {
            let h_r = sc.mission().reference_altitude();
            let p = v.get(sc.mission().min_altitude(), 0.0, 1.2 * h_r);
            let sc = sc.with_penalty_altitude(p);
            if p.is_finite() {
                assert_eq!(sc.penalty_altitude().to_bits(), p.to_bits());
            }
            physical &= within(&[p], PHYSICAL_LENGTH);
            sc
        }
    };
    let tracks = sc.waypoints().tracks();
    let first = usize::from(input.first_track) % (tracks + 1);
    let count = 1 + usize::from(input.count % 3);
    let (track_len, len) = line.lengths();
    let wp = sc.waypoints().positions();
    let d0 = sc.default_initial_depth();
    let start: VehicleState<N> =
        input
            .start
            .state(wp.get(first).copied().unwrap_or(wp[0]), track_len, len, d0);
    let depths = input.depths.map(|v| v.get(d0, d0 - len, d0 + len));
    physical &= state_is_physical(&start) && within(&depths[..count], PHYSICAL_LENGTH);
    fly(&sc, &start, first, &depths, count, physical)
}

/// Both passes over `count` tracks from `first`, checked (`physical`: the
/// input's magnitudes are, see [`crate::known`]).
pub fn fly<const N: usize>(
    sc: &Scenario<'_, N>,
    start: &VehicleState<N>,
    first: usize,
    depths: &[f32; 3],
    count: usize,
    physical: bool,
) -> Outcome {
    let strict = known::applies(known::ABSURD_OVERFLOW, physical);
    let mut scores = [TrackScore::default(); 3];
    let mut prev_x = f32::NEG_INFINITY;
    let mut bad_sample = None;
    let plain = sc.simulate(start, first, &depths[..count], &mut scores, |s| {
        let finite = [s.x, s.depth, s.pitch, s.pitch_rate]
            .iter()
            .all(|v| v.is_finite())
            && s.reference.is_none_or(|(_, r)| r.is_finite())
            && s.command.is_none_or(|c| {
                let (d, p) = (c.depth_terms, c.pitch_terms);
                c.pitch_ref.is_finite()
                    && c.elevator.is_finite()
                    && [d.p, d.i, d.d, p.p, p.i, p.d].iter().all(|v| v.is_finite())
            });
        let reference_ok = s.reference.is_none_or(|(t, r)| {
            t >= first && t < first + count && r.to_bits() == depths[t - first].to_bits()
        });
        if bad_sample.is_none() && !((finite || !strict) && reference_ok && s.x >= prev_x) {
            bad_sample = Some(*s);
        }
        prev_x = s.x;
    });
    let tangent = sc.evaluate_tracks::<3>(start, first, depths, count);
    match (plain, tangent) {
        (Err(e), Err(f)) => {
            assert_eq!(e, f, "the plain and the tangent pass fail differently");
            Outcome::Error(e)
        }
        (Err(e), Ok(t)) => panic!("the plain pass fails ({e}), the tangent pass flies: {t:?}"),
        (Ok(end), tangent) => {
            if let Some(s) = bad_sample {
                panic!("bad sample (not finite, not advancing or wrong reference): {s:?}");
            }
            if strict {
                assert!(state_is_finite(&end), "non-finite end state {end:?}");
                for s in &scores[..count] {
                    check_score(s);
                }
            }
            match tangent {
                Err(SimError::Diverged) => Outcome::GradientDiverged,
                Err(e) => panic!("the plain pass flies, the tangent pass fails: {e}"),
                Ok(t) => {
                    assert!(
                        t.scores[..count].iter().zip(&scores).all(|(a, b)| {
                            same(a.j(), b.j())
                                && same(a.min_altitude(), b.min_altitude())
                                && same(a.violation(), b.violation())
                        }) && t.end == end,
                        "the passes fly differently: {:?} / {end:?} vs {:?}",
                        &scores[..count],
                        t
                    );
                    if !strict {
                        return Outcome::Flown;
                    }
                    let values = [t.j, t.violation, t.min_altitude];
                    assert!(
                        values.iter().all(|v| v.is_finite())
                            && t.grad_j.iter().all(|v| v.is_finite())
                            && t.grad_violation.iter().all(|v| v.is_finite()),
                        "non-finite evaluation {t:?}"
                    );
                    assert!(t.j >= 0.0 && t.violation >= 0.0, "negative sum: {t:?}");
                    let least = scores[..count]
                        .iter()
                        .map(TrackScore::min_altitude)
                        .fold(f32::INFINITY, f32::min);
                    assert_eq!(least.to_bits(), t.min_altitude.to_bits());
                    // Unused entries: zero gradients.
                    for i in count..3 {
                        assert!(t.grad_j[i] == 0.0 && t.grad_violation[i] == 0.0);
                    }
                    Outcome::Flown
                }
            }
        }
    }
}

/// Bit for bit, any NaN equal to any NaN.
fn same(a: f32, b: f32) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

fn check_score(s: &TrackScore) {
    let v = [s.j(), s.rms(), s.violation(), s.min_altitude()];
    assert!(v.iter().all(|v| v.is_finite()), "non-finite score {s:?}");
    assert!(s.j() >= 0.0 && s.violation() >= 0.0, "negative score {s:?}");
}
