//! The world a flight meets (spec/cli.md, `plan fly`): `WORLD.toml`, its
//! per-flight draw, and the true bottom, current and sensor noise of one
//! flight. Host side, f64.
//!
//! Frames: the vehicle flies along the true along-track position `x`; its
//! navigation reads `ξ = x + nav_drift (x − X_0)` (the waypoints are
//! switched and the map is looked up at `ξ`); the map itself is displaced
//! by `map_horizontal_offset`, and the true bottom is
//! `b(x) = map(x − map_horizontal_offset) + v(x)` with `v` the map's
//! vertical error, a Gauss-Markov (AR(1)) process along track with standard
//! deviation `map_vertical_sigma` and correlation length
//! `map_correlation_length`, truncated at `map_vertical_bound` σ. So under
//! the navigated `ξ` the true bottom is the map at `ξ − δ` with
//! `|δ| ≤ |offset| + |drift| |ξ − X_0| (1 + |drift|)`, the form of the
//! declared `horizontal_uncertainty` + `nav_drift` (model.md §12), and
//! `|v| ≤ bound σ`, the declared `vertical_uncertainty`.

use std::collections::BTreeMap;

use crate::fail::Fail;

/// Every key of `WORLD.toml`, its default (the planner's model exactly)
/// and what it means. A value or a `[lo, hi]` range drawn per flight.
pub const KEYS: &[(&str, f64, &str)] = &[
    ("speed_error", 0.0, "true speed U0 (1 + e_U), fraction"),
    (
        "flight_path_offset",
        0.0,
        "alpha, deg (flight path below pitch)",
    ),
    (
        "vertical_current",
        0.0,
        "constant vertical current, m/s, down",
    ),
    (
        "current_amplitude",
        0.0,
        "slowly varying current amplitude, m/s",
    ),
    ("current_period", 600.0, "its period, s"),
    ("plant_gain_scale", 1.0, "true plant gain / model gain"),
    (
        "plant_time_scale",
        1.0,
        "true plant time constants / model's",
    ),
    ("actuator_lag", 0.0, "first-order elevator lag, s (0: none)"),
    (
        "elevator_rate_limit",
        0.0,
        "elevator rate limit, deg/s (0: none)",
    ),
    ("depth_noise", 0.0, "depth sensor noise sigma, m"),
    ("pitch_noise", 0.0, "pitch sensor noise sigma, deg"),
    (
        "pitch_rate_noise",
        0.0,
        "pitch-rate sensor noise sigma, deg/s",
    ),
    ("map_vertical_sigma", 0.0, "map vertical error sigma, m"),
    (
        "map_vertical_bound",
        3.0,
        "truncation of that error, in sigma (0: none)",
    ),
    ("map_correlation_length", 200.0, "its correlation length, m"),
    ("map_horizontal_offset", 0.0, "map displaced along track, m"),
    ("nav_drift", 0.0, "navigation drift, m per m travelled"),
    (
        "dvl_range",
        100.0,
        "DVL bottom-track slant range, m (600 kHz)",
    ),
    (
        "dvl_min_grazing",
        30.0,
        "least grazing angle a beam locks at, deg",
    ),
    ("dvl_noise", 0.0, "DVL range noise sigma, m"),
    (
        "dvl_timeout",
        10.0,
        "bottom follower: depth hold on lock loss, s",
    ),
];

/// A key's value: fixed or a uniform range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range(pub f64, pub f64);

/// `WORLD.toml` parsed: one range per key of [`KEYS`].
#[derive(Clone, Debug)]
pub struct WorldSpec {
    pub keys: BTreeMap<&'static str, Range>,
}

impl WorldSpec {
    /// The planner's model: every key at its default.
    pub fn nominal() -> Self {
        Self {
            keys: KEYS.iter().map(|&(k, d, _)| (k, Range(d, d))).collect(),
        }
    }

    /// Parses `WORLD.toml` (`name` for messages). Unknown keys, non-numbers
    /// and reversed ranges are errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, Fail> {
        let table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| Fail::input(format!("{name}: {}", e.message().trim())))?;
        let mut spec = Self::nominal();
        for (key, value) in &table {
            let Some(&(k, _, _)) = KEYS.iter().find(|(k, _, _)| k == key) else {
                return Err(Fail::input(format!(
                    "{name}: unknown key `{key}` (known: {})",
                    KEYS.iter().map(|k| k.0).collect::<Vec<_>>().join(", ")
                )));
            };
            let num = |v: &toml::Value| match v {
                toml::Value::Float(f) if f.is_finite() => Some(*f),
                toml::Value::Integer(i) => Some(*i as f64),
                _ => None,
            };
            let bad = || Fail::input(format!("{name}: {key} must be a number or [lo, hi]"));
            let r = match value {
                toml::Value::Array(a) if a.len() == 2 => {
                    let (lo, hi) = (num(&a[0]).ok_or_else(bad)?, num(&a[1]).ok_or_else(bad)?);
                    if lo > hi {
                        return Err(Fail::input(format!(
                            "{name}: {key} = [{lo}, {hi}]: lo > hi"
                        )));
                    }
                    Range(lo, hi)
                }
                v => {
                    let x = num(v).ok_or_else(bad)?;
                    Range(x, x)
                }
            };
            spec.keys.insert(k, r);
        }
        spec.check(name)?;
        Ok(spec)
    }

    fn check(&self, name: &str) -> Result<(), Fail> {
        let positive = [
            "plant_gain_scale",
            "plant_time_scale",
            "current_period",
            "dvl_range",
        ];
        let nonneg = [
            "actuator_lag",
            "elevator_rate_limit",
            "depth_noise",
            "pitch_noise",
            "pitch_rate_noise",
            "map_vertical_sigma",
            "map_vertical_bound",
            "map_correlation_length",
            "dvl_noise",
            "dvl_timeout",
            "dvl_min_grazing",
        ];
        for (k, r) in &self.keys {
            if (positive.contains(k) && r.0 <= 0.0) || (nonneg.contains(k) && r.0 < 0.0) {
                return Err(Fail::input(format!(
                    "{name}: {k} = {} is out of range",
                    r.0
                )));
            }
        }
        if self.keys["speed_error"].0 <= -1.0 {
            return Err(Fail::input(format!("{name}: speed_error must be > -1")));
        }
        Ok(())
    }

    /// One flight's values, drawn from `rng`.
    pub fn draw(&self, rng: &mut Rng) -> BTreeMap<&'static str, f64> {
        self.keys
            .iter()
            .map(|(&k, &Range(lo, hi))| {
                (
                    k,
                    if hi > lo {
                        lo + (hi - lo) * rng.uniform()
                    } else {
                        lo
                    },
                )
            })
            .collect()
    }
}

/// splitmix64: small, seeded, the same on every platform; a flight's
/// stream depends on `(seed, flight)` only, never on the thread.
#[derive(Clone, Debug)]
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64, stream: u64) -> Self {
        let mut r = Self(seed ^ 0x9E37_79B9_7F4A_7C15_u64.wrapping_mul(stream.wrapping_add(1)));
        r.next();
        r
    }
    pub fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Standard normal (Box–Muller).
    pub fn normal(&mut self) -> f64 {
        let u1 = 1.0 - self.uniform();
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// The map as the host flies over it (f64, clamped at its ends).
#[derive(Clone, Debug)]
pub struct Map {
    pub x: Vec<f64>,
    pub b: Vec<f64>,
}

impl Map {
    pub fn at(&self, x: f64) -> f64 {
        let n = self.x.len();
        if x <= self.x[0] {
            return self.b[0];
        }
        if x >= self.x[n - 1] {
            return self.b[n - 1];
        }
        let i = self.x.partition_point(|&p| p <= x).clamp(1, n - 1);
        let (x0, x1, b0, b1) = (self.x[i - 1], self.x[i], self.b[i - 1], self.b[i]);
        b0 + (b1 - b0) * (x - x0) / (x1 - x0)
    }
}

/// Grid step of the map's vertical error, m.
const V_STEP: f64 = 2.0;

/// One flight's world, drawn.
#[derive(Clone, Debug)]
pub struct Flight {
    pub v: BTreeMap<&'static str, f64>,
    /// Start of the line, m.
    pub x0: f64,
    /// The vertical error on a grid from `x0 - 500` every `V_STEP` m.
    verr: Vec<f64>,
    /// Phase of the varying current, rad.
    phase: f64,
}

impl Flight {
    /// Draws a flight's values and its map error over `[x0, x_end]`.
    pub fn draw(spec: &WorldSpec, rng: &mut Rng, x0: f64, x_end: f64) -> Self {
        let v = spec.draw(rng);
        let (sigma, len, bound) = (
            v["map_vertical_sigma"],
            v["map_correlation_length"],
            v["map_vertical_bound"],
        );
        let n = ((x_end - x0 + 1000.0) / V_STEP).ceil() as usize + 2;
        let mut verr = vec![0.0; n];
        if sigma > 0.0 {
            let rho = if len > 0.0 {
                (-V_STEP / len).exp()
            } else {
                0.0
            };
            let kick = sigma * (1.0 - rho * rho).sqrt();
            let clip = |e: f64| {
                if bound > 0.0 {
                    e.clamp(-bound * sigma, bound * sigma)
                } else {
                    e
                }
            };
            let mut e = clip(sigma * rng.normal());
            for slot in &mut verr {
                *slot = e;
                e = clip(rho * e + kick * rng.normal());
            }
        }
        let phase = std::f64::consts::TAU * rng.uniform();
        Self { v, x0, verr, phase }
    }

    /// The true bottom at true position `x`, m.
    pub fn bottom(&self, map: &Map, x: f64) -> f64 {
        let s = ((x - self.x0 + 500.0) / V_STEP).max(0.0);
        let i = (s.floor() as usize).min(self.verr.len() - 2);
        let f = (s - i as f64).min(1.0);
        let e = self.verr[i] + (self.verr[i + 1] - self.verr[i]) * f;
        map.at(x - self.v["map_horizontal_offset"]) + e
    }

    /// Where navigation says the vehicle is, m.
    pub fn navigated(&self, x: f64) -> f64 {
        x + self.v["nav_drift"] * (x - self.x0)
    }

    /// The vertical current at time `t` (s), m/s, positive down.
    pub fn current(&self, t: f64) -> f64 {
        let a = self.v["current_amplitude"];
        self.v["vertical_current"]
            + if a != 0.0 {
                a * (std::f64::consts::TAU * t / self.v["current_period"] + self.phase).sin()
            } else {
                0.0
            }
    }
}
