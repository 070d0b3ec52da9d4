//! The `render` fuzz target: arbitrary meshes drawn with arbitrary options, then drawn again
//! through a [`RenderCache`] after an arbitrary edit, first as a draft, then exactly.
//!
//! It panics when the renderer misbehaves: a panic inside it, a pixel left unwritten, a channel
//! that is not finite or outside `0..=1`, a cached render that differs from a fresh one, a
//! render on one thread that differs from one on two, or an error with no message.

use std::sync::OnceLock;

use arbitrary::Arbitrary;
use gradmesh::render::{
    self, draw_outlines, BlendSpace, GamutMapping, OutputPixel, RenderCache, RenderOptions, View,
};
use gradmesh::{ColourSpace, Document, Error, GradientMesh};
use kurbo::Vec2;

use super::{check_error, colour_in, set_edge_by_slot, set_handle_by_slot, MeshDescription};

/// The most quads a fuzz render builds for one layer: keeps one input fast.
const FUZZ_MAX_QUADS: usize = 1 << 15;
/// The largest side of a reference render (the slow path).
const FUZZ_REFERENCE_SIDE: u32 = 48;

/// What part of the plane is shown.
#[derive(Arbitrary, Clone, Debug)]
pub enum ViewDescription {
    /// The document's bounds, with a margin in percent.
    Fit { margin: u8 },
    /// The fitted view scaled by 2^(zoom / 8) around a centre moved by (dx, dy) tenths of it.
    Zoom { zoom: i8, dx: i8, dy: i8 },
    /// The fitted view moved 10^exponent of its size away.
    Far { exponent: u8, dx: bool, dy: bool },
    /// Any four numbers (mostly refused: degenerate, huge, not finite).
    Raw { x0: f64, y0: f64, x1: f64, y1: f64 },
}

impl ViewDescription {
    fn view(&self, doc: &Document) -> View {
        let fit = View::fit(doc, 0.0);
        let (cx, cy) = (0.5 * (fit.x0 + fit.x1), 0.5 * (fit.y0 + fit.y1));
        let (hw, hh) = (0.5 * fit.width(), 0.5 * fit.height());
        match *self {
            ViewDescription::Fit { margin } => View::fit(doc, margin as f64 / 100.0),
            ViewDescription::Zoom { zoom, dx, dy } => {
                let s = (zoom as f64 / 8.0).exp2();
                let (cx, cy) = (cx + hw * dx as f64 / 5.0, cy + hh * dy as f64 / 5.0);
                View::new(cx - s * hw, cy - s * hh, cx + s * hw, cy + s * hh)
            }
            ViewDescription::Far { exponent, dx, dy } => {
                let d = 10f64.powi((exponent % 200) as i32) * hw.max(hh);
                let (ox, oy) = (if dx { d } else { -d }, if dy { d } else { 0.0 });
                View::new(fit.x0 + ox, fit.y0 + oy, fit.x1 + ox, fit.y1 + oy)
            }
            ViewDescription::Raw { x0, y0, x1, y1 } => View::new(x0, y0, x1, y1),
        }
    }
}

/// The channel type of the output.
#[derive(Arbitrary, Clone, Copy, Debug)]
pub enum Bits {
    Eight,
    Sixteen,
    Float,
}

/// One edit of the document between the two renders.
#[derive(Arbitrary, Clone, Debug)]
pub enum Edit {
    /// Moves a point by (dx, dy) sixty-fourths of its layer's extent.
    MovePoint {
        layer: u8,
        point: u8,
        dx: i8,
        dy: i8,
    },
    /// Sets a point's colour and opacity.
    Colour {
        layer: u8,
        point: u8,
        colour: [i8; 3],
        opacity: u8,
    },
    /// Sets a handle (see [`set_handle_by_slot`]).
    Handle {
        layer: u8,
        point: u8,
        slot: u8,
        length: u8,
        turn: i8,
    },
    /// Tags an edge (see [`set_edge_by_slot`]).
    EdgeTag {
        layer: u8,
        slot: u8,
        kind: u8,
        sharpness: u8,
    },
    /// Adds a layer on top.
    AddLayer(Box<MeshDescription>),
    /// Removes a layer.
    RemoveLayer(u8),
}

impl Edit {
    pub fn apply(&self, doc: &mut Document) {
        fn layer(doc: &mut Document, i: u8) -> Option<&mut GradientMesh> {
            let n = doc.layers.len();
            (n > 0).then(|| &mut doc.layers[i as usize % n])
        }
        let n = doc.layers.len();
        match self {
            Edit::MovePoint {
                layer: l,
                point,
                dx,
                dy,
            } => {
                let Some(mesh) = layer(doc, *l) else { return };
                let Some(step) = extent(mesh).map(|e| e / 64.0) else {
                    return;
                };
                let k = *point as usize % mesh.points.len();
                mesh.points[k].position += Vec2::new(*dx as f64, *dy as f64) * step;
            }
            Edit::Colour {
                layer: l,
                point,
                colour,
                opacity,
            } => {
                let Some(mesh) = layer(doc, *l) else { return };
                if mesh.points.is_empty() {
                    return;
                }
                let k = *point as usize % mesh.points.len();
                mesh.points[k].colour = colour_in(mesh.colour_space, *colour);
                mesh.points[k].opacity = *opacity as f64 / 255.0;
            }
            Edit::Handle {
                layer: l,
                point,
                slot,
                length,
                turn,
            } => {
                if let Some(mesh) = layer(doc, *l) {
                    set_handle_by_slot(mesh, *point, *slot, *length, *turn);
                }
            }
            Edit::EdgeTag {
                layer: l,
                slot,
                kind,
                sharpness,
            } => {
                if let Some(mesh) = layer(doc, *l) {
                    set_edge_by_slot(mesh, *slot, *kind, *sharpness);
                }
            }
            Edit::AddLayer(desc) => doc.layers.push(desc.build()),
            Edit::RemoveLayer(i) => {
                if n > 0 {
                    doc.layers.remove(*i as usize % n);
                }
            }
        }
    }
}

/// The larger side of the bounding box of a mesh's points (`None` without points).
fn extent(mesh: &GradientMesh) -> Option<f64> {
    let first = mesh.points.first()?.position;
    let bounds = mesh
        .points
        .iter()
        .fold(kurbo::Rect::from_points(first, first), |b, p| {
            b.union_pt(p.position)
        });
    Some(bounds.width().max(bounds.height()))
}

/// A document of one to three layers, render options, and an edit.
#[derive(Arbitrary, Clone, Debug)]
pub struct RenderDescription {
    pub layers: Vec<MeshDescription>,
    /// Image side minus one (1 to 256 pixels).
    pub width: u8,
    pub height: u8,
    pub view: ViewDescription,
    pub bits: Bits,
    pub dither: bool,
    pub clip_gamut: bool,
    pub blend_linear: bool,
    pub colour_space: Option<u8>,
    pub background: Option<[u8; 4]>,
    pub outline: bool,
    pub reference: bool,
    pub linear_colour: bool,
    /// A forced level, 2 to 4.
    pub level: Option<u8>,
    pub edit: Edit,
}

impl RenderDescription {
    /// The document described (at most three layers).
    pub fn document(&self) -> Document {
        Document::new(
            self.layers
                .iter()
                .take(3)
                .map(MeshDescription::build)
                .collect(),
        )
    }

    /// The options described, for `doc`.
    pub fn options(&self, doc: &Document) -> RenderOptions {
        let mut opts = RenderOptions::new(
            1 + self.width as u32,
            1 + self.height as u32,
            self.view.view(doc),
        );
        if self.reference {
            opts.width = opts.width.min(FUZZ_REFERENCE_SIDE);
            opts.height = opts.height.min(FUZZ_REFERENCE_SIDE);
        }
        opts.max_quads = FUZZ_MAX_QUADS;
        opts.dither = self.dither;
        opts.gamut = if self.clip_gamut {
            GamutMapping::Clip
        } else {
            GamutMapping::Chroma
        };
        opts.blend = if self.blend_linear {
            BlendSpace::Linear
        } else {
            BlendSpace::Srgb
        };
        opts.colour_space_override = self
            .colour_space
            .map(|c| ColourSpace::ALL[c as usize % ColourSpace::ALL.len()]);
        opts.background = self.background.map(|b| b.map(|c| c as f64 / 255.0));
        opts.reference = self.reference;
        opts.quadratic = !self.linear_colour;
        opts.level = self.level.map(|l| 2 + l as usize % 3);
        opts
    }
}

/// The thread pools of one and two threads, made once.
fn pools() -> &'static [rayon::ThreadPool; 2] {
    static POOLS: OnceLock<[rayon::ThreadPool; 2]> = OnceLock::new();
    POOLS.get_or_init(|| {
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .expect("a thread pool")
        };
        [pool(1), pool(2)]
    })
}

/// A channel type the checks can compare bit for bit, with a fill value that no render writes
/// everywhere by chance.
trait Channel: OutputPixel + Copy + PartialEq + std::fmt::Debug {
    /// Two different fills: a pixel left unwritten keeps its buffer's fill.
    const FILLS: [Self; 2];
    /// The channel as bits, for exact comparison (`f32` NaN compares by bits).
    fn bits(self) -> u32;
    /// Whether the channel is a finite value within `0..=1` once scaled.
    fn in_range(self) -> bool;
    /// Draws the outlines on top, where the type has an overlay (`f32`, as
    /// `gradmesh render --boundary` does).
    fn draw_outlines(
        _doc: &Document,
        _opts: &RenderOptions,
        _out: &mut Vec<Self>,
    ) -> Result<(), Error> {
        Ok(())
    }
}

impl Channel for u8 {
    const FILLS: [Self; 2] = [0, u8::MAX];
    fn bits(self) -> u32 {
        self as u32
    }
    fn in_range(self) -> bool {
        true
    }
}

impl Channel for u16 {
    const FILLS: [Self; 2] = [0, u16::MAX];
    fn bits(self) -> u32 {
        self as u32
    }
    fn in_range(self) -> bool {
        true
    }
}

impl Channel for f32 {
    const FILLS: [Self; 2] = [f32::NAN, -1.0];
    fn bits(self) -> u32 {
        self.to_bits()
    }
    fn in_range(self) -> bool {
        (0.0..=1.0).contains(&self)
    }
    fn draw_outlines(
        doc: &Document,
        opts: &RenderOptions,
        out: &mut Vec<Self>,
    ) -> Result<(), Error> {
        let mut image = render::Image {
            width: opts.width,
            height: opts.height,
            data: std::mem::take(out),
        };
        let drawn = draw_outlines(doc, opts, &mut image);
        *out = image.data;
        drawn
    }
}

/// One render: fresh (no cache) on one thread, or through `cache` on two, into a buffer
/// filled with the first or second fill. Outlines are drawn on top of `f32` output.
fn draw<P: Channel>(
    doc: &Document,
    opts: &RenderOptions,
    cache: Option<&mut RenderCache>,
    outline: bool,
) -> Result<Vec<P>, Error> {
    let (fill, pool) = match cache {
        None => (P::FILLS[0], &pools()[0]),
        Some(_) => (P::FILLS[1], &pools()[1]),
    };
    let mut out = vec![fill; 4 * opts.width as usize * opts.height as usize];
    pool.install(|| {
        match cache {
            None => render::render_document_into(doc, opts, &mut out),
            Some(cache) => render::render_document_into_cached(doc, opts, cache, &mut out),
        }?;
        if outline {
            P::draw_outlines(doc, opts, &mut out)?;
        }
        Ok(out)
    })
}

/// Renders `doc` fresh and through `cache`, and checks that both agree, fail alike, and give
/// every channel a value in range. Returns whether the document rendered.
fn render_both<P: Channel>(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
    outline: bool,
    what: &str,
) -> bool {
    let fresh = draw::<P>(doc, opts, None, outline);
    let cached = draw::<P>(doc, opts, Some(cache), outline);
    match (fresh, cached) {
        (Ok(a), Ok(b)) => {
            for (i, (x, y)) in a.iter().zip(&b).enumerate() {
                assert!(
                    x.bits() == y.bits(),
                    "{what}: channel {i} (pixel {}, {}) is {x:?} on one thread without a \
                     cache, {y:?} on two through the cache (or a pixel was left unwritten)",
                    i / 4 % opts.width as usize,
                    i / 4 / opts.width as usize,
                );
                assert!(x.in_range(), "{what}: channel {i} is {x:?}");
            }
            true
        }
        (Err(a), Err(b)) => {
            check_error(&a);
            assert_eq!(
                a, b,
                "{what}: the fresh and cached renders fail differently"
            );
            false
        }
        (a, b) => panic!(
            "{what}: one render failed and the other did not: fresh {:?}, cached {:?}",
            a.err(),
            b.err()
        ),
    }
}

/// Draws `doc` through `cache` as a draft ([`RenderOptions::draft`], as the editor draws a
/// gesture): a render that gives every channel a value in range, or an error with a message.
fn draft_through<P: Channel>(
    doc: &Document,
    opts: &RenderOptions,
    cache: &mut RenderCache,
    outline: bool,
) {
    let draft = RenderOptions {
        draft: true,
        ..opts.clone()
    };
    match draw::<P>(doc, &draft, Some(cache), outline) {
        Ok(pixels) => {
            for (i, x) in pixels.iter().enumerate() {
                assert!(x.in_range(), "the draft: channel {i} is {x:?}");
            }
        }
        Err(e) => check_error(&e),
    }
}

/// Draws the described document, edits it, draws the edit as a draft and then exactly through
/// the same cache (which must equal a render from scratch: the drafted faces are planned again).
pub fn render_entry(desc: &RenderDescription) {
    let doc = desc.document();
    let opts = desc.options(&doc);
    let outline = desc.outline && matches!(desc.bits, Bits::Float);
    let mut cache = RenderCache::new();
    let run = |doc: &Document, cache: &mut RenderCache, what: &str| match desc.bits {
        Bits::Eight => render_both::<u8>(doc, &opts, cache, outline, what),
        Bits::Sixteen => render_both::<u16>(doc, &opts, cache, outline, what),
        Bits::Float => render_both::<f32>(doc, &opts, cache, outline, what),
    };
    if !run(&doc, &mut cache, "first render") {
        return;
    }
    let mut edited = doc.clone();
    desc.edit.apply(&mut edited);
    match desc.bits {
        Bits::Eight => draft_through::<u8>(&edited, &opts, &mut cache, outline),
        Bits::Sixteen => draft_through::<u16>(&edited, &opts, &mut cache, outline),
        Bits::Float => draft_through::<f32>(&edited, &opts, &mut cache, outline),
    }
    run(&edited, &mut cache, "after the edit and its draft");
}

/// Decodes `data` as the render target does (arbitrary's `arbitrary_take_rest`) and runs it.
pub fn render_bytes(data: &[u8]) {
    if let Ok(desc) = RenderDescription::arbitrary_take_rest(arbitrary::Unstructured::new(data)) {
        render_entry(&desc);
    }
}
