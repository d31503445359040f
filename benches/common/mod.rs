//! The paper's line for the host benchmarks: `us_monterey_canyon_1` from
//! the bundled CSVs, the default vehicle C-AUV #4 and the default mission.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, dead_code)]

use auvnav::{Mission, Profile, Scenario, Vehicle, Waypoints};

const PROFILE: &str = include_str!("../../data/bathymetry/us_monterey_canyon_1.csv");
const WAYPOINTS: &str = include_str!("../../data/bathymetry/us_monterey_canyon_1.waypoints.csv");

/// The vehicle, the bottom profile and the waypoints of the line.
pub struct Line {
    pub vehicle: Vehicle<3>,
    pub profile: Profile<256>,
    pub waypoints: Waypoints<8>,
}

/// Column `i` of a CSV row.
fn col(row: &str, i: usize) -> f32 {
    row.split(',').nth(i).unwrap().parse().unwrap()
}

/// The line, read from the CSVs (`x_m, depth_m`; `wp, x_m, ...`).
pub fn line() -> Line {
    let rows: Vec<&str> = PROFILE.lines().skip(1).collect();
    let x: Vec<f32> = rows.iter().map(|l| col(l, 0)).collect();
    let b: Vec<f32> = rows.iter().map(|l| col(l, 1)).collect();
    let wps: Vec<f32> = WAYPOINTS.lines().skip(1).map(|l| col(l, 1)).collect();
    Line {
        vehicle: Vehicle::c_auv4().unwrap(),
        profile: Profile::new(&x, &b).unwrap(),
        waypoints: Waypoints::new(&wps).unwrap(),
    }
}

impl Line {
    /// The line's scenario under the default mission.
    pub fn scenario(&self) -> Scenario<'_, 3> {
        Scenario::new(
            &self.vehicle,
            &self.profile,
            &self.waypoints,
            Mission::default(),
        )
        .unwrap()
    }
}
