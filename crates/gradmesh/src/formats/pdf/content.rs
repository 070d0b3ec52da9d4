//! A page's content streams, interpreted for what paints patch-mesh shadings: the graphics
//! state (`q`, `Q`, `cm`, `gs`), paths and clipping paths, `sh`, fills with a shading pattern,
//! and form XObjects.

use std::collections::BTreeMap;
use std::rc::Rc;

use kurbo::{Affine, BezPath, ParamCurve, Point, Rect, Shape};
use lopdf::content::Content;
use lopdf::{Dictionary, Object, ObjectId};

use super::colour::ShadingColour;
use super::objects::{invalid, number, object_name, Objects};
use super::scene::{ClipPath, Patch, ShadingFill};
use super::shading::{read_shading, ReadShading, Shading, ShadingLimits};
use crate::error::Error;
use crate::formats::svg::FillRule;

/// The deepest nesting of form XObjects.
const MAX_FORM_DEPTH: usize = 16;
/// The most `q` without `Q`.
const MAX_SAVED_STATES: usize = 256;

/// The graphics state, as far as it matters here.
#[derive(Clone)]
struct State {
    /// User space to picture units.
    ctm: Affine,
    /// Clipping paths in picture units; the clip is their intersection.
    clips: Vec<ClipPath>,
    /// `ca`.
    fill_alpha: f64,
    /// The pattern of `scn`, when the fill colour space is `Pattern`.
    fill_pattern: Option<Vec<u8>>,
    fill_is_pattern_space: bool,
    /// The soft mask (`SMask` other than `None`).
    soft_mask: Option<SoftMask>,
}

/// A soft mask of the graphics state.
#[derive(Clone)]
enum SoftMask {
    /// A luminosity mask whose group paints one grey patch-mesh shading (in picture units):
    /// the opacity of a shading of the same patches.
    Shading(Rc<ShadingFill>),
    /// Another mask, named by the graphics state that sets it: not applied.
    Other(String),
}

/// What the interpretation collects.
pub(crate) struct Interpreter<'a> {
    objects: Objects<'a>,
    limits: ShadingLimits,
    pub fills: Vec<ShadingFill>,
    /// Warnings, each once, with the number of times it occurred.
    notes: BTreeMap<String, usize>,
    /// The form XObjects being run, to refuse one that draws itself.
    forms: Vec<ObjectId>,
    /// Patches read so far.
    patches: u64,
}

impl<'a> Interpreter<'a> {
    pub fn new(objects: Objects<'a>, limits: ShadingLimits) -> Self {
        Interpreter {
            objects,
            limits,
            fills: Vec::new(),
            notes: BTreeMap::new(),
            forms: Vec::new(),
            patches: 0,
        }
    }

    /// The warnings, each with how often it occurred.
    pub fn warnings(&self) -> Vec<String> {
        self.notes
            .iter()
            .map(|(message, &n)| match n {
                1 => message.clone(),
                n => format!("{message} ({n} times)"),
            })
            .collect()
    }

    fn note(&mut self, message: impl Into<String>) {
        *self.notes.entry(message.into()).or_default() += 1;
    }

    /// Runs the content `data` (`what` names it) with `resources`, from the state `ctm` (user
    /// space to picture units), clipped by `clips`; patterns are in the space `ctm` maps.
    pub fn run(
        &mut self,
        data: &[u8],
        what: &str,
        resources: Option<&'a Dictionary>,
        ctm: Affine,
        clips: Vec<ClipPath>,
    ) -> Result<(), Error> {
        let content = Content::decode(data)
            .map_err(|e| invalid(what, format!("the content stream cannot be parsed: {e}")))?;
        let mut state = State {
            ctm,
            clips,
            fill_alpha: 1.0,
            fill_pattern: None,
            fill_is_pattern_space: false,
            soft_mask: None,
        };
        let pattern_space = ctm;
        let mut saved: Vec<State> = Vec::new();
        let mut path = BezPath::new();
        let mut pending_clip: Option<FillRule> = None;
        for op in &content.operations {
            let operands = &op.operands;
            let nums = |n: usize| -> Result<Vec<f64>, Error> {
                let label = format!("{what}: operator {}", op.operator);
                if operands.len() < n {
                    return Err(invalid(
                        label,
                        format!("needs {n} operands, has {}", operands.len()),
                    ));
                }
                operands[operands.len() - n..]
                    .iter()
                    .map(|o| number(o, &label))
                    .collect()
            };
            match op.operator.as_str() {
                "q" => {
                    if saved.len() >= MAX_SAVED_STATES {
                        return Err(invalid(
                            what,
                            format!("more than {MAX_SAVED_STATES} nested q"),
                        ));
                    }
                    saved.push(state.clone());
                }
                "Q" => {
                    if let Some(s) = saved.pop() {
                        state = s;
                    }
                }
                "cm" => {
                    let m = nums(6)?;
                    state.ctm *= Affine::new([m[0], m[1], m[2], m[3], m[4], m[5]]);
                }
                "m" | "l" | "c" | "v" | "y" | "h" | "re" => {
                    let operands = nums(operand_count(&op.operator))?;
                    build_path(&mut path, &op.operator, &operands);
                }
                "W" => pending_clip = Some(FillRule::NonZero),
                "W*" => pending_clip = Some(FillRule::EvenOdd),
                "n" | "f" | "F" | "f*" | "B" | "B*" | "b" | "b*" | "S" | "s" => {
                    let placed = state.ctm * std::mem::take(&mut path);
                    self.paint_path(
                        &op.operator,
                        &placed,
                        &state,
                        resources,
                        pattern_space,
                        what,
                    )?;
                    if let Some(rule) = pending_clip.take() {
                        state.clips.push((placed, rule));
                    }
                }
                "cs" => {
                    state.fill_is_pattern_space = operands
                        .first()
                        .and_then(|o| o.as_name().ok())
                        .is_some_and(|n| is_pattern_space(self.objects, resources, n));
                    state.fill_pattern = None;
                }
                "scn" => {
                    state.fill_pattern = operands
                        .last()
                        .and_then(|o| o.as_name().ok())
                        .map(<[u8]>::to_vec);
                }
                "g" | "rg" | "k" | "sc" => {
                    state.fill_is_pattern_space = false;
                    state.fill_pattern = None;
                }
                "gs" => self.graphics_state(&mut state, resources, operands, what)?,
                "sh" => {
                    let name = operands
                        .first()
                        .and_then(|o| o.as_name().ok())
                        .ok_or_else(|| invalid(what, "sh names no shading"))?;
                    let shading = resource(self.objects, resources, b"Shading", name, what)?;
                    let label = label_of(shading, name);
                    self.paint_shading(shading, &label, &state, state.ctm, None)?;
                }
                "Do" => {
                    let name = operands
                        .first()
                        .and_then(|o| o.as_name().ok())
                        .ok_or_else(|| invalid(what, "Do names no XObject"))?;
                    self.draw_xobject(name, resources, &state, what)?;
                }
                "BT" => self.note("text is not drawn"),
                "BI" | "EI" | "ID" => self.note("inline images are not drawn"),
                _ => {}
            }
        }
        Ok(())
    }

    /// A painting operator on `path` (in picture units): a fill with a shading pattern paints
    /// the shading inside it; the rest is counted as left out.
    fn paint_path(
        &mut self,
        operator: &str,
        path: &BezPath,
        state: &State,
        resources: Option<&'a Dictionary>,
        pattern_space: Affine,
        what: &str,
    ) -> Result<(), Error> {
        let fills = !matches!(operator, "n" | "S" | "s");
        let strokes = matches!(operator, "B" | "B*" | "b" | "b*" | "S" | "s");
        let rule = if operator.ends_with('*') {
            FillRule::EvenOdd
        } else {
            FillRule::NonZero
        };
        if fills {
            self.fill(state, resources, pattern_space, (path, rule), what)?;
        }
        if strokes {
            self.note("strokes are not drawn");
        }
        Ok(())
    }

    /// A fill of `path` (in picture units): with a shading pattern, the shading inside it.
    fn fill(
        &mut self,
        state: &State,
        resources: Option<&'a Dictionary>,
        pattern_space: Affine,
        (path, rule): (&BezPath, FillRule),
        what: &str,
    ) -> Result<(), Error> {
        let Some(name) = state
            .fill_pattern
            .as_ref()
            .filter(|_| state.fill_is_pattern_space)
        else {
            self.note("fills with a plain colour are not drawn");
            return Ok(());
        };
        let pattern_object = resource(self.objects, resources, b"Pattern", name, what)?;
        let label = label_of(pattern_object, name);
        let dict = self.objects.dict(pattern_object, &label)?;
        let kind = self
            .objects
            .get(dict, b"PatternType", &label)?
            .map(|o| self.objects.number(o, &label))
            .transpose()?;
        if kind != Some(2.0) {
            self.note(format!("{label}: tiling patterns are not drawn"));
            return Ok(());
        }
        let matrix = match self.objects.get(dict, b"Matrix", &label)? {
            Some(m) => {
                let m = self.objects.numbers(m, &format!("{label} /Matrix"))?;
                if m.len() != 6 {
                    return Err(invalid(format!("{label} /Matrix"), "expected 6 numbers"));
                }
                Affine::new([m[0], m[1], m[2], m[3], m[4], m[5]])
            }
            None => Affine::IDENTITY,
        };
        if self.objects.get(dict, b"ExtGState", &label)?.is_some() {
            self.note(format!("{label}: the pattern's ExtGState is not applied"));
        }
        let shading = self
            .objects
            .get(dict, b"Shading", &label)?
            .ok_or_else(|| invalid(&label, "the shading pattern has no Shading"))?;
        let shading_label = match dict.get(b"Shading") {
            Ok(Object::Reference(id)) => object_name(*id),
            _ => format!("the shading of {label}"),
        };
        self.paint_shading(
            shading,
            &shading_label,
            state,
            pattern_space * matrix,
            Some((path.clone(), rule)),
        )
    }

    /// Paints the shading `object` with `to_picture` (its space to picture units), clipped by
    /// the state's clip and `pattern_path`, the path filled when the shading is a pattern's;
    /// then, its `Background` first, as poppler, MuPDF and Ghostscript paint it (`sh` ignores
    /// the `Background`, as the specification says).
    fn paint_shading(
        &mut self,
        object: &'a Object,
        what: &str,
        state: &State,
        to_picture: Affine,
        pattern_path: Option<ClipPath>,
    ) -> Result<(), Error> {
        let read = match read_shading(self.objects, object, what, self.limits)? {
            Shading::Mesh(read) => *read,
            Shading::Other(kind) => {
                self.note(format!("shadings of type {kind} are not drawn ({what})"));
                return Ok(());
            }
        };
        let mut clips = state.clips.clone();
        let bbox = read.bbox.map(|b| to_picture * b.to_path(0.1));
        clips.extend(bbox.clone().map(|b| (b, FillRule::NonZero)));
        if let Some(path) = &pattern_path {
            clips.push(path.clone());
            self.paint_background(&read, what, state, clips.clone(), &path.0, bbox.as_ref())?;
        }
        let mut patches = read.patches;
        for patch in &mut patches {
            for p in patch.points.iter_mut().flatten() {
                *p = to_picture * *p;
            }
        }
        let mut fill = ShadingFill {
            object: what.to_string(),
            shading_type: read.shading_type,
            patches,
            colour: read.colour,
            clip: None,
            opacity: state.fill_alpha.clamp(0.0, 1.0),
            corner_opacity: None,
        };
        match state.soft_mask.clone() {
            Some(SoftMask::Shading(mask)) => match mask_opacity(&mask, &fill) {
                Some(opacity) => fill.corner_opacity = Some(opacity),
                None => self.note(format!(
                    "{what}: the soft mask's shading ({}) has other patches: not applied",
                    mask.object
                )),
            },
            Some(SoftMask::Other(label)) => {
                self.note(format!("{label}: the soft mask is not applied"))
            }
            None => {}
        }
        self.push_fill(fill, clips, what)
    }

    /// Paints the `Background` of the shading `read` of a pattern fill, if it has one: its
    /// colour over the filled `path` (in picture units) within the shading's `bbox`, under
    /// the same clips as the shading.
    fn paint_background(
        &mut self,
        read: &ReadShading,
        what: &str,
        state: &State,
        clips: Vec<ClipPath>,
        path: &BezPath,
        bbox: Option<&BezPath>,
    ) -> Result<(), Error> {
        let components = match &read.background {
            None => return Ok(()),
            Some(Err(why)) => {
                self.note(format!("{why}: the Background is not painted"));
                return Ok(());
            }
            Some(Ok(components)) => components,
        };
        let mut area = path.bounding_box();
        if let Some(b) = bbox {
            area = area.intersect(b.bounding_box());
        }
        if area.width() <= 0.0 || area.height() <= 0.0 {
            return Ok(());
        }
        if state.soft_mask.is_some() {
            self.note(format!(
                "{what}: the soft mask is not applied to the Background"
            ));
        }
        let fill = ShadingFill {
            object: format!("{what} /Background"),
            shading_type: 6,
            patches: vec![Patch::flat(area, components)],
            colour: ShadingColour {
                space: read.colour.space.clone(),
                function: None,
            },
            clip: None,
            opacity: state.fill_alpha.clamp(0.0, 1.0),
            corner_opacity: None,
        };
        self.push_fill(fill, clips, what)
    }

    /// Adds `fill` to the picture, within the page's patch limit, clipped by the innermost
    /// of `clips` that does not hold all of it (a warning says when more than one was left).
    fn push_fill(
        &mut self,
        mut fill: ShadingFill,
        mut clips: Vec<ClipPath>,
        what: &str,
    ) -> Result<(), Error> {
        self.patches += fill.patches.len() as u64;
        if self.patches > self.limits.patches {
            return Err(crate::error::ErrorKind::LimitExceeded {
                what: "the patches of the page".into(),
                found: self.patches,
                limit: self.limits.patches,
            }
            .into());
        }
        let bounds = fill.control_bounds();
        clips.retain(|(path, _)| !rectangle_holding(path, bounds));
        if clips.len() > 1 {
            self.note(format!(
                "{what}: {} clipping paths intersect; only the innermost is applied",
                clips.len()
            ));
        }
        fill.clip = clips.pop();
        if !fill
            .patches
            .iter()
            .flat_map(|p| p.points.iter().flatten())
            .all(|p| p.x.is_finite() && p.y.is_finite())
        {
            return Err(invalid(what, "its transformed points are not finite"));
        }
        self.fills.push(fill);
        Ok(())
    }

    /// Notes a blend mode (`BM`, a name or an array whose first name is used) other than
    /// `Normal` and `Compatible`: shadings are composited as `Normal`.
    fn note_blend_mode(&mut self, mode: &Object, label: &str) {
        let name = match mode {
            Object::Array(items) => items.first().and_then(|o| o.as_name().ok()),
            other => other.as_name().ok(),
        };
        if let Some(name) = name.filter(|n| *n != b"Normal" && *n != b"Compatible") {
            self.note(format!(
                "{label}: the blend mode {} is not applied (shadings are composited as Normal)",
                String::from_utf8_lossy(name)
            ));
        }
    }

    /// `gs`: the fill opacity and the soft mask.
    fn graphics_state(
        &mut self,
        state: &mut State,
        resources: Option<&'a Dictionary>,
        operands: &[Object],
        what: &str,
    ) -> Result<(), Error> {
        let name = operands
            .first()
            .and_then(|o| o.as_name().ok())
            .ok_or_else(|| invalid(what, "gs names no graphics state"))?;
        let object = resource(self.objects, resources, b"ExtGState", name, what)?;
        let label = label_of(object, name);
        let dict = self.objects.dict(object, &label)?;
        if let Some(ca) = self.objects.get(dict, b"ca", &label)? {
            state.fill_alpha = self.objects.number(ca, &format!("{label} /ca"))?;
        }
        if let Some(mode) = self.objects.get(dict, b"BM", &label)? {
            self.note_blend_mode(mode, &label);
        }
        if let Some(mask) = self.objects.get(dict, b"SMask", &label)? {
            state.soft_mask = match mask {
                Object::Name(n) if n == b"None" => None,
                _ => Some(self.soft_mask(mask, &label, state, resources)?),
            };
        }
        Ok(())
    }

    /// The soft mask `mask` of the graphics state `label`, set with `state`: a luminosity mask
    /// whose group paints exactly one grey patch-mesh shading is kept with that shading.
    fn soft_mask(
        &mut self,
        mask: &'a Object,
        label: &str,
        state: &State,
        resources: Option<&'a Dictionary>,
    ) -> Result<SoftMask, Error> {
        let dict = self.objects.dict(mask, label)?;
        let kind = self.objects.get(dict, b"S", label)?;
        let luminosity = kind.map(|k| self.objects.name(k, label)).transpose()?
            == Some(b"Luminosity".as_slice());
        let group = match dict.get(b"G") {
            Ok(g) if luminosity => g,
            _ => return Ok(SoftMask::Other(label.to_string())),
        };
        let mut inner = Interpreter {
            objects: self.objects,
            limits: self.limits,
            fills: Vec::new(),
            notes: BTreeMap::new(),
            forms: self.forms.clone(),
            patches: self.patches,
        };
        let plain = State {
            soft_mask: None,
            fill_alpha: 1.0,
            ..state.clone()
        };
        inner.run_form(group, &format!("{label} /SMask /G"), &plain, resources)?;
        self.patches = inner.patches;
        match inner.fills.pop() {
            Some(fill)
                if inner.fills.is_empty()
                    && fill.colour.space == super::colour::PdfColourSpace::Gray =>
            {
                Ok(SoftMask::Shading(Rc::new(fill)))
            }
            _ => Ok(SoftMask::Other(label.to_string())),
        }
    }

    /// `Do`: a form XObject is run with its matrix, resources and bounding box.
    fn draw_xobject(
        &mut self,
        name: &[u8],
        resources: Option<&'a Dictionary>,
        state: &State,
        what: &str,
    ) -> Result<(), Error> {
        let object = resource(self.objects, resources, b"XObject", name, what)?;
        let label = label_of(object, name);
        self.run_form(object, &label, state, resources)
    }

    /// Runs the form XObject `object` (`label` names it) with its matrix, resources and
    /// bounding box; an image is counted as left out.
    fn run_form(
        &mut self,
        object: &'a Object,
        label: &str,
        state: &State,
        resources: Option<&'a Dictionary>,
    ) -> Result<(), Error> {
        let label = label.to_string();
        let (resolved, id) = self.objects.resolve(object, &label)?;
        let stream = self.objects.stream(resolved, &label)?;
        let subtype = self.objects.get(&stream.dict, b"Subtype", &label)?;
        if subtype.map(|s| self.objects.name(s, &label)).transpose()? != Some(b"Form".as_slice()) {
            self.note("images are not drawn");
            return Ok(());
        }
        if let Some(id) = id {
            if self.forms.contains(&id) {
                return Err(invalid(&label, "the form draws itself"));
            }
        }
        if self.forms.len() >= MAX_FORM_DEPTH {
            return Err(invalid(
                &label,
                format!("forms nest deeper than {MAX_FORM_DEPTH}"),
            ));
        }
        let dict = &stream.dict;
        let matrix = match self.objects.get(dict, b"Matrix", &label)? {
            Some(m) => {
                let m = self.objects.numbers(m, &format!("{label} /Matrix"))?;
                if m.len() != 6 {
                    return Err(invalid(format!("{label} /Matrix"), "expected 6 numbers"));
                }
                Affine::new([m[0], m[1], m[2], m[3], m[4], m[5]])
            }
            None => Affine::IDENTITY,
        };
        let ctm = state.ctm * matrix;
        let mut clips = state.clips.clone();
        if let Some(b) = self.objects.get(dict, b"BBox", &label)? {
            let b = self.objects.numbers(b, &format!("{label} /BBox"))?;
            if b.len() == 4 {
                let rect = Rect::new(b[0], b[1], b[2], b[3]).abs();
                clips.push((ctm * rect.to_path(0.1), FillRule::NonZero));
            }
        }
        let form_resources = match self.objects.get(dict, b"Resources", &label)? {
            Some(r) => Some(self.objects.dict(r, &label)?),
            None => resources,
        };
        let data = self
            .objects
            .stream_data(stream, &label, self.limits.bytes)?;
        self.forms.push(id.unwrap_or((0, 0)));
        let result = self.run(&data, &label, form_resources, ctm, clips);
        self.forms.pop();
        result
    }
}

/// The opacity of the corners of every patch of `fill` from the grey shading `mask`, when it
/// has the same patches (corners within a millionth of the mesh's size).
fn mask_opacity(mask: &ShadingFill, fill: &ShadingFill) -> Option<Vec<[f64; 4]>> {
    if mask.patches.len() != fill.patches.len() {
        return None;
    }
    let bounds = fill.control_bounds();
    let tolerance = 1e-6 * bounds.width().max(bounds.height()).max(1.0);
    let n = mask.colour.corner_components();
    mask.patches
        .iter()
        .zip(&fill.patches)
        .map(|(m, f)| {
            let corners = [(0, 0), (0, 3), (3, 0), (3, 3)];
            let same = corners
                .iter()
                .all(|&(i, j)| m.points[i][j].distance(f.points[i][j]) <= tolerance);
            same.then(|| {
                std::array::from_fn(|c| mask.colour.to_srgb(&m.components[c * n..c * n + n])[0])
            })
        })
        .collect()
}

/// The number of operands of a path construction operator.
fn operand_count(operator: &str) -> usize {
    match operator {
        "m" | "l" => 2,
        "c" => 6,
        "v" | "y" | "re" => 4,
        _ => 0,
    }
}

/// Adds the segment of a path construction operator to `path` (in user space).
fn build_path(path: &mut BezPath, operator: &str, p: &[f64]) {
    match operator {
        "m" => path.move_to((p[0], p[1])),
        "l" => line_or_move(path, Point::new(p[0], p[1])),
        "c" => curve(path, (p[0], p[1]), (p[2], p[3]), (p[4], p[5])),
        "v" => {
            let current = current_point(path);
            curve(path, current, (p[0], p[1]), (p[2], p[3]));
        }
        "y" => curve(path, (p[0], p[1]), (p[2], p[3]), (p[2], p[3])),
        // `h` without a current point does nothing (viewers ignore it).
        "h" if !path.elements().is_empty() => path.close_path(),
        "re" => {
            path.move_to((p[0], p[1]));
            path.line_to((p[0] + p[2], p[1]));
            path.line_to((p[0] + p[2], p[1] + p[3]));
            path.line_to((p[0], p[1] + p[3]));
            path.close_path();
        }
        _ => {}
    }
}

/// A name of a resource category, in messages: its object, or `/Name`.
fn label_of(object: &Object, name: &[u8]) -> String {
    match object {
        Object::Reference(id) => object_name(*id),
        _ => format!("/{}", String::from_utf8_lossy(name)),
    }
}

/// The resource `name` of `category` (`Shading`, `Pattern`, ...).
fn resource<'a>(
    objects: Objects<'a>,
    resources: Option<&'a Dictionary>,
    category: &[u8],
    name: &[u8],
    what: &str,
) -> Result<&'a Object, Error> {
    let missing = || {
        invalid(
            what,
            format!(
                "the resources have no {} named /{}",
                String::from_utf8_lossy(category),
                String::from_utf8_lossy(name)
            ),
        )
    };
    let resources = resources.ok_or_else(missing)?;
    let dict = objects
        .get(resources, category, what)?
        .ok_or_else(missing)?;
    let dict = objects.dict(dict, what)?;
    dict.get(name).map_err(|_| missing())
}

/// Whether the colour space `name` is `Pattern` (by name, or through the resources).
fn is_pattern_space(objects: Objects, resources: Option<&Dictionary>, name: &[u8]) -> bool {
    if name == b"Pattern" {
        return true;
    }
    let Some(space) = resources
        .and_then(|r| {
            objects
                .get(r, b"ColorSpace", "the resources")
                .ok()
                .flatten()
        })
        .and_then(|d| objects.dict(d, "the resources").ok())
        .and_then(|d| d.get(name).ok())
    else {
        return false;
    };
    match objects.resolve(space, "a colour space").map(|r| r.0) {
        Ok(Object::Array(items)) => items
            .first()
            .and_then(|o| o.as_name().ok())
            .is_some_and(|n| n == b"Pattern"),
        Ok(Object::Name(n)) => n == b"Pattern",
        _ => false,
    }
}

fn current_point(path: &BezPath) -> (f64, f64) {
    let p = path
        .segments()
        .last()
        .map(|s| s.end())
        .or_else(|| match path.elements().last() {
            Some(kurbo::PathEl::MoveTo(p)) => Some(*p),
            _ => None,
        })
        .unwrap_or_default();
    (p.x, p.y)
}

fn line_or_move(path: &mut BezPath, p: Point) {
    if path.elements().is_empty() {
        path.move_to(p);
    } else {
        path.line_to(p);
    }
}

fn curve(path: &mut BezPath, a: (f64, f64), b: (f64, f64), c: (f64, f64)) {
    if path.elements().is_empty() {
        path.move_to(a);
    }
    path.curve_to(a, b, c);
}

/// Whether `path` is an axis-aligned rectangle holding `bounds` (a clip that cuts nothing
/// off).
fn rectangle_holding(path: &BezPath, bounds: Rect) -> bool {
    let b = path.bounding_box();
    let area = b.area();
    (path.area().abs() - area).abs() <= 1e-9 * area.max(1.0)
        && path
            .elements()
            .iter()
            .filter(|e| matches!(e, kurbo::PathEl::MoveTo(_)))
            .count()
            == 1
        && b.contains(bounds.origin())
        && b.x1 >= bounds.x1
        && b.y1 >= bounds.y1
}
