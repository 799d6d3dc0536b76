//! The MR-JE-C's IP filter ([Pr. PN24]–[Pr. PN30]) and operation specification IP address
//! ([Pr. PN31]–[Pr. PN36]) (MR-JE-C manual §5.2.3): in the emulator after a power cycle (and
//! gone after a 1011h restore, §7.4.5), and on loopback, where clients send from 127.0.0.1 and
//! 127.0.0.2 (no namespace needed).

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::time::Duration;

use cellrt_emulator::mr_je_c::server::{Ports, Server};
use cellrt_emulator::mr_je_c::{MrJeC, MrJeCParams};
use cellrt_fieldbus::cclink_ief_basic::master::{CyclicMaster, MasterParams};
use cellrt_fieldbus::cclink_ief_basic::{bit, set_bit, READY_BIT};
use cellrt_fieldbus::mr_je_c::access::typed::{ModesOfOperation, Statusword, TargetPosition};
use cellrt_fieldbus::mr_je_c::{AccessError, ObjectAccess, ObjectId, Value};
use cellrt_fieldbus::slmp::client::{FrameType, SlmpClient};

/// Sets [Pr. PN`first`] on with `values` as commissioning does (into the EEPROM at once, so
/// the next power-on takes them).
fn set(d: &mut MrJeC, first: u8, values: &[u32]) {
    for (k, v) in values.iter().enumerate() {
        let id = ObjectId::new(0x2580 + u16::from(first) + k as u16, 0);
        d.commission(id, &Value::U32(*v), Duration::ZERO).unwrap();
    }
}

fn ip(s: &str) -> Ipv4Addr {
    s.parse().unwrap()
}

#[test]
fn the_rules_take_effect_at_power_on() {
    let mut d = MrJeC::new(MrJeCParams::default());
    assert!(d.address_rules().admits(ip("10.1.2.3")));
    // Filter 192.168.3.0 with the 4th octet up to 20; 2nd and 3rd exact (range 256).
    set(&mut d, 24, &[192, 168, 3, 0]);
    set(&mut d, 30, &[20]);
    assert!(
        d.address_rules().admits(ip("10.1.2.3")),
        "not before a power cycle"
    );
    d.power_cycle();
    let rules = d.address_rules();
    assert!(rules.admits(ip("192.168.3.0")) && rules.admits(ip("192.168.3.20")));
    assert!(!rules.admits(ip("192.168.3.21")));
    assert!(!rules.admits(ip("192.168.4.5")));
    assert!(!rules.admits(ip("193.168.3.5")));
    // No operation rule: everyone admitted may operate.
    assert!(rules.may_operate(ip("10.1.2.3")));
    // Operation 192.168.3.250 with the 3rd octet 3–4.
    set(&mut d, 31, &[192, 168, 3, 250]);
    set(&mut d, 35, &[4]);
    d.power_cycle();
    let rules = d.address_rules();
    assert!(rules.may_operate(ip("192.168.3.250")) && rules.may_operate(ip("192.168.4.250")));
    assert!(!rules.may_operate(ip("192.168.5.250")) && !rules.may_operate(ip("192.168.3.251")));
    // The parameters survived the power cycle; the state did not.
    assert_eq!(d.read(ObjectId::new(0x2598, 0)).unwrap(), Value::U32(192));
    // 1011h:4 = "load", then a power cycle: the parameters' factory values, the rules off.
    let load = Value::U32(0x6461_6F6C);
    d.write(ObjectId::new(0x1011, 4), &load, Duration::ZERO)
        .unwrap();
    assert_eq!(d.read(ObjectId::new(0x1011, 4)).unwrap(), Value::U32(1));
    d.power_cycle();
    assert_eq!(d.read(ObjectId::new(0x2598, 0)).unwrap(), Value::U32(0));
    assert_eq!(d.read(ObjectId::new(0x2582, 0)).unwrap(), Value::U32(1000));
    assert!(d.address_rules().admits(ip("10.1.2.3")));
}

const LOCAL: Ipv4Addr = Ipv4Addr::LOCALHOST;
const OTHER: Ipv4Addr = Ipv4Addr::new(127, 0, 0, 2);
const SHORT: Duration = Duration::from_millis(300);

fn server() -> Server {
    let any = Ports::ANY;
    Server::start(MrJeC::new(MrJeCParams::default()), IpAddr::V4(LOCAL), any).unwrap()
}

fn slmp_from(from: Ipv4Addr, s: &Server) -> SlmpClient {
    SlmpClient::udp_from(
        SocketAddr::new(from.into(), 0),
        s.slmp_udp,
        FrameType::E4,
        SHORT,
    )
    .unwrap()
}

#[test]
fn the_operation_list_discards_writes_from_others() {
    let s = server();
    {
        let mut d = s.drive();
        set(&mut d, 31, &[127, 0, 0, 1]);
        d.power_cycle();
    }
    let mut other = slmp_from(OTHER, &s);
    // Reads stay open; a write is discarded without an answer.
    assert_eq!(other.read::<Statusword>().unwrap().0 & 0x4F, 0x40);
    assert!(matches!(
        other.write::<TargetPosition>(5),
        Err(AccessError::Timeout(_))
    ));
    assert_eq!(
        s.drive().read(ObjectId::new(0x607A, 0)).unwrap(),
        Value::I32(0)
    );
    let mut local = slmp_from(LOCAL, &s);
    local.write::<TargetPosition>(7).unwrap();
    assert_eq!(local.read::<TargetPosition>().unwrap(), 7);
    // The cyclic link from 127.0.0.2: CSR/SSR work, RWw is not imported.
    let p = MasterParams {
        response_timeout: Duration::from_secs(2),
        ..Default::default()
    };
    let mut m = CyclicMaster::new(SocketAddr::new(OTHER.into(), 0), s.cclink, p).unwrap();
    let (mut rww, mut ry) = ([0u8; 64], [0u8; 8]);
    rww[0] = 3;
    set_bit(&mut ry, READY_BIT, true);
    m.exchange(false, &rww, &ry).unwrap();
    let r = m.exchange(true, &rww, &ry).unwrap();
    assert!(bit(&r.station.bits, READY_BIT));
    assert_eq!(local.read::<ModesOfOperation>().unwrap(), 0);
}

#[test]
fn the_ip_filter_drops_other_hosts() {
    let s = server();
    {
        let mut d = s.drive();
        set(&mut d, 24, &[127, 0, 0, 1]);
        d.power_cycle();
    }
    let mut other = slmp_from(OTHER, &s);
    assert!(matches!(
        other.read::<Statusword>(),
        Err(AccessError::Timeout(_))
    ));
    let mut local = slmp_from(LOCAL, &s);
    assert_eq!(local.read::<Statusword>().unwrap().0 & 0x4F, 0x40);
    let p = MasterParams {
        response_timeout: SHORT,
        ..Default::default()
    };
    let mut m = CyclicMaster::new(SocketAddr::new(OTHER.into(), 0), s.cclink, p).unwrap();
    assert!(m.exchange(false, &[0; 64], &[0; 8]).is_err());
}
