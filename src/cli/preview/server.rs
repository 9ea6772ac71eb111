//! The preview's HTTP routes (served by [`super::http`], a thread per connection): the page, the
//! session's status as a long poll, images, the inspector, view and knob changes and the export.
//!
//! **Safe to leave running.** Every request must carry the session's random token (`t=`, 128
//! bits from the operating system); its `Host` must be the server's own address (a DNS-rebinding
//! page reaches the server under a foreign host name) and its `Origin`, when the browser sends
//! one, the server's own origin. No request names a file: the routes are fixed and the page is
//! compiled in. Connections, request heads and bodies are capped ([`super::http`]) and long polls
//! last at most [`LONG_POLL`], so nothing a client sends can hold the server.

use super::frame::{self, Aov};
use super::http::{Request, Response};
use super::state::{MAX_PIXELS, MAX_SPP, Shared};
use crate::image::ToneMap;
use serde_json::{Value, json};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

/// The page, compiled in.
pub const PAGE: &str = include_str!("page.html");
/// Longest a status request waits for a new frame.
pub const LONG_POLL: Duration = Duration::from_secs(10);

/// What a handler needs besides the request.
pub struct Context {
    /// The session.
    pub shared: Arc<Shared>,
    /// The token every request must carry.
    pub token: String,
    /// `host:port` values the `Host` header may have.
    pub hosts: Vec<String>,
    /// Where exports go.
    pub out_dir: PathBuf,
    /// The command line's knobs (what `{"reset": true}` restores).
    pub initial_knobs: crate::scene::Knobs,
}

/// A new random token (hex, 128 bits from the operating system's generator).
pub fn token() -> std::io::Result<String> {
    let mut b = [0u8; 16];
    getrandom::fill(&mut b).map_err(|e| std::io::Error::other(e.to_string()))?;
    Ok(b.iter().map(|x| format!("{x:02x}")).collect())
}

type Reply = Response;

fn reply(status: u16, content_type: &str, body: Vec<u8>) -> Reply {
    let h = |k: &str, v: &str| (k.to_string(), v.to_string());
    Response {
        status,
        headers: vec![
            h("Content-Type", content_type),
            h("Cache-Control", "no-store"),
            h("X-Content-Type-Options", "nosniff"),
            h("Referrer-Policy", "no-referrer"),
            h("X-Frame-Options", "DENY"),
        ],
        body,
    }
}

fn json_reply(status: u16, v: &Value) -> Reply {
    reply(status, "application/json", v.to_string().into_bytes())
}

fn error(status: u16, message: impl Into<String>) -> Reply {
    json_reply(status, &json!({ "error": message.into() }))
}

/// Splits a URL into its path and decoded query pairs.
fn split_url(url: &str) -> (&str, Vec<(String, String)>) {
    let (path, query) = url.split_once('?').unwrap_or((url, ""));
    let pairs = query
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (decode(k), decode(v))
        })
        .collect();
    (path, pairs)
}

/// Percent-decoding (`+` as a space); invalid escapes are kept as they are.
fn decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < b.len() => {
                let hex = |c: u8| (c as char).to_digit(16);
                match (hex(b[i + 1]), hex(b[i + 2])) {
                    (Some(h), Some(l)) => {
                        out.push((h * 16 + l) as u8);
                        i += 2;
                    }
                    _ => out.push(b'%'),
                }
            }
            c => out.push(c),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Constant-time comparison (the token must not leak through timing).
fn same(a: &str, b: &str) -> bool {
    a.len() == b.len()
        && a.bytes()
            .zip(b.bytes())
            .fold(0u8, |acc, (x, y)| acc | (x ^ y))
            == 0
}

/// Why a request is refused before routing, if it is.
fn refuse(ctx: &Context, req: &Request, query: &[(String, String)]) -> Option<Reply> {
    let get = |name: &str| req.header(name).map(str::to_string);
    match get("Host") {
        Some(h) if ctx.hosts.iter().any(|a| a.eq_ignore_ascii_case(&h)) => {}
        _ => {
            return Some(error(
                403,
                "unknown Host: this server answers only its own address",
            ));
        }
    }
    if let Some(origin) = get("Origin")
        && !ctx
            .hosts
            .iter()
            .any(|a| origin.eq_ignore_ascii_case(&format!("http://{a}")))
    {
        return Some(error(403, "cross-origin request refused"));
    }
    let token = query
        .iter()
        .find(|(k, _)| k == "t")
        .map(|(_, v)| v.as_str());
    if !token.is_some_and(|t| same(t, &ctx.token)) {
        return Some(error(
            403,
            "missing or wrong token: open the URL `lapidary preview` printed",
        ));
    }
    None
}

fn number<T: std::str::FromStr>(query: &[(String, String)], name: &str) -> Option<T> {
    query
        .iter()
        .find(|(k, _)| k == name)
        .and_then(|(_, v)| v.parse().ok())
}

fn text<'a>(query: &'a [(String, String)], name: &str) -> Option<&'a str> {
    query
        .iter()
        .find(|(k, _)| k == name)
        .map(|(_, v)| v.as_str())
}

/// Answers one request.
pub fn handle(ctx: &Context, req: &Request) -> Reply {
    let (path, query) = split_url(&req.target);
    if let Some(r) = refuse(ctx, req, &query) {
        return r;
    }
    ctx.shared.client_seen();
    match (req.method.as_str(), path) {
        ("GET", "/") => {
            let mut r = reply(200, "text/html; charset=utf-8", PAGE.into());
            r.headers.push((
                "Content-Security-Policy".into(),
                "default-src 'self'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
                 img-src 'self' blob: data:; connect-src 'self'; frame-ancestors 'none'"
                    .into(),
            ));
            r
        }
        ("GET", "/status") => status(ctx, req, &query),
        ("GET", "/frame.png") => frame_png(ctx, &query),
        ("GET", "/inspect") => inspect(ctx, &query),
        ("POST", "/view") => view(ctx, &req.body),
        ("POST", "/knobs") => knobs(ctx, &req.body),
        ("POST", "/export") => export(ctx, &query),
        (_, "/" | "/status" | "/frame.png" | "/inspect" | "/view" | "/export" | "/knobs") => {
            error(405, "method not allowed")
        }
        _ => error(404, "no such page"),
    }
}

/// The status JSON (see docs/preview.md).
pub fn status_json(ctx: &Context, s: &super::state::State) -> Value {
    let image = s.image.as_ref();
    let error_estimate = image.filter(|i| i.spp >= 2).map(|i| {
        // The relative standard error of the image's mean luminance.
        let (mut sum, mut var) = (0.0f64, 0.0f64);
        for p in &i.film.pixels {
            let m = p.mean().0;
            let v = p.variance_of_mean();
            sum += f64::from(0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2]);
            var +=
                f64::from(0.2126 * 0.2126 * v[0] + 0.7152 * 0.7152 * v[1] + 0.0722 * 0.0722 * v[2]);
        }
        if sum > 0.0 { var.sqrt() / sum } else { 0.0 }
    });
    let r = s.request;
    json!({
        "frame": s.frame,
        "generation": s.generation,
        "recipe": ctx.shared.recipe.display().to_string(),
        "state": s.phase.name(),
        // An image rendered with other knobs than the session's: the quick draft without the
        // calibration, or the last image before a knob change.
        "draft": image.is_some_and(|i| i.knobs != s.knobs),
        "spp": image.map_or(0, |i| i.spp),
        // Whether the image carries the Stokes vector (the page offers S0–S3 then).
        "stokes": image.is_some_and(|i| !i.film.stokes.is_empty()),
        "target_spp": r.spp,
        "paths_per_second": s.paths_per_second,
        "elapsed": s.generation_start.elapsed().as_secs_f64(),
        "render_seconds": s.render_seconds,
        "pauses": s.pauses,
        "paused_seconds": s.paused_seconds,
        "first_pixels": s.first_pixels,
        "error_estimate": error_estimate,
        "error": s.error,
        "size": [r.size.0, r.size.1],
        "view": {
            "yaw": r.view.yaw, "pitch": r.view.pitch, "zoom": r.view.zoom,
            "tilt_x": r.view.tilt_x, "tilt_z": r.view.tilt_z, "light_yaw": r.view.light_yaw,
            "rock": r.rock, "width": r.size.0, "height": r.size.1, "spp": r.spp,
        },
        "command": image.map(|i| frame::command(&ctx.shared.recipe, i, &i.knobs, None)),
        "knobs": s.knobs.to_string(),
        "knob_costs": s.knob_costs.iter().map(|c| json!({
            "key": c.key, "value": c.value, "before": c.before, "after": c.after,
            "ratio": c.before.zip(c.after).map(|(b, a)| a / b.max(1e-9)),
        })).collect::<Vec<_>>(),
        "knob_choices": super::choices::knob_choices(),
        "all_effects": crate::scene::Effect::ALL.iter().map(|e| e.name()).collect::<Vec<_>>(),
        "materials": image.map(|i| i.scene.surface.names.clone()),
        "effects": image.map(|i| i.scene.effects.iter().map(|e| e.name()).collect::<Vec<_>>()),
        "rebuild": {
            "materials_reused": s.rebuild.reused,
            "materials_built": s.rebuild.built,
            "seconds": s.rebuild.seconds,
        },
    })
}

fn status(ctx: &Context, req: &Request, query: &[(String, String)]) -> Reply {
    let Some(since) = number::<u64>(query, "since") else {
        return json_reply(200, &status_json(ctx, &ctx.shared.lock()));
    };
    // Waits in short slices, giving up when the client has gone (a reloaded or closed tab).
    let deadline = std::time::Instant::now() + LONG_POLL;
    loop {
        let left = deadline.saturating_duration_since(std::time::Instant::now());
        let s = ctx
            .shared
            .wait_newer(since, left.min(Duration::from_millis(250)));
        if s.frame > since || s.quit || left.is_zero() {
            return json_reply(200, &status_json(ctx, &s));
        }
        drop(s);
        if req.client_gone() {
            return error(400, "the client went away");
        }
    }
}

fn tone_map(query: &[(String, String)]) -> Result<ToneMap, Reply> {
    frame::tone_map(text(query, "exposure"), text(query, "tonemap")).map_err(|m| error(400, m))
}

fn frame_png(ctx: &Context, query: &[(String, String)]) -> Reply {
    let tm = match tone_map(query) {
        Ok(t) => t,
        Err(r) => return r,
    };
    let a = text(query, "aov").unwrap_or("color");
    let Some(aov) = Aov::parse(a) else {
        return error(
            400,
            format!(
                "aov `{a}`: expected color, albedo, normal, depth, material, cells, variance or \
                 s0 … s3 (with --stokes)"
            ),
        );
    };
    let image = ctx.shared.lock().image.clone();
    match image {
        Some(i) if matches!(aov, Aov::Stokes(_)) && i.film.stokes.is_empty() => error(
            404,
            format!(
                "aov `{a}`: this image has no Stokes vector (run `lapidary preview --stokes`; \
                 polarised transport must stay on)"
            ),
        ),
        Some(i) => reply(200, "image/png", frame::png(&i, aov, &tm)),
        None => error(404, "no image yet"),
    }
}

fn inspect(ctx: &Context, query: &[(String, String)]) -> Reply {
    let (Some(x), Some(y)) = (number::<u32>(query, "x"), number::<u32>(query, "y")) else {
        return error(400, "expected x and y pixel coordinates");
    };
    let image = ctx.shared.lock().image.clone();
    let Some(image) = image else {
        return error(404, "no image yet");
    };
    match super::inspect::inspect(&image, x, y) {
        Some(v) => json_reply(200, &v),
        None => error(400, format!("pixel ({x}, {y}) is outside the image")),
    }
}

/// Applies a view change (JSON object; see docs/preview.md).
fn view(ctx: &Context, body: &[u8]) -> Reply {
    let Ok(Value::Object(fields)) = serde_json::from_slice::<Value>(body) else {
        return error(400, "expected a JSON object of view fields");
    };
    let mut request = ctx.shared.lock().request;
    let mut v = request.view;
    for (k, val) in &fields {
        let num = || val.as_f64().map(|x| x as f32);
        let bad = |allowed: &str| error(400, format!("view `{k}` = {val}: {allowed}"));
        match k.as_str() {
            "reset" if val.as_bool() == Some(true) => {
                v = crate::scene::view::View::default();
                request.rock = false;
            }
            "reset" => {}
            "rock" => match val.as_bool() {
                Some(b) => request.rock = b,
                None => return bad("expected true or false"),
            },
            "yaw" | "pitch" | "zoom" | "tilt_x" | "tilt_z" | "light_yaw" => {
                let Some(x) = num() else {
                    return bad("expected a number");
                };
                match k.as_str() {
                    "yaw" => v.yaw = x,
                    "pitch" => v.pitch = x,
                    "zoom" => v.zoom = x,
                    "tilt_x" => v.tilt_x = x,
                    "tilt_z" => v.tilt_z = x,
                    _ => v.light_yaw = x,
                }
            }
            "width" | "height" => match val.as_u64() {
                Some(n @ 16..=2048) => {
                    if k == "width" {
                        request.size.0 = n as u32;
                    } else {
                        request.size.1 = n as u32;
                    }
                }
                _ => return bad("expected pixels in 16..=2048"),
            },
            "spp" => match val.as_u64() {
                Some(n) if (1..=u64::from(MAX_SPP)).contains(&n) => request.spp = n as u32,
                _ => return bad(&format!("expected samples per pixel in 1..={MAX_SPP}")),
            },
            other => {
                return error(
                    400,
                    format!(
                        "unknown view field `{other}` (expected yaw, pitch, zoom, tilt_x, tilt_z, \
                         light_yaw, rock, width, height, spp or reset)"
                    ),
                );
            }
        }
    }
    if u64::from(request.size.0) * u64::from(request.size.1) > MAX_PIXELS {
        return error(
            400,
            format!(
                "size {}x{}: at most {MAX_PIXELS} pixels (1024x768) in the preview",
                request.size.0, request.size.1
            ),
        );
    }
    if let Err(e) = v.check() {
        return error(400, e.to_string());
    }
    request.view = v.normalised();
    ctx.shared.set_request(|r| *r = request);
    let s = ctx.shared.lock();
    json_reply(200, &status_json(ctx, &s))
}

/// Sets accuracy knobs (JSON object of `knob: "value"` pairs, the keys and values of
/// `lapidary tradeoff`'s knobs, e.g. `{"model": "course", "facet-bump": "off"}`; `{"reset":
/// true}` goes back to the command line's): the recipe is compiled again with them.
fn knobs(ctx: &Context, body: &[u8]) -> Reply {
    let Ok(Value::Object(fields)) = serde_json::from_slice::<Value>(body) else {
        return error(400, "expected a JSON object of knobs");
    };
    if fields.len() > super::choices::MAX_KNOB_FIELDS {
        return error(
            400,
            format!(
                "at most {} knobs in one request",
                super::choices::MAX_KNOB_FIELDS
            ),
        );
    }
    let mut acc = ctx.shared.lock().knobs.clone();
    let mut changed = vec![];
    for (k, v) in &fields {
        if k == "reset" {
            if v.as_bool() == Some(true) {
                acc = ctx.initial_knobs.clone();
                changed.push(("reset".to_string(), "command line".to_string()));
            }
            continue;
        }

        let value = match v {
            Value::String(t) => t.clone(),
            Value::Bool(b) => (if *b { "on" } else { "off" }).to_string(),
            _ => return error(400, format!("knob `{k}`: expected a string or true/false")),
        };
        if k == "platelets" && !["on", "off"].contains(&value.to_ascii_lowercase().as_str()) {
            // `render` has no flag for explicit/statistical platelets: an export's command
            // could not repeat it. The effect's on/off is a knob like the others.
            return error(
                400,
                "knob `platelets`: on or off in the preview (explicit or statistical is set by \
                 `platelets:` in the recipe's `stage.render`)",
            );
        }
        if let Err(e) = acc.set(k, &value) {
            return error(400, e.to_string());
        }
        changed.push((k.clone(), value));
    }
    ctx.shared.set_knobs(acc, &changed);
    let s = ctx.shared.lock();
    json_reply(200, &status_json(ctx, &s))
}

fn export(ctx: &Context, query: &[(String, String)]) -> Reply {
    let tm = match tone_map(query) {
        Ok(t) => t,
        Err(r) => return r,
    };
    let (image, inputs) = {
        let s = ctx.shared.lock();
        (s.image.clone(), s.inputs.paths())
    };
    let Some(image) = image else {
        return error(409, "no image yet");
    };
    match frame::export(&ctx.shared.recipe, &image, &inputs, &ctx.out_dir, &tm) {
        Ok(v) => json_reply(200, &v),
        Err(e) => error(409, format!("{e:#}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn urls_split_and_decode() {
        let (p, q) = split_url("/inspect?t=ab%20c&x=3&y=+4&bad=%zz&end=%4");
        assert_eq!(p, "/inspect");
        assert_eq!(q[0], ("t".into(), "ab c".into()));
        assert_eq!(q[2], ("y".into(), " 4".into()));
        assert_eq!(q[3], ("bad".into(), "%zz".into()));
        assert_eq!(q[4], ("end".into(), "%4".into()));
        assert!(same("abc", "abc") && !same("abc", "abd") && !same("abc", "ab"));
        let t = token().unwrap();
        assert_eq!(t.len(), 32);
        assert_ne!(t, token().unwrap());
    }
}
