//! A failed write is a failure, for every command that writes: an I/O error at any point of any
//! output (`ENOSPC`, `EIO`, `EDQUOT`; at the first byte, mid-file, at `fsync`; in one format
//! only) makes the command exit non-zero naming the file and the error, every existing output
//! stays byte-identical, and no temporary file is left behind. The errors are injected by the
//! debug/test-build hook `LAPIDARY_WRITE_FAULT` (src/image/atomic/sink.rs); `full_disk.rs` does
//! the same on a real, full tmpfs.
//!
//! Each case runs its command once to make the old outputs, then with each fault a second
//! variant whose outputs differ (checked at the end by running it without a fault).

use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Command, Output, Stdio};

#[path = "common/scratch.rs"]
mod scratch;
use scratch::{Scratch, text};
#[path = "common/writes.rs"]
mod writes;
use writes::{Case, cases};

/// The faults tried on every command, and what the OS error says.
const FAULTS: [(&str, &str); 8] = [
    ("ENOSPC@0", "No space left on device"),
    ("EIO@60", "Input/output error"),
    ("EDQUOT@sync", "Disk quota exceeded"),
    ("ENOSPC@flush", "No space left on device"),
    ("ENOSPC@80:png", "No space left on device"),
    ("EIO@sync:exr", "Input/output error"),
    ("EDQUOT@0:csv", "Disk quota exceeded"),
    ("EIO@0:sbatch", "Input/output error"),
];

fn run(dir: &Path, args: &[String], fault: Option<&str>) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lapidary"));
    c.args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .env_remove("LAPIDARY_WRITE_FAULT");
    if let Some(f) = fault {
        c.env("LAPIDARY_WRITE_FAULT", f);
    }
    c.output().expect("binary runs")
}

/// Every file under `dir` (recursively) with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().map(Result::unwrap) {
            let p = e.path();
            if e.file_type().unwrap().is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

/// Runs one case through every fault.
fn check(case: &Case) {
    let s = Scratch::new("write-failures", case.name);
    (case.setup)(&s);
    let first = run(&s.0, &case.first, None);
    assert!(
        case.ok_status.contains(&first.status.code().unwrap_or(-1)),
        "{}: the first run failed:\n{}",
        case.name,
        text(&first.stderr)
    );
    let before = snapshot(&s.0);
    for out in &case.outputs {
        assert!(
            before.contains_key(*out),
            "{}: no {out} after the first run",
            case.name
        );
    }
    let mut struck = 0;
    for (fault, says) in FAULTS {
        // A fault limited to a format the command does not write would not strike.
        let applies = match fault.split_once(':') {
            Some((_, ext)) => case.outputs.iter().any(|f| f.ends_with(&format!(".{ext}"))),
            None => true,
        };
        if !applies {
            continue;
        }
        struck += 1;
        let o = run(&s.0, &case.second, Some(fault));
        let after = snapshot(&s.0);
        let err = text(&o.stderr);
        let code = o.status.code().unwrap_or(0);
        assert!(
            code != 0 && !case.ok_status.contains(&code),
            "{} with {fault}: exit {code}, as if it had worked\n{err}",
            case.name
        );
        assert!(
            err.contains(says) && err.contains("cannot write"),
            "{} with {fault}: the error must name the file and the OS error:\n{err}",
            case.name
        );
        for (name, bytes) in &before {
            assert!(
                after.get(name) == Some(bytes),
                "{} with {fault}: {name} changed or vanished",
                case.name
            );
        }
        for name in after.keys() {
            assert!(
                !name.contains(".lapidary-"),
                "{} with {fault}: temporary file {name} left behind",
                case.name
            );
            assert!(
                before.contains_key(name) || case.may_add.iter().any(|p| name.starts_with(p)),
                "{} with {fault}: new file {name}",
                case.name
            );
        }
    }
    assert!(struck >= 4, "{}: too few faults applied", case.name);
    // Without a fault the second variant does replace the outputs: the checks above had teeth.
    let o = run(&s.0, &case.second, None);
    assert!(
        case.ok_status.contains(&o.status.code().unwrap_or(-1)),
        "{}: the second run failed without a fault:\n{}",
        case.name,
        text(&o.stderr)
    );
    let after = snapshot(&s.0);
    for out in &case.outputs {
        assert_ne!(
            before.get(*out),
            after.get(*out),
            "{}: {out} is the same after the second run",
            case.name
        );
    }
}

macro_rules! case_tests {
    ($($name:ident),* $(,)?) => {$(
        #[test]
        fn $name() {
            let all = cases();
            let case = all
                .iter()
                .find(|c| c.name == stringify!($name))
                .expect("a case of that name");
            check(case);
        }
    )*};
}

case_tests!(
    render,
    render_part,
    merge,
    compare_heatmap,
    regress_update,
    regress_failure,
    map,
    tradeoff,
    brdf_plot,
    farm_slurm,
    farm_regress,
);

#[test]
fn every_case_is_tested() {
    let names: Vec<&str> = cases().iter().map(|c| c.name).collect();
    assert_eq!(
        names,
        [
            "render",
            "render_part",
            "merge",
            "compare_heatmap",
            "regress_update",
            "regress_failure",
            "map",
            "tradeoff",
            "brdf_plot",
            "farm_slurm",
            "farm_regress"
        ]
    );
}
