"""An independent client of the Foxglove WebSocket protocol (foxglove.sdk.v1, the successor of
foxglove.websocket.v1 with the same messages; both are offered), written
with PyPI's websockets and protobuf, for tools/tests/live_view.rs: it connects to a running
cell's live view, checks the advertised channels and schemas, subscribes to /cell/cycle and
/axis/x, decodes the protobuf messages with the advertised schema, and prints a JSON summary.
With --stall S it stops reading for S seconds after the first messages (a stuck viewer), then
reads again.
Usage: live_view.py URL SECONDS [--stall S]
"""
import asyncio
import base64
import json
import struct
import sys
import time

import websockets
from google.protobuf import descriptor_pb2, descriptor_pool, message_factory

MESSAGE_DATA = 0x01


def message_class(channel):
    fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(channel["schema"]))
    pool = descriptor_pool.DescriptorPool()
    for f in fds.file:
        pool.Add(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(channel["schemaName"]))


async def run(url, seconds, stall):
    async with websockets.connect(
        url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"], max_size=None
    ) as ws:
        info, channels = None, {}
        while info is None or "/cell/cycle" not in channels or "/axis/x" not in channels:
            msg = await asyncio.wait_for(ws.recv(), 10)
            if isinstance(msg, str):
                doc = json.loads(msg)
                if doc["op"] == "serverInfo":
                    info = doc
                elif doc["op"] == "advertise":
                    for ch in doc["channels"]:
                        channels[ch["topic"]] = ch
        for topic in ("/cell/cycle", "/axis/x"):
            ch = channels[topic]
            if ch["encoding"] != "protobuf" or ch["schemaEncoding"] != "protobuf":
                sys.exit(f"{topic}: encodings {ch['encoding']} / {ch['schemaEncoding']}")
        subs = {1: "/cell/cycle", 2: "/axis/x"}
        await ws.send(json.dumps({
            "op": "subscribe",
            "subscriptions": [{"id": k, "channelId": channels[t]["id"]} for k, t in subs.items()],
        }))
        classes = {k: message_class(channels[t]) for k, t in subs.items()}
        cycles, positions = [], []
        stalled = stall == 0
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            try:
                msg = await asyncio.wait_for(ws.recv(), 5)
            except (asyncio.TimeoutError, websockets.exceptions.ConnectionClosed):
                break
            if isinstance(msg, str) or msg[0] != MESSAGE_DATA:
                continue
            sub, _t = struct.unpack_from("<IQ", msg, 1)
            decoded = classes[sub].FromString(msg[13:])
            if sub == 1:
                cycles.append(decoded.cycle)
            else:
                positions.append(decoded.actual_position)
            if not stalled and len(cycles) > 100:
                stalled = True
                time.sleep(stall)  # stops reading: the server must drop, the cell run on
        print(json.dumps({
            "server": info.get("name", ""),
            "topics": sorted(channels),
            "cycles": len(cycles),
            "first": cycles[0] if cycles else None,
            "last": cycles[-1] if cycles else None,
            "increasing": all(a < b for a, b in zip(cycles, cycles[1:])),
            "positions": len(positions),
            "max_position": max(positions) if positions else None,
        }))


def main():
    stall = float(sys.argv[sys.argv.index("--stall") + 1]) if "--stall" in sys.argv else 0.0
    asyncio.run(run(sys.argv[1], float(sys.argv[2]), stall))


if __name__ == "__main__":
    main()
