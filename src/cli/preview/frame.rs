//! What the page asks of a published image: a PNG of the colour or of an AOV, the inspector's
//! view of one pixel, and the export to EXR + PNG with the batch command that renders it again.

use super::state::Image;
use crate::image::{Curve, ToneMap};
use crate::render::world::Hit;
use crate::render::{Metadata, RenderStats, Rendered, exr_image};
use crate::scene::Knobs;
use serde_json::{Value, json};
use std::path::{Path, PathBuf};

/// The views of an image the page can show.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Aov {
    /// Tone-mapped radiance.
    Color,
    /// First-hit albedo.
    Albedo,
    /// First-hit shading normal (`0.5 n + 0.5`).
    Normal,
    /// First-hit distance, near bright.
    Depth,
    /// First-hit material, one colour each.
    Material,
    /// The map's cells at the first hit (hashed colours).
    Cells,
    /// Relative standard error of each pixel's mean (viridis, 0 → 10 %).
    Variance,
    /// Stokes component `k` (0–3) of the light reaching the camera (`preview --stokes`): S0
    /// tone-mapped as the colour; S1–S3 as their fraction of S0's luminance, `−1 … 1`, warm where
    /// positive (horizontal, +45°, right-circular), cool where negative, black where unpolarised.
    Stokes(usize),
}

impl Aov {
    /// Parses a query value.
    pub fn parse(s: &str) -> Option<Aov> {
        Some(match s {
            "color" => Aov::Color,
            "albedo" => Aov::Albedo,
            "normal" => Aov::Normal,
            "depth" => Aov::Depth,
            "material" => Aov::Material,
            "cells" => Aov::Cells,
            "variance" => Aov::Variance,
            "s0" => Aov::Stokes(0),
            "s1" => Aov::Stokes(1),
            "s2" => Aov::Stokes(2),
            "s3" => Aov::Stokes(3),
            _ => return None,
        })
    }
}

/// The page's display settings: `exposure` in stops (−30 ..= 30, default 0) and the tone curve
/// (`filmic`, the default, or `clamp`); the error says what is wrong and what is allowed.
pub fn tone_map(exposure: Option<&str>, curve: Option<&str>) -> Result<ToneMap, String> {
    let exposure = match exposure {
        None => 0.0,
        Some(v) => match v.parse::<f32>() {
            Ok(e) if (-30.0..=30.0).contains(&e) => e,
            _ => return Err(format!("exposure `{v}`: expected stops in -30..=30")),
        },
    };
    let curve = match curve.unwrap_or("filmic") {
        "filmic" => Curve::Filmic,
        "clamp" => Curve::Clamp,
        other => return Err(format!("tonemap `{other}`: expected filmic or clamp")),
    };
    Ok(ToneMap { exposure, curve })
}

/// The image's PNG at the requested size (a quick low-resolution frame is enlarged, each pixel
/// a block). A Stokes view of an image without the Stokes sums is black.
pub fn png(image: &Image, aov: Aov, tm: &ToneMap) -> Vec<u8> {
    let film = &image.film;
    let stokes = |i: usize| {
        film.stokes
            .get(i)
            .map_or([[0.0; 3]; 4], |s| s.mean(film.pixels[i].n))
    };
    let (w, h) = (film.width, film.height);
    let max_depth = film
        .pixels
        .iter()
        .map(|p| p.mean_depth())
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let cells = (aov == Aov::Cells).then(|| cell_ids(image));
    let pixel = |i: usize| -> [u8; 3] {
        let p = &film.pixels[i];
        let unit = |v: [f32; 3]| v.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        match aov {
            Aov::Color => crate::image::tone_map_pixel(p.mean().0, tm),
            Aov::Albedo => crate::image::tone_map_pixel(
                p.mean_albedo(),
                &ToneMap {
                    exposure: 0.0,
                    curve: Curve::Clamp,
                },
            ),
            Aov::Normal => unit(p.mean_normal().map(|c| 0.5 * c + 0.5)),
            Aov::Depth => {
                let d = p.mean_depth();
                let v = if d > 0.0 { 1.0 - d / max_depth } else { 0.0 };
                unit([v; 3])
            }
            Aov::Material => match usize::try_from(p.material) {
                Ok(m) => crate::cli::map::palette(m),
                Err(_) => [24, 24, 24],
            },
            Aov::Cells => match cells.as_ref().and_then(|c| c[i]) {
                Some(id) => {
                    let h = crate::sampler::mix64(id);
                    [
                        (h >> 8) as u8 | 0x30,
                        (h >> 24) as u8 | 0x30,
                        (h >> 40) as u8 | 0x30,
                    ]
                }
                None => [24, 24, 24],
            },
            Aov::Variance => {
                let m = p.mean().0;
                let v = p.variance_of_mean();
                let lum = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                let rel = lum(v.map(f32::sqrt)) / lum(m).max(1e-6);
                crate::image::heatmap::viridis((rel / 0.1).clamp(0.0, 1.0))
            }
            Aov::Stokes(0) => crate::image::tone_map_pixel(stokes(i)[0], tm),
            Aov::Stokes(k) => {
                let s = stokes(i);
                let lum = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
                let q = lum(s[k.min(3)]) / lum(s[0]).max(1e-12);
                let q = if q.is_finite() {
                    q.clamp(-1.0, 1.0)
                } else {
                    0.0
                };
                let warm = [1.0, 0.55, 0.1].map(|c| c * q.max(0.0));
                let cool = [0.1, 0.6, 1.0].map(|c| c * (-q).max(0.0));
                unit([0, 1, 2].map(|c| warm[c] + cool[c]))
            }
        }
    };
    let s = image.scale.max(1);
    let (ow, oh) = (w * s, h * s);
    let mut bytes = Vec::with_capacity(3 * (ow * oh) as usize);
    for y in 0..oh {
        for x in 0..ow {
            bytes.extend_from_slice(&pixel(((y / s) * w + x / s) as usize));
        }
    }
    let mut out = Vec::new();
    // Encoding into memory fails only on a size mismatch, which the loops above rule out.
    let _ = crate::image::png::encode_rgb8(&mut out, ow, oh, &bytes);
    out
}

/// The map's cell trail hash at the first hit of every film pixel (`None`: not the stone).
fn cell_ids(image: &Image) -> Vec<Option<u64>> {
    let (w, h) = (image.film.width, image.film.height);
    let rays = super::inspect::camera_rays(image);
    (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(
            |(x, y)| match super::inspect::primary_hit_with(image, &rays, x, y).0 {
                Some(Hit::Stone(s)) => Some(image.world.map.lookup(s.p_object, 0.5).trail.hash()),
                _ => None,
            },
        )
        .collect()
}

/// The batch command that renders `image` again (the same pixels once it has `spp` samples).
pub fn command(recipe: &Path, image: &Image, knobs: &Knobs, out: Option<&Path>) -> String {
    let r = &image.scene.stage.render;
    let mut cmd = format!(
        "lapidary render {} --size {}x{} --spp {}",
        shell_quote(&recipe.display().to_string()),
        r.width,
        r.height,
        image.spp
    );
    if let Some(v) = image.view.to_arg() {
        cmd += &format!(" --view {v}");
    }
    if image.scene.stage.stokes {
        cmd += " --stokes";
    }
    cmd += &knob_flags(knobs);
    if let Some(o) = out {
        cmd += &format!(" --output {}", shell_quote(&o.display().to_string()));
    }
    cmd
}

/// The command-line flags of `knobs` (each as `render` reads it).
fn knob_flags(knobs: &Knobs) -> String {
    let onoff = |b: bool| if b { "on" } else { "off" };
    let mut out = String::new();
    if let Some(s) = knobs.sampler {
        out += &format!(" --sampler {}", s.name());
    }
    if let Some(d) = knobs.max_depth {
        out += &format!(" --max-depth {d}");
    }
    if let Some(d) = knobs.medium_depth {
        out += &format!(" --medium-depth {d}");
    }
    if let Some(s) = knobs.medium_scattering {
        out += &format!(" --medium-scattering {}", onoff(s));
    }
    if let Some(c) = knobs.manifold_continuation {
        out += &format!(" --manifold-continuation {}", onoff(c));
    }
    if let Some(h) = knobs.manifold_halvings {
        out += &format!(" --manifold-halvings {h}");
    }
    let k = &knobs.accuracy;
    if let Some(m) = k.model {
        out += &format!(" --model {m}");
    }
    if let Some(f) = k.fresnel {
        out += &format!(" --fresnel {f}");
    }
    if let Some(d) = k.distribution {
        out += &format!(" --distribution {d}");
    }
    if let Some(m) = k.masking {
        out += &format!(" --masking {m}");
    }
    if let Some(c) = k.compensation {
        out += &format!(" --compensation {}", onoff(c));
    }
    if let Some(c) = k.calibration {
        out += &format!(" --calibration {}", onoff(c));
    }
    for (e, on) in &k.effects {
        out += &format!(" --effect {}={}", e.name(), onoff(*on));
    }
    out
}

fn shell_quote(s: &str) -> String {
    if !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./+=:,@".contains(c))
    {
        s.to_string()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}

/// Writes `image` as `<stem>-preview.exr` and `.png` in `dir` (all or nothing; refused when a
/// name is one of `inputs`) and returns the paths and the batch command.
pub fn export(
    recipe: &Path,
    image: &Image,
    inputs: &[PathBuf],
    dir: &Path,
    tm: &ToneMap,
) -> anyhow::Result<Value> {
    use crate::image::outputs::{Format, OutputPlan};
    anyhow::ensure!(
        image.scale == 1,
        "the image is still at its quick first resolution: wait for the first full pass"
    );
    let stem = recipe
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "preview".into());
    let mut plan = OutputPlan::new();
    for i in inputs {
        plan.input(i, "an input of the recipe")?;
    }
    let exr_path = dir.join(format!("{stem}-preview.exr"));
    let png_path = dir.join(format!("{stem}-preview.png"));
    let exr = plan.output(&exr_path, Format::Exr)?;
    let png = plan.output(&png_path, Format::Png)?;
    let rendered = Rendered {
        film: image.film.clone(),
        stats: RenderStats {
            elapsed: std::time::Duration::ZERO,
            paths: image.film.samples() + image.film.dropped(),
            rays: image.film.rays(),
            dropped: image.film.dropped(),
            partial: false,
            spp_complete: image.spp,
        },
    };
    let mut scene = (*image.scene).clone();
    scene.stage.render.spp = image.spp;
    let meta = Metadata::of(&recipe.display().to_string(), &scene);
    let (w, h) = (image.film.width, image.film.height);
    crate::image::atomic::all_or_nothing(|| {
        crate::image::write_exr(&exr, &exr_image(&rendered, &meta))?;
        crate::image::write_png(&png, w, h, &rendered.film.rgb(), tm)?;
        Ok(())
    })?;
    Ok(json!({
        "exr": exr_path.display().to_string(),
        "png": png_path.display().to_string(),
        "command": command(recipe, image, &image.knobs, Some(&exr_path)),
    }))
}
