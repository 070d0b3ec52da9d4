//! Replays the committed, minimised fuzz corpus (`fuzz/seeds/<target>/`), the working corpus
//! of a local fuzzing run (`fuzz/corpus/<target>/`, when present) and the regression files
//! (`tests/regressions/<target>/`: inputs that once crashed a fuzz target) through the same entry
//! points as the fuzz targets (`tests/integration/fuzz_entry/mod.rs`), so that `cargo test`
//! catches a regression without cargo-fuzz.

use crate::fuzz_entry;

use std::fs;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

const TARGETS: [&str; 9] = [
    "parse_json",
    "parse_off",
    "parse_obj",
    "parse_svg",
    "parse_pdf",
    "parse_pdf_shading",
    "pipeline",
    "render",
    "vectorise",
];

fn inputs(dir: &Path) -> Vec<PathBuf> {
    let Ok(entries) = fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    files
}

/// Runs every file of `dir` through the entry point of `target`; returns the count.
fn replay(target: &str, dir: &Path, failures: &mut Vec<String>) -> usize {
    let files = inputs(dir);
    for path in &files {
        // A running fuzzer may remove corpus files as it reduces them.
        let Ok(data) = fs::read(path) else {
            continue;
        };
        if let Err(e) = catch_unwind(AssertUnwindSafe(|| fuzz_entry::run_target(target, &data))) {
            let message = e
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            failures.push(format!("{}: {message}", path.display()));
        }
    }
    files.len()
}

#[test]
fn fuzz_corpus_and_regressions_replay_cleanly() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut failures = Vec::new();
    let mut regressions = 0;
    for target in TARGETS {
        for corpus in ["../../fuzz/seeds", "../../fuzz/corpus"] {
            replay(target, &crate_dir.join(corpus).join(target), &mut failures);
        }
        regressions += replay(
            target,
            &crate_dir.join("tests/regressions").join(target),
            &mut failures,
        );
    }
    assert!(
        failures.is_empty(),
        "{} inputs failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert!(regressions > 0, "no regression file was found");
}

#[test]
fn sample_descriptions_run() {
    use crate::fuzz_entry::{MeshDescription, Scale, Shape};
    let base = MeshDescription {
        shape: Shape::Grid {
            w: 2,
            h: 1,
            cells: vec![0, 1, 2],
        },
        scale: Scale::One,
        offset: (0, 0),
        jitter: vec![(1, 3, -2)],
        collapse: vec![],
        colour_space: 0,
        colours: vec![[10, 20, 30], [-100, 5, 7], [0, 0, 0], [127, -128, 3]],
        opacity: vec![255, 128],
        corners: vec![2],
        handles: vec![(0, 0, 12, 5), (4, 1, 2, -9)],
        edges: vec![(1, 1, 6), (3, 2, 0)],
        wedges: vec![(0, 0, [1, 2, 3], Some(100))],
        boundary_edge_only: false,
        chaikin: true,
        interpolate_positions: true,
        reverse_faces: false,
        depth: 3,
    };
    fuzz_entry::pipeline(&base);
    for scale in [Scale::Tiny, Scale::Huge, Scale::Any(-3.5)] {
        fuzz_entry::pipeline(&MeshDescription {
            scale,
            ..base.clone()
        });
    }
    for shape in [
        Shape::Polygon {
            n: 5,
            fan: true,
            closed_fan: true,
        },
        Shape::Polygon {
            n: 9,
            fan: false,
            closed_fan: false,
        },
        Shape::Raw {
            points: 5,
            faces: vec![vec![0, 1, 2], vec![2, 1, 3], vec![0, 0, 1]],
        },
    ] {
        fuzz_entry::pipeline(&MeshDescription {
            shape,
            ..base.clone()
        });
    }
}
