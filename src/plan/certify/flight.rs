//! One world's flight of a continuation for a certificate: the least
//! altitude on its first track and to the end, each track's into the
//! certificate's rows, and a knife edge's other switch flown too where
//! one vehicle world is declared.

use core::cell::Cell;

use crate::model::ProfileView;
use crate::sim::{Scenario, SimError, TrackScore, VehicleState, World};

/// One world's flight of `depths` from `st` on `track`: the least altitude
/// on the first track, and to the end (`-inf` from the track on which a
/// flight fails). Each track's altitude less `margin` also lowers the
/// matching entry of `per_track` (which may be shorter, or empty).
///
/// With one vehicle world (nothing declared, or only the map: each world
/// then switches where the nominal flight does), where a track's end
/// lies on its waypoint's knife edge ([`Scenario::on_edge`]), the line is
/// also flown with that switch the other way ([`fly_once`]'s branch, one
/// flight more each) while `flights` is below `cap` (else the nominal
/// switch alone), and both flights count: the same depths flown in other
/// arithmetic may switch the other way, and the next track's least
/// altitude can move by a tenth of a metre (`check_planner.py --seed
/// 2585`, `unseen_2585_5`: 60.09 m in f32, 59.974 m in f64, below `h_a`).
/// Under declared motion the vehicle margin's floor covers it instead.
/// (Not inlined: its callers share one copy of the flight. A branch flies
/// from the world's start again, after the first flight rather than
/// inside it, so that a certificate's stack holds one flight at a time.)
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(in crate::plan) fn fly_world<const N: usize>(
    sc: &Scenario<'_, N>,
    w: &World,
    bottom: ProfileView<'_>,
    at: (&VehicleState<N>, usize),
    depths: &[f32],
    (margin, per_track): (f32, &[Cell<f32>]),
    (flights, cap): (&mut u32, u32),
) -> (f32, f32) {
    const FAILED: (f32, f32) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
    let world = (w, bottom);
    *flights = flights.saturating_add(1);
    let Ok((first, mut all, edges)) = fly_once(sc, world, at, depths, (margin, per_track), None)
    else {
        return FAILED;
    };
    let edges = if !sc.mission().uncertainty().motion_uncertain() {
        edges
    } else {
        0
    };
    for j in (0..depths.len().min(64)).filter(|&j| (edges >> j) & 1 == 1) {
        if *flights >= cap {
            break;
        }
        *flights = flights.saturating_add(1);
        let minima = (margin, per_track);
        all = match fly_once(sc, world, at, depths, minima, Some(j)) {
            Ok((_, a, _)) => all.min(a),
            Err(_) => f32::NEG_INFINITY,
        };
    }
    (first, all)
}

/// One flight of the line `depths` from `st` on `track` in world `w` over
/// `bottom`: the least altitude on the first track, and to the end
/// (`-inf` from the track on which a flight fails), each track's less
/// `margin` also lowering its entry of `per_track`; with the tracks whose
/// end lies on a knife edge, a track of `depths` following (bit `j` for
/// track `track + j`, the first 64). With `branch` `Some(j)`, the switch
/// at the end of track `j` (of `depths`) falls the other way
/// ([`Scenario::switch_other_way`]; its own edges are not reported).
///
/// # Errors
/// [`SimError`] for a waypoint outside `bottom`.
#[inline(always)]
fn fly_once<const N: usize>(
    sc: &Scenario<'_, N>,
    (w, bottom): (&World, ProfileView<'_>),
    (st, track): (&VehicleState<N>, usize),
    depths: &[f32],
    (margin, per_track): (f32, &[Cell<f32>]),
    branch: Option<usize>,
) -> Result<(f32, f32, u64), SimError> {
    let scw = sc.in_world(w, bottom)?;
    let mut score = [TrackScore::default()];
    let mut state = *st;
    let (mut first, mut all, mut edges) = (f32::INFINITY, f32::INFINITY, 0_u64);
    // One flight of the line, flown track by track (runs chain exactly).
    for (j, &z) in depths.iter().enumerate() {
        let t = track.saturating_add(j);
        let flown = scw.fly(&state, t, &[z], &mut score);
        let h = match (&flown, score.first()) {
            (Ok(_), Some(s)) => s.min_altitude(),
            _ => f32::NEG_INFINITY,
        };
        all = all.min(h);
        if j == 0 {
            first = h;
        }
        if let Some(l) = per_track.get(j) {
            l.set(l.get().min(h - margin));
        }
        let Ok(mut next) = flown else {
            break;
        };
        if branch == Some(j) {
            // (Track `j`'s own flight is the first one's, but for a
            // sample past its waypoint, which the next track scores.)
            // (`state` is used up: `next` follows.)
            if scw
                .switch_other_way((&mut state, &mut next), (t, z), &mut score)
                .is_err()
            {
                all = f32::NEG_INFINITY;
                let later = per_track.get(j.saturating_add(1)..).unwrap_or(&[]);
                later.iter().for_each(|l| l.set(f32::NEG_INFINITY));
                break;
            }
        } else if branch.is_none()
            && j < 64
            && j.saturating_add(1) < depths.len()
            && scw.on_edge(t, &next)
        {
            edges |= 1 << j;
        }
        state = next;
    }
    Ok((first, all, edges))
}
