//! `lapidary preview RECIPE`: author a gem live in the browser (docs/preview.md). A page served
//! from the binary shows the recipe's image refining progressively; saving the recipe or any file
//! it reads re-renders it (only the materials an edit changed are rebuilt), a broken recipe shows
//! its positioned errors over the last good image, and the page orbits, tilts and rocks the
//! stone, turns the lights, shows the AOVs, inspects a pixel and exports the view with the batch
//! command that renders it again.
//!
//! Layout: [`session`] (the render worker and its state), [`progressive`] (how one generation
//! refines), [`tev`] (streaming to the tev viewer), [`watch`] (the recipe's files), [`server`] (HTTP:
//! routes and the checks that make it safe to leave running), [`frame`] (PNGs, the inspector,
//! the export), `page.html` (the page, compiled in).

pub mod choices;
pub mod frame;
pub mod http;
pub mod inspect;
pub mod progressive;
pub mod server;
pub mod session;
pub mod state;
pub mod tev;
pub mod watch;

use anyhow::{Context as _, Result, bail};
use clap::Args;
use state::{MAX_PIXELS, MAX_SPP, Request, Shared};
use std::io::Write as _;
use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

/// Arguments of `lapidary preview`.
#[derive(Debug, Args)]
pub struct PreviewArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// TCP port (0: any free port; the URL printed says which).
    #[arg(long, default_value_t = 7878)]
    pub port: u16,
    /// Image size `WxH` (at most 1024x768 pixels in the preview).
    #[arg(long, value_parser = super::render::parse_size, default_value = "320x240")]
    pub size: (u32, u32),
    /// Stop refining after this many seconds of rendering (default: at the spp budget only).
    #[arg(long, value_parser = super::render::parse_seconds)]
    pub time_budget: Option<f64>,
    /// Refinement budget in samples per pixel.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(1..=i64::from(MAX_SPP)))]
    pub spp: u32,
    /// Open the page in the default browser (`xdg-open`).
    #[arg(long)]
    pub open: bool,
    /// Listen on this address instead of 127.0.0.1 (anyone who can reach it and knows the token
    /// can use the preview: a warning is printed).
    #[arg(long)]
    pub bind: Option<IpAddr>,
    /// Folder the page's export writes to (default: the current folder).
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
    /// Pause rendering when no page has asked for anything for this many seconds (a closed
    /// tab); it resumes when a page comes back.
    #[arg(long, default_value_t = 30.0, value_parser = super::render::parse_seconds)]
    pub idle: f64,
    /// Also stream the progressive image to the tev viewer over its IPC protocol (`HOST:PORT`;
    /// `--tev` alone: 127.0.0.1:14158, tev's default).
    #[arg(long, num_args = 0..=1, default_missing_value = "", value_parser = tev::parse_address)]
    pub tev: Option<SocketAddr>,
    /// Also measure the Stokes vector of the light reaching the camera (polarised transport, as
    /// `render --stokes`): the page shows S0–S3 and the export writes them as AOVs.
    #[arg(long)]
    pub stokes: bool,
    /// Accuracy knobs (override the recipe's), as for `render`.
    #[command(flatten)]
    pub knobs: super::knobs::KnobArgs,
}

/// A running preview: its address, token and session; [`Running::stop`] shuts it down.
pub struct Running {
    /// The page's URL (token included).
    pub url: String,
    /// The session.
    pub shared: Arc<Shared>,
    server: http::Server,
    threads: Vec<std::thread::JoinHandle<()>>,
}

impl Running {
    /// Stops the worker and the handlers and waits for them.
    pub fn stop(self) {
        self.server.stop();
        self.shared.quit();
        for t in self.threads {
            let _ = t.join();
        }
    }
}

/// Starts the server and the worker (returns once it listens).
pub fn start(args: &PreviewArgs) -> Result<Running> {
    let (w, h) = args.size;
    if u64::from(w) * u64::from(h) > MAX_PIXELS {
        bail!("--size {w}x{h}: at most {MAX_PIXELS} pixels (1024x768) in the preview");
    }
    std::fs::metadata(&args.recipe)
        .with_context(|| format!("{}: cannot read the recipe", args.recipe.display()))?;
    let knobs = crate::scene::Knobs {
        accuracy: super::knobs::with_stokes(
            args.knobs.accuracy().map_err(anyhow::Error::msg)?,
            args.stokes,
        )?,
        ..Default::default()
    };
    let ip = args.bind.unwrap_or(IpAddr::V4(Ipv4Addr::LOCALHOST));
    if !ip.is_loopback() {
        eprintln!(
            "warning: --bind {ip}: the preview is reachable from other machines; anyone who \
             learns its URL (with the token) can use it"
        );
    }
    let listener = std::net::TcpListener::bind(SocketAddr::new(ip, args.port))
        .with_context(|| format!("cannot listen on {ip}:{} (try --port 0)", args.port))?;
    let port = listener.local_addr()?.port();
    let token = server::token().context("no random token from the operating system")?;
    let host = match ip {
        IpAddr::V6(v6) => format!("[{v6}]:{port}"),
        IpAddr::V4(v4) => format!("{v4}:{port}"),
    };
    let mut hosts = vec![host.clone(), format!("localhost:{port}")];
    if ip.is_loopback() {
        hosts.push(format!("127.0.0.1:{port}"));
        hosts.push(format!("[::1]:{port}"));
    }
    hosts.dedup();
    let shared = Shared::new(
        args.recipe.clone(),
        Request {
            view: crate::scene::view::View::default(),
            rock: false,
            size: args.size,
            spp: args.spp,
            seconds: args.time_budget,
        },
        knobs.clone(),
        args.threads.map(|t| t as usize),
        Duration::from_secs_f64(args.idle),
        args.stokes,
    );
    if let Ok(mut w) = shared.watcher.lock() {
        *w = watch_inputs(&shared);
    }
    let ctx = Arc::new(server::Context {
        shared: Arc::clone(&shared),
        token: token.clone(),
        hosts,
        out_dir: args.out.clone(),
        initial_knobs: knobs,
    });
    let mut threads = Vec::new();
    {
        let shared = Arc::clone(&shared);
        threads.push(std::thread::spawn(move || session::run_worker(&shared)));
    }
    if let Some(addr) = args.tev {
        // tev on another machine gets the images unencrypted: say so as for --bind.
        if !addr.ip().is_loopback() {
            eprintln!("warning: --tev {addr}: the images go over the network unencrypted");
        }
        let shared = Arc::clone(&shared);
        let name = format!(
            "lapidary: {}",
            args.recipe
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy()
        );
        threads.push(std::thread::spawn(move || {
            tev::stream(&shared, addr, &name)
        }));
    }
    let handler = move |req: http::Request| {
        // A panic in one request must not take the server down.
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| server::handle(&ctx, &req)))
            .unwrap_or_else(|_| http::Response {
                status: 500,
                headers: vec![],
                body: b"internal error".to_vec(),
            })
    };
    let server = http::Server::start(listener, Arc::new(handler))?;
    Ok(Running {
        url: format!("http://{host}/?t={token}"),
        shared,
        server,
        threads,
    })
}

/// Runs `lapidary preview` until Ctrl-C.
pub fn run(args: &PreviewArgs) -> Result<()> {
    let stop = super::render::interrupted();
    let running = start(args)?;
    outln!("lapidary preview: {}", running.url);
    outln!("  watching {} (Ctrl-C stops)", args.recipe.display());
    let _ = std::io::stdout().flush();
    if args.open
        && let Err(e) = std::process::Command::new("xdg-open")
            .arg(&running.url)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
    {
        eprintln!("warning: could not open a browser (xdg-open: {e}); open the URL above");
    }
    while !stop.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(100));
    }
    running.stop();
    Ok(())
}

/// Starts watching the session's input folders; the returned watcher must be kept alive (and
/// [`rewatch`] called when the inputs change). `None` when the platform's watcher cannot start:
/// the worker's modification-time checks still notice saves.
fn watch_inputs(shared: &Arc<Shared>) -> Option<notify::RecommendedWatcher> {
    use notify::{EventKind, Watcher};
    let weak = Arc::downgrade(shared);
    let mut watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
        let Ok(event) = event else { return };
        if matches!(event.kind, EventKind::Access(_)) {
            return;
        }
        let Some(shared) = weak.upgrade() else { return };
        let hit = {
            let s = shared.lock();
            event.paths.iter().any(|p| s.inputs.contains(p))
        };
        if hit {
            shared.files_changed();
        }
    })
    .ok()?;
    for dir in shared.lock().inputs.dirs() {
        let _ = watcher.watch(&dir, notify::RecursiveMode::NonRecursive);
    }
    Some(watcher)
}
