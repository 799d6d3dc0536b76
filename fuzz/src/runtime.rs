//! Runtime targets: cell config and program TOML, the operator wire format, and setpoint
//! blocks as the RT thread reads them.

use std::path::Path;
use std::sync::OnceLock;

use cellrt_config::CellConfig;
use cellrt_runtime::host::operator::wire::{self, Reply};
use cellrt_runtime::host::program::Program;
use cellrt_runtime::setpoints::{AxisSetpoint, SetpointBlock, SetpointHeader, MAX_START_CYCLE};

/// Where fuzzed configs and programs say they come from: a directory with no files, so a
/// relative path they name (program, ESI) resolves to nothing.
const FUZZ_DIR: &str = "/nonexistent-cellrt-fuzz";

/// A cell config file's text.
pub fn cell_config(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = CellConfig::parse(&Path::new(FUZZ_DIR).join("cell.toml"), text);
    }
}

/// The cell programs are validated against: the shipped demo cell.
fn demo_cell() -> &'static CellConfig {
    static CELL: OnceLock<CellConfig> = OnceLock::new();
    CELL.get_or_init(|| {
        let text = include_str!("../../configs/demo.toml");
        CellConfig::parse(&Path::new(FUZZ_DIR).join("demo.toml"), text)
            .expect("the demo config is valid")
    })
}

/// A program file's text, validated against the demo cell.
pub fn program(data: &[u8]) {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = Program::parse(&Path::new(FUZZ_DIR).join("p.toml"), text, demo_cell());
    }
}

/// An operator message: as a request (the cell's side) and as a reply (the client's side).
pub fn operator_wire(data: &[u8]) {
    if let Ok(request) = wire::decode_request(data) {
        let _ = request.name();
        let _ = wire::encode(&request);
    }
    let _ = serde_json::from_slice::<Reply>(data);
}

/// A setpoint block from shared memory: header fields, the cell's axis count and the
/// setpoints from the input, read as the RT thread does (well-formedness, end cycle, the start
/// slip sum, a lookup of every covered cycle and axis).
pub fn setpoint_block(data: &[u8]) {
    let mut head = [0u8; 25];
    let n = data.len().min(head.len());
    head[..n].copy_from_slice(&data[..n]);
    let u32_at = |at: usize| u32::from_le_bytes(head[at..at + 4].try_into().expect("4 bytes"));
    let header = SetpointHeader {
        motion_id: u32_at(0),
        flags: u32_at(4),
        start_cycle: u64::from_le_bytes(head[8..16].try_into().expect("8 bytes")),
        cycles: u32_at(16),
        axis_count: u32_at(20),
    };
    let axes = usize::from(head[24] % 8);
    let setpoints: Vec<AxisSetpoint> = data[n..]
        .chunks_exact(24)
        .map(|c| AxisSetpoint {
            position: f64::from_le_bytes(c[0..8].try_into().expect("8 bytes")),
            velocity: f64::from_le_bytes(c[8..16].try_into().expect("8 bytes")),
            torque: f64::from_le_bytes(c[16..24].try_into().expect("8 bytes")),
        })
        .collect();
    let block = SetpointBlock {
        header: &header,
        setpoints: &setpoints,
    };
    let _ = (block.is_last(), block.is_torque());
    if !block.is_well_formed(axes) {
        return;
    }
    assert!(header.start_cycle <= MAX_START_CYCLE);
    let end = block.end_cycle();
    let _latest_start = header.start_cycle + u64::from(u32::MAX);
    for cycle in header.start_cycle.saturating_sub(1)..=end {
        for axis in 0..=axes {
            let covered = cycle >= header.start_cycle && cycle < end && axis < axes;
            assert_eq!(block.get(cycle, axis).is_some(), covered);
        }
    }
}
