//! A simulated Doppler velocity log's bottom track: four Janus beams at
//! 30° from the vehicle's vertical (fore, aft, port, starboard), each
//! locking on the true bottom when its slant range is within `dvl_range`
//! (600 kHz class: about 90 m of altitude, 100 m slant) and it meets the
//! bottom at a grazing angle of at least `dvl_min_grazing`. Bottom lock
//! needs three beams (a DVL's velocity solution); the altitude is the mean
//! vertical projection of the locked beams. The fore beam's range is also
//! the forward-looking range DUNE's `SlopeData` takes its slope from
//! (`src/DUNE/Control/SlopeData.hpp`, `updateFRange`).
//!
//! The world is an along-track profile, flat across track: the port and
//! starboard beams meet the bottom under the vehicle, tilted only along
//! track.

use super::world::{Flight, Map, Rng};

/// Beam angle from the vehicle's vertical, deg.
const JANUS: f64 = 30.0;
/// Ray-marching step, m.
const MARCH: f64 = 0.5;

/// One DVL ping.
#[derive(Clone, Copy, Debug, Default)]
pub struct Ping {
    /// Bottom lock (three beams or more).
    pub lock: bool,
    /// Measured altitude, m (when locked).
    pub altitude: f64,
    /// The fore beam's hit (horizontal distance ahead, depth), when it
    /// locked.
    pub fore: Option<(f64, f64)>,
}

/// Slope angle of the true bottom at `x`, rad, positive rising ahead.
fn slope(world: &Flight, map: &Map, x: f64) -> f64 {
    let h = 1.0;
    (-(world.bottom(map, x + h) - world.bottom(map, x - h)) / (2.0 * h)).atan()
}

/// The beam from `(x, d)` at `phi` (rad) from the vertical, forward
/// positive: slant range, hit `(x, depth)` and grazing angle (rad).
fn cast(
    world: &Flight,
    map: &Map,
    x: f64,
    d: f64,
    phi: f64,
    max: f64,
) -> Option<(f64, f64, f64, f64)> {
    let (sx, sz) = (phi.sin(), phi.cos());
    let mut r = 0.0;
    while r <= max {
        let (hx, hz) = (x + r * sx, d + r * sz);
        if hz >= world.bottom(map, hx) {
            let beta = slope(world, map, hx);
            // Bottom tangent (cos β, −sin β) in (x, z down); the beam
            // (sin φ, cos φ): grazing = asin |beam × tangent| ... the
            // angle between beam and surface.
            let cross = (sx * (-beta.sin()) - sz * beta.cos()).abs();
            return Some((r, hx, hz, cross.clamp(0.0, 1.0).asin()));
        }
        r += MARCH;
    }
    None
}

/// One ping from the vehicle at true `x`, depth `d`, pitch `theta_deg`.
pub fn ping(world: &Flight, map: &Map, rng: &mut Rng, x: f64, d: f64, theta_deg: f64) -> Ping {
    let max = world.v["dvl_range"];
    let min_graze = world.v["dvl_min_grazing"].to_radians();
    let noise = world.v["dvl_noise"];
    let (j, th) = (JANUS.to_radians(), theta_deg.to_radians());
    let mut n = 0;
    let mut alt = 0.0;
    let mut fore = None;
    // Fore and aft, in the pitch plane (nose up tilts both aft).
    for (phi, is_fore) in [(j - th, true), (-j - th, false)] {
        if let Some((r, hx, hz, g)) = cast(world, map, x, d, phi, max)
            && g >= min_graze
        {
            let r = r + noise * rng.normal();
            n += 1;
            alt += r * phi.cos();
            if is_fore {
                fore = Some((hx - x, hz));
            }
        }
    }
    // Port and starboard: across track, the bottom tilted along track.
    let b = world.bottom(map, x);
    let beta = slope(world, map, x);
    let r = (b - d) / (j.cos() * th.cos());
    let graze = std::f64::consts::FRAC_PI_2 - (j.cos() * beta.cos()).clamp(-1.0, 1.0).acos();
    if b > d && r <= max && graze >= min_graze {
        for _ in 0..2 {
            let r = r + noise * rng.normal();
            n += 1;
            alt += r * j.cos() * th.cos();
        }
    }
    Ping {
        lock: n >= 3,
        altitude: if n > 0 { alt / n as f64 } else { 0.0 },
        fore,
    }
}
