//! `docs/errors.md` lists every error with an example input and the message it gives. The
//! table is generated here by running each example, and must equal the one in the document, so
//! that the document cannot drift from the code: `GRADMESH_BLESS=1 cargo test -p gradmesh --test
//! integration errors_doc` rewrites it. Every variant of `ErrorKind` (read from `src/error.rs`)
//! must appear.

use std::fs;
use std::path::Path;

use gradmesh::formats::{self, Format};
use gradmesh::render::{render_document, RenderOptions, View};
use gradmesh::Refinement;
use gradmesh::{ColourSpace, Document, EdgeKind, Error, GradientMesh, Limits};
use kurbo::{Point, Vec2};

const BEGIN: &str = "<!-- BEGIN GENERATED TABLE: tests/integration/errors_doc.rs -->";
const END: &str = "<!-- END GENERATED TABLE -->";

/// A JSON document with one layer made of `points` (objects), `faces` and extra fields.
fn json(points: &str, faces: &str, extra: &str) -> String {
    format!(
        r#"{{"format": "gradmesh", "version": 1, "layers": [{{"points": [{points}], "faces": [{faces}]{extra}}}]}}"#
    )
}

const TRI: &str = r#"{"position": [0, 0], "colour": [50, 0, 0]}, {"position": [1, 0], "colour": [50, 0, 0]}, {"position": [0, 1], "colour": [50, 0, 0]}"#;
const OFF_TRI: &str = "OFF\n3 1 0\n0 0 0 50 0 0 0\n1 0 0 60 0 0 0\n0 1 0 70 0 0 0\n3 0 1 2\n";
const OBJ_TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

fn triangle() -> GradientMesh {
    let mut m = GradientMesh::new(ColourSpace::Lab);
    m.add_point(Point::new(0.0, 0.0), [50.0, 0.0, 0.0]);
    m.add_point(Point::new(1.0, 0.0), [50.0, 0.0, 0.0]);
    m.add_point(Point::new(0.0, 1.0), [50.0, 0.0, 0.0]);
    m.add_face([0, 1, 2]);
    m
}

/// How an example is run.
enum Run {
    /// Read text in a format, then validate each layer.
    Text(Format, String),
    /// Validate a mesh built in code (errors the readers catch earlier).
    Mesh(GradientMesh),
    /// Something else.
    Other(Box<dyn Fn() -> Result<(), Error>>),
}

struct Case {
    /// The ErrorKind variant.
    kind: &'static str,
    /// Who reports it.
    by: &'static str,
    /// The example, in words when not text.
    input: String,
    run: Run,
}

fn text(kind: &'static str, by: &'static str, format: Format, input: &str) -> Case {
    Case {
        kind,
        by,
        input: String::new(),
        run: Run::Text(format, input.to_string()),
    }
}

fn mesh(kind: &'static str, input: &str, build: impl Fn(&mut GradientMesh)) -> Case {
    let mut m = triangle();
    build(&mut m);
    Case {
        kind,
        by: "validate",
        input: input.to_string(),
        run: Run::Mesh(m),
    }
}

fn other(
    kind: &'static str,
    by: &'static str,
    input: &str,
    f: impl Fn() -> Result<(), Error> + 'static,
) -> Case {
    Case {
        kind,
        by,
        input: input.to_string(),
        run: Run::Other(Box::new(f)),
    }
}

fn cases() -> Vec<Case> {
    use Format::{Json, Obj, Off};
    let mut c = vec![
        // ---- JSON reader
        text("Syntax", "JSON reader", Json, ""),
        text("Syntax", "JSON reader", Json, "[1, 2]"),
        text("Syntax", "JSON reader", Json, r#"{"layers": []}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "svg", "version": 1}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh-refined", "version": 1}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh"}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 2}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 1}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 1, "layers": [], "x": 0}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 1, "layers": [], "layers": []}"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 1, "layers": []} x"#),
        text("Syntax", "JSON reader", Json, r#"{"format": "gradmesh", "version": 1, "layers": [}"#),
        text("Syntax", "JSON reader", Json, &json(r#"{"position": [NaN, 0], "colour": [0, 0, 0]}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(r#"{"position": [1e400, 0], "colour": [0, 0, 0]}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(r#"{"position": [0], "colour": [0, 0, 0]}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(r#"{"position": [0, "a"], "colour": [0, 0, 0]}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(r#"{"colour": [0, 0, 0]}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": true}"#, "", "")),
        text("Syntax", "JSON reader", Json, &json(TRI, "[0, 1, -2]", "")),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "colour_space": "cmyk""#)),
        text("Invalid", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": "orang"}"#, "", "")),
        text("Invalid", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": "oklch(70% 1e30 200)"}"#, "", "")),
        text("Invalid", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": [0, 0, 0], "opacity": 2}"#, "", "")),
        text("Invalid", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": [0, 0, 0], "handles": [[3, 0, 0]]}"#, "", "")),
        text("Invalid", "JSON reader", Json, &json(r#"{"position": [0, 0], "colour": [0, 0, 0], "handles": [[0, 0, 0]]}"#, "", "")),
        text("Invalid", "JSON reader", Json, &json(TRI.replacen("[0, 0], \"colour\": [50, 0, 0]", "[0, 0], \"colour\": [50, 0, 0], \"handles\": [[1, 0, 0], [1, 0, 0]]", 1).as_str(), "[0, 1, 2]", "")),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1]", "")),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 1]", "")),
        text("IndexOutOfRange", "JSON reader", Json, &json(TRI, "[0, 1, 3]", "")),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [0, 5], "kind": "crease"}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [1, 1], "kind": "crease"}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [0, 1], "kind": "sharp"}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [0, 1], "kind": "discontinuous", "sharpness": 1}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [0, 1], "kind": "crease", "sharpness": -1}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "edges": [{"points": [0, 1], "kind": "crease"}, {"points": [1, 0], "kind": "crease"}]"#)),
        text("Invalid", "JSON reader", Json, &json(TRI, "[0, 1, 2]", r#", "wedges": [{"point": 0, "face": 4, "colour": [0, 0, 0]}]"#)),
        text("Invalid", "JSON reader", Json, &json(&format!("{TRI}, {}", r#"{"position": [5, 5], "colour": [0, 0, 0]}"#), "[0, 1, 2]", r#", "wedges": [{"point": 3, "face": 0, "colour": [0, 0, 0]}]"#)),
        text("LimitExceeded", "JSON reader", Json, &format!("{}{}", "[".repeat(65), "]".repeat(65))),
        // ---- OFF reader
        text("Syntax", "OFF reader", Off, ""),
        text("Syntax", "OFF reader", Off, "COFF\n"),
        text("Syntax", "OFF reader", Off, "OFF\n3 1\n"),
        text("Syntax", "OFF reader", Off, "OFF\n3 -1 0\n"),
        text("Syntax", "OFF reader", Off, "OFF\n3 1 2\n"),
        text("LimitExceeded", "OFF reader", Off, "OFF\n1 100000000 0\n"),
        text("LimitExceeded", "OFF reader", Off, "OFF\n100000000 1 0\n"),
        text("LimitExceeded", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2", "99999999999 0 1 2")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60", "1 zero 0 60")),
        text("NotFinite", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60", "nan 0 0 60")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60 0 0 1 2 0.1")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60 0 0 99 2")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60 0 0 1 7 0.1 0")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60 0 0 1 1 0.1 0")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("1 0 0 60 0 0 0", "1 0 0 60 0 0 2 0 0 0.1 0 0.1 0")),
        text("NoSuchEdge", "OFF reader", Off, "OFF\n4 1 0\n0 0 0 50 0 0 1 2 0.1 0.1\n1 0 0 50 0 0 0\n1 1 0 50 0 0 0\n0 1 0 50 0 0 0\n4 0 1 2 3\n"),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2", "2 0 1")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2", "4 0 1 2")),
        text("IndexOutOfRange", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2", "3 0 1 3")),
        text("DegenerateFace", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2", "3 0 1 1")),
        text("Syntax", "OFF reader", Off, &OFF_TRI.replace("3 0 1 2\n", "")),
        text("Syntax", "OFF reader", Off, &format!("{OFF_TRI}3 0 2 1\n")),
        // ---- OBJ reader
        text("Syntax", "OBJ reader", Obj, "v 0 0 0\nv 1 0\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 x\n"),
        text("NotFinite", "OBJ reader", Obj, "v 0 0 inf\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 0 1 0 0\nv 1 0 0\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 0\nv 1 0 0\nf 1 2\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 0\nf 1 a 1\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 0\nf 0 1 2\n"),
        text("Syntax", "OBJ reader", Obj, "v 0 0 0\nf -1 -2 -3\n"),
        text("Syntax", "OBJ reader", Obj, "f 1 2 99999999999\n"),
        text("Syntax", "OBJ reader", Obj, "f 1 2 1\n"),
        text("Syntax", "OBJ reader", Obj, &OBJ_TRI.replace("f 1 2 3", "f 1 2 4")),
        text("Syntax", "OBJ reader", Obj, "curv 0 1 1 2\n"),
        text("Syntax", "OBJ reader", Obj, "f 1 2 \\\n 3\n"),
        text("Syntax", "OBJ reader", Obj, "t crease\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/x/0 0 1 1\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/1/0 0 1\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/1/0 0 -1 1\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/1/0 0 1 x\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 3/1/0 0 1 2 1\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/2/0 0 1 1 2 3\n"),
        text("Syntax", "OBJ reader", Obj, "t crease 2/1/0 0 1 -1\n"),
        text("Syntax", "OBJ reader", Obj, &format!("{OBJ_TRI}t crease 2/1/0 1 1 1\n")),
        text("Syntax", "OBJ reader", Obj, &format!("{OBJ_TRI}t crease 2/1/0 1 5 1\n")),
        text("Syntax", "OBJ reader", Obj, "t corner 0/1/0 1\n"),
        text("Syntax", "OBJ reader", Obj, "t interpolateboundary 1/0/0 0\n"),
        text("Syntax", "OBJ reader", Obj, "t creasemethod 0/0/1 smooth\n"),
        text("Syntax", "OBJ reader", Obj, "t hole 1/0/0 0\n"),
        // ---- validate
        mesh("NotFinite", "point 1 at x = NaN", |m| m.points[1].position.x = f64::NAN),
        mesh("Invalid", "point 1 with opacity 2", |m| m.points[1].opacity = 2.0),
        mesh("Invalid", "point 1 at x = 1e200", |m| m.points[1].position.x = 1e200),
        mesh("Invalid", "point 1 at x = 1e13 with interpolated positions", |m| {
            m.points[1].position.x = 1e13;
            m.interpolate_positions = true;
        }),
        mesh("Invalid", "point 1 at x = 1e-200, point 0 at the origin", |m| {
            m.points[1].position.x = 1e-200
        }),
        mesh("Invalid", "a handle 1e60 times its edge", |m| {
            m.set_handle(0, 1, Vec2::new(1e60, 0.0))
        }),
        mesh("Invalid", "crease sharpness -1 (set in code)", |m| {
            m.set_edge(0, 1, EdgeKind::Crease, Some(-1.0))
        }),
        mesh("ZeroLengthEdge", "point 1 moved onto point 0", |m| {
            m.points[1].position = Point::ZERO
        }),
        mesh("DegenerateFace", "a face [0, 1] (built in code)", |m| m.faces[0] = vec![0, 1]),
        mesh("DegenerateFace", "a face [0, 1, 1] (built in code)", |m| {
            m.faces[0] = vec![0, 1, 1]
        }),
        mesh("IndexOutOfRange", "a face [0, 1, 5] (built in code)", |m| {
            m.faces[0] = vec![0, 1, 5]
        }),
        mesh("NonManifoldEdge", "three triangles on edge 0-1", |m| {
            m.add_point(Point::new(0.0, -1.0), [0.0; 3]);
            m.add_point(Point::new(1.0, 1.0), [0.0; 3]);
            m.add_face([1, 0, 3]);
            m.add_face([0, 1, 4]);
        }),
        mesh("NonManifoldVertex", "two triangles touching at point 0", |m| {
            m.add_point(Point::new(-1.0, 0.0), [0.0; 3]);
            m.add_point(Point::new(0.0, -1.0), [0.0; 3]);
            m.add_face([0, 3, 4]);
        }),
        mesh("InconsistentWinding", "faces [0, 1, 2] and [1, 2, 3]", |m| {
            m.add_point(Point::new(1.0, 1.0), [0.0; 3]);
            m.add_face([1, 2, 3]);
        }),
        mesh("NoSuchEdge", "a handle of point 0 towards 2 on a quad's diagonal", |m| {
            m.add_point(Point::new(1.0, 1.0), [0.0; 3]);
            m.faces[0] = vec![0, 1, 3, 2];
            m.set_handle(0, 3, Vec2::new(0.1, 0.1));
        }),
        mesh("NoSuchEdge", "an edge tag on a quad's diagonal", |m| {
            m.add_point(Point::new(1.0, 1.0), [0.0; 3]);
            m.faces[0] = vec![0, 1, 3, 2];
            m.set_edge(0, 3, EdgeKind::Crease, None);
        }),
    ];
    // ---- files, refinement, rendering, writing
    c.push(other(
        "UnsupportedFormat",
        "read_path",
        "`picture.png`",
        || formats::read_path(Path::new("picture.png")).map(drop),
    ));
    c.push(other(
        "Io",
        "read_path",
        "`missing.json`, which does not exist",
        || formats::read_path(Path::new("missing.json")).map(drop),
    ));
    c.push(other("Io", "read_path", "`dir.json`, a directory", || {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("dir.json");
        fs::create_dir(&path).unwrap();
        formats::read_path(&path)
            .map(drop)
            .map_err(|e| strip(e, dir.path()))
    }));
    c.push(other(
        "Syntax",
        "read_path",
        "`latin1.off` with the byte 0xE9 on line 2",
        || {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("latin1.off");
            fs::write(&path, b"OFF\n3 1 0 \xe9\n").unwrap();
            formats::read_path(&path)
                .map(drop)
                .map_err(|e| strip(e, dir.path()))
        },
    ));
    c.push(other(
        "LimitExceeded",
        "read_path_with_limits",
        "`a.obj` of 100 bytes, `Limits { input_bytes: 64, .. }`",
        || {
            let dir = tempfile::tempdir().unwrap();
            let path = dir.path().join("a.obj");
            fs::write(&path, [b'#'; 100]).unwrap();
            let limits = Limits {
                input_bytes: 64,
                ..Limits::DEFAULT
            };
            formats::read_path_with_limits(&path, &limits)
                .map(drop)
                .map_err(|e| strip(e, dir.path()))
        },
    ));
    c.push(other(
        "LimitExceeded",
        "read_str_with_limits",
        "a triangle in OBJ, `Limits { corners: 2, .. }`",
        || {
            let limits = Limits {
                corners: 2,
                ..Limits::DEFAULT
            };
            formats::read_str_with_limits(OBJ_TRI, Format::Obj, &limits).map(drop)
        },
    ));
    c.push(other(
        "LimitExceeded",
        "read_str_with_limits",
        "a triangle in JSON, `Limits { points: 2, .. }`",
        || {
            let limits = Limits {
                points: 2,
                ..Limits::DEFAULT
            };
            formats::read_str_with_limits(&json(TRI, "[0, 1, 2]", ""), Format::Json, &limits)
                .map(drop)
        },
    ));
    c.push(other(
        "LimitExceeded",
        "Refinement::new_with_limits",
        "a triangle refined to level 13",
        || Refinement::new_with_limits(&triangle(), 13, &Limits::DEFAULT).map(drop),
    ));
    c.push(other(
        "LimitExceeded",
        "Refinement::new_with_limits",
        "a triangle refined to level 12",
        || Refinement::new_with_limits(&triangle(), 12, &Limits::DEFAULT).map(drop),
    ));
    c.push(other(
        "LimitExceeded",
        "Refinement::new_with_limits",
        "a triangle refined to level 20, `Limits::NONE`",
        || Refinement::new_with_limits(&triangle(), 20, &Limits::NONE).map(drop),
    ));
    c.push(other(
        "LimitExceeded",
        "render",
        "a square of side 30000 at 1 pixel per unit",
        || {
            let opts = RenderOptions::new(30_000, 30_000, View::new(0.0, 0.0, 3e4, 3e4));
            let doc = Document::new(vec![triangle()]);
            render_document(&doc, &opts).map(drop)
        },
    ));
    c.push(other(
        "Io",
        "write_atomic",
        "`no/such/dir/out.json`",
        || formats::write_atomic(Path::new("no/such/dir/out.json"), b"{}"),
    ));
    c.push(other(
        "Io",
        "write_atomic",
        "`out.json`, an existing directory",
        || {
            let dir = tempfile::tempdir().unwrap();
            fs::create_dir(dir.path().join("out.json")).unwrap();
            formats::write_atomic(&dir.path().join("out.json"), b"{}")
                .map_err(|e| strip(e, dir.path()))
        },
    ));
    c.push(other("Io", "write_atomic", "`..` (names no file)", || {
        formats::write_atomic(Path::new(".."), b"{}")
    }));
    c
}

/// The error with the temporary directory removed from its message's path.
fn strip(mut e: Error, dir: &Path) -> Error {
    if let Some(f) = &e.location.file {
        if let Ok(rest) = f.strip_prefix(dir) {
            e.location.file = Some(rest.to_path_buf());
        }
    }
    e
}

fn outcome(run: &Run) -> Result<(), Error> {
    match run {
        Run::Text(format, input) => {
            let doc = formats::read_str(input, *format)?;
            for (i, mesh) in doc.layers.iter().enumerate() {
                gradmesh::validate(mesh).map_err(|e| e.in_layer(i))?;
            }
            Ok(())
        }
        Run::Mesh(mesh) => gradmesh::validate(mesh).map(drop),
        Run::Other(f) => f(),
    }
}

/// Inline code that Markdown shows as is, with `\n` for line breaks and `\|` for bars.
fn code(s: &str) -> String {
    let s = s.replace('\n', "\\n").replace('|', "\\|");
    if s.is_empty() {
        "(empty)".into()
    } else if s.contains('`') {
        format!("`` {s} ``")
    } else {
        format!("`{s}`")
    }
}

fn table() -> (String, Vec<String>) {
    let mut out =
        String::from("| Kind | Reported by | Example input | Message |\n|---|---|---|---|\n");
    let mut kinds = Vec::new();
    for case in cases() {
        let input = match &case.run {
            Run::Text(format, text) => format!("{} {}", format.extension(), code(text)),
            _ => case.input.clone(),
        };
        let e = match outcome(&case.run) {
            Ok(()) => panic!("{} example {input} gave no error", case.kind),
            Err(e) => e,
        };
        let name = format!("{:?}", e.kind);
        assert!(
            name.starts_with(case.kind),
            "{input}: expected {}, found {name}",
            case.kind
        );
        kinds.push(case.kind.to_string());
        out.push_str(&format!(
            "| `{}` | {} | {input} | {} |\n",
            case.kind,
            case.by,
            code(&e.to_string())
        ));
    }
    (out, kinds)
}

#[test]
fn the_error_table_is_up_to_date() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/errors.md");
    let doc = fs::read_to_string(&path).unwrap();
    let (start, end) = (
        doc.find(BEGIN).expect("begin marker") + BEGIN.len(),
        doc.find(END).expect("end marker"),
    );
    let (generated, kinds) = table();
    let current = doc[start..end].trim();
    if current != generated.trim() {
        if std::env::var_os("GRADMESH_BLESS").is_some() {
            let new = format!("{}\n{}\n{}", &doc[..start], generated.trim(), &doc[end..]);
            fs::write(&path, new).unwrap();
        } else {
            panic!(
                "docs/errors.md is out of date; run GRADMESH_BLESS=1 cargo test -p gradmesh --test integration errors_doc\n{generated}"
            );
        }
    }
    // Every variant of ErrorKind has an example.
    let source =
        fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/error.rs")).unwrap();
    let body = &source[source.find("pub enum ErrorKind").unwrap()..];
    let body = &body[..body.find("\n}").unwrap()];
    for line in body.lines() {
        let t = line.trim_start();
        if line.starts_with("    ") && !line.starts_with("     ") {
            if let Some(name) = t
                .split(|c: char| !c.is_alphanumeric())
                .next()
                .filter(|n| n.starts_with(|c: char| c.is_ascii_uppercase()))
            {
                assert!(
                    kinds.iter().any(|k| k == name),
                    "ErrorKind::{name} has no example in docs/errors.md"
                );
            }
        }
    }
}
