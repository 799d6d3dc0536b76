"""An independent Modbus RTU master (PyPI pymodbus with pyserial) against the MR-JE-C emulator
on a pseudo-terminal, for axes/emulator/tests/mr_je_c_rs485.rs: two stations on one line, the drive at
station 2 run to Operation enabled, a 32-bit target written high word first ([Pr. PC72] = 1)
and read back, the 08h echo, an exception, and station 3 (not on the line) silent. Exits non-zero naming the first
check that fails.
Usage: modbus_rtu_client.py SERIAL_PATH
"""
import inspect
import sys

from pymodbus.client import ModbusSerialClient
from pymodbus.exceptions import ModbusIOException
from pymodbus.pdu.diag_message import ReturnQueryDataRequest


def unit_arg() -> str:
    params = inspect.signature(ModbusSerialClient.read_holding_registers).parameters
    return "device_id" if "device_id" in params else "slave"


def main() -> None:
    # 115200 bit/s (the drive's initial rate, manual section 4.9.1), no parity and 2 stop bits
    # ([Pr. PF45] = 2): Linux refuses pyserial's parity settings on a pseudo-terminal.
    client = ModbusSerialClient(
        sys.argv[1], baudrate=115200, parity="N", stopbits=2, bytesize=8, timeout=1, retries=0
    )
    if not client.connect():
        sys.exit("cannot open the serial port")
    key = unit_arg()

    def read(station, address, count=1):
        r = client.read_holding_registers(address, count=count, **{key: station})
        if r.isError():
            sys.exit(f"station {station} read {address:04X}h: {r}")
        return r.registers

    def write(station, address, values):
        r = client.write_registers(address, values, **{key: station})
        if r.isError():
            sys.exit(f"station {station} write {address:04X}h: {r}")

    def check(what, got, want):
        if got != want:
            sys.exit(f"{what}: got {got!r}, want {want!r}")

    check("station 1 in Switch on disabled", read(1, 0x6041)[0] & 0x4F, 0x40)
    for word in (0x0006, 0x0007, 0x000F):
        write(2, 0x6040, [word])
    check("station 2 statusword in Operation enabled", read(2, 0x6041), [0x0437])
    check("station 1 untouched", read(1, 0x6041)[0] & 0x4F, 0x40)
    # Station 2 has [Pr. PC72] = 1: 32-bit values high word first. 100000 = 0001 86A0h.
    write(2, 0x607A, [0x0001, 0x86A0])
    check("607Ah read back", read(2, 0x607A, 2), [0x0001, 0x86A0])
    dev = "dev_id" if "dev_id" in inspect.signature(ReturnQueryDataRequest.__init__).parameters else key
    echo = client.execute(False, ReturnQueryDataRequest(message=b"\x12\x34", **{dev: 2}))
    check("08h echo", (echo.isError(), getattr(echo, "message", None)), (False, b"\x12\x34"))
    r = client.read_holding_registers(0x5FFF, count=1, **{key: 2})
    check("exception on a missing object", (r.isError(), getattr(r, "exception_code", None)), (True, 2))
    try:
        r = client.read_holding_registers(0x6041, count=1, **{key: 3})
        silent = r.isError()
    except ModbusIOException:
        silent = True
    check("station 3 is not on the line (no response)", silent, True)
    client.close()
    print("ok")


if __name__ == "__main__":
    main()
