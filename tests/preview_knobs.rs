//! The preview's knob controls over HTTP (issue 38): every knob `tradeoff` knows is offered with
//! its values and accepted, bad values and unknown or unrepeatable knobs are refused with the
//! allowed range, each change's cost in paths/s is measured before and after it, and an export
//! with render-level and material knobs equals the batch command it prints, bit for bit.

mod preview_common;

use preview_common::{scratch, start};

#[test]
fn every_offered_knob_value_is_accepted_and_bad_ones_are_refused() {
    let p = start(&scratch("knobs-all"), &["--spp", "1"]);
    let s = p.wait("the first image", |s| s["state"] == "done");
    let choices = s["knob_choices"].as_object().unwrap();
    for key in [
        "model",
        "fresnel",
        "distribution",
        "masking",
        "sampler",
        "max-depth",
    ] {
        assert!(choices.contains_key(key), "{key} offered");
    }
    assert_eq!(choices["facet-bump"], serde_json::json!(["on", "off"]));
    assert_eq!(choices["platelets"], serde_json::json!(["on", "off"]));
    for (key, values) in choices {
        let values: Vec<String> = match values.as_array() {
            Some(v) => v.iter().map(|x| x.as_str().unwrap().to_string()).collect(),
            None => vec!["3".to_string()],
        };
        for v in values {
            let r = p.post("/knobs", &format!(r#"{{"{key}": "{v}"}}"#));
            assert_eq!(r.status, 200, "{key}={v}: {}", r.json());
            assert!(
                r.json()["knobs"]
                    .as_str()
                    .unwrap()
                    .contains(&format!("={v}")),
                "{key}={v}: {}",
                r.json()
            );
        }
    }
    for (body, want) in [
        (r#"{"max-depth": "0"}"#, "1 ..= 1024"),
        (r#"{"medium-depth": "5000"}"#, "0 ..= "),
        (r#"{"fresnel": "fast"}"#, "schlick"),
        (r#"{"compensation": "maybe"}"#, "on, off"),
        (r#"{"frobnicate": "on"}"#, "allowed model"),
        (r#"{"platelets": "explicit"}"#, "on or off in the preview"),
        (r#"{"model": 3}"#, "string or true/false"),
    ] {
        let r = p.post("/knobs", body);
        assert_eq!(r.status, 400, "{body}");
        let e = r.json()["error"].as_str().unwrap().to_string();
        assert!(e.contains(want), "{body}: {e}");
    }
    let many: Vec<String> = (0..41).map(|i| format!(r#""k{i}": "on""#)).collect();
    let r = p.post("/knobs", &format!("{{{}}}", many.join(",")));
    assert_eq!(r.status, 400);
    assert!(r.json()["error"].as_str().unwrap().contains("at most 40"));
}

#[test]
fn a_knob_change_shows_its_cost_and_exports_as_its_command() {
    let dir = scratch("knobs-cost");
    let p = start(&dir, &["--spp", "8"]);
    p.wait("the recipe's image", |s| {
        s["state"] == "done" && s["draft"] == false
    });
    let r = p.post(
        "/knobs",
        r#"{"max-depth": "3", "sampler": "independent", "model": "course"}"#,
    );
    assert_eq!(r.status, 200, "{}", r.json());
    let s = p.wait("the knobs' image", |s| {
        s["state"] == "done"
            && s["draft"] == false
            && s["knob_costs"]
                .as_array()
                .is_some_and(|c| c.len() == 3 && c.iter().all(|c| c["after"].is_number()))
    });
    for c in s["knob_costs"].as_array().unwrap() {
        let (before, after) = (c["before"].as_f64().unwrap(), c["after"].as_f64().unwrap());
        assert!(before > 0.0 && after > 0.0, "{c}");
        let ratio = c["ratio"].as_f64().unwrap();
        assert!((ratio - after / before).abs() < 1e-9 * ratio, "{c}");
    }
    let command = s["command"].as_str().unwrap();
    for flag in ["--max-depth 3", "--sampler independent", "--model course"] {
        assert!(command.contains(flag), "{command}");
    }

    // The export is the batch command's image, bit for bit.
    let r = p.post("/export", "");
    assert_eq!(r.status, 200, "{}", String::from_utf8_lossy(&r.body));
    let v = r.json();
    preview_common::export_is_its_command(&v, &dir);

    // A second change of one knob replaces its entry; the reset is listed too.
    let r = p.post("/knobs", r#"{"max-depth": "5"}"#);
    assert_eq!(r.status, 200);
    let r = p.post("/knobs", r#"{"reset": true}"#);
    let costs = r.json()["knob_costs"].as_array().unwrap().clone();
    let keys: Vec<&str> = costs.iter().map(|c| c["key"].as_str().unwrap()).collect();
    // (serde_json reads an object's fields in name order.)
    assert_eq!(
        keys,
        ["model", "sampler", "max-depth", "reset"],
        "{costs:?}"
    );
    assert_eq!(costs[2]["value"], "5");
}
