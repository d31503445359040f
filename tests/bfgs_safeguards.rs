//! Two safeguards of the BFGS (`src/optim/bfgs.rs`, module docs) on
//! functions whose behaviour is known in closed form: a run that the line
//! search can only move by slivers stops, and a concave stretch is walked
//! in doubling steps.
#![allow(clippy::unwrap_used, clippy::arithmetic_side_effects)]
// (A point projected on the box is the bound exactly.)
#![allow(clippy::float_cmp)]

use auvnav::optim::{self, BfgsConfig, Bounds, Objective, Status};

/// A sawtooth: the trend `(z − 10)²/2` plus teeth 1 cm wide that fall at
/// `K` per metre and jump back up by `K` cm at each edge; the gradient is
/// the exact one inside a tooth, `z − 10 − K`. Near the trend's minimum no
/// step longer than a tooth decreases `J` as the gradient promises.
struct Sawtooth;

/// The teeth's slope, m³/m.
const K: f32 = 100.0;
/// The teeth's width, m.
const W: f32 = 0.01;

impl Objective<1> for Sawtooth {
    type Error = ();
    fn eval(&mut self, z: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
        let x = z[0];
        let tooth = x - W * libm::floorf(x / W);
        Ok((0.5 * (x - 10.0) * (x - 10.0) - K * tooth, [x - 10.0 - K]))
    }
}

/// Crawling tooth by tooth, a centimetre an iteration, took 18
/// iterations; the run now stops on its second sliver in a row (3
/// iterations, 0.6 m from the trend's minimum).
#[test]
fn a_run_moved_only_by_slivers_stops() {
    let mut f = Sawtooth;
    let out = optim::bfgs(
        &mut f,
        &[5.0],
        &Bounds::uniform(0.0, 100.0),
        &BfgsConfig::default(),
    )
    .unwrap();
    assert_eq!(out.status, Status::LineSearchFailed, "{out:?}");
    assert!(out.iterations <= 10, "{} iterations", out.iterations);
    assert!((out.z[0] - 10.0).abs() < 1.5, "stopped at {}", out.z[0]);
}

/// `J = −z²/2`: concave everywhere, its minimum on the box at 100. From 1
/// with a first step of 0.1 m the metric, never updated (negative
/// curvature), would move `z` by a tenth of itself an iteration: 49
/// iterations to the bound. Halved after each full step, 7.
#[test]
fn a_concave_stretch_is_walked_in_doubling_steps() {
    struct Concave;
    impl Objective<1> for Concave {
        type Error = ();
        fn eval(&mut self, z: &[f32; 1]) -> Result<(f32, [f32; 1]), ()> {
            Ok((-0.5 * z[0] * z[0], [-z[0]]))
        }
    }
    let cfg = BfgsConfig {
        first_step: 0.1,
        ..BfgsConfig::default()
    };
    let out = optim::bfgs(&mut Concave, &[1.0], &Bounds::uniform(0.0, 100.0), &cfg).unwrap();
    assert_eq!(out.z[0], 100.0, "{out:?}");
    assert!(out.iterations <= 10, "{} iterations", out.iterations);
}
