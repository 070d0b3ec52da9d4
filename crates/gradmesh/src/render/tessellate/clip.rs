//! Clipping a layer to an outline (an SVG shape that a mesh gradient fills): the outline
//! flattened in pixels and binned into bands, for exact-area coverage with its fill rule.
//!
//! A pixel of a clipped layer is covered by the smaller of the layer's own coverage and the
//! clip's. That is the exact area of the intersection wherever, within the pixel, one region
//! holds the other: everywhere except where the two outlines cross inside the same pixel. In
//! particular it is exact where they coincide, as when a mesh was built over the box of the
//! rectangle it fills (a product of coverages would square the edge pixels there).

use kurbo::{Affine, BezPath, PathEl, Point};

use crate::render::raster::coverage::Line;
use crate::view::ToPixels;

/// Flattening tolerance of a clip outline (pixels), as for a layer's own outline.
const CLIP_TOLERANCE_PX: f64 = 0.002;

/// `path` (in the plane) in pixels, flattened into closed loops of lines: every subpath is
/// closed, and lines with a coordinate that is not finite are left out.
pub(crate) fn clip_lines(path: &BezPath, xf: &ToPixels) -> Vec<Line> {
    let to_pixels = Affine::new([xf.sx, 0.0, 0.0, xf.sy, -xf.x0 * xf.sx, -xf.y0 * xf.sy]);
    let path = to_pixels * path.clone();
    let mut lines = Vec::new();
    let (mut start, mut last): (Option<Point>, Point) = (None, Point::ZERO);
    let close = |start: &mut Option<Point>, last: Point, lines: &mut Vec<Line>| {
        if let Some(s) = start.take() {
            if s != last {
                lines.push(line(last, s));
            }
        }
    };
    kurbo::flatten(&path, CLIP_TOLERANCE_PX, |el| match el {
        PathEl::MoveTo(p) => {
            close(&mut start, last, &mut lines);
            start = Some(p);
            last = p;
        }
        PathEl::LineTo(p) => {
            if start.is_none() {
                start = Some(last);
            }
            lines.push(line(last, p));
            last = p;
        }
        PathEl::ClosePath => {
            let s = start;
            close(&mut start, last, &mut lines);
            if let Some(s) = s {
                last = s;
            }
        }
        // `flatten` gives lines only.
        PathEl::QuadTo(..) | PathEl::CurveTo(..) => {}
    });
    close(&mut start, last, &mut lines);
    lines.retain(|l| l.p0.iter().chain(&l.p1).all(|v| v.is_finite()));
    lines
}

fn line(a: Point, b: Point) -> Line {
    Line {
        p0: [a.x, a.y],
        p1: [b.x, b.y],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::View;

    /// Every subpath comes out closed, whether the path closes it or not.
    #[test]
    fn subpaths_are_closed() {
        let mut path = BezPath::new();
        path.move_to((0.0, 0.0));
        path.line_to((10.0, 0.0));
        path.line_to((10.0, 10.0));
        path.move_to((20.0, 0.0));
        path.line_to((30.0, 0.0));
        path.line_to((30.0, 10.0));
        path.close_path();
        let xf = ToPixels::new(&View::new(0.0, 0.0, 40.0, 20.0), 80, 40);
        let lines = clip_lines(&path, &xf);
        assert_eq!(lines.len(), 6);
        // Scaled by 2, and the first triangle closed back to its start.
        assert_eq!(lines[2].p0, [20.0, 20.0]);
        assert_eq!(lines[2].p1, [0.0, 0.0]);
        assert_eq!(lines[5].p1, [40.0, 0.0]);
    }
}
