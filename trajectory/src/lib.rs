//! Units, scaling and jerk-limited multi-axis planning.
