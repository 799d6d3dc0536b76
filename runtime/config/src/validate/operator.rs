//! `[operator]`: the group whose members may command the cell, resolved to its id.

use std::path::Path;

use super::super::raw::RawOperator;
use super::super::{ConfigError, OperatorConfig, OperatorGroup};

/// Resolves `operator.group` on this machine; an unknown group is refused, named.
pub(super) fn operator_config(
    file: &Path,
    raw: &RawOperator,
) -> Result<OperatorConfig, ConfigError> {
    let Some(name) = &raw.group else {
        return Ok(OperatorConfig::default());
    };
    let refuse = |why: String| Err(ConfigError::new(file, "operator.group", why));
    if name.is_empty() || name.contains(['\0', ':', '/']) {
        return refuse(format!("'{name}' is not a group name"));
    }
    match nix::unistd::Group::from_name(name) {
        Ok(Some(g)) => Ok(OperatorConfig {
            group: Some(OperatorGroup {
                name: name.clone(),
                gid: g.gid.as_raw(),
            }),
        }),
        Ok(None) => refuse(format!("no group named '{name}' on this machine")),
        Err(e) => refuse(format!("cannot look up group '{name}': {e}")),
    }
}

#[cfg(test)]
mod tests {
    use crate::CellConfig;
    use std::path::Path;

    const CELL: &str = "[cell]\nname = \"g\"\ncycle_time_us = 1000\n\
        [[axes]]\nname = \"x\"\ndrive = \"mr-j5-g-n1\"\nmotor = { counts_per_rev = 10000 }\n\
        counts_per_unit = 1000\nlimits = { position = [0.0, 500.0], velocity = 100.0, \
        acceleration = 1000.0, jerk = 10000.0 }\n";

    #[test]
    fn the_operator_group_is_resolved_or_refused_by_name() {
        let c = CellConfig::parse(Path::new("g.toml"), CELL).unwrap();
        assert_eq!(c.operator.group, None);
        let text = format!("{CELL}[operator]\ngroup = \"root\"\n");
        let c = CellConfig::parse(Path::new("g.toml"), &text).unwrap();
        let g = c.operator.group.unwrap();
        assert_eq!((g.name.as_str(), g.gid), ("root", 0));
        let text = format!("{CELL}[operator]\ngroup = \"no-such-group-x7\"\n");
        let e = CellConfig::parse(Path::new("g.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("operator.group") && e.contains("no group named 'no-such-group-x7'"),
            "{e}"
        );
        let text = format!("{CELL}[operator]\ngroup = \"\"\n");
        let e = CellConfig::parse(Path::new("g.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(e.contains("operator.group"), "{e}");
    }
}
