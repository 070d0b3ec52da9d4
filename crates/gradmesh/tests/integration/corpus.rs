//! Malformed and hostile inputs in `tests/corpus/`, each with its expected outcome in a sidecar
//! `<name>.expected`: `ok`, or text that the message of the first error must contain.
//!
//! Every input goes through what `gradmesh render` does with it: read the file (default
//! limits), validate each layer, refine it to level 3 and to the limit (within the default
//! limits, all numbers finite), and render the document at one pixel per unit. None may panic.
//! Messages are compared with the corpus directory stripped, as `name.json:3: ...`.
//!
//! `GRADMESH_BLESS=1 cargo test --test integration corpus::` writes the current messages into
//! missing sidecars (review them before committing).

use std::fs;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use gradmesh::formats;
use gradmesh::render::{document_bounds, render_document, RenderOptions, View};
use gradmesh::Refinement;
use gradmesh::{Error, ErrorKind, Limits};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/corpus")
}

/// Everything `gradmesh render` does with a file, up to the first error.
fn run(path: &Path) -> Result<(), Error> {
    let doc = formats::read_path(path)?;
    for (i, mesh) in doc.layers.iter().enumerate() {
        let locate = |e: Error| e.in_layer(i).in_file(path);
        gradmesh::validate(mesh).map_err(locate)?;
        let (mut r, _) = Refinement::new_with_limits(mesh, 3, &Limits::DEFAULT).map_err(locate)?;
        let data = r.evaluate();
        let limit = r.limit(&data, 3);
        for (v, d) in limit.iter().enumerate() {
            assert!(
                d.to_array().iter().all(|x| x.is_finite()),
                "layer {i} vertex {v}: {d:?}"
            );
        }
    }
    if let Some(rect) = document_bounds(&doc) {
        // One pixel per unit, with half a unit around so that a flat mesh has an area.
        let rect = rect.inflate(0.5, 0.5);
        let side = |x: f64| x.ceil().clamp(1.0, u32::MAX as f64) as u32;
        let opts = RenderOptions::new(
            side(rect.width()),
            side(rect.height()),
            View::from_rect(rect),
        );
        let image = render_document(&doc, &opts).map_err(|e| e.in_file(path))?;
        assert!(image.data.iter().all(|x| x.is_finite()));
    }
    Ok(())
}

#[test]
fn every_corpus_input_gives_its_expected_outcome() {
    let dir = corpus_dir();
    let bless = std::env::var_os("GRADMESH_BLESS").is_some();
    let mut inputs: Vec<PathBuf> = fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_none_or(|e| e != "expected"))
        .collect();
    inputs.sort();
    assert!(inputs.len() >= 40, "only {} corpus inputs", inputs.len());
    let mut failures = Vec::new();
    for path in &inputs {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let sidecar = path.with_file_name(format!("{name}.expected"));
        let start = Instant::now();
        let outcome = match catch_unwind(AssertUnwindSafe(|| run(path))) {
            Ok(Ok(())) => "ok".to_string(),
            Ok(Err(e)) => e.to_string().replace(&format!("{}/", dir.display()), ""),
            Err(_) => {
                failures.push(format!("{name}: panicked"));
                continue;
            }
        };
        if start.elapsed() > Duration::from_secs(20) {
            failures.push(format!("{name}: took {:?}", start.elapsed()));
        }
        let expected = match fs::read_to_string(&sidecar) {
            Ok(text) => text.lines().next().unwrap_or("").to_string(),
            Err(_) if bless => {
                fs::write(&sidecar, format!("{outcome}\n")).unwrap();
                outcome.clone()
            }
            Err(_) => {
                failures.push(format!("{name}: no {name}.expected (outcome: {outcome})"));
                continue;
            }
        };
        let pass = if expected == "ok" {
            outcome == "ok"
        } else {
            outcome != "ok" && outcome.contains(&expected)
        };
        if !pass {
            failures.push(format!(
                "{name}:\n  expected: {expected}\n     found: {outcome}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The header of the OFF file declares 100 million faces: refused on the header line, before
/// anything is allocated for them.
#[test]
fn a_hundred_million_faces_are_refused_without_allocating() {
    let start = Instant::now();
    let e = formats::read_str("OFF\n1 100000000 0\n", formats::Format::Off).unwrap_err();
    assert!(start.elapsed() < Duration::from_millis(100));
    assert_eq!(e.location.line, Some(2));
    assert!(
        matches!(
            e.kind,
            ErrorKind::LimitExceeded {
                found: 100_000_000,
                limit: 16_777_216,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(
        e.to_string(),
        "2: the number of faces is 100,000,000, above the limit of 16,777,216"
    );
}
