//! MR-JET-G-N1 and MR-J5-G-N1 parameters. Both communication manuals place the servo
//! parameters in the 2000h–25FFh area and leave their objects, initial values and ranges to
//! their separate object-dictionary manuals (MR-JET-G-N1 and MR-J5-G-N1 manuals §3.1), which
//! cellrt does not have. The parameters whose object, initial value and range
//! these manuals do give are the torque limit 2 parameters carried by 2D6Dh (§9.1 of both,
//! with rotation direction selection POL disabled). Store 1010h:01 is §3.2 of both; neither
//! manual has an alarm history object.

use super::{par, ParameterFacts, SaveFacts, SaveReadback, Setting};
use crate::profiles::facts::DataType::*;
use crate::profiles::facts::Unit;

/// MR-JET-G-N1 / MR-J5-G-N1 manual §9.1, one row per parameter. 2D6Dh:02/:03 print no type;
/// U16 is taken from the range (0–10000).
#[rustfmt::skip]
pub const TABLE: &[super::Parameter] = &[
    par("PC42", "", "Positive/Negative torque limit 2 select", (0x2D6D, 1), U16).default(0).hex().setting(Setting::Ranges(&[(0, 1)])).not_while_enabled().cite("§9.1: 2D6Dh:01, saved"),
    par("PC43", "", "Forward rotation torque limit 2", (0x2D6D, 2), U16).default(10_000).unit(Unit::TenthPercentRated).setting(Setting::Ranges(&[(0, 10_000)])).not_while_enabled().cite("§9.1: 2D6Dh:02 Positive torque limit value 2 (POL disabled)"),
    par("PC44", "", "Reverse rotation torque limit 2", (0x2D6D, 3), U16).default(10_000).unit(Unit::TenthPercentRated).setting(Setting::Ranges(&[(0, 10_000)])).not_while_enabled().cite("§9.1: 2D6Dh:03 Negative torque limit value 2 (POL disabled)"),
];

/// What the MR-JET-G-N1 and MR-J5-G-N1 manuals state about parameters.
pub const FACTS: ParameterFacts = ParameterFacts {
    table: TABLE,
    table_source: "MR-JET-G-N1 / MR-J5-G-N1 manuals §9.1 (the other parameters' objects are in \
                   the object-dictionary manuals, not in the communication manuals)",
    objects: &[],
    save: Ok(SaveFacts {
        object: (0x1010, 1),
        signature: super::SAVE_SIGNATURE,
        readback: SaveReadback::IdleBit,
        groups: &[],
        source: "MR-JET-G-N1 / MR-J5-G-N1 manuals §3.2",
    }),
    alarm_history: Err(
        "the MR-JET-G-N1 and MR-J5-G-N1 communication manuals give no alarm history object \
         (only the current alarm, 603Fh)",
    ),
    write_inhibit: None,
};
