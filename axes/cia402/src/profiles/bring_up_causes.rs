//! Likely causes of a refused AL state change, per model, as its manual states them: what
//! bring-up names beside the AL status code when a SubDevice will not go on.

use super::DriveModel;
use crate::mode::ModeOfOperation;

/// One likely cause of a refused state change, with where it is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BringUpCause {
    /// It fits a refusal with one of these AL status codes (empty: any code).
    pub al_codes: &'static [u16],
    /// It fits only where an axis of the SubDevice runs one of these modes (empty: any).
    pub modes: &'static [ModeOfOperation],
    /// It fits only where the SubDevice runs without SYNC0 (`distributed_clocks = false`).
    pub free_run_only: bool,
    /// The cause and what to do about it.
    pub cause: &'static str,
    /// The manual and section (or standard) that says so.
    pub source: &'static str,
}

/// The likely causes of a refused state change on `model` (empty where its manual names none).
pub fn bring_up_causes(model: DriveModel) -> &'static [BringUpCause] {
    match model {
        DriveModel::MrJ4TM => super::mr_j4_tm::BRING_UP_CAUSES,
        DriveModel::GenericCia402 => super::generic_cia402::BRING_UP_CAUSES,
        DriveModel::MrJ5GN1
        | DriveModel::MrJ5W2GN1
        | DriveModel::MrJ5W3GN1
        | DriveModel::MrJ3T04
        | DriveModel::MrJetGN1 => &[],
    }
}
