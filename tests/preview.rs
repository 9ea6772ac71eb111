//! `lapidary preview` end to end over HTTP (issue 38): the binary serves on an ephemeral port and
//! these tests talk to it with a plain HTTP/1.1 client — the security checks (token, Host,
//! Origin, methods, body size), progressive refinement, reload on save with only the edited
//! material rebuilt, errors shown and recovered from, view changes refused out of range, the
//! inspector, and an export that equals the batch command it prints, bit for bit.

mod preview_common;

use preview_common::{raw, scratch, start};
use serde_json::Value;
use std::io::Read;
use std::path::Path;
use std::time::Duration;

#[test]
fn refuses_requests_without_its_token_host_or_origin() {
    let p = start(&scratch("refuse"), &[]);
    let host = p.host();
    let ok = format!("/status?t={}", p.token);
    let code = |method: &str, target: &str, headers: &[(&str, &str)]| {
        raw(p.port, method, target, headers, b"").status
    };
    assert_eq!(code("GET", &ok, &[("Host", &host)]), 200);
    let localhost = format!("localhost:{}", p.port);
    assert_eq!(
        code("GET", &ok, &[("Host", &localhost)]),
        200,
        "localhost is the server's own name too"
    );
    assert_eq!(code("GET", "/status", &[("Host", &host)]), 403, "no token");
    assert_eq!(
        code("GET", "/status?t=0123", &[("Host", &host)]),
        403,
        "wrong token"
    );
    let mut wrong = p.token.clone();
    wrong.replace_range(0..1, if wrong.starts_with('0') { "1" } else { "0" });
    assert_eq!(
        code("GET", &format!("/status?t={wrong}"), &[("Host", &host)]),
        403
    );
    // DNS rebinding: the right token under a foreign host name.
    assert_eq!(
        code("GET", &ok, &[("Host", &format!("evil.example:{}", p.port))]),
        403
    );
    assert_eq!(code("GET", &ok, &[]), 403, "no Host at all");
    assert_eq!(
        code(
            "GET",
            &ok,
            &[("Host", &host), ("Origin", "http://evil.example")]
        ),
        403
    );
    assert_eq!(
        code(
            "GET",
            &ok,
            &[("Host", &host), ("Origin", &format!("http://{host}"))]
        ),
        200
    );
    // Fixed routes only: nothing names a file.
    for path in [
        "/etc/passwd",
        "/../Cargo.toml",
        "/page.html",
        "/lepidolite.ron",
    ] {
        assert_eq!(
            code("GET", &format!("{path}?t={}", p.token), &[("Host", &host)]),
            404,
            "{path}"
        );
    }
    assert_eq!(code("POST", &ok, &[("Host", &host)]), 405);
    assert_eq!(
        code(
            "DELETE",
            &format!("/view?t={}", p.token),
            &[("Host", &host)]
        ),
        405
    );
    // Bodies are bounded.
    let big = vec![b' '; 20_000];
    let r = raw(
        p.port,
        "POST",
        &format!("/view?t={}", p.token),
        &[("Host", &host)],
        &big,
    );
    assert_eq!(r.status, 413);
    // Connections are bounded: with 32 idle ones open, the next is refused at once (503) and the
    // server's threads stay bounded; once they close it answers again.
    let threads = || preview_common::proc_status(p.child.id(), "Threads");
    let idle: Vec<std::net::TcpStream> = (0..40)
        .map(|_| std::net::TcpStream::connect(("127.0.0.1", p.port)).unwrap())
        .collect();
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(code("GET", &ok, &[("Host", &host)]), 503);
    assert!(threads() < 32 + 16, "{} threads", threads());
    drop(idle);
    // Their threads see the close and free the slots (give a loaded machine a few seconds).
    let t0 = std::time::Instant::now();
    while code("GET", &ok, &[("Host", &host)]) != 200 {
        assert!(t0.elapsed() < Duration::from_secs(5), "slots not freed");
        std::thread::sleep(Duration::from_millis(50));
    }
    // Long polls of clients that went away (closed or reloaded tabs) free their connections
    // within a second, not at the end of the 10 s poll.
    let open_polls = || -> Vec<std::net::TcpStream> {
        (0..40)
            .map(|_| {
                let mut c = std::net::TcpStream::connect(("127.0.0.1", p.port)).unwrap();
                let req = format!(
                    "GET /status?since=999999999&t={} HTTP/1.1\r\nHost: {host}\r\n\r\n",
                    p.token
                );
                std::io::Write::write_all(&mut c, req.as_bytes()).unwrap();
                c
            })
            .collect()
    };
    // On a loaded machine the idle connections' threads above may still hold a few slots when
    // the polls arrive (those polls are refused, and the slots free up after): try again then.
    let mut polls = open_polls();
    let mut held = false;
    for _ in 0..5 {
        std::thread::sleep(Duration::from_millis(300));
        if code("GET", &ok, &[("Host", &host)]) == 503 {
            held = true;
            break;
        }
        drop(polls);
        std::thread::sleep(Duration::from_millis(700));
        polls = open_polls();
    }
    assert!(held, "32 long polls never held the slots");
    drop(polls);
    let t0 = std::time::Instant::now();
    while code("GET", &ok, &[("Host", &host)]) != 200 {
        // Each poll notices its client's close within 250 ms; 5 s allows a loaded machine
        // (without the check they would hold their slots for the whole 10 s poll).
        assert!(
            t0.elapsed() < Duration::from_secs(5),
            "abandoned polls still hold their slots"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    eprintln!(
        "abandoned long polls freed in {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    // The page: compiled in, nothing fetched from elsewhere (its policy forbids it too).
    let page = p.get("/");
    assert_eq!(page.status, 200);
    let csp = page.header("content-security-policy").unwrap();
    assert!(csp.contains("default-src 'self'"), "{csp}");
    let html = String::from_utf8(page.body.clone()).unwrap();
    for external in [
        "src=\"http",
        "href=\"http",
        "src='http",
        "@import",
        "url(http",
    ] {
        assert!(!html.contains(external), "the page loads {external}…");
    }
    assert!(html.contains("/status") && html.contains("/frame.png"));
}

#[test]
fn refines_reloads_on_save_and_recovers_from_errors() {
    let dir = scratch("reload");
    let p = start(&dir, &[]);
    let s = p.wait("two samples per pixel", |s| s["spp"].as_u64() >= Some(2));
    assert!(s["error"].is_null());
    assert!(s["first_pixels"].as_f64().unwrap() > 0.0);
    let png = p.get("/frame.png?aov=color&exposure=1&tonemap=clamp");
    assert_eq!(png.status, 200);
    assert_eq!(png.header("content-type"), Some("image/png"));
    assert_eq!(&png.body[1..4], b"PNG");
    for aov in ["albedo", "normal", "depth", "material", "cells", "variance"] {
        assert_eq!(p.get(&format!("/frame.png?aov={aov}")).status, 200, "{aov}");
    }
    assert_eq!(p.get("/frame.png?aov=nope").status, 400);
    assert_eq!(p.get("/frame.png?exposure=99").status, 400);
    let done = p.wait("the budget", |s| s["state"] == "done");
    assert_eq!(done["spp"], 8);
    assert_eq!(
        done["draft"], false,
        "the refined image has the session's knobs"
    );
    let generation = done["generation"].as_u64().unwrap();

    // A one-number edit of one material: a new generation that rebuilds that material only.
    let recipe = dir.join("lepidolite.ron");
    let text = std::fs::read_to_string(&recipe).unwrap();
    let edited = text.replacen("Srgb(0.42, 0.33, 0.47)", "Srgb(0.52, 0.33, 0.47)", 1);
    assert_ne!(edited, text);
    std::fs::write(&recipe, &edited).unwrap();
    let s = p.wait("the reload", |s| {
        s["generation"].as_u64() > Some(generation) && s["spp"].as_u64() >= Some(1)
    });
    assert_eq!(s["rebuild"]["materials_built"], 1, "{s}");
    assert_eq!(s["rebuild"]["materials_reused"], 19, "{s}");

    // A broken recipe: the positioned error of `lapidary check`, over the last good image.
    let broken = edited.replacen("roughness: 5.0)", "roughness: 500.0)", 1);
    assert_ne!(broken, edited);
    std::fs::write(&recipe, &broken).unwrap();
    let s = p.wait("the error", |s| !s["error"].is_null());
    let e = s["error"].as_str().unwrap();
    assert!(
        e.contains("lepidolite.ron:") && e.contains("out of range"),
        "{e}"
    );
    assert!(e.contains("allowed"), "{e}");
    assert_eq!(s["state"], "error");
    assert_eq!(p.get("/frame.png").status, 200, "the last good image stays");
    // Fixed again: renders without a restart.
    std::fs::write(&recipe, &text).unwrap();
    let s = p.wait("the recovery", |s| {
        s["error"].is_null() && s["spp"].as_u64() >= Some(1)
    });
    assert_eq!(
        s["rebuild"]["materials_built"], 0,
        "every material was built before: {s}"
    );
}

#[test]
fn views_are_checked_and_the_export_equals_its_batch_command() {
    let dir = scratch("export");
    let p = start(&dir, &[]);
    p.wait("the first image", |s| s["spp"].as_u64() >= Some(1));
    for (body, want) in [
        (r#"{"pitch": 90}"#, "-85..=85"),
        (r#"{"zoom": 0}"#, "0.1..=10"),
        (r#"{"tilt_x": -61}"#, "-60..=60"),
        (r#"{"width": 5000}"#, "16..=2048"),
        (r#"{"spp": 0}"#, "1..=65536"),
        (r#"{"fov": 3}"#, "unknown view field"),
        (r#"[1, 2]"#, "JSON object"),
        (r#"{"width": 2048, "height": 2048}"#, "at most"),
    ] {
        let r = p.post("/view", body);
        assert_eq!(r.status, 400, "{body}");
        assert!(
            r.json()["error"].as_str().unwrap().contains(want),
            "{body}: {}",
            r.json()
        );
    }
    let before = p.status()["generation"].as_u64().unwrap();
    let r = p.post(
        "/view",
        r#"{"yaw": 390, "pitch": -10, "zoom": 0.8, "light_yaw": 45, "tilt_z": 5}"#,
    );
    assert_eq!(r.status, 200);
    assert_eq!(r.json()["view"]["yaw"], 30.0, "yaw wraps");
    let s = p.wait("the new view's budget", |s| {
        s["generation"].as_u64() > Some(before) && s["state"] == "done"
    });
    assert_eq!(s["spp"], 8);

    // The inspector: the stone at the centre, the sky or floor at a corner.
    let centre = p.get("/inspect?x=32&y=24").json();
    assert_eq!(centre["hit"], "stone", "{centre}");
    let name = centre["material"]["name"].as_str().unwrap();
    assert!(s["materials"].as_array().unwrap().iter().any(|m| m == name));
    assert_eq!(centre["spp"], 8);
    assert_eq!(centre["radiance"].as_array().unwrap().len(), 3);
    assert_eq!(p.get("/inspect?x=64&y=0").status, 400);
    assert_eq!(p.get("/inspect?x=a").status, 400);

    let r = p.post("/export", "");
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let v = r.json();
    let command = v["command"].as_str().unwrap();
    assert!(
        command.contains("--view yaw=30,pitch=-10,zoom=0.8,tilt_z=5,light_yaw=45"),
        "{command}"
    );
    assert!(Path::new(v["png"].as_str().unwrap()).is_file());
    // The printed command, run to another file, gives the same pixels bit for bit.
    let batch = preview_common::export_is_its_command(&v, &p.dir);
    assert_eq!((batch.width, batch.height), (64, 48));
    // The command without --output is what the page shows.
    assert!(
        p.status()["command"]
            .as_str()
            .unwrap()
            .starts_with("lapidary render ")
    );
}

#[test]
fn a_recipe_that_vanishes_or_becomes_a_folder_is_an_error_not_a_panic() {
    let dir = scratch("vanish");
    let p = start(&dir, &[]);
    p.wait("the first image", |s| s["spp"].as_u64() >= Some(1));
    let recipe = dir.join("lepidolite.ron");
    let text = std::fs::read_to_string(&recipe).unwrap();
    std::fs::remove_file(&recipe).unwrap();
    let s = p.wait("the missing file's error", |s| !s["error"].is_null());
    assert!(
        s["error"].as_str().unwrap().contains("lepidolite.ron"),
        "{s}"
    );
    std::fs::create_dir(&recipe).unwrap();
    std::fs::write(recipe.join("x"), "x").unwrap();
    // Still answering, still showing an error and the last image.
    let s = p.status();
    assert!(!s["error"].is_null(), "{s}");
    assert_eq!(p.get("/frame.png").status, 200);
    std::fs::remove_dir_all(&recipe).unwrap();
    std::fs::write(&recipe, text).unwrap();
    p.wait("the recovery", |s| {
        s["error"].is_null() && s["state"] == "done"
    });
}

#[test]
fn a_closed_page_pauses_the_render_and_knobs_recompile() {
    let dir = scratch("idle");
    let p = start(&dir, &["--idle", "1", "--spp", "65536"]);
    // The calibrated image (the session's first is a draft, shown while the tables build).
    p.wait("the first refined image", |s| {
        s["spp"].as_u64() >= Some(1) && s["draft"] == false && s["state"] == "rendering"
    });
    // Nobody asks for 2.5 s: the worker stops starting ranges and counts a pause. (Asking for
    // the status is a request too, which ends the pause, so the state its answer reads may
    // already be `rendering` again: the count is what shows the pause. On a loaded machine the
    // range in flight may outlast the idle second, so the quiet spell is tried again, up to six
    // times.)
    let mut paused = Value::Null;
    for _ in 0..6 {
        std::thread::sleep(Duration::from_millis(2500));
        paused = p.status();
        if paused["pauses"].as_u64() >= Some(1) {
            break;
        }
    }
    assert!(paused["pauses"].as_u64() >= Some(1), "{paused}");
    let spp = paused["spp"].as_u64().unwrap();
    // Coming back resumes the same accumulation, and the pause's time is counted.
    let s = p.wait("more samples", |s| s["spp"].as_u64() > Some(spp));
    assert_eq!(s["generation"], paused["generation"]);
    assert!(s["paused_seconds"].as_f64() > Some(0.0), "{s}");

    // Knobs: a bad value names the allowed ones; a good one recompiles and the command
    // line repeats it.
    let r = p.post("/knobs", r#"{"model": "nonsense"}"#);
    assert_eq!(r.status, 400);
    assert!(
        r.json()["error"].as_str().unwrap().contains("course"),
        "{}",
        r.json()
    );
    let r = p.post("/knobs", r#"{"model": "course", "facet-bump": false}"#);
    assert_eq!(r.status, 200, "{}", r.json());
    let s = p.wait("the knobs' image", |s| {
        s["command"]
            .as_str()
            .is_some_and(|c| c.contains("--model course") && c.contains("--effect facet-bump=off"))
            && s["spp"].as_u64() >= Some(1)
    });
    assert!(
        !s["effects"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e == "facet-bump"),
        "{s}"
    );
    let r = p.post("/knobs", r#"{"reset": true}"#);
    assert_eq!(r.status, 200);
    p.wait("the reset", |s| {
        s["command"]
            .as_str()
            .is_some_and(|c| !c.contains("--model"))
            && s["spp"].as_u64() >= Some(1)
    });
}

#[test]
fn streams_the_image_to_a_tev_viewer() {
    // A stand-in for tev: accepts one connection and reads its packets.
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let dir = scratch("tev");
    let p = start(&dir, &["--tev", &addr]);
    let (mut conn, _) = listener.accept().unwrap();
    conn.set_read_timeout(Some(Duration::from_secs(120)))
        .unwrap();
    let mut read_packet = || {
        let mut len = [0u8; 4];
        conn.read_exact(&mut len).unwrap();
        let n = u32::from_le_bytes(len) as usize;
        assert!((6..1 << 24).contains(&n), "packet length {n}");
        let mut rest = vec![0u8; n - 4];
        conn.read_exact(&mut rest).unwrap();
        rest
    };
    let create = read_packet();
    assert_eq!(create[0], 4, "create image first");
    let name_end = 2 + create[2..].iter().position(|&b| b == 0).unwrap();
    assert!(String::from_utf8_lossy(&create[2..name_end]).contains("lepidolite"));
    let int = |b: &[u8], at: usize| i32::from_le_bytes(b[at..at + 4].try_into().unwrap());
    assert_eq!(
        (int(&create, name_end + 1), int(&create, name_end + 5)),
        (64, 48)
    );
    // Updates cover the whole image with finite, non-negative values.
    let mut covered = vec![false; 64 * 48];
    while covered.iter().any(|c| !c) {
        let u = read_packet();
        if u[0] == 4 {
            continue;
        }
        assert_eq!(u[0], 6);
        let at = name_end + 1 + 4 + 6;
        let (x, y, w, h) = (
            int(&u, at),
            int(&u, at + 4),
            int(&u, at + 8),
            int(&u, at + 12),
        );
        let data = &u[at + 16 + 48..];
        assert_eq!(data.len(), (w * h * 3 * 4) as usize);
        for v in data.chunks_exact(4) {
            let v = f32::from_le_bytes(v.try_into().unwrap());
            assert!(v.is_finite() && v >= 0.0, "{v}");
        }
        for yy in y..y + h {
            for xx in x..x + w {
                covered[(yy * 64 + xx) as usize] = true;
            }
        }
    }
    drop(p);
}

/// `preview --stokes` on a glass sphere between crossed polars: the status says the image carries
/// the Stokes vector, the S0–S3 views are PNGs (S1 lit where the light box's polarised light
/// reaches the camera), the inspector gives the vector, and the export — its batch command says
/// `--stokes` — writes S0–S3 equal to the command's bit for bit. Without the flag the status says
/// no and a Stokes view is refused, naming the flag.
#[test]
fn stokes_views_the_inspector_and_the_export() {
    let polariscope = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/polariscope-glass-sphere.ron"),
    )
    .unwrap();
    let dir = scratch("stokes");
    // The scratch's recipe file, now holding the polariscope scene.
    std::fs::write(dir.join("lepidolite.ron"), &polariscope).unwrap();
    let p = start(&dir, &["--stokes"]);
    let s = p.wait("the budget", |s| s["state"] == "done");
    assert_eq!(s["stokes"], true, "{s}");
    for k in 0..4 {
        let r = p.get(&format!("/frame.png?aov=s{k}"));
        assert_eq!(r.status, 200, "s{k}");
        assert_eq!(&r.body[1..4], b"PNG");
        if k == 1 {
            let img = image::load_from_memory(&r.body).unwrap().to_rgb8();
            assert!(
                img.pixels().any(|px| px[0] > 64),
                "S1 shows polarised light"
            );
        }
    }
    let centre = p.get("/inspect?x=32&y=24").json();
    assert_eq!(
        centre["stokes"].as_array().map(Vec::len),
        Some(4),
        "{centre}"
    );
    let r = p.post("/export", "");
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let v = r.json();
    assert!(v["command"].as_str().unwrap().contains(" --stokes"), "{v}");
    let batch = preview_common::export_is_its_command(&v, &p.dir);
    assert!(batch.channel("S1.G").is_some());
    drop(p);

    let plain = scratch("stokes-off");
    std::fs::write(plain.join("lepidolite.ron"), &polariscope).unwrap();
    let q = start(&plain, &[]);
    let s = q.wait("the first image", |s| s["spp"].as_u64() >= Some(1));
    assert_eq!(s["stokes"], false);
    let r = q.get("/frame.png?aov=s2");
    assert_eq!(r.status, 404);
    assert!(String::from_utf8_lossy(&r.body).contains("--stokes"));
}
