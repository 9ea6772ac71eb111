//! Streaming the progressive image to the tev viewer (`--tev [HOST:PORT]`), as pbrt-v4's
//! `--display-server` does: tev listens on TCP (port 14158 by default) for length-prefixed
//! packets. The layout used here (all integers little-endian) is tev's documented IPC protocol
//! (tev's `src/python/ipc.py`, BSD-3-Clause; facts only, no code taken):
//!
//! * every packet: `u32` total length (these four bytes included), `u8` type, payload;
//! * create image (type 4): `u8` grab focus, image name (UTF-8, NUL-terminated), `i32` width,
//!   `i32` height, `i32` channel count, channel names (NUL-terminated);
//! * update image, version 3 (type 6): `u8` grab focus, image name, `i32` channel count, channel
//!   names, `i32` x, `i32` y, `i32` width, `i32` height, per channel an `i64` offset, then per
//!   channel an `i64` stride (in floats, into the pixel data), then the `f32` pixel data.
//!
//! Only the newest image is sent (a slow viewer skips frames; nothing queues), in tiles of at
//! most [`TILE`]² pixels so that each packet stays small.

use super::state::{Image, Shared};
use std::io::Write;
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::sync::Arc;
use std::time::Duration;

/// tev's default IPC port.
pub const DEFAULT_PORT: u16 = 14158;
/// Tile edge of an update packet, pixels.
pub const TILE: u32 = 128;

/// Parses `--tev` values: `HOST:PORT`, `HOST` (default port) or empty (`127.0.0.1:14158`).
pub fn parse_address(s: &str) -> Result<SocketAddr, String> {
    let s = s.trim();
    let with_port = if s.is_empty() {
        format!("127.0.0.1:{DEFAULT_PORT}")
    } else if s
        .rsplit_once(':')
        .is_some_and(|(_, p)| p.parse::<u16>().is_ok())
    {
        s.to_string()
    } else {
        format!("{s}:{DEFAULT_PORT}")
    };
    with_port
        .to_socket_addrs()
        .map_err(|e| format!("`{s}`: not a host and port ({e})"))?
        .next()
        .ok_or_else(|| format!("`{s}`: the name resolves to no address"))
}

fn string(out: &mut Vec<u8>, s: &str) {
    out.extend_from_slice(s.as_bytes());
    out.push(0);
}

fn finish(mut packet: Vec<u8>) -> Vec<u8> {
    let len = packet.len() as u32;
    packet[0..4].copy_from_slice(&len.to_le_bytes());
    packet
}

/// The create-image packet of an image `name` of `width × height` with channels R, G, B.
pub fn create_packet(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut p = vec![0, 0, 0, 0, 4, 0];
    string(&mut p, name);
    for v in [width as i32, height as i32, 3] {
        p.extend_from_slice(&v.to_le_bytes());
    }
    for c in ["R", "G", "B"] {
        string(&mut p, c);
    }
    finish(p)
}

/// The update packets (version 3) carrying `rgb` (row-major, `width × height`), tile by tile.
pub fn update_packets(name: &str, width: u32, height: u32, rgb: &[[f32; 3]]) -> Vec<Vec<u8>> {
    let mut packets = Vec::new();
    for y0 in (0..height).step_by(TILE as usize) {
        for x0 in (0..width).step_by(TILE as usize) {
            let (w, h) = (TILE.min(width - x0), TILE.min(height - y0));
            let mut p = vec![0, 0, 0, 0, 6, 0];
            string(&mut p, name);
            p.extend_from_slice(&3i32.to_le_bytes());
            for c in ["R", "G", "B"] {
                string(&mut p, c);
            }
            for v in [x0 as i32, y0 as i32, w as i32, h as i32] {
                p.extend_from_slice(&v.to_le_bytes());
            }
            // Interleaved RGB: channel c starts at float c, every third float.
            for offset in 0..3i64 {
                p.extend_from_slice(&offset.to_le_bytes());
            }
            for _ in 0..3 {
                p.extend_from_slice(&3i64.to_le_bytes());
            }
            for y in y0..y0 + h {
                for x in x0..x0 + w {
                    for c in rgb[(y * width + x) as usize] {
                        p.extend_from_slice(&c.to_le_bytes());
                    }
                }
            }
            packets.push(finish(p));
        }
    }
    packets
}

/// The image as tev shows it: the mean radiance at the requested size (a quick low-resolution
/// frame enlarged).
fn pixels(image: &Image) -> (u32, u32, Vec<[f32; 3]>) {
    let f = &image.film;
    let s = image.scale.max(1);
    let (w, h) = (f.width * s, f.height * s);
    let rgb = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| f.pixels[((y / s) * f.width + x / s) as usize].mean().0)
        .collect();
    (w, h, rgb)
}

/// Streams the session's images to tev at `addr` until the session quits. A viewer that is not
/// there (yet) or goes away is retried every two seconds; one warning says so.
pub fn stream(shared: &Arc<Shared>, addr: SocketAddr, name: &str) {
    let mut conn: Option<TcpStream> = None;
    let mut warned = false;
    let mut sent_frame = 0u64;
    let mut size = (0, 0);
    loop {
        let image = {
            let s = shared.wait_newer(sent_frame, Duration::from_secs(2));
            if s.quit {
                return;
            }
            sent_frame = s.frame;
            s.image.clone()
        };
        let Some(image) = image else { continue };
        if conn.is_none() {
            match TcpStream::connect_timeout(&addr, Duration::from_secs(1)) {
                Ok(c) => {
                    let _ = c.set_write_timeout(Some(Duration::from_secs(5)));
                    conn = Some(c);
                    size = (0, 0);
                    warned = false;
                }
                Err(e) => {
                    if !warned {
                        eprintln!("warning: tev at {addr}: {e} (retrying every 2 s)");
                        warned = true;
                    }
                    std::thread::sleep(Duration::from_secs(2));
                    continue;
                }
            }
        }
        let (w, h, rgb) = pixels(&image);
        let mut packets = Vec::new();
        if (w, h) != size {
            packets.push(create_packet(name, w, h));
        }
        packets.extend(update_packets(name, w, h, &rgb));
        let ok = conn
            .as_mut()
            .is_some_and(|c| packets.iter().all(|p| c.write_all(p).is_ok()));
        if ok {
            size = (w, h);
        } else {
            conn = None;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packets_have_tevs_layout() {
        let p = create_packet("gem", 300, 2);
        assert_eq!(
            u32::from_le_bytes(p[0..4].try_into().unwrap()) as usize,
            p.len()
        );
        assert_eq!(&p[4..6], &[4, 0]);
        assert_eq!(&p[6..10], b"gem\0");
        assert_eq!(i32::from_le_bytes(p[10..14].try_into().unwrap()), 300);
        assert_eq!(&p[22..], b"R\0G\0B\0");
        let rgb: Vec<[f32; 3]> = (0..600).map(|i| [i as f32, 0.5, -1.0]).collect();
        let ups = update_packets("gem", 300, 2, &rgb);
        // 300 wide: tiles of 128, 128 and 44 columns.
        assert_eq!(ups.len(), 3);
        let last = &ups[2];
        assert_eq!(
            u32::from_le_bytes(last[0..4].try_into().unwrap()) as usize,
            last.len()
        );
        assert_eq!(last[4], 6);
        let head = 6 + 4 + 4 + 6; // type, focus, "gem\0", count, "R\0G\0B\0"
        let int =
            |k: usize| i32::from_le_bytes(last[head + 4 * k..head + 4 * k + 4].try_into().unwrap());
        assert_eq!((int(0), int(1), int(2), int(3)), (256, 0, 44, 2));
        let data = head + 16 + 48;
        assert_eq!(last.len() - data, 44 * 2 * 3 * 4);
        let first = f32::from_le_bytes(last[data..data + 4].try_into().unwrap());
        assert_eq!(first, 256.0, "pixel (256, 0), red");
        assert!(parse_address("").unwrap().port() == DEFAULT_PORT);
        assert_eq!(parse_address("127.0.0.1:9").unwrap().port(), 9);
        assert!(parse_address("nonsense host with spaces").is_err());
    }
}
