#!/usr/bin/env python3
"""Reads a cellrt recording with the PyPI `mcap` and `mcap-protobuf-support` packages (what a
user's Python would do), decodes every message of every channel with the protobuf decoder,
and checks the channels, schemas, counts and the cell metadata.

    check_recording.py FILE.mcap [--axes x,y,z,c] [--cycles N]

Exits 0 when every check passes, 1 with one line per failed check otherwise, 2 when the
packages are missing.
"""
import argparse
import sys

try:
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory
except ImportError as e:  # pragma: no cover
    print(f"missing Python package ({e}): pip install mcap mcap-protobuf-support", file=sys.stderr)
    sys.exit(2)

SCHEMAS = {
    "/cell/cycle": "cellrt.CycleStats",
    "/cell/events": "cellrt.Event",
}
AXIS_SCHEMA = "cellrt.AxisCycle"
AXIS_FIELDS = [
    "cycle", "setpoint_position", "actual_position", "following_error", "setpoint_velocity",
    "actual_velocity", "setpoint_counts", "actual_position_counts", "actual_velocity_counts",
    "following_error_counts", "controlword", "statusword", "fsa_state", "mode_display",
    "error_code", "setpoint_torque", "actual_torque", "counter_sent", "counter_received",
    "status_do_1", "status_do_2", "status_do_3", "controlword2", "profile_velocity",
    "profile_acceleration", "profile_deceleration", "torque_slope",
]
CYCLE_FIELDS = [
    "cycle", "deadline_ns", "wakeup_latency_ns", "loop_time_ns", "overruns", "cell_state",
    "dropped_records",
]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("file")
    ap.add_argument("--axes", help="expected axis names, comma-separated")
    ap.add_argument("--cycles", type=int, help="expected number of cycle messages")
    ap.add_argument("--status-do", action="store_true",
                    help="the drives map Status DO (2D11h-2D13h): expect S_ZSP (2D12h bit 3) "
                         "in Operation enabled at rest and its absence in motion")
    args = ap.parse_args()
    failures = []

    counts = {}
    last_cycle = {}
    # (at rest in Operation enabled with S_ZSP, moving in Operation enabled without S_ZSP)
    zero_speed = [0, 0]
    with open(args.file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        summary = reader.get_summary()
        if summary is None or not summary.chunk_indexes:
            failures.append("no summary with chunk indexes")
        for schema, channel, message, proto in reader.iter_decoded_messages():
            topic = channel.topic
            counts[topic] = counts.get(topic, 0) + 1
            if schema.encoding != "protobuf" or channel.message_encoding != "protobuf":
                failures.append(f"{topic}: encoding {schema.encoding}/{channel.message_encoding}")
            expected = SCHEMAS.get(topic, AXIS_SCHEMA if topic.startswith("/axis/") else None)
            if expected is None:
                failures.append(f"unexpected topic {topic}")
            elif schema.name != expected:
                failures.append(f"{topic}: schema {schema.name}, expected {expected}")
            fields = (AXIS_FIELDS if topic.startswith("/axis/")
                      else CYCLE_FIELDS if topic == "/cell/cycle" else [])
            for field in fields:
                if not hasattr(proto, field):
                    failures.append(f"{topic}: no field {field}")
                    fields = []
            if fields:
                prev = last_cycle.get(topic)
                if prev is not None and proto.cycle <= prev:
                    failures.append(f"{topic}: cycle {proto.cycle} after {prev}")
                last_cycle[topic] = proto.cycle
                if topic.startswith("/axis/") and (proto.statusword & 0x6F) == 0x27:
                    zsp = proto.status_do_2 & 0x0008 != 0
                    if proto.actual_velocity_counts == 0 and zsp:
                        zero_speed[0] += 1
                    elif abs(proto.actual_velocity_counts) > 10000 and not zsp:
                        zero_speed[1] += 1
            if len(failures) > 20:
                break
        metadata = {m.name: dict(m.metadata) for m in reader.iter_metadata()}
        attachments = [a.name for a in reader.iter_attachments()]

    cell = metadata.get("cellrt.cell")
    if cell is None:
        failures.append("no cellrt.cell metadata")
    elif not cell.get("cell") or not cell.get("cycle_time_us"):
        failures.append(f"cellrt.cell metadata incomplete: {sorted(cell)}")
    if not any(a.endswith(".toml") for a in attachments):
        failures.append(f"no configuration attached (attachments: {attachments})")
    if summary is not None and summary.statistics is not None:
        for cid, n in summary.statistics.channel_message_counts.items():
            topic = summary.channels[cid].topic
            if counts.get(topic, 0) != n:
                failures.append(f"{topic}: {counts.get(topic, 0)} decoded, summary says {n}")
    n_cycles = counts.get("/cell/cycle", 0)
    if n_cycles == 0:
        failures.append("no /cell/cycle messages")
    if args.cycles is not None and n_cycles != args.cycles:
        failures.append(f"/cell/cycle: {n_cycles} messages, expected {args.cycles}")
    if args.axes:
        for axis in args.axes.split(","):
            n = counts.get(f"/axis/{axis}", 0)
            if n != n_cycles:
                failures.append(f"/axis/{axis}: {n} messages, expected {n_cycles}")
    if args.status_do and (zero_speed[0] == 0 or zero_speed[1] == 0):
        failures.append(f"Status DO: S_ZSP at rest / not in motion in Operation enabled: "
                        f"{zero_speed[0]} / {zero_speed[1]} messages")
    if "/cell/events" not in counts:
        failures.append("no /cell/events messages")

    for topic in sorted(counts):
        print(f"{topic:<16} {counts[topic]:>9}")
    if failures:
        for f in failures:
            print(f"FAIL: {f}", file=sys.stderr)
        return 1
    print(f"{args.file}: {sum(counts.values())} messages decoded with mcap-protobuf-support: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main())
