//! The simulated drive's side of NodeSearch and IPAddressSet on UDP 61451 (MR-JE-C manual
//! §2.4.3, §2.5.2, §5.2.3): a NodeSearch is answered with the drive's MAC, address, subnet mask
//! and gateway; an IPAddressSet naming the drive's MAC writes [Pr. PN11]–[Pr. PN22] (taken at
//! the next power-on) and is answered; one naming another MAC is not. Both need [Pr. PN08] to
//! select Ethernet. The addresses go to the EEPROM at once (`MrJeC::commission`): the manual
//! says only that the command writes the parameters and that the power cycle after it
//! reflects them (§2.5.2, §5.2.3), which a RAM-only write would never do `[INFER]`.

use std::net::Ipv4Addr;
use std::time::Duration;

use super::{MrJeC, Transport};
use cellrt_fieldbus::mr_je_c::objects::ObjectId;
use cellrt_fieldbus::mr_je_c::parameters::{Group, Parameter};
use cellrt_fieldbus::mr_je_c::value::Value;
use cellrt_fieldbus::slmp::node_search::{
    decode_request, encode_response, IpAddressSet, NodeInfo, SearchRequest, SearchResponse,
    MAX_SEARCH_FRAME,
};

/// [Pr. PN11]–[Pr. PN14] IP address, [Pr. PN15]–[Pr. PN18] subnet mask, [Pr. PN19]–[Pr. PN22]
/// default gateway: one octet each.
const IP_FROM: u8 = 11;
const SUBNET_FROM: u8 = 15;
const GATEWAY_FROM: u8 = 19;

/// The response frame to the search-port frame `frame`, reaching the drive at `own_ip`.
pub fn answer(drive: &mut MrJeC, own_ip: Ipv4Addr, frame: &[u8], now: Duration) -> Option<Vec<u8>> {
    if !drive.serves(Transport::CcLink) {
        return None;
    }
    let (request, serial) = decode_request(frame).ok()?;
    let response = match request {
        SearchRequest::NodeSearch(master) => SearchResponse::Node(master, info(drive, own_ip)),
        SearchRequest::IpAddressSet(master, set) if set.mac == drive.params().mac => {
            set_addresses(drive, &set, now)?;
            SearchResponse::AddressSet(master.mac)
        }
        SearchRequest::IpAddressSet(..) => return None,
    };
    let mut buf = [0u8; MAX_SEARCH_FRAME];
    let n = encode_response(&response, serial, &mut buf);
    Some(buf[..n].to_vec())
}

fn info(drive: &MrJeC, own_ip: Ipv4Addr) -> NodeInfo {
    let p = drive.params();
    NodeInfo {
        mac: p.mac,
        ip: own_ip,
        subnet: drive.subnet_mask(),
        gateway: drive.default_gateway(),
        vendor_code: p.vendor_code,
        model_code: u32::from(p.model_code),
        equipment_version: 0,
        status: 0,
        port: cellrt_fieldbus::cclink_ief_basic::SEARCH_PORT,
    }
}

fn pn(number: u8) -> ObjectId {
    ObjectId::new(
        Parameter {
            group: Group::PN,
            number,
        }
        .index(),
        0,
    )
}

/// Writes the new addresses; `None` if the drive refuses one (nothing is answered then).
fn set_addresses(drive: &mut MrJeC, set: &IpAddressSet, now: Duration) -> Option<()> {
    let mut fields = vec![(IP_FROM, set.ip), (SUBNET_FROM, set.subnet)];
    fields.extend(set.gateway.map(|g| (GATEWAY_FROM, g)));
    for (first, addr) in fields {
        for (k, octet) in addr.octets().into_iter().enumerate() {
            drive
                .commission(pn(first + k as u8), &Value::U32(u32::from(octet)), now)
                .ok()?;
        }
    }
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use cellrt_fieldbus::slmp::node_search::{
        decode_response, encode_request, Mac, Master, IP_ADDRESS_SET, NODE_SEARCH,
    };

    const T: Duration = Duration::ZERO;
    const MASTER: Master = Master {
        mac: Mac([2, 0, 0, 0, 0, 1]),
        ip: Ipv4Addr::new(192, 168, 3, 100),
    };

    fn frame(r: &SearchRequest) -> Vec<u8> {
        let mut buf = [0u8; MAX_SEARCH_FRAME];
        let n = encode_request(r, [7, 0], &mut buf);
        buf[..n].to_vec()
    }

    #[test]
    fn node_search_reports_the_parameters_and_ip_address_set_writes_them() {
        let mut d = MrJeC::new(Default::default());
        let own = Ipv4Addr::new(192, 168, 3, 10);
        let reply = answer(&mut d, own, &frame(&SearchRequest::NodeSearch(MASTER)), T).unwrap();
        let SearchResponse::Node(m, n) = decode_response(&reply, [7, 0], NODE_SEARCH).unwrap()
        else {
            panic!("not a node");
        };
        assert_eq!(m, MASTER);
        // [Pr. PN15]–[Pr. PN22] initial: 255.255.255.0, 192.168.3.1 (§5.2.3).
        assert_eq!((n.ip, n.subnet), (own, Ipv4Addr::new(255, 255, 255, 0)));
        assert_eq!(n.gateway, Ipv4Addr::new(192, 168, 3, 1));
        assert_eq!((n.mac, n.port), (d.params().mac, 61451));

        let mut set = IpAddressSet {
            mac: Mac([2, 0, 0, 0, 0, 9]),
            ip: Ipv4Addr::new(10, 1, 2, 3),
            subnet: Ipv4Addr::new(255, 255, 0, 0),
            gateway: None,
        };
        // Another drive's MAC: silent, nothing written.
        assert_eq!(
            answer(
                &mut d,
                own,
                &frame(&SearchRequest::IpAddressSet(MASTER, set)),
                T
            ),
            None
        );
        assert_eq!(d.subnet_mask(), Ipv4Addr::new(255, 255, 255, 0));
        set.mac = d.params().mac;
        let reply = answer(
            &mut d,
            own,
            &frame(&SearchRequest::IpAddressSet(MASTER, set)),
            T,
        );
        assert_eq!(
            decode_response(&reply.unwrap(), [7, 0], IP_ADDRESS_SET).unwrap(),
            SearchResponse::AddressSet(MASTER.mac)
        );
        assert_eq!(d.subnet_mask(), Ipv4Addr::new(255, 255, 0, 0));
        assert_eq!(
            d.default_gateway(),
            Ipv4Addr::new(192, 168, 3, 1),
            "gateway not set"
        );
        assert_eq!(d.read(pn(14)).unwrap().as_i64(), Some(3));
        // In the EEPROM without 1010h: the next power-on takes them (§2.5.2).
        d.power_cycle();
        assert_eq!(d.subnet_mask(), Ipv4Addr::new(255, 255, 0, 0));
        assert_eq!(d.read(pn(14)).unwrap().as_i64(), Some(3));
    }

    #[test]
    fn an_rs485_drive_does_not_answer() {
        let mut d = MrJeC::new(Default::default());
        d.write(pn(8), &Value::U32(0x1000), T).unwrap();
        let f = frame(&SearchRequest::NodeSearch(MASTER));
        assert_eq!(answer(&mut d, Ipv4Addr::LOCALHOST, &f, T), None);
    }
}
