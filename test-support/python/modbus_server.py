"""An independent Modbus/TCP server (PyPI pymodbus) for axes/fieldbus/tests/modbus_pymodbus.rs.

Holding register i holds the value i (so a read shows which addresses were served), the
addresses 0–65534; it answers any unit identifier, like one MR-JE-C answers FFh.
Usage: modbus_server.py PORT
"""
import sys

from pymodbus.datastore import (
    ModbusDeviceContext,
    ModbusSequentialDataBlock,
    ModbusServerContext,
)
from pymodbus.server import StartTcpServer


def main() -> None:
    port = int(sys.argv[1])
    # pymodbus numbers its blocks from 1: block address 1 is protocol address 0.
    block = ModbusSequentialDataBlock(1, list(range(65535)))
    context = ModbusServerContext(devices=ModbusDeviceContext(hr=block), single=True)
    StartTcpServer(context=context, address=("127.0.0.1", port))


if __name__ == "__main__":
    main()
