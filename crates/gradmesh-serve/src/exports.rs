//! Exports from the page: the visible layers as PNG, PDF or SVG through the library's
//! renderer and export, as a download named after the document.

use std::sync::Arc;

use axum::extract::{Query, State};
use axum::http::{header, StatusCode};
use axum::response::{IntoResponse, Response};
use gradmesh::export::{self, ExportOptions};
use gradmesh::render::{self, RenderOptions};
use gradmesh::Document;
use serde::Deserialize;

use crate::session::App;

/// The longest side of an export when the request names none, in pixels (or PDF points).
pub const DEFAULT_SIZE: u32 = 2048;

/// The largest `size` accepted.
pub const MAX_SIZE: u32 = 16384;

/// The formats the page exports.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
#[serde(rename_all = "lowercase")]
pub enum ExportFormat {
    /// An 8-bit RGBA PNG.
    Png,
    /// PDF type 7 shadings.
    Pdf,
    /// SVG mesh gradients (with a raster fallback beneath for browsers).
    Svg,
}

impl ExportFormat {
    fn extension(self) -> &'static str {
        match self {
            ExportFormat::Png => "png",
            ExportFormat::Pdf => "pdf",
            ExportFormat::Svg => "svg",
        }
    }

    fn media_type(self) -> &'static str {
        match self {
            ExportFormat::Png => "image/png",
            ExportFormat::Pdf => "application/pdf",
            ExportFormat::Svg => "image/svg+xml",
        }
    }
}

/// What `/api/export` is asked for.
#[derive(Debug, Deserialize)]
pub struct ExportQuery {
    /// The format.
    pub format: ExportFormat,
    /// The longest side in pixels (PDF: points); default [`DEFAULT_SIZE`].
    pub size: Option<u32>,
}

/// The visible layers of `doc` in `format`, fitted to `size` pixels on the longest side.
pub fn export_document(doc: &Document, format: ExportFormat, size: u32) -> Result<Vec<u8>, String> {
    if !(1..=MAX_SIZE).contains(&size) {
        return Err(format!(
            "the size must be 1 to {MAX_SIZE} pixels, not {size}"
        ));
    }
    if doc.layers.iter().all(|l| l.faces.is_empty()) {
        return Err("nothing to export: no visible layer has a face".into());
    }
    let opts = RenderOptions::fit(doc, size);
    let fail = |e: gradmesh::Error| e.to_string();
    match format {
        ExportFormat::Png => {
            let mut pixels = vec![0u8; 4 * opts.width as usize * opts.height as usize];
            render::render_document_into(doc, &opts, &mut pixels).map_err(fail)?;
            render::encode_png_rgba8(opts.width, opts.height, &pixels).map_err(fail)
        }
        ExportFormat::Pdf | ExportFormat::Svg => {
            let export_opts = ExportOptions::new(opts.width, opts.height, opts.view);
            export_opts.check().map_err(fail)?;
            let written = if format == ExportFormat::Pdf {
                export::write_pdf(doc, &export_opts)
            } else {
                export::write_svg(doc, &export_opts, true)
            };
            written.map(|(bytes, _)| bytes).map_err(fail)
        }
    }
}

/// The download's file name: the document's file name with the format's extension, or
/// `untitled`; characters a header cannot carry plainly become `_`.
pub fn download_name(document: Option<&std::path::Path>, format: ExportFormat) -> String {
    let stem = document
        .and_then(|p| p.file_stem())
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "untitled".into());
    let safe: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_graphic() && c != '"' && c != '\\' || c == ' ' {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("{safe}.{}", format.extension())
}

/// `GET /api/export?format=png|pdf|svg&size=N`: the visible layers as a download.
pub async fn export_route(State(app): State<Arc<App>>, Query(q): Query<ExportQuery>) -> Response {
    let (doc, name) = {
        let editor = app.editor();
        let name = download_name(editor.path.as_deref(), q.format);
        (editor.history.current().visible(), name)
    };
    let size = q.size.unwrap_or(DEFAULT_SIZE);
    let format = q.format;
    let bytes = tokio::task::spawn_blocking(move || export_document(&doc, format, size))
        .await
        .unwrap_or_else(|_| Err("the export failed".into()));
    match bytes {
        Ok(bytes) => (
            [
                (header::CONTENT_TYPE, format.media_type().to_string()),
                (
                    header::CONTENT_DISPOSITION,
                    format!("attachment; filename=\"{name}\""),
                ),
            ],
            bytes,
        )
            .into_response(),
        Err(e) => (StatusCode::UNPROCESSABLE_ENTITY, e).into_response(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    #[test]
    fn downloads_are_named_after_the_document() {
        let png = download_name(Some(Path::new("/a/Tucan art.json")), ExportFormat::Png);
        assert_eq!(png, "Tucan art.png");
        assert_eq!(download_name(None, ExportFormat::Pdf), "untitled.pdf");
        let odd = download_name(Some(Path::new("/a/x\"é.json")), ExportFormat::Svg);
        assert_eq!(odd, "x__.svg");
    }
}
