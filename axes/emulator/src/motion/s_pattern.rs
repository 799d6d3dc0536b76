//! S-pattern acceleration/deceleration (MR-JE-C manual §1 function list "S-pattern
//! acceleration/deceleration time constant", §5.1.1 [Pr. PC03] STC, initial 0 ms; §7.3 6086h
//! Motion profile type = −1 "S-pattern", fixed). The manual says only that [Pr. PC03] smooths
//! the acceleration and deceleration and that "the acceleration/deceleration time will be
//! longer for the S-pattern acceleration/deceleration time constants regardless of command
//! speed"; §6.1's stroke-end table lets a stop "continue for the delay of the S-pattern
//! acceleration/deceleration time constants". The emulator models it, as Mitsubishi drives
//! implement it, as a moving average (FIR filter) of length PC03 over the trapezoid's
//! commanded velocity: the filtered position is the mean of the trapezoid's position over the
//! last PC03 ms, so a move takes PC03 longer, its acceleration is a ramp (bounded jerk) and it
//! ends exactly where the trapezoid ended.
//!
//! The trapezoid's position is sampled every [`SAMPLE`] of motion time into a ring buffer
//! sized once for [`MAX_MS`] (no allocation per step); between samples it is taken as linear.

use std::time::Duration;

/// The filter's sample period: one sample of the trapezoid per ms, the unit of [Pr. PC03].
pub const SAMPLE: Duration = Duration::from_millis(1);

/// The largest [Pr. PC03], ms: the top of the parameter's setting range (a larger write is
/// refused).
pub const MAX_MS: i64 = cellrt_fieldbus::mr_je_c::parameters::PC03_MAX_MS;

/// The moving average over the trapezoid's position.
#[derive(Debug, Clone)]
pub struct SPattern {
    /// The samples s_0 (newest) … s_n, at `ring[(head + n + 1 − k) % (n + 1)]`; sized for
    /// [`MAX_MS`].
    ring: Vec<f64>,
    /// The filter length in samples (0: no filter).
    n: usize,
    /// Where s_0 is.
    head: usize,
    /// s_0 + … + s_(n−1), recomputed at every wrap of the ring.
    sum: f64,
    /// How many samples in a row equal the one before.
    still: usize,
    /// Motion time since s_0 was taken.
    since: Duration,
}

impl Default for SPattern {
    fn default() -> Self {
        SPattern {
            ring: vec![0.0; MAX_MS as usize + 1],
            n: 0,
            head: 0,
            sum: 0.0,
            still: 0,
            since: Duration::ZERO,
        }
    }
}

impl SPattern {
    /// The filter length, ms (samples).
    pub fn len(&self) -> usize {
        self.n
    }

    /// Starts over with `ms` (limited to 0 … [`MAX_MS`]) with the trapezoid standing at `x`.
    pub fn reset(&mut self, ms: i64, x: f64) {
        self.n = ms.clamp(0, MAX_MS) as usize;
        self.ring[..=self.n].fill(x);
        self.head = 0;
        self.sum = self.n as f64 * x;
        self.still = self.n;
        self.since = Duration::ZERO;
    }

    /// s_k, 0 ≤ k ≤ n.
    fn sample(&self, k: usize) -> f64 {
        let cap = self.n + 1;
        self.ring[(self.head + cap - k % cap) % cap]
    }

    /// Motion time since the last sample.
    pub fn since(&self) -> Duration {
        self.since
    }

    /// `h` of motion time passed with the trapezoid now at `x`: a sample is taken on every
    /// [`SAMPLE`].
    pub fn elapse(&mut self, h: Duration, x: f64) {
        self.since += h;
        if self.n == 0 || self.since < SAMPLE {
            return;
        }
        self.since = Duration::ZERO;
        let (newest, dropped) = (self.sample(0), self.sample(self.n - 1));
        let cap = self.n + 1;
        self.head = (self.head + 1) % cap;
        self.ring[self.head] = x;
        self.still = if x == newest {
            self.still.saturating_add(1)
        } else {
            0
        };
        self.sum = if self.head == 0 {
            (0..self.n).map(|k| self.sample(k)).sum()
        } else {
            self.sum + x - dropped
        };
    }

    /// The trapezoid has stood at `x` for the whole window: the output is `x`.
    pub fn drained(&self, x: f64) -> bool {
        self.n == 0 || (self.still >= self.n && x == self.sample(0))
    }

    /// The time into the oldest interval: `since` as a fraction of [`SAMPLE`].
    fn phase(&self) -> f64 {
        (self.since.as_secs_f64() / SAMPLE.as_secs_f64()).clamp(0.0, 1.0)
    }

    /// The trapezoid's position one window ago (linear between samples).
    fn window_start(&self) -> f64 {
        let (last, before) = (self.sample(self.n), self.sample(self.n - 1));
        last + (before - last) * self.phase()
    }

    /// The filtered position with the trapezoid now at `x`: its mean over the last n ms.
    pub fn output(&self, x: f64) -> f64 {
        if self.drained(x) {
            return if self.n == 0 { x } else { self.sample(0) };
        }
        let (s0, tau) = (self.sample(0), self.phase());
        // Areas in units of SAMPLE × position: the part since s_0, the full intervals
        // between s_(n−1) and s_0, and the part of the oldest interval still in the window.
        let recent = (s0 + x) / 2.0 * tau;
        let full = self.sum - s0 / 2.0 - self.sample(self.n - 1) / 2.0;
        let oldest = (self.window_start() + self.sample(self.n - 1)) / 2.0 * (1.0 - tau);
        (recent + full + oldest) / self.n as f64
    }

    /// The filtered speed, pos units/s, with the trapezoid now at `x` running at `v`: the
    /// distance it covered over the last n ms divided by n ms.
    pub fn velocity(&self, x: f64, v: f64) -> f64 {
        if self.n == 0 {
            return v;
        }
        if self.drained(x) {
            return 0.0;
        }
        (x - self.window_start()) / (self.n as f64 * SAMPLE.as_secs_f64())
    }

    /// Every sample moved by `d` (the indexer's position back into one revolution).
    pub fn shift(&mut self, d: f64) {
        self.map(|s| s + d);
    }

    /// Every sample scaled by `k` (a new position unit).
    pub fn scale(&mut self, k: f64) {
        self.map(|s| s * k);
    }

    fn map(&mut self, f: impl Fn(f64) -> f64) {
        for s in &mut self.ring[..=self.n] {
            *s = f(*s);
        }
        self.sum = (0..self.n).map(|k| self.sample(k)).sum();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_becomes_a_ramp_over_the_window() {
        let mut f = SPattern::default();
        f.reset(4, 0.0);
        assert_eq!(f.output(0.0), 0.0);
        // The trapezoid ramps to 8 in the first ms (area 4) and stays: the mean over 4 ms
        // climbs by 2 per ms after the first.
        let mut out = vec![];
        for _ in 0..6 {
            f.elapse(SAMPLE, 8.0);
            out.push(f.output(8.0));
        }
        assert_eq!(out, [1.0, 3.0, 5.0, 7.0, 8.0, 8.0]);
        assert!(f.drained(8.0));
        // Half way into the next ms of a move at 4 per ms: linear in between.
        f.elapse(SAMPLE / 2, 10.0);
        assert!(!f.drained(10.0));
        // (8 + 10) / 2 × 0.5 + 3 × 8 + 8 × 0.5 = 32.5 over 4 ms.
        assert_eq!(f.output(10.0), 8.125);
        assert_eq!(f.velocity(10.0, 4000.0), 2.0 / 0.004);
    }
}
