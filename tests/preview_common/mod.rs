//! Shared by `tests/preview.rs` and `tests/preview_browser.rs`: a `lapidary preview` process on
//! an ephemeral port, a scratch copy of the Lepidolite recipe, and a plain HTTP/1.1 client.

#![allow(dead_code)]

use serde_json::Value;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A running `lapidary preview` (killed on drop).
pub struct Preview {
    pub child: Child,
    pub port: u16,
    pub token: String,
    pub dir: PathBuf,
}

impl Drop for Preview {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A scratch folder with a copy of the Lepidolite recipe.
pub fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("lapidary-preview-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("gems/lepidolite.ron"))
            .unwrap();
    std::fs::write(dir.join("lepidolite.ron"), text).unwrap();
    dir
}

pub fn start(dir: &Path, extra: &[&str]) -> Preview {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("preview")
        .arg(dir.join("lepidolite.ron"))
        .args(["--port", "0", "--size", "64x48", "--threads", "2"])
        .args(if extra.contains(&"--spp") {
            &[][..]
        } else {
            &["--spp", "8"][..]
        })
        .arg("--out")
        .arg(dir)
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut line = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    // "lapidary preview: http://127.0.0.1:PORT/?t=TOKEN"
    let url = line.trim().rsplit(' ').next().unwrap().to_string();
    let rest = url.strip_prefix("http://127.0.0.1:").expect(&line);
    let (port, token) = rest.split_once("/?t=").unwrap();
    Preview {
        child,
        port: port.parse().unwrap(),
        token: token.to_string(),
        dir: dir.to_path_buf(),
    }
}

/// A response: status, headers (lower-case names), body.
pub struct Reply {
    pub status: u16,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

impl Reply {
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&self.body)))
    }
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v.as_str())
    }
}

/// One HTTP/1.1 request with explicit headers; the connection is closed after it.
pub fn raw(port: u16, method: &str, target: &str, headers: &[(&str, &str)], body: &[u8]) -> Reply {
    let mut s = TcpStream::connect(("127.0.0.1", port)).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    let mut req = format!("{method} {target} HTTP/1.1\r\nConnection: close\r\n");
    for (k, v) in headers {
        req += &format!("{k}: {v}\r\n");
    }
    req += &format!("Content-Length: {}\r\n\r\n", body.len());
    s.write_all(req.as_bytes()).unwrap();
    let _ = s.write_all(body);
    // Read the head, then exactly the body its headers announce (chromedriver keeps the
    // connection open despite `Connection: close`).
    let mut all = Vec::new();
    let mut buf = [0u8; 65536];
    let split = loop {
        if let Some(k) = all.windows(4).position(|w| w == b"\r\n\r\n") {
            break k;
        }
        let n = s.read(&mut buf).unwrap();
        assert!(n > 0, "connection closed before a complete HTTP head");
        all.extend_from_slice(&buf[..n]);
    };
    let head = String::from_utf8_lossy(&all[..split]).to_string();
    let mut lines = head.lines();
    let status = lines
        .next()
        .unwrap()
        .split(' ')
        .nth(1)
        .unwrap()
        .parse()
        .unwrap();
    let headers: Vec<(String, String)> = lines
        .filter_map(|l| l.split_once(':'))
        .map(|(k, v)| (k.trim().to_ascii_lowercase(), v.trim().to_string()))
        .collect();
    let length = headers
        .iter()
        .find(|(k, _)| k == "content-length")
        .and_then(|(_, v)| v.parse::<usize>().ok());
    let chunked = headers
        .iter()
        .any(|(k, v)| k == "transfer-encoding" && v.contains("chunked"));
    let mut body = all[split + 4..].to_vec();
    loop {
        let complete = match length {
            Some(n) => body.len() >= n,
            None if chunked => body.windows(5).any(|w| w == b"0\r\n\r\n"),
            None => false,
        };
        if complete {
            break;
        }
        match s.read(&mut buf) {
            Ok(0) | Err(_) => break,
            Ok(n) => body.extend_from_slice(&buf[..n]),
        }
    }
    if let Some(n) = length {
        body.truncate(n);
    } else if chunked {
        body = dechunk(&body);
    }
    Reply {
        status,
        headers,
        body,
    }
}

fn dechunk(mut b: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    loop {
        let line_end = b.windows(2).position(|w| w == b"\r\n").unwrap();
        let n =
            usize::from_str_radix(std::str::from_utf8(&b[..line_end]).unwrap().trim(), 16).unwrap();
        if n == 0 {
            return out;
        }
        out.extend_from_slice(&b[line_end + 2..line_end + 2 + n]);
        b = &b[line_end + 2 + n + 2..];
    }
}

impl Preview {
    pub fn host(&self) -> String {
        format!("127.0.0.1:{}", self.port)
    }
    pub fn get(&self, path: &str) -> Reply {
        let sep = if path.contains('?') { '&' } else { '?' };
        let target = format!("{path}{sep}t={}", self.token);
        raw(self.port, "GET", &target, &[("Host", &self.host())], b"")
    }
    pub fn post(&self, path: &str, body: &str) -> Reply {
        let target = format!("{path}?t={}", self.token);
        raw(
            self.port,
            "POST",
            &target,
            &[("Host", &self.host()), ("Content-Type", "application/json")],
            body.as_bytes(),
        )
    }
    pub fn status(&self) -> Value {
        self.get("/status").json()
    }
    /// Polls the status until `ok` holds (at most two minutes: a debug build renders slowly).
    pub fn wait(&self, what: &str, ok: impl Fn(&Value) -> bool) -> Value {
        let start = Instant::now();
        let mut frame = 0;
        loop {
            let s = self.get(&format!("/status?since={frame}")).json();
            if ok(&s) {
                return s;
            }
            frame = s["frame"].as_u64().unwrap();
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "waited two minutes for {what}; last status {s}"
            );
        }
    }
}

/// A number field of `/proc/PID/status` (`Threads`, `VmRSS` in KiB, …).
pub fn proc_status(pid: u32, field: &str) -> u64 {
    let s = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    s.lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no {field} in /proc/{pid}/status"))
}

/// Runs the batch command an export printed (`v` is the export's JSON) to another file in `dir`
/// and checks that it renders the exported EXR again, channel by channel and bit for bit;
/// returns the batch render.
pub fn export_is_its_command(v: &Value, dir: &Path) -> lapidary::image::ExrImage {
    let exported = lapidary::image::read_exr(Path::new(v["exr"].as_str().unwrap())).unwrap();
    let mut args: Vec<String> = v["command"]
        .as_str()
        .unwrap()
        .split(' ')
        .skip(1)
        .map(|a| a.trim_matches('\'').to_string())
        .collect();
    let at = args.iter().position(|a| a == "--output").unwrap();
    let again = dir.join("again.exr");
    args[at + 1] = again.display().to_string();
    let st = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .args(&args)
        .arg("--quiet")
        .status()
        .unwrap();
    assert!(st.success());
    let batch = lapidary::image::read_exr(&again).unwrap();
    for c in &exported.channels {
        let b = batch.channels.iter().find(|b| b.name == c.name).unwrap();
        let same = c
            .data
            .iter()
            .zip(&b.data)
            .all(|(x, y)| x.to_bits() == y.to_bits());
        assert!(same, "channel {} differs", c.name);
    }
    batch
}
