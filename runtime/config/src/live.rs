//! `[live]`: where the live view (Foxglove WebSocket protocol) and its built-in page listen.

use std::net::SocketAddr;
use std::path::Path;

use super::raw::RawLive;
use super::ConfigError;

/// The live page's port (`[live] page_port`); the page listens on the live view's IP, so a
/// browser that loaded it reaches the live view at the same host name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PagePort {
    /// Not given: the live view's port + 1 (any free port when that is 0). Taken by something
    /// else, it is a warning and the cell runs without the page.
    #[default]
    NextToLiveView,
    /// `page_port = N` (0: any free one). Taken by something else, the run does not start.
    Given(u16),
}

/// Why the live page has no address beside the live view (the text names no key: the caller
/// knows whether the address came from the file or `--live`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PagePortError {
    /// `page_port` is the live view's own port.
    #[error("the live page cannot share the live view's port {port}")]
    SharesLiveViewPort {
        /// The port.
        port: u16,
    },
    /// The live view listens on port 65535 and no `page_port` is given.
    #[error("port 65535 leaves no next port for the live page: set live.page_port")]
    NoNextPort,
}

impl PagePort {
    /// The page's address beside the live view on `listen`, or why there is none (the text
    /// names no key: the caller knows whether the address came from the file or `--live`).
    pub fn addr(self, listen: SocketAddr) -> Result<SocketAddr, PagePortError> {
        let port = match self {
            PagePort::Given(port) if port != 0 && port == listen.port() => {
                return Err(PagePortError::SharesLiveViewPort { port })
            }
            PagePort::Given(p) => p,
            PagePort::NextToLiveView if listen.port() == 0 => 0,
            PagePort::NextToLiveView => listen
                .port()
                .checked_add(1)
                .ok_or(PagePortError::NoNextPort)?,
        };
        Ok(SocketAddr::new(listen.ip(), port))
    }

    /// Whether the port was given (a port in use is then an error, not a warning).
    pub fn given(self) -> bool {
        matches!(self, PagePort::Given(_))
    }
}

/// The live view's address (none: no live view) and the page's port, checked together.
pub(super) fn live_config(
    file: &Path,
    raw: &RawLive,
) -> Result<(Option<SocketAddr>, PagePort), ConfigError> {
    let listen = match &raw.listen {
        Some(text) => Some(
            super::parse_live_addr(text)
                .map_err(|e| ConfigError::new(file, "live.listen", e.to_string()))?,
        ),
        None => None,
    };
    let page = match raw.page_port {
        None => PagePort::NextToLiveView,
        Some(p) => PagePort::Given(u16::try_from(p).map_err(|_| {
            ConfigError::new(
                file,
                "live.page_port",
                format!("{p} is not a port (0..=65535)"),
            )
        })?),
    };
    match listen {
        Some(addr) => {
            page.addr(addr).map_err(|e| {
                let key = if page.given() {
                    "live.page_port"
                } else {
                    "live.listen"
                };
                ConfigError::new(file, key, e.to_string())
            })?;
        }
        None if page.given() => {
            return Err(ConfigError::new(
                file,
                "live.page_port",
                "the live page shows the live view's stream: set live.listen too",
            ))
        }
        None => {}
    }
    Ok((listen, page))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(
        listen: Option<&str>,
        page_port: Option<i64>,
    ) -> Result<(Option<SocketAddr>, PagePort), ConfigError> {
        let raw = RawLive {
            listen: listen.map(str::to_string),
            page_port,
        };
        live_config(Path::new("cell.toml"), &raw)
    }

    #[test]
    fn the_page_listens_next_to_the_live_view_unless_told() {
        let (listen, page) = parse(Some("127.0.0.1:8765"), None).unwrap();
        assert_eq!(
            page.addr(listen.unwrap()).unwrap(),
            "127.0.0.1:8766".parse().unwrap()
        );
        let (listen, page) = parse(Some("[::1]:0"), None).unwrap();
        assert_eq!(
            page.addr(listen.unwrap()).unwrap(),
            "[::1]:0".parse().unwrap()
        );
        let (listen, page) = parse(Some("0.0.0.0:9000"), Some(8080)).unwrap();
        assert_eq!(
            page.addr(listen.unwrap()).unwrap(),
            "0.0.0.0:8080".parse().unwrap()
        );
        assert!(page.given());
    }

    #[test]
    fn bad_page_ports_are_refused_naming_the_key() {
        let e = parse(Some("127.0.0.1:8765"), Some(70_000)).unwrap_err();
        assert_eq!(e.key, "live.page_port");
        assert!(e.message.contains("70000 is not a port"), "{e}");
        let e = parse(Some("127.0.0.1:8765"), Some(8765)).unwrap_err();
        assert_eq!(e.key, "live.page_port");
        assert!(e.message.contains("share the live view's port 8765"), "{e}");
        let e = parse(None, Some(8766)).unwrap_err();
        assert_eq!(e.key, "live.page_port");
        assert!(e.message.contains("set live.listen"), "{e}");
        let e = parse(Some("127.0.0.1:65535"), None).unwrap_err();
        assert_eq!(e.key, "live.listen");
        assert!(e.message.contains("set live.page_port"), "{e}");
        assert!(parse(Some("127.0.0.1:65535"), Some(0)).is_ok());
    }

    #[test]
    fn the_key_is_read_from_the_file() {
        let text = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../configs/demo.toml"
        ))
        .unwrap()
        .replace("cpu = 1 ", "# cpu = 1 ")
            + "\n[live]\nlisten = \"127.0.0.1:8765\"\npage_port = \"web\"\n";
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("demo-program.toml"), "").unwrap();
        let e = crate::CellConfig::parse(&dir.path().join("demo.toml"), &text).unwrap_err();
        assert!(e.to_string().contains("page_port"), "{e}");
    }
}
