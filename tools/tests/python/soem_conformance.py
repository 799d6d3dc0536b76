#!/usr/bin/env python3
"""An independent EtherCAT MainDevice (SOEM, through PyPI `pysoem`) against `cellrt drive-sim
ethercat`: scan, identities, SOEM's own PDO mapping (config_map), DC SYNC0, OP, every CiA 402
axis through the state machine to Operation enabled in csp, a move of a known distance checked
in 6064h, then back to INIT. Before the mapping, in PRE-OP, each SubDevice's SDO Information is
walked as SOEM reads it (Get OD List, Object and Entry Descriptions) and every entry the file
DECLARED lists for it is checked for its data type and access. Prints one JSON report on
stdout; judges outcomes, not timing.

One thread does everything in OP, one process-data exchange per cycle, so that the interpreter
never holds the exchange back (no SDO in OP, no second thread waiting for the GIL).

usage: soem_conformance.py IFACE CYCLE_US DISTANCE_COUNTS DECLARED_JSON
"""
import json
import os
import struct
import sys
import time

import pysoem

IFACE, CYCLE_US, DISTANCE = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
with open(sys.argv[4]) as f:
    DECLARED = json.load(f)
CYCLE_S = CYCLE_US / 1e6
# Index offset of axis k of a multi-axis unit (MR-J5W2/W3-G-N1: 6000h, 6800h, 7000h).
AXIS_STRIDE = 0x800
CONTROLWORD, STATUSWORD, MODE, MODE_DISPLAY = 0x6040, 0x6041, 0x6060, 0x6061
TARGET_POSITION, POSITION_ACTUAL = 0x607A, 0x6064
TORQUE_LIMITS = (0x60E0, 0x60E1)
# 60E0h/60E1h where the RxPDO carries them: 1000.0 % of rated torque, the MR-J4-TM default
# (manual §5.9); 0 would mean no torque at all.
TORQUE_LIMIT = 10_000
# The MR-J3-T04's incremental counter, RxPDO side, counted up every cycle (manual §8.11.1).
INCREMENTAL_COUNTER = 0x2020
CSP = 8
# 10F1h:02 written where the model has it: the largest U16.
SYNC_ERROR_LIMIT = 0xFFFF
# Cycles of the ramp of each move.
RAMP_CYCLES = 200
# Cycles an outcome may take (a loaded machine is slow, never wrong): 20 s worth.
PATIENCE = int(20.0 / CYCLE_S)


# CiA 301 data type codes (Table 44) of the type names in DECLARED.
TYPE_CODES = {"BOOL": 0x0001, "I8": 0x0002, "I16": 0x0003, "I32": 0x0004, "U8": 0x0005,
              "U16": 0x0006, "U32": 0x0007, "STRING": 0x0009}
# ETG.1000.6 object access word: bits 0-2 readable in PRE-OP/SAFE-OP/OP, 3-5 writable.
READ_BITS, WRITE_BITS = 0x07, 0x38


def walk_sdo_info(slave, declared):
    """The SubDevice's dictionary through SOEM's SDO Information (ecx_readODlist, then
    ecx_readODdescription and ecx_readOE for each declared object): each declared entry listed,
    with its data type and access."""
    od = {o.index: o for o in slave.od}
    problems = []
    for e in declared["entries"]:
        where = f"{e['index']:04X}h:{e['sub']}"
        o = od.get(e["index"])
        if o is None:
            problems.append(f"{where} not listed")
            continue
        entries = o.entries
        if entries:
            if e["sub"] >= len(entries) or not entries[e["sub"]].obj_access:
                problems.append(f"{where} has no entry description")
                continue
            data_type, access = entries[e["sub"]].data_type, entries[e["sub"]].obj_access
        elif e["sub"] == 0:
            data_type, access = o.data_type, o.obj_access
        else:
            problems.append(f"{where}: {e['index']:04X}h is a VAR")
            continue
        want = TYPE_CODES.get(e["type"])
        if want is not None and data_type != want:
            problems.append(f"{where} data type {data_type:#06x}, declared {e['type']}")
        rights = {"ro": (True, False), "rw": (True, True), "wo": (False, True)}.get(e["access"])
        if rights is not None and (bool(access & READ_BITS), bool(access & WRITE_BITS)) != rights:
            problems.append(f"{where} access {access:#06x}, declared {e['access']}")
    return {"model": declared["model"], "objects": len(od), "checked": len(declared["entries"]),
            "problems": problems[:20], "info_errors": drain_errors(slave)}


# An index no model has: its upload must abort with 0602 0000h "object does not exist".
MISSING_OBJECT = 0x5FFE


def missing_object_abort(slave):
    """What SOEM makes of the abort of an upload of a missing object: the abort code of an
    SdoError (an Abort SDO Transfer framed as ETG.1000.6 frames it), or the other error's text."""
    try:
        slave.sdo_read(MISSING_OBJECT, 0)
        return "read without an abort"
    except pysoem.SdoError as e:
        return e.abort_code
    except Exception as e:
        return f"{type(e).__name__}: {e}"


def drain_errors(slave):
    """SOEM's ecx_readOE asks for every sub-index from 0 to the highest and queues an SDO Info
    error for each one an object does not have (a gap); pysoem raises the oldest queued error
    at the next SDO, so they are taken off the queue here, one per read, and counted."""
    n = 0
    while n < 10_000:
        try:
            slave.sdo_read(0x1000, 0)
            return n
        except Exception:
            n += 1
    return n


def mapping(slave, assign):
    """(index, sub, byte offset, bits) of every entry the SM assignment `assign` maps."""
    out, offset = [], 0
    count = slave.sdo_read(assign, 0)[0]
    for k in range(1, count + 1):
        pdo = struct.unpack("<H", slave.sdo_read(assign, k))[0]
        n = slave.sdo_read(pdo, 0)[0]
        for e in range(1, n + 1):
            word = struct.unpack("<I", slave.sdo_read(pdo, e))[0]
            index, sub, bits = word >> 16, (word >> 8) & 0xFF, word & 0xFF
            out.append((index, sub, offset // 8, bits))
            offset += bits
    return out


def at(table, index):
    return next((o for (x, s, o, b) in table if x == index and s == 0), None)


class Axis:
    """One CiA 402 axis: where its objects sit in its SubDevice's process image, and the
    steps it goes through (a generator of the controlword and target for each cycle)."""

    def __init__(self, slave_no, k, rx, tx):
        self.slave_no, self.k = slave_no, k
        b = lambda i: i + AXIS_STRIDE * k
        self.cw, self.target, self.mode = at(rx, b(CONTROLWORD)), at(rx, b(TARGET_POSITION)), at(rx, b(MODE))
        self.limits = [o for o in (at(rx, b(i)) for i in TORQUE_LIMITS) if o is not None]
        self.sw, self.pos, self.display = at(tx, b(STATUSWORD)), at(tx, b(POSITION_ACTUAL)), at(tx, b(MODE_DISPLAY))
        self.result = None

    def complete(self):
        return None not in (self.cw, self.target, self.sw, self.pos)

    def name(self):
        return f"slave {self.slave_no} axis {self.k}"


class Bus:
    """The process image, exchanged once per cycle on this thread."""

    def __init__(self, master):
        self.master = master
        self.out = [bytearray(s.output) for s in master.slaves]
        self.inp = [bytes(s.input) for s in master.slaves]
        self.counters = []
        self.cycles = self.wkc_errors = 0
        self.next = time.monotonic()
        self.last = None
        # The longest time between two exchanges, s: a stall of this interpreter or its host,
        # which a drive sees as lost frames.
        self.max_gap = 0.0

    def cycle(self):
        for slave_no, o in self.counters:
            self.out[slave_no][o] = (self.out[slave_no][o] + 1) % 256
        for i, s in enumerate(self.master.slaves):
            s.output = bytes(self.out[i])
        now = time.monotonic()
        if self.last is not None:
            self.max_gap = max(self.max_gap, now - self.last)
        self.last = now
        self.master.send_processdata()
        wkc = self.master.receive_processdata(2000)
        if wkc >= self.master.expected_wkc:
            self.inp = [bytes(s.input) for s in self.master.slaves]
        else:
            self.wkc_errors += 1
        self.cycles += 1
        self.next += CYCLE_S + self.sync_correction()
        pause = self.next - time.monotonic()
        if pause > 0:
            time.sleep(pause)
        else:
            self.next = time.monotonic()  # late: a missed cycle is skipped, not caught up

    def sync_correction(self):
        """Seconds to shift the next frame by so that frames pass the SubDevices an eighth of a
        cycle after SYNC0, as SOEM's own examples steer their loop by the DC time (`ec_sync`)
        and cellrt's master does: a frame near a SYNC0 edge may miss it."""
        dc = self.master.dc_time
        if not dc:
            return 0.0
        cycle_ns = CYCLE_US * 1000
        error = (dc - cycle_ns // 8) % cycle_ns
        if error > cycle_ns // 2:
            error -= cycle_ns
        return -0.1 * error / 1e9

    def put(self, a, o, fmt, v):
        struct.pack_into(fmt, self.out[a.slave_no], o, v)

    def get(self, a, o, fmt):
        return struct.unpack_from(fmt, self.inp[a.slave_no], o)[0]

    def until(self, pred, what):
        for _ in range(PATIENCE):
            self.cycle()
            if pred():
                return
        raise RuntimeError(f"timed out after {PATIENCE} cycles: {what}")


def drive(bus, axes):
    """Every axis at once: the CiA 402 state machine to Operation enabled in csp, a ramp of
    DISTANCE counts, the target reached in 6064h, back to Ready to switch on."""
    sw = lambda a: bus.get(a, a.sw, "<H")
    state = lambda a: sw(a) & 0x6F
    start = {a: bus.get(a, a.pos, "<i") for a in axes}
    for a in axes:
        bus.put(a, a.target, "<i", start[a])
        if sw(a) & 0x08:
            bus.put(a, a.cw, "<H", 0x80)
    bus.until(lambda: all(not sw(a) & 0x08 for a in axes), "fault reset")
    for cw, want, name in ((0x06, 0x21, "Ready to switch on"), (0x07, 0x23, "Switched on"),
                           (0x0F, 0x27, "Operation enabled")):
        for a in axes:
            bus.put(a, a.cw, "<H", cw)
        bus.until(lambda: all(state(a) == want for a in axes),
                  name + ": " + ", ".join(f"{a.name()} {sw(a):#06x}" for a in axes if state(a) != want))
    for j in range(1, RAMP_CYCLES + 1):
        for a in axes:
            bus.put(a, a.target, "<i", start[a] + DISTANCE * j // RAMP_CYCLES)
        bus.cycle()
        left = [a for a in axes if state(a) != 0x27]
        if left:
            raise RuntimeError(f"{left[0].name()} left Operation enabled during the move (statusword {sw(left[0]):#06x})")
    there = lambda a: abs(bus.get(a, a.pos, "<i") - (start[a] + DISTANCE)) <= 1
    bus.until(lambda: all(there(a) for a in axes), "every axis at its target")
    end = {a: bus.get(a, a.pos, "<i") for a in axes}
    for a in axes:
        bus.put(a, a.cw, "<H", 0x06)
    bus.until(lambda: all(state(a) == 0x21 for a in axes), "back to Ready to switch on")
    return [{"slave": a.slave_no, "axis": a.k, "start": start[a], "end": end[a],
             "mode_display": bus.get(a, a.display, "<b") if a.display is not None else None}
            for a in axes]


REPORT = {"slaves": [], "axes": [], "emergencies": []}
# The bus once it runs, for the report of a failure.
BUS = []


def main():
    report = REPORT
    try:  # as cellrt's RT thread: SCHED_FIFO where allowed (root)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(70))
    except (PermissionError, OSError):
        pass
    master = pysoem.Master()
    master.open(IFACE)
    report["found"] = master.config_init()
    cycle_ns = CYCLE_US * 1000

    def setup(slave_pos):
        s = master.slaves[slave_pos]
        # PRE-OP, as a PLC configures a drive: the cycle, DC SYNC0 as synchronisation type
        # (ETG.1020: 2) where the model lists 1C32h:01, csp by SDO on every axis (a model with
        # 6060h in its RxPDO gets it there too).
        s.sdo_write(0x1C32, 2, struct.pack("<I", cycle_ns))
        try:
            s.sdo_write(0x1C32, 1, struct.pack("<H", 2))
        except pysoem.SdoError:
            pass
        # This MainDevice is a Python loop, not a real-time one: where the model has the
        # sync error counter limit (10F1h:02, ETG.1020; AL.086.1 on MR-JET/MR-J5), raise it so
        # that a late frame of the interpreter is not a lost one. The MR-J3-T04 has none (its
        # AL.36 takes about 7 ms of silence).
        try:
            s.sdo_write(0x10F1, 2, struct.pack("<H", SYNC_ERROR_LIMIT))
        except pysoem.SdoError:
            pass
        for k in range(3):
            try:
                s.sdo_write(MODE + AXIS_STRIDE * k, 0, struct.pack("<b", CSP))
            except pysoem.SdoError:
                pass

    report["sdo_info"] = [walk_sdo_info(s, d) for s, d in zip(master.slaves, DECLARED)]
    report["missing_object"] = [missing_object_abort(s) for s in master.slaves]
    for i, s in enumerate(master.slaves):
        s.add_emergency_callback(lambda e, i=i: report["emergencies"].append(f"slave {i}: {e.error_code:04X}h"))
        s.config_func = setup
        report["slaves"].append({"name": s.name, "vendor": s.man, "product": s.id, "revision": s.rev})
    report["iomap"] = master.config_map()
    report["dc"] = bool(master.config_dc())
    for s in master.slaves:
        s.dc_sync(True, cycle_ns)
    if master.state_check(pysoem.SAFEOP_STATE, 5_000_000) != pysoem.SAFEOP_STATE:
        master.read_state()
        raise RuntimeError("not SAFE-OP: " + ", ".join(f"{s.name} AL {s.al_status:#06x}" for s in master.slaves))
    axes, bus = [], Bus(master)
    for i, s in enumerate(master.slaves):
        rx, tx = mapping(s, 0x1C12), mapping(s, 0x1C13)
        bus.counters += [(i, o) for (x, sub, o, b) in rx if x == INCREMENTAL_COUNTER]
        axes += [a for a in (Axis(i, k, rx, tx) for k in range(3)) if a.complete()]
    for a in axes:
        if a.mode is not None:
            bus.put(a, a.mode, "<b", CSP)
        for o in a.limits:
            bus.put(a, o, "<H", TORQUE_LIMIT)
    for _ in range(10):
        bus.cycle()
    master.state = pysoem.OP_STATE
    master.write_state()
    bus.until(lambda: master.state_check(pysoem.OP_STATE, 1) == pysoem.OP_STATE, "OP")
    report["op"] = True
    BUS.append(bus)
    report["axes"] = drive(bus, axes)
    # The clean way out (MR-JET-G-N1 manual §2.3): axes disabled, then SAFE-OP, PRE-OP, INIT,
    # exchanging all along.
    for state, name in ((pysoem.SAFEOP_STATE, "SAFE-OP"), (pysoem.PREOP_STATE, "PRE-OP"),
                        (pysoem.INIT_STATE, "INIT")):
        master.state = state
        master.write_state()
        bus.until(lambda: master.state_check(state, 1) == state, name)
    report["init"] = True
    report["cycles"], report["wkc_errors"] = bus.cycles, bus.wkc_errors
    report["max_gap_ms"] = bus.max_gap * 1e3
    master.close()
    print(json.dumps(report))


if __name__ == "__main__":
    try:
        main()
    except Exception as e:  # one line the Rust test shows
        gap = {"max_gap_ms": BUS[0].max_gap * 1e3} if BUS else {}
        print(json.dumps(dict(REPORT, error=f"{type(e).__name__}: {e}", **gap)))
        sys.exit(1)
