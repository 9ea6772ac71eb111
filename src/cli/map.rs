//! `lapidary map`: draws a recipe's map tree on a plane, so an author sees the pattern without
//! rendering. Each material gets a distinct flat colour (listed in a legend with its share of the
//! plane), glitter cells (filled cells of sparse maps) are outlined, and facet tilt is shaded by a
//! light from the upper left. Stochastic switch bands show as dithering: every pixel draws its own
//! random number from `(seed, pixel)`.

use crate::bsdf::{Base, StackDesc};
use crate::image::outputs::{Format, OutputPlan};
use crate::sampler::{hash_words, to_unit_f32};
use crate::scene::Accuracy;
use crate::texture::MapHit;
use anyhow::{Result, anyhow};
use clap::Args;
use glam::Vec3;
use plotters::prelude::*;
use rayon::prelude::*;
use std::io::Write;
use std::path::PathBuf;

/// A plane `axis = offset` in object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// 0, 1, 2 for x, y, z.
    pub axis: usize,
    /// Its coordinate.
    pub offset: f32,
}

impl Plane {
    /// The object-space point at in-plane coordinates `(a, b)` (right, up).
    pub fn point(&self, a: f32, b: f32) -> Vec3 {
        match self.axis {
            0 => Vec3::new(self.offset, a, b),
            1 => Vec3::new(a, self.offset, b),
            _ => Vec3::new(a, b, self.offset),
        }
    }
}

/// Parses `x=0.5`, `y=-1`, `z=0`.
pub fn parse_plane(s: &str) -> Result<Plane, String> {
    let err = || format!("`{s}`: expected AXIS=VALUE with AXIS one of x, y, z (e.g. z=0)");
    let (axis, value) = s.split_once('=').ok_or_else(err)?;
    let axis = match axis.trim() {
        "x" | "X" => 0,
        "y" | "Y" => 1,
        "z" | "Z" => 2,
        _ => return Err(err()),
    };
    let offset: f32 = value.trim().parse().map_err(|_| err())?;
    if !offset.is_finite() || offset.abs() > 1e6 {
        return Err(format!("`{s}`: the offset must be finite, within ±1e6"));
    }
    Ok(Plane { axis, offset })
}

fn parse_extent(s: &str) -> Result<f32, String> {
    let v: f32 = s.parse().map_err(|_| format!("`{s}` is not a number"))?;
    if v > 0.0 && v <= 1e5 {
        Ok(v)
    } else {
        Err(format!("extent = {v} is out of range: allowed 0 <.. 1e5"))
    }
}

/// Arguments of `lapidary map`.
#[derive(Debug, Args)]
pub struct MapArgs {
    /// Gem recipe (RON).
    pub recipe: PathBuf,
    /// Output PNG (checked before drawing, see `docs/rendering.md`; written atomically: a failed
    /// run leaves an existing file untouched).
    #[arg(long, short)]
    pub out: PathBuf,
    /// Side of the square map in pixels.
    #[arg(long, default_value_t = 768, value_parser = clap::value_parser!(u32).range(16..=8192))]
    pub size: u32,
    /// The object-space plane drawn: x=…, y=… or z=….
    #[arg(long, default_value = "z=0", value_parser = parse_plane)]
    pub plane: Plane,
    /// Half-width of the drawn square in object units (the studio cabochon has radius 1).
    #[arg(long, default_value = "1", value_parser = parse_extent)]
    pub extent: f32,
    /// Seed of the per-pixel random numbers for stochastic switch bands.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Leave out the legend column.
    #[arg(long)]
    pub no_legend: bool,
    /// How materials are coloured: `material` (a distinct flat colour each) or `albedo` (a rough
    /// preview of each material's own colour at normal incidence).
    #[arg(long, value_enum, default_value_t = Colours::Material)]
    pub colours: Colours,
}

/// Colouring of `lapidary map`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Colours {
    /// A distinct palette colour per material.
    Material,
    /// Each material's approximate colour: the base's albedo (a conductor's normal-incidence
    /// reflectance `((n−1)² + k²)/((n+1)² + k²)`), times each coat's transmittance down and up,
    /// `exp(−2·α·d)`, encoded as sRGB. Coat reflections and roughness are ignored: a preview only.
    Albedo,
}

/// The `--colours albedo` preview colour of a stack (see [`Colours::Albedo`]).
pub fn preview_colour(stack: &StackDesc) -> [u8; 3] {
    let base = match &stack.base {
        Base::Lambert { albedo } | Base::OrenNayar { albedo, .. } => *albedo,
        Base::Conductor { ior, .. } => match ior.rgb() {
            Some((n, k)) => n.zip(k, |n, k| {
                ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k)
            }),
            None => crate::color::Rgb::ONE,
        },
    };
    let rgb = stack.coats.iter().fold(base, |c, coat| {
        c.zip(coat.absorption, |c, a| {
            c * (-2.0 * a * coat.thickness).exp()
        })
    });
    let encode = |v: f32| {
        let v = v.clamp(0.0, 1.0);
        let s = if v <= 0.003_130_8 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    rgb.0.map(encode)
}

/// Distinct colours: hues a golden angle apart, alternating saturation and value.
pub fn palette(i: usize) -> [u8; 3] {
    let h = (i as f32 * 137.507_77).rem_euclid(360.0) / 60.0;
    let s = [0.55, 0.8, 0.4][i % 3];
    let v = [0.95, 0.75, 0.85][(i / 3) % 3];
    let c = v * s;
    let x = c * (1.0 - (h.rem_euclid(2.0) - 1.0).abs());
    let (r, g, b) = match h as u32 {
        0 => (c, x, 0.0),
        1 => (x, c, 0.0),
        2 => (0.0, c, x),
        3 => (0.0, x, c),
        4 => (x, 0.0, c),
        _ => (c, 0.0, x),
    };
    let m = v - c;
    [r, g, b].map(|t| ((t + m) * 255.0).round() as u8)
}

/// Runs `lapidary map`.
pub fn run(args: &MapArgs) -> Result<()> {
    let mut plan = OutputPlan::new();
    plan.input(&args.recipe, "the recipe")?;
    let out_file = plan.output(&args.out, Format::Png)?;
    let loaded = super::load::load_scene(&args.recipe, &Accuracy::default(), Some(&mut plan))?;
    let surface = loaded.scene.surface;
    for name in surface.unused() {
        eprintln!("warning: material \"{name}\" is never used by the surface map");
    }
    let n = args.size as usize;
    let px = 2.0 * args.extent / n as f32;
    // Pixel centres; row 0 is the top (+b).
    let hits: Vec<MapHit> = (0..n * n)
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i % n, i / n);
            let a = -args.extent + (x as f32 + 0.5) * px;
            let b = args.extent - (y as f32 + 0.5) * px;
            let u = to_unit_f32(hash_words(&[args.seed, x as u64, y as u64]));
            surface.map.lookup(args.plane.point(a, b), u)
        })
        .collect();
    let names = surface.leaf_names();
    let mats = names.len();
    let colours: Vec<[u8; 3]> = (0..mats)
        .map(|i| match (args.colours, surface.stacks.get(i)) {
            (Colours::Material, _) => palette(i),
            (Colours::Albedo, Some(stack)) => preview_colour(stack),
            // The translucent body: a pale glass tone.
            (Colours::Albedo, None) => [225, 232, 240],
        })
        .collect();
    let mut count = vec![0usize; mats];
    let light = Vec3::new(-0.5, 0.5, 1.0).normalize();
    // Outlines in black, or in white where the materials are dark (albedo previews).
    let outline_colour = if args.colours == Colours::Albedo {
        [255, 255, 255]
    } else {
        [20, 20, 20]
    };
    let legend = Legend::fitting(n, mats);
    let (w, h) = (n + if args.no_legend { 0 } else { legend.width() }, n);
    let mut buf = vec![255u8; w * h * 3];
    let mut glitter = 0usize;
    for y in 0..n {
        for x in 0..n {
            let hit = &hits[y * n + x];
            count[hit.material as usize] += 1;
            let g = hit.trail.glitter_cell();
            glitter += usize::from(g.is_some());
            let outline = g.is_some()
                && [(0i64, 1i64), (1, 0), (0, -1), (-1, 0)]
                    .iter()
                    .any(|(dx, dy)| {
                        let (xx, yy) = (x as i64 + dx, y as i64 + dy);
                        (0..n as i64).contains(&xx)
                            && (0..n as i64).contains(&yy)
                            && hits[yy as usize * n + xx as usize].trail.glitter_cell() != g
                    });
            let rgb = if outline {
                outline_colour
            } else {
                let shade = hit
                    .facet
                    .map_or(1.0, |f| (f.dot(light) / light.z).clamp(0.3, 1.6));
                colours[hit.material as usize].map(|c| (f32::from(c) * shade).min(255.0) as u8)
            };
            let o = (y * w + x) * 3;
            buf[o..o + 3].copy_from_slice(&rgb);
        }
    }
    if !args.no_legend {
        draw_legend(&mut buf, (w, h), n, &legend, &names, &colours, &count)?;
    }
    crate::image::png::write_rgb8(&out_file, w as u32, h as u32, buf)?;
    // The summary: what share of the plane each material covers.
    let total = (n * n) as f64;
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "{}: {} materials, plane {:?}={}, extent ±{}, map {n}×{n} px{} → {} ({w}×{h} px)",
        loaded.recipe.file(),
        mats,
        ["x", "y", "z"][args.plane.axis],
        args.plane.offset,
        args.extent,
        if args.no_legend {
            String::new()
        } else {
            format!(" + legend {} px", w - n)
        },
        args.out.display()
    )?;
    for (i, name) in names.iter().enumerate() {
        writeln!(out, "  {:>6.2} %  {name}", 100.0 * count[i] as f64 / total)?;
    }
    writeln!(
        out,
        "  glitter cells cover {:.2} % of the plane",
        100.0 * glitter as f64 / total
    )?;
    Ok(())
}

/// How the legend beside a map is laid out: as tall as the map, in as many columns of swatches
/// as the materials need, the lines shrunk (to no less than [`Legend::MIN_LINE`]) before a column
/// is added.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Legend {
    /// Height of one entry, px.
    line: usize,
    /// Entries per column.
    rows: usize,
    /// Columns.
    columns: usize,
}

impl Legend {
    /// The line height of a roomy legend, px (a 15 px font).
    const LINE: usize = 22;
    /// The smallest line height, px.
    const MIN_LINE: usize = 12;
    /// A column's width at the roomy line height, px.
    const COLUMN: usize = 300;
    /// Margin above and below the entries, px.
    const MARGIN: usize = 10;

    /// The layout for `mats` entries beside a map `side` px tall.
    fn fitting(side: usize, mats: usize) -> Legend {
        let room = side.saturating_sub(2 * Self::MARGIN).max(Self::MIN_LINE);
        let mats = mats.max(1);
        let line = (room / mats).clamp(Self::MIN_LINE, Self::LINE);
        let rows = (room / line).max(1);
        Legend {
            line,
            rows,
            columns: mats.div_ceil(rows),
        }
    }

    /// Width of one column, px.
    fn column(&self) -> usize {
        Self::COLUMN * self.line / Self::LINE
    }

    /// Width of the whole legend, px.
    fn width(&self) -> usize {
        self.columns * self.column()
    }
}

/// The legend right of the map: a swatch, the name and the share of the plane per material.
fn draw_legend(
    buf: &mut [u8],
    (w, h): (usize, usize),
    left: usize,
    layout: &Legend,
    names: &[String],
    colours: &[[u8; 3]],
    count: &[usize],
) -> Result<()> {
    super::plot::register_font();
    let total: usize = count.iter().sum::<usize>().max(1);
    let root = BitMapBackend::with_buffer(buf, (w as u32, h as u32)).into_drawing_area();
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("legend: {e:?}");
    let line = layout.line as i32;
    let font = ("sans-serif", (line * 15 / 22) as u32).into_font();
    let swatch = line * 16 / 22;
    for (i, name) in names.iter().enumerate() {
        let x0 = (left + 10 + (i / layout.rows) * layout.column()) as i32;
        let y = (Legend::MARGIN + (i % layout.rows) * layout.line) as i32;
        let [r, g, b] = colours[i];
        root.draw(&Rectangle::new(
            [(x0, y), (x0 + swatch, y + swatch)],
            RGBColor(r, g, b).filled(),
        ))
        .map_err(e)?;
        let label = format!("{name}  {:.1} %", 100.0 * count[i] as f64 / total as f64);
        root.draw(&Text::new(label, (x0 + swatch + 8, y + 1), font.clone()))
            .map_err(e)?;
    }
    root.present().map_err(e)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::ConductorIor;

    #[test]
    fn the_legend_is_as_tall_as_the_map() {
        // Few materials: one roomy column.
        assert_eq!(
            Legend::fitting(768, 5),
            Legend {
                line: 22,
                rows: 34,
                columns: 1
            }
        );
        // Lepidolite's 20 materials beside a 256 px map: the smallest lines, two columns.
        let l = Legend::fitting(256, 20);
        assert_eq!((l.line, l.columns), (12, 2));
        assert!(l.rows * l.line <= 256 - 2 * Legend::MARGIN);
        for (side, mats) in [(16, 1), (16, 300), (256, 20), (8192, 3)] {
            let l = Legend::fitting(side, mats);
            assert!(l.rows * l.columns >= mats, "{side} {mats}: {l:?}");
            assert!(l.line >= Legend::MIN_LINE && l.line <= Legend::LINE);
        }
    }

    #[test]
    fn planes_parse_and_reject_nonsense() {
        assert_eq!(
            parse_plane("z=0").unwrap(),
            Plane {
                axis: 2,
                offset: 0.0
            }
        );
        assert_eq!(
            parse_plane("x = -0.5").unwrap().point(1.0, 2.0),
            Vec3::new(-0.5, 1.0, 2.0)
        );
        for bad in ["w=0", "z", "z=abc", "z=inf", "z=1e9"] {
            assert!(parse_plane(bad).is_err(), "{bad}");
        }
        assert!(parse_extent("0").is_err() && parse_extent("2").is_ok());
    }

    #[test]
    fn preview_colours_follow_base_and_tint() {
        use crate::bsdf::Coat;
        use crate::color::Rgb;
        let white = StackDesc::new(vec![], Base::Lambert { albedo: Rgb::ONE });
        assert_eq!(preview_colour(&white), [255, 255, 255]);
        let tinted = StackDesc::new(
            vec![Coat {
                ior: 1.5,
                roughness: 1.0,
                absorption: Rgb::new(0.0, 0.5, 2.0),
                thickness: 1.0,
            }],
            Base::Lambert {
                albedo: Rgb::splat(0.5),
            },
        );
        let [r, g, b] = preview_colour(&tinted);
        assert!(r > g && g > b, "{r} {g} {b}");
        let silver = StackDesc::new(
            vec![],
            Base::Conductor {
                ior: ConductorIor::Perfect,
                roughness: 1.0,
            },
        );
        assert_eq!(preview_colour(&silver), [255, 255, 255]);
    }

    #[test]
    fn palette_colours_are_distinct() {
        let cols: Vec<[u8; 3]> = (0..40).map(palette).collect();
        for i in 0..cols.len() {
            for j in 0..i {
                let d: i32 = (0..3)
                    .map(|k| (i32::from(cols[i][k]) - i32::from(cols[j][k])).abs())
                    .sum();
                assert!(d > 24, "{i} and {j}: {:?} {:?}", cols[i], cols[j]);
            }
        }
    }
}
