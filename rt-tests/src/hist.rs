//! Latency histograms with 1 µs buckets, the resolution `cyclictest -h` reports, so cellrt's and
//! cyclictest's samples go through the same percentile arithmetic before they are compared.

use std::collections::BTreeMap;

use cellrt_runtime::rt::histogram::NsHistogram;
use serde::Serialize;

/// Counts per whole microsecond (a sample of 23.9 µs is in bucket 23, as in cyclictest).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct UsHistogram {
    /// Bucket (µs, rounded down) → samples.
    pub buckets: BTreeMap<u64, u64>,
    /// Largest sample, µs (exact where the source knows it).
    pub max_us: f64,
    /// Smallest sample, µs.
    pub min_us: f64,
}

/// Percentiles in µs, computed from 1 µs buckets (each quantile is the bucket's lower bound).
#[derive(Debug, Clone, Copy, Default, Serialize, PartialEq)]
pub struct UsPercentiles {
    /// Samples.
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
}

impl UsHistogram {
    /// Adds `n` samples in bucket `us`.
    pub fn add(&mut self, us: u64, n: u64) {
        if n == 0 {
            return;
        }
        let v = us as f64;
        if self.is_empty() || v < self.min_us {
            self.min_us = v;
        }
        if v > self.max_us {
            self.max_us = v;
        }
        *self.buckets.entry(us).or_default() += n;
    }

    /// Converts a nanosecond histogram (HdrHistogram buckets are narrower than 1 µs below
    /// 2 ms, so the conversion is exact up to there); min and max stay exact.
    pub fn from_ns(h: &NsHistogram) -> UsHistogram {
        let mut out = UsHistogram::default();
        for (ns, n) in h.buckets() {
            out.add(ns / 1000, n);
        }
        if !h.is_empty() {
            let p = h.percentiles();
            out.min_us = p.min_us;
            out.max_us = p.max_us;
        }
        out
    }

    /// Samples.
    pub fn count(&self) -> u64 {
        self.buckets.values().sum()
    }

    /// Whether empty.
    pub fn is_empty(&self) -> bool {
        self.buckets.is_empty()
    }

    /// Adds every sample of `other`.
    pub fn merge(&mut self, other: &UsHistogram) {
        if other.is_empty() {
            return;
        }
        let (min, max) = (other.min_us, other.max_us);
        let was_empty = self.is_empty();
        for (&us, &n) in &other.buckets {
            *self.buckets.entry(us).or_default() += n;
        }
        self.min_us = if was_empty { min } else { self.min_us.min(min) };
        self.max_us = self.max_us.max(max);
    }

    /// Lower bound of the bucket holding the `q` quantile (nearest-rank).
    pub fn quantile(&self, q: f64) -> f64 {
        let total = self.count();
        if total == 0 {
            return 0.0;
        }
        let rank = ((q * total as f64).ceil() as u64).clamp(1, total);
        let mut seen = 0;
        for (&us, &n) in &self.buckets {
            seen += n;
            if seen >= rank {
                return us as f64;
            }
        }
        self.max_us
    }

    /// Min/p50/p99/p99.9/max.
    pub fn percentiles(&self) -> UsPercentiles {
        UsPercentiles {
            count: self.count(),
            min_us: self.min_us,
            p50_us: self.quantile(0.5),
            p99_us: self.quantile(0.99),
            p999_us: self.quantile(0.999),
            max_us: self.max_us,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_are_nearest_rank_bucket_bounds() {
        let mut h = UsHistogram::default();
        for us in 1..=100 {
            h.add(us, 1);
        }
        let p = h.percentiles();
        assert_eq!(p.count, 100);
        assert_eq!(p.p50_us, 50.0);
        assert_eq!(p.p99_us, 99.0);
        assert_eq!(p.p999_us, 100.0);
        assert_eq!((p.min_us, p.max_us), (1.0, 100.0));
    }

    #[test]
    fn from_ns_floors_to_microseconds_and_merges() {
        let mut ns = NsHistogram::new();
        ns.record(23_900);
        ns.record(24_100);
        let h = UsHistogram::from_ns(&ns);
        assert_eq!(h.buckets.get(&23), Some(&1));
        assert_eq!(h.buckets.get(&24), Some(&1));
        let mut m = UsHistogram::default();
        m.merge(&h);
        m.merge(&h);
        assert_eq!(m.count(), 4);
        assert!((m.min_us - 23.9).abs() < 0.05 && (m.max_us - 24.1).abs() < 0.05);
    }
}
