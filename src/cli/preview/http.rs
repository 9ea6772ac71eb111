//! A minimal HTTP/1.1 server for the preview: one request per connection (`Connection: close`),
//! a thread per connection up to a fixed number of connections.
//!
//! Written here rather than taken from a crate because the preview must bound its clients (issue
//! 38: "clients, message sizes and queued frames are bounded"): `tiny_http` 0.12, the small
//! blocking server we tried first, starts a thread for every open connection and queues every
//! request a client pipelines, with no limit on either; the async servers bring an executor
//! whose build cost is out of proportion to a loopback page. Here every count is bounded: open
//! connections ([`MAX_CONNECTIONS`]; one more gets `503` and is closed), the request head
//! ([`MAX_HEAD`]), the body ([`MAX_BODY`]), and the time a client may take to send its request
//! ([`READ_TIMEOUT`]).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

/// Most connections open at once (an open page holds one long poll and briefly one or two more).
pub const MAX_CONNECTIONS: usize = 32;
/// Largest request line plus headers, bytes.
pub const MAX_HEAD: usize = 16 * 1024;
/// Largest request body, bytes.
pub const MAX_BODY: usize = 16 * 1024;
/// How long a client may take to send its request.
pub const READ_TIMEOUT: Duration = Duration::from_secs(10);

/// A request as read.
#[derive(Debug)]
pub struct Request {
    /// `GET`, `POST`, …
    pub method: String,
    /// The request target (path and query).
    pub target: String,
    /// Header names (as sent) and values.
    pub headers: Vec<(String, String)>,
    /// The body (at most [`MAX_BODY`] bytes).
    pub body: Vec<u8>,
    /// The connection, to notice a client that went away while its request waits (a long poll
    /// of a closed tab must not hold its connection slot for the whole poll).
    pub conn: Option<TcpStream>,
}

impl Request {
    /// The first header named `name` (case-insensitive).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k.eq_ignore_ascii_case(name))
            .map(|(_, v)| v.as_str())
    }

    /// Whether the client closed its side of the connection (it can no longer read an answer).
    pub fn client_gone(&self) -> bool {
        let Some(c) = &self.conn else { return false };
        if c.set_nonblocking(true).is_err() {
            return false;
        }
        let mut b = [0u8; 1];
        let gone = match c.peek(&mut b) {
            Ok(0) => true,
            Ok(_) => false,
            Err(e) => e.kind() != std::io::ErrorKind::WouldBlock,
        };
        let _ = c.set_nonblocking(false);
        gone
    }
}

/// A response to send.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Response {
    /// Status code.
    pub status: u16,
    /// Headers besides `Content-Length` and `Connection`.
    pub headers: Vec<(String, String)>,
    /// The body.
    pub body: Vec<u8>,
}

fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        409 => "Conflict",
        500 => "Internal Server Error",
        413 => "Content Too Large",
        431 => "Request Header Fields Too Large",
        503 => "Service Unavailable",
        _ => "Status",
    }
}

fn write_response(stream: &mut TcpStream, r: &Response) -> std::io::Result<()> {
    let mut head = format!("HTTP/1.1 {} {}\r\n", r.status, reason(r.status));
    for (k, v) in &r.headers {
        head += &format!("{k}: {v}\r\n");
    }
    head += &format!(
        "Content-Length: {}\r\nConnection: close\r\n\r\n",
        r.body.len()
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(&r.body)?;
    stream.flush()
}

fn plain(status: u16, text: &str) -> Response {
    Response {
        status,
        headers: vec![("Content-Type".into(), "text/plain; charset=utf-8".into())],
        body: text.as_bytes().to_vec(),
    }
}

/// Reads one request; `Err` carries the response to send instead.
fn read_request(stream: &TcpStream) -> Result<Request, Response> {
    let mut reader = BufReader::new(stream.take((MAX_HEAD + MAX_BODY + 1) as u64));
    let mut head_bytes = 0usize;
    let mut line = String::new();
    let mut next_line = |line: &mut String| -> Result<(), Response> {
        line.clear();
        match reader.read_line(line) {
            Ok(0) => Err(plain(400, "incomplete request")),
            Ok(n) => {
                head_bytes += n;
                if head_bytes > MAX_HEAD {
                    Err(plain(431, "request head over 16 KiB"))
                } else {
                    Ok(())
                }
            }
            Err(_) => Err(plain(400, "unreadable or slow request")),
        }
    };
    next_line(&mut line)?;
    let mut parts = line.trim_end().splitn(3, ' ');
    let (Some(method), Some(target), Some(version)) = (parts.next(), parts.next(), parts.next())
    else {
        return Err(plain(400, "malformed request line"));
    };
    if !version.starts_with("HTTP/1.") {
        return Err(plain(400, "HTTP/1.x only"));
    }
    let (method, target) = (method.to_string(), target.to_string());
    let mut headers = Vec::new();
    loop {
        next_line(&mut line)?;
        let l = line.trim_end_matches(['\r', '\n']);
        if l.is_empty() {
            break;
        }
        let Some((k, v)) = l.split_once(':') else {
            return Err(plain(400, "malformed header"));
        };
        headers.push((k.trim().to_string(), v.trim().to_string()));
    }
    let mut req = Request {
        method,
        target,
        headers,
        body: Vec::new(),
        conn: stream.try_clone().ok(),
    };
    if req
        .header("Transfer-Encoding")
        .is_some_and(|t| !t.eq_ignore_ascii_case("identity"))
    {
        return Err(plain(400, "chunked request bodies are not accepted"));
    }
    let length = match req.header("Content-Length") {
        None => 0,
        Some(v) => match v.parse::<usize>() {
            Ok(n) if n <= MAX_BODY => n,
            Ok(_) => return Err(plain(413, "body over 16 KiB")),
            Err(_) => return Err(plain(400, "bad Content-Length")),
        },
    };
    let mut body = vec![0u8; length];
    reader
        .read_exact(&mut body)
        .map_err(|_| plain(400, "incomplete body"))?;
    req.body = body;
    Ok(req)
}

/// Counts an open connection for as long as it lives.
struct Slot(Arc<AtomicUsize>);

impl Drop for Slot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// A running server: [`Server::stop`] ends its accept loop.
pub struct Server {
    addr: SocketAddr,
    quit: Arc<AtomicBool>,
    accept: Option<std::thread::JoinHandle<()>>,
}

impl Server {
    /// Serves `listener` with `handler` on a thread per connection (at most
    /// [`MAX_CONNECTIONS`]).
    pub fn start(
        listener: TcpListener,
        handler: Arc<dyn Fn(Request) -> Response + Send + Sync>,
    ) -> std::io::Result<Server> {
        let addr = listener.local_addr()?;
        let quit = Arc::new(AtomicBool::new(false));
        let open = Arc::new(AtomicUsize::new(0));
        let q = Arc::clone(&quit);
        let accept = std::thread::spawn(move || {
            for stream in listener.incoming() {
                if q.load(Ordering::SeqCst) {
                    break;
                }
                let Ok(mut stream) = stream else { continue };
                let _ = stream.set_read_timeout(Some(READ_TIMEOUT));
                let _ = stream.set_write_timeout(Some(READ_TIMEOUT));
                if open.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS {
                    open.fetch_sub(1, Ordering::SeqCst);
                    let _ = write_response(&mut stream, &plain(503, "too many connections"));
                    continue;
                }
                let slot = Slot(Arc::clone(&open));
                let handler = Arc::clone(&handler);
                let spawned = std::thread::Builder::new().spawn(move || {
                    let _slot = slot;
                    let response = match read_request(&stream) {
                        Ok(req) => handler(req),
                        Err(r) => r,
                    };
                    let _ = write_response(&mut stream, &response);
                });
                // A thread that cannot start drops its connection (and its slot).
                drop(spawned);
            }
        });
        Ok(Server {
            addr,
            quit,
            accept: Some(accept),
        })
    }

    /// The address it listens on.
    pub fn addr(&self) -> SocketAddr {
        self.addr
    }

    /// Stops accepting and waits for the accept loop (connections in flight finish on their own).
    pub fn stop(mut self) {
        self.quit.store(true, Ordering::SeqCst);
        // Wake the blocking accept.
        let _ = TcpStream::connect_timeout(&self.addr, Duration::from_secs(1));
        if let Some(t) = self.accept.take() {
            let _ = t.join();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ask(addr: SocketAddr, raw: &[u8]) -> String {
        let mut s = TcpStream::connect(addr).unwrap();
        s.write_all(raw).unwrap();
        let mut out = String::new();
        let _ = s.read_to_string(&mut out);
        out
    }

    #[test]
    fn parses_answers_and_bounds() {
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let server = Server::start(
            listener,
            Arc::new(|r: Request| Response {
                status: 200,
                headers: vec![],
                body: format!("{} {} {}", r.method, r.target, r.body.len()).into_bytes(),
            }),
        )
        .unwrap();
        let a = server.addr();
        let ok = ask(
            a,
            b"POST /x?y=1 HTTP/1.1\r\nHost: h\r\nContent-Length: 3\r\n\r\nabc",
        );
        assert!(
            ok.starts_with("HTTP/1.1 200 OK\r\n") && ok.ends_with("POST /x?y=1 3"),
            "{ok}"
        );
        assert!(ask(a, b"GET / HTTP/2\r\n\r\n").starts_with("HTTP/1.1 400"));
        assert!(ask(a, b"nonsense\r\n\r\n").starts_with("HTTP/1.1 400"));
        let big = format!(
            "POST / HTTP/1.1\r\nContent-Length: {}\r\n\r\n",
            MAX_BODY + 1
        );
        assert!(ask(a, big.as_bytes()).starts_with("HTTP/1.1 413"));
        let long = format!("GET / HTTP/1.1\r\nX: {}\r\n\r\n", "a".repeat(MAX_HEAD));
        assert!(ask(a, long.as_bytes()).starts_with("HTTP/1.1 431"));
        let chunked = b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n";
        assert!(ask(a, chunked).starts_with("HTTP/1.1 400"));
        // Idle connections beyond the bound are refused at once; the server still answers
        // once they close.
        let idle: Vec<TcpStream> = (0..MAX_CONNECTIONS)
            .map(|_| TcpStream::connect(a).unwrap())
            .collect();
        std::thread::sleep(Duration::from_millis(200));
        assert!(ask(a, b"GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 503"));
        drop(idle);
        std::thread::sleep(Duration::from_millis(200));
        assert!(ask(a, b"GET / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 200"));
        server.stop();
    }
}
