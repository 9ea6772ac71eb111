//! `lapidary cut RECIPE [--tilts 0,10,20,30] [--out DIR]`: the stone face-up under the cut
//! report's lightings ([`report`]: ISO, COS, ASET; [`sparkle`]: the spots) at each tilt — a
//! contact sheet (PNG), a CSV and tables of light return, the ASET shares and leakage,
//! extinction, contrast, fire, sparkles and scintillation, and for a stone with platelets the
//! share of pixels showing the schiller flash ([`schiller`]), each with its standard error
//! (docs/cuts.md).
//!
//! The stone is seen along −y through an orthographic camera framing its bounds, the floor and
//! the recipe's lights removed, the environment replaced by the lighting; a tilt turns the stone
//! about the x axis through its centre (`scene::view::View`, as the preview tilts it). Renders
//! are deterministic: the same recipe, seed and spp give the same report for any thread count.

pub mod report;
pub mod schiller;
pub mod sparkle;
mod table;

use super::load::load_scene;
use crate::image::outputs::{Format, OutputPlan};
use crate::render::world::Hit;
use crate::render::{CameraRays, Control, World, render_scene};
use crate::scene::Accuracy;
use crate::scene::stage::{Camera, Environment, Projection};
use crate::scene::view::View;
use anyhow::{Context as _, Result, bail};
use clap::Args;
use glam::{Vec2, Vec3};
use report::{Estimate, Lighting};
use std::path::PathBuf;

/// Most tilts one report renders.
pub const MAX_TILTS: usize = 16;

/// Arguments of `lapidary cut`.
#[derive(Debug, Args)]
pub struct CutArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Tilts of the stone about the x axis, degrees, comma-separated (each −60 ..= 60, at most 16).
    #[arg(long, default_value = "0,10,20,30", value_parser = parse_tilts)]
    pub tilts: Tilts,
    /// Image size of each view in pixels (square).
    #[arg(long, default_value_t = 192, value_parser = clap::value_parser!(u32).range(16..=1024))]
    pub size: u32,
    /// Samples per pixel of each view.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub spp: u32,
    /// Folder the contact sheet (`NAME-cut.png`) and the CSV (`NAME-cut.csv`) go to.
    #[arg(long, default_value = ".")]
    pub out: PathBuf,
    /// Worker threads (default: one per core).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub threads: Option<u32>,
}

/// A list of tilts, degrees.
#[derive(Clone, Debug, PartialEq)]
pub struct Tilts(pub Vec<f32>);

fn parse_tilts(s: &str) -> Result<Tilts, String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| {
            t.trim()
                .parse::<f32>()
                .ok()
                .filter(|x| (-60.0..=60.0).contains(x))
                .ok_or_else(|| format!("`{}`: each tilt is degrees in −60 ..= 60", t.trim()))
        })
        .collect::<Result<_, _>>()?;
    if v.is_empty() || v.len() > MAX_TILTS {
        return Err(format!("{} tilts: allowed 1 ..= {MAX_TILTS}", v.len()));
    }
    Ok(Tilts(v))
}

/// One tilt's measures.
struct Row {
    tilt: f32,
    light_return: Estimate,
    cos: Estimate,
    aset: [Estimate; 4],
    extinction: Estimate,
    contrast: Estimate,
    fire: Estimate,
    /// The number of sparkles; its error from the two independent halves' counts.
    sparkles: Estimate,
    /// Share of the stone's pixels that sparkle.
    sparkling: Estimate,
    scintillation: Estimate,
    /// The schiller share (a stone with platelets only).
    schiller: Option<Estimate>,
}

/// What lights one view.
#[derive(Clone, Copy)]
enum Light {
    /// One of the environment lightings.
    Sky(Lighting),
    /// The spots on a black sky.
    Spots,
}

/// The pixel-wise mean of two renders of one view.
fn mean_rgb(a: &crate::render::film::Film, b: &crate::render::film::Film) -> Vec<[f32; 3]> {
    a.rgb()
        .iter()
        .zip(b.rgb())
        .map(|(p, q)| [0, 1, 2].map(|k| 0.5 * (p[k] + q[k])))
        .collect()
}

/// One rendered view of the stone.
struct Shot {
    world: World,
    scene: crate::scene::Scene,
    film: crate::render::film::Film,
    /// The pixels whose camera ray meets the stone.
    mask: Vec<bool>,
}

/// Runs the report.
pub fn run(args: &CutArgs) -> Result<()> {
    let mut plan = OutputPlan::new();
    let loaded = load_scene(&args.recipe, &Accuracy::default(), Some(&mut plan))?;
    plan.folder(&args.out)?;
    let stem = args
        .recipe
        .file_stem()
        .map_or("stone".into(), |s| s.to_string_lossy().into_owned());
    let png = plan.output_in(&args.out, &format!("{stem}-cut.png"), Format::Png)?;
    let csv = plan.output_in(&args.out, &format!("{stem}-cut.csv"), Format::Csv)?;
    // The lightings as environment maps, in a scratch folder removed on every way out.
    let scratch = Scratch::new()?;
    let mut sheet: Vec<Vec<[f32; 3]>> = vec![];
    let mut rows = vec![];
    let none = || "the stone covers no pixel of the view";
    // Fire is dispersion's: a stone without it has none.
    let dispersive = loaded
        .scene
        .surface
        .body
        .as_ref()
        .is_some_and(|b| b.dispersion.is_some());
    for &tilt in &args.tilts.0 {
        let shoot_at = |light, tilt, twin| shoot(&loaded.scene, light, tilt, twin, args, &scratch);
        let shoot = |light, twin| shoot_at(light, tilt, twin);
        // The ISO and spot views twice, independently: their contrast and fire need two.
        let iso = shoot(Light::Sky(Lighting::Iso), false)?;
        let iso_twin = shoot(Light::Sky(Lighting::Iso), true)?;
        let cos = shoot(Light::Sky(Lighting::Cos), false)?;
        let aset = shoot(Light::Sky(Lighting::Aset), false)?;
        let spots = shoot(Light::Spots, false)?;
        let spots_twin = shoot(Light::Spots, true)?;
        let tilted = shoot_at(Light::Spots, tilt + sparkle::TILT_STEP, false)?;
        let tilted_twin = shoot_at(Light::Spots, tilt + sparkle::TILT_STEP, true)?;
        let iso_view = mean_rgb(&iso.film, &iso_twin.film);
        let spot_view = mean_rgb(&spots.film, &spots_twin.film);
        let on = sparkle::sparkling(&spot_view, &spots.mask);
        let on_tilted =
            sparkle::sparkling(&mean_rgb(&tilted.film, &tilted_twin.film), &tilted.mask);
        let light_return = [&iso, &iso_twin].map(|s| report::mean_luminance(&s.film, &s.mask));
        rows.push(Row {
            tilt,
            light_return: Estimate::mean_of(light_return).context(none())?,
            cos: report::mean_luminance(&cos.film, &cos.mask).context(none())?,
            aset: report::aset_shares(&aset.film, &aset.mask).context(none())?,
            extinction: report::extinction(&iso_view, &iso.mask).context(none())?,
            contrast: report::contrast([&iso.film, &iso_twin.film], &iso.mask).context(none())?,
            fire: if dispersive {
                sparkle::fire([&spots.film, &spots_twin.film], &spots.mask).context(none())?
            } else {
                Estimate {
                    value: 0.0,
                    se: 0.0,
                }
            },
            sparkles: {
                let half = |f: &crate::render::film::Film| {
                    f64::from(sparkle::count_sparkles(
                        &sparkle::sparkling(&f.rgb(), &spots.mask),
                        args.size,
                    ))
                };
                Estimate {
                    value: f64::from(sparkle::count_sparkles(&on, args.size)),
                    se: 0.5 * (half(&spots.film) - half(&spots_twin.film)).abs(),
                }
            },
            sparkling: sparkle::share(&on, &spots.mask).context(none())?,
            scintillation: sparkle::scintillation(
                &on,
                &on_tilted,
                &spots.mask,
                &tilted.mask,
                sparkle::TILT_STEP,
            )
            .context(none())?,
            schiller: schiller::share(&iso.world, &iso.scene, &iso.scene.stage.camera, args.size),
        });
        sheet.extend([iso_view, cos.film.rgb(), aset.film.rgb(), spot_view]);
    }
    let table = table::table(&rows);
    print!("{table}");
    let (n, size) = (rows.len() as u32, args.size);
    let bytes = contact_sheet(&sheet, n, size);
    crate::image::atomic::all_or_nothing(|| {
        crate::image::png::write_rgb8(&png, COLUMNS * size, n * size, bytes)?;
        crate::image::atomic::write_atomically(&csv, |w| {
            use std::io::Write as _;
            w.write_all(table::csv_text(&rows).as_bytes())?;
            Ok(())
        })?;
        Ok(())
    })?;
    println!("wrote {} and {}", png.display(), csv.display());
    Ok(())
}

/// Renders the stone of `scene` face-up at `tilt` degrees under `light`; a `twin` with other
/// random numbers than the view rendered without.
fn shoot(
    scene: &crate::scene::Scene,
    light: Light,
    tilt: f32,
    twin: bool,
    args: &CutArgs,
    scratch: &Scratch,
) -> Result<Shot> {
    let mut scene = scene.clone();
    let st = &mut scene.stage;
    st.ground = None;
    st.lights.clear();
    View {
        tilt_x: tilt,
        ..View::default()
    }
    .apply(st);
    let frame = frame(&scene)?;
    match light {
        Light::Sky(lighting) => {
            let env = scratch.0.join(format!("{}.exr", lighting.name()));
            if !env.exists() {
                crate::image::write_exr(&env, &exr_of(&lighting.environment()))?;
            }
            scene.stage.environment = Environment::Map {
                path: env,
                intensity: 1.0,
                rotate: 0.0,
            };
        }
        Light::Spots => {
            let env = scratch.0.join("spots.exr");
            if !env.exists() {
                crate::image::write_exr(&env, &exr_of(&sparkle::spot_map()))?;
            }
            scene.stage.environment = Environment::Map {
                path: env,
                intensity: 1.0,
                rotate: 0.0,
            };
        }
    }
    scene.effects.turn_on(
        crate::scene::Effect::EnvironmentImportance,
        "lapidary cut's lighting",
    );
    scene.stage.camera = face_up(&frame)?;
    let r = &mut scene.stage.render;
    (r.width, r.height, r.spp) = (args.size, args.size, args.spp);
    if twin {
        // Any other seed gives independent sample sequences.
        r.seed = r.seed.wrapping_add(0x9e37_79b9_7f4a_7c15);
    }
    let world = World::new(&scene).context("building the stone")?;
    let control = Control {
        threads: args.threads.map(|t| t as usize),
        ..Control::default()
    };
    let film = render_scene(&world, &scene, &control).film;
    let mask = stone_mask(&world, &scene.stage.camera, args.size);
    Ok(Shot {
        world,
        scene,
        film,
        mask,
    })
}

/// Where the stone is, in world space.
struct Frame {
    /// The centre of its bounds.
    centre: Vec3,
    /// The larger of its horizontal extents.
    extent: f32,
    /// The height of its top.
    top: f32,
}

fn frame(scene: &crate::scene::Scene) -> Result<Frame> {
    let stone = crate::geometry::Stone::new(&scene.stage.shape, scene.stage.to_world)
        .context("building the stone")?;
    let (lo, hi) = stone.bounds();
    let extent = (hi.x - lo.x).max(hi.z - lo.z);
    if !(extent > 0.0 && extent.is_finite()) {
        bail!("the stone has no extent to frame");
    }
    Ok(Frame {
        centre: 0.5 * (lo + hi),
        extent,
        top: hi.y,
    })
}

/// An orthographic camera straight down onto the stone, framing its extent with a margin.
fn face_up(frame: &Frame) -> Result<Camera> {
    let Frame {
        centre,
        extent,
        top,
    } = *frame;
    let from = Vec3::new(centre.x, top + 2.0 * extent + 1.0, centre.z);
    let Some(camera) = Camera::look_at(
        from,
        centre,
        Vec3::NEG_Z,
        Projection::Orthographic {
            height: 1.1 * extent,
        },
    ) else {
        bail!("the stone has no extent to frame");
    };
    Ok(camera)
}

/// Whether the camera ray through the centre of each pixel meets the stone.
fn stone_mask(world: &World, camera: &Camera, size: u32) -> Vec<bool> {
    let rays = CameraRays::new(camera, size, size, false);
    (0..size)
        .flat_map(|y| (0..size).map(move |x| (x, y)))
        .map(|(x, y)| {
            let ray = rays.ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5), Vec2::splat(0.5));
            matches!(world.intersect(&ray, f32::INFINITY), Some(Hit::Stone(_)))
        })
        .collect()
}

/// Views per row of the contact sheet.
const COLUMNS: u32 = 4;

/// Rows: tilts; columns: ISO, COS, ASET, spots (each view `size` square, clamped to [0, 1], sRGB).
fn contact_sheet(views: &[Vec<[f32; 3]>], rows: u32, size: u32) -> Vec<u8> {
    let w = COLUMNS * size;
    let mut out = vec![0u8; (3 * w * rows * size) as usize];
    for (k, view) in views.iter().enumerate() {
        let (r, c) = (k as u32 / COLUMNS, k as u32 % COLUMNS);
        for (i, px) in view.iter().enumerate() {
            let (x, y) = (c * size + i as u32 % size, r * size + i as u32 / size);
            let at = (3 * (y * w + x)) as usize;
            for ch in 0..3 {
                let v = crate::image::png::srgb_encode(px[ch].clamp(0.0, 1.0));
                out[at + ch] = (255.0 * v).round() as u8;
            }
        }
    }
    out
}

/// An RGB image as an EXR of channels R, G, B.
fn exr_of(img: &crate::image::RgbImage) -> crate::image::ExrImage {
    let channel = |name: &str, k: usize| crate::image::Channel {
        name: name.into(),
        data: img.pixels.iter().map(|p| p[k]).collect(),
    };
    crate::image::ExrImage {
        width: img.width,
        height: img.height,
        channels: vec![channel("R", 0), channel("G", 1), channel("B", 2)],
        attributes: vec![],
    }
}

/// A scratch folder for the lightings' maps, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new() -> Result<Scratch> {
        let dir = std::env::temp_dir().join(format!(
            "lapidary-cut-{}-{}",
            std::process::id(),
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.as_nanos())
        ));
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        Ok(Scratch(dir))
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
