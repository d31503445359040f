//! The tool's one-line errors: every bad input exits with status 2.

use std::fmt;

/// Why the tool stops early.
#[derive(Debug)]
pub enum Fail {
    /// `--help`: usage on stdout, status 0.
    Help,
    /// Bad command line.
    Usage(String),
    /// Bad input data or configuration.
    Input(String),
}

impl Fail {
    pub fn usage(msg: String) -> Self {
        Self::Usage(msg)
    }
    pub fn input(msg: String) -> Self {
        Self::Input(msg)
    }
}

impl fmt::Display for Fail {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Help => f.write_str(crate::args::USAGE),
            // One line, always: newlines inside a message become "; ".
            Self::Usage(m) | Self::Input(m) => f.write_str(&m.replace('\n', "; ")),
        }
    }
}
