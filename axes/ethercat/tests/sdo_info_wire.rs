//! The SDO Information codecs of the patched ethercrab (`ethercrab::sdo_info`, ETG.1000.6
//! §5.6.3) against hand-built mailbox messages: the requests' layout, the descriptions' fields,
//! fragments joined, an SDO Info Error Request as its abort code.

use ethercrab::error::{CoeAbortCode, Error, MailboxError, PduError};
use ethercrab::sdo_info::{
    take_fragment, EntryDescription, EntryDescriptionRequest, Fragment, ObjectAccess, ObjectCode,
    ObjectDescription, ObjectDescriptionRequest, SdoInfoOpCode, MAX_NAME_LEN,
};
use ethercrab::EtherCrabWireWriteSized;

/// A CoE SDO Information mailbox message: headers (opcode, incomplete, fragments left)
/// and `data`.
fn message(op: u8, incomplete: bool, fragments_left: u16, data: &[u8]) -> Vec<u8> {
    let len = (6 + data.len()) as u16;
    let mut m = Vec::new();
    m.extend_from_slice(&len.to_le_bytes());
    m.extend_from_slice(&[0, 0, 0, 0x03 | (1 << 4)]);
    m.extend_from_slice(&[0x00, 0x80]); // CoE service 8 in bits 12–15
    m.push(op | if incomplete { 0x80 } else { 0 });
    m.push(0);
    m.extend_from_slice(&fragments_left.to_le_bytes());
    m.extend_from_slice(data);
    // Trailing mailbox bytes past the length.
    m.extend_from_slice(&[0xAA; 4]);
    m
}

#[test]
fn an_object_description_request_packs_as_the_spec_lays_it_out() {
    let r = ObjectDescriptionRequest::new(2, 0x6041);
    assert_eq!(
        r.pack(),
        [8, 0, 0, 0, 0, 0x23, 0x00, 0x80, 0x03, 0x00, 0x00, 0x00, 0x41, 0x60]
    );
    let r = EntryDescriptionRequest::new(3, 0x1018, 4);
    assert_eq!(
        r.pack(),
        [10, 0, 0, 0, 0, 0x33, 0x00, 0x80, 0x05, 0x00, 0x00, 0x00, 0x18, 0x10, 4, 0]
    );
}

#[test]
fn an_object_description_decodes_index_type_subs_code_and_name() {
    let mut data = vec![0x18, 0x10, 0x23, 0x00, 4, 9];
    data.extend_from_slice(b"Identity object");
    let d = ObjectDescription::parse(&data).unwrap();
    assert_eq!(
        (d.index, d.data_type, d.max_sub_index, d.object_code),
        (0x1018, 0x0023, 4, ObjectCode::Record)
    );
    assert_eq!(&d.name[..], b"Identity object");
    assert_eq!(
        ObjectDescription::parse(&[0x41, 0x60, 6]),
        Err(Error::Pdu(PduError::Decode))
    );
}

#[test]
fn an_entry_description_decodes_type_length_access_and_name() {
    // 6041h:00 UNSIGNED16, 16 bits, readable in every state, TxPDO-mappable.
    let mut data = vec![0x41, 0x60, 0, 0, 0x06, 0x00, 16, 0, 0x87, 0x00];
    data.extend_from_slice(b"Statusword\0");
    let e = EntryDescription::parse(&data).unwrap();
    assert_eq!(
        (e.index, e.sub_index, e.data_type, e.bit_length),
        (0x6041, 0, 6, 16)
    );
    assert!(e.access.readable() && !e.access.writable());
    assert!(e.access.contains(ObjectAccess::TXPDO_MAPPABLE));
    assert!(!e.access.contains(ObjectAccess::RXPDO_MAPPABLE));
    assert_eq!(&e.name[..], b"Statusword");
    // Optional values were not asked for: refused rather than read as the name.
    let mut with_default = data.clone();
    with_default[3] = 0x10;
    assert_eq!(
        EntryDescription::parse(&with_default),
        Err(Error::Pdu(PduError::Decode))
    );
    // A long name is cut.
    let mut long = data[..10].to_vec();
    long.extend(std::iter::repeat_n(b'x', 300));
    assert_eq!(
        EntryDescription::parse(&long).unwrap().name.len(),
        MAX_NAME_LEN
    );
}

#[test]
fn fragments_are_joined_and_only_the_first_drops_the_list_type() {
    let mut buf = heapless::Vec::<u8, 64>::new();
    let first = message(0x02, true, 1, &[0x01, 0x00, 0x00, 0x10, 0x18, 0x10]);
    let last = message(0x02, false, 0, &[0x41, 0x60]);
    let op = SdoInfoOpCode::GetObjectDescriptionListResponse;
    assert_eq!(
        take_fragment(&first, op, 2, &mut buf, true),
        Ok(Fragment::More)
    );
    assert_eq!(
        take_fragment(&last, op, 2, &mut buf, false),
        Ok(Fragment::Last)
    );
    assert_eq!(&buf[..], &[0x00, 0x10, 0x18, 0x10, 0x41, 0x60]);
}

#[test]
fn an_sdo_info_error_is_its_abort_code_and_other_messages_are_skipped() {
    let mut buf = heapless::Vec::<u8, 64>::new();
    let op = SdoInfoOpCode::GetEntryDescriptionResponse;
    let error = message(0x07, false, 0, &0x0609_0011u32.to_le_bytes());
    assert_eq!(
        take_fragment(&error, op, 0, &mut buf, true),
        Err(Error::Mailbox(MailboxError::SdoInfoAborted {
            code: CoeAbortCode::SubIndexNotFound
        }))
    );
    let other_opcode = message(0x04, false, 0, &[1, 2, 3]);
    assert_eq!(
        take_fragment(&other_opcode, op, 0, &mut buf, true),
        Ok(Fragment::Other)
    );
    // A CoE Emergency (service 1) is not a fragment.
    let mut emergency = message(0x06, false, 0, &[0; 4]);
    emergency[7] = 0x10;
    assert_eq!(
        take_fragment(&emergency, op, 0, &mut buf, true),
        Ok(Fragment::Other)
    );
    assert!(buf.is_empty());
    // More than the buffer holds is an error, not a wait.
    let mut small = heapless::Vec::<u8, 2>::new();
    let big = message(0x06, false, 0, &[0; 3]);
    assert_eq!(
        take_fragment(&big, op, 0, &mut small, true),
        Err(Error::Pdu(PduError::TooLong))
    );
}
