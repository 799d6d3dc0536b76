//! The place of one axis' keys in a config file, for errors that name them.

use std::path::Path;

use super::positive;
use crate::plausible::Plausible;
use crate::ConfigError;

/// Where an axis' keys live (`axes[i]` of `file`): errors name `axes[i].<sub>`.
pub(super) struct AxisKey<'a> {
    pub(super) file: &'a Path,
    pub(super) key: &'a str,
}

impl AxisKey<'_> {
    /// An error at `axes[i].<sub>`.
    pub(super) fn err(&self, sub: &str, msg: String) -> ConfigError {
        ConfigError::new(self.file, format!("{}.{sub}", self.key), msg)
    }

    /// `v` checked positive and finite, as key `axes[i].<sub>`.
    pub(super) fn positive(&self, sub: &str, v: f64) -> Result<f64, ConfigError> {
        positive(self.file, &format!("{}.{sub}", self.key), v)
    }

    /// `v` checked within what a real drive and motor can be (`bound`), as key `axes[i].<sub>`.
    pub(super) fn plausible(
        &self,
        sub: &str,
        bound: &Plausible,
        v: f64,
    ) -> Result<f64, ConfigError> {
        bound.check(v).map_err(|m| self.err(sub, m))
    }
}
