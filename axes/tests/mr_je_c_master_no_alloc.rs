//! The CC-Link IE Field Basic cyclic master allocates nothing per exchange (issue 18: the
//! cyclic client never allocates per cycle), counted on its own thread against the emulator on
//! loopback.

use std::net::{IpAddr, Ipv4Addr};
use std::time::Duration;

use cellrt_axes::cclink_ief_basic::master::{CyclicMaster, MasterParams};
use cellrt_axes::cclink_ief_basic::{bit, set_bit, READY_BIT};
use cellrt_axes::mr_je_c::emulator::server::{Ports, Server};
use cellrt_axes::mr_je_c::emulator::{MrJeC, MrJeCParams};
use cellrt_test_support::counting_alloc::{thread_heap_calls, CountingAllocator};

#[global_allocator]
static GLOBAL: CountingAllocator = CountingAllocator;

#[test]
fn cyclic_exchanges_are_allocation_free() {
    let ip = IpAddr::V4(Ipv4Addr::LOCALHOST);
    let any = Ports {
        modbus_tcp: 0,
        slmp_udp: 0,
        slmp_tcp: 0,
        cclink: 0,
    };
    let s = Server::start(MrJeC::new(MrJeCParams::default()), ip, any).unwrap();
    let p = MasterParams {
        response_timeout: Duration::from_secs(2),
        ..Default::default()
    };
    let mut m = CyclicMaster::new((ip, 0).into(), s.cclink, p).unwrap();
    let (mut rww, mut ry) = ([0u8; 64], [0u8; 8]);
    m.exchange(false, &rww, &ry).unwrap();
    set_bit(&mut ry, READY_BIT, true);
    rww[0] = 1;
    rww[2] = 6;
    m.exchange(true, &rww, &ry).unwrap();
    let before = thread_heap_calls();
    let mut ready = 0;
    for k in 0..200u16 {
        rww[4] = k as u8;
        let r = m.exchange(true, &rww, &ry).unwrap();
        ready += usize::from(bit(&r.station.bits, READY_BIT));
    }
    assert_eq!(
        thread_heap_calls() - before,
        0,
        "heap calls in 200 exchanges"
    );
    assert_eq!(ready, 200);
}
