//! A table of malformed gem recipes: each must be rejected by `GemRecipe::check_source` with its
//! first error at the expected `file:line:col` and a message naming what is wrong (and, for numbers,
//! the allowed range). Also: several errors in one file (and, in `every_error`, every error of a
//! file in one check, each where it is when alone, none twice), and the `lapidary check` command
//! line.

use lapidary::recipe::{GemRecipe, RecipeError, Source};
use std::path::{Path, PathBuf};
use std::process::Command;

#[path = "recipe_errors/every_error.rs"]
mod every_error;

/// One malformed recipe and what its first error must say.
struct Row {
    name: &'static str,
    /// File name (suffix) the first error must name.
    file: &'static str,
    line: usize,
    col: usize,
    /// Substrings the message must contain.
    msg: &'static [&'static str],
    text: String,
}

fn row(name: &'static str, at: (usize, usize), msg: &'static [&'static str], text: String) -> Row {
    Row {
        name,
        file: "bad.ron",
        line: at.0,
        col: at.1,
        msg,
        text,
    }
}

/// Line 1 of most rows: two materials, "a" and "b".
const M: &str = r#"(materials: { "a": (base: Lambert(albedo: Gray(0.5))), "b": (base: Lambert(albedo: Gray(0.2))) },"#;

/// `M`, then `body` from line 2 (the surface and whatever else), then the closing parenthesis.
fn gem(body: &str) -> String {
    format!("{M}\n{body})")
}

/// A material "c" whose second coat (line 3) is `coat`; the first coat is fine.
fn coat(coat: &str) -> String {
    format!(
        "(materials: {{\n \"c\": (\n  coats: [(ior: 1.5, roughness: 1.0), ({coat})],\n  base: Lambert(albedo: Gray(0.5))),\n}},\n surface: Material(\"c\"))"
    )
}

/// A valid surface, then `stage: (` on line 3 with `stage` from line 4.
fn stage(stage: &str) -> String {
    gem(&format!(
        " surface: Material(\"a\"),\n stage: (\n{stage}\n ),\n"
    ))
}

/// `n` named maps `m0 → m1 → …`, each a one-stop Switch over the next: nesting far beyond what
/// the runtime evaluates, while each map is shallow for the RON parser.
fn deep_switches(n: usize) -> String {
    let mut maps = String::new();
    for i in 0..n {
        let next = if i + 1 == n {
            "Material(\"a\")".to_string()
        } else {
            format!("Map(\"m{}\")", i + 1)
        };
        maps += &format!("  \"m{i}\": Switch(by: Constant(0.0), stops: [(0.0, {next})]),\n");
    }
    gem(&format!(" maps: {{\n{maps} }},\n surface: Map(\"m0\")"))
}

/// A sparse glitter Voronoi over `n - 1` nested Voronoi maps, in an Overlay: one lookup visits `n`.
fn nested_glitter(n: usize) -> String {
    let mut tree = "Material(\"b\")".to_string();
    for i in (0..n).rev() {
        let fill = if i == 0 { 0.1 } else { 1.0 };
        tree = format!(
            "Voronoi(scale: 0.{}, fill: {fill}, entries: [(1.0, {tree})])",
            i + 1
        );
    }
    gem(&format!(
        " surface: Overlay(under: Material(\"a\"),\n  over: {tree}),\n"
    ))
}

/// A body with two platelet populations from line 2: a valid one on line 3, then `second` from
/// line 4 (the surface follows it).
fn platelets(second: &str) -> String {
    gem(&format!(
        " body: (ior: 1.5, platelets: [\n  (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")]),\n  {second}]),\n surface: Body"
    ))
}

fn rows() -> Vec<Row> {
    let s = |t: &str| t.to_string();
    #[rustfmt::skip]
    let rows = vec![
        // --- Syntax and shape of the file.
        row("empty_file", (1, 1), &["Expected opening `(`", "GemDesc"], s("")),
        row("missing_comma", (3, 4), &["Expected comma"], gem(" surface: Voronoi(scale: 0.1\n   fill: 0.5, entries: [(1.0, Material(\"a\"))])")),
        row("unclosed_paren", (2, 41), &["Expected comma"], s("(materials: {\n \"c\": (coats: [(ior: 1.5, roughness: 1.0], base: Lambert(albedo: Gray(0.5))),\n},\n surface: Material(\"c\"))")),
        row("unclosed_paren_at_eof", (2, 60), &["Expected comma", "the `(` at 2:18 is never closed"], s(M) + "\n surface: Overlay(under: Material(\"a\"), over: Material(\"b\")\n"),
        row("unknown_top_field", (2, 2), &["`colour`", "`seed`, `include`, `materials`, `maps`, `body`, `surface`, or `stage`"], gem(" colour: 1,\n surface: Material(\"a\")")),
        row("unknown_field_voronoi", (3, 4), &["`size` in `Voronoi`", "`scale`", "`entries`", "`fill`"], gem(" surface: Voronoi(scale: 0.1,\n   size: 2.0, entries: [(1.0, Material(\"a\"))])")),
        row("unknown_field_coat", (3, 66), &["`colour` in `CoatDesc`", "`ior`", "`tint`"], coat("ior: 1.5, roughness: 1.0, colour: 1")),
        row("unknown_field_stage", (4, 3), &["`lighting` in `StageDesc`", "`lights`", "`camera`"], stage("  lighting: [],")),
        row("unknown_field_camera", (5, 4), &["`zoom` in `Perspective`", "`fov`"], stage("  camera: Perspective(from: (0.0, 1.0, 5.0), to: (0.0, 0.0, 0.0),\n   zoom: 2.0),")),
        row("number_for_string", (3, 18), &["Expected string"], gem(" surface: Overlay(under: Material(\"a\"),\n  over: Material(3))")),
        row("variant_voronoy", (2, 11), &["`Voronoy`", "`Voronoi`"], gem(" surface: Voronoy(scale: 1.0)")),
        row("variant_plastic", (3, 9), &["`Plastic`", "`Lambert`", "`Conductor`"], s("(materials: {\n \"c\": (coats: [],\n  base: Plastic(albedo: Gray(0.5))),\n},\n surface: Material(\"c\"))")),
        // --- Names; a name in a comment never attracts the error.
        row("unknown_material", (5, 11), &["unknown material \"garnett\"", "did you mean \"garnet\""], s("(materials: {\n \"garnet\": (base: Lambert(albedo: Gray(0.5))),\n},\n // was Material(\"garnett\") before\n surface: Material(\"garnett\"))")),
        row("unknown_map", (3, 29), &["unknown map \"tile\"", "did you mean \"tiles\""], gem(" maps: { \"tiles\": Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\"))]) },\n /* Map(\"tile\") */ surface: Map(\"tile\")")),
        // --- Coats and bases (checked after parsing, located at the field in the right coat).
        row("ior_one", (3, 40), &["material \"c\"", "coats[1].ior = 1 ", "1.0001 ..= 10"], coat("ior: 1.0, roughness: 1.0")),
        row("ior_half", (3, 56), &["coats[1].ior = 0.5", "1.0001 ..= 10"], coat("roughness: 1.0, ior: 0.5")),
        row("ior_nan", (3, 40), &["coats[1].ior = NaN", "1.0001 ..= 10"], coat("ior: NaN, roughness: 1.0")),
        row("roughness_zero", (3, 50), &["coats[1].roughness = 0 ", "0.01 ..< 90"], coat("ior: 1.5, roughness: 0.0")),
        row("roughness_ninety", (3, 50), &["coats[1].roughness = 90", "0.01 ..< 90"], coat("ior: 1.5, roughness: 90.0")),
        row("thickness_negative", (3, 66), &["coats[1].thickness = -1", "any finite value ≥ 0"], coat("ior: 1.5, roughness: 1.0, thickness: -1.0")),
        row("absorption_negative", (3, 82), &["coats[1].absorption[0] = -1", "any finite value ≥ 0"], coat("ior: 1.5, roughness: 1.0, thickness: 1.0, absorption: Rgb(-1.0, 0.0, 0.0)")),
        row("tint_no_thickness", (3, 66), &["coats[1].tint needs thickness > 0"], coat("ior: 1.5, roughness: 1.0, tint: Gray(0.5)")),
        row("absorption_and_tint", (3, 39), &["coats[1]", "either `absorption` or `tint`, not both"], coat("ior: 1.5, roughness: 1.0, thickness: 1.0, absorption: Gray(0.1), tint: Gray(0.5)")),
        row("albedo_nan", (3, 17), &["base.albedo", "must be finite"], s("(materials: {\n \"c\": (coats: [(ior: 1.5, roughness: 1.0)],\n  base: Lambert(albedo: Rgb(0.5, NaN, 0.5))),\n},\n surface: Material(\"c\"))")),
        row("srgb_above_one", (3, 17), &["base.albedo", "Srgb(1.2, 0.5, 0.5)", "0 ..= 1"], s("(materials: {\n \"c\": (coats: [(ior: 1.5, roughness: 1.0)],\n  base: Lambert(albedo: Srgb(1.2, 0.5, 0.5))),\n},\n surface: Material(\"c\"))")),
        row("hex_five_digits", (3, 17), &["Hex(\"#12345\")", "#rrggbb"], s("(materials: {\n \"c\": (coats: [(ior: 1.5, roughness: 1.0)],\n  base: Lambert(albedo: Hex(\"#12345\"))),\n},\n surface: Material(\"c\"))")),
        // --- Map numbers (checked while parsing, located at the number).
        row("fill_above_one", (3, 10), &["fill = 1.5", "0 ..= 1"], gem(" surface: Voronoi(scale: 0.1,\n   fill: 1.5, entries: [(1.0, Material(\"a\"))])")),
        row("fill_negative", (3, 10), &["fill = -0.1", "0 ..= 1"], gem(" surface: Voronoi(scale: 0.1,\n   fill: -0.1, entries: [(1.0, Material(\"a\"))])")),
        row("scale_zero", (3, 11), &["scale = 0 ", "0.0001 ..= 10000"], gem(" surface: Voronoi(entries: [(1.0, Material(\"a\"))],\n   scale: 0.0)")),
        row("scale_inf", (3, 11), &["scale = inf", "0.0001 ..= 10000"], gem(" surface: Voronoi(entries: [(1.0, Material(\"a\"))],\n   scale: inf)")),
        row("weight_zero", (3, 5), &["weight = 0 ", "0 <.. 1e6"], gem(" surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\")),\n   (0.0, Material(\"b\"))])")),
        row("weights_all_zero", (3, 15), &["weight = 0 ", "0 <.. 1e6"], gem(" surface: Voronoi(scale: 0.1,\n   entries: [(0.0, Material(\"a\")), (0.0, Material(\"b\"))])")),
        row("weight_nan", (2, 42), &["weight = NaN", "0 <.. 1e6"], gem(" surface: Voronoi(scale: 0.1, entries: [(NaN, Material(\"a\"))])")),
        row("octaves_40", (3, 13), &["octaves = 40", "1 ..= 16"], gem(" surface: Switch(by: Marble(scale: 1.0,\n   octaves: 40), stops: [(0.0, Material(\"a\"))])")),
        row("jitter_2", (3, 12), &["jitter = 2", "0 ..= 1"], gem(" surface: Voronoi(scale: 0.1,\n   jitter: 2.0, entries: [(1.0, Material(\"a\"))])")),
        row("cone_95", (3, 27), &["half_angle = 95", "0 ..= 89"], gem(" surface: Voronoi(scale: 0.1, entries: [(1.0, Material(\"a\"))],\n   bump: Cone(half_angle: 95.0))")),
        // --- Stage (numbers at the number; a tuple or colour at its closing parenthesis).
        row("spp_zero", (5, 9), &["spp = 0", "1 ..= 1048576"], stage("  render: (width: 64,\n   spp: 0),")),
        row("width_zero", (5, 11), &["image size = 0", "1 ..= 16384"], stage("  render: (spp: 4,\n   width: 0),")),
        row("pixels_too_many", (4, 3), &["16384x8192 is 134217728 pixels", "at most 67108864"], stage("  render: (spp: 4,\n   width: 16384, height: 8192),")),
        row("fov_zero", (5, 9), &["fov = 0", "1 ..= 170"], stage("  camera: Perspective(from: (0.0, 1.0, 5.0), to: (0.0, 0.0, 0.0),\n   fov: 0.0),")),
        row("camera_inf", (5, 10), &["(0.0, inf, 5.0)", "finite"], stage("  camera: Perspective(to: (0.0, 0.0, 0.0),\n   from: (0.0, inf, 5.0)),")),
        row("camera_nan", (5, 8), &["(NaN, 0.0, 0.0)", "finite"], stage("  camera: Orthographic(from: (0.0, 1.0, 5.0), height: 2.0,\n   to: (NaN, 0.0, 0.0)),")),
        row("radiance_negative", (5, 14), &["radiance [-1.0, 0.0, 0.0]", "allowed 0 ..="], stage("  lights: [Disc(center: (0.0, 4.0, 0.0), radius: 1.0,\n   radiance: Rgb(-1.0, 0.0, 0.0))],")),
        row("camera_from_is_to", (5, 3), &["stage.camera", "equals `from`"], stage("  render: (spp: 4),\n  camera: Perspective(from: (1.0, 2.0, 3.0), to: (1.0, 2.0, 3.0)),")),
        row("mesh_missing", (5, 10), &["mesh \"no_such_mesh.obj\"", "no such file"], stage("  shape: Mesh(scale: 2.0,\n   file: \"no_such_mesh.obj\"),")),
        row("env_map_missing", (5, 10), &["environment map \"no_sky.exr\"", "no such file"], stage("  environment: Map(intensity: 2.0,\n   file: \"no_sky.exr\"),")),
        // --- Structure.
        row("transparent_root", (3, 2), &["surface can be transparent", "Overlay"], gem(" maps: {},\n surface: Voronoi(scale: 0.1, fill: 0.5, entries: [(1.0, Material(\"a\"))])")),
        row("map_cycle", (2, 51), &["map \"x\" contains itself"], gem(" maps: { \"x\": Voronoi(scale: 1.0, entries: [(1.0, Map(\"x\"))]) },\n surface: Map(\"x\"),")),
        row("glitter_17_voronoi", (2, 2), &["visit 17 Voronoi maps", "at most 16"], nested_glitter(17)),
        row("include_missing", (4, 4), &["include \"no_such_library.ron\"", "no such file"], gem(" // \"no_such_library.ron\" is missing\n include: [\"lib.ron\",\n   \"no_such_library.ron\"],\n surface: Material(\"from_lib\")")),
        Row { file: "cycle_b.ron", ..row("include_cycle", (3, 15), &["include \"cycle_a.ron\" makes a cycle", "cycle_a.ron → ", "cycle_b.ron → "], gem(" include: [\"cycle_a.ron\"],\n surface: Material(\"from_b\")")) },
        Row { file: "dup.ron", ..row("include_duplicate", (4, 9), &["material \"a\" is already defined at bad.ron:1:15", "unique"], gem(" include: [\"dup.ron\"],\n surface: Material(\"a\")")) },
        row("duplicate_material_key", (3, 3), &["\"a\" is defined twice", "unique"], s("(materials: {\n \"a\": (base: Lambert(albedo: Gray(0.5))),\n \"a\": (base: Lambert(albedo: Gray(0.2))),\n},\n surface: Material(\"a\"))")),
        row("unknown_material_in_unused_map", (2, 55), &["unknown material \"c\""], gem(" maps: { \"spare\": Voronoi(scale: 0.1, entries: [(1.0, Material(\"c\"))]) },\n surface: Material(\"a\"),")),
        row("no_materials_at_all", (1, 26), &["unknown material \"x\""], s("(materials: {}, surface: Material(\"x\"))")),
        row("no_materials_unknown_map", (1, 26), &["unknown map \"m\""], s("(materials: {}, surface: Map(\"m\"))")),
        row("unknown_field_in_metal", (2, 79), &["field named `q`", "expected either `n` or `k`"], s("(materials: {\n \"m\": (base: Conductor(metal: Complex(n: (1.0, 1.0, 1.0), k: (1.0, 1.0, 1.0), q: 1.0), roughness: 3.0)),\n},\n surface: Material(\"m\"))")),
        // Positions refined after parsing: type errors on the value, checks of a whole Switch on
        // the stop or blend they reject, a cycle at the use that closes it, nesting at the
        // definition of the named map where the limit is crossed, a light at its own entry.
        row("string_for_number", (2, 26), &["Expected float", "found `\"big\"`"], gem(" surface: Voronoi(scale: \"big\", entries: [(1.0, Material(\"a\"))])")),
        row("thresholds_unordered", (4, 6), &["strictly ascending", "stops[0] = 0.5 ≥ stops[1] = 0.2"], gem(" surface: Switch(by: Constant(0.0),\n   stops: [(0.5, Material(\"a\")),\n     (0.2, Material(\"b\"))],\n ")),
        row("blend_too_wide", (2, 44), &["blend = 0.5", "0 ..= 0.2", "narrowest gap"], gem(" surface: Switch(by: Constant(0.0), blend: 0.5,\n   stops: [(0.0, Material(\"a\")), (0.2, Material(\"b\"))],\n ")),
        row("map_cycle_used_first", (3, 51), &["map \"x\" contains itself"], gem(" surface: Map(\"x\"),\n maps: { \"x\": Voronoi(scale: 1.0, entries: [(1.0, Map(\"x\"))]) },")),
        row("nesting_too_deep", (34, 3), &["maps.\"m31\".stops[0]", "nest more than 64 levels", "too deep to evaluate"], deep_switches(70)),
        // --- Translucent bodies (issue 17): numbers while parsing, combinations after.
        row("body_ior", (2, 14), &["body.ior = 0.9", "1.0001 ..= 4"], gem(" body: (ior: 0.9),\n surface: Body")),
        row("body_roughness", (2, 30), &["body.roughness = 95", "0.01 ..< 90"], gem(" body: (ior: 1.5, roughness: 95.0),\n surface: Body")),
        row("body_alpha", (2, 26), &["body.alpha = 20", "0.0002 ..= 10"], gem(" body: (ior: 1.5, alpha: 20.0),\n surface: Body")),
        row("body_roughness_and_alpha", (2, 2), &["body", "either `roughness` (degrees) or `alpha`, not both"], gem(" body: (ior: 1.5, roughness: 2.0, alpha: 0.1),\n surface: Body")),
        row("body_sigma_negative", (3, 24), &["medium.absorption = (1.0, -1.0, 0.0)", "0 ..= 10000 per object unit"], gem(" body: (ior: 1.5,\n  medium: (absorption: (1.0, -1.0, 0.0))),\n surface: Body")),
        row("body_colour_zero", (3, 20), &["medium.colour", "each channel must be 0 <.. 1"], gem(" body: (ior: 1.5,\n  medium: (colour: Gray(0.0), distance: 1.0)),\n surface: Body")),
        row("body_colour_without_distance", (3, 3), &["body.medium", "`colour` needs `distance`"], gem(" body: (ior: 1.5,\n  medium: (colour: Gray(0.5))),\n surface: Body")),
        row("body_g_one", (3, 39), &["phase g = 1", "-0.99 ..= 0.99"], gem(" body: (ior: 1.5,\n  medium: (phase: HenyeyGreenstein(g: 1.0))),\n surface: Body")),
        row("body_missing", (2, 11), &["`Body`", "no `body: (ior: …)`"], gem(" surface: Body")),
        // --- Platelets (issue 18): numbers while parsing, at the value; the compiler's checks at
        // the population's entry or `density` (the second population here, after a valid one).
        row("platelets_density_zero", (5, 13), &["platelets.density = 0 ", "0 <.. 10000000"], platelets("(radius: (0.01, 0.03),\n   density: 0.0, orientation: Uniform, entries: [(1.0, \"a\")])")),
        row("platelets_density_negative", (4, 35), &["platelets.density = -5", "0 <.. 10000000"], platelets("(radius: (0.01, 0.03), density: -5.0, orientation: Uniform, entries: [(1.0, \"a\")])")),
        row("platelets_radius_reversed", (4, 29), &["platelets.radius = (0.03, 0.01)", "0 < smallest <= largest <= 1000"], platelets("(density: 3000.0, radius: (0.03, 0.01), orientation: Uniform, entries: [(1.0, \"a\")])")),
        row("platelets_spread_120", (4, 95), &["spread = 120", "0 ..= 90"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Aligned(axis: (0.0, 1.0, 0.0), spread: 120.0), entries: [(1.0, \"a\")])")),
        row("platelets_axis_zero", (4, 70), &["axis = (0.0, 0.0, 0.0)", "finite, non-zero direction"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Aligned(axis: (0.0, 0.0, 0.0), spread: 10.0), entries: [(1.0, \"a\")])")),
        row("platelets_unknown_material", (4, 93), &["body.platelets[1]", "unknown material \"c\"", "layered materials"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\"), (1.0, \"c\")])")),
        row("platelets_weight_zero", (4, 88), &["entry weight = 0 ", "0 <.. 1000000"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\"), (0.0, \"b\")])")),
        row("platelets_entries_empty", (4, 75), &["list is empty"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [])")),
        row("platelets_unknown_field", (4, 88), &["`size` in `PlateletsDesc`", "`density`", "`seed`"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")], size: 2.0)")),
        row("platelets_too_dense", (5, 13), &["body.platelets[1]", "density 1000000 with radius up to 0.2", "more than 16 platelets", "overlap"], platelets("(radius: (0.1, 0.2), orientation: Uniform, entries: [(1.0, \"a\")],\n   density: 1000000.0)")),
        // The density modulation: a field as a Switch's, its numbers checked while parsing; a
        // field that never exceeds 0 is the compiler's error, at the value of `modulation`.
        row("platelets_modulation_scale_zero", (5, 30), &["scale = 0 ", "0.0001 ..= 10000"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Perlin(scale: 0.0))")),
        row("platelets_modulation_octaves_40", (5, 68), &["octaves = 40", "1 ..= 16"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Sum([Constant(0.5), Turbulence(scale: 0.2, octaves: 40)]))")),
        row("platelets_modulation_unknown_field", (5, 39), &["`size`", "`scale`"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Turbulence(scale: 0.2, size: 2.0))")),
        row("platelets_modulation_not_a_field", (5, 16), &["`Material`", "`Perlin`"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Material(\"a\"))")),
        row("platelets_modulation_zero", (5, 16), &["body.platelets[1]", "modulation", "never above 0", "0 everywhere"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Constant(0.0))")),
        row("platelets_modulation_remap_below_zero", (5, 16), &["body.platelets[1]", "modulation", "-1 ..= 0", "never above 0"], platelets("(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")],\n   modulation: Remap(field: Perlin(scale: 0.3), from: (-1.0, 1.0), to: (-1.0, 0.0), clamp: true))")),
        row("platelets_stone_too_large", (4, 3), &["body.platelets[1]: the stone spans 205", "platelet cells along its diagonal, at most 65533", "allowed 1 ..= 65533", "a smaller stone"], gem(" body: (ior: 1.5, platelets: [\n  (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")]),\n  (density: 10000000.0, radius: (0.001, 0.002), orientation: Uniform, entries: [(1.0, \"a\")])]),\n surface: Body,\n stage: (shape: Sphere(radius: 200.0)),\n")),
        row("platelets_under_ior_3_5", (3, 20), &["body.platelets[0]", "material \"b\" under the body", "outside_ior = 3.5", "1 ..= 3"], gem(" body: (ior: 3.5, platelets: [(density: 3000.0, radius: (0.01, 0.03), orientation: Uniform,\n   entries: [(1.0, \"b\"), (1.0, \"a\")])]),\n surface: Body")),
        // Readable ranges: no bound printed as the largest float or integer.
        row("blend_one_stop", (2, 75), &["blend = -1", "allowed any finite value ≥ 0"], gem(" surface: Switch(by: Constant(0.0), stops: [(0.0, Material(\"a\"))], blend: -1.0)")),
        row("seed_negative", (2, 8), &["seed = -1", "allowed 0 ..= 2⁶⁴ − 1 (a whole number)"], gem(" seed: -1,\n surface: Material(\"a\")")),
        // A Sellmeier law below its resonance (C₁ = 0.25 µm²: 500 nm) gives n² < 1: the law's own
        // n², not the index 1 it is clamped to.
        row("sellmeier_n2_below_one", (3, 3), &["body.dispersion", "n² = 0.4618 < 1 (n = 0.6796) at 360 nm", "allowed 1 <.. 4"], gem(" body: (ior: 1.6771,\n  dispersion: Sellmeier(b: (0.5, 0.0, 0.0), c: (0.25, 0.0, 0.0))),\n surface: Body")),
        // --- Crystal optics (issue 40).
        row("crystal_rough", (3, 3), &["body.crystal", "needs a smooth boundary"], gem(" body: (ior: 1.544, roughness: 2.0,\n  crystal: Uniaxial(ne: 1.553, axis: (0.0, 1.0, 0.0))),\n surface: Body")),
        row("crystal_ne_five", (3, 25), &["crystal.ne = 5", "1.0001 ..= 4"], gem(" body: (ior: 1.544,\n  crystal: Uniaxial(ne: 5.0, axis: (0.0, 1.0, 0.0))),\n surface: Body")),
        row("crystal_axis_zero", (3, 38), &["axis = (0.0, 0.0, 0.0)", "non-zero direction"], gem(" body: (ior: 1.544,\n  crystal: Uniaxial(ne: 1.553, axis: (0.0, 0.0, 0.0))),\n surface: Body")),
        row("pleochroism_black", (4, 4), &["body.crystal.pleochroism.ordinary", "0 <..= 1"], gem(" body: (ior: 1.544,\n  crystal: Uniaxial(ne: 1.553, axis: (0.0, 1.0, 0.0),\n   pleochroism: (ordinary: Gray(0.0), extraordinary: Gray(0.5), distance: 1.0))),\n surface: Body")),
        row("biaxial_beta_below_ior", (3, 20), &["body.crystal", "ior ≤ beta ≤ gamma", "1.544 / 1.54 / 1.553"], gem(" body: (ior: 1.544,\n  crystal: Biaxial(beta: 1.54, gamma: 1.553, x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0))),\n surface: Body")),
        row("biaxial_gamma_five", (3, 40), &["crystal.gamma = 5", "1.0001 ..= 4"], gem(" body: (ior: 1.544,\n  crystal: Biaxial(beta: 1.548, gamma: 5.0, x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0))),\n surface: Body")),
        row("biaxial_axes_parallel", (3, 72), &["body.crystal.z_axis", "within 5° of x_axis", "at least 5° apart"], gem(" body: (ior: 1.544,\n  crystal: Biaxial(beta: 1.548, gamma: 1.553, x_axis: (1.0, 0.0, 0.0), z_axis: (1.0, 0.05, 0.0))),\n surface: Body")),
        row("trichroism_black", (4, 4), &["body.crystal.pleochroism.gamma", "0 <..= 1"], gem(" body: (ior: 1.544,\n  crystal: Biaxial(beta: 1.548, gamma: 1.553, x_axis: (1.0, 0.0, 0.0), z_axis: (0.0, 0.0, 1.0),\n   pleochroism: (alpha: Gray(0.5), beta: Gray(0.5), gamma: Gray(0.0), distance: 1.0))),\n surface: Body")),
        row("thin_section_unit_zero", (3, 79), &["thin_section.unit_nm = 0", "0 <.. 10000000"], gem(" body: (ior: 1.544,\n  crystal: Uniaxial(ne: 1.553, axis: (0.0, 1.0, 0.0), thin_section: (unit_nm: 0.0))),\n surface: Body")),
        row("analyser_400", (4, 13), &["analyser = 400", "-360 ..= 360"], stage("  analyser: 400.0,")),
        row("polariscope_rotation_500", (4, 33), &["rotation = 500", "-360 ..= 360"], stage("  preset: Polariscope(rotation: 500.0),")),
        row("dichroscope_rotation_minus_720", (4, 33), &["rotation = -720", "-360 ..= 360"], stage("  preset: Dichroscope(rotation: -720.0),")),
        row("polariser_minus_400", (4, 92), &["polariser = -400", "-360 ..= 360"], stage("  lights: [Rect(center: (0.0, 4.0, 0.0), size: (1.0, 1.0), radiance: Gray(1.0), polariser: -400.0)],")),
        row("light_target_is_center", (6, 4), &["stage.lights[1]", "`target` equals `center`"], stage("  lights: [\n   Rect(center: (0.0, 4.0, 0.0), size: (1.0, 1.0), radiance: Gray(1.0)),\n   Disc(center: (1.0, 2.0, 3.0), target: (1.0, 2.0, 3.0), radius: 1.0, radiance: Gray(1.0)),\n  ],")),
    ];
    rows
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/recipe_errors")
}

/// The first error of `row`, or a description of what went wrong (no error, a panic).
fn first_error(row: &Row) -> Result<RecipeError, String> {
    let path = fixtures().join("bad.ron");
    let text = row.text.clone();
    let report = std::panic::catch_unwind(move || {
        GemRecipe::check_source(Source::new("bad.ron", &text), Some(&path))
    })
    .map_err(|_| "check_source panicked".to_string())?;
    report
        .errors
        .into_iter()
        .next()
        .ok_or_else(|| "no error reported".to_string())
}

/// Checks every row; returns one readable paragraph per failing row.
fn check_rows(rows: &[Row]) -> Vec<String> {
    let mut failures = vec![];
    for row in rows {
        let problem = match first_error(row) {
            Err(e) => Some((e, String::new())),
            Ok(e) => {
                let mut wrong = vec![];
                if (e.line, e.col) != (row.line, row.col) {
                    wrong.push(format!(
                        "position: got {}:{}, expected {}:{}",
                        e.line, e.col, row.line, row.col
                    ));
                }
                if !e.file.ends_with(row.file) {
                    wrong.push(format!("file: got {:?}, expected …{}", e.file, row.file));
                }
                for m in row.msg.iter().filter(|m| !e.message.contains(*m)) {
                    wrong.push(format!("message lacks {m:?}"));
                }
                (!wrong.is_empty()).then(|| (wrong.join("; "), e.to_string()))
            }
        };
        if let Some((what, shown)) = problem {
            failures.push(format!(
                "[{}] {what}\n    error: {shown}\n    recipe:\n{}",
                row.name,
                row.text
                    .lines()
                    .enumerate()
                    .map(|(i, l)| format!("    {:>3}| {l}", i + 1))
                    .collect::<Vec<_>>()
                    .join("\n")
            ));
        }
    }
    failures
}

#[test]
fn malformed_recipes_point_at_the_problem() {
    let rows = rows();
    assert!(rows.len() >= 30, "{} rows", rows.len());
    let failures = check_rows(&rows);
    assert!(
        failures.is_empty(),
        "{} of {} rows failed:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}

/// Every error of `many_errors.ron`: an include, a coat and two names, each at its own position.
#[test]
fn one_check_reports_every_error() {
    let path = fixtures().join("many_errors.ron");
    let source = Source::read(&path).expect("the fixture is readable");
    let report = GemRecipe::check_source(source, Some(&path));
    let expected: [(usize, usize, &[&str]); 4] = [
        (3, 15, &["include \"missing_library.ron\"", "no such file"]),
        (
            7,
            48,
            &[
                "material \"bad_coat\"",
                "coats[0].thickness = -2",
                "any finite value ≥ 0",
            ],
        ),
        (
            15,
            19,
            &["unknown material \"bodyy\"", "did you mean \"body\""],
        ),
        (17, 19, &["unknown material \"glitter\""]),
    ];
    let all: Vec<String> = report.errors.iter().map(|e| e.to_string()).collect();
    assert!(report.errors.len() >= 4, "{all:#?}");
    assert!(report.scene.is_none());
    for (line, col, msg) in expected {
        assert!(
            report.errors.iter().any(|e| (e.line, e.col) == (line, col)
                && e.file.ends_with("many_errors.ron")
                && msg.iter().all(|m| e.message.contains(m))),
            "no error at {line}:{col} saying {msg:?}; got {all:#?}"
        );
    }
    let mut at: Vec<(usize, usize)> = report.errors.iter().map(|e| (e.line, e.col)).collect();
    at.sort();
    at.dedup();
    assert_eq!(
        at.len(),
        report.errors.len(),
        "positions not distinct: {all:#?}"
    );
    assert!(at.iter().all(|&(l, _)| l > 0), "{all:#?}");
}

/// Platelet errors point into the population they are about: two populations under a body of
/// η 3.5 (beyond what a platelet face's layered model allows) both list material "a", one is too
/// dense — each error at its own population's entry or `density` value.
#[test]
fn platelet_errors_point_into_their_population() {
    let text = gem(
        " body: (ior: 3.5, platelets: [\n  (density: 3000.0, radius: (0.01, 0.03), orientation: Uniform, entries: [(1.0, \"a\")]),\n  (radius: (0.1, 0.2), orientation: Uniform, entries: [(2.0, \"b\"), (1.0, \"a\")], density: 1e6)]),\n surface: Body",
    );
    let report = GemRecipe::check_source(Source::new("bad.ron", &text), None);
    let all: Vec<String> = report.errors.iter().map(|e| e.to_string()).collect();
    let expected: [(usize, usize, &[&str]); 4] = [
        (
            3,
            81,
            &["body.platelets[0]", "material \"a\" under the body"],
        ),
        (
            4,
            62,
            &["body.platelets[1]", "material \"b\" under the body"],
        ),
        (
            4,
            74,
            &["body.platelets[1]", "material \"a\" under the body"],
        ),
        (4, 90, &["body.platelets[1]", "density 1000000"]),
    ];
    for (line, col, msg) in expected {
        assert!(
            report.errors.iter().any(
                |e| (e.line, e.col) == (line, col) && msg.iter().all(|m| e.message.contains(m))
            ),
            "no error at {line}:{col} saying {msg:?}; got {all:#?}\n{text}"
        );
    }
}

fn lapidary_check(files: &[String]) -> (Option<i32>, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_lapidary"))
        .arg("check")
        .args(files)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("the binary runs");
    let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
    (out.status.code(), text(&out.stdout), text(&out.stderr))
}

#[test]
fn check_command_prints_positions_and_fails() {
    let bad = "tests/recipe_errors/many_errors.ron";
    let good = "gems/sunstone.ron";
    let (code, stdout, stderr) = lapidary_check(&[bad.into(), good.into()]);
    let shown = format!("stdout:\n{stdout}\nstderr:\n{stderr}");
    assert_eq!(code, Some(1), "{shown}");
    for at in [
        "3:15: include",
        "7:48: material",
        "15:19: unknown",
        "17:19: unknown",
    ] {
        assert!(
            stderr.contains(&format!("error: {bad}:{at}")),
            "{at}\n{shown}"
        );
    }
    let errors = stderr.lines().filter(|l| l.starts_with("error: ")).count();
    assert!(errors >= 4, "{shown}");
    assert!(stdout.contains(&format!("{good}: ok")), "{shown}");
    assert!(!stdout.contains(&format!("{bad}: ok")), "{shown}");
}

#[test]
fn check_command_accepts_every_shipped_file() {
    let mut files: Vec<String> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("gems"))
            .expect("gems/ is readable")
            .map(|e| {
                e.expect("a directory entry")
                    .file_name()
                    .to_string_lossy()
                    .into_owned()
            })
            .filter(|n| n.ends_with(".ron"))
            .map(|n| format!("gems/{n}"))
            .collect();
    files.sort();
    assert!(files.len() >= 2, "{files:?}");
    files.push("materials/course.ron".into());
    let (code, stdout, stderr) = lapidary_check(&files);
    assert_eq!(code, Some(0), "stdout:\n{stdout}\nstderr:\n{stderr}");
    for f in &files {
        assert!(stdout.contains(&format!("{f}: ok")), "{f}\n{stdout}");
    }
}
