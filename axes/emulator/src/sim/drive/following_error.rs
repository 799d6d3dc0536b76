//! Statusword bit 13 "Following error" in the position modes: 1 once the droop 60F4h has stayed
//! at or above the following error window 6065h for the following error time out 6066h
//! (MR-J3-T04 manual §8.5.2, MR-J4-TM manual §5.4.4 and §5.4.6). The manuals give neither
//! default: the window and time out are named parameters, overridden by an SDO write to 6065h /
//! 6066h where the model has the objects.

use super::SimDrive;
use cellrt_cia402::fsa::FsaState;
use cellrt_cia402::mode::ModeOfOperation;

/// 6065h Following error window.
const FOLLOWING_ERROR_WINDOW: u16 = 0x6065;
/// 6066h Following error time out, ms.
const FOLLOWING_ERROR_TIME_OUT: u16 = 0x6066;

impl SimDrive {
    /// Accumulates how long the droop has been at or above the window (reset when it is not,
    /// outside the position modes and at servo-off).
    pub(super) fn watch_following_error(&mut self, dt: f64) {
        let position_mode = matches!(
            self.mode_display,
            ModeOfOperation::CyclicSyncPosition | ModeOfOperation::ProfilePosition
        );
        let window = self
            .sdo_value(FOLLOWING_ERROR_WINDOW, 0)
            .map_or(self.params.following_error_window, |v| v as u32);
        if self.state == FsaState::OperationEnabled
            && position_mode
            && self.following_error.unsigned_abs() >= window
        {
            self.following_error_over += dt;
        } else {
            self.following_error_over = 0.0;
        }
    }

    /// Statusword bit 13 in csp / pp.
    pub(super) fn following_error_bit(&self) -> bool {
        let time_out_ms = self
            .sdo_value(FOLLOWING_ERROR_TIME_OUT, 0)
            .map_or(self.params.following_error_time_out_ms, |v| v as u16);
        self.following_error_over > 0.0
            && self.following_error_over * 1e3 >= f64::from(time_out_ms) - 1e-9
    }
}
