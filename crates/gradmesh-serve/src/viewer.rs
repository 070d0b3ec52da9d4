//! One page's view of the picture: its canvas size and view rectangle, the renderer's cache,
//! and the last frame sent, so that only the rows that changed are sent again.

use gradmesh::render::{self, RenderCache, RenderOptions, View};
use gradmesh::Document;

/// The first bytes of every frame message.
pub const FRAME_MAGIC: &[u8; 4] = b"GMF1";

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
            vec![(0, vp.height as usize)]
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

/// Runs of rows `(first, count)` where `new` differs from `old` (images of rows of `row` bytes).
/// Runs closer than 8 rows are merged: a run's header costs more than a few rows re-sent.
pub fn changed_runs(old: &[u8], new: &[u8], row: usize) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    for (y, (a, b)) in old.chunks_exact(row).zip(new.chunks_exact(row)).enumerate() {
        if a == b {
            continue;
        }
        match runs.last_mut() {
            Some((first, count)) if y - (*first + *count) < 8 => *count = y + 1 - *first,
            _ => runs.push((y, 1)),
        }
    }
    runs
}

/// A frame message: [`FRAME_MAGIC`], then little-endian `u32`s: frame number, width, height,
/// number of runs; then each run: first row, row count, and its RGBA8 rows.
pub fn encode_frame(
    number: u32,
    width: u32,
    height: u32,
    runs: &[(usize, usize)],
    pixels: &[u8],
) -> Vec<u8> {
    let row = 4 * width as usize;
    let rows: usize = runs.iter().map(|r| r.1).sum();
    let mut out = Vec::with_capacity(20 + 8 * runs.len() + rows * row);
    out.extend_from_slice(FRAME_MAGIC);
    for v in [number, width, height, runs.len() as u32] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for &(first, count) in runs {
        out.extend_from_slice(&(first as u32).to_le_bytes());
        out.extend_from_slice(&(count as u32).to_le_bytes());
        out.extend_from_slice(&pixels[first * row..(first + count) * row]);
    }
    out
}

/// Applies a frame message to `image` (RGBA8 of the frame's size, resized if it is not):
/// the inverse of [`encode_frame`], as the page does it. Returns the frame number.
pub fn decode_frame(message: &[u8], image: &mut Vec<u8>) -> Result<u32, String> {
    let word = |i: usize| -> Result<u32, String> {
        let bytes = message
            .get(i..i + 4)
            .ok_or("the frame message is cut short")?;
        Ok(u32::from_le_bytes(bytes.try_into().expect("four bytes")))
    };
    if message.get(..4) != Some(FRAME_MAGIC) {
        return Err("not a frame message".into());
    }
    let (number, width, height, runs) = (word(4)?, word(8)?, word(12)?, word(16)?);
    let row = 4 * width as usize;
    image.resize(row * height as usize, 0);
    let mut at = 20;
    for _ in 0..runs {
        let (first, count) = (word(at)? as usize, word(at + 4)? as usize);
        at += 8;
        let bytes = count * row;
        let src = message
            .get(at..at + bytes)
            .ok_or("the frame message is cut short")?;
        image
            .get_mut(first * row..first * row + bytes)
            .ok_or("a run lies outside the image")?
            .copy_from_slice(src);
        at += bytes;
    }
    Ok(number)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_cover_the_changed_rows() {
        let row = 8;
        let old = vec![0u8; row * 40];
        let mut new = old.clone();
        for y in [3, 5, 30] {
            new[y * row + 2] = 9;
        }
        assert_eq!(changed_runs(&old, &new, row), vec![(3, 3), (30, 1)]);
        assert!(changed_runs(&old, &old, row).is_empty());
    }

    #[test]
    fn frames_round_trip() {
        let (w, h) = (3u32, 20u32);
        let pixels: Vec<u8> = (0..4 * w * h).map(|i| (i * 7 % 251) as u8).collect();
        let mut image = vec![0u8; pixels.len()];
        let runs = [(0usize, 2usize), (10, 10)];
        let message = encode_frame(5, w, h, &runs, &pixels);
        assert_eq!(decode_frame(&message, &mut image), Ok(5));
        let row = 4 * w as usize;
        assert_eq!(image[..2 * row], pixels[..2 * row]);
        assert_eq!(image[10 * row..], pixels[10 * row..]);
        assert!(image[2 * row..10 * row].iter().all(|&b| b == 0));
        assert!(decode_frame(&message[..30], &mut image).is_err());
    }
}
