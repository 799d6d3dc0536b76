//! The checks of `sdo` before anything is sent, and how an answer is typed.

use super::*;

/// The shipped configuration `name` (configs/), parsed.
pub(in crate::host::operator) fn shipped(name: &str) -> CellConfig {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../configs")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    CellConfig::parse(&path, &text).unwrap()
}

fn refused(cell: &CellConfig, axis: &str, index: u16, sub: u8, value: Option<i64>) -> String {
    match check(cell, axis, index, sub, value) {
        Ok(c) => panic!("{} sent: {:?}", object_text(index, sub), c.request),
        Err(e) => e.to_string(),
    }
}

#[test]
fn reads_and_writes_in_the_profile_dictionary_are_sized_by_the_object_type() {
    // ethercat-cell.toml: y is an MR-J4-TM (MR-J4-TM manual §8.1: 6085h UNSIGNED32 rw).
    let cell = shipped("ethercat-cell.toml");
    let read = check(&cell, "y", 0x6041, 0, None).unwrap();
    assert_eq!(read.axis, 1);
    assert_eq!(
        read.request,
        SdoRequest::Upload {
            index: 0x6041,
            sub: 0
        }
    );
    assert_eq!(read.reply.data_type, "UNSIGNED16");
    assert_eq!(read.reply.name, "Statusword");
    let write = check(&cell, "y", 0x6085, 0, Some(250)).unwrap();
    assert_eq!(
        write.request,
        SdoRequest::Download {
            index: 0x6085,
            sub: 0,
            data: SdoData::new(&[250, 0, 0, 0]).unwrap()
        }
    );
    // 6098h INTEGER8: one byte, two's complement.
    let method = check(&cell, "y", 0x6098, 0, Some(-1)).unwrap();
    assert_eq!(
        method.request,
        SdoRequest::Download {
            index: 0x6098,
            sub: 0,
            data: SdoData::new(&[0xFF]).unwrap()
        }
    );
}

#[test]
fn what_must_not_be_sent_is_refused_with_the_reason() {
    let cell = shipped("ethercat-cell.toml");
    let e = refused(&cell, "w", 0x6041, 0, None);
    assert!(e.starts_with("sdo: ") && e.contains("'w'"), "{e}");
    assert!(e.contains("x, y, z, c"), "{e}");
    let e = refused(&cell, "y", 0x2FFF, 0, None);
    assert_eq!(
        e,
        "sdo: object 2FFFh:00 is not in the object dictionary of axis 'y' (Mitsubishi MR-J4-TM)"
    );
    let e = refused(&cell, "y", 0x607C, 0, Some(5));
    assert_eq!(e, "sdo: 607Ch:00 of axis 'y' (Home offset) is read-only");
    let e = refused(&cell, "y", 0x6040, 0, Some(6));
    assert!(e.contains("6040h:00") && e.contains("RxPDO"), "{e}");
    // x maps its own RxPDO (6040h, 2001h, 607Ah): 6060h is not in it and may be written.
    assert!(check(&cell, "x", 0x6060, 0, Some(8)).is_ok());
    let e = refused(&cell, "x", 0x607A, 0, Some(8));
    assert!(e.contains("RxPDO"), "{e}");
    // 6098h: stated range −43..37 (MR-J4-TM manual §4.10), INTEGER8.
    let e = refused(&cell, "y", 0x6098, 0, Some(38));
    assert_eq!(
        e,
        "sdo: 6098h:00 of axis 'y' (Homing method) takes -43..37 (stated range): 38 is out of it"
    );
    let e = refused(&cell, "y", 0x6085, 0, Some(-1));
    assert!(
        e.ends_with("takes UNSIGNED32: -1 is out of its range 0..4294967295"),
        "{e}"
    );
    let e = refused(&cell, "y", 0x6067, 0, Some(10));
    assert!(e.contains("no stated data type"), "{e}");
}

#[test]
fn an_esi_axis_is_checked_against_its_esi_dictionary() {
    let cell = shipped("cia402-esi.toml");
    let name = cell.axes.on_loop()[0].name.clone();
    let read = check(&cell, &name, 0x6061, 0, None).unwrap();
    assert_eq!(read.reply.data_type, "INTEGER8");
    // 607Ch is rw in the ESI (the MR-J4-TM's own table says ro).
    let write = check(&cell, &name, 0x607C, 0, Some(-100)).unwrap();
    assert_eq!(
        write.request,
        SdoRequest::Download {
            index: 0x607C,
            sub: 0,
            data: SdoData::new(&(-100i32).to_le_bytes()).unwrap()
        }
    );
    let e = refused(&cell, &name, 0x6502, 0, Some(1));
    assert!(e.ends_with("is read-only"), "{e}");
    let e = refused(&cell, &name, 0x2000, 0, None);
    assert!(e.contains("ESI device"), "{e}");
}

#[test]
fn an_answer_is_typed_by_the_object() {
    let cell = shipped("ethercat-cell.toml");
    let read = check(&cell, "y", 0x6061, 0, None).unwrap();
    // A drive (or master) that zero-extends a byte: INTEGER8 0xFF is −1.
    let r = answer(
        read.clone(),
        UserSdoOutcome::Done(SdoOutcome::Uploaded(0xFF)),
    )
    .unwrap();
    assert_eq!(r.outcome, SdoAnswer::Read { value: -1 });
    let r = answer(
        read.clone(),
        UserSdoOutcome::Done(SdoOutcome::Aborted(0x0601_0002)),
    )
    .unwrap();
    assert_eq!(
        r.outcome,
        SdoAnswer::Aborted {
            code: 0x0601_0002,
            meaning: abort_meaning(0x0601_0002).to_string()
        }
    );
    let e = answer(read, UserSdoOutcome::Unsupported).unwrap_err();
    assert!(matches!(e, SdoError::NoChannel { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "sdo: axis 'y' has no acyclic channel to its drive"
    );
    let write = check(&cell, "y", 0x6085, 0, Some(4_000_000_000)).unwrap();
    let r = answer(write, UserSdoOutcome::Done(SdoOutcome::Downloaded)).unwrap();
    assert_eq!(
        r.outcome,
        SdoAnswer::Written {
            value: 4_000_000_000
        }
    );
}

/// A link whose RT thread takes requests and publishes the outcomes it is given.
#[derive(Default)]
pub(in crate::host::operator) struct FakeLink {
    sent: Vec<UserSdo>,
    outcome: Option<(u16, UserSdoOutcome)>,
}

impl CellLink for FakeLink {
    fn status(
        &mut self,
    ) -> Result<crate::host::link::StatusSnapshot, crate::host::link::LinkError> {
        Err(crate::host::link::LinkError::InProcessOnly("status"))
    }
    fn command(
        &mut self,
        _: crate::handoff::CellCommand,
    ) -> Result<(), crate::host::link::LinkError> {
        Ok(())
    }
    fn home(&mut self, _: crate::handoff::HomeRequest) -> Result<(), crate::host::link::LinkError> {
        Ok(())
    }
    fn event(&mut self, _: crate::handoff::EventKind, _: i64) {}
    fn profile(
        &mut self,
        _: crate::handoff::ProfileCommand,
    ) -> Result<(), crate::host::link::LinkError> {
        Err(crate::host::link::LinkError::InProcessOnly("profile"))
    }
    fn feed_override(&mut self, _: f64) -> Result<(), crate::host::link::LinkError> {
        Ok(())
    }
    fn sdo(&mut self, request: UserSdo) -> Result<(), crate::host::link::LinkError> {
        self.sent.push(request);
        Ok(())
    }
    fn sdo_outcome(&mut self, seq: u16) -> Option<UserSdoOutcome> {
        self.outcome.filter(|(s, _)| *s == seq).map(|(_, o)| o)
    }
}

#[test]
fn one_request_is_in_flight_until_its_own_answer_or_the_timeout() {
    let cell = shipped("ethercat-cell.toml");
    let mut link = FakeLink::default();
    let mut flight = SdoInFlight::with_timeout(Duration::from_millis(200));
    let read = check(&cell, "y", 0x6061, 0, None).unwrap();
    flight.start(&mut link, read.clone()).unwrap();
    assert_eq!(link.sent[0].seq, 1);
    assert_eq!(link.sent[0].axis, 1);
    let e = flight.start(&mut link, read.clone()).unwrap_err();
    assert!(matches!(e, SdoError::InFlight), "{e:?}");
    assert!(e.to_string().contains("in flight"), "{e}");
    assert!(flight.poll(&mut link).is_none());
    // An outcome under another sequence number (a request that timed out before) is not this
    // request's answer.
    link.outcome = Some((9, UserSdoOutcome::Done(SdoOutcome::Uploaded(3))));
    assert!(flight.poll(&mut link).is_none());
    link.outcome = Some((1, UserSdoOutcome::Done(SdoOutcome::Uploaded(8))));
    let r = flight.poll(&mut link).unwrap().unwrap();
    assert_eq!(r.outcome, SdoAnswer::Read { value: 8 });
    assert!(!flight.busy());
    // No answer: refused after the timeout, and the next request gets a new number.
    flight.start(&mut link, read.clone()).unwrap();
    let start = Instant::now();
    let e = loop {
        if let Some(r) = flight.poll(&mut link) {
            break r.unwrap_err();
        }
        assert!(start.elapsed() < Duration::from_secs(5), "never timed out");
        std::thread::sleep(Duration::from_millis(5));
    };
    assert!(start.elapsed() >= Duration::from_millis(200));
    assert!(matches!(e, SdoError::NoAnswer { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "sdo: no answer for 6061h:00 of axis 'y' within 200ms"
    );
    flight.start(&mut link, read).unwrap();
    assert_eq!(link.sent[2].seq, 3);
}

#[test]
fn a_refused_object_says_which_rule_it_broke() {
    let cell = shipped("ethercat-cell.toml");
    let e = check(&cell, "y", 0x607C, 0, Some(5)).unwrap_err();
    assert!(
        matches!(
            &e,
            SdoError::Object {
                refusal: ObjectRefusal::ReadOnly,
                ..
            }
        ),
        "{e:?}"
    );
    let e = check(&cell, "y", 0x6085, 0, Some(-1)).unwrap_err();
    assert!(
        matches!(
            &e,
            SdoError::Object {
                refusal: ObjectRefusal::OutOfTypeRange { value: -1, .. },
                ..
            }
        ),
        "{e:?}"
    );
    let e = check(&cell, "w", 0x6041, 0, None).unwrap_err();
    assert!(matches!(e, SdoError::Axis(_)), "{e:?}");
}
