//! Benchmark harness and end-to-end scenarios.
