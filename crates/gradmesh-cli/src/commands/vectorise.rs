//! `gradmesh vectorise`: a photograph into a gradient mesh fitted to it.

use std::io::IsTerminal;
use std::time::Instant;

use gradmesh::formats::{self, json};
use gradmesh::{Error, ErrorKind, RgbaImage, VectoriseOptions};

use crate::args::VectoriseArgs;

pub fn run(args: &VectoriseArgs) -> Result<(), Error> {
    let is_json = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"));
    if !is_json {
        return Err(Error::new(ErrorKind::UnsupportedFormat(format!(
            "{}: vectorise writes .json",
            args.output.display()
        ))));
    }
    super::check_not_input(&args.output, &[args.input.as_path()], args.force)?;
    let start = Instant::now();
    let image = RgbaImage::read_path(&args.input, args.max_input_bytes, args.max_pixels)?;
    let options = VectoriseOptions {
        points: args.points,
        psnr: args.psnr,
        quality: args.quality.into(),
        ..VectoriseOptions::default()
    };
    let bar = std::io::stderr().is_terminal().then(|| {
        let total = options.points.unwrap_or(options.max_points) as u64;
        let bar = indicatif::ProgressBar::new(total);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{elapsed:>4} [{bar:30}] {pos}/{len} points {msg}",
            )
            .expect("a valid template")
            .progress_chars("=> "),
        );
        bar
    });
    let result = gradmesh::vectorise_with_progress(&image, &options, |p| {
        if let Some(bar) = &bar {
            bar.set_position(p.points as u64);
            bar.set_message(format!("{:.2} dB", p.psnr));
        }
    })?;
    if let Some(bar) = bar {
        bar.finish_and_clear();
    }
    formats::write_atomic(
        &args.output,
        json::write_document(&result.document).as_bytes(),
    )
    .map_err(|e| e.in_file(&args.output))?;
    eprintln!(
        "{}: {} x {} pixels, {} points, PSNR {:.2} dB, {} rounds, {:.2} s",
        args.output.display(),
        image.width,
        image.height,
        result.points,
        result.psnr,
        result.rounds,
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
