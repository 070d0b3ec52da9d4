//! Walking an SVG document in paint order and collecting the shapes filled with mesh gradients.

use std::collections::HashMap;
use std::str::FromStr;

use kurbo::{Affine, Point, Rect, Shape};
use roxmltree::{Document, Node, ParsingOptions};

use super::attr::{self, error_at, is_svg_element, warning_at};
use super::gradient::{self, Units};
use super::mask;
use super::scene::{AspectRatio, FillRule, MeshFill, MeshGrid, SvgScene};
use super::shape;
use crate::error::{Error, ErrorKind, Location, Warning, WarningKind};
use crate::formats::check_size;
use crate::size_limits::Limits;

/// The deepest nesting of elements accepted: deeper documents are refused, so that walking
/// them needs a bounded stack.
pub const MAX_DEPTH: usize = 1024;

/// Elements that are never drawn where they stand, or draw nothing: skipped without a warning.
const NOT_DRAWN: [&str; 20] = [
    "defs",
    "symbol",
    "clipPath",
    "mask",
    "pattern",
    "marker",
    "filter",
    "linearGradient",
    "radialGradient",
    "meshgradient",
    "meshGradient",
    "mesh",
    "title",
    "desc",
    "metadata",
    "style",
    "script",
    "view",
    "cursor",
    "font-face",
];

/// Reads an SVG document within `limits`: the input size, and the number of patches over
/// all fills (against [`Limits::faces`], one face per patch) and of corners (against
/// [`Limits::points`]).
pub fn read_svg_with_limits(text: &str, limits: &Limits) -> Result<SvgScene, Error> {
    check_size(text.len() as u64, limits.input_bytes)?;
    refuse_entity_declarations(text)?;
    let options = ParsingOptions {
        allow_dtd: true,
        ..ParsingOptions::default()
    };
    let doc = Document::parse_with_options(text, options).map_err(|e| Error {
        location: Location::default().at_line(e.pos().row as usize),
        kind: ErrorKind::Syntax(format!("the file is not well-formed XML: {e}")),
    })?;
    let _lines = super::lines::LineIndex::new(&doc);
    let root = doc.root_element();
    if !is_svg_element(root, &["svg"]) {
        return Err(error_at(root, "the root element is not <svg>"));
    }
    let mut reader = Reader::new(&doc, limits);
    let mut scene = reader.viewport(root);
    let transform = attr::transform_attribute(root, "transform");
    let transform = reader.or_ignored(root, transform, Affine::IDENTITY);
    let opacity = reader.or_ignored(root, attr::own_opacity(root, "opacity"), 1.0);
    reader.walk(root, transform, opacity, 1)?;
    scene.fills = reader.fills;
    scene.warnings = reader.warnings;
    Ok(scene)
}

/// Entities are refused: they are rare in SVG and can blow up (entity expansion).
fn refuse_entity_declarations(text: &str) -> Result<(), Error> {
    match text.find("<!ENTITY") {
        Some(at) => Err(Error {
            location: Location::default().at_line(1 + text[..at].matches('\n').count()),
            kind: ErrorKind::Syntax(
                "the file declares an XML entity; entities are not read, for safety".into(),
            ),
        }),
        None => Ok(()),
    }
}

/// The state of one walk over a document.
struct Reader<'a, 'input> {
    ids: HashMap<&'a str, Node<'a, 'input>>,
    /// The rectangle percentages are measured against (the view box, or the viewport).
    percent_base: Rect,
    max_patches: u64,
    max_corners: u64,
    patches_so_far: u64,
    corners_so_far: u64,
    fills: Vec<MeshFill>,
    warnings: Vec<Warning>,
}

impl<'a, 'input> Reader<'a, 'input> {
    fn new(doc: &'a Document<'input>, limits: &Limits) -> Self {
        let mut ids = HashMap::new();
        for node in doc.descendants().filter(Node::is_element) {
            if let Some(id) = node.attribute("id") {
                ids.entry(id).or_insert(node);
            }
        }
        Reader {
            ids,
            percent_base: Rect::new(0.0, 0.0, 100.0, 100.0),
            max_patches: limits.faces,
            max_corners: limits.points,
            patches_so_far: 0,
            corners_so_far: 0,
            fills: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// The root's `viewBox`, `preserveAspectRatio`, `width` and `height` (invalid values
    /// ignored with a warning), in a scene with no fills yet; sets the base of percentages.
    fn viewport(&mut self, root: Node) -> SvgScene {
        let view_box = match root.attribute("viewBox") {
            Some(text) => match svgtypes::ViewBox::from_str(text) {
                Ok(v)
                    if [v.x, v.y, v.w, v.h].iter().all(|c| c.is_finite())
                        && v.w > 0.0
                        && v.h > 0.0 =>
                {
                    Some(Rect::new(v.x, v.y, v.x + v.w, v.y + v.h))
                }
                _ => {
                    self.warnings.push(warning_at(
                        root,
                        WarningKind::SvgReadDifferently,
                        format!("viewBox {text:?} is not a valid view box: ignored"),
                    ));
                    None
                }
            },
            None => None,
        };
        let aspect = match root.attribute("preserveAspectRatio") {
            Some(text) => match svgtypes::AspectRatio::from_str(text) {
                Ok(a) => aspect_ratio(a),
                Err(e) => {
                    self.warnings.push(warning_at(
                        root,
                        WarningKind::SvgReadDifferently,
                        format!("preserveAspectRatio {text:?} is not valid ({e}): ignored"),
                    ));
                    AspectRatio::default()
                }
            },
            None => AspectRatio::default(),
        };
        let mut absolute = |name: &str| match root.attribute(name) {
            Some(t) if !t.trim_end().ends_with('%') => {
                let length = attr::length(root, name, t, 0.0).map(Some);
                self.or_ignored(root, length, None).filter(|v| *v > 0.0)
            }
            _ => None,
        };
        let (width, height) = (absolute("width"), absolute("height"));
        let scene = SvgScene {
            view_box,
            aspect,
            width,
            height,
            fills: Vec::new(),
            warnings: Vec::new(),
        };
        let (w, h) = scene.pixel_size();
        self.percent_base = view_box.unwrap_or(Rect::new(0.0, 0.0, w, h));
        scene
    }

    /// The value read, or else `default` with a warning that the invalid attribute of `node`
    /// is ignored (as browsers and resvg ignore it).
    fn or_ignored<T>(&mut self, node: Node, read: Result<T, Error>, default: T) -> T {
        match read {
            Ok(value) => value,
            Err(e) => {
                self.warnings.push(attr::ignored(node, &e));
                default
            }
        }
    }

    /// Walks the children of `node` in paint order; `ctm` maps their user space to the root's.
    fn walk(
        &mut self,
        node: Node<'a, 'input>,
        ctm: Affine,
        opacity: f64,
        depth: usize,
    ) -> Result<(), Error> {
        for child in node.children().filter(Node::is_element) {
            if depth >= MAX_DEPTH {
                return Err(attr::limit_at(
                    child,
                    "the nesting depth of elements".into(),
                    depth as u64 + 1,
                    MAX_DEPTH as u64,
                ));
            }
            if !matches!(child.tag_name().namespace(), None | Some(attr::SVG_NS))
                || is_svg_element(child, &NOT_DRAWN)
                || attr::own_property(child, "display") == Some("none")
            {
                continue;
            }
            let transform = attr::transform_attribute(child, "transform");
            let child_ctm = ctm * self.or_ignored(child, transform, Affine::IDENTITY);
            let own_opacity = attr::own_opacity(child, "opacity");
            let child_opacity = opacity * self.or_ignored(child, own_opacity, 1.0);
            let first_fill = self.fills.len();
            match child.tag_name().name() {
                "g" | "a" | "switch" => self.walk(child, child_ctm, child_opacity, depth + 1)?,
                name if shape::SHAPES.contains(&name) => {
                    self.shape(child, child_ctm, child_opacity)?
                }
                "line" => self.warn_paint(child, "stroke"),
                _ => self.warnings.push(warning_at(
                    child,
                    WarningKind::SvgNotMeshFill,
                    "left out: only shapes filled with mesh gradients are read",
                )),
            }
            if let Some(mask) = attr::own_property(child, "mask").filter(|m| *m != "none") {
                self.mask(child, mask, child_ctm, first_fill)?;
            }
        }
        Ok(())
    }

    /// The mask `reference` of `node` (whose user space `ctm` maps to the root's), over the
    /// mesh fills read from it (`self.fills[first..]`): a mask of mesh gradients that match
    /// them patch for patch is read into their corners' opacity; any other mask over mesh fills
    /// is left out with a warning.
    fn mask(
        &mut self,
        node: Node<'a, 'input>,
        reference: &str,
        ctm: Affine,
        first: usize,
    ) -> Result<(), Error> {
        if self.fills.len() == first {
            return Ok(());
        }
        let masks = self.mask_meshes(reference, ctm)?;
        if !masks.is_some_and(|m| mask::apply_luminance_mask(&mut self.fills[first..], &m)) {
            self.warnings.push(warning_at(
                node,
                WarningKind::SvgReadDifferently,
                format!(
                    "mask {reference:?} left out: only a mask of mesh gradients matching its \
                     mesh fills patch for patch is read (gradmesh's SVG export writes a \
                     translucent layer so)"
                ),
            ));
        }
        Ok(())
    }

    /// The meshes, in root units, of the drawn children of the `<mask>` that `reference`
    /// (`url(#id)`) names in a user space `ctm` maps to the root's; `None` unless that mask
    /// exists, has user-space content, and every drawn child is a shape filled with a mesh
    /// gradient that can be read.
    fn mask_meshes(
        &mut self,
        reference: &str,
        ctm: Affine,
    ) -> Result<Option<Vec<MeshGrid>>, Error> {
        let id = match svgtypes::Paint::from_str(reference) {
            Ok(svgtypes::Paint::FuncIRI(id, _)) => id,
            _ => return Ok(None),
        };
        let Some(mask) = self.ids.get(id).copied() else {
            return Ok(None);
        };
        if !is_svg_element(mask, &["mask"])
            || mask.attribute("maskContentUnits") == Some("objectBoundingBox")
        {
            return Ok(None);
        }
        let mut grids = Vec::new();
        let drawn = mask.children().filter(|n| {
            n.is_element()
                && !is_svg_element(*n, &NOT_DRAWN)
                && attr::own_property(*n, "display") != Some("none")
        });
        for shape in drawn {
            let Some(mesh) = self.mask_mesh(shape)? else {
                return Ok(None);
            };
            grids.push(transformed(mesh, ctm));
        }
        Ok(Some(grids))
    }

    /// The mesh of a shape inside a mask, in the mask's user space; `None` unless it is a
    /// shape filled with a mesh gradient that can be read.
    fn mask_mesh(&mut self, shape: Node<'a, 'input>) -> Result<Option<MeshGrid>, Error> {
        if !is_svg_element(shape, &shape::SHAPES) {
            return Ok(None);
        }
        let fill = attr::inherited_property(shape, "fill").unwrap_or("black");
        let gradient = match svgtypes::Paint::from_str(fill) {
            Ok(svgtypes::Paint::FuncIRI(id, _)) => self.ids.get(id).copied(),
            _ => None,
        };
        let Some(gradient) = gradient.filter(|g| gradient::is_mesh_gradient(*g)) else {
            return Ok(None);
        };
        let (Ok(transform), Ok(Some(outline))) = (
            attr::transform_attribute(shape, "transform"),
            shape::outline(shape, self.percent_base),
        ) else {
            return Ok(None);
        };
        match self.mesh_for(gradient, shape, outline.bounding_box()) {
            Ok(mesh) => Ok(mesh.map(|m| transformed(m, transform))),
            Err(e) if matches!(e.kind, ErrorKind::LimitExceeded { .. }) => Err(e),
            Err(_) => Ok(None),
        }
    }

    /// A warning for a paint property that is set and not `none`.
    fn warn_paint(&mut self, node: Node, property: &str) {
        match attr::inherited_property(node, property) {
            Some("none") => {}
            None if property == "stroke" => {}
            value => {
                let value = value.unwrap_or("black");
                self.warnings.push(warning_at(
                    node,
                    WarningKind::SvgNotMeshFill,
                    format!("{property} {value:?} left out: only mesh-gradient fills are read"),
                ));
            }
        }
    }

    /// A shape: read when its fill is a mesh gradient, otherwise a warning.
    fn shape(&mut self, node: Node<'a, 'input>, ctm: Affine, opacity: f64) -> Result<(), Error> {
        self.warn_paint(node, "stroke");
        let fill = attr::inherited_property(node, "fill").unwrap_or("black");
        let gradient = match svgtypes::Paint::from_str(fill) {
            Ok(svgtypes::Paint::FuncIRI(id, _)) => self
                .ids
                .get(id)
                .copied()
                .filter(|g| gradient::is_mesh_gradient(*g)),
            Ok(svgtypes::Paint::None) => return Ok(()),
            _ => None,
        };
        let Some(gradient) = gradient else {
            self.warn_paint(node, "fill");
            return Ok(());
        };
        let outline = shape::outline(node, self.percent_base);
        let Some(outline) = self.or_ignored(node, outline, None) else {
            return Ok(());
        };
        let mesh = match self.mesh_for(gradient, node, outline.bounding_box()) {
            Ok(Some(mesh)) => mesh,
            Ok(None) => return Ok(()),
            Err(e) if matches!(e.kind, ErrorKind::LimitExceeded { .. }) => return Err(e),
            Err(e) => {
                let line = e
                    .location
                    .line
                    .map(|l| format!("line {l}: "))
                    .unwrap_or_default();
                self.warnings.push(warning_at(
                    node,
                    WarningKind::SvgMeshLeftOut,
                    format!("its mesh-gradient fill is left out: {line}{}", e.kind),
                ));
                return Ok(());
            }
        };
        let mut clip = outline;
        clip.apply_affine(ctm);
        let mesh = transformed(mesh, ctm);
        if !all_finite(&mesh, &clip) {
            return Err(error_at(
                node,
                "its mesh or outline has coordinates too large to represent",
            ));
        }
        let fill_rule = match attr::inherited_property(node, "fill-rule") {
            Some("evenodd") => FillRule::EvenOdd,
            _ => FillRule::NonZero,
        };
        let fill_opacity = match attr::inherited_property(node, "fill-opacity") {
            Some(text) => self.or_ignored(node, attr::opacity(node, "fill-opacity", text), 1.0),
            None => 1.0,
        };
        self.fills.push(MeshFill {
            shape_id: node.attribute("id").map(str::to_string),
            shape_tag: node.tag_name().name().to_string(),
            gradient_id: gradient.attribute("id").unwrap_or_default().to_string(),
            clip,
            fill_rule,
            fill_opacity,
            group_opacity: opacity,
            mesh,
        });
        Ok(())
    }

    /// The mesh of gradient `node` for a shape with bounding box `bbox`, in the shape's user
    /// space; `None` (with a warning) when bounding-box units meet a flat box.
    fn mesh_for(
        &mut self,
        node: Node<'a, 'input>,
        shape: Node,
        bbox: Rect,
    ) -> Result<Option<MeshGrid>, Error> {
        let gradient = gradient::resolve(node, &self.ids, &mut self.warnings)?;
        let (units_map, base) = match gradient.units {
            Units::UserSpaceOnUse => (Affine::IDENTITY, self.percent_base),
            Units::ObjectBoundingBox => {
                if bbox.width() <= 0.0 || bbox.height() <= 0.0 {
                    self.warnings.push(warning_at(
                        shape,
                        WarningKind::SvgMeshLeftOut,
                        "its bounding box is flat, so its objectBoundingBox mesh is not drawn",
                    ));
                    return Ok(None);
                }
                let map = Affine::new([bbox.width(), 0.0, 0.0, bbox.height(), bbox.x0, bbox.y0]);
                (map, Rect::new(0.0, 0.0, 1.0, 1.0))
            }
        };
        let coordinate = |c: Option<(Node, &str)>, name: &str, size: f64| match c {
            Some((n, text)) => attr::length(n, name, text, size),
            None => Ok(0.0),
        };
        let origin = Point::new(
            coordinate(gradient.x, "x", base.width())?,
            coordinate(gradient.y, "y", base.height())?,
        );
        let budget = self.max_patches.saturating_sub(self.patches_so_far);
        let mesh = gradient::read_grid(&gradient, origin, budget, &mut self.warnings)
            .map_err(|e| over_all_fills(e, self.patches_so_far))?;
        self.patches_so_far += (mesh.rows * mesh.columns) as u64;
        self.corners_so_far += mesh.corners.len() as u64;
        if self.corners_so_far > self.max_corners {
            return Err(attr::limit_at(
                node,
                "the number of mesh corners over all fills".into(),
                self.corners_so_far,
                self.max_corners,
            ));
        }
        Ok(Some(transformed(mesh, units_map * gradient.transform)))
    }
}

/// svgtypes' `preserveAspectRatio` as the scene records it (`defer` applies to images only).
fn aspect_ratio(a: svgtypes::AspectRatio) -> AspectRatio {
    use svgtypes::Align as A;
    let align = match a.align {
        A::None => None,
        A::XMinYMin => Some((0.0, 0.0)),
        A::XMidYMin => Some((0.5, 0.0)),
        A::XMaxYMin => Some((1.0, 0.0)),
        A::XMinYMid => Some((0.0, 0.5)),
        A::XMidYMid => Some((0.5, 0.5)),
        A::XMaxYMid => Some((1.0, 0.5)),
        A::XMinYMax => Some((0.0, 1.0)),
        A::XMidYMax => Some((0.5, 1.0)),
        A::XMaxYMax => Some((1.0, 1.0)),
    };
    AspectRatio {
        align,
        slice: a.slice,
    }
}

/// A patch-limit error counted over all fills read so far.
fn over_all_fills(mut e: Error, before: u64) -> Error {
    if let ErrorKind::LimitExceeded { what, found, limit } = &mut e.kind {
        if before > 0 {
            *what = format!("{what} over all fills");
            *found = found.saturating_add(before);
            *limit = limit.saturating_add(before);
        }
    }
    e
}

/// The mesh with every point mapped by `map`: Bézier curves map exactly under affine maps.
fn transformed(mut mesh: MeshGrid, map: Affine) -> MeshGrid {
    for corner in &mut mesh.corners {
        corner.position = map * corner.position;
    }
    for side in mesh.row_sides.iter_mut().chain(&mut mesh.column_sides) {
        *side = map * *side;
    }
    mesh
}

/// Whether every coordinate of the mesh and the outline is finite.
fn all_finite(mesh: &MeshGrid, clip: &kurbo::BezPath) -> bool {
    use kurbo::PathEl;
    let sides = mesh.row_sides.iter().chain(&mesh.column_sides);
    let outline = clip.elements().iter().flat_map(|e| match *e {
        PathEl::MoveTo(a) | PathEl::LineTo(a) => vec![a],
        PathEl::QuadTo(a, b) => vec![a, b],
        PathEl::CurveTo(a, b, c) => vec![a, b, c],
        PathEl::ClosePath => vec![],
    });
    sides
        .flat_map(|s| [s.p0, s.p1, s.p2, s.p3])
        .chain(outline)
        .all(|p| p.is_finite())
}
