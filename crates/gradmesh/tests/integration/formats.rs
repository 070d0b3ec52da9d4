//! The file formats on real and hand-written files: the paper authors' OFF artwork loads and
//! validates, the native JSON round-trips exactly, and every kind of error names its line.

use std::fs;
use std::path::{Path, PathBuf};

use gradmesh::formats::{self, json, obj, off, Format};
use gradmesh::{validate, ColourSpace, Document, EdgeKind, ErrorKind};

use crate::realdata;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn files_with_extension(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .collect();
    files.sort();
    files
}

/// Reading, writing, reading again gives the same document; writing that gives the same bytes.
fn assert_round_trip(doc: &Document, what: &str) {
    let once = json::write_document(doc);
    let back = json::read_document(&once).unwrap_or_else(|e| panic!("{what}: {e}\n{once}"));
    assert_eq!(&back, doc, "{what}: the document changed in a round trip");
    assert_eq!(
        json::write_document(&back),
        once,
        "{what}: writing twice gave different bytes"
    );
}

#[test]
fn every_real_off_file_loads_and_validates() {
    let files = files_with_extension(&realdata::dir(), "off");
    assert!(
        files.len() >= 11,
        "expected the 11 artwork files, found {files:?}"
    );
    for path in files {
        let doc = formats::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(doc.layers.len(), 1);
        let mesh = &doc.layers[0];
        let stem = path.file_stem().unwrap().to_str().unwrap();
        assert_eq!(mesh.name.as_deref(), Some(stem));
        assert_eq!(mesh.colour_space, ColourSpace::Lab);

        // The counts of the header and the handles of the vertex lines are all there.
        let text = fs::read_to_string(&path).unwrap();
        let counts: Vec<usize> = text
            .lines()
            .nth(1)
            .unwrap()
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        assert_eq!(mesh.points.len(), counts[0], "{stem}");
        assert_eq!(mesh.faces.len(), counts[1], "{stem}");
        let declared_handles: usize = text
            .lines()
            .skip(2)
            .filter(|l| !l.trim().is_empty())
            .take(counts[0])
            .map(|l| {
                l.split_whitespace()
                    .nth(6)
                    .unwrap()
                    .parse::<usize>()
                    .unwrap()
            })
            .sum();
        assert_eq!(mesh.handles.len(), declared_handles, "{stem}");

        validate(mesh).unwrap_or_else(|e| panic!("{stem}: {e}"));
        assert_round_trip(&doc, stem);
    }
}

#[test]
fn the_authors_refined_outputs_load_as_meshes_too() {
    // Their output lines `x y z L a b 0 0` are vertex lines without neighbours.
    for path in files_with_extension(&realdata::path("reference-output"), "off") {
        let doc = formats::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
        let mesh = &doc.layers[0];
        assert!(mesh.handles.is_empty());
        validate(mesh).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    }
}

#[test]
fn json_keeps_css_text_and_round_trips() {
    let path = data("discontinuity.json");
    let doc = formats::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(doc.layers.len(), 2);
    let [background, two] = &doc.layers[..] else {
        unreachable!()
    };
    assert_eq!(background.colour_space, ColourSpace::Oklab);
    assert_eq!(background.points[0].colour_text.as_deref(), Some("#1d3557"));
    assert_eq!(background.points[3].opacity, 0.8);
    assert_eq!(two.points[1].colour_text.as_deref(), Some("lab(60% 40 30)"));
    assert!(two.points[4].corner);
    assert_eq!(two.points[3].opacity, 0.5);
    assert_eq!(two.edge_tag(1, 0).kind, EdgeKind::Crease);
    assert_eq!(two.edge_tag(1, 0).sharpness, Some(1.5));
    assert_eq!(two.edge_tag(4, 1).kind, EdgeKind::Discontinuous);
    assert_eq!(two.wedges.len(), 2);
    assert_eq!(two.wedges[0].colour_text.as_deref(), Some("#e63946"));
    assert_eq!(two.wedges[1].opacity, Some(0.75));
    for mesh in &doc.layers {
        validate(mesh).unwrap_or_else(|e| panic!("{e}"));
    }
    assert_round_trip(&doc, "discontinuity.json");

    // The file is already canonical: it is written back byte for byte.
    let text = fs::read_to_string(&path).unwrap();
    assert_eq!(json::write_document(&doc), text);
}

#[test]
fn css_lab_is_d50_and_converted() {
    // CSS lab() is relative to D50; the working Lab space is D65. `lab(60% 40 30)` through XYZ
    // D50, Bradford adaptation to D65 (CSS Color 4's matrix) and back to Lab D65, computed
    // independently, is (59.472, 38.563, 29.074).
    let doc = formats::read_path(&data("discontinuity.json")).unwrap();
    let c = doc.layers[1].points[1].colour;
    for (got, want) in c.iter().zip([59.472, 38.563, 29.074]) {
        // The CSS parser works in single precision.
        assert!((got - want).abs() < 0.01, "{c:?}");
    }
}

#[test]
fn obj_import_with_tags() {
    let doc = formats::read_path(&data("creases.obj")).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &doc.layers[0];
    assert_eq!(mesh.name.as_deref(), Some("creases"));
    assert_eq!(mesh.colour_space, ColourSpace::Srgb);
    assert_eq!(mesh.points.len(), 12);
    assert_eq!(mesh.faces.len(), 6);
    assert_eq!(mesh.faces[4], vec![5, 9, 10, 6]);
    assert_eq!(mesh.edge_tag(1, 5).sharpness, Some(10.0));
    assert_eq!(mesh.edge_tag(5, 6).sharpness, Some(2.0));
    assert_eq!(mesh.edge_tag(7, 6).sharpness, Some(0.5));
    assert!(mesh.points[11].corner);
    validate(mesh).unwrap_or_else(|e| panic!("{e}"));
    assert_round_trip(&doc, "creases.obj");
}

#[test]
fn small_off_file_in_srgb() {
    let doc = formats::read_path(&data("triangle.off")).unwrap_or_else(|e| panic!("{e}"));
    let mesh = &doc.layers[0];
    assert_eq!(mesh.colour_space, ColourSpace::Srgb);
    assert_eq!(mesh.handles.len(), 9);
    validate(mesh).unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn examples_load_validate_and_round_trip() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    if !dir.is_dir() {
        return;
    }
    for path in files_with_extension(&dir, "json") {
        let doc = formats::read_path(&path).unwrap_or_else(|e| panic!("{e}"));
        for mesh in &doc.layers {
            validate(mesh).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
        assert_round_trip(&doc, &path.display().to_string());
        // The examples are written canonically: reading and writing changes no byte.
        let text = fs::read_to_string(&path).unwrap();
        assert!(
            json::write_document(&doc) == text,
            "{}: writing the document back changes it",
            path.display()
        );
    }
}

/// Writes `text` to a temporary file named `name` and reads it, expecting an error.
fn error_of(name: &str, text: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    fs::write(&path, text).unwrap();
    let e = formats::read_path(&path).unwrap_err();
    assert_eq!(e.location.file.as_deref(), Some(path.as_path()));
    // Strip the directory so that messages can be compared.
    e.to_string()
        .replace(&format!("{}/", dir.path().display()), "")
}

#[test]
fn json_errors_name_the_line() {
    let good = fs::read_to_string(data("discontinuity.json")).unwrap();
    let cases = [
        // A syntax error: a missing comma.
        (
            good.replacen("\"#1d3557\"},", "\"#1d3557\"}", 1),
            "m.json:10: layer 0: point 0: expected `,` or `]`",
        ),
        // A wrong type.
        (
            good.replacen("\"opacity\": 0.5", "\"opacity\": \"half\"", 1),
            "m.json:24: layer 1: point 3: opacity: expected a number, found string \"half\"",
        ),
        // A wrong length.
        (
            good.replacen("[100.0, 60.0]", "[100.0]", 1),
            "m.json:26: layer 1: point 5: position: expected an array of 2 numbers, found 1 element",
        ),
        // An unknown field.
        (
            good.replacen("\"corner\": true", "\"corners\": true", 1),
            "m.json:25: layer 1: point 4: unknown field `corners`, expected one of `position`, `colour`, `opacity`, `corner`, `handles`",
        ),
        // An index out of range.
        (
            good.replacen("[1, 2, 5, 4]", "[1, 2, 5, 6]", 1),
            "m.json:30: layer 1: face 1: corner 3 refers to point 6, but there are only 6 points",
        ),
        // A colour string that is not CSS.
        (
            good.replacen("\"orange\"", "\"orang\"", 1),
            "m.json:25: layer 1: point 4: colour: expected 3 numbers or a CSS colour string, found \"orang\"",
        ),
        // An unknown name.
        (
            good.replacen("\"oklab\"", "\"cmyk\"", 1),
            "m.json:7: layer 0: colour_space: expected one of \"lab\", \"oklab\", \"srgb-linear\", \"srgb\", found \"cmyk\"",
        ),
        // A wedge whose face does not contain its point.
        (
            good.replacen("{\"point\": 4, \"face\": 1", "{\"point\": 0, \"face\": 1", 1),
            "m.json:38: layer 1: wedge 1: face: face 1 [1, 2, 5, 4] does not contain point 0",
        ),
        // A newer version.
        (
            good.replacen("\"version\": 1", "\"version\": 2", 1),
            "m.json:3: version: unsupported version 2: this program reads version 1",
        ),
        // A truncated file.
        (
            good[..good.len() / 2].to_string(),
            "m.json:23: unexpected end of the text while reading a value",
        ),
    ];
    for (text, expected) in cases {
        let message = error_of("m.json", &text);
        assert!(
            message.starts_with(expected),
            "expected: {expected}\n   found: {message}"
        );
    }
}

#[test]
fn off_errors_name_the_line() {
    let good = fs::read_to_string(data("triangle.off")).unwrap();
    let cases = [
        (good.replacen("OFF", "OFF3", 1), "t.off:1: expected \"OFF\", found \"OFF3\""),
        (
            good.replacen("4 3 1", "4 3", 1),
            "t.off:2: expected 3 numbers \"nV nF colour_mode\", found 2 values \"4 3\"",
        ),
        (
            good.replacen("30 0 1", "30 O 1", 1),
            "t.off:4: vertex 1: y: expected a number, found \"O\"",
        ),
        (
            good.replacen("15 26 1", "15 26 inf", 1),
            "t.off:5: vertex 2: z is not a finite number (inf)",
        ),
        (
            good.replacen("2 0 3 -5", "2 0 4 -5", 1),
            "t.off:5: vertex 2: neighbour 2 is 4, but there are only 4 vertices",
        ),
        (
            good.replacen("3 2 0 3", "3 2 0 9", 1),
            "t.off:10: face 2: corner 2 refers to point 9, but there are only 4 points",
        ),
        (
            good.replacen("3 2 0 3", "", 1),
            "t.off:10: unexpected end of file: expected the line of face 2 (the header declares 3 faces)",
        ),
        (
            good.replacen("4 3 1", "100000000 3 1", 1),
            "t.off:2: the number of vertices is 100,000,000, above the limit of 16,777,216",
        ),
    ];
    for (text, expected) in cases {
        let message = error_of("t.off", &text);
        assert!(
            message.starts_with(expected),
            "expected: {expected}\n   found: {message}"
        );
    }
}

#[test]
fn obj_errors_name_the_line() {
    let good = fs::read_to_string(data("creases.obj")).unwrap();
    let cases = [
        (
            good.replacen("v 1 1 0 0 1 0.5", "v 1 1 0 0 1", 1),
            "c.obj:8: vertex 6: expected \"x y z\" or \"x y z r g b\", found 5 numbers",
        ),
        (
            good.replacen("f 3 7 8 4", "f 3 7 8 40", 1),
            "c.obj:21: face 3: corner 4 refers to vertex 40, but there are only 12 vertices",
        ),
        (
            good.replacen("t corner 1/1/0 11 10", "t corner 1/1/0 12 10", 1),
            "c.obj:27: tag corner: vertex 12 (0-based) does not exist (there are 12 vertices)",
        ),
        (
            good.replacen("s off", "bevel off", 1),
            "c.obj:18: unknown statement \"bevel\" (expected v, f or t)",
        ),
    ];
    for (text, expected) in cases {
        let message = error_of("c.obj", &text);
        assert!(
            message.starts_with(expected),
            "expected: {expected}\n   found: {message}"
        );
    }
}

#[test]
fn huge_declared_off_counts_are_refused_without_allocating() {
    let text = "OFF\n100000000 0 0\n";
    let e = off::read_off(text).unwrap_err();
    assert!(
        matches!(
            e.kind,
            ErrorKind::LimitExceeded {
                found: 100_000_000,
                ..
            }
        ),
        "{e}"
    );
    assert_eq!(e.location.line, Some(2));
    // Within the limit, a lie about the count is a truncated file, found without reserving
    // the declared amount.
    let e = off::read_off("OFF\n16777216 16777216 0\n").unwrap_err();
    assert!(
        e.to_string().contains("expected the line of vertex 0"),
        "{e}"
    );
}

#[test]
fn read_str_dispatches_by_format() {
    let text = fs::read_to_string(data("triangle.off")).unwrap();
    let doc = formats::read_str(&text, Format::Off).unwrap();
    assert_eq!(doc.layers[0].name, None);
    assert!(formats::read_str(&text, Format::Json).is_err());
    let text = fs::read_to_string(data("creases.obj")).unwrap();
    assert_eq!(
        formats::read_str(&text, Format::Obj).unwrap().layers[0]
            .points
            .len(),
        12
    );
}

#[test]
fn written_files_read_back() {
    let doc = formats::read_path(&data("discontinuity.json")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("copy.json");
    formats::write_atomic(&path, json::write_document(&doc).as_bytes()).unwrap();
    assert_eq!(formats::read_path(&path).unwrap(), doc);
}

#[test]
fn refined_outputs_are_written() {
    use gradmesh::Refinement;
    let doc = formats::read_path(&data("triangle.off")).unwrap();
    let mesh = &doc.layers[0];
    let (refinement, _) = Refinement::new(mesh, 2).unwrap();
    let levels = refinement.evaluate();
    let topology = refinement.topology(2);
    let points = &levels.levels[2];
    let text = obj::write_refined_obj(&[(mesh.name.as_deref(), topology, points)]);
    assert_eq!(
        text.lines().filter(|l| l.starts_with("v ")).count(),
        points.len()
    );
    assert_eq!(
        text.lines().filter(|l| l.starts_with("f ")).count(),
        topology.face_count()
    );
    let text = json::write_refined(&[json::RefinedLayer {
        name: mesh.name.as_deref(),
        colour_space: mesh.colour_space,
        topology,
        data: points,
    }]);
    assert!(text.contains("\"format\": \"gradmesh-refined\""));
    // The refined mesh is not mistaken for an editable one.
    assert!(json::read_document(&text).is_err());
}

#[test]
fn the_example_of_the_specification_reads_and_validates() {
    let spec =
        fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/format.md")).unwrap();
    let section = &spec[spec.find("### 1.9 Example").expect("section 1.9")..];
    let start = section.find("```json\n").unwrap() + "```json\n".len();
    let text = &section[start..start + section[start..].find("```").unwrap()];
    let doc = json::read_document(text).unwrap_or_else(|e| panic!("{e}"));
    for mesh in &doc.layers {
        validate(mesh).unwrap_or_else(|e| panic!("{e}"));
    }
    // The example is written canonically.
    assert_eq!(json::write_document(&doc), text);
}

#[test]
fn css_forms_listed_in_the_specification_parse() {
    for css in [
        "#ff8800",
        "#f80",
        "#ff880080",
        "rgb(255 136 0)",
        "hsl(120deg 50% 50%)",
        "hwb(120 10% 20%)",
        "lab(60% 40 30)",
        "lch(60% 50 40)",
        "oklab(0.7 0.1 0.1)",
        "oklch(70% 0.1 200)",
        "rebeccapurple",
    ] {
        gradmesh::parse_css_colour(css, ColourSpace::Lab).unwrap_or_else(|e| panic!("{css}: {e}"));
    }
}
