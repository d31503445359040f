//! One tangent column (the state's derivative with respect to one
//! reference depth; the equations are in [`super::tangent`]): its step,
//! its sleep where that step has become the identity, the pieces it
//! scores; and what every column's step multiplies by.

use nalgebra::{SMatrix, SVector};

use crate::model::Vehicle;
use crate::num::DEG;

use super::lin::{EndAt, StepLin};

/// Below this, a column's settled state is taken for zero (m/m for the
/// depth, deg/m for the pitch loop's states and the integrators' terms):
/// seven orders under a column's response to its own track (about 1 m/m
/// in depth), so that dropping it moves no gradient entry by more than
/// f32 resolves of it (see [`Column::settle`]).
pub(super) const NEGLIGIBLE: f32 = 1e-7;

/// The tangent of the state with respect to one reference depth, and the
/// gradients it accumulates.
#[derive(Clone, Copy)]
pub(super) struct Column<const N: usize> {
    pub eta: SVector<f32, N>,
    pub d: f32,
    pub d_prev: f32,
    pub x: f32,
    pub x_prev: f32,
    pub depth_integral: f32,
    pub pitch_integral: f32,
    pub grad_j: f32,
    pub grad_violation: f32,
    /// Asleep (see [`Column::step`]): the state is held, only the scores'
    /// tangents accumulate.
    pub asleep: bool,
}

impl<const N: usize> Column<N> {
    /// Zero: the start state does not depend on the depths.
    pub(super) fn zero() -> Self {
        Self {
            eta: SVector::zeros(),
            d: 0.0,
            d_prev: 0.0,
            x: 0.0,
            x_prev: 0.0,
            depth_integral: 0.0,
            pitch_integral: 0.0,
            grad_j: 0.0,
            grad_violation: 0.0,
            asleep: false,
        }
    }
}

impl<const N: usize> Column<N> {
    /// `∂e` at a piece end.
    #[inline(always)]
    pub(super) fn de(&self, at: EndAt, slope_ratio: f32) -> f32 {
        match at {
            EndAt::Start { slope } => self.x_prev * slope - self.d_prev,
            EndAt::End { slope } => self.x * slope - self.d,
            EndAt::Clip { t } => {
                -((self.d_prev - self.x_prev * slope_ratio) * (1.0 - t)
                    + (self.d - self.x * slope_ratio) * t)
            }
        }
    }

    /// `∂x` at a piece end (zero at a fixed waypoint).
    #[inline(always)]
    pub(super) fn dx(&self, at: EndAt) -> f32 {
        match at {
            EndAt::Start { .. } => self.x_prev,
            EndAt::End { .. } => self.x,
            EndAt::Clip { .. } => 0.0,
        }
    }
}

/// What every column's step multiplies by, gathered once per pass: the
/// cascade's gains (the pitch loop's with its sign, the depth loop's `Kdd`
/// over `Ts`), the plant, and `½ · π/180` for the mean pitch.
#[derive(Clone, Copy)]
pub(super) struct Gains<const N: usize> {
    kp: f32,
    ki: f32,
    kd_ts: f32,
    pitch: (f32, f32, f32),
    ts: f32,
    ad: SMatrix<f32, N, N>,
    bd: SVector<f32, N>,
}

impl<const N: usize> Gains<N> {
    pub(super) fn of(v: &Vehicle<N>) -> Self {
        let plant = v.plant();
        let ap = v.autopilot();
        let cfg = ap.config();
        let ts = plant.sample_time();
        let sign = ap.loop_sign();
        let (gd, gt) = (&cfg.depth_pid, &cfg.pitch_pid);
        Self {
            kp: gd.kp,
            ki: gd.ki,
            kd_ts: gd.kd / ts,
            pitch: (sign * gt.kp, sign * gt.ki, sign * gt.kd),
            ts,
            ad: *plant.ad_m(),
            bd: *plant.bd_v(),
        }
    }
}

/// One step's factors: the clamps (1 or 0) and the integrators' switches
/// (`Ts` or 0), the same for every column, and the kinematics' `½ U Ts
/// cos θ̄ · π/180` and `… sin θ̄ …`.
#[derive(Clone, Copy)]
pub(super) struct Factors {
    pitch_ref: f32,
    elevator: f32,
    depth_integral: f32,
    pitch_integral: f32,
    dd: f32,
    dx: f32,
    /// The depth loop reaches the pitch loop (the pitch reference is
    /// unclamped or the depth integrator integrates).
    open: bool,
    /// Whether the awake columns look for sleep after this step.
    check: bool,
}

impl Factors {
    #[inline(always)]
    pub(super) fn of<const N: usize>(g: &Gains<N>, lin: &StepLin, check: bool) -> Self {
        let c = lin.command;
        let on = |b: bool, v: f32| if b { v } else { 0.0 };
        let half = 0.5 * DEG * lin.step;
        Self {
            pitch_ref: on(c.pitch_ref_linear, 1.0),
            elevator: on(c.elevator_linear, 1.0),
            depth_integral: on(c.depth_integrating, g.ts),
            pitch_integral: on(c.pitch_integrating, g.ts),
            dd: half * lin.cos,
            dx: half * lin.sin,
            open: c.pitch_ref_linear || c.depth_integrating,
            check,
        }
    }
}

impl<const N: usize> Column<N> {
    /// One step of this column: the cascade's tangent (the clamps and
    /// integrators as factors, so no branch), the plant's, the
    /// kinematics'; `driven` for the column of the active track, whose
    /// reference moves with its depth.
    ///
    /// A column asleep is held: its step is the identity (to within
    /// [`NEGLIGIBLE`], see [`Column::settle`]) until the depth loop reaches
    /// the pitch loop again with something to carry (the reference, where
    /// driven, or its own depth or depth integral).
    #[inline(always)]
    pub(super) fn step(&mut self, g: &Gains<N>, f: &Factors, driven: bool) {
        if self.asleep {
            let carries = driven || self.d != 0.0 || self.depth_integral != 0.0;
            if !(f.open && carries) {
                return;
            }
            self.asleep = false;
        }
        self.advance(g, f, driven);
        if f.check {
            self.settle(g, f, driven);
        }
    }

    /// Puts the column to sleep where its step has become the identity to
    /// within [`NEGLIGIBLE`]: the pitch loop's tangent has settled (the
    /// plant's states, the pitch integrator's term and the depth's last
    /// change all negligible) and either the depth loop does not reach the
    /// pitch loop this step (a saturated dive or climb: the depth, its
    /// integral and the along-track shift are held as they are) or the
    /// column's track is over and its depth and depth integrator's term are
    /// negligible too (the column has decayed: only the along-track shift
    /// is left, held for good). The negligible residue is dropped.
    #[inline(always)]
    fn settle(&mut self, g: &Gains<N>, f: &Factors, driven: bool) {
        let small = |v: f32| libm::fabsf(v) <= NEGLIGIBLE;
        let quiet = self.eta.iter().all(|&v| small(v))
            && small(g.pitch.1 * self.pitch_integral)
            && small(self.d - self.d_prev);
        if !quiet {
            return;
        }
        let decayed = !driven && small(self.d) && small(g.ki * self.depth_integral);
        if f.open && !decayed {
            return;
        }
        self.eta = SVector::zeros();
        self.pitch_integral = 0.0;
        if decayed {
            self.d = 0.0;
            self.depth_integral = 0.0;
        }
        self.d_prev = self.d;
        self.x_prev = self.x;
        self.asleep = true;
    }

    /// The column's step proper (see [`Column::step`]).
    #[inline(always)]
    fn advance(&mut self, g: &Gains<N>, f: &Factors, driven: bool) {
        let (kp_t, ki_t, kd_t) = g.pitch;
        let pitch = self.eta.get(0).copied().unwrap_or(0.0);
        let pitch_rate = self.eta.get(1).copied().unwrap_or(0.0);
        let e_d = if driven { 1.0 - self.d } else { -self.d };
        let v = g.kd_ts * (self.d - self.d_prev) - g.kp * e_d - g.ki * self.depth_integral;
        let e_t = f.pitch_ref * v - pitch;
        let w = f.elevator * (kp_t * e_t + ki_t * self.pitch_integral - kd_t * pitch_rate);
        self.depth_integral += f.depth_integral * e_d;
        self.pitch_integral += f.pitch_integral * e_t;
        // (By reference: by value, nalgebra copies `Ad` each step.)
        #[allow(clippy::op_ref)]
        let eta = &g.ad * self.eta + g.bd.scale(w);
        self.eta = eta;
        let mean = pitch + self.eta.get(0).copied().unwrap_or(0.0);
        self.d_prev = self.d;
        self.x_prev = self.x;
        self.d -= mean * f.dd;
        self.x -= mean * f.dx;
    }

    /// [`Column::step`] and the piece it flew between samples on bottom
    /// slopes `s0`, `s1` (`sq_e = ¼ (e_lo² + e_hi²)`, `he = ½ L e`);
    /// returns `(∂e_lo, ∂e_hi)`.
    #[inline(always)]
    pub(super) fn step_piece(
        &mut self,
        g: &Gains<N>,
        f: &Factors,
        driven: bool,
        (s0, s1): (f32, f32),
        (sq_e, he_lo, he_hi): (f32, f32, f32),
    ) -> (f32, f32) {
        let de_lo = self.x * s0 - self.d;
        let x0 = self.x;
        self.step(g, f, driven);
        let de_hi = self.x * s1 - self.d;
        self.grad_j += (self.x - x0) * sq_e + de_lo * he_lo + de_hi * he_hi;
        (de_lo, de_hi)
    }
}
