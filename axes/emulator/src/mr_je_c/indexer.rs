//! Indexer mode (idx, 6060h = −103, SW A4+; MR-JE-C manual §7.3 2D60h–2D6Ah, 607Bh, 6092h,
//! §7.5.8 C_RT, §7.6.3): one motor revolution holds [Pr. PT28] stations and the position unit
//! is the station (6092h:1 = PT28, 607Bh = 0 … PT28 − 1). A rising edge of Controlword bit 4
//! turns to the station Target point table 2D60h names at 6081h (limited by 607Fh), with
//! 6083h/6084h, or [Pr. PC30]/[Pr. PC31] while C_RT or C_RTCDP (2D08h bits 1, 2) is on. The
//! Halt bit is disabled (§7.6.3); 2D69h holds the previous station until completion and 2D6Ah
//! reads 00h. The motor's route to the station is in the Positioning Mode manual, which the
//! emulator does not have: see [`shortest_route`].

use super::point_table::Positioning;
use super::profile::Profile;

/// Control DI 8 (2D08h) bit 1 C_RT, second acceleration/deceleration (§7.5.8).
pub const C_RT: i64 = 1 << 1;
/// Control DI 8 (2D08h) bit 2 C_RTCDP, second acceleration/deceleration and gains (§7.5.8).
pub const C_RTCDP: i64 = 1 << 2;

/// [Pr. PT28] stations per revolution used while PT28 reads outside 2–255: the network
/// manual gives no initial value for PT28 (its [Pr. PT__] list is in the Positioning Mode
/// manual), so this is an emulator choice.
pub const DEFAULT_STATIONS: i64 = 8;

/// The stations per revolution [Pr. PT28] `pt28` gives (2–255; [Pr. PT58] is not emulated).
pub fn stations(pt28: i64) -> i64 {
    if (2..=255).contains(&pt28) {
        pt28
    } else {
        DEFAULT_STATIONS
    }
}

/// The station target from `position` (stations, unbounded): the shorter way round, the
/// address-increasing way when both are equal. The manual does not give the route (the SIG
/// input "indexer rotation direction decision" is described in the Positioning Mode manual):
/// an emulator choice.
pub fn shortest_route(position: f64, station: i64, stations: i64) -> i64 {
    let n = stations as f64;
    let base = (position / n).floor() * n + station as f64;
    let best = [base - n, base, base + n]
        .into_iter()
        .map(|c| (c, (c - position).abs()))
        .fold((base, f64::INFINITY), |(bc, bd), (c, d)| {
            if d < bd - 1e-9 || ((d - bd).abs() <= 1e-9 && c > bc) {
                (c, d)
            } else {
                (bc, bd)
            }
        });
    best.0 as i64
}

/// The positioning a bit 4 edge starts from `position`: to station 2D60h (`None` outside
/// 0 … PT28 − 1).
pub fn positioning(p: &Profile, position: f64) -> Option<Positioning> {
    let (n, station) = (p.units_per_rev, p.indexer_station);
    (0..n).contains(&station).then(|| Positioning {
        number: station,
        target: shortest_route(position, station, n),
        speed: p.profile_velocity,
        ramp: p.indexer_ramp,
        m_code: 0,
    })
}
