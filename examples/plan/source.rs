//! Where a run's line comes from (`plan` and `plan fly` alike): cut from
//! `--grid/--line`, read from `--profile/--waypoints`, or the bundled line.

use std::path::Path;

use crate::fail::Fail;
use crate::{input, map};

/// The command line's line options.
pub struct LineSource<'a> {
    pub profile: Option<&'a Path>,
    pub waypoints: Option<&'a Path>,
    pub grid: Option<&'a Path>,
    pub line: Option<&'a Path>,
    /// `--spacing`, m.
    pub spacing: Option<f64>,
}

/// The profile and waypoint texts a run plans over, with the names its
/// errors give them, and the cut (for the chart) when the line came from
/// a grid.
pub struct LineInput {
    pub profile_text: String,
    pub profile_name: String,
    pub wp_text: String,
    pub wp_name: String,
    pub cut: Option<map::Cut>,
}

impl LineSource<'_> {
    /// The reports' name of the profile.
    pub fn label(&self) -> String {
        match (self.profile, self.grid, self.line) {
            (Some(p), _, _) => p.display().to_string(),
            (_, Some(g), Some(l)) => format!("{} on {}", l.display(), g.display()),
            _ => "us_monterey_canyon_1 (bundled)".to_string(),
        }
    }

    /// Reads (or cuts) the line.
    pub fn read(&self) -> Result<LineInput, Fail> {
        if let Some(g) = self.grid {
            let l = self
                .line
                .ok_or_else(|| Fail::usage("--grid needs --line".into()))?;
            let (profile_text, wp_text, cut) = map::profile_and_waypoints(g, l, self.spacing)?;
            return Ok(LineInput {
                profile_text,
                profile_name: self.label(),
                wp_text,
                wp_name: l.display().to_string(),
                cut: Some(cut),
            });
        }
        let (profile_text, profile_name, wp_text, wp_name) = match (self.profile, self.waypoints) {
            (Some(p), Some(w)) => (
                input::read(p)?,
                p.display().to_string(),
                input::read(w)?,
                w.display().to_string(),
            ),
            _ => (
                input::BUNDLED_PROFILE.to_string(),
                "us_monterey_canyon_1.csv (bundled)".to_string(),
                input::BUNDLED_WAYPOINTS.to_string(),
                "us_monterey_canyon_1.waypoints.csv (bundled)".to_string(),
            ),
        };
        Ok(LineInput {
            profile_text,
            profile_name,
            wp_text,
            wp_name,
            cut: None,
        })
    }
}
