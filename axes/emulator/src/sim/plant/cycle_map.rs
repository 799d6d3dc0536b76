//! The servo-on substep recurrence of [`super::ServoPlant::step`] over one whole cycle,
//! composed into one linear map so a cycle costs a few dot products instead of a loop.
//!
//! While no saturation engages (velocity command, acceleration and velocity all inside their
//! limits at every substep) the recurrence is linear in the cycle's inputs
//! `z = [v0, start − p0, command − p0, feed-forward]`, so every intermediate quantity is a
//! precomputed row times `z`. The rows are checked first; if any substep would saturate, the
//! caller runs the substep loop instead, so the result is the same model either way.

use std::sync::Arc;

/// Longest cycle (in substeps) the map is built for; longer steps always take the loop.
pub const MAX_MAPPED_SUBSTEPS: usize = 128;

/// Number of components of the input vector `z`.
const Z: usize = 4;

/// Coefficient rows for one cycle of `n` substeps of length `h`, structure-of-arrays so the
/// per-substep checks vectorise.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleMap {
    /// The time step the map was built for (s).
    pub dt_s: f64,
    n: usize,
    /// `Z` columns of `n` rows each: velocity command at every substep.
    v_cmd: Box<[f64]>,
    /// Acceleration at every substep.
    accel: Box<[f64]>,
    /// Velocity after every substep.
    vel: Box<[f64]>,
    /// End of cycle: position change, velocity, last acceleration.
    end: [[f64; Z]; 3],
}

/// The distinct cycle maps of one bus' plants. Plants of identical axes then read one table,
/// which stays in the cache (64 private copies of a few kilobytes each do not). Owned by the
/// bus that runs the plants, never process-wide; filled at start-up (allocates).
#[derive(Debug, Default)]
pub struct CycleMapPool(Vec<Arc<CycleMap>>);

impl CycleMapPool {
    /// Points `map` at an equal map already in the pool, or adds it.
    pub fn share(&mut self, map: &mut Arc<CycleMap>) {
        match self.0.iter().find(|m| ***m == **map) {
            Some(m) => *map = Arc::clone(m),
            None => self.0.push(Arc::clone(map)),
        }
    }

    /// How many distinct maps the pool holds.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether the pool holds no map.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

/// The plant state at the end of a mapped cycle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MappedStep {
    /// Position change over the cycle (counts).
    pub delta_position: f64,
    /// Velocity at the end of the cycle (counts/s).
    pub velocity: f64,
    /// Acceleration of the last substep (counts/s²).
    pub acceleration: f64,
}

/// Saturation limits the mapped cycle must stay strictly inside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// |velocity command| and |velocity| bound (counts/s).
    pub vmax: f64,
    /// Largest positive acceleration (counts/s²).
    pub accel_hi: f64,
    /// Most negative acceleration (counts/s², ≤ 0).
    pub accel_lo: f64,
}

impl CycleMap {
    /// Composes `n` substeps of length `h` with position gain `kp` and velocity gain `g`
    /// (already the capped `kv·h / h`). `None` when `n` is 0 or above [`MAX_MAPPED_SUBSTEPS`].
    pub fn build(dt_s: f64, n: u32, h: f64, kp: f64, g: f64) -> Option<Self> {
        let n = n as usize;
        if n == 0 || n > MAX_MAPPED_SUBSTEPS || h.is_nan() || h <= 0.0 {
            return None;
        }
        let mut v_cmd = vec![0.0; Z * n].into_boxed_slice();
        let mut accel = vec![0.0; Z * n].into_boxed_slice();
        let mut vel = vec![0.0; Z * n].into_boxed_slice();
        // Coefficients of q = p − p0 and v in terms of z.
        let mut q = [0.0; Z];
        let mut v = [1.0, 0.0, 0.0, 0.0];
        let mut a = [0.0; Z];
        for i in 0..n {
            let frac = (i + 1) as f64 / n as f64;
            // command_i − p0 = (start − p0)·(1 − frac) + (command − p0)·frac
            let cmd = [0.0, 1.0 - frac, frac, 0.0];
            for k in 0..Z {
                let ff = if k == 3 { 1.0 } else { 0.0 };
                let vc = ff + kp * (cmd[k] - q[k]);
                a[k] = g * (vc - v[k]);
                v[k] += a[k] * h;
                q[k] += v[k] * h;
                v_cmd[k * n + i] = vc;
                accel[k * n + i] = a[k];
                vel[k * n + i] = v[k];
            }
        }
        Some(CycleMap {
            dt_s,
            n,
            v_cmd,
            accel,
            vel,
            end: [q, v, a],
        })
    }

    /// The end-of-cycle state for inputs `z`, or `None` when some substep would saturate
    /// (or an input is not finite): the caller then runs the substep loop.
    #[inline]
    pub fn step(&self, z: [f64; Z], lim: Limits) -> Option<MappedStep> {
        let n = self.n;
        let mut inside = true;
        for i in 0..n {
            let row = |m: &[f64]| {
                m[i] * z[0] + m[n + i] * z[1] + m[2 * n + i] * z[2] + m[3 * n + i] * z[3]
            };
            let vc = row(&self.v_cmd);
            let a = row(&self.accel);
            let v = row(&self.vel);
            inside &= (vc.abs() < lim.vmax)
                & (a < lim.accel_hi)
                & (a > lim.accel_lo)
                & (v.abs() < lim.vmax);
        }
        if !inside {
            return None;
        }
        let dot = |r: &[f64; Z]| r[0] * z[0] + r[1] * z[1] + r[2] * z[2] + r[3] * z[3];
        Some(MappedStep {
            delta_position: dot(&self.end[0]),
            velocity: dot(&self.end[1]),
            acceleration: dot(&self.end[2]),
        })
    }
}
