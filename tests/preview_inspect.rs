//! The preview's pixel inspector over HTTP (issue 38): the map path that chose each pixel's
//! material (named maps by name, each Voronoi map's cell and entry, the overlay's and the switch's
//! branch) agrees with the material and cells it reports, and for a translucent stone the camera
//! ray refracted into the body meets the platelets and the far side, with Snell's law and the
//! medium's transmittance.

mod preview_common;

use preview_common::{scratch, start};
use serde_json::Value;

/// The stone pixels of the `64 × 48` image on every other row and column.
fn stone_pixels(p: &preview_common::Preview) -> Vec<Value> {
    let mut out = vec![];
    for y in (0..48).step_by(2) {
        for x in (0..64).step_by(2) {
            let v = p.get(&format!("/inspect?x={x}&y={y}")).json();
            if v["hit"] == "stone" {
                out.push(v);
            }
        }
    }
    out
}

#[test]
fn the_map_path_explains_each_lepidolite_pixel() {
    let p = start(&scratch("inspect-map"), &["--spp", "1"]);
    p.wait("the first image", |s| s["state"] == "done");
    let pixels = stone_pixels(&p);
    assert!(pixels.len() > 100, "{} stone pixels", pixels.len());
    let (mut glitter, mut under, mut named) = (0, 0, 0);
    for v in &pixels {
        let map = v["map"].as_array().unwrap();
        // gems/lepidolite.ron: `surface: Overlay(under: Switch(…), over: Voronoi(…))`.
        assert_eq!(map[0]["path"], "surface", "{v}");
        assert_eq!(map[0]["kind"], "Overlay", "{v}");
        assert_eq!(map[1]["path"], "surface.over", "{v}");
        assert_eq!(map[1]["kind"], "Voronoi (sparse)", "{v}");
        let covered = map[0]["shows"] == "over";
        assert_eq!(map[1]["filled"], covered, "{v}");
        if covered {
            glitter += 1;
            let entry = map[1]["entry"].as_u64().unwrap();
            assert!(entry < map[1]["entries"].as_u64().unwrap());
            assert_eq!(
                map[2]["path"],
                format!("surface.over.entries[{entry}]"),
                "{v}"
            );
            assert_eq!(v["glitter_cell"], map[1]["cell"], "{v}");
        } else {
            under += 1;
            assert_eq!(map[2]["path"], "surface.under", "{v}");
            assert_eq!(map[2]["kind"], "Switch", "{v}");
            assert!(v["glitter_cell"].is_null(), "{v}");
            // The switch's stop is the one its value selects (stops at 0.0 and 0.9; the recipe
            // has no blend band).
            let value = map[2]["value"].as_f64().unwrap();
            let want = if value >= 0.9 { 1 } else { 0 };
            assert_eq!(map[2]["stop"], want, "{v}");
            assert_eq!(
                map[3]["path"],
                format!("surface.under.stops[{want}]"),
                "{v}"
            );
            // Both stops are named maps, and the inspector names them.
            let name = map[3]["defined"].as_str().unwrap();
            assert!(
                name == "maps.\"tiles\"" || name == "maps.\"inclusions\"",
                "{v}"
            );
            named += map
                .iter()
                .filter(|s| {
                    s["defined"] == "maps.\"dark_tiles\"" || s["defined"] == "maps.\"bright_tiles\""
                })
                .count();
        }
        // Levels grow by one from a node to the node it chose.
        for w in map.windows(2) {
            assert!(w[1]["level"].as_u64() <= Some(w[0]["level"].as_u64().unwrap() + 1));
        }
        // The walk ends at the material the pixel reports, and its cells are the trail.
        let last = map.last().unwrap();
        assert_eq!(last["kind"], "Material", "{v}");
        assert_eq!(last["name"], v["material"]["name"], "{v}");
        assert_eq!(last["index"], v["material"]["index"], "{v}");
        let cells: Vec<&Value> = map.iter().filter_map(|s| s.get("cell")).collect();
        let trail: Vec<&Value> = v["cells"].as_array().unwrap().iter().collect();
        assert_eq!(cells, trail, "{v}");
        // The stack's model and knobs.
        let model = &v["material"]["model"];
        assert!(model["summary"].as_str().unwrap().contains("base"), "{v}");
        assert!(model["fresnel"].is_string() && model["calibration"].is_boolean());
    }
    assert!(
        glitter > 0 && under > 0 && named > 0,
        "glitter {glitter}, under {under}, named tiles {named}"
    );
}

#[test]
fn the_inspector_follows_the_camera_ray_into_a_translucent_body() {
    let dir = scratch("inspect-body");
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/gems/oregon-sunstone.ron")).unwrap();
    let text = text.replace("\"../data/", &format!("\"{root}/data/"));
    std::fs::write(dir.join("lepidolite.ron"), text).unwrap();
    let p = start(&dir, &["--spp", "1"]);
    p.wait("the first image", |s| s["state"] == "done");
    let pixels = stone_pixels(&p);
    assert!(pixels.len() > 100, "{} stone pixels", pixels.len());
    let mut hits = 0;
    for v in &pixels {
        assert_eq!(v["material"]["name"], "Body", "{v}");
        let inside = &v["inside"];
        let (n, i, t) = (
            inside["ior"].as_f64().unwrap(),
            inside["incidence_deg"].as_f64().unwrap().to_radians(),
            inside["refraction_deg"].as_f64().unwrap().to_radians(),
        );
        assert!((n - 1.565).abs() < 1e-6);
        // Snell's law at the boundary: sin θi = n sin θt.
        assert!((i.sin() - n * t.sin()).abs() < 1e-4, "{v}");
        let exit = inside["exit_distance"].as_f64().unwrap();
        assert!(exit > 0.0 && exit < 3.0, "{v}");
        let reach = match inside["platelet"].as_object() {
            Some(pl) => {
                hits += 1;
                assert_eq!(pl["material"]["name"], "copper_platelet", "{v}");
                let d = pl["distance"].as_f64().unwrap();
                assert!(d > 0.0 && d < exit, "{v}");
                // Aligned platelets (axis +y, spread 4°): the normal is within a few degrees of it.
                let ny = pl["normal"][1].as_f64().unwrap().abs();
                assert!(ny > 20f64.to_radians().cos(), "{v}");
                d
            }
            None => exit,
        };
        // Beer–Lambert along the ray with the medium's coefficients.
        for c in 0..3 {
            let a = inside["medium"]["sigma_a"][c].as_f64().unwrap();
            let s = inside["medium"]["sigma_s"][c].as_f64().unwrap();
            let tr = inside["transmittance"][c].as_f64().unwrap();
            let want = (-(a + s) * reach).exp();
            assert!((tr - want).abs() < 1e-4 * want.max(1e-3), "{v}");
            assert!(tr > 0.0 && tr <= 1.0);
        }
    }
    // 800 platelets per unit³ of mean area ≈ 0.0025 unit²: a ray half a unit long meets one
    // with probability near ½, so both cases occur among the stone's pixels.
    assert!(
        hits > 5 && hits < pixels.len() - 5,
        "{hits} of {} rays meet a platelet",
        pixels.len()
    );
}

#[test]
fn the_inspector_names_the_facet_of_a_cut_stone() {
    let dir = scratch("inspect-facet");
    std::fs::write(
        dir.join("lepidolite.ron"),
        r#"(materials: {"m": (base: Lambert(albedo: Gray(0.5)))}, surface: Material("m"),
            stage: (shape: Cut(Brilliant()), ground: Off,
                    camera: Orthographic(from: (0.0, 5.0, 0.001), to: (0.0, 0.0, 0.0), height: 2.4)))"#,
    )
    .unwrap();
    let p = start(&dir, &["--spp", "1"]);
    p.wait("the first image", |s| s["state"] == "done");
    // Seen from above: the table in the middle, a crown facet off it, nothing at the corner.
    let centre = p.get("/inspect?x=32&y=24").json();
    assert_eq!(centre["facet"], "table", "{centre}");
    let side = p.get("/inspect?x=50&y=24").json();
    let name = side["facet"].as_str().unwrap();
    assert!(
        ["star", "bezel", "upper girdle"]
            .iter()
            .any(|g| name.starts_with(g)),
        "{side}"
    );
    assert!(p.get("/inspect?x=0&y=0").json()["facet"].is_null());
}
