//! The built-in live page: `http://ADDR/` serves a small read-only page (HTML, script and style
//! compiled into the binary; nothing is fetched from elsewhere) that connects to the live view
//! as one more Foxglove WebSocket viewer and shows the cell state, each axis (position,
//! setpoint, following error as a scrolling plot, FSA state, alarm), the event log and the
//! wakeup-latency histogram.
//!
//! This thread only answers GET requests for the three files: the page's data comes from the
//! live view's server, which keeps a bounded backlog per viewer and drops the oldest messages
//! of one that does not keep up, so a slow page slows neither the recorder nor the RT thread.
//! The page counts the cycle messages it lost: the jumps in the cycle numbers beyond the
//! deadlines the RT thread skipped.

use std::net::{SocketAddr, TcpListener};
use std::sync::Arc;
use std::thread::JoinHandle;

use tiny_http::{Header, Method, Response, Server};

const INDEX_HTML: &str = include_str!("index.html");
const PAGE_JS: &str = include_str!("page.js");
const PAGE_CSS: &str = include_str!("page.css");

/// Why the live page could not start.
#[derive(Debug, thiserror::Error)]
#[error("live page on {addr}: {reason}")]
pub struct PageError {
    /// The address.
    pub addr: SocketAddr,
    /// Why.
    pub reason: String,
}

/// One file of the page.
struct Asset {
    path: &'static str,
    content_type: &'static str,
    body: String,
}

/// The running page server; stopped on drop.
pub struct LivePage {
    /// Where it listens.
    pub addr: SocketAddr,
    server: Arc<Server>,
    thread: Option<JoinHandle<()>>,
}

impl LivePage {
    /// Serves the page of cell `cell` on `addr`; the page connects to the live view on port
    /// `live_port` of the host it was loaded from.
    pub fn start(
        cell: &str,
        axes: &[AxisScale],
        addr: SocketAddr,
        live_port: u16,
    ) -> Result<LivePage, PageError> {
        let fail = |reason: String| PageError { addr, reason };
        let listener = TcpListener::bind(addr).map_err(|e| fail(e.to_string()))?;
        let addr = listener.local_addr().map_err(|e| fail(e.to_string()))?;
        let server =
            Arc::new(Server::from_listener(listener, None).map_err(|e| fail(e.to_string()))?);
        let assets = assets(cell, axes, live_port);
        let csp = content_security_policy(live_port);
        let s = server.clone();
        let thread = std::thread::Builder::new()
            .name("cellrt-live-page".into())
            .spawn(move || serve(&s, &assets, &csp))
            .map_err(|e| fail(format!("cannot start its thread: {e}")))?;
        Ok(LivePage {
            addr,
            server,
            thread: Some(thread),
        })
    }
}

impl Drop for LivePage {
    fn drop(&mut self) {
        self.server.unblock();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// The page's files, the cell's name and the live view's port filled in.
/// An axis as the page labels and scales it: its unit, and its counts per unit (the
/// following-error plot spans at least a few counts, so quantisation noise stays a line).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct AxisScale {
    /// The axis.
    pub name: String,
    /// Its unit (mm, deg…).
    pub unit: String,
    /// Drive counts per unit.
    pub counts_per_unit: f64,
}

impl AxisScale {
    /// Every axis of `cell`.
    pub fn of_cell(cell: &cellrt_config::CellConfig) -> Vec<AxisScale> {
        cell.axes
            .iter()
            .map(|a| AxisScale {
                name: a.name().to_string(),
                unit: a.unit().to_string(),
                counts_per_unit: a.counts_per_unit(),
            })
            .collect()
    }
}

fn assets(cell: &str, axes: &[AxisScale], live_port: u16) -> Vec<Asset> {
    let axes = serde_json::to_string(axes).unwrap_or_else(|_| "[]".into());
    let html = INDEX_HTML
        .replace("{{CELL}}", &escape_html(cell))
        .replace("{{AXES}}", &escape_html(&axes))
        .replace("{{LIVE_PORT}}", &live_port.to_string());
    vec![
        Asset {
            path: "/",
            content_type: "text/html; charset=utf-8",
            body: html,
        },
        Asset {
            path: "/page.js",
            content_type: "text/javascript; charset=utf-8",
            body: PAGE_JS.to_string(),
        },
        Asset {
            path: "/page.css",
            content_type: "text/css; charset=utf-8",
            body: PAGE_CSS.to_string(),
        },
    ]
}

/// Only the page's own files, and WebSocket connections to the live view's port.
fn content_security_policy(live_port: u16) -> String {
    format!(
        "default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self'; \
         connect-src ws://*:{live_port}; base-uri 'none'; form-action 'none'; frame-ancestors 'none'"
    )
}

fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
        .replace('\'', "&#39;")
}

/// Answers requests until the server is unblocked.
fn serve(server: &Server, assets: &[Asset], csp: &str) {
    for request in server.incoming_requests() {
        let response = respond(request.method(), request.url(), assets, csp);
        // A client that went away is no concern of the cell.
        let _ = request.respond(response);
    }
}

/// The response to `method` on `url`: a file of the page, 404 or 405.
fn respond(
    method: &Method,
    url: &str,
    assets: &[Asset],
    csp: &str,
) -> Response<std::io::Cursor<Vec<u8>>> {
    let header = |name: &str, value: &str| {
        Header::from_bytes(name.as_bytes(), value.as_bytes()).expect("ASCII header")
    };
    if !matches!(method, Method::Get | Method::Head) {
        return Response::from_string("only GET and HEAD\n")
            .with_status_code(405)
            .with_header(header("Allow", "GET, HEAD"));
    }
    let path = url.split(['?', '#']).next().unwrap_or("/");
    let path = if path == "/index.html" { "/" } else { path };
    match assets.iter().find(|a| a.path == path) {
        Some(a) => Response::from_string(a.body.clone())
            .with_header(header("Content-Type", a.content_type))
            .with_header(header("Content-Security-Policy", csp))
            .with_header(header("X-Content-Type-Options", "nosniff"))
            .with_header(header("Cache-Control", "no-store")),
        None => Response::from_string(format!("{path}: not part of the live page\n"))
            .with_status_code(404)
            .with_header(header("Content-Type", "text/plain; charset=utf-8")),
    }
}

#[cfg(test)]
mod tests;
