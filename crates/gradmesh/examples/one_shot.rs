//! What a one-shot render pays that a warm one does not, and PNG encoding's bytes against
//! time: the six Tucan layers rendered as `gradmesh render --width 1024` renders them, eight
//! times in one process (the first pays for the thread pool, first-touch page faults and the
//! allocator's growth), then that image encoded with each of the `png` crate's settings and
//! gradmesh's two (medians of 9; the decoded pixels are checked to be the same).
//!
//! Run: `cargo run --release -p gradmesh --example one_shot` (needs `../shared/realdata`).
use gradmesh::render::{render_document_into, RenderOptions, View};
use gradmesh::{formats, Document};
use std::time::Instant;

fn main() {
    let t0 = Instant::now();
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/realdata/gradientmeshimproved-off");
    let mut doc = Document::default();
    for i in (0..6).rev() {
        let d = formats::read_path(&dir.join(format!("Tucan_Tucan_Layer{i}.off"))).unwrap();
        doc.layers.extend(d.layers);
    }
    let read = t0.elapsed();
    let view = View::fit(&doc, 0.0);
    let w = 1024u32;
    let h = (w as f64 / (view.width() / view.height())).round() as u32;
    let opts = RenderOptions::new(w, h, view);
    let mut times = Vec::new();
    let mut buf = vec![0u8; (4 * w * h) as usize];
    for _ in 0..8 {
        let t = Instant::now();
        let info = render_document_into(&doc, &opts, &mut buf).unwrap();
        times.push((
            t.elapsed().as_secs_f64() * 1e3,
            info.timings.prepare.as_secs_f64() * 1e3,
            info.timings.draw.as_secs_f64() * 1e3,
        ));
    }
    eprintln!("read {:.2} ms {}x{}", read.as_secs_f64() * 1e3, w, h);
    for (t, p, d) in &times {
        eprintln!("render {t:7.2} ms  prepare {p:7.2} draw {d:7.2}");
    }
    println!("| encoding | bytes | time |\n|---|---|---|");
    png_table(w, h, &buf);
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn png_table(w: u32, h: u32, buf: &[u8]) {
    use gradmesh::render::{write_png_rgba8_with, PngCompression};
    let reference = {
        let mut out = Vec::new();
        write_png_rgba8_with(&mut out, w, h, buf, PngCompression::Fast).unwrap();
        decode(&out)
    };
    let row = |name: &str, f: &dyn Fn() -> Vec<u8>| {
        let mut times = Vec::new();
        let mut bytes = Vec::new();
        for _ in 0..9 {
            let t = Instant::now();
            bytes = f();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        assert_eq!(decode(&bytes), reference, "{name}");
        println!("| {name} | {} | {:.2} ms |", bytes.len(), median(times));
    };
    let ours = |c: PngCompression| {
        let mut out = Vec::new();
        write_png_rgba8_with(&mut out, w, h, buf, c).unwrap();
        out
    };
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    row("gradmesh fast, all threads", &|| ours(PngCompression::Fast));
    row("gradmesh fast, one thread", &|| {
        one.install(|| ours(PngCompression::Fast))
    });
    let png_crate = |c: png::DeflateCompression, f: png::Filter| {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, w, h);
        enc.set_color(png::ColorType::Rgba);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
        enc.set_deflate_compression(c);
        enc.set_filter(f);
        let mut wr = enc.write_header().unwrap();
        wr.write_image_data(buf).unwrap();
        wr.finish().unwrap();
        out
    };
    use png::{DeflateCompression as D, Filter as F};
    row("png NoCompression", &|| {
        png_crate(D::NoCompression, F::NoFilter)
    });
    row("png fdeflate, Sub", &|| {
        png_crate(D::FdeflateUltraFast, F::Sub)
    });
    row("png fdeflate, Up", &|| {
        png_crate(D::FdeflateUltraFast, F::Up)
    });
    row("png fdeflate, Paeth", &|| {
        png_crate(D::FdeflateUltraFast, F::Paeth)
    });
    row("png fdeflate, Adaptive", &|| {
        png_crate(D::FdeflateUltraFast, F::Adaptive)
    });
    row("png zlib 1, Sub", &|| png_crate(D::Level(1), F::Sub));
    row("png zlib 6, Adaptive", &|| {
        png_crate(D::Level(6), F::Adaptive)
    });
    row("gradmesh best (png zlib 9, Adaptive)", &|| {
        ours(PngCompression::Best)
    });
}

fn decode(bytes: &[u8]) -> Vec<u8> {
    let mut reader = png::Decoder::new(std::io::Cursor::new(bytes))
        .read_info()
        .unwrap();
    let mut out = vec![0; reader.output_buffer_size().unwrap()];
    reader.next_frame(&mut out).unwrap();
    out
}
