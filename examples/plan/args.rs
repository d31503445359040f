//! Command-line arguments of `plan` (spec/cli.md).

use std::ffi::OsString;
use std::path::PathBuf;

use crate::fail::Fail;
use crate::input::MAX_HORIZON;

/// Optimizer choice.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    Bfgs,
    Gd,
}

/// Planning mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    Horizon,
    Track,
}

/// Parsed command line.
#[derive(Debug)]
pub struct Args {
    pub profile: Option<PathBuf>,
    pub waypoints: Option<PathBuf>,
    pub config: Option<PathBuf>,
    /// Raw `--depths` text; parsed once the number of tracks is known.
    pub depths: Option<String>,
    pub method: Method,
    pub mode: Mode,
    pub horizon: Option<usize>,
    pub unconstrained: bool,
    pub json: bool,
    pub trajectory: Option<PathBuf>,
    pub plot: Option<PathBuf>,
}

pub const USAGE: &str = "usage: plan [--profile PROFILE.csv --waypoints WAYPOINTS.csv] [--config VEHICLE.toml] \
[--depths z1,...,zM] [--method bfgs|gd] [--mode horizon|track] [--horizon K] [--unconstrained] \
[--json] [--trajectory OUT.csv] [--plot OUT.svg]";

impl Args {
    /// Parses the arguments as the operating system passes them: one that
    /// is not UTF-8 is a usage error (`std::env::args` would panic).
    pub fn parse_os(it: impl Iterator<Item = OsString>) -> Result<Self, Fail> {
        let args = it
            .enumerate()
            .map(|(i, a)| {
                a.into_string().map_err(|a| {
                    Fail::usage(format!(
                        "argument {} ('{}') is not valid UTF-8",
                        i + 1,
                        a.to_string_lossy()
                    ))
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Self::parse(args.into_iter())
    }

    /// Parses `--flag value` and `--flag=value` forms.
    pub fn parse(mut it: impl Iterator<Item = String>) -> Result<Self, Fail> {
        let mut a = Args {
            profile: None,
            waypoints: None,
            config: None,
            depths: None,
            method: Method::Bfgs,
            mode: Mode::Horizon,
            horizon: None,
            unconstrained: false,
            json: false,
            trajectory: None,
            plot: None,
        };
        while let Some(arg) = it.next() {
            let (flag, inline) = match arg.split_once('=') {
                Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
                _ => (arg.clone(), None),
            };
            let mut value = |name: &str| -> Result<String, Fail> {
                match inline.clone().or_else(|| it.next()) {
                    Some(v) => Ok(v),
                    None => Err(Fail::usage(format!("{name} needs a value"))),
                }
            };
            match flag.as_str() {
                "--profile" => a.profile = Some(value("--profile")?.into()),
                "--waypoints" => a.waypoints = Some(value("--waypoints")?.into()),
                "--config" => a.config = Some(value("--config")?.into()),
                "--depths" => a.depths = Some(value("--depths")?),
                "--trajectory" => a.trajectory = Some(value("--trajectory")?.into()),
                "--plot" => a.plot = Some(value("--plot")?.into()),
                "--method" => {
                    a.method = match value("--method")?.as_str() {
                        "bfgs" => Method::Bfgs,
                        "gd" => Method::Gd,
                        other => {
                            return Err(Fail::usage(format!(
                                "--method must be bfgs or gd, got '{other}'"
                            )));
                        }
                    }
                }
                "--mode" => {
                    a.mode = match value("--mode")?.as_str() {
                        "horizon" => Mode::Horizon,
                        "track" => Mode::Track,
                        other => {
                            return Err(Fail::usage(format!(
                                "--mode must be horizon or track, got '{other}'"
                            )));
                        }
                    }
                }
                "--horizon" => {
                    let v = value("--horizon")?;
                    match v.trim().parse::<usize>() {
                        Ok(k) if (1..=MAX_HORIZON).contains(&k) => a.horizon = Some(k),
                        _ => {
                            return Err(Fail::usage(format!(
                                "--horizon must be a whole number of tracks from 1 to {}, got '{v}'",
                                MAX_HORIZON
                            )));
                        }
                    }
                }
                "--unconstrained" | "--json" if inline.is_some() => {
                    return Err(Fail::usage(format!("{flag} takes no value")));
                }
                "--unconstrained" => a.unconstrained = true,
                "--json" => a.json = true,
                "-h" | "--help" => return Err(Fail::Help),
                other => return Err(Fail::usage(format!("unknown argument '{other}'"))),
            }
        }
        if a.profile.is_some() != a.waypoints.is_some() {
            return Err(Fail::usage(
                "--profile and --waypoints go together (give both, or neither for the bundled line)"
                    .into(),
            ));
        }
        Ok(a)
    }
}

/// Parses `--depths` for `tracks` tracks.
pub fn parse_depths(text: &str, tracks: usize) -> Result<Vec<f32>, Fail> {
    let mut out = Vec::new();
    for (i, item) in text.split(',').enumerate() {
        let item = item.trim();
        let v: f32 = item.parse().map_err(|_| {
            Fail::input(format!(
                "--depths: value {} ('{item}') is not a number",
                i + 1
            ))
        })?;
        if !v.is_finite() {
            return Err(Fail::input(format!(
                "--depths: value {} ('{item}') is not finite",
                i + 1
            )));
        }
        out.push(v);
    }
    if out.len() != tracks {
        return Err(Fail::input(format!(
            "--depths: got {} depths for {tracks} tracks (one per track)",
            out.len()
        )));
    }
    Ok(out)
}
