//! The whole picture of an SVG file: what is not a mesh-gradient fill is drawn by resvg, and
//! the mesh fills are composited between it in paint order.
//!
//! The file's drawn elements are split at its mesh-filled shapes into segments: the elements
//! below the first mesh fill, those between two fills, those above the last. Each segment is
//! rendered by resvg from a copy of the text in which every drawn element outside the segment
//! has `display:none`, and whose root shows the render's view at the render's size. A mesh
//! shape's stroke is drawn at the start of the segment above its fill (its fill set to `none`).
//! Everything is drawn into one premultiplied canvas ([`Canvas`]): resvg draws each segment
//! into it (at 16 bits, through one reused 8-bit pixmap) and the mesh layers are composited
//! into it band by band, source-over on sRGB-encoded values (as resvg and Inkscape blend). A
//! segment that draws nothing (no element
//! but mesh shapes, and no stroke on the mesh shape it starts at) is not rendered, and the mesh
//! layers it separates are rendered together: a file of thousands of mesh-filled shapes and
//! nothing else (gradmesh's own SVG export) costs one mesh render. Each segment that draws is
//! a copy of the file parsed by resvg; above [`MAX_SEGMENT_TEXT`] bytes of such copies only
//! the mesh fills are drawn, with a warning.
//!
//! Limits: a group's `opacity`, `filter`, `mask` or `clip-path` is applied to each segment's
//! part of the group separately, not to the group as a whole, when a mesh fill splits it.

use std::collections::HashSet;
use std::ops::Range;
use std::path::Path;

use gradmesh::render::{self, LayerSource, PictureLayer, RenderOptions};
use gradmesh::{Error, ErrorKind};
use roxmltree::{Document, Node};

use crate::resvg_guard;

const SVG_NS: &str = "http://www.w3.org/2000/svg";

/// Elements never drawn where they stand, or that draw nothing: not hidden, not segments.
const NOT_DRAWN: &[&str] = &[
    "defs",
    "clipPath",
    "mask",
    "pattern",
    "marker",
    "symbol",
    "linearGradient",
    "radialGradient",
    "meshgradient",
    "meshGradient",
    "mesh",
    "filter",
    "style",
    "script",
    "title",
    "desc",
    "metadata",
];

/// Whether an element named `name` is a mesh gradient as gradmesh reads them
/// (`formats::svg`): the SVG 2 draft's `meshgradient`, Inkscape 0.91's `meshGradient`, and
/// the `mesh` of Inkscape 0.92's pre-releases.
fn is_mesh_gradient(name: &str) -> bool {
    name.eq_ignore_ascii_case("meshgradient") || name == "mesh"
}

/// The shapes gradmesh reads mesh fills from (`formats::svg`'s list).
const SHAPES: &[&str] = &["rect", "circle", "ellipse", "polygon", "polyline", "path"];

/// One text edit: `range` of the original text is replaced by `with`.
struct Edit {
    range: Range<usize>,
    with: String,
}

/// The drawn elements of a document in paint order, and which of them are mesh-filled shapes.
struct DrawnElements<'a, 'input> {
    /// The ids of the document's mesh gradients.
    mesh_ids: HashSet<&'a str>,
    elements: Vec<Node<'a, 'input>>,
    /// Indices into `elements` of the shapes whose fill is a mesh gradient, bottom first.
    mesh_shapes: Vec<usize>,
}

fn is_svg(node: Node) -> bool {
    node.is_element() && matches!(node.tag_name().namespace(), None | Some(SVG_NS))
}

/// The value of presentation property `name` set on `node` itself (its `style` wins).
fn own_property<'a>(node: Node<'a, '_>, name: &str) -> Option<&'a str> {
    let from_style = node.attribute("style").and_then(|style| {
        style.split(';').rev().find_map(|decl| {
            let (key, value) = decl.split_once(':')?;
            (key.trim() == name).then(|| value.trim())
        })
    });
    from_style.or_else(|| node.attribute(name).map(str::trim))
}

/// Whether the (inherited) fill of `node` names one of `mesh_ids`.
fn fills_with_mesh(mesh_ids: &HashSet<&str>, node: Node) -> bool {
    let Some(fill) = node.ancestors().find_map(|n| own_property(n, "fill")) else {
        return false;
    };
    let Some(id) = fill
        .strip_prefix("url(")
        .and_then(|rest| rest.split(')').next())
        .map(|iri| iri.trim().trim_matches(['"', '\'']).trim_start_matches('#'))
    else {
        return false;
    };
    mesh_ids.contains(id)
}

fn collect<'a, 'input>(node: Node<'a, 'input>, out: &mut DrawnElements<'a, 'input>) {
    for child in node.children().filter(|c| is_svg(*c)) {
        let name = child.tag_name().name();
        if NOT_DRAWN.contains(&name) || own_property(child, "display") == Some("none") {
            continue;
        }
        match name {
            "g" | "a" | "switch" => collect(child, out),
            _ => {
                if SHAPES.contains(&name) && fills_with_mesh(&out.mesh_ids, child) {
                    out.mesh_shapes.push(out.elements.len());
                }
                out.elements.push(child);
            }
        }
    }
}

impl<'a, 'input> DrawnElements<'a, 'input> {
    /// The drawn elements of `doc`.
    fn of(doc: &'a Document<'input>) -> Self {
        let mesh_ids = doc
            .descendants()
            .filter(|n| is_svg(*n) && is_mesh_gradient(n.tag_name().name()))
            .filter_map(|n| n.attribute("id"))
            .collect();
        let mut drawn = DrawnElements {
            mesh_ids,
            elements: Vec::new(),
            mesh_shapes: Vec::new(),
        };
        collect(doc.root_element(), &mut drawn);
        drawn
    }
}

/// Whether `doc` has a style sheet (whose rules are not read here).
fn has_style_sheets(doc: &Document) -> bool {
    doc.descendants()
        .any(|n| is_svg(n) && n.tag_name().name() == "style")
}

/// An edit that appends `declaration` to the `style` of `node` (adding the attribute if need be).
fn add_style(node: Node, text: &str, declaration: &str) -> Edit {
    match node.attribute_node("style") {
        Some(style) => {
            let end = style.range_value().end;
            Edit {
                range: end..end,
                with: format!(";{declaration}"),
            }
        }
        None => {
            let start = node.range().start + 1;
            let name_end = text[start..]
                .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
                .map_or(text.len(), |n| start + n);
            Edit {
                range: name_end..name_end,
                with: format!(" style=\"{declaration}\""),
            }
        }
    }
}

/// Edits of the root that make it show `opts.view` at `opts.width` x `opts.height` pixels.
fn root_view(root: Node, text: &str, opts: &RenderOptions) -> Vec<Edit> {
    let mut edits: Vec<Edit> = root
        .attributes()
        .filter(|a| {
            a.namespace().is_none()
                && ["width", "height", "viewBox", "preserveAspectRatio"].contains(&a.name())
        })
        .map(|a| Edit {
            range: a.range(),
            with: String::new(),
        })
        .collect();
    let v = opts.view;
    let start = root.range().start + 1;
    let name_end = start
        + text[start..]
            .find(|c: char| c.is_whitespace() || c == '/' || c == '>')
            .unwrap_or(0);
    edits.push(Edit {
        range: name_end..name_end,
        with: format!(
            " width=\"{}\" height=\"{}\" viewBox=\"{} {} {} {}\" preserveAspectRatio=\"none\"",
            opts.width,
            opts.height,
            v.x0,
            v.y0,
            v.width(),
            v.height()
        ),
    });
    edits
}

fn apply(text: &str, mut edits: Vec<Edit>) -> String {
    edits.sort_by_key(|e| (e.range.start, e.range.end));
    let mut out = String::with_capacity(text.len() + 32 * edits.len());
    let mut at = 0;
    for e in edits {
        out.push_str(&text[at..e.range.start]);
        out.push_str(&e.with);
        at = e.range.end;
    }
    out.push_str(&text[at..]);
    out
}

/// The most text resvg is given to parse for one picture, summed over its segments (each
/// segment is a whole copy of the file): beyond it only the mesh fills are drawn.
const MAX_SEGMENT_TEXT: usize = 1 << 30;

/// A document split at its mesh-filled shapes into segments (`fills + 1` of them, bottom
/// first): segment `s` runs from mesh shape `s - 1` (its stroke only) to below mesh shape `s`.
struct Segments<'a, 'input> {
    text: &'input str,
    drawn: DrawnElements<'a, 'input>,
    /// Whether each drawn element is a mesh-filled shape.
    is_mesh_shape: Vec<bool>,
    /// Whether each segment draws anything: an element other than a mesh shape, or the stroke
    /// of the mesh shape it starts at.
    drawing: Vec<bool>,
    /// The root's edits that show the render's view at its size.
    root: Vec<Edit>,
    /// The edits that hide the mesh-filled shapes inside masks ([`masked_mesh_shapes`]).
    masked: Vec<Edit>,
}

/// Edits hiding (`display:none`) the shapes inside `<mask>` elements whose fill is one of
/// `mesh_ids`. resvg draws no mesh gradient, so it would paint such a shape's fallback colour.
/// gradmesh reads a mask of mesh gradients into the opacity of the meshes it masks
/// (`formats::svg`), and where a mask of mesh gradients masks other content (gradmesh's SVG
/// export hides its PNG fallback from viewers that draw mesh gradients so), that content is
/// masked as by a mask that paints nothing.
fn masked_mesh_shapes(doc: &Document, text: &str, mesh_ids: &HashSet<&str>) -> Vec<Edit> {
    let is_mask = |n: Node| is_svg(n) && n.tag_name().name() == "mask";
    doc.descendants()
        .filter(|n| is_svg(*n) && SHAPES.contains(&n.tag_name().name()))
        .filter(|n| n.ancestors().skip(1).any(is_mask) && fills_with_mesh(mesh_ids, *n))
        .map(|n| add_style(n, text, "display:none"))
        .collect()
}

/// Whether `node` may be stroked: its own or an inherited `stroke` other than `none`, or any
/// style sheet in the document (whose rules are not read here).
fn may_have_stroke(node: Node, style_sheets: bool) -> bool {
    style_sheets
        || node
            .ancestors()
            .find_map(|n| own_property(n, "stroke"))
            .is_some_and(|stroke| stroke != "none")
}

impl<'a, 'input> Segments<'a, 'input> {
    /// Splits `doc` (parsed from `text`) and finds which segments draw; an error message when
    /// the file's mesh-filled shapes are not the `fills` that gradmesh read.
    fn new(
        doc: &'a Document<'input>,
        text: &'input str,
        fills: usize,
        opts: &RenderOptions,
    ) -> Result<Self, String> {
        let drawn = DrawnElements::of(doc);
        if drawn.mesh_shapes.len() != fills {
            return Err(format!(
                "{} shapes name a mesh gradient as fill, but {fills} mesh fills were read",
                drawn.mesh_shapes.len()
            ));
        }
        let mut is_mesh_shape = vec![false; drawn.elements.len()];
        for &i in &drawn.mesh_shapes {
            is_mesh_shape[i] = true;
        }
        let style_sheets = has_style_sheets(doc);
        let mut drawing = vec![false; fills + 1];
        let mut segment = 0;
        for (i, node) in drawn.elements.iter().enumerate() {
            if is_mesh_shape[i] {
                segment += 1;
                drawing[segment] |= may_have_stroke(*node, style_sheets);
            } else {
                drawing[segment] = true;
            }
        }
        let root = root_view(doc.root_element(), text, opts);
        let masked = masked_mesh_shapes(doc, text, &drawn.mesh_ids);
        Ok(Segments {
            text,
            drawn,
            is_mesh_shape,
            drawing,
            root,
            masked,
        })
    }

    /// The text of segment `s`, showing the render's view at its size.
    fn text(&self, s: usize) -> String {
        let bounds = &self.drawn.mesh_shapes;
        let start = s.checked_sub(1).map(|k| bounds[k]);
        let end = bounds.get(s).copied().unwrap_or(usize::MAX);
        let mut edits: Vec<Edit> = self
            .root
            .iter()
            .chain(&self.masked)
            .map(|e| Edit {
                range: e.range.clone(),
                with: e.with.clone(),
            })
            .collect();
        for (i, node) in self.drawn.elements.iter().enumerate() {
            let inside = start.is_none_or(|b| i >= b) && i < end;
            if Some(i) == start {
                edits.push(add_style(*node, self.text, "fill:none"));
            } else if !inside || self.is_mesh_shape[i] {
                edits.push(add_style(*node, self.text, "display:none"));
            }
        }
        apply(self.text, edits)
    }
}

/// The whole picture's memory, in bytes per pixel: the premultiplied canvas (4 bytes, or 8 at
/// 16 bits with resvg's RGBA8 segment, 4 more) and the PNG's compressed rows (at most about
/// the 8-bit image's 4 bytes; `docs/svg.md` gives the peaks measured).
pub fn bytes_per_pixel(sixteen: bool) -> u64 {
    if sixteen {
        8 + 4 + 4
    } else {
        4 + 4
    }
}

/// The memory a cell of a mesh fill drawn classically takes while the fills of one run are
/// drawn (its two triangles, its bins and its share of the fill's outline; `docs/svg.md`
/// gives the peaks measured).
const BYTES_PER_CELL: u64 = 350;

/// The memory the tessellations of `layers`, prepared together, take: their cells
/// ([`render::classic_cells`]) for SVG mesh fills drawn classically. Layers of the scheme are
/// bounded by `opts.max_quads` instead.
fn tessellation_bytes(layers: &[PictureLayer<'_>], opts: &RenderOptions) -> u64 {
    layers
        .iter()
        .map(|layer| match layer.source {
            LayerSource::Classic(fill) => render::classic_cells(fill, opts) as u64,
            _ => 0,
        })
        .sum::<u64>()
        .saturating_mul(BYTES_PER_CELL)
}

/// An error for a panic inside resvg or usvg.
fn panicked(message: String) -> Error {
    Error::new(ErrorKind::Invalid {
        what: "the rest of the picture (what is not a mesh fill)".into(),
        message: format!("resvg failed ({message}), so it could not be drawn"),
    })
}

/// Refuses `bytes` of memory over `max_memory`.
fn check_memory(bytes: u64, max_memory: u64, opts: &RenderOptions) -> Result<(), Error> {
    if bytes > max_memory {
        return Err(Error::new(ErrorKind::LimitExceeded {
            what: format!(
                "the memory the whole picture at {}x{} needs (estimated from its bytes a \
                 pixel, resvg's layers and the mesh fills' cells; see --max-memory)",
                opts.width, opts.height
            ),
            found: bytes,
            limit: max_memory,
        }));
    }
    Ok(())
}

/// Draws one segment's text with resvg onto `canvas`, after checking the buffers resvg would
/// allocate against `opts.max_pixels` and, with `base` bytes already in use, `max_memory`.
/// `Ok(Err(message))` when resvg cannot parse the text.
fn render_segment(
    text: &str,
    options: &resvg::usvg::Options,
    opts: &RenderOptions,
    (base, max_memory): (u64, u64),
    canvas: &mut Canvas,
) -> Result<Result<(), String>, Error> {
    let parsed =
        resvg_guard::catching(|| resvg::usvg::Tree::from_str(text, options)).map_err(panicked)?;
    let tree = match parsed {
        Ok(tree) => tree,
        Err(e) => return Ok(Err(e.to_string())),
    };
    let limits = resvg_guard::Canvas {
        width: opts.width,
        height: opts.height,
        max_pixels: opts.max_pixels,
    };
    let layers = resvg_guard::check_tree(&tree, &limits).map_err(|e| {
        Error::new(ErrorKind::LimitExceeded {
            what: e.what,
            found: e.found,
            limit: e.limit,
        })
    })?;
    check_memory(base.saturating_add(layers), max_memory, opts)?;
    resvg_guard::catching(|| canvas.draw_segment(&tree)).map_err(panicked)?;
    Ok(Ok(()))
}

/// resvg's options: relative links resolved against `folder` (the file's), the system's fonts, and for each generic family (and text that names no
/// font) the first of some common metric-compatible families that the system has, as the
/// defaults (Times New Roman, Arial, Courier New) are often missing on Linux.
fn resvg_options(folder: &Path) -> resvg::usvg::Options<'static> {
    let mut options = resvg::usvg::Options {
        resources_dir: Some(folder.to_path_buf()),
        ..Default::default()
    };
    let db = options.fontdb_mut();
    db.load_system_fonts();
    let installed: HashSet<String> = db
        .faces()
        .flat_map(|f| f.families.iter().map(|(name, _)| name.clone()))
        .collect();
    let first = |names: &[&str]| {
        names
            .iter()
            .find(|n| installed.contains(**n))
            .map(|n| n.to_string())
    };
    let serif = first(&[
        "Times New Roman",
        "Liberation Serif",
        "Nimbus Roman",
        "DejaVu Serif",
    ]);
    let sans = first(&["Arial", "Liberation Sans", "Nimbus Sans", "DejaVu Sans"]);
    let mono = first(&[
        "Courier New",
        "Liberation Mono",
        "Nimbus Mono PS",
        "DejaVu Sans Mono",
    ]);
    if let Some(name) = &sans {
        db.set_sans_serif_family(name.clone());
    }
    if let Some(name) = &mono {
        db.set_monospace_family(name.clone());
    }
    if let Some(name) = serif {
        db.set_serif_family(name.clone());
        options.font_family = name;
    }
    options
}

/// Warnings for the `<image>` elements of SVG `text` (read from `path`) whose file is missing:
/// relative links are resolved against the file's folder; other URLs are never fetched.
pub fn missing_images((path, text): (&Path, &str)) -> Vec<String> {
    match parse(text) {
        Ok(doc) => images_missing(&doc, path.parent().unwrap_or(Path::new("."))),
        Err(_) => Vec::new(),
    }
}

/// The XML of an SVG file, with its DTD read (entities are common in exported files).
fn parse(text: &str) -> Result<Document<'_>, roxmltree::Error> {
    Document::parse_with_options(
        text,
        roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        },
    )
}

/// The `<image>` elements of `doc` whose file is missing, links resolved against `folder`.
fn images_missing(doc: &Document, folder: &Path) -> Vec<String> {
    let mut warnings = Vec::new();
    for node in doc
        .descendants()
        .filter(|n| is_svg(*n) && n.tag_name().name() == "image")
    {
        let href = node
            .attribute(("http://www.w3.org/1999/xlink", "href"))
            .or_else(|| node.attribute("href"));
        let Some(href) = href.map(str::trim) else {
            continue;
        };
        if href.starts_with("data:") {
            continue;
        }
        let pos = doc.text_pos_at(node.range().start);
        let place = format!("<image> at {}:{}", pos.row, pos.col);
        let local = href.strip_prefix("file://").unwrap_or(href);
        if local.contains("://") {
            warnings.push(format!(
                "{place}: href {href:?} is not a local file and is never fetched: not drawn"
            ));
        } else if !folder.join(local).is_file() {
            warnings.push(format!(
                "{place}: href {href:?} names {}, which is missing: not drawn",
                folder.join(local).display()
            ));
        }
    }
    warnings
}

/// The whole picture as it is composited, premultiplied: 8-bit, the pixmap resvg draws each
/// segment straight into, or 16-bit, into which each segment is composited from one pixmap
/// that every segment reuses. Mesh layers are composited into it band by band
/// ([`render::render_picture_over`]): no other buffer of the picture's size.
enum Canvas {
    Eight(resvg::tiny_skia::Pixmap),
    Sixteen {
        canvas: Vec<u16>,
        segment: resvg::tiny_skia::Pixmap,
    },
}

/// The finished picture, straight alpha: 8-bit or 16-bit RGBA.
pub enum WholePicture {
    /// 8-bit RGBA, rows top to bottom.
    Eight(Vec<u8>),
    /// 16-bit RGBA, rows top to bottom.
    Sixteen(Vec<u16>),
}

impl Canvas {
    /// A canvas of `opts`'s size filled with `opts.background` (or clear), 16-bit when
    /// `sixteen`; `None` when tiny-skia cannot make a pixmap that size.
    fn new(opts: &RenderOptions, sixteen: bool) -> Option<Canvas> {
        let pixmap = resvg::tiny_skia::Pixmap::new(opts.width, opts.height)?;
        let bg = opts.background.map(|bg| {
            let alpha = bg[3].clamp(0.0, 1.0);
            [0, 1, 2, 3].map(|c| {
                if c == 3 {
                    alpha
                } else {
                    bg[c].clamp(0.0, 1.0) * alpha
                }
            })
        });
        if !sixteen {
            let mut pixmap = pixmap;
            if let Some(bg) = bg {
                let px = bg.map(|v| (v * 255.0).round() as u8);
                for p in pixmap.data_mut().chunks_exact_mut(4) {
                    p.copy_from_slice(&px);
                }
            }
            return Some(Canvas::Eight(pixmap));
        }
        let px = bg.unwrap_or([0.0; 4]).map(|v| (v * 65535.0).round() as u16);
        let canvas = px.repeat(opts.width as usize * opts.height as usize);
        Some(Canvas::Sixteen {
            canvas,
            segment: pixmap,
        })
    }

    /// Draws a segment parsed by resvg source-over onto the canvas.
    fn draw_segment(&mut self, tree: &resvg::usvg::Tree) {
        let identity = resvg::tiny_skia::Transform::identity();
        match self {
            Canvas::Eight(pixmap) => resvg::render(tree, identity, &mut pixmap.as_mut()),
            Canvas::Sixteen { canvas, segment } => {
                segment.fill(resvg::tiny_skia::Color::TRANSPARENT);
                resvg::render(tree, identity, &mut segment.as_mut());
                for (dst, src) in canvas
                    .chunks_exact_mut(4)
                    .zip(segment.data().chunks_exact(4))
                {
                    if src[3] == 0 {
                        continue;
                    }
                    let keep = 1.0 - f32::from(src[3]) / 255.0;
                    for c in 0..4 {
                        let v = f32::from(src[c]) * 257.0 + f32::from(dst[c]) * keep;
                        dst[c] = v.round().min(65535.0) as u16;
                    }
                }
            }
        }
    }

    /// Composites mesh layers onto the canvas.
    fn draw_meshes(
        &mut self,
        layers: &[PictureLayer<'_>],
        opts: &RenderOptions,
    ) -> Result<render::RenderInfo, Error> {
        match self {
            Canvas::Eight(pixmap) => render::render_picture_over(layers, opts, pixmap.data_mut()),
            Canvas::Sixteen { canvas, .. } => render::render_picture_over(layers, opts, canvas),
        }
    }

    /// The picture with straight alpha, in place.
    fn into_straight(self) -> WholePicture {
        match self {
            Canvas::Eight(pixmap) => {
                let mut data = pixmap.take();
                unpremultiply(&mut data, 255);
                WholePicture::Eight(data)
            }
            Canvas::Sixteen {
                mut canvas,
                segment,
            } => {
                drop(segment);
                unpremultiply(&mut canvas, 65535);
                WholePicture::Sixteen(canvas)
            }
        }
    }
}

/// Premultiplied RGBA pixels whose channels run to `max` made straight, rounding.
fn unpremultiply<T: Copy + Into<u32> + TryFrom<u32>>(data: &mut [T], max: u32) {
    for px in data.chunks_exact_mut(4) {
        let alpha: u32 = px[3].into();
        if alpha == 0 || alpha == max {
            continue;
        }
        for c in 0..3 {
            let v: u32 = px[c].into();
            let straight = ((u64::from(v) * u64::from(max) + u64::from(alpha / 2))
                / u64::from(alpha))
            .min(u64::from(max)) as u32;
            if let Ok(s) = T::try_from(straight) {
                px[c] = s;
            }
        }
    }
}

/// The whole picture of SVG `text` (read from `path`: its relative links are resolved against
/// its folder; [`missing_images`] says which images it lacks): `mesh_layers` (its mesh fills, bottom first, as gradmesh
/// read them) between the rest of its content drawn by resvg, on `opts.background`, in 8-bit
/// RGBA or, when `sixteen`, 16-bit, straight alpha. `Ok(Err(message))` when the file's content cannot be split
/// around its mesh fills or resvg cannot read it (the caller then draws the meshes alone).
/// An error when resvg panics, or when the picture's memory (estimated) is over `max_memory`
/// or a buffer resvg would allocate is over `opts.max_pixels`.
pub fn render_whole_picture(
    (path, text): (&Path, &str),
    mesh_layers: &[PictureLayer<'_>],
    opts: &RenderOptions,
    (max_memory, sixteen): (u64, bool),
) -> Result<Result<(WholePicture, render::RenderInfo), String>, Error> {
    let doc = match parse(text) {
        Ok(doc) => doc,
        Err(e) => return Ok(Err(e.to_string())),
    };
    let segments = match Segments::new(&doc, text, mesh_layers.len(), opts) {
        Ok(s) => s,
        Err(message) => return Ok(Err(message)),
    };
    let drawing = segments.drawing.iter().filter(|&&d| d).count();
    if drawing.saturating_mul(text.len()) > MAX_SEGMENT_TEXT {
        return Ok(Err(format!(
            "{drawing} parts of other content lie between its mesh fills, each drawn from a \
             copy of the file: over the limit of {MAX_SEGMENT_TEXT} bytes in all"
        )));
    }
    let pixels = u64::from(opts.width) * u64::from(opts.height);
    let base = pixels.saturating_mul(bytes_per_pixel(sixteen));
    check_memory(base, max_memory, opts)?;
    let folder = path.parent().unwrap_or(Path::new("."));
    let options = resvg_options(folder);
    let Some(mut canvas) = Canvas::new(opts, sixteen) else {
        return Ok(Err(format!(
            "resvg cannot draw a {}x{} picture",
            opts.width, opts.height
        )));
    };
    let mut info = render::RenderInfo::default();
    // Mesh layers with nothing drawn between them are composited together, in one call: the
    // layers from `run_start` wait until the next segment that draws, or the end.
    let mut run_start = 0;
    let mut draw_meshes_below = |end: usize, canvas: &mut Canvas| {
        if run_start < end {
            let run = &mesh_layers[run_start..end];
            check_memory(
                base.saturating_add(tessellation_bytes(run, opts)),
                max_memory,
                opts,
            )?;
            let drawn = canvas.draw_meshes(run, opts)?;
            merge_info(&mut info, drawn, run_start);
            run_start = end;
        }
        Ok::<(), Error>(())
    };
    for s in 0..=mesh_layers.len() {
        if segments.drawing[s] {
            draw_meshes_below(s, &mut canvas)?;
            let text = segments.text(s);
            if let Err(message) =
                render_segment(&text, &options, opts, (base, max_memory), &mut canvas)?
            {
                return Ok(Err(message));
            }
        }
    }
    draw_meshes_below(mesh_layers.len(), &mut canvas)?;
    Ok(Ok((canvas.into_straight(), info)))
}

/// Adds the report of a render of mesh layers, the first of which is layer `first` of the
/// picture, to `info`.
fn merge_info(info: &mut render::RenderInfo, drawn: render::RenderInfo, first: usize) {
    info.timings.prepare += drawn.timings.prepare;
    info.timings.draw += drawn.timings.draw;
    info.layers.extend(drawn.layers);
    info.warnings
        .extend(drawn.warnings.into_iter().map(|mut w| {
            w.layer = w.layer.map(|l| first + l);
            w
        }));
}

/// What SVG `text` (read from `path`) draws besides its mesh fills, drawn by resvg at
/// `opts.width` x `opts.height` showing `opts.view`, on a clear canvas: RGBA8 with straight
/// alpha, rows top to bottom. Every shape filled with a mesh gradient has its fill left out
/// (its stroke is drawn). `Ok(Ok(None))` when the file draws nothing but mesh fills;
/// `Ok(Err(message))` when resvg cannot read it; an error when resvg panics, or when a buffer
/// it would allocate is over `opts.max_pixels` or the memory over `max_memory`.
pub fn render_backdrop(
    (path, text): (&Path, &str),
    opts: &RenderOptions,
    max_memory: u64,
) -> Result<Result<Option<Vec<u8>>, String>, Error> {
    let doc = match parse(text) {
        Ok(doc) => doc,
        Err(e) => return Ok(Err(e.to_string())),
    };
    let drawn = DrawnElements::of(&doc);
    let style_sheets = has_style_sheets(&doc);
    let draws =
        drawn.elements.iter().enumerate().any(|(i, node)| {
            !drawn.mesh_shapes.contains(&i) || may_have_stroke(*node, style_sheets)
        });
    if !draws {
        return Ok(Ok(None));
    }
    let mut edits = root_view(doc.root_element(), text, opts);
    edits.extend(masked_mesh_shapes(&doc, text, &drawn.mesh_ids));
    for &i in &drawn.mesh_shapes {
        edits.push(add_style(drawn.elements[i], text, "fill:none"));
    }
    let mut clear = opts.clone();
    clear.background = None;
    let pixels = u64::from(opts.width) * u64::from(opts.height);
    let base = pixels.saturating_mul(bytes_per_pixel(false));
    check_memory(base, max_memory, opts)?;
    let Some(mut canvas) = Canvas::new(&clear, false) else {
        return Ok(Err(format!(
            "resvg cannot draw a {}x{} picture",
            opts.width, opts.height
        )));
    };
    let options = resvg_options(path.parent().unwrap_or(Path::new(".")));
    let text = apply(text, edits);
    if let Err(message) = render_segment(&text, &options, opts, (base, max_memory), &mut canvas)? {
        return Ok(Err(message));
    }
    match canvas.into_straight() {
        WholePicture::Eight(rgba) => Ok(Ok(Some(rgba))),
        WholePicture::Sixteen(_) => Ok(Err("an 8-bit canvas gave 16 bits".into())),
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use gradmesh::render::View;

    const PICTURE: &str = r##"<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 100 100">
      <meshgradient id="m" x="0" y="0" gradientUnits="userSpaceOnUse">
        <meshrow><meshpatch>
          <stop path="l 50,0" stop-color="#f00"/><stop path="l 0,50" stop-color="#0f0"/>
          <stop path="l -50,0" stop-color="#00f"/><stop path="l 0,-50" stop-color="#ff0"/>
        </meshpatch></meshrow>
      </meshgradient>
      <rect width="50" height="50" fill="url(#m)"/>
      <rect x="60" y="60" width="40" height="40" fill="#000000"/>
    </svg>"##;

    fn at(rgba: &[u8], width: u32, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y * width + x) as usize;
        [rgba[i], rgba[i + 1], rgba[i + 2], rgba[i + 3]]
    }

    #[test]
    fn the_backdrop_draws_the_rest_and_leaves_the_mesh_fill_out() {
        let opts = RenderOptions::new(100, 100, View::new(0.0, 0.0, 100.0, 100.0));
        let rgba = render_backdrop((Path::new("x.svg"), PICTURE), &opts, u64::MAX)
            .unwrap()
            .unwrap()
            .expect("the black square is drawn");
        assert_eq!(rgba.len(), 4 * 100 * 100);
        assert_eq!(at(&rgba, 100, 80, 80), [0, 0, 0, 255]);
        assert_eq!(at(&rgba, 100, 25, 25)[3], 0, "the mesh fill is left out");
        // The view is the render's: the square's corner moves with it.
        let shifted = RenderOptions::new(100, 100, View::new(50.0, 50.0, 150.0, 150.0));
        let rgba = render_backdrop((Path::new("x.svg"), PICTURE), &shifted, u64::MAX)
            .unwrap()
            .unwrap()
            .unwrap();
        assert_eq!(at(&rgba, 100, 20, 20), [0, 0, 0, 255]);
        assert_eq!(at(&rgba, 100, 5, 5)[3], 0);
    }

    #[test]
    fn a_file_of_mesh_fills_alone_has_no_backdrop() {
        let only_mesh = PICTURE.replace(r##"fill="#000000""##, r##"fill="url(#m)""##);
        let opts = RenderOptions::new(50, 50, View::new(0.0, 0.0, 100.0, 100.0));
        let drawn = render_backdrop((Path::new("x.svg"), &only_mesh), &opts, u64::MAX).unwrap();
        assert_eq!(drawn, Ok(None));
    }
}
