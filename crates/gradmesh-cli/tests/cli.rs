//! The `gradmesh` binary, run for real in temporary directories.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn realdata() -> PathBuf {
    PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/realdata/gradientmeshimproved-off"
    ))
}

fn real_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(realdata())
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "off"))
        .collect();
    files.sort();
    assert!(files.len() >= 11, "{files:?}");
    files
}

fn gradmesh(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .args(args)
        .output()
        .expect("the binary runs")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn info_works_on_every_real_file() {
    let files = real_files();
    let args: Vec<&str> = std::iter::once("info")
        .chain(files.iter().map(|p| s(p)))
        .collect();
    let out = gradmesh(&args);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.matches("colour space lab").count(), files.len());
    assert!(
        text.contains("points 129, faces 102"),
        "Glasses.off: {text}"
    );
    assert!(text.contains("face sizes {"));
    assert!(text.contains("valences {"));
    assert!(text.contains("bounds x "));
}

/// Counts `v` and `f` lines of an OBJ file.
fn obj_counts(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let v = text.lines().filter(|l| l.starts_with("v ")).count();
    let f = text.lines().filter(|l| l.starts_with("f ")).count();
    (v, f)
}

#[test]
fn refine_works_on_every_real_file() {
    let dir = tempfile::tempdir().unwrap();
    for file in real_files() {
        let mut last = (0, 0);
        for level in 0..=3 {
            let out = dir.path().join(format!("level{level}.obj"));
            let o = gradmesh(&[
                "refine",
                s(&file),
                "-o",
                s(&out),
                "--levels",
                &level.to_string(),
            ]);
            assert!(o.status.success(), "{}: {}", file.display(), stderr(&o));
            let counts = obj_counts(&out);
            assert!(
                counts.0 > last.0 && counts.1 > last.1,
                "{}: {counts:?}",
                file.display()
            );
            if level >= 2 {
                // Each Catmull-Clark step turns every face into quads, one per corner.
                let text = std::fs::read_to_string(&out).unwrap();
                assert!(text
                    .lines()
                    .filter(|l| l.starts_with("f "))
                    .all(|l| l.split_whitespace().count() == 5));
            }
            last = counts;
        }
        let json = dir.path().join("limit.json");
        let o = gradmesh(&[
            "refine",
            s(&file),
            "-o",
            s(&json),
            "--levels",
            "2",
            "--limit",
        ]);
        assert!(o.status.success(), "{}: {}", file.display(), stderr(&o));
        let text = std::fs::read_to_string(&json).unwrap();
        assert!(text.starts_with('{'));
    }
}

#[test]
fn refine_obj_vertices_carry_position_and_colour() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t.obj");
    let file = realdata().join("Tucan_Tucan_Layer0.off");
    let o = gradmesh(&["refine", s(&file), "-o", s(&out), "--levels", "1"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    let v: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    // The reference output of the authors' tool has 88 points after the ternary step.
    assert_eq!(v.len(), 88);
    for line in v {
        let fields: Vec<f64> = line[2..]
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(fields.len(), 6, "{line}");
        assert_eq!(fields[2], 0.0);
        assert!((0.0..=100.0).contains(&fields[3]), "L in 0..100: {line}");
    }
}

#[test]
fn a_failed_run_leaves_the_existing_output_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.obj");
    std::fs::write(&out, "precious").unwrap();
    let bad = dir.path().join("bad.off");
    std::fs::write(&bad, "OFF\n3 1 0\n0 0 1 50 0 0 0 0\n").unwrap();
    let o = gradmesh(&["refine", s(&bad), "-o", s(&out)]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("bad.off"), "the message names the file: {msg}");
    assert_eq!(std::fs::read_to_string(&out).unwrap(), "precious");
    // No temporary file is left behind.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 2, "{names:?}");
}

#[test]
fn convert_never_writes_over_its_input_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("glasses.json");
    let o = gradmesh(&[
        "convert",
        s(&realdata().join("Glasses.off")),
        "-o",
        s(&json),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let before = std::fs::read(&json).unwrap();
    let o = gradmesh(&["convert", s(&json), "-o", s(&json)]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("--force"), "{}", stderr(&o));
    assert_eq!(std::fs::read(&json).unwrap(), before);
    // Read and written again, a native document is byte-identical.
    let o = gradmesh(&["convert", s(&json), "-o", s(&json), "--force"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(std::fs::read(&json).unwrap(), before);
    // And it refines like the original.
    let (a, b) = (dir.path().join("a.obj"), dir.path().join("b.obj"));
    assert!(
        gradmesh(&["refine", s(&json), "-o", s(&a), "--levels", "2"])
            .status
            .success()
    );
    let off = realdata().join("Glasses.off");
    assert!(gradmesh(&["refine", s(&off), "-o", s(&b), "--levels", "2"])
        .status
        .success());
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn errors_name_the_file_and_the_element() {
    let dir = tempfile::tempdir().unwrap();
    let obj = dir.path().join("bowtie.obj");
    std::fs::write(
        &obj,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv -1 0 0\nv 0 -1 0\nf 1 2 3\nf 1 4 5\n",
    )
    .unwrap();
    let o = gradmesh(&["info", s(&obj)]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(msg.contains("bowtie.obj"), "{msg}");
    assert!(msg.contains("point 0 is non-manifold"), "{msg}");
    let o = gradmesh(&["refine", s(&obj), "-o", s(&dir.path().join("x.png"))]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains(".obj or .json"), "{}", stderr(&o));
}

#[test]
fn refinement_beyond_the_limits_is_refused_before_building() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("t.off");
    std::fs::write(
        &input,
        "OFF\n3 1 0\n0 0 0 50 0 0 0\n1 0 0 60 0 0 0\n0 1 0 70 0 0 0\n3 0 1 2\n",
    )
    .unwrap();
    let out = dir.path().join("out.obj");
    let start = std::time::Instant::now();
    let o = gradmesh(&["refine", s(&input), "-o", s(&out), "-l", "12"]);
    assert!(!o.status.success());
    assert!(start.elapsed() < std::time::Duration::from_secs(5));
    assert!(
        stderr(&o).contains(
            "t.off: layer 0: the number of faces of refinement level 12 (about 22 GB of memory) is 28,311,552, above the limit of 8,388,608"
        ),
        "{}",
        stderr(&o)
    );
    let o = gradmesh(&["refine", s(&input), "-o", s(&out), "-l", "13"]);
    assert!(stderr(&o).contains("the refinement level is 13, above the limit of 12"));
    // The limits are raised or lowered by flags.
    let o = gradmesh(&[
        "refine",
        s(&input),
        "-o",
        s(&out),
        "-l",
        "2",
        "--max-refined-faces",
        "10",
    ]);
    assert!(
        stderr(&o).contains("above the limit of 10"),
        "{}",
        stderr(&o)
    );
    let o = gradmesh(&["refine", s(&input), "-o", s(&out), "-l", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = gradmesh(&["info", s(&input), "--max-points", "2"]);
    assert!(
        stderr(&o).contains("t.off:2: the number of vertices is 3, above the limit of 2"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("out.json").exists());
}

#[test]
fn output_into_a_missing_directory_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("t.off");
    std::fs::write(
        &input,
        "OFF\n3 1 0\n0 0 0 50 0 0 0\n1 0 0 60 0 0 0\n0 1 0 70 0 0 0\n3 0 1 2\n",
    )
    .unwrap();
    let out = dir.path().join("missing/out.json");
    let o = gradmesh(&["convert", s(&input), "-o", s(&out)]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("missing does not exist"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("missing").exists());
    let o = gradmesh(&["convert", s(&input), "-o", s(dir.path())]);
    assert!(!o.status.success());
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(names.len(), 1, "a temporary file was left behind");
}

#[test]
fn scheme_options_on_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let input = realdata().join("Tucan_Tucan_Layer3.off");
    // Interpolated positions: every control point is a limit point.
    let out = dir.path().join("limit.obj");
    let o = gradmesh(&[
        "refine",
        s(&input),
        "-o",
        s(&out),
        "--levels",
        "2",
        "--limit",
        "--interpolate-positions",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    let limits: Vec<(f64, f64)> = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| {
            let f: Vec<f64> = l[2..]
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            (f[0], f[1])
        })
        .collect();
    let original = std::fs::read_to_string(&input).unwrap();
    let count: usize = original
        .lines()
        .nth(1)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .parse()
        .unwrap();
    for line in original.lines().skip(2).take(count) {
        let f: Vec<f64> = line
            .split_whitespace()
            .take(2)
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(
            limits
                .iter()
                .any(|&(x, y)| (x - f[0]).abs() < 1e-6 && (y - f[1]).abs() < 1e-6),
            "control point ({}, {}) is not a limit point",
            f[0],
            f[1]
        );
    }
    // Two binary steps: level 1 is all quads.
    let out = dir.path().join("binary.obj");
    let o = gradmesh(&[
        "refine",
        s(&input),
        "-o",
        s(&out),
        "--levels",
        "1",
        "--first-step",
        "binary",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text
        .lines()
        .filter(|l| l.starts_with("f "))
        .all(|l| l.split_whitespace().count() == 5));
}

#[test]
fn info_warns_where_the_surface_folds() {
    let examples = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples"));
    let o = gradmesh(&["info", s(&examples.join("fold.json"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(
        text.contains("the surface folds over itself near"),
        "{text}"
    );
    let o = gradmesh(&["info", s(&examples.join("fold-fixed.json"))]);
    let text = String::from_utf8(o.stdout).unwrap();
    assert!(!text.contains("folds over itself"), "{text}");
}

#[test]
fn images_beyond_the_pixel_limit_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("big.png");
    let input = realdata().join("Glasses.off");
    let o = gradmesh(&["render", s(&input), "-o", s(&out), "--width", "20000"]);
    assert!(!o.status.success());
    let msg = stderr(&o);
    assert!(
        msg.contains("pixel count") && msg.contains("100,000,000"),
        "{msg}"
    );
    assert!(!out.exists());
    let o = gradmesh(&[
        "render",
        s(&input),
        "-o",
        s(&out),
        "--width",
        "300",
        "--max-pixels",
        "1000",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("above the limit of 1,000"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn edits_are_listed_and_applied_by_refine() {
    let example = PathBuf::from(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../examples/multires.json"
    ));
    let out = gradmesh(&["edits", s(&example)]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("layer 0 (multires): 7 edits, colour-only"),
        "{text}"
    );
    assert!(
        text.contains("edit 2: level 2, face 1 at point 2, [1, 2]: vertex 141 at (301.111, 78.333): colour + [-30, 0, 0] (lab)"),
        "{text}"
    );

    // The refined level 3 differs from that of the same mesh without edits.
    let dir = tempfile::tempdir().unwrap();
    let mut plain: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&example).unwrap()).unwrap();
    plain["layers"][0].as_object_mut().unwrap().remove("edits");
    let plain_path = dir.path().join("plain.json");
    std::fs::write(&plain_path, plain.to_string()).unwrap();
    let refined = |input: &Path, name: &str| {
        let output = dir.path().join(name);
        let out = gradmesh(&["refine", s(input), "-o", s(&output), "--levels", "3"]);
        assert!(out.status.success(), "{}", stderr(&out));
        std::fs::read_to_string(output).unwrap()
    };
    let (a, b) = (refined(&example, "a.obj"), refined(&plain_path, "b.obj"));
    assert_eq!(a.lines().count(), b.lines().count());
    let differing = a.lines().zip(b.lines()).filter(|(x, y)| x != y).count();
    assert!(
        differing > 10 && differing < a.lines().count() / 4,
        "{differing}"
    );

    let out = gradmesh(&["edits", s(&plain_path)]);
    assert!(String::from_utf8(out.stdout).unwrap().contains("no edits"));
}

/// `--png-compression best` writes a smaller file of the same pixels.
#[test]
fn png_compression_keeps_the_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let input = realdata().join("Glasses.off");
    let decode = |path: &Path| {
        let file = std::fs::File::open(path).unwrap();
        let mut reader = png::Decoder::new(std::io::BufReader::new(file))
            .read_info()
            .unwrap();
        let mut data = vec![0; reader.output_buffer_size().unwrap()];
        reader.next_frame(&mut data).unwrap();
        data
    };
    let mut files = Vec::new();
    for level in ["fast", "best"] {
        let out = dir.path().join(format!("{level}.png"));
        let args = ["render", s(&input), "-o", s(&out), "--width", "300"];
        let o = gradmesh(&[&args[..], &["--png-compression", level]].concat());
        assert!(o.status.success(), "{}", stderr(&o));
        files.push(out);
    }
    assert_eq!(decode(&files[0]), decode(&files[1]));
    let size = |p: &Path| std::fs::metadata(p).unwrap().len();
    assert!(size(&files[1]) < size(&files[0]));
    let o = gradmesh(&[
        "render",
        s(&input),
        "-o",
        "x.png",
        "--png-compression",
        "max",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("fast"), "{}", stderr(&o));
}

/// `render` draws straight into 8- or 16-bit pixels (no `f32` image) unless outlines go on
/// top: every way gives the bytes the library's image path encodes.
#[test]
fn render_writes_the_image_paths_pixels() {
    use gradmesh::render::{encode_png, render_image, PngDepth, RenderOptions, View};
    let dir = tempfile::tempdir().unwrap();
    let input = realdata().join("Glasses.off");
    let doc = gradmesh::formats::read_path(&input).unwrap();
    // The command's view and size for `--width 240`.
    let view = View::fit(&doc, 0.0);
    let height = (240.0 * view.height() / view.width()).round() as u32;
    let (image, _) = render_image(&doc, &RenderOptions::new(240, height, view)).unwrap();
    for (extra, depth) in [
        (&[][..], PngDepth::Eight { dither: true }),
        (&["--bits", "16"][..], PngDepth::Sixteen),
        (&["--no-dither"][..], PngDepth::Eight { dither: false }),
    ] {
        let out = dir.path().join("out.png");
        let mut args = vec!["render", s(&input), "-o", s(&out), "--width", "240"];
        args.extend_from_slice(extra);
        let o = gradmesh(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        let expect = encode_png(&image, depth).unwrap();
        assert!(std::fs::read(&out).unwrap() == expect, "{extra:?}");
    }
    // `--linear-colour` is the library's `quadratic: false`, and draws other pixels.
    let mut opts = RenderOptions::new(240, height, view);
    opts.quadratic = false;
    let (linear, _) = render_image(&doc, &opts).unwrap();
    let out = dir.path().join("linear.png");
    let args = [
        "render",
        s(&input),
        "-o",
        s(&out),
        "--width",
        "240",
        "--linear-colour",
    ];
    let o = gradmesh(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let expect = encode_png(&linear, PngDepth::Eight { dither: true }).unwrap();
    assert!(std::fs::read(&out).unwrap() == expect);
    assert!(expect != encode_png(&image, PngDepth::Eight { dither: true }).unwrap());
}

/// An absurd request: the command fails with exit status 1 (as every refused limit does) and
/// one line of error on standard error, without aborting, in well under a second of work, and
/// leaves an existing output file as it was.
fn assert_refused(args: &[&str], output: Option<&Path>, expected: &[&str]) {
    if let Some(out) = output {
        std::fs::write(out, "precious").unwrap();
    }
    let o = gradmesh(args);
    let msg = stderr(&o);
    assert_eq!(o.status.code(), Some(1), "{args:?}: {msg}");
    let errors: Vec<&str> = msg
        .lines()
        .filter(|l| !l.starts_with("gradmesh: warning:"))
        .collect();
    assert_eq!(errors.len(), 1, "{args:?}: one line of error, got {msg}");
    assert!(
        errors[0].starts_with("gradmesh: error: "),
        "{args:?}: {msg}"
    );
    for e in expected {
        assert!(errors[0].contains(e), "{args:?}: {e:?} not in {msg}");
    }
    if let Some(out) = output {
        assert_eq!(
            std::fs::read_to_string(out).unwrap(),
            "precious",
            "{args:?}"
        );
        let dir = out.parent().unwrap();
        let tmp = std::fs::read_dir(dir)
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .contains(".tmp")
            })
            .count();
        assert_eq!(
            tmp,
            0,
            "{args:?}: a temporary file was left in {}",
            dir.display()
        );
    }
}

#[test]
fn absurd_images_are_refused_before_anything_is_allocated() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.png");
    let input = realdata().join("Glasses.off");
    let render = |extra: &[&str], expected: &[&str]| {
        let mut args = vec!["render", s(&input), "-o", s(&out)];
        args.extend_from_slice(extra);
        assert_refused(&args, Some(&out), expected);
    };
    // 10^12 pixels: the pixel count and the limit are named.
    render(
        &["--width", "1000000", "--height", "1000000"],
        &["pixel count is 1,000,000,000,000", "limit of 100,000,000"],
    );
    // A side of 2^31, alone and with the pixel limit lifted.
    render(&["--width", "2147483648"], &["pixel count"]);
    render(
        &[
            "--width",
            "2147483648",
            "--height",
            "1",
            "--max-pixels",
            "18446744073709551615",
        ],
        &["image side is 2,147,483,648", "limit of 32,768"],
    );
    // 40 levels.
    render(
        &["--width", "100", "--level", "40"],
        &[
            "Glasses.off: layer 0: the number of faces of refinement level",
            "limit of 2,097,152",
        ],
    );
    // A level whose quads would exceed max_quads is refused from an estimate.
    render(
        &["--width", "100", "--level", "9"],
        &[
            "Glasses.off: layer 0: the number of faces of refinement level 9",
            "limit of 2,097,152",
        ],
    );
    // Views 1e300 and 1e-300 wide.
    render(
        &["--width", "100", "--view", "0", "0", "1e300", "1e300"],
        &["view: (0.0, 0.0) to (1e300, 1e300)", "beyond ±1e150"],
    );
    render(
        &["--width", "100", "--view", "0", "0", "1e-300", "1e-300"],
        &[
            "view: (0.0, 0.0) to (1e-300, 1e-300)",
            "a pixel would be 1e-302 units across",
        ],
    );
    // A view far from the origin whose pixels its coordinates cannot resolve.
    render(
        &[
            "--width",
            "100",
            "--view",
            "1e12",
            "0",
            "1.000000000001e12",
            "1",
        ],
        &["a pixel would be"],
    );
    // 16 bits at the pixel limit: one pixel more than allowed is refused, as at 8 bits.
    render(
        &["--width", "10001", "--height", "10000", "--bits", "16"],
        &["pixel count is 100,010,000", "limit of 100,000,000"],
    );
    render(
        &[
            "--width",
            "41",
            "--height",
            "100",
            "--bits",
            "16",
            "--max-pixels",
            "4000",
        ],
        &["pixel count is 4,100", "limit of 4,000"],
    );
    render(
        &[
            "--width",
            "41",
            "--height",
            "100",
            "--boundary",
            "--max-pixels",
            "4000",
        ],
        &["pixel count is 4,100", "limit of 4,000"],
    );
    // At the limit it renders.
    let o = gradmesh(&[
        "render",
        s(&input),
        "-o",
        s(&out),
        "--width",
        "40",
        "--height",
        "100",
        "--bits",
        "16",
        "--max-pixels",
        "4000",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_ne!(std::fs::read(&out).unwrap(), b"precious");
}

#[test]
fn absurd_inputs_are_refused_by_every_command() {
    let dir = tempfile::tempdir().unwrap();
    // 2^31 declared faces (and, with the face limit lifted, a file too short for them).
    let faces = dir.path().join("faces.off");
    std::fs::write(&faces, "OFF\n3 2147483648 0\n0 0 0 50 0 0 0\n").unwrap();
    // An edit at level 40.
    let deep = dir.path().join("deep.json");
    let mut doc: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../examples/multires.json"
        ))
        .unwrap(),
    )
    .unwrap();
    doc["layers"][0]["edits"] = serde_json::json!([
        {"level": 40, "face": 5, "point": 8, "at": [1, 1], "opacity": 0.5}
    ]);
    std::fs::write(&deep, doc.to_string()).unwrap();
    let out_json = dir.path().join("out.json");
    let out_obj = dir.path().join("out.obj");
    let out_png = dir.path().join("out.png");
    for (input, expected) in [
        (
            &faces,
            vec![
                "faces.off:2: the number of faces is 2,147,483,648",
                "limit of 16,777,216",
            ],
        ),
        (
            &deep,
            vec!["deep.json: layer 0: edit 0: expected a level in 1..=8, found 40"],
        ),
    ] {
        let input = s(input);
        assert_refused(&["info", input], None, &expected);
        assert_refused(&["edits", input], None, &expected);
        assert_refused(
            &["convert", input, "-o", s(&out_json)],
            Some(&out_json),
            &expected,
        );
        assert_refused(
            &["refine", input, "-o", s(&out_obj)],
            Some(&out_obj),
            &expected,
        );
        assert_refused(
            &["render", input, "-o", s(&out_png)],
            Some(&out_png),
            &expected,
        );
    }
    let lifted = ["--max-faces", "4294967296"];
    let short = ["faces.off:3: unexpected end of file: expected the line of vertex 1"];
    let f = s(&faces);
    assert_refused(&[&["info", f][..], &lifted].concat(), None, &short);
    assert_refused(
        &[&["render", f, "-o", s(&out_png)][..], &lifted].concat(),
        Some(&out_png),
        &short,
    );
    // 40 levels of refinement.
    let glasses = realdata().join("Glasses.off");
    assert_refused(
        &["refine", s(&glasses), "-o", s(&out_obj), "--levels", "40"],
        Some(&out_obj),
        &["Glasses.off: layer 0: the refinement level is 40, above the limit of 12"],
    );
    assert_refused(
        &[
            "refine",
            s(&glasses),
            "-o",
            s(&out_obj),
            "--levels",
            "40",
            "--max-level",
            "100",
        ],
        Some(&out_obj),
        &[
            "the number of faces of refinement level",
            "limit of 8,388,608",
        ],
    );
}

#[test]
fn info_reports_each_unreadable_file_once() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.json");
    let b = dir.path().join("b.json");
    std::fs::write(&a, "{").unwrap();
    std::fs::write(&b, "[]").unwrap();
    let o = gradmesh(&["info", s(&a), s(&b)]);
    assert_eq!(o.status.code(), Some(1));
    let msg = stderr(&o);
    assert_eq!(msg.lines().count(), 2, "{msg}");
    assert_eq!(msg.matches("a.json").count(), 1, "{msg}");
    assert_eq!(msg.matches("b.json").count(), 1, "{msg}");
    let o = gradmesh(&["info", s(&a)]);
    assert_eq!(stderr(&o).lines().count(), 1, "{}", stderr(&o));
}

/// The README's first command: the Tucan's six layers.
fn tucan_layers() -> Vec<PathBuf> {
    (0..6)
        .rev()
        .map(|i| realdata().join(format!("Tucan_Tucan_Layer{i}.off")))
        .collect()
}

/// The lines of `text` that are warnings about the file `path`.
fn warnings_about<'a>(text: &'a str, path: &Path) -> Vec<&'a str> {
    let prefix = format!("gradmesh: warning: {}: ", path.display());
    text.lines().filter(|l| l.starts_with(&prefix)).collect()
}

#[test]
fn render_counts_the_warnings_of_each_file_in_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tucan.png");
    let layers = tucan_layers();
    let mut args = vec!["render"];
    args.extend(layers.iter().map(|p| s(p)));
    args.extend(["-o", s(&out), "--width", "64"]);
    let quiet = gradmesh(&args);
    let msg = stderr(&quiet);
    assert!(quiet.status.success(), "{msg}");
    assert!(!msg.contains("longer than half its edge"), "{msg}");
    let mut summarised = 0;
    for layer in &layers {
        let lines = warnings_about(&msg, layer);
        assert!(lines.len() <= 1, "{}: {msg}", layer.display());
        summarised += lines.len();
    }
    assert!(summarised >= 1, "some Tucan layer has warnings: {msg}");
    assert_eq!(msg.lines().count(), summarised, "{msg}");
    assert!(
        msg.lines()
            .all(|l| l.ends_with(": --warnings to list them")),
        "{msg}"
    );
    assert!(msg.contains("handles may fold"), "{msg}");
    assert!(msg.contains("1 colour outside sRGB"), "{msg}");

    args.push("--warnings");
    let listed = gradmesh(&args);
    let full = stderr(&listed);
    assert!(listed.status.success(), "{full}");
    let handles = full.matches("longer than half its edge").count();
    let gamut = full.matches("outside the sRGB gamut").count();
    // Each kind's count in the summary is the number of warnings listed.
    let counted = |what: &str| -> usize {
        msg.split([',', ':'])
            .filter_map(|part| part.trim().strip_suffix(what))
            .map(|n| n.trim().parse::<usize>().unwrap())
            .sum()
    };
    assert_eq!(
        counted("handles may fold") + counted("handle may fold"),
        handles,
        "{msg}\n{full}"
    );
    assert_eq!(counted("colour outside sRGB"), gamut, "{msg}\n{full}");
    assert!(handles > summarised, "{full}");
    assert_eq!(full.lines().count(), handles + gamut, "{full}");
    // `info` lists them all without the flag, under their layer.
    let info_args: Vec<&str> = std::iter::once("info")
        .chain(layers.iter().map(|p| s(p)))
        .collect();
    let info = gradmesh(&info_args);
    let text = String::from_utf8(info.stdout).unwrap();
    assert_eq!(
        text.matches("longer than half its edge").count(),
        handles,
        "{text}"
    );
}

#[test]
fn warnings_are_counted_for_convert_and_refine_too() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("long.json");
    // A quad with a handle longer than half its edge, and a point no face uses.
    std::fs::write(
        &input,
        r##"{"format": "gradmesh", "version": 1, "layers": [{
            "points": [{"position": [0, 0], "colour": "#ff0000", "handles": [[1, 7, 0]]},
                       {"position": [10, 0], "colour": "#00ff00"},
                       {"position": [10, 10], "colour": "#0000ff"}, {"position": [0, 10], "colour": "#ffffff"},
                       {"position": [20, 20], "colour": "#000000"}],
            "faces": [[0, 1, 2, 3]]}]}"##,
    )
    .unwrap();
    let json = dir.path().join("out.json");
    let obj = dir.path().join("out.obj");
    for args in [
        vec!["convert", s(&input), "-o", s(&json)],
        vec!["refine", s(&input), "-o", s(&obj), "--levels", "1"],
    ] {
        let o = gradmesh(&args);
        let msg = stderr(&o);
        assert!(o.status.success(), "{args:?}: {msg}");
        assert_eq!(
            msg.trim_end(),
            format!(
                "gradmesh: warning: {}: 1 handle may fold, 1 point on no face: --warnings to list them",
                input.display()
            ),
            "{args:?}"
        );
        let mut listing = args.clone();
        listing.push("--warnings");
        let msg = stderr(&gradmesh(&listing));
        assert_eq!(msg.lines().count(), 2, "{args:?}: {msg}");
        assert!(
            msg.contains("layer 0: handle of point 0 towards 1 is longer"),
            "{msg}"
        );
        assert!(
            msg.contains("layer 0: point 4 is not used by any face"),
            "{msg}"
        );
    }
}

/// A reader that stops early (`gradmesh info ... | head`) ends the command quietly with status
/// 0, not with a panic. The output, a description per file of 2,000, is far more than a pipe
/// holds, so the command writes after the reader has gone whenever that happens.
#[test]
fn info_into_a_closed_pipe_ends_quietly() {
    let example = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/annulus.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_gradmesh"))
        .arg("info")
        .args(std::iter::repeat_n(example, 2000))
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("the binary runs");
    drop(child.stdout.take());
    let out = child.wait_with_output().expect("the command ends");
    let err = stderr(&out);
    assert!(out.status.success(), "{:?}: {err}", out.status);
    assert!(!err.contains("panicked"), "{err}");
}
