//! Our Modbus/TCP client against an independent server, PyPI's pymodbus: reads, writes read
//! back, the diagnostics echo and an exception, framed by two implementations that share no
//! code. Needs a Python with pymodbus (`CELLRT_PYTHON`, as CI sets up); says SKIPPED without
//! one outside CI.

use std::net::{SocketAddr, TcpListener, TcpStream};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use cellrt_fieldbus::modbus::client::{ClientError, TcpClient};
use cellrt_fieldbus::modbus::ExceptionCode;

struct Server(Child);

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn start(python: &str) -> (Server, SocketAddr) {
    let port = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let script = cellrt_test_support::python::script("modbus_server.py");
    let log = std::env::temp_dir().join(format!("modbus-server-{port}.log"));
    let child = Command::new(python)
        .arg(script)
        .arg(port.to_string())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("python starts");
    let mut server = Server(child);
    let addr: SocketAddr = format!("127.0.0.1:{port}").parse().unwrap();
    let end = Instant::now() + Duration::from_secs(30);
    while TcpStream::connect(addr).is_err() {
        let exited = server.0.try_wait().ok().flatten();
        if exited.is_some() || Instant::now() > end {
            panic!(
                "pymodbus server did not start ({exited:?}):\n{}",
                std::fs::read_to_string(&log).unwrap_or_default()
            );
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    (server, addr)
}

#[test]
fn our_client_talks_to_pymodbus() {
    let Some(python) = cellrt_test_support::python::pymodbus("our_client_talks_to_pymodbus") else {
        return;
    };
    let (_server, addr) = start(&python);
    let mut client = TcpClient::connect(addr, Duration::from_secs(5)).unwrap();

    // Register i holds i: the words come back in address order (pymodbus may count its
    // addresses from 1; the offset is the same for every word).
    let mut words = [0u16; 4];
    client.read_registers(0x2B05, &mut words).unwrap();
    let offset = words[0].wrapping_sub(0x2B05);
    assert!(offset <= 1, "{words:04x?}");
    assert_eq!(words, [0, 1, 2, 3].map(|k| 0x2B05 + offset + k));

    // A 32-bit value low word first (100000 = 000186A0h), written and read back.
    client.write_registers(0x607A, &[0x86A0, 0x0001]).unwrap();
    let mut back = [0u16; 2];
    client.read_registers(0x607A, &mut back).unwrap();
    assert_eq!(back, [0x86A0, 0x0001]);

    // The diagnostics echo.
    client.echo(0x1234).unwrap();

    // Beyond the server's registers: exception 02h, and the connection stays usable.
    let mut far = [0u16; 2];
    match client.read_registers(0xFFFF, &mut far) {
        Err(ClientError::Exception { function, code }) => {
            assert_eq!((function, code), (0x03, ExceptionCode::IllegalDataAddress))
        }
        other => panic!("{other:?}"),
    }
    client.read_registers(0x6041, &mut words[..1]).unwrap();
    assert_eq!(words[0], 0x6041 + offset);
}
