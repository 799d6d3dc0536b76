//! The mailbox of an emulated station: SDO requests in SM0, and SM1 filled with Emergencies
//! (the drives' alarms as they are raised) and SDO responses.

use std::collections::VecDeque;

use super::{Station, EMERGENCY_QUEUE, SM_FULL};
use crate::ethercat::coe::{self, CoeContext};
use cellrt_ethercat::emergency::{CoeEmergency, Emergency};
use cellrt_ethercat::register as reg;

/// What the SubDevice firmware has to write into SM1 (one buffer: ETG.1000.4 §6.7.2 "1-buffer
/// mode"): Emergencies raised and not yet written, and at most one SDO response (the master
/// waits for it before its next request). Whenever SM1 is empty (read by the master, or at
/// the firmware's next event: a mailbox request, a process-data cycle) the next one is
/// written: Emergencies first, in the order raised, then the response. A queued Emergency was
/// raised at a process-data cycle, so before any request that is waiting now (emulated
/// requests are served at once), and CiA 301 §7.2.7 gives EMCY the higher priority.
#[derive(Debug)]
pub(super) struct Outbox {
    /// The model sends Emergencies ([`cellrt_cia402::profiles::EmergencyFacts`]).
    pub(super) sends_emergencies: bool,
    pub(super) emergencies: VecDeque<Emergency>,
    /// Emergencies dropped because the queue was full.
    pub(super) lost: u64,
    /// Per axis: the alarm last reported (an Emergency goes out when it changes to `Some`).
    pub(super) alarms: Vec<Option<u16>>,
    /// The SDO response not yet written into SM1 (`response_len` bytes of `response`).
    pub(super) response: Vec<u8>,
    pub(super) response_len: usize,
    /// SDO Information fragments still to follow the response, each a whole message.
    pub(super) fragments: VecDeque<Vec<u8>>,
    /// The mailbox counter of the last message written into SM1 (1..=7).
    pub(super) counter: u8,
    /// When the SDO response may go into SM1 (the segment's clock, ns): the firmware's answer
    /// time ([`SubDeviceVariant::sdo_response_delay_ns`](crate::ethercat::SubDeviceVariant)).
    pub(super) response_due_ns: u64,
}

impl Station {
    /// Emergencies dropped because [`EMERGENCY_QUEUE`] was full (diagnostics).
    pub fn emergencies_lost(&self) -> u64 {
        self.outbox.lost
    }

    /// Emergencies raised and not yet written into SM1.
    pub fn emergencies_queued(&self) -> usize {
        self.outbox.emergencies.len()
    }

    /// Queues an Emergency for each axis whose drive raised an alarm since the last look
    /// (603Fh = the alarm code; [`Emergency::of_alarm`] names the slot), where the model sends
    /// them ([`cellrt_cia402::profiles::EmergencyFacts`]), and writes SM1 if it is empty.
    pub(super) fn watch_alarms(&mut self) {
        let out = &mut self.outbox;
        for (slot, (d, last)) in self.drives.iter().zip(out.alarms.iter_mut()).enumerate() {
            let now = d.alarm();
            if now == *last {
                continue;
            }
            *last = now;
            let Some(code) = now else {
                continue;
            };
            if !out.sends_emergencies {
                continue;
            }
            if out.emergencies.len() < EMERGENCY_QUEUE {
                out.emergencies
                    .push_back(Emergency::of_alarm(code, slot as u8));
            } else {
                out.lost += 1;
            }
        }
        self.fill_mailbox_in();
    }

    /// The firmware writes the next outgoing mailbox message ([`Outbox`]) into SM1 if SM1 is
    /// enabled and empty, with the next mailbox counter.
    pub(super) fn fill_mailbox_in(&mut self) {
        let sm1 = usize::from(reg::sync_manager(1)) + 5;
        if !self.sm_enabled(1) || self.mem[sm1] & SM_FULL != 0 {
            return;
        }
        let mb = self.layout.mailbox_in;
        let (start, len) = (usize::from(mb.start), usize::from(mb.len));
        let out = &mut self.outbox;
        let counter = if out.counter >= 7 { 1 } else { out.counter + 1 };
        let buf = &mut self.mem[start..start + len];
        if let Some(e) = out.emergencies.pop_front() {
            e.encode(counter, buf);
        } else if out.response_len > 0 && self.now_ns >= out.response_due_ns {
            let n = out.response_len.min(len);
            buf[..n].copy_from_slice(&out.response[..n]);
            buf[5] = (buf[5] & 0x0F) | (counter << 4);
            out.response_len = 0;
            // The next SDO Information fragment follows once the master has read this one.
            if let Some(next) = out.fragments.pop_front() {
                out.response_len = next.len();
                out.response[..next.len()].copy_from_slice(&next);
            }
        } else {
            return;
        }
        out.counter = counter;
        self.mem[sm1] |= SM_FULL;
    }

    pub(super) fn mailbox_request(&mut self) {
        let out = self.layout.mailbox_out;
        let inb = self.layout.mailbox_in;
        let req_start = usize::from(out.start);
        let request: Vec<u8> = self.mem[req_start..req_start + usize::from(out.len)].to_vec();
        let response = &mut self.outbox.response;
        response.resize(usize::from(inb.len), 0);
        response.fill(0);
        let mut ctx = CoeContext {
            drives: &mut self.drives,
            identity: self.identity,
            al_state: self.al_state,
            pdo: &mut self.pdo,
            // The counter is set when the response is written into SM1 (`fill_mailbox_in`).
            counter: &mut self.mailbox_counter,
            upload: &mut self.upload,
            variant: &self.variant,
            esi: self.esi.as_deref(),
            info_fragments: &mut self.outbox.fragments,
        };
        if coe::serve(&mut ctx, &request, response) {
            // A response the master never read is replaced: it has moved on.
            self.outbox.response_len = response.len();
            let delay = if self.al_state == cellrt_ethercat::register::AlState::Op {
                self.variant.sdo_response_delay_ns
            } else {
                0
            };
            self.outbox.response_due_ns = self.now_ns + delay;
        }
        // The request is consumed at once: SM0 is empty again.
        self.mem[usize::from(reg::sync_manager(0)) + 5] &= !SM_FULL;
        // An alarm raised since the last look goes out ahead of the response, as a drive's
        // firmware sends its Emergency when the alarm occurs (the master must expect one where
        // its SDO response should be).
        self.watch_alarms();
    }
}
