"""An independent Modbus/TCP client (PyPI pymodbus) against the MR-JE-C emulator, for
axes/emulator/tests/mr_je_c_sockets.rs. Runs the drive to Operation enabled, writes and reads back a
32-bit target low word first, and checks the exceptions; exits non-zero naming the first
check that fails.
Usage: modbus_client.py PORT
"""
import inspect
import sys

from pymodbus.client import ModbusTcpClient

UNIT = 255  # the only unit identifier an MR-JE-C answers (manual §3.5)


def unit_arg() -> str:
    params = inspect.signature(ModbusTcpClient.read_holding_registers).parameters
    return "device_id" if "device_id" in params else "slave"


def main() -> None:
    client = ModbusTcpClient("127.0.0.1", port=int(sys.argv[1]), retries=0)
    if not client.connect():
        sys.exit("cannot connect")
    unit = {unit_arg(): UNIT}

    def read(address, count=1):
        r = client.read_holding_registers(address, count=count, **unit)
        if r.isError():
            sys.exit(f"read {address:04X}h: {r}")
        return r.registers

    def write(address, values):
        r = client.write_registers(address, values, **unit)
        if r.isError():
            sys.exit(f"write {address:04X}h: {r}")

    def check(what, got, want):
        if got != want:
            sys.exit(f"{what}: got {got!r}, want {want!r}")

    for word in (0x0006, 0x0007, 0x000F):
        write(0x6040, [word])
    check("statusword in Operation enabled", read(0x6041), [0x0437])
    write(0x607A, [0x86A0, 0x0001])  # 100000, low word first
    check("607Ah read back", read(0x607A, 2), [0x86A0, 0x0001])
    write(0x6060, [0x009B])  # -101, point table mode
    check("6061h follows 6060h", read(0x6061), [0x009B])
    check("1000h device type", read(0x1000, 2), [0x0192, 0x0002])
    r = client.read_holding_registers(0x5FFF, count=1, **unit)
    check("exception on a missing object", (r.isError(), getattr(r, "exception_code", None)), (True, 2))
    r = client.write_registers(0x6041, [0], **unit)
    check("exception on a read-only object", (r.isError(), getattr(r, "exception_code", None)), (True, 2))
    r = client.write_registers(0x6098, [40], **unit)
    check("exception out of range", (r.isError(), getattr(r, "exception_code", None)), (True, 3))
    client.close()
    print("ok")


if __name__ == "__main__":
    main()
