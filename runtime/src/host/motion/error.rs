//! Why the motion engine refuses a request or drops its motion, in the words the operator and
//! the program's error report show.

use crate::host::link::LinkError;

/// Why the motion engine refused a request or dropped its motion.
#[derive(Debug, thiserror::Error)]
pub enum MotionError {
    /// The cell could not be reached.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The request does not fit the cell's configuration or limits (the text names the axis
    /// and the limit).
    #[error("{0}")]
    Refused(String),
    /// Another motion is active and the request needs the axes at rest.
    #[error("a {active} is active: halt it (or wait for its end) first")]
    Busy {
        /// What is active ("motion", "line move", "torque command").
        active: &'static str,
    },
    /// A line or waypoint path starts from rest only.
    #[error("a {0} starts from rest: halt the motion (or wait for its end) first")]
    NotAtRest(&'static str),
    /// The cell does not take motion in its state.
    #[error("the cell is {0}, not idle (power on first, or reset after a stop)")]
    NotIdle(&'static str),
    /// An axis of the request has MC_Power off.
    #[error("axis '{0}' is not powered (power it on first)")]
    NotPowered(String),
    /// The motion whose last block is out did not end within [`FINISH_WAIT`](super::FINISH_WAIT).
    #[error("the previous motion did not finish")]
    PreviousNotFinished,
    /// A trajectory could not be planned or sampled (`what`: "line", "path", "torque profile",
    /// "planning failed").
    #[error("{what}: {detail}")]
    Planning {
        /// Which planner.
        what: &'static str,
        /// The planner's reason.
        detail: String,
    },
    /// The setpoint service refused a block (`what`: "loan", "publish").
    #[error("setpoint {what} failed: {detail}")]
    Setpoints {
        /// The step that failed.
        what: &'static str,
        /// The iceoryx2 error.
        detail: String,
    },
    /// The RT thread stopped the motion.
    #[error("motion {id} was stopped by the RT thread ({why})")]
    StoppedByRt {
        /// Motion id.
        id: u32,
        /// The stop reason's name.
        why: &'static str,
    },
    /// The cell left the powered states during the motion.
    #[error("the cell is {state} during motion {id}")]
    LeftPower {
        /// The cell state's name.
        state: &'static str,
        /// Motion id.
        id: u32,
    },
    /// A request names an axis index the cell does not have.
    #[error("axis index {0} unknown")]
    UnknownAxis(usize),
    /// The RT thread went idle after the motion without reporting its end.
    #[error("the RT thread is idle after motion {0} without reporting its end")]
    EndNotReported(u32),
    /// The RT thread never started the motion.
    #[error(
        "the RT thread did not start motion {0} (its first block was rejected; see the events)"
    )]
    NotStarted(u32),
}

/// A refusal whose text names the axis and the limit.
pub(super) fn refused(reason: impl Into<String>) -> MotionError {
    MotionError::Refused(reason.into())
}

impl MotionError {
    pub(super) fn planning(
        what: &'static str,
    ) -> impl FnOnce(&dyn std::fmt::Display) -> MotionError {
        move |e| MotionError::Planning {
            what,
            detail: one_line(&e.to_string()),
        }
    }
}

/// The first line of a planner's message, at most [`MAX_DETAIL_CHARS`] characters: the
/// operator gets one line, not the planner's state dump.
pub(super) fn one_line(text: &str) -> String {
    let first = text.lines().next().unwrap_or("").trim();
    match first.char_indices().nth(MAX_DETAIL_CHARS) {
        Some((at, _)) => format!("{}…", &first[..at]),
        None => first.to_string(),
    }
}

/// The longest planner detail an error message carries.
const MAX_DETAIL_CHARS: usize = 160;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_planner_dump_becomes_one_line() {
        let dump = "Calculator error: error in step 1, dof: 0 input: inp.current_position = [\n 0.0,\n]\nmore";
        let e = MotionError::planning("line")(&dump);
        let text = e.to_string();
        assert!(!text.contains('\n'), "{text}");
        assert!(
            text.starts_with("line: Calculator error: error in step 1"),
            "{text}"
        );
        assert!(one_line(&"x".repeat(500)).chars().count() <= MAX_DETAIL_CHARS + 1);
    }

    #[test]
    fn refusals_keep_the_text_operators_and_tests_read() {
        let busy = MotionError::Busy {
            active: "line move",
        };
        assert_eq!(
            busy.to_string(),
            "a line move is active: halt it (or wait for its end) first"
        );
        assert_eq!(
            MotionError::NotAtRest("waypoint path").to_string(),
            "a waypoint path starts from rest: halt the motion (or wait for its end) first"
        );
        assert_eq!(
            MotionError::planning("torque profile")(&"slope 0").to_string(),
            "torque profile: slope 0"
        );
        let stopped = MotionError::StoppedByRt {
            id: 3,
            why: "underrun",
        };
        assert_eq!(
            stopped.to_string(),
            "motion 3 was stopped by the RT thread (underrun)"
        );
        let link = MotionError::from(LinkError::NoStatus("c".into()));
        assert_eq!(link.to_string(), "no status from cell 'c' yet");
    }
}
