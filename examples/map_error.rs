//! Monte Carlo study of map error: plan each Monterey line on the mapped
//! bottom (receding horizon, default vehicle), then fly the planned depths
//! over the "true" bottom, the map plus a random error correlated along
//! track, and count the flights that go below `h_a` and below the bottom.
//!
//! `cargo run --release --example map_error -- [--flights N] [--readme README.md]`
//!
//! Error model: at the profile samples, a stationary AR(1) sequence with
//! standard deviation σ and correlation `exp(−Δx / ℓ)`, ℓ = 200 m (about
//! half a GEBCO cell), linearly interpolated between samples. The flight
//! does not depend on the bottom (the autopilot steers to reference depths),
//! so each plan is simulated once and its altitude re-measured over each
//! random bottom.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]
#![allow(
    clippy::arithmetic_side_effects,
    clippy::cast_precision_loss,
    clippy::float_cmp
)]

use auvnav::{
    Mission, Planner, PlannerConfig, Profile, Scenario, TrackScore, Uncertainty, Vehicle,
    Waypoints, lower_envelope,
};

/// The margin `h_r − h_a` of the certified study, m.
const CERT_MARGIN: f32 = 20.0;

const LINES: [&str; 2] = ["us_monterey_canyon_1", "us_monterey_canyon_2"];
const SIGMAS: [f64; 3] = [5.0, 10.0, 20.0];
const MARGINS: [f32; 4] = [10.0, 20.0, 30.0, 40.0];
const H_A: f32 = 60.0;
const CORRELATION_M: f64 = 200.0;
const START: &str = "<!-- map-error:start -->";
const END: &str = "<!-- map-error:end -->";

/// SplitMix64 and Box–Muller: a seeded, dependency-free normal generator.
struct Rng(u64);
impl Rng {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    fn normal(&mut self) -> f64 {
        let u = self.next_f64().max(1e-300);
        let v = self.next_f64();
        (-2.0 * u.ln()).sqrt() * (2.0 * std::f64::consts::PI * v).cos()
    }
}

fn read(name: &str) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/data/bathymetry");
    let p = std::fs::read_to_string(format!("{dir}/{name}.csv")).unwrap();
    let (mut x, mut b) = (Vec::new(), Vec::new());
    for l in p.lines().skip(1) {
        let mut it = l.split(',');
        x.push(it.next().unwrap().parse().unwrap());
        b.push(it.next().unwrap().parse().unwrap());
    }
    let w = std::fs::read_to_string(format!("{dir}/{name}.waypoints.csv")).unwrap();
    let wp = w
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    (x, b, wp)
}

/// The planned flight over the map: every sample's (x, depth) within the line.
fn plan(x: &[f32], b: &[f32], wp: &[f32], h_r: f32) -> (Vec<(f64, f64)>, bool, f32) {
    let (samples, safe, min, _) = plan_declared(x, b, wp, h_r, 0.0);
    (samples, safe, min)
}

/// [`plan`] certified against a declared vertical map error `e_v` (m):
/// also returns the line's total `J`, m³.
fn plan_declared(
    x: &[f32],
    b: &[f32],
    wp: &[f32],
    h_r: f32,
    e_v: f32,
) -> (Vec<(f64, f64)>, bool, f32, f32) {
    let v = Vehicle::c_auv4().unwrap();
    let profile = Profile::<512>::new(x, b).unwrap();
    let wps = Waypoints::<8>::new(wp).unwrap();
    let u = Uncertainty::new(0.0, 0.0, e_v, 0.0, 0.0, 0.0).unwrap();
    let env = lower_envelope::<1600>(profile.view(), &u, wp[0]).unwrap();
    let mission = Mission::new(h_r, H_A, [0.0, 6000.0])
        .unwrap()
        .with_uncertainty(u);
    let sc = Scenario::new(&v, &profile, &wps, mission)
        .unwrap()
        .with_certification_bottom(env.view())
        .unwrap();
    let mut planner = Planner::<5>::new(PlannerConfig::default()).unwrap();
    let mut st = sc.start_state(sc.default_initial_depth());
    let mut depths = Vec::new();
    let mut all_safe = true;
    for n in 0..wps.tracks() {
        let p = planner.plan(&sc, &st, n).unwrap();
        all_safe &= p.safe;
        depths.push(p.depth);
        st = p.next_state;
    }
    let start = sc.start_state(sc.default_initial_depth());
    let mut scores = vec![TrackScore::default(); depths.len()];
    let mut samples = Vec::new();
    let x_end = *wp.last().unwrap();
    sc.simulate(&start, 0, &depths, &mut scores, |s| {
        if s.x <= x_end {
            samples.push((f64::from(s.x), f64::from(s.depth)));
        }
    })
    .unwrap();
    let min = scores
        .iter()
        .map(TrackScore::min_altitude)
        .fold(f32::INFINITY, f32::min);
    let j = scores.iter().map(TrackScore::j).sum();
    (samples, all_safe, min, j)
}

/// Flies `samples` over the map plus `flights` error fields of `sigma`
/// (m): the percentages of flights below `h_a` and below 0.
fn fly_errors(
    samples: &[(f64, f64)],
    (x, b): (&[f32], &[f32]),
    sigma: f64,
    rng: &mut Rng,
    flights: usize,
) -> (f64, f64) {
    let rho = |dx: f64| (-dx / CORRELATION_M).exp();
    let (mut below_ha, mut below_0) = (0usize, 0usize);
    for _ in 0..flights {
        let mut err = Vec::with_capacity(x.len());
        let mut e = sigma * rng.normal();
        err.push(e);
        for i in 1..x.len() {
            let r = rho(f64::from(x[i] - x[i - 1]));
            e = r * e + (1.0 - r * r).sqrt() * sigma * rng.normal();
            err.push(e);
        }
        let mut seg = 0;
        let mut min_alt = f64::INFINITY;
        for &(xs, d) in samples {
            while seg + 2 < x.len() && xs >= f64::from(x[seg + 1]) {
                seg += 1;
            }
            let (x0, x1) = (f64::from(x[seg]), f64::from(x[seg + 1]));
            let t = ((xs - x0) / (x1 - x0)).clamp(0.0, 1.0);
            let truth = f64::from(b[seg])
                + err[seg]
                + t * (f64::from(b[seg + 1]) + err[seg + 1] - f64::from(b[seg]) - err[seg]);
            min_alt = min_alt.min(truth - d);
        }
        below_ha += usize::from(min_alt < f64::from(H_A));
        below_0 += usize::from(min_alt < 0.0);
    }
    (
        100.0 * below_ha as f64 / flights as f64,
        100.0 * below_0 as f64 / flights as f64,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let flag = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .and_then(|i| args.get(i + 1))
            .cloned()
    };
    let flights: usize = flag("--flights").map_or(1000, |v| v.parse().unwrap());
    let mut out = vec![
        START.to_string(),
        String::new(),
        format!(
            "Generated by `cargo run --release --example map_error -- --readme README.md` \
             ({flights} flights per cell, seed fixed; do not edit by hand). Each line is planned \
             on the map (receding horizon, default vehicle, `h_a` = {H_A} m, `h_r` = `h_a` + \
             margin), then flown over the map plus an error correlated along track (AR(1), \
             correlation length {CORRELATION_M} m, standard deviation σ). Cells: percentage of \
             flights whose minimum true altitude went below `h_a` / below 0 (hitting the bottom)."
        ),
        String::new(),
    ];
    let mut advice = Vec::new();
    let mut active_lines: Vec<String> = Vec::new();
    for line in LINES {
        let (x, b, wp) = read(line);
        out.push(format!("**{line}**"));
        out.push(String::new());
        let mut header = "| σ \\ margin `h_r − h_a` |".to_string();
        let mut rule = "|---|".to_string();
        for m in MARGINS {
            header += &format!(" {m} m |");
            rule += "---|";
        }
        out.push(header);
        out.push(rule);
        let plans: Vec<_> = MARGINS
            .iter()
            .map(|&m| plan(&x, &b, &wp, H_A + m))
            .collect();
        for &sigma in &SIGMAS {
            let mut row = format!("| σ = {sigma} m |");
            let mut rng = Rng(0x5eed_0000 + sigma as u64);
            let mut first_ok = None;
            let mut worst_0 = 0.0_f64;
            for (k, (samples, _, _)) in plans.iter().enumerate() {
                let (pa, p0) = fly_errors(samples, (&x, &b), sigma, &mut rng, flights);
                row += &format!(" {pa:.1} % / {p0:.1} % |");
                worst_0 = worst_0.max(p0);
                if first_ok.is_none() && p0 < 0.1 && pa < 5.0 {
                    first_ok = Some(MARGINS[k]);
                }
            }
            out.push(row);
            advice.push((line, sigma, first_ok, worst_0));
        }
        let nominal: Vec<String> = plans
            .iter()
            .zip(MARGINS)
            .map(|((_, safe, min), m)| {
                format!(
                    "{m} m: {}{min:.1} m",
                    if *safe { "" } else { "unsafe on the map, " }
                )
            })
            .collect();
        out.push(String::new());
        out.push(format!(
            "Planned minimum altitude on the map, per margin: {}.",
            nominal.join("; ")
        ));
        if plans.iter().all(|(_, _, min)| *min < H_A + 1.0) {
            active_lines.push(format!("`{line}`"));
        }
        out.push(String::new());
    }
    out.push(format!(
        "**Certified against the map error** (`vertical_uncertainty` = 3σ declared, margin \
         `h_r − h_a` = {CERT_MARGIN} m; the same error fields): below `h_a` / below 0, the plan's \
         `J` against the nominal plan's, and whether it is certified safe."
    ));
    out.push(String::new());
    out.push("| line | σ | below `h_a` / below 0 | `J` vs nominal | certified |".to_string());
    out.push("|---|---|---|---|---|".to_string());
    for line in LINES {
        let (x, b, wp) = read(line);
        let (_, _, _, j0) = plan_declared(&x, &b, &wp, H_A + CERT_MARGIN, 0.0);
        for &sigma in &SIGMAS {
            let (samples, safe, _, j) =
                plan_declared(&x, &b, &wp, H_A + CERT_MARGIN, 3.0 * sigma as f32);
            let mut rng = Rng(0x5eed_0000 + sigma as u64);
            let (pa, p0) = fly_errors(&samples, (&x, &b), sigma, &mut rng, flights);
            out.push(format!(
                "| `{line}` | {sigma} m | {pa:.1} % / {p0:.1} % | {:+.0} % | {} |",
                100.0 * (j / j0 - 1.0),
                if safe { "yes" } else { "no (infeasible)" }
            ));
        }
    }
    out.push(String::new());
    out.push(format!(
        "Declaring 3σ takes the flights below `h_a` from the nominal table's figures (margin 20 m) to the \
         Gaussian tail beyond 3σ, with no collision. Where the line is not certified, the start \
         itself ({} m above the map) is already less than `h_a` + 3σ above the certification \
         bottom: no certified line exists from it, and the planner says so from the first call.",
        H_A + CERT_MARGIN
    ));
    out.push(String::new());
    out.push("What it means for choosing `h_r` and `h_a`:".to_string());
    out.push(String::new());
    let worst0 = |sigma: f64| {
        advice
            .iter()
            .filter(|a| a.1 == sigma)
            .map(|a| a.3)
            .fold(0.0_f64, f64::max)
    };
    let active = active_lines.join(", ");
    if !active_lines.is_empty() {
        out.push(format!(
            "- On {active} the planned flight touches the `h_a` envelope (minimum altitude on the \
             map within 1 m of `h_a`) whatever the margin: on a wall the vehicle cannot track `h_r`, \
             the constraint is active, and the margin `h_r − h_a` buys nothing there. Any map error \
             that raises the bottom under such a point takes the flight below `h_a`, hence the high \
             first figures."
        ));
    }
    out.push(format!(
        "- Collisions (below 0) stayed at or under {:.1} % for σ = 5 m, {:.1} % for σ = 10 m and \
         {:.1} % for σ = 20 m: with `h_a` = {H_A} m the bottom is reached only by errors of \
         three σ and more, where σ = 20 m.",
        worst0(5.0),
        worst0(10.0),
        worst0(20.0)
    ));
    out.push(
        "- So the map error must be carried by the certificate, not by `h_r − h_a`: declare \
         `vertical_uncertainty` of about three times the map's vertical error (for GEBCO-class \
         grids on canyon walls, σ of 10–20 m and more, since a horizontal error on a steep \
         slope becomes a large vertical one; declare that as `horizontal_uncertainty`), as the \
         certified table shows; the margin `h_r − h_a` only matters where the terrain lets the \
         vehicle track `h_r`, where it keeps the flight off the envelope and absorbs smaller \
         errors."
            .to_string(),
    );
    out.push(String::new());
    out.push(END.to_string());
    let section = out.join("\n");
    match flag("--readme") {
        Some(path) => {
            let text = std::fs::read_to_string(&path).unwrap();
            let text = match (text.find(START), text.find(END)) {
                (Some(a), Some(b)) => {
                    format!("{}{}{}", &text[..a], section, &text[b + END.len()..])
                }
                _ => format!(
                    "{}\n\n## Monte Carlo: map error\n\n{section}\n",
                    text.trim_end()
                ),
            };
            std::fs::write(&path, text).unwrap();
            println!("{path} updated");
        }
        None => println!("{section}"),
    }
}
