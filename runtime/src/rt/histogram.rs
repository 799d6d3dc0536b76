//! Preallocated nanosecond histograms for wakeup latency and loop time (HdrHistogram: recording
//! never allocates, 3 significant digits).

use hdrhistogram::Histogram;
use serde::Serialize;

/// Highest value tracked exactly, ns (60 s); larger values saturate to it.
const HIGHEST_NS: u64 = 60_000_000_000;

/// A fixed-size histogram of durations in nanoseconds.
#[derive(Debug, Clone)]
pub struct NsHistogram {
    inner: Histogram<u64>,
}

/// Percentiles of a histogram, in microseconds.
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct Percentiles {
    /// Number of samples.
    pub count: u64,
    /// Smallest sample, µs.
    pub min_us: f64,
    /// Median, µs.
    pub p50_us: f64,
    /// 99th percentile, µs.
    pub p99_us: f64,
    /// 99.9th percentile, µs.
    pub p999_us: f64,
    /// Largest sample, µs.
    pub max_us: f64,
    /// Mean, µs.
    pub mean_us: f64,
}

impl Default for NsHistogram {
    fn default() -> Self {
        Self::new()
    }
}

impl NsHistogram {
    /// Allocates the whole histogram up front.
    pub fn new() -> Self {
        let mut inner = Histogram::new_with_bounds(1, HIGHEST_NS, 3)
            .expect("static histogram bounds are valid");
        inner.auto(false);
        NsHistogram { inner }
    }

    /// Records one duration; allocation-free.
    pub fn record(&mut self, ns: u64) {
        self.inner.saturating_record(ns.max(1));
    }

    /// Number of samples.
    pub fn len(&self) -> u64 {
        self.inner.len()
    }

    /// Whether no sample was recorded.
    pub fn is_empty(&self) -> bool {
        self.inner.is_empty()
    }

    /// Value at quantile `q` (0..=1), ns.
    pub fn quantile_ns(&self, q: f64) -> u64 {
        self.inner.value_at_quantile(q)
    }

    /// Min/p50/p99/p99.9/max/mean in µs.
    pub fn percentiles(&self) -> Percentiles {
        if self.inner.is_empty() {
            return Percentiles::default();
        }
        let us = |ns: u64| ns as f64 / 1e3;
        Percentiles {
            count: self.inner.len(),
            min_us: us(self.inner.min()),
            p50_us: us(self.inner.value_at_quantile(0.5)),
            p99_us: us(self.inner.value_at_quantile(0.99)),
            p999_us: us(self.inner.value_at_quantile(0.999)),
            max_us: us(self.inner.max()),
            mean_us: self.inner.mean() / 1e3,
        }
    }

    /// Adds the samples of `other` (merging the runs of a benchmark; allocation-free, both
    /// have the same bounds).
    pub fn merge(&mut self, other: &NsHistogram) {
        // Same bounds and precision on both sides: `add` cannot fail.
        let _ = self.inner.add(&other.inner);
    }

    /// Non-empty buckets as (upper bound ns, count), for plots and exports.
    pub fn buckets(&self) -> Vec<(u64, u64)> {
        self.inner
            .iter_recorded()
            .map(|v| (v.value_iterated_to(), v.count_at_value()))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_of_a_known_distribution() {
        let mut h = NsHistogram::new();
        for v in 1..=1000u64 {
            h.record(v * 1000);
        }
        let p = h.percentiles();
        assert_eq!(p.count, 1000);
        assert!((p.p50_us - 500.0).abs() <= 1.0, "{p:?}");
        assert!((p.p99_us - 990.0).abs() <= 1.0, "{p:?}");
        assert!((p.max_us - 1000.0).abs() <= 1.0, "{p:?}");
    }

    #[test]
    fn huge_values_saturate_instead_of_failing() {
        let mut h = NsHistogram::new();
        h.record(u64::MAX);
        assert_eq!(h.len(), 1);
        assert!(h.percentiles().max_us >= 59e6);
    }
}
