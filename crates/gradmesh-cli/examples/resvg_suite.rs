//! resvg's regression suite through gradmesh's whole-picture path.
//!
//! Every test SVG of resvg's suite (`crates/resvg/tests/tests/**.svg` in linebender/resvg,
//! each beside its reference PNG) gets an invisible 1x1 rect filled with a mesh gradient far
//! outside the canvas, so that `gradmesh render` draws the rest of the picture with resvg and
//! composites the (invisible) mesh fill into it. The command is run at the reference's size;
//! its exit status must be 0 or 1 (anything else, a panic's 101, an abort's 134 or a signal,
//! is a bug), and its PNG is compared with the reference. For scale, resvg itself renders
//! each original file as its own suite does (the suite's fonts) and is compared the same way.
//!
//! ```text
//! cargo run -p gradmesh-cli --example resvg_suite -- TESTS_DIR GRADMESH_BINARY OUT_DIR
//! ```
//!
//! `scripts/resvg-suite.sh` fetches the suite and runs this; `docs/svg.md` gives the figures.
//! The injected copies are written beside the originals (relative links resolve against the
//! file's folder), so TESTS_DIR must be a scratch copy of the suite.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// The mesh fill added to every file: a 1x1 patch at (-100000, -100000), off any canvas.
const PROBE: &str = concat!(
    "<defs><meshgradient id=\"gm_probe_mesh\" x=\"-100000\" y=\"-100000\" ",
    "gradientUnits=\"userSpaceOnUse\"><meshrow><meshpatch>",
    "<stop path=\"l 1,0\" stop-color=\"#f00\"/><stop path=\"l 0,1\" stop-color=\"#f00\"/>",
    "<stop path=\"l -1,0\" stop-color=\"#f00\"/><stop path=\"l 0,-1\" stop-color=\"#f00\"/>",
    "</meshpatch></meshrow></meshgradient></defs>",
    "<rect x=\"-100000\" y=\"-100000\" width=\"1\" height=\"1\" fill=\"url(#gm_probe_mesh)\"/>"
);

/// A pixel differs when a channel differs by more than this (resvg's suite uses 1), unless
/// both pixels are fully transparent.
const CHANNEL_TOLERANCE: u8 = 1;

/// A render "nearly matches" when at most this share of its pixels differ.
const NEAR_SHARE: f64 = 0.001;

/// The longest a single render may take before it is killed and counted as a time-out.
const TIME_LIMIT: Duration = Duration::from_secs(120);

/// What became of one file.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Debug)]
enum Outcome {
    /// Every pixel within [`CHANNEL_TOLERANCE`] of the reference.
    Matches,
    /// At most [`NEAR_SHARE`] of the pixels differ.
    NearlyMatches,
    Differs,
    /// Exit status 1: refused with an error message.
    Refused,
    /// Any other exit status, a signal or a time-out.
    Crashed,
}

struct Counts(BTreeMap<Outcome, usize>);

impl Counts {
    fn add(&mut self, o: Outcome) {
        *self.0.entry(o).or_default() += 1;
    }
    fn get(&self, o: Outcome) -> usize {
        self.0.get(&o).copied().unwrap_or(0)
    }
    fn total(&self) -> usize {
        self.0.values().sum()
    }
    fn line(&self, name: &str) -> String {
        let t = self.total().max(1) as f64;
        let m = self.get(Outcome::Matches);
        let n = self.get(Outcome::NearlyMatches);
        format!(
            "{name:16} {:5} files: exit 0 {:5}, exit 1 {:4}, other {:3}; matching {:5} ({:5.1} %), \
             within {:.1} % of pixels {:5} ({:5.1} %)",
            self.total(),
            self.total() - self.get(Outcome::Refused) - self.get(Outcome::Crashed),
            self.get(Outcome::Refused),
            self.get(Outcome::Crashed),
            m,
            100.0 * m as f64 / t,
            100.0 * NEAR_SHARE,
            m + n,
            100.0 * (m + n) as f64 / t,
        )
    }
}

/// RGBA8 pixels, straight alpha.
struct Picture {
    width: u32,
    height: u32,
    data: Vec<u8>,
}

fn decode_png(path: &Path) -> Result<Picture, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder
        .read_info()
        .map_err(|e| format!("{}: {e}", path.display()))?;
    let size = reader.output_buffer_size().ok_or("PNG too large")?;
    let mut raw = vec![0; size];
    let info = reader
        .next_frame(&mut raw)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    raw.truncate(info.buffer_size());
    let data = match info.color_type {
        png::ColorType::Rgba => raw,
        png::ColorType::Rgb => raw
            .chunks_exact(3)
            .flat_map(|p| [p[0], p[1], p[2], 255])
            .collect(),
        png::ColorType::GrayscaleAlpha => raw
            .chunks_exact(2)
            .flat_map(|p| [p[0], p[0], p[0], p[1]])
            .collect(),
        png::ColorType::Grayscale => raw.iter().flat_map(|&g| [g, g, g, 255]).collect(),
        png::ColorType::Indexed => {
            return Err(format!("{}: indexed after expansion", path.display()))
        }
    };
    Ok(Picture {
        width: info.width,
        height: info.height,
        data,
    })
}

/// How many pixels of `a` and `b` differ (a pixel outside either picture differs).
fn differing_pixels(a: &Picture, b: &Picture) -> usize {
    if (a.width, a.height) != (b.width, b.height) {
        return (a.width.max(b.width) * a.height.max(b.height)) as usize;
    }
    a.data
        .chunks_exact(4)
        .zip(b.data.chunks_exact(4))
        .filter(|(p, q)| {
            !(p[3] == 0 && q[3] == 0) && (0..4).any(|c| p[c].abs_diff(q[c]) > CHANNEL_TOLERANCE)
        })
        .count()
}

fn compare(actual: &Picture, reference: &Picture) -> Outcome {
    let differing = differing_pixels(actual, reference);
    let pixels = (reference.width * reference.height).max(1) as f64;
    if differing == 0 {
        Outcome::Matches
    } else if differing as f64 <= NEAR_SHARE * pixels {
        Outcome::NearlyMatches
    } else {
        Outcome::Differs
    }
}

/// `text` with [`PROBE`] before the root's closing tag; `None` when it has no `</svg>`.
fn inject(text: &[u8]) -> Option<Vec<u8>> {
    let close = text.windows(6).rposition(|w| w == b"</svg>")?;
    let mut out = Vec::with_capacity(text.len() + PROBE.len());
    out.extend_from_slice(&text[..close]);
    out.extend_from_slice(PROBE.as_bytes());
    out.extend_from_slice(&text[close..]);
    Some(out)
}

/// Runs `command`, killing it after [`TIME_LIMIT`]; `None` on a time-out.
fn run_with_limit(mut command: Command) -> std::io::Result<(Option<ExitStatus>, Vec<u8>)> {
    let mut child = command
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()?;
    let mut stderr = child.stderr.take().expect("piped");
    let reader = std::thread::spawn(move || {
        let mut buf = Vec::new();
        let _ = std::io::Read::read_to_end(&mut stderr, &mut buf);
        buf
    });
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break Some(status);
        }
        if start.elapsed() > TIME_LIMIT {
            child.kill()?;
            child.wait()?;
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Ok((status, reader.join().unwrap_or_default()))
}

/// The suite's font setup (its `tests/integration/main.rs`).
fn suite_options(tests_dir: &Path, svg: &Path) -> resvg::usvg::Options<'static> {
    let mut options = resvg::usvg::Options {
        resources_dir: svg.parent().map(Path::to_path_buf),
        ..Default::default()
    };
    let db = options.fontdb_mut();
    db.load_fonts_dir(tests_dir.join("fonts"));
    db.set_serif_family("Noto Serif");
    db.set_sans_serif_family("Noto Sans");
    db.set_cursive_family("Yellowtail");
    db.set_fantasy_family("Sedgwick Ave Display");
    db.set_monospace_family("Noto Mono");
    options
}

/// resvg's own render of `svg` at `width` x `height`, unpremultiplied, as its suite renders.
fn resvg_render(tests_dir: &Path, svg: &Path, width: u32, height: u32) -> Option<Picture> {
    let data = std::fs::read(svg).ok()?;
    let options = suite_options(tests_dir, svg);
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let tree = resvg::usvg::Tree::from_data(&data, &options).ok()?;
        let mut pixmap = resvg::tiny_skia::Pixmap::new(width, height)?;
        let size = tree.size();
        let ts = resvg::tiny_skia::Transform::from_scale(
            width as f32 / size.width(),
            height as f32 / size.height(),
        );
        resvg::render(&tree, ts, &mut pixmap.as_mut());
        let data = pixmap
            .pixels()
            .iter()
            .flat_map(|p| {
                let c = p.demultiply();
                [c.red(), c.green(), c.blue(), c.alpha()]
            })
            .collect();
        Some(Picture {
            width,
            height,
            data,
        })
    }))
    .ok()
    .flatten()
}

/// The test SVGs under `dir` (those with a reference PNG beside them), sorted.
fn test_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            test_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "svg")
            && !path.to_string_lossy().ends_with(".gm-injected.svg")
            && path.with_extension("png").is_file()
        {
            out.push(path);
        }
    }
    out.sort();
}

/// One file's result: gradmesh's outcome, resvg's, and a note for the log.
struct FileResult {
    gradmesh: Outcome,
    resvg: Outcome,
    note: String,
}

fn run_one(tests_dir: &Path, bin: &Path, out_dir: &Path, svg: &Path) -> Result<FileResult, String> {
    let reference = decode_png(&svg.with_extension("png"))?;
    let resvg = match resvg_render(tests_dir, svg, reference.width, reference.height) {
        Some(p) => compare(&p, &reference),
        None => Outcome::Refused,
    };
    let text = std::fs::read(svg).map_err(|e| format!("{}: {e}", svg.display()))?;
    let (input, injected) = match inject(&text) {
        Some(t) => (svg.with_extension("gm-injected.svg"), t),
        None => (svg.to_path_buf(), text),
    };
    if input != svg {
        std::fs::write(&input, &injected).map_err(|e| format!("{}: {e}", input.display()))?;
    }
    let png = out_dir.join("out.png");
    let _ = std::fs::remove_file(&png);
    let mut command = Command::new(bin);
    command.arg("render").arg(&input).arg("-o").arg(&png).args([
        "--width",
        &reference.width.to_string(),
        "--height",
        &reference.height.to_string(),
        "--no-dither",
    ]);
    let (status, stderr) =
        run_with_limit(command).map_err(|e| format!("{}: {e}", bin.display()))?;
    let stderr = String::from_utf8_lossy(&stderr).replace('\n', " | ");
    let gradmesh = match status.and_then(|s| s.code()) {
        Some(0) => compare(&decode_png(&png)?, &reference),
        Some(1) => Outcome::Refused,
        _ => Outcome::Crashed,
    };
    let note = match status {
        None => "time-out".to_string(),
        Some(s) if gradmesh == Outcome::Crashed || gradmesh == Outcome::Refused => {
            format!("{s}: {stderr}")
        }
        Some(_) => String::new(),
    };
    Ok(FileResult {
        gradmesh,
        resvg,
        note,
    })
}

fn main() -> Result<(), String> {
    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [tests_dir, bin, out_dir] = args.as_slice() else {
        return Err("usage: resvg_suite TESTS_DIR GRADMESH_BINARY OUT_DIR".into());
    };
    std::fs::create_dir_all(out_dir).map_err(|e| format!("{}: {e}", out_dir.display()))?;
    let mut files = Vec::new();
    test_files(&tests_dir.join("tests"), &mut files);
    if files.is_empty() {
        return Err(format!("no test SVGs under {}/tests", tests_dir.display()));
    }
    let log_path = out_dir.join("results.tsv");
    let mut log =
        std::fs::File::create(&log_path).map_err(|e| format!("{}: {e}", log_path.display()))?;
    let mut by_area: BTreeMap<String, (Counts, Counts)> = BTreeMap::new();
    let (mut all, mut all_resvg) = (Counts(BTreeMap::new()), Counts(BTreeMap::new()));
    for (i, svg) in files.iter().enumerate() {
        let name = svg.strip_prefix(tests_dir.join("tests")).unwrap_or(svg);
        let area = name
            .iter()
            .next()
            .map_or(String::new(), |a| a.to_string_lossy().into_owned());
        let r = run_one(tests_dir, bin, out_dir, svg)?;
        let _ = writeln!(
            log,
            "{}\t{:?}\t{:?}\t{}",
            name.display(),
            r.gradmesh,
            r.resvg,
            r.note
        );
        if r.gradmesh == Outcome::Crashed {
            eprintln!("CRASH {}: {}", name.display(), r.note);
        }
        let entry = by_area
            .entry(area)
            .or_insert_with(|| (Counts(BTreeMap::new()), Counts(BTreeMap::new())));
        entry.0.add(r.gradmesh);
        entry.1.add(r.resvg);
        all.add(r.gradmesh);
        all_resvg.add(r.resvg);
        if (i + 1) % 100 == 0 {
            eprintln!("{} / {}", i + 1, files.len());
        }
    }
    println!("gradmesh render (mesh injected), against resvg's reference PNGs:");
    for (area, (g, _)) in &by_area {
        println!("{}", g.line(area));
    }
    println!("{}", all.line("all"));
    println!("resvg itself (the suite's fonts), against the same PNGs:");
    for (area, (_, r)) in &by_area {
        println!("{}", r.line(area));
    }
    println!("{}", all_resvg.line("all"));
    println!("per file: {}", log_path.display());
    Ok(())
}
