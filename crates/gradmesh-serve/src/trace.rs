//! Trace: a mesh fitted to (a part of) the reference image by the library's vectoriser
//! ([`gradmesh::vectorise`]), placed where the image lies in the document, added as a new
//! layer in one step of the history.
//!
//! The page sends the pixels of the part to trace as a PNG (the reference image never leaves
//! the page otherwise) with the rectangle of the document it covers.

use gradmesh::{vectorise, GradientMesh, RgbaImage, VectoriseOptions};
use serde::Deserialize;

use crate::editor::Editor;

/// The most pixels of a picture to trace; the page scales larger parts down to fit.
pub const MAX_TRACE_PIXELS: u64 = 1 << 20;

/// The most control points a trace may ask for.
pub const MAX_TRACE_POINTS: usize = 4096;

/// What to trace: the rectangle of the document the picture covers and the point budget.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq)]
pub struct TraceRequest {
    /// Left edge of the picture in the document.
    pub x0: f64,
    /// Top edge.
    pub y0: f64,
    /// Right edge.
    pub x1: f64,
    /// Bottom edge.
    pub y1: f64,
    /// The most control points of the mesh (4 to [`MAX_TRACE_POINTS`]).
    pub points: usize,
}

/// A traced layer and how well it fits.
#[derive(Clone, Debug)]
pub struct Traced {
    /// The layer, in the document's coordinates.
    pub mesh: GradientMesh,
    /// Its control points.
    pub points: usize,
    /// The PSNR of its render against the picture, in dB.
    pub psnr: f64,
}

/// Fits a mesh to the PNG or JPEG `picture` and places it over `request`'s rectangle. Takes
/// seconds for large budgets: call it off the async runtime.
pub fn trace(picture: &[u8], request: &TraceRequest) -> Result<Traced, String> {
    check(request)?;
    let image = RgbaImage::decode(picture, MAX_TRACE_PIXELS)
        .map_err(|e| format!("the picture to trace: {e}"))?;
    let options = VectoriseOptions {
        points: Some(request.points),
        ..VectoriseOptions::default()
    };
    let fitted = vectorise(&image, &options).map_err(|e| format!("the trace: {e}"))?;
    let mut mesh = fitted
        .document
        .layers
        .into_iter()
        .next()
        .ok_or("the trace made no mesh")?;
    place(&mut mesh, (image.width, image.height), request);
    mesh.name = Some("Trace".into());
    Ok(Traced {
        mesh,
        points: fitted.points,
        psnr: fitted.psnr,
    })
}

/// Refuses a rectangle that is empty or not finite, and a budget out of range.
fn check(request: &TraceRequest) -> Result<(), String> {
    let TraceRequest { x0, y0, x1, y1, .. } = *request;
    if ![x0, y0, x1, y1].iter().all(|v| v.is_finite()) || x1 <= x0 || y1 <= y0 {
        return Err(format!(
            "the rectangle to trace ({x0}, {y0}) to ({x1}, {y1}) is empty or not finite"
        ));
    }
    if !(4..=MAX_TRACE_POINTS).contains(&request.points) {
        return Err(format!(
            "the point budget must be 4 to {MAX_TRACE_POINTS}, not {}",
            request.points
        ));
    }
    Ok(())
}

/// Maps `mesh` from the picture's pixels (`0..width` x `0..height`) onto the rectangle.
fn place(mesh: &mut GradientMesh, (width, height): (u32, u32), r: &TraceRequest) {
    let sx = (r.x1 - r.x0) / f64::from(width);
    let sy = (r.y1 - r.y0) / f64::from(height);
    for point in &mut mesh.points {
        point.position.x = r.x0 + point.position.x * sx;
        point.position.y = r.y0 + point.position.y * sy;
    }
    for handle in mesh.handles.values_mut() {
        handle.x *= sx;
        handle.y *= sy;
    }
    for wedge in &mut mesh.wedges {
        for handle in wedge.handles.values_mut() {
            handle.x *= sx;
            handle.y *= sy;
        }
    }
}

/// Adds `mesh` above the document's layers, as one step of the history; its index.
pub fn add_layer(editor: &mut Editor, mesh: GradientMesh) -> Result<usize, String> {
    let mut next = editor.history.current().clone();
    next.hidden.push(false);
    next.doc.layers.push(mesh);
    let index = next.doc.layers.len() - 1;
    editor.history.replace(next)?;
    Ok(index)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A picture of `width` x `height` whose left half is red and right half blue, as PNG.
    fn halves(width: u32, height: u32) -> Vec<u8> {
        let mut pixels = Vec::new();
        for _ in 0..height {
            for x in 0..width {
                let colour = if x < width / 2 {
                    [255, 0, 0, 255]
                } else {
                    [0, 0, 255, 255]
                };
                pixels.extend_from_slice(&colour);
            }
        }
        gradmesh::render::encode_png_rgba8(width, height, &pixels).unwrap()
    }

    #[test]
    fn a_trace_covers_the_rectangle_asked_for_within_its_budget() {
        let request = TraceRequest {
            x0: 100.0,
            y0: 50.0,
            x1: 300.0,
            y1: 150.0,
            points: 30,
        };
        let traced = trace(&halves(64, 32), &request).unwrap();
        assert!(traced.points <= 30, "{} points", traced.points);
        assert_eq!(traced.mesh.points.len(), traced.points);
        let xs = traced.mesh.points.iter().map(|p| p.position.x);
        let ys = traced.mesh.points.iter().map(|p| p.position.y);
        let (min_x, max_x) = xs.fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(x), b.max(x)));
        let (min_y, max_y) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
        assert!((min_x - 100.0).abs() < 1e-6 && (max_x - 300.0).abs() < 1e-6);
        assert!((min_y - 50.0).abs() < 1e-6 && (max_y - 150.0).abs() < 1e-6);
        gradmesh::validate(&traced.mesh).unwrap();
        assert!(traced.psnr > 15.0, "{} dB", traced.psnr);
    }

    #[test]
    fn bad_requests_are_refused_with_what_is_wrong() {
        let mut request = TraceRequest {
            x0: 0.0,
            y0: 0.0,
            x1: 0.0,
            y1: 10.0,
            points: 30,
        };
        assert!(trace(&halves(8, 8), &request)
            .unwrap_err()
            .contains("empty"));
        request.x1 = 10.0;
        request.points = 2;
        assert!(trace(&halves(8, 8), &request)
            .unwrap_err()
            .contains("budget"));
        request.points = 30;
        let err = trace(b"not a picture", &request).unwrap_err();
        assert!(err.starts_with("the picture to trace"), "{err}");
    }
}
