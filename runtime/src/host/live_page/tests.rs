use std::io::{Read, Write};
use std::net::TcpStream;

use super::{AxisScale, LivePage};

/// Sends `request` and returns the whole response.
fn ask(page: &LivePage, request: &str) -> String {
    let mut s = TcpStream::connect(page.addr).unwrap();
    s.write_all(request.as_bytes()).unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    out
}

fn get(page: &LivePage, path: &str) -> String {
    ask(
        page,
        &format!("GET {path} HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"),
    )
}

#[test]
fn serves_the_page_with_the_live_views_port_and_the_cell_name_escaped() {
    let page = LivePage::start("a<b>&c", &[], "127.0.0.1:0".parse().unwrap(), 8765).unwrap();
    assert_ne!(page.addr.port(), 0);
    let html = get(&page, "/");
    assert!(html.starts_with("HTTP/1.1 200"), "{html}");
    assert!(
        html.contains("Content-Type: text/html; charset=utf-8"),
        "{html}"
    );
    assert!(html.contains(r#"<meta name="cellrt-live-port" content="8765">"#));
    assert!(html.contains("cellrt live: a&lt;b&gt;&amp;c"));
    assert!(!html.contains("{{"), "a placeholder left: {html}");
    assert!(html.contains("connect-src ws://*:8765;"), "{html}");
    assert!(get(&page, "/index.html?x=1").contains("cellrt-live-port"));
    let js = get(&page, "/page.js");
    assert!(js.contains("Content-Type: text/javascript"), "{js}");
    assert!(js.contains("foxglove.sdk.v1"));
    assert!(get(&page, "/page.css").contains("Content-Type: text/css"));
}

#[test]
fn the_page_names_each_axis_unit_and_scale_escaped_for_its_attribute() {
    let axes = [AxisScale {
        name: "x\"<".into(),
        unit: "mm".into(),
        counts_per_unit: 262.144,
    }];
    let page = LivePage::start("demo", &axes, "127.0.0.1:0".parse().unwrap(), 8765).unwrap();
    let html = get(&page, "/");
    assert!(
        html.contains(
            r#"<meta name="cellrt-axes" content="[{&quot;name&quot;:&quot;x\&quot;&lt;&quot;,&quot;unit&quot;:&quot;mm&quot;,&quot;counts_per_unit&quot;:262.144}]">"#
        ),
        "{html}"
    );
}

#[test]
fn nothing_else_is_served() {
    let page = LivePage::start("demo", &[], "127.0.0.1:0".parse().unwrap(), 8765).unwrap();
    let missing = get(&page, "/etc/passwd");
    assert!(missing.starts_with("HTTP/1.1 404"), "{missing}");
    assert!(missing.contains("/etc/passwd: not part of the live page"));
    let post = ask(
        &page,
        "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 0\r\nConnection: close\r\n\r\n",
    );
    assert!(post.starts_with("HTTP/1.1 405"), "{post}");
    assert!(post.contains("Allow: GET, HEAD"), "{post}");
    let head = ask(
        &page,
        "HEAD / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n",
    );
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    assert!(!head.contains("<html"), "{head}");
}

#[test]
fn a_taken_port_is_an_error_naming_the_address() {
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap();
    let e = LivePage::start("demo", &[], addr, 8765).err().unwrap();
    assert!(
        e.to_string().starts_with(&format!("live page on {addr}: ")),
        "{e}"
    );
}
