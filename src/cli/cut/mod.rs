//! `lapidary cut RECIPE [--tilts 0,10,20,30] [--out DIR]`: the stone face-up under the cut
//! report's lightings ([`report`]) at each tilt — a contact sheet (PNG), a CSV and a table of
//! light return, the ASET shares and leakage, and for a stone with platelets the share of pixels
//! showing the schiller flash ([`schiller`]), each with its standard error (docs/cuts.md).
//!
//! The stone is seen along −y through an orthographic camera framing its bounds, the floor and
//! the recipe's lights removed, the environment replaced by the lighting; a tilt turns the stone
//! about the x axis through its centre (`scene::view::View`, as the preview tilts it). Renders
//! are deterministic: the same recipe, seed and spp give the same report for any thread count.

pub mod report;
pub mod schiller;

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
use std::fmt::Write as _;
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
    /// The schiller share (a stone with platelets only).
    schiller: Option<Estimate>,
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
    for &tilt in &args.tilts.0 {
        let mut row = Row {
            tilt,
            light_return: Estimate {
                value: 0.0,
                se: 0.0,
            },
            cos: Estimate {
                value: 0.0,
                se: 0.0,
            },
            aset: [Estimate {
                value: 0.0,
                se: 0.0,
            }; 4],
            schiller: None,
        };
        for lighting in Lighting::ALL {
            let env = scratch.0.join(format!("{}.exr", lighting.name()));
            if !env.exists() {
                crate::image::write_exr(&env, &exr_of(&lighting.environment()))?;
            }
            let mut scene = loaded.scene.clone();
            let st = &mut scene.stage;
            st.ground = None;
            st.lights.clear();
            st.environment = Environment::Map {
                path: env,
                intensity: 1.0,
                rotate: 0.0,
            };
            View {
                tilt_x: tilt,
                ..View::default()
            }
            .apply(st);
            scene.stage.camera = face_up(&scene)?;
            let r = &mut scene.stage.render;
            (r.width, r.height, r.spp) = (args.size, args.size, args.spp);
            scene.effects.turn_on(
                crate::scene::Effect::EnvironmentImportance,
                "lapidary cut's lighting",
            );
            let world = World::new(&scene).context("building the stone")?;
            let control = Control {
                threads: args.threads.map(|t| t as usize),
                ..Control::default()
            };
            let film = render_scene(&world, &scene, &control).film;
            let mask = stone_mask(&world, &scene.stage.camera, args.size);
            match lighting {
                Lighting::Iso => {
                    row.light_return = report::mean_luminance(&film, &mask)
                        .context("the stone covers no pixel of the view")?;
                    row.schiller = schiller::share(&world, &scene, &scene.stage.camera, args.size);
                }
                Lighting::Cos => row.cos = report::mean_luminance(&film, &mask).unwrap_or(row.cos),
                Lighting::Aset => row.aset = report::aset_shares(&film, &mask).unwrap_or(row.aset),
            }
            sheet.push(film.rgb());
        }
        rows.push(row);
    }
    let table = table(&rows);
    print!("{table}");
    let (n, size) = (rows.len() as u32, args.size);
    let bytes = contact_sheet(&sheet, n, size);
    crate::image::atomic::all_or_nothing(|| {
        crate::image::png::write_rgb8(&png, 3 * size, n * size, bytes)?;
        crate::image::atomic::write_atomically(&csv, |w| {
            use std::io::Write as _;
            w.write_all(csv_text(&rows).as_bytes())?;
            Ok(())
        })?;
        Ok(())
    })?;
    println!("wrote {} and {}", png.display(), csv.display());
    Ok(())
}

/// An orthographic camera straight down onto the stone, framing its bounds with a margin.
fn face_up(scene: &crate::scene::Scene) -> Result<Camera> {
    let stone = crate::geometry::Stone::new(&scene.stage.shape, scene.stage.to_world)
        .context("building the stone")?;
    let (lo, hi) = stone.bounds();
    let centre = 0.5 * (lo + hi);
    let extent = (hi.x - lo.x).max(hi.z - lo.z);
    let from = Vec3::new(centre.x, hi.y + 2.0 * extent + 1.0, centre.z);
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

/// Rows: tilts; columns: ISO, COS, ASET (each view `size` square, clamped to [0, 1], sRGB).
fn contact_sheet(views: &[Vec<[f32; 3]>], rows: u32, size: u32) -> Vec<u8> {
    let w = 3 * size;
    let mut out = vec![0u8; (3 * w * rows * size) as usize];
    for (k, view) in views.iter().enumerate() {
        let (r, c) = (k as u32 / 3, k as u32 % 3);
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

fn table(rows: &[Row]) -> String {
    let mut s = String::from(
        "tilt   light return (ISO)   COS              ASET red        green           blue            leakage         schiller\n",
    );
    let pm = |e: &Estimate| format!("{:.3} ± {:.3}", e.value, e.se);
    for r in rows {
        let _ = writeln!(
            s,
            "{:>4}°  {:<20} {:<16} {:<15} {:<15} {:<15} {:<15} {}",
            r.tilt,
            pm(&r.light_return),
            pm(&r.cos),
            pm(&r.aset[0]),
            pm(&r.aset[1]),
            pm(&r.aset[2]),
            pm(&r.aset[3]),
            r.schiller.as_ref().map_or("–".to_string(), pm)
        );
    }
    s
}

fn csv_text(rows: &[Row]) -> String {
    let mut s = String::from(
        "tilt_deg,light_return_iso,light_return_iso_se,cos,cos_se,aset_red,aset_red_se,\
         aset_green,aset_green_se,aset_blue,aset_blue_se,leakage,leakage_se,schiller,schiller_se\n",
    );
    for r in rows {
        let mut cells = vec![r.tilt.to_string()];
        for e in [&r.light_return, &r.cos].into_iter().chain(r.aset.iter()) {
            cells.push(format!("{:.6}", e.value));
            cells.push(format!("{:.6}", e.se));
        }
        // Empty cells for a stone without platelets.
        match &r.schiller {
            Some(e) => cells.extend([format!("{:.6}", e.value), format!("{:.6}", e.se)]),
            None => cells.extend([String::new(), String::new()]),
        }
        s += &cells.join(",");
        s.push('\n');
    }
    s
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
