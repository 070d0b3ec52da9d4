//! One page's view of the picture: its canvas size and view rectangle, the renderer's cache,
//! and the last frame sent, so that only the rows that changed are sent again.

use gradmesh::render::{self, RenderCache, RenderOptions, View};
use gradmesh::Document;

/// The first bytes of every frame message.
pub const FRAME_MAGIC: &[u8; 4] = b"GMF2";

/// The largest canvas side the editor renders, in pixels.
pub const MAX_CANVAS_SIDE: u32 = 8192;

/// What a page shows: canvas size in device pixels and the rectangle of the plane.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Viewport {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The rectangle of the plane shown.
    pub view: View,
}

impl Viewport {
    /// Refuses sizes and views the renderer would refuse or that are too large for a canvas.
    pub fn check(&self) -> Result<(), String> {
        if self.width == 0 || self.height == 0 {
            return Err("the canvas has no pixels".into());
        }
        if self.width > MAX_CANVAS_SIDE || self.height > MAX_CANVAS_SIDE {
            return Err(format!(
                "the canvas is larger than {MAX_CANVAS_SIDE} pixels a side"
            ));
        }
        let opts = RenderOptions::new(self.width, self.height, self.view);
        opts.check().map_err(|e| e.to_string())
    }
}

/// The renderer's state for one page.
pub struct Viewer {
    viewport: Option<Viewport>,
    cache: RenderCache,
    /// The frame the page has (RGBA8, rows top to bottom).
    shown: Vec<u8>,
    /// The frame being drawn.
    drawn: Vec<u8>,
    frames: u32,
}

impl Default for Viewer {
    fn default() -> Self {
        Viewer::new()
    }
}

impl Viewer {
    /// A viewer with no viewport yet.
    pub fn new() -> Viewer {
        Viewer {
            viewport: None,
            cache: RenderCache::new(),
            shown: Vec::new(),
            drawn: Vec::new(),
            frames: 0,
        }
    }

    /// The viewport, once the page has set it.
    pub fn viewport(&self) -> Option<Viewport> {
        self.viewport
    }

    /// Sets the viewport (checked); a new size makes the next frame whole.
    pub fn set_viewport(&mut self, viewport: Viewport) -> Result<(), String> {
        viewport.check()?;
        let resized = self
            .viewport
            .is_none_or(|v| (v.width, v.height) != (viewport.width, viewport.height));
        if resized {
            self.shown.clear();
        }
        self.viewport = Some(viewport);
        Ok(())
    }

    /// Renders `doc` and encodes the rows that differ from the frame the page has, as a frame
    /// message (see [`decode_frame`] for its layout); `None` if nothing changed or no viewport
    /// is set. A `draft` (while a gesture is open) plans the faces the edits reach with looser
    /// tolerances ([`RenderOptions::draft`]); the next render that is not a draft draws them
    /// exactly again.
    pub fn render(&mut self, doc: &Document, draft: bool) -> Result<Option<Vec<u8>>, String> {
        let Some(vp) = self.viewport else {
            return Ok(None);
        };
        let opts = RenderOptions {
            draft,
            ..RenderOptions::new(vp.width, vp.height, vp.view)
        };
        let len = 4 * vp.width as usize * vp.height as usize;
        self.drawn.resize(len, 0);
        render::render_document_into_cached(doc, &opts, &mut self.cache, &mut self.drawn)
            .map_err(|e| e.to_string())?;
        let row = 4 * vp.width as usize;
        let runs = if self.shown.len() == len {
            changed_runs(&self.shown, &self.drawn, row)
        } else {
            vec![Run {
                first: 0,
                count: vp.height as usize,
                x: 0,
                width: vp.width as usize,
            }]
        };
        std::mem::swap(&mut self.shown, &mut self.drawn);
        if runs.is_empty() {
            return Ok(None);
        }
        self.frames = self.frames.wrapping_add(1);
        Ok(Some(encode_frame(
            self.frames,
            vp.width,
            vp.height,
            &runs,
            &self.shown,
        )))
    }

    /// The frame the page has: width, height and RGBA8 pixels.
    pub fn shown(&self) -> Option<(u32, u32, &[u8])> {
        let vp = self.viewport?;
        (self.shown.len() == 4 * vp.width as usize * vp.height as usize).then_some((
            vp.width,
            vp.height,
            &self.shown[..],
        ))
    }
}

/// A rectangle of changed pixels: rows `first..first + count`, columns `x..x + width`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    /// The first row.
    pub first: usize,
    /// How many rows.
    pub count: usize,
    /// The first column.
    pub x: usize,
    /// How many columns.
    pub width: usize,
}

/// The columns `x0..x1` where two rows of RGBA8 pixels differ, if they do.
fn changed_columns(a: &[u8], b: &[u8]) -> Option<(usize, usize)> {
    let differ = |(p, q): (&[u8], &[u8])| p != q;
    let pixels = || a.chunks_exact(4).zip(b.chunks_exact(4));
    let x0 = pixels().position(differ)?;
    let x1 = a.len() / 4 - pixels().rev().position(differ).expect("a pixel differs");
    Some((x0, x1))
}

/// Rectangles covering the pixels where `new` differs from `old` (images of rows of `row`
/// bytes), in row order. Rows closer than 8 are merged into one rectangle spanning the columns
/// of both: a rectangle's header and the page's call to draw it cost more than a few pixels
/// sent again.
pub fn changed_runs(old: &[u8], new: &[u8], row: usize) -> Vec<Run> {
    let mut runs: Vec<Run> = Vec::new();
    for (y, (a, b)) in old.chunks_exact(row).zip(new.chunks_exact(row)).enumerate() {
        let Some((x0, x1)) = changed_columns(a, b) else {
            continue;
        };
        match runs.last_mut() {
            Some(r) if y - (r.first + r.count) < 8 => {
                let (left, right) = (r.x.min(x0), (r.x + r.width).max(x1));
                *r = Run {
                    count: y + 1 - r.first,
                    x: left,
                    width: right - left,
                    ..*r
                };
            }
            _ => runs.push(Run {
                first: y,
                count: 1,
                x: x0,
                width: x1 - x0,
            }),
        }
    }
    runs
}

/// A frame message: [`FRAME_MAGIC`], then little-endian `u32`s: frame number, width, height,
/// number of runs; then each run: first row, row count, first column, column count, and the
/// RGBA8 pixels of its rectangle, row by row.
pub fn encode_frame(number: u32, width: u32, height: u32, runs: &[Run], pixels: &[u8]) -> Vec<u8> {
    let row = 4 * width as usize;
    let area: usize = runs.iter().map(|r| r.count * r.width).sum();
    let mut out = Vec::with_capacity(20 + 16 * runs.len() + 4 * area);
    out.extend_from_slice(FRAME_MAGIC);
    for v in [number, width, height, runs.len() as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for r in runs {
        for v in [r.first, r.count, r.x, r.width] {
            out.extend_from_slice(&(v as u32).to_le_bytes());
        }
        for y in r.first..r.first + r.count {
            out.extend_from_slice(&pixels[y * row + 4 * r.x..y * row + 4 * (r.x + r.width)]);
        }
    }
    out
}

/// Applies a frame message to `image` (RGBA8 of the frame's size, resized if it is not):
/// the inverse of [`encode_frame`], as the page does it. Returns the frame number.
pub fn decode_frame(message: &[u8], image: &mut Vec<u8>) -> Result<u32, String> {
    let word = |i: usize| -> Result<usize, String> {
        let bytes = message
            .get(i..i + 4)
            .ok_or("the frame message is cut short")?;
        Ok(u32::from_le_bytes(bytes.try_into().expect("four bytes")) as usize)
    };
    if message.get(..4) != Some(FRAME_MAGIC) {
        return Err("not a frame message".into());
    }
    let (number, width, height, runs) = (word(4)?, word(8)?, word(12)?, word(16)?);
    let row = 4 * width;
    image.resize(row * height, 0);
    let mut at = 20;
    for _ in 0..runs {
        let (first, count, x, columns) = (word(at)?, word(at + 4)?, word(at + 8)?, word(at + 12)?);
        at += 16;
        if x + columns > width || first + count > height {
            return Err("a run lies outside the image".into());
        }
        for y in first..first + count {
            let src = message
                .get(at..at + 4 * columns)
                .ok_or("the frame message is cut short")?;
            image[y * row + 4 * x..y * row + 4 * (x + columns)].copy_from_slice(src);
            at += 4 * columns;
        }
    }
    Ok(number as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_cover_the_changed_pixels() {
        let row = 4 * 10;
        let old = vec![0u8; row * 40];
        let mut new = old.clone();
        for (y, x) in [(3, 2), (5, 7), (30, 4)] {
            new[y * row + 4 * x + 1] = 9;
        }
        let run = |first, count, x, width| Run {
            first,
            count,
            x,
            width,
        };
        assert_eq!(
            changed_runs(&old, &new, row),
            vec![run(3, 3, 2, 6), run(30, 1, 4, 1)]
        );
        assert!(changed_runs(&old, &old, row).is_empty());
    }

    #[test]
    fn frames_round_trip() {
        let (w, h) = (6u32, 20u32);
        let pixels: Vec<u8> = (0..4 * w * h).map(|i| (i * 7 % 251) as u8).collect();
        let mut image = vec![0u8; pixels.len()];
        let runs = changed_runs(&image, &pixels, 4 * w as usize);
        let message = encode_frame(5, w, h, &runs, &pixels);
        assert_eq!(decode_frame(&message, &mut image), Ok(5));
        assert_eq!(image, pixels);

        // Two rectangles: only their pixels are sent and set.
        let mut changed = pixels.clone();
        let row = 4 * w as usize;
        changed[row + 4..row + 8].copy_from_slice(&[1, 2, 3, 4]);
        changed[15 * row + 20..15 * row + 24].copy_from_slice(&[5, 6, 7, 8]);
        let runs = changed_runs(&pixels, &changed, row);
        assert_eq!(runs.len(), 2);
        let message = encode_frame(6, w, h, &runs, &changed);
        assert_eq!(message.len(), 20 + 2 * 16 + 2 * 4);
        assert_eq!(decode_frame(&message, &mut image), Ok(6));
        assert_eq!(image, changed);
        assert!(decode_frame(&message[..30], &mut image).is_err());
        let mut outside = message.clone();
        outside[28..32].copy_from_slice(&6u32.to_le_bytes());
        assert!(decode_frame(&outside, &mut image).is_err());
    }
}
