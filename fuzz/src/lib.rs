//! Fuzz targets for cellrt's decoders and parsers: each takes arbitrary bytes and must return
//! without a panic, a hang or an unbounded allocation, whatever the bytes. `cargo fuzz` runs
//! them through `fuzz_targets/` (feature `libfuzzer`, see `tools/fuzz.sh`); `tests/corpus.rs`
//! replays the committed corpora and mutations of them on every `cargo test`.

pub mod ethercat;
pub mod fieldbus;
pub mod mutate;
pub mod recording;
pub mod runtime;
pub mod sii_link;

/// A fuzz target: a name (its `fuzz_targets/NAME.rs` and `corpus/NAME/`) and its entry point.
pub struct Target {
    /// The target's name.
    pub name: &'static str,
    /// Feeds one input to the decoder under test.
    pub run: fn(&[u8]),
}

/// Every fuzz target.
pub const TARGETS: &[Target] = &[
    Target {
        name: "ethercat_frame",
        run: ethercat::frame,
    },
    Target {
        name: "ethercat_emulator",
        run: ethercat::emulator,
    },
    Target {
        name: "coe_server",
        run: ethercat::coe_server,
    },
    Target {
        name: "mailbox_message",
        run: ethercat::mailbox_message,
    },
    Target {
        name: "sii_scan",
        run: ethercat::sii_scan,
    },
    Target {
        name: "esi_xml",
        run: ethercat::esi_xml,
    },
    Target {
        name: "modbus",
        run: fieldbus::modbus,
    },
    Target {
        name: "slmp",
        run: fieldbus::slmp,
    },
    Target {
        name: "cclink_ief_basic",
        run: fieldbus::cclink_ief_basic,
    },
    Target {
        name: "cell_config",
        run: runtime::cell_config,
    },
    Target {
        name: "program",
        run: runtime::program,
    },
    Target {
        name: "operator_wire",
        run: runtime::operator_wire,
    },
    Target {
        name: "setpoint_block",
        run: runtime::setpoint_block,
    },
    Target {
        name: "mcap_recording",
        run: recording::mcap_recording,
    },
];

/// The target named `name`.
pub fn target(name: &str) -> &'static Target {
    TARGETS
        .iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("no fuzz target {name}"))
}

/// Splits `data` into pieces at each `0xFF 0x00` separator, so one input can carry a sequence
/// of frames or requests.
pub fn pieces(data: &[u8]) -> impl Iterator<Item = &[u8]> {
    let mut rest = Some(data);
    std::iter::from_fn(move || {
        let r = rest?;
        match r.windows(2).position(|w| w == [0xFF, 0x00]) {
            Some(at) => {
                rest = Some(&r[at + 2..]);
                Some(&r[..at])
            }
            None => {
                rest = None;
                Some(r)
            }
        }
    })
}
