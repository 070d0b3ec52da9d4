//! The native JSON format (specified in `docs/format.md`), and the refined-mesh JSON output.
//!
//! Reading goes through serde with every field checked (unknown fields are errors). Errors carry
//! the line, and a path in words ("point 3: colour: ...") recovered by scanning the text up to the
//! position serde_json reports. Writing is done by hand so that the output is canonical: fixed
//! key order, defaults omitted, one point per line, shortest round-trip numbers.

use std::collections::{BTreeMap, HashSet};
use std::fmt;
use std::fmt::Write as _;

use kurbo::{Point, Vec2};
use serde::de::{self, Deserialize, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

use crate::colour::{parse_css_colour, ColourSpace};
use crate::error::{Error, ErrorKind, Location};
use crate::mesh::{
    edge_key, BoundaryInterpolation, ControlPoint, CreasingMethod, Document, EdgeKind, EdgeTag,
    FirstStep, GradientMesh, WedgeOverride,
};
use crate::multires::{ColourEdit, Edit, FineEdits, OpacityEdit, VertexAddress};
use crate::size_limits::Limits;
use crate::topology::Topology;
use crate::validate::VertexData;

use super::{check_count, check_size};

/// The value of `"format"` in a gradient-mesh document.
pub const FORMAT_NAME: &str = "gradmesh";

/// The value of `"format"` in a refined-mesh file written by [`write_refined`].
pub const REFINED_FORMAT_NAME: &str = "gradmesh-refined";

/// The version of the format this module reads and writes.
pub const VERSION: u64 = 1;

/// The deepest nesting of arrays and objects accepted by default (a document needs 7):
/// [`Limits::nesting_depth`].
pub const MAX_NESTING_DEPTH: usize = Limits::DEFAULT.nesting_depth;

// ---------------------------------------------------------------------------------------------
// Reading

/// Reads a document in the native format.
///
/// Errors carry the line (in [`Location::line`]) and the layer (in [`Location::layer`]), and say
/// what was expected and what was found. Beyond the syntax, the reader checks what the model
/// cannot represent or would silently merge: indices in range, no point joined to itself, no
/// repeated handle, edge or face corner, opacities in 0..=1, crease sharpness >= 0. The topology
/// (manifoldness, winding, handles along existing edges) is checked by [`crate::validate()`].
///
/// Input beyond the default [`Limits`] is refused.
pub fn read_document(text: &str) -> Result<Document, Error> {
    read_document_with_limits(text, &Limits::DEFAULT)
}

/// Reads a document in the native format as [`read_document`] does, within `limits`: input
/// bytes and nesting depth (checked before parsing), and points, faces and corners of each
/// layer (checked before the layer is converted).
pub fn read_document_with_limits(text: &str, limits: &Limits) -> Result<Document, Error> {
    check_size(text.len() as u64, limits.input_bytes)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    check_nesting(text, limits.nesting_depth)?;
    let header: Header = serde_json::from_str(text).map_err(|e| serde_error(text, e))?;
    check_header(text, &header)?;
    let raw: RawDocument = serde_json::from_str(text).map_err(|e| serde_error(text, e))?;
    let view = raw.view.map(|v| document_view(text, v.0)).transpose()?;
    let layers = raw
        .layers
        .into_iter()
        .enumerate()
        .map(|(l, layer)| convert_layer(text, l, layer, limits))
        .collect::<Result<_, _>>()?;
    Ok(Document { layers, view })
}

/// The document's `"view": [x0, y0, x1, y1]`: finite, with `x1 > x0` and `y1 > y0`.
fn document_view(text: &str, [x0, y0, x1, y1]: [f64; 4]) -> Result<kurbo::Rect, Error> {
    if [x0, y0, x1, y1].iter().all(|v| v.is_finite()) && x1 > x0 && y1 > y0 {
        return Ok(kurbo::Rect::new(x0, y0, x1, y1));
    }
    let line = text
        .find("\"view\"")
        .map_or(1, |at| text[..at].matches('\n').count() + 1);
    Err(Error::new(ErrorKind::Syntax(format!(
        "{line}: view: expected [x0, y0, x1, y1] with x1 > x0 and y1 > y0, found \
         [{x0}, {y0}, {x1}, {y1}]"
    ))))
}

/// Refuses nesting deeper than `max_depth` before serde recurses into it.
fn check_nesting(text: &str, max_depth: usize) -> Result<(), Error> {
    let (mut depth, mut line) = (0usize, 1usize);
    let (mut in_string, mut escaped) = (false, false);
    for &b in text.as_bytes() {
        if b == b'\n' {
            line += 1;
        }
        if in_string {
            match (escaped, b) {
                (true, _) => escaped = false,
                (false, b'\\') => escaped = true,
                (false, b'"') => in_string = false,
                _ => {}
            }
            continue;
        }
        match b {
            b'"' => in_string = true,
            b'[' | b'{' => {
                depth += 1;
                if depth > max_depth {
                    return Err(Error {
                        location: Location::default().at_line(line),
                        kind: ErrorKind::LimitExceeded {
                            what: "the nesting depth of arrays and objects".into(),
                            found: depth as u64,
                            limit: max_depth as u64,
                        },
                    });
                }
            }
            b']' | b'}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    Ok(())
}

/// `"format"` and `"version"`, read first so that a foreign or newer file gets a clear error
/// rather than one about its first unknown field.
struct Header {
    format: Option<serde_json::Value>,
    version: Option<serde_json::Value>,
}

impl<'de> Deserialize<'de> for Header {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Header;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an object (a gradmesh document)")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Header, A::Error> {
                let mut h = Header {
                    format: None,
                    version: None,
                };
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "format" => h.format = Some(map.next_value()?),
                        "version" => h.version = Some(map.next_value()?),
                        _ => {
                            map.next_value::<IgnoredAny>()?;
                        }
                    }
                }
                Ok(h)
            }
        }
        d.deserialize_map(V)
    }
}

fn check_header(text: &str, h: &Header) -> Result<(), Error> {
    let at = |key: &str, message: String| {
        let path = [Seg::Key(key.into())];
        Error {
            location: Location::default().at_line(line_of_path(text, &path).unwrap_or(1)),
            kind: ErrorKind::Syntax(format!("{key}: {message}")),
        }
    };
    match &h.format {
        None => {
            return Err(Error {
                location: Location::default().at_line(1),
                kind: ErrorKind::Syntax(format!(
                    "not a gradmesh document: missing \"format\": \"{FORMAT_NAME}\""
                )),
            })
        }
        Some(serde_json::Value::String(s)) if s == FORMAT_NAME => {}
        Some(serde_json::Value::String(s)) if s == REFINED_FORMAT_NAME => {
            return Err(at(
                "format",
                format!(
                "expected \"{FORMAT_NAME}\", found \"{REFINED_FORMAT_NAME}\": this is a refined \
                     mesh written by `gradmesh refine`, not an editable gradient mesh"
            ),
            ))
        }
        Some(v) => {
            return Err(at(
                "format",
                format!("expected \"{FORMAT_NAME}\" (not a gradmesh document), found {v}"),
            ))
        }
    }
    match &h.version {
        None => Err(Error {
            location: Location::default().at_line(1),
            kind: ErrorKind::Syntax(format!("missing \"version\": {VERSION}")),
        }),
        Some(v) if v.as_u64() == Some(VERSION) => Ok(()),
        Some(v) => Err(at(
            "version",
            format!("unsupported version {v}: this program reads version {VERSION}"),
        )),
    }
}

// Raw structures, as serde reads them. The struct names appear in messages ("expected a point
// object"), hence the renames.

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "document object")]
struct RawDocument {
    #[serde(rename = "format")]
    _format: IgnoredAny,
    #[serde(rename = "version")]
    _version: IgnoredAny,
    #[serde(default)]
    view: Option<Numbers<4>>,
    layers: Vec<RawLayer>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "layer object")]
struct RawLayer {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    colour_space: Option<String>,
    #[serde(default)]
    boundary: Option<String>,
    #[serde(default)]
    creasing: Option<String>,
    #[serde(default)]
    interpolate_positions: bool,
    #[serde(default)]
    first_step: Option<String>,
    points: Vec<RawPoint>,
    faces: Vec<Vec<Index>>,
    #[serde(default)]
    edges: Vec<RawEdge>,
    #[serde(default)]
    wedges: Vec<RawWedge>,
    #[serde(default)]
    fine_edits: Option<String>,
    #[serde(default)]
    edits: Vec<RawEdit>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "edit object")]
struct RawEdit {
    level: Index,
    face: Index,
    point: Index,
    at: IndexPair,
    #[serde(default)]
    colour: Option<RawColour>,
    #[serde(default)]
    colour_offset: Option<Numbers<3>>,
    #[serde(default)]
    opacity: Option<Num>,
    #[serde(default)]
    opacity_offset: Option<Num>,
    #[serde(default)]
    offset: Option<Numbers<2>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "point object")]
struct RawPoint {
    position: Numbers<2>,
    colour: RawColour,
    #[serde(default)]
    opacity: Option<Num>,
    #[serde(default)]
    corner: bool,
    #[serde(default)]
    handles: Vec<RawHandle>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "edge object")]
struct RawEdge {
    points: IndexPair,
    kind: String,
    #[serde(default)]
    sharpness: Option<Num>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields, rename = "wedge object")]
struct RawWedge {
    point: Index,
    face: Index,
    colour: RawColour,
    #[serde(default)]
    opacity: Option<Num>,
    #[serde(default)]
    handles: Vec<RawHandle>,
}

/// A JSON number.
#[derive(Clone, Copy)]
struct Num(f64);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Num;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
                Ok(Num(v))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
        }
        d.deserialize_f64(V)
    }
}

/// An index of a point or face: a whole number in `0..2^32`.
#[derive(Clone, Copy)]
struct Index(u32);

impl<'de> Deserialize<'de> for Index {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Index;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an index (a whole number from 0)")
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Index, E> {
                u32::try_from(v)
                    .map(Index)
                    .map_err(|_| E::invalid_value(de::Unexpected::Unsigned(v), &self))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Index, E> {
                match u64::try_from(v) {
                    Ok(u) => self.visit_u64(u),
                    Err(_) => Err(E::invalid_value(de::Unexpected::Signed(v), &self)),
                }
            }
        }
        d.deserialize_u64(V)
    }
}

/// Reads exactly `n` elements of a sequence, reporting the true length otherwise.
fn exact_seq<'de, A, T>(mut seq: A, n: usize, exp: &dyn de::Expected) -> Result<Vec<T>, A::Error>
where
    A: SeqAccess<'de>,
    T: Deserialize<'de>,
{
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        match seq.next_element()? {
            Some(x) => out.push(x),
            None => return Err(de::Error::invalid_length(out.len(), exp)),
        }
    }
    let mut extra = 0;
    while seq.next_element::<IgnoredAny>()?.is_some() {
        extra += 1;
    }
    if extra > 0 {
        return Err(de::Error::invalid_length(n + extra, exp));
    }
    Ok(out)
}

/// Exactly `N` numbers.
struct Numbers<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Numbers<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for V<N> {
            type Value = Numbers<N>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                write!(f, "an array of {N} numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Numbers<N>, A::Error> {
                let v: Vec<Num> = exact_seq(seq, N, &self)?;
                Ok(Numbers(std::array::from_fn(|i| v[i].0)))
            }
        }
        d.deserialize_seq(V::<N>)
    }
}

/// Exactly two point indices.
struct IndexPair([u32; 2]);

impl<'de> Deserialize<'de> for IndexPair {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = IndexPair;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an array of 2 point indices")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<IndexPair, A::Error> {
                let v: Vec<Index> = exact_seq(seq, 2, &self)?;
                Ok(IndexPair([v[0].0, v[1].0]))
            }
        }
        d.deserialize_seq(V)
    }
}

/// `[neighbour, dx, dy]`.
struct RawHandle {
    to: u32,
    offset: Vec2,
}

impl<'de> Deserialize<'de> for RawHandle {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawHandle;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a handle [neighbour index, dx, dy]")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawHandle, A::Error> {
                let missing = |n| de::Error::invalid_length(n, &self);
                let to: Index = seq.next_element()?.ok_or_else(|| missing(0))?;
                let dx: Num = seq.next_element()?.ok_or_else(|| missing(1))?;
                let dy: Num = seq.next_element()?.ok_or_else(|| missing(2))?;
                let mut extra = 0;
                while seq.next_element::<IgnoredAny>()?.is_some() {
                    extra += 1;
                }
                if extra > 0 {
                    return Err(de::Error::invalid_length(3 + extra, &self));
                }
                Ok(RawHandle {
                    to: to.0,
                    offset: Vec2::new(dx.0, dy.0),
                })
            }
        }
        d.deserialize_seq(V)
    }
}

/// A colour as written: three numbers in the layer's space, or a CSS colour string.
enum RawColour {
    Numbers([f64; 3]),
    Text(String),
}

impl<'de> Deserialize<'de> for RawColour {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = RawColour;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("3 numbers or a CSS colour string")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<RawColour, E> {
                Ok(RawColour::Text(v.to_owned()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<RawColour, A::Error> {
                let v: Vec<Num> = exact_seq(seq, 3, &self)?;
                Ok(RawColour::Numbers([v[0].0, v[1].0, v[2].0]))
            }
        }
        d.deserialize_any(V)
    }
}

/// A colour resolved in a layer's space: coordinates, kept text, and the CSS alpha (1 for
/// numbers).
fn resolve_colour(
    raw: RawColour,
    space: ColourSpace,
) -> Result<([f64; 3], Option<String>, f64), String> {
    match raw {
        RawColour::Numbers(c) => Ok((c, None, 1.0)),
        RawColour::Text(t) => match css_colour(&t, space) {
            Ok((c, _)) if c.iter().any(|x| !x.is_finite()) => Err(format!(
                "expected 3 numbers or a CSS colour string, found {}, which gives a colour that \
                 is not finite ({c:?} in {})",
                quoted(&t),
                space.name()
            )),
            Ok((c, alpha)) => Ok((c, Some(t), alpha)),
            Err(e) => Err(format!(
                "expected 3 numbers or a CSS colour string, found {} ({e})",
                quoted(&t)
            )),
        },
    }
}

/// A CSS colour in `space`, and its alpha. The CSS parser works in single precision; the alpha
/// is given back as the shortest decimal of that single-precision value, so that `80%` is 0.8.
fn css_colour(text: &str, space: ColourSpace) -> Result<([f64; 3], f64), String> {
    let (c, alpha) = parse_css_colour(text, space)?;
    let alpha = (alpha as f32).to_string().parse().unwrap_or(alpha);
    Ok((c, alpha))
}

fn quoted(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| format!("{s:?}"))
}

/// Turns the raw layer `layer` of `text` into the model, with located errors.
struct LayerReader<'a> {
    text: &'a str,
    layer: usize,
    /// Number of points in the layer.
    n: usize,
}

fn key(k: &str) -> Seg {
    Seg::Key(k.into())
}

/// `[key, index]` followed by `rest`.
fn item(k: &str, i: usize, rest: &[&str]) -> Vec<Seg> {
    let mut p = vec![key(k), Seg::Index(i)];
    p.extend(rest.iter().map(|r| key(r)));
    p
}

impl LayerReader<'_> {
    fn fail(&self, path: Vec<Seg>, message: String) -> Error {
        invalid_at(self.text, self.layer, path, message)
    }

    /// The value named `given` among `choices` (the default when absent).
    fn named<T: Copy>(
        &self,
        field: &str,
        given: Option<&str>,
        choices: &[(&str, T)],
    ) -> Result<T, Error> {
        let Some(given) = given else {
            return Ok(choices[0].1);
        };
        match choices.iter().find(|(name, _)| *name == given) {
            Some(&(_, value)) => Ok(value),
            None => {
                let names: Vec<String> = choices.iter().map(|(n, _)| format!("\"{n}\"")).collect();
                Err(self.fail(
                    vec![key(field)],
                    format!(
                        "expected one of {}, found {}",
                        names.join(", "),
                        quoted(given)
                    ),
                ))
            }
        }
    }

    fn check_point(&self, path: Vec<Seg>, point: u32) -> Result<(), Error> {
        if (point as usize) < self.n {
            Ok(())
        } else {
            Err(self.fail(
                path,
                format!("point {point} does not exist (there are {} points)", self.n),
            ))
        }
    }

    fn check_opacity(&self, path: Vec<Seg>, o: f64) -> Result<(), Error> {
        if (0.0..=1.0).contains(&o) {
            Ok(())
        } else {
            Err(self.fail(path, format!("expected a number in 0..1, found {o}")))
        }
    }

    /// The handles of `point` (listed at `base`), each towards another existing point, at most
    /// one per neighbour.
    fn handles(
        &self,
        base: &[Seg],
        point: u32,
        handles: Vec<RawHandle>,
    ) -> Result<BTreeMap<u32, Vec2>, Error> {
        let mut out = BTreeMap::new();
        for (h, handle) in handles.into_iter().enumerate() {
            let mut path = base.to_vec();
            path.extend([key("handles"), Seg::Index(h)]);
            let to = handle.to;
            if to as usize >= self.n {
                return Err(self.fail(
                    path,
                    format!(
                        "the neighbour {to} does not exist (there are {} points)",
                        self.n
                    ),
                ));
            }
            if to == point {
                return Err(self.fail(path, format!("the neighbour is the point itself ({to})")));
            }
            if out.insert(to, handle.offset).is_some() {
                return Err(self.fail(path, format!("a second handle towards point {to}")));
            }
        }
        Ok(out)
    }

    fn point(&self, p: usize, raw: RawPoint, mesh: &mut GradientMesh) -> Result<(), Error> {
        let (colour, colour_text, alpha) = resolve_colour(raw.colour, mesh.colour_space)
            .map_err(|m| self.fail(item("points", p, &["colour"]), m))?;
        // A CSS alpha stands for the opacity when none is given.
        let opacity = raw.opacity.map_or(alpha, |o| o.0);
        self.check_opacity(item("points", p, &["opacity"]), opacity)?;
        let [x, y] = raw.position.0;
        mesh.points.push(ControlPoint {
            position: Point::new(x, y),
            colour,
            opacity,
            corner: raw.corner,
            colour_text,
        });
        let handles = self.handles(&item("points", p, &[]), p as u32, raw.handles)?;
        for (to, h) in handles {
            mesh.handles.insert((p as u32, to), h);
        }
        Ok(())
    }

    fn face(&self, f: usize, raw: Vec<Index>) -> Result<Vec<u32>, Error> {
        let corners: Vec<u32> = raw.into_iter().map(|i| i.0).collect();
        for (c, &v) in corners.iter().enumerate() {
            if v as usize >= self.n {
                let mut path = item("faces", f, &[]);
                path.push(Seg::Index(c));
                return Err(error_at_path(
                    self.text,
                    self.layer,
                    &path,
                    ErrorKind::IndexOutOfRange {
                        face: f,
                        corner: c,
                        index: v as u64,
                        count: self.n,
                    },
                ));
            }
        }
        if corners.len() < 3 {
            return Err(self.fail(
                item("faces", f, &[]),
                format!(
                    "expected at least 3 corners, found {}: {corners:?}",
                    corners.len()
                ),
            ));
        }
        let mut seen = HashSet::with_capacity(corners.len());
        if let Some(v) = corners.iter().find(|&&v| !seen.insert(v)) {
            return Err(self.fail(
                item("faces", f, &[]),
                format!("point {v} appears twice: {}", short_list(&corners)),
            ));
        }
        Ok(corners)
    }

    fn edge(&self, e: usize, raw: RawEdge, mesh: &mut GradientMesh) -> Result<(), Error> {
        let [a, b] = raw.points.0;
        for v in [a, b] {
            self.check_point(item("edges", e, &["points"]), v)?;
        }
        if a == b {
            return Err(self.fail(
                item("edges", e, &["points"]),
                format!("expected two different points, found [{a}, {b}]"),
            ));
        }
        let kind = self.edge_kind(e, &raw.kind)?;
        let sharpness = match raw.sharpness {
            None => None,
            Some(_) if kind != EdgeKind::Crease => {
                return Err(self.fail(
                    item("edges", e, &["sharpness"]),
                    "only a crease has a sharpness".into(),
                ))
            }
            Some(Num(s)) if s >= 0.0 => Some(s),
            Some(Num(s)) => {
                return Err(self.fail(
                    item("edges", e, &["sharpness"]),
                    format!("expected a number >= 0, found {s}"),
                ))
            }
        };
        let k = edge_key(a, b);
        if mesh.edges.insert(k, EdgeTag { kind, sharpness }).is_some() {
            return Err(self.fail(
                item("edges", e, &[]),
                format!("a second entry for the edge {}-{}", k.0, k.1),
            ));
        }
        Ok(())
    }

    fn edge_kind(&self, e: usize, kind: &str) -> Result<EdgeKind, Error> {
        match kind {
            "crease" => Ok(EdgeKind::Crease),
            "discontinuous" => Ok(EdgeKind::Discontinuous),
            other => Err(self.fail(
                item("edges", e, &["kind"]),
                format!(
                    "expected one of \"crease\", \"discontinuous\", found {}",
                    quoted(other)
                ),
            )),
        }
    }

    fn wedge(
        &self,
        w: usize,
        raw: RawWedge,
        mesh: &GradientMesh,
        corners_of: &HashSet<(u32, u32)>,
    ) -> Result<WedgeOverride, Error> {
        let (point, face) = (raw.point.0, raw.face.0);
        self.check_point(item("wedges", w, &["point"]), point)?;
        let Some(corners) = mesh.faces.get(face as usize) else {
            return Err(self.fail(
                item("wedges", w, &["face"]),
                format!(
                    "face {face} does not exist (there are {} faces)",
                    mesh.faces.len()
                ),
            ));
        };
        if !corners_of.contains(&(point, face)) {
            return Err(self.fail(
                item("wedges", w, &["face"]),
                format!(
                    "face {face} {} does not contain point {point}",
                    short_list(corners)
                ),
            ));
        }
        let (colour, colour_text, alpha) = resolve_colour(raw.colour, mesh.colour_space)
            .map_err(|m| self.fail(item("wedges", w, &["colour"]), m))?;
        // A CSS alpha below 1 stands for the opacity when none is given; else the point's holds.
        let opacity = match raw.opacity {
            Some(Num(o)) => Some(o),
            None if alpha < 1.0 => Some(alpha),
            None => None,
        };
        if let Some(o) = opacity {
            self.check_opacity(item("wedges", w, &["opacity"]), o)?;
        }
        let handles = self.handles(&item("wedges", w, &[]), point, raw.handles)?;
        Ok(WedgeOverride {
            point,
            face,
            colour,
            colour_text,
            opacity,
            handles,
        })
    }
}

impl LayerReader<'_> {
    fn edit(&self, i: usize, raw: RawEdit, space: ColourSpace) -> Result<Edit, Error> {
        let at = |field: &str| item("edits", i, &[field]);
        let both = |a: &str, b: &str| {
            self.fail(
                item("edits", i, &[]),
                format!("give \"{a}\" (absolute) or \"{b}\" (relative), not both"),
            )
        };
        let colour = match (raw.colour, raw.colour_offset) {
            (Some(_), Some(_)) => return Err(both("colour", "colour_offset")),
            (Some(c), None) => {
                let (c, _, alpha) =
                    resolve_colour(c, space).map_err(|m| self.fail(at("colour"), m))?;
                if alpha < 1.0 {
                    return Err(self.fail(
                        at("colour"),
                        "a colour with alpha: give the opacity in \"opacity\"".into(),
                    ));
                }
                Some(ColourEdit::Set(c))
            }
            (None, Some(d)) => Some(ColourEdit::Offset(d.0)),
            (None, None) => None,
        };
        let opacity = match (raw.opacity, raw.opacity_offset) {
            (Some(_), Some(_)) => return Err(both("opacity", "opacity_offset")),
            (Some(Num(o)), None) => {
                self.check_opacity(at("opacity"), o)?;
                Some(OpacityEdit::Set(o))
            }
            (None, Some(Num(d))) => Some(OpacityEdit::Offset(d)),
            (None, None) => None,
        };
        Ok(Edit {
            address: VertexAddress::new(raw.level.0, raw.face.0, raw.point.0, raw.at.0),
            colour,
            opacity,
            offset: raw.offset.map(|o| Vec2::new(o.0[0], o.0[1])),
        })
    }
}

/// A list of indices for a message: whole when short, else its start and its length.
fn short_list(items: &[u32]) -> String {
    const SHOWN: usize = 12;
    if items.len() <= SHOWN {
        format!("{items:?}")
    } else {
        let head: Vec<String> = items[..SHOWN].iter().map(u32::to_string).collect();
        format!("[{}, ... ({} in all)]", head.join(", "), items.len())
    }
}

fn convert_layer(
    text: &str,
    layer: usize,
    raw: RawLayer,
    limits: &Limits,
) -> Result<GradientMesh, Error> {
    let reader = LayerReader {
        text,
        layer,
        n: raw.points.len(),
    };
    let spaces = ColourSpace::ALL.map(|c| (c.name(), c));
    let boundaries = [
        BoundaryInterpolation::EdgeAndCorner,
        BoundaryInterpolation::EdgeOnly,
    ]
    .map(|b| (b.name(), b));
    let creasings = [CreasingMethod::Uniform, CreasingMethod::Chaikin].map(|c| (c.name(), c));
    let first_steps = [FirstStep::Ternary, FirstStep::Binary].map(|s| (s.name(), s));
    let fine = [FineEdits::ColourAndPosition, FineEdits::ColourOnly].map(|f| (f.name(), f));

    let limit = |e: Error, field: &str| {
        let path = item("layers", layer, &[field]);
        Error {
            location: Location {
                line: line_of_path(text, &path),
                layer: Some(layer),
                ..Location::default()
            },
            ..e
        }
    };
    check_count(
        "the number of points",
        raw.points.len() as u64,
        limits.points,
    )
    .map_err(|e| limit(e, "points"))?;
    check_count("the number of faces", raw.faces.len() as u64, limits.faces)
        .map_err(|e| limit(e, "faces"))?;
    let corners = raw.faces.iter().map(|f| f.len() as u64).sum();
    check_count("the number of corners", corners, limits.corners).map_err(|e| limit(e, "faces"))?;
    check_count("the number of edits", raw.edits.len() as u64, limits.points)
        .map_err(|e| limit(e, "edits"))?;

    let mut mesh = GradientMesh {
        name: raw.name,
        colour_space: reader.named("colour_space", raw.colour_space.as_deref(), &spaces)?,
        boundary: reader.named("boundary", raw.boundary.as_deref(), &boundaries)?,
        creasing: reader.named("creasing", raw.creasing.as_deref(), &creasings)?,
        interpolate_positions: raw.interpolate_positions,
        first_step: reader.named("first_step", raw.first_step.as_deref(), &first_steps)?,
        fine_edits: reader.named("fine_edits", raw.fine_edits.as_deref(), &fine)?,
        points: Vec::with_capacity(raw.points.len()),
        faces: Vec::with_capacity(raw.faces.len()),
        ..GradientMesh::default()
    };
    for (p, point) in raw.points.into_iter().enumerate() {
        reader.point(p, point, &mut mesh)?;
    }
    for (f, face) in raw.faces.into_iter().enumerate() {
        let corners = reader.face(f, face)?;
        mesh.faces.push(corners);
    }
    for (e, edge) in raw.edges.into_iter().enumerate() {
        reader.edge(e, edge, &mut mesh)?;
    }
    // (point, face) of every corner, built only when there are wedge entries to check.
    let mut corners_of = HashSet::new();
    if !raw.wedges.is_empty() {
        for (f, face) in mesh.faces.iter().enumerate() {
            corners_of.extend(face.iter().map(|&p| (p, f as u32)));
        }
    }
    for (w, wedge) in raw.wedges.into_iter().enumerate() {
        let wedge = reader.wedge(w, wedge, &mesh, &corners_of)?;
        mesh.wedges.push(wedge);
    }
    for (i, edit) in raw.edits.into_iter().enumerate() {
        let edit = reader.edit(i, edit, mesh.colour_space)?;
        mesh.edits.push(edit);
    }
    Ok(mesh)
}

// ---------------------------------------------------------------------------------------------
// Locating errors: paths into the document, recovered from the text

/// One step of a path into a JSON document.
#[derive(Clone, Debug, PartialEq)]
enum Seg {
    Key(String),
    Index(usize),
}

/// An open array or object while scanning.
struct Frame {
    array: bool,
    /// Element index in an array.
    index: usize,
    /// Current key in an object (none between a comma and the next key).
    key: Option<String>,
}

fn frames_path(frames: &[Frame]) -> Vec<Seg> {
    frames
        .iter()
        .filter_map(|f| {
            if f.array {
                Some(Seg::Index(f.index))
            } else {
                f.key.clone().map(Seg::Key)
            }
        })
        .collect()
}

/// Offset just past the string that starts (with its quote) at `start`.
fn string_end(b: &[u8], start: usize) -> usize {
    let mut j = start + 1;
    while j < b.len() {
        match b[j] {
            b'\\' => j += 2,
            b'"' => return j + 1,
            _ => j += 1,
        }
    }
    b.len()
}

/// Scans `text` up to `end`, calling `at_value(frames, offset)` where each value starts; stops
/// when it returns true. Returns the containers open at the stop. The text before `end` is
/// assumed to be mostly well-formed JSON (serde_json has read it that far).
fn scan(text: &str, end: usize, mut at_value: impl FnMut(&[Frame], usize) -> bool) -> Vec<Frame> {
    let b = text.as_bytes();
    let end = end.min(b.len());
    let mut stack: Vec<Frame> = Vec::new();
    let mut expect_key = false;
    let mut i = 0;
    while i < end {
        let c = b[i];
        match c {
            b' ' | b'\t' | b'\n' | b'\r' | b':' => {
                i += 1;
                continue;
            }
            b',' => {
                if let Some(f) = stack.last_mut() {
                    if f.array {
                        f.index += 1;
                    } else {
                        f.key = None;
                        expect_key = true;
                    }
                }
                i += 1;
                continue;
            }
            b'}' | b']' => {
                stack.pop();
                expect_key = false;
                i += 1;
                continue;
            }
            _ => {}
        }
        if expect_key && c == b'"' {
            let close = string_end(b, i);
            let key = text.get(i + 1..close.saturating_sub(1)).unwrap_or("");
            if let Some(f) = stack.last_mut() {
                f.key = Some(key.to_owned());
            }
            expect_key = false;
            i = close;
            continue;
        }
        if at_value(&stack, i) {
            return stack;
        }
        match c {
            b'{' => {
                stack.push(Frame {
                    array: false,
                    index: 0,
                    key: None,
                });
                expect_key = true;
                i += 1;
            }
            b'[' => {
                stack.push(Frame {
                    array: true,
                    index: 0,
                    key: None,
                });
                i += 1;
            }
            b'"' => i = string_end(b, i),
            _ => {
                i += 1;
                while i < b.len()
                    && !matches!(b[i], b',' | b'}' | b']' | b' ' | b'\t' | b'\n' | b'\r')
                {
                    i += 1;
                }
            }
        }
    }
    stack
}

/// The path open at byte `offset`.
fn path_at(text: &str, offset: usize) -> Vec<Seg> {
    frames_path(&scan(text, offset, |_, _| false))
}

/// The line (1-based) where the value at `path` starts.
fn line_of_path(text: &str, path: &[Seg]) -> Option<usize> {
    let mut found = None;
    scan(text, text.len(), |frames, offset| {
        if frames_path(frames) == path {
            found = Some(offset);
            true
        } else {
            false
        }
    });
    found.map(|o| line_of_offset(text, o))
}

fn line_of_offset(text: &str, offset: usize) -> usize {
    1 + text.as_bytes()[..offset.min(text.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// The byte offset of serde_json's (line, column): column counts the bytes read on that line.
fn offset_of_line_column(text: &str, line: usize, column: usize) -> usize {
    let start: usize = text
        .split_inclusive('\n')
        .take(line.saturating_sub(1))
        .map(str::len)
        .sum();
    (start + column).min(text.len())
}

/// Splits a path into its layer and a description of the rest ("point 3, handle 1: colour").
fn describe(path: &[Seg]) -> (Option<usize>, String) {
    let (layer, rest) = match path {
        [Seg::Key(k), Seg::Index(i), rest @ ..] if k == "layers" => (Some(*i), rest),
        _ => (None, path),
    };
    let singular = |k: &str| match k {
        "layers" => Some("layer"),
        "points" => Some("point"),
        "faces" => Some("face"),
        "edges" => Some("edge entry"),
        "wedges" => Some("wedge"),
        "edits" => Some("edit"),
        "handles" => Some("handle"),
        _ => None,
    };
    let mut out = String::new();
    let mut last_was_item = false;
    let mut j = 0;
    while j < rest.len() {
        match (&rest[j], rest.get(j + 1)) {
            (Seg::Key(k), Some(Seg::Index(i))) if singular(k).is_some() => {
                out.push_str(if out.is_empty() {
                    ""
                } else if last_was_item {
                    ", "
                } else {
                    ": "
                });
                write!(out, "{} {i}", singular(k).unwrap_or_default()).unwrap();
                j += 2;
                if k == "faces" {
                    if let Some(Seg::Index(c)) = rest.get(j) {
                        write!(out, ", corner {c}").unwrap();
                        j += 1;
                    }
                }
                last_was_item = true;
            }
            (Seg::Key(k), _) => {
                if !out.is_empty() {
                    out.push_str(": ");
                }
                out.push_str(k);
                j += 1;
                last_was_item = false;
            }
            (Seg::Index(i), _) => {
                if out.is_empty() {
                    write!(out, "element {i}").unwrap();
                } else {
                    write!(out, "[{i}]").unwrap();
                }
                j += 1;
            }
        }
    }
    (layer, out)
}

/// A semantic error at `path` inside layer `layer`.
fn invalid_at(text: &str, layer: usize, path: Vec<Seg>, message: String) -> Error {
    let mut full = vec![Seg::Key("layers".into()), Seg::Index(layer)];
    full.extend(path);
    let (_, what) = describe(&full);
    error_at_path(
        text,
        layer,
        &full[2..],
        ErrorKind::Invalid {
            what: if what.is_empty() {
                "layer".into()
            } else {
                what
            },
            message,
        },
    )
}

/// An error of `kind` located at `path` (relative to layer `layer`).
fn error_at_path(text: &str, layer: usize, path: &[Seg], kind: ErrorKind) -> Error {
    let mut full = vec![Seg::Key("layers".into()), Seg::Index(layer)];
    full.extend_from_slice(path);
    Error {
        location: Location {
            file: None,
            layer: Some(layer),
            line: line_of_path(text, &full),
        },
        kind,
    }
}

/// Turns a serde_json error into a located error that says where in the document it lies and
/// what was expected and found.
fn serde_error(text: &str, e: serde_json::Error) -> Error {
    let (line, column) = (e.line(), e.column());
    let full = e.to_string();
    let suffix = format!(" at line {line} column {column}");
    let raw = full.strip_suffix(&suffix).unwrap_or(&full);
    let mut path = if e.is_eof() || line == 0 {
        Vec::new()
    } else {
        path_at(text, offset_of_line_column(text, line, column))
    };
    if raw.starts_with("unknown field") || raw.starts_with("duplicate field") {
        // The scan has already entered the offending key.
        if let Some(Seg::Key(_)) = path.last() {
            path.pop();
        }
    }
    let (layer, place) = describe(&path);
    let message = reword(raw);
    Error {
        location: Location {
            file: None,
            layer,
            line: (line > 0).then_some(line),
        },
        kind: ErrorKind::Syntax(if place.is_empty() {
            message
        } else {
            format!("{place}: {message}")
        }),
    }
}

/// serde's wording in the terms of this format: "expected X, found Y".
fn reword(raw: &str) -> String {
    let expected = |e: &str| {
        e.replace("struct ", "a ")
            .replace("a sequence", "an array")
            .replace("a map", "an object")
    };
    let found = |f: &str| match f {
        "sequence" => "an array".to_string(),
        "map" => "an object".to_string(),
        "unit value" => "null".to_string(),
        other => other.to_string(),
    };
    for prefix in ["invalid type: ", "invalid value: "] {
        if let Some(rest) = raw.strip_prefix(prefix) {
            if let Some((f, e)) = rest.rsplit_once(", expected ") {
                return format!("expected {}, found {}", expected(e), found(f));
            }
        }
    }
    if let Some(rest) = raw.strip_prefix("invalid length ") {
        if let Some((len, e)) = rest.split_once(", expected ") {
            let plural = if len == "1" { "" } else { "s" };
            return format!("expected {}, found {len} element{plural}", expected(e));
        }
    }
    if let Some(rest) = raw.strip_prefix("EOF while parsing ") {
        return format!("unexpected end of the text while reading {rest}");
    }
    match raw {
        "number out of range" => "number out of range (not a finite 64-bit number)".into(),
        "trailing characters" => "unexpected text after the end of the document".into(),
        "expected value" => "expected a JSON value (NaN and Infinity are not JSON numbers)".into(),
        _ => expected(raw),
    }
}

// ---------------------------------------------------------------------------------------------
// Writing

/// A number, in the shortest form that reads back to the same value. Non-finite values, which
/// JSON cannot hold, are written as `null` (which the reader refuses).
fn num(v: f64) -> String {
    serde_json::to_string(&v).unwrap_or_else(|_| "null".into())
}

fn string(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

fn numbers(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|&v| num(v)).collect();
    format!("[{}]", parts.join(", "))
}

fn indices(values: &[u32]) -> String {
    let parts: Vec<String> = values.iter().map(u32::to_string).collect();
    format!("[{}]", parts.join(", "))
}

fn handles(map: impl Iterator<Item = (u32, Vec2)>) -> String {
    let parts: Vec<String> = map
        .map(|(to, h)| format!("[{to}, {}, {}]", num(h.x), num(h.y)))
        .collect();
    format!("[{}]", parts.join(", "))
}

/// `{"a": 1, "b": 2}` on one line.
fn inline_object(fields: &[(&str, String)]) -> String {
    let parts: Vec<String> = fields
        .iter()
        .map(|(k, v)| format!("\"{k}\": {v}"))
        .collect();
    format!("{{{}}}", parts.join(", "))
}

/// An array with one item per line, at `indent`; `[]` when empty.
fn block_array(indent: usize, items: impl IntoIterator<Item = String>) -> String {
    let pad = " ".repeat(indent + 2);
    let lines: Vec<String> = items.into_iter().map(|i| format!("{pad}{i}")).collect();
    if lines.is_empty() {
        "[]".into()
    } else {
        format!("[\n{}\n{}]", lines.join(",\n"), " ".repeat(indent))
    }
}

/// An object with one field per line, at `indent`.
fn block_object(indent: usize, fields: &[(&str, String)]) -> String {
    let pad = " ".repeat(indent + 2);
    let lines: Vec<String> = fields
        .iter()
        .map(|(k, v)| format!("{pad}\"{k}\": {v}"))
        .collect();
    format!("{{\n{}\n{}}}", lines.join(",\n"), " ".repeat(indent))
}

/// The text to write for a colour with kept text: the text if it still denotes `colour`
/// (with the CSS alpha it implies), else the numbers.
fn colour_out(colour: [f64; 3], text: Option<&str>, space: ColourSpace) -> (String, Option<f64>) {
    if let Some(t) = text {
        if let Ok((c, alpha)) = css_colour(t, space) {
            if c == colour {
                return (string(t), Some(alpha));
            }
        }
    }
    (numbers(&colour), None)
}

/// Writes a document in the native format, canonically: fields in a fixed order, fields at
/// their defaults left out, one point per line, numbers in their shortest exact form, a colour's
/// kept CSS text when it still gives exactly the colour. Reading the output and writing again
/// gives the same bytes.
///
/// Handles of points that do not exist, and tags of kind smooth, are not written; non-finite
/// numbers are written as `null`.
pub fn write_document(doc: &Document) -> String {
    let layers = doc.layers.iter().map(|l| write_layer(l, 4));
    let mut fields = vec![
        ("format", string(FORMAT_NAME)),
        ("version", VERSION.to_string()),
    ];
    if let Some(v) = doc.view {
        fields.push(("view", numbers(&[v.x0, v.y0, v.x1, v.y1])));
    }
    fields.push(("layers", block_array(2, layers)));
    block_object(0, &fields) + "\n"
}

fn write_layer(mesh: &GradientMesh, indent: usize) -> String {
    let space = mesh.colour_space;
    let mut fields: Vec<(&str, String)> = Vec::new();
    if let Some(name) = &mesh.name {
        fields.push(("name", string(name)));
    }
    if space != ColourSpace::Lab {
        fields.push(("colour_space", string(space.name())));
    }
    if mesh.boundary != BoundaryInterpolation::EdgeAndCorner {
        fields.push(("boundary", string(mesh.boundary.name())));
    }
    if mesh.creasing != CreasingMethod::Uniform {
        fields.push(("creasing", string(mesh.creasing.name())));
    }
    if mesh.interpolate_positions {
        fields.push(("interpolate_positions", "true".to_string()));
    }
    if mesh.first_step != FirstStep::Ternary {
        fields.push(("first_step", string(mesh.first_step.name())));
    }
    let points = mesh.points.iter().enumerate().map(|(p, cp)| {
        let p = p as u32;
        let (colour, alpha) = colour_out(cp.colour, cp.colour_text.as_deref(), space);
        let mut f = vec![
            ("position", numbers(&[cp.position.x, cp.position.y])),
            ("colour", colour),
        ];
        // Without "opacity", the reader takes the CSS alpha (1 for numbers).
        if cp.opacity.to_bits() != alpha.unwrap_or(1.0).to_bits() {
            f.push(("opacity", num(cp.opacity)));
        }
        if cp.corner {
            f.push(("corner", "true".into()));
        }
        let mut h = mesh
            .handles
            .range((p, 0)..=(p, u32::MAX))
            .map(|(&(_, to), &v)| (to, v))
            .peekable();
        if h.peek().is_some() {
            f.push(("handles", handles(h)));
        }
        inline_object(&f)
    });
    fields.push(("points", block_array(indent + 2, points)));
    fields.push((
        "faces",
        block_array(indent + 2, mesh.faces.iter().map(|f| indices(f))),
    ));
    let edges: Vec<String> = mesh
        .edges
        .iter()
        .filter(|(_, t)| t.kind != EdgeKind::Smooth)
        .map(|(&(a, b), t)| {
            let mut f = vec![
                ("points", indices(&[a, b])),
                ("kind", string(t.kind.name())),
            ];
            if let (EdgeKind::Crease, Some(s)) = (t.kind, t.sharpness) {
                f.push(("sharpness", num(s)));
            }
            inline_object(&f)
        })
        .collect();
    if !edges.is_empty() {
        fields.push(("edges", block_array(indent + 2, edges)));
    }
    let wedges: Vec<String> = mesh
        .wedges
        .iter()
        .map(|w| {
            let (mut colour, alpha) = colour_out(w.colour, w.colour_text.as_deref(), space);
            // Without "opacity", the reader takes the CSS alpha when below 1, else the point's.
            let mut implied = alpha.filter(|&a| a < 1.0);
            if implied.is_some() && w.opacity.is_none() {
                // The text would impose an opacity the wedge does not have: write numbers.
                colour = numbers(&w.colour);
                implied = None;
            }
            let mut f = vec![
                ("point", w.point.to_string()),
                ("face", w.face.to_string()),
                ("colour", colour),
            ];
            if let Some(o) = w.opacity {
                if implied.map(f64::to_bits) != Some(o.to_bits()) {
                    f.push(("opacity", num(o)));
                }
            }
            if !w.handles.is_empty() {
                f.push((
                    "handles",
                    handles(w.handles.iter().map(|(&to, &v)| (to, v))),
                ));
            }
            inline_object(&f)
        })
        .collect();
    if !wedges.is_empty() {
        fields.push(("wedges", block_array(indent + 2, wedges)));
    }
    if mesh.fine_edits != FineEdits::ColourAndPosition {
        fields.push(("fine_edits", string(mesh.fine_edits.name())));
    }
    let edits: Vec<String> = mesh.edits.iter().map(write_edit).collect();
    if !edits.is_empty() {
        fields.push(("edits", block_array(indent + 2, edits)));
    }
    block_object(indent, &fields)
}

fn write_edit(e: &Edit) -> String {
    let a = e.address;
    let mut f = vec![
        ("level", a.level.to_string()),
        ("face", a.face.to_string()),
        ("point", a.point.to_string()),
        ("at", indices(&a.at)),
    ];
    match e.colour {
        Some(ColourEdit::Set(c)) => f.push(("colour", numbers(&c))),
        Some(ColourEdit::Offset(d)) => f.push(("colour_offset", numbers(&d))),
        None => {}
    }
    match e.opacity {
        Some(OpacityEdit::Set(o)) => f.push(("opacity", num(o))),
        Some(OpacityEdit::Offset(d)) => f.push(("opacity_offset", num(d))),
        None => {}
    }
    if let Some(o) = e.offset {
        f.push(("offset", numbers(&[o.x, o.y])));
    }
    inline_object(&f)
}

/// One layer of a refined mesh, for [`write_refined`].
#[derive(Clone, Copy, Debug)]
pub struct RefinedLayer<'a> {
    /// The layer's name, if any.
    pub name: Option<&'a str>,
    /// The space of the colours in `data`.
    pub colour_space: ColourSpace,
    /// Faces of the refined mesh.
    pub topology: &'a Topology,
    /// Position, colour and opacity of each vertex of `topology`.
    pub data: &'a [VertexData],
}

/// Writes refined meshes (a level of refinement, or its limit points) as JSON: per layer its
/// name, colour space, points (position, colour, opacity) and faces. Documented in
/// `docs/format.md` as the refined-mesh JSON; its `"format"` is [`REFINED_FORMAT_NAME`].
pub fn write_refined(layers: &[RefinedLayer]) -> String {
    let layers = layers.iter().map(|layer| {
        let mut fields: Vec<(&str, String)> = Vec::new();
        if let Some(name) = layer.name {
            fields.push(("name", string(name)));
        }
        fields.push(("colour_space", string(layer.colour_space.name())));
        let points = layer.data.iter().map(|d| {
            inline_object(&[
                ("position", numbers(&d.position)),
                ("colour", numbers(&d.colour)),
                ("opacity", num(d.opacity)),
            ])
        });
        fields.push(("points", block_array(6, points)));
        let faces =
            (0..layer.topology.face_count()).map(|f| indices(layer.topology.face_vertices(f)));
        fields.push(("faces", block_array(6, faces)));
        block_object(4, &fields)
    });
    let top = block_object(
        0,
        &[
            ("format", string(REFINED_FORMAT_NAME)),
            ("version", VERSION.to_string()),
            ("layers", block_array(2, layers)),
        ],
    );
    top + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = r##"{
  "format": "gradmesh",
  "version": 1,
  "layers": [
    {
      "name": "square",
      "points": [
        {"position": [0, 0], "colour": [50, 0, 0]},
        {"position": [1, 0], "colour": "#ff0000", "handles": [[2, 0, 0.25], [0, -0.25, 0]]},
        {"position": [1, 1], "colour": "rgb(0 0 255 / 50%)", "corner": true},
        {"position": [0, 1], "colour": [20, 10, -10], "opacity": 0.25}
      ],
      "faces": [[0, 1, 2, 3]],
      "edges": [{"points": [2, 1], "kind": "crease", "sharpness": 2.5}]
    }
  ]
}"##;

    fn err(text: &str) -> Error {
        read_document(text).unwrap_err()
    }

    #[test]
    fn reads_every_field() {
        let doc = read_document(SQUARE).unwrap();
        let m = &doc.layers[0];
        assert_eq!(m.name.as_deref(), Some("square"));
        assert_eq!(m.colour_space, ColourSpace::Lab);
        assert_eq!(m.points.len(), 4);
        assert_eq!(m.points[0].colour, [50.0, 0.0, 0.0]);
        assert_eq!(m.points[1].colour_text.as_deref(), Some("#ff0000"));
        assert!(
            (m.points[1].colour[0] - 53.24).abs() < 0.05,
            "{:?}",
            m.points[1]
        );
        assert_eq!(m.points[2].opacity, 0.5);
        assert!(m.points[2].corner);
        assert_eq!(m.points[3].opacity, 0.25);
        assert_eq!(m.handles[&(1, 2)], Vec2::new(0.0, 0.25));
        assert_eq!(m.handles[&(1, 0)], Vec2::new(-0.25, 0.0));
        assert_eq!(m.faces, vec![vec![0, 1, 2, 3]]);
        assert_eq!(
            m.edges[&(1, 2)],
            EdgeTag {
                kind: EdgeKind::Crease,
                sharpness: Some(2.5)
            }
        );
        crate::validate::validate(m).unwrap();
    }

    #[test]
    fn round_trip_is_exact_and_canonical() {
        let doc = read_document(SQUARE).unwrap();
        let once = write_document(&doc);
        let again = read_document(&once).unwrap();
        assert_eq!(again, doc);
        assert_eq!(write_document(&again), once);
        assert!(once.contains("\"colour\": \"#ff0000\""), "{once}");
        assert!(
            once.contains("\"colour\": \"rgb(0 0 255 / 50%)\""),
            "{once}"
        );
        // The alpha of the CSS text gives the opacity; it is not repeated.
        assert!(!once.contains("\"opacity\": 0.5"), "{once}");
        // Handles are sorted by neighbour.
        assert!(once.contains("[[0, -0.25, 0.0], [2, 0.0, 0.25]]"), "{once}");
    }

    #[test]
    fn changed_colour_is_written_as_numbers() {
        let mut doc = read_document(SQUARE).unwrap();
        doc.layers[0].points[1].colour[0] += 1.0;
        let text = write_document(&doc);
        assert!(!text.contains("#ff0000"), "{text}");
        let back = read_document(&text).unwrap();
        assert_eq!(
            back.layers[0].points[1].colour,
            doc.layers[0].points[1].colour
        );
    }

    /// One grey sRGB quad over the unit square.
    fn grey_unit_square() -> GradientMesh {
        let mut mesh = GradientMesh::new(ColourSpace::Srgb);
        for (x, y) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
            mesh.add_point(Point::new(x, y), [0.5; 3]);
        }
        mesh.add_face([0, 1, 2, 3]);
        mesh
    }

    /// A document's view is written after the version, read back as written, and refused
    /// when it is empty or reversed.
    #[test]
    fn the_view_round_trips_and_bad_ones_are_refused() {
        let doc = Document {
            layers: vec![grey_unit_square()],
            view: Some(kurbo::Rect::new(-2.0, 0.0, 3.5, 4.0)),
        };
        let text = write_document(&doc);
        assert!(text.contains("\"view\": [-2.0, 0.0, 3.5, 4.0]"), "{text}");
        let back = read_document(&text).unwrap();
        assert_eq!(back, doc);
        assert_eq!(write_document(&back), text);
        let reversed = text.replace("[-2.0, 0.0, 3.5, 4.0]", "[3, 0, 1, 4]");
        let e = read_document(&reversed).unwrap_err().to_string();
        assert!(e.contains("4: view: expected"), "{e}");
    }

    #[test]
    fn wedge_opacity_rules() {
        let mut mesh = grey_unit_square();
        let text_colour = "rgb(255 0 0 / 0.5)";
        let (c, _) = parse_css_colour(text_colour, ColourSpace::Srgb).unwrap();
        for opacity in [None, Some(0.5), Some(0.75)] {
            mesh.wedges = vec![WedgeOverride {
                point: 0,
                face: 0,
                colour: c,
                colour_text: Some(text_colour.into()),
                opacity,
                handles: BTreeMap::new(),
            }];
            let doc = Document::new(vec![mesh.clone()]);
            let text = write_document(&doc);
            let back = read_document(&text).unwrap();
            assert_eq!(back.layers[0].wedges[0].opacity, opacity, "{text}");
            assert_eq!(back.layers[0].wedges[0].colour, c);
            assert_eq!(text.contains(text_colour), opacity.is_some(), "{text}");
            assert_eq!(write_document(&back), text);
        }
    }

    #[test]
    fn errors_name_line_place_and_what_was_found() {
        let bad = SQUARE.replace("\"colour\": [20, 10, -10]", "\"colour\": true");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(11), "{e}");
        assert_eq!(e.location.layer, Some(0));
        assert_eq!(
            e.kind.to_string(),
            "point 3: colour: expected 3 numbers or a CSS colour string, found boolean `true`"
        );

        let bad = SQUARE.replace("[20, 10, -10]", "[20, 10]");
        assert_eq!(
            err(&bad).kind.to_string(),
            "point 3: colour: expected 3 numbers or a CSS colour string, found 2 elements"
        );

        let bad = SQUARE.replace("\"#ff0000\"", "\"#ff00zz\"");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(9), "{e}");
        assert!(
            e.to_string().starts_with(
                "9: layer 0: point 1: colour: expected 3 numbers or a CSS colour string, found \"#ff00zz\""
            ),
            "{e}"
        );

        let bad = SQUARE.replace("\"corner\": true", "\"cornr\": true");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(10));
        assert!(
            e.kind
                .to_string()
                .starts_with("point 2: unknown field `cornr`"),
            "{e}"
        );

        let bad = SQUARE.replace("[0, 1, 2, 3]", "[0, 1, 2, 7]");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(13), "{e}");
        assert!(matches!(
            e.kind,
            ErrorKind::IndexOutOfRange { index: 7, .. }
        ));

        let bad = SQUARE.replace("[0, 1, 2, 3]", "[0, 1, -2, 3]");
        assert_eq!(
            err(&bad).kind.to_string(),
            "face 0, corner 2: expected an index (a whole number from 0), found integer `-2`"
        );

        let bad = SQUARE.replace("\"position\": [1, 1]", "\"position\": [1, \"a\"]");
        assert_eq!(
            err(&bad).kind.to_string(),
            "point 2: position[1]: expected a number, found string \"a\""
        );

        let bad = SQUARE.replace("{\"position\": [0, 0], ", "{");
        assert_eq!(
            err(&bad).kind.to_string(),
            "point 0: missing field `position`"
        );

        let bad = SQUARE.replace("\"crease\"", "\"sharp\"");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(14));
        assert_eq!(
            e.kind.to_string(),
            "edge entry 0: kind: expected one of \"crease\", \"discontinuous\", found \"sharp\""
        );

        let bad = SQUARE.replace("\"opacity\": 0.25", "\"opacity\": 1.5");
        assert_eq!(
            err(&bad).kind.to_string(),
            "point 3: opacity: expected a number in 0..1, found 1.5"
        );

        let bad = SQUARE.replace("[2, 0, 0.25]", "[1, 0, 0.25]");
        assert_eq!(
            err(&bad).kind.to_string(),
            "point 1, handle 0: the neighbour is the point itself (1)"
        );

        let bad = SQUARE.replace("\"points\": [2, 1]", "\"points\": [1, 1]");
        assert!(err(&bad)
            .to_string()
            .contains("edge entry 0: points: expected two different points"));
    }

    #[test]
    fn syntax_errors_are_located() {
        let bad = SQUARE.replace("[0, 1, 2, 3]]", "[0, 1, 2, 3]");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(14), "{e}");
        assert!(e.kind.to_string().contains("expected `,` or `]`"), "{e}");

        let e = err(&SQUARE[..100]);
        assert!(e.to_string().contains("unexpected end of the text"), "{e}");

        let e = err("{\"format\": \"gradmesh\", \"version\": 1, \"layers\": [], }");
        assert!(e.to_string().contains("trailing comma"), "{e}");
    }

    #[test]
    fn numbers_beyond_f64_and_repeated_fields() {
        let bad = SQUARE.replace("[1, 1]", "[1e400, 1]");
        let e = err(&bad);
        assert_eq!(e.location.line, Some(10), "{e}");
        assert!(e.to_string().contains("number out of range"), "{e}");
        let bad = SQUARE.replace("\"corner\": true", "\"corner\": true, \"corner\": false");
        assert_eq!(
            err(&bad).to_string(),
            "10: layer 0: point 2: duplicate field `corner`"
        );
    }

    #[test]
    fn explicit_defaults_are_dropped_once() {
        let text = SQUARE.replace(
            "\"name\": \"square\",",
            "\"name\": \"square\", \"colour_space\": \"lab\", \"boundary\": \"edge-and-corner\", \"creasing\": \"uniform\",",
        );
        let doc = read_document(&text).unwrap();
        let once = write_document(&doc);
        assert!(
            !once.contains("colour_space") && !once.contains("boundary"),
            "{once}"
        );
        assert_eq!(read_document(&once).unwrap(), doc);
    }

    #[test]
    fn foreign_and_future_documents() {
        let e = err("{\"format\": \"svg\", \"version\": 1, \"layers\": []}");
        assert_eq!(
            e.to_string(),
            "1: format: expected \"gradmesh\" (not a gradmesh document), found \"svg\""
        );
        let e = err("{\n\"format\": \"gradmesh\",\n\"version\": 2,\n\"extra\": 0\n}");
        assert_eq!(
            e.to_string(),
            "3: version: unsupported version 2: this program reads version 1"
        );
        let e = err("{\"layers\": []}");
        assert!(e.to_string().contains("missing \"format\""), "{e}");
        let e = err("[1, 2]");
        assert!(
            e.to_string()
                .contains("expected an object (a gradmesh document), found an array"),
            "{e}"
        );
        let e = err("{\"format\": \"gradmesh\", \"version\": 1, \"layers\": [], \"x\": 1}");
        assert!(e.to_string().contains("unknown field `x`"), "{e}");
    }

    #[test]
    fn refined_output_is_refused_as_input() {
        let e = err("{\"format\": \"gradmesh-refined\", \"version\": 1, \"layers\": []}");
        assert!(e.to_string().contains("refined mesh"), "{e}");
    }

    #[test]
    fn deep_nesting_is_refused_before_parsing() {
        let text = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
        let e = err(&text);
        assert!(
            matches!(
                e.kind,
                ErrorKind::LimitExceeded {
                    found: 65,
                    limit: 64,
                    ..
                }
            ),
            "{e}"
        );
        // Brackets inside strings do not count.
        let name = "[".repeat(100);
        let text = format!(
            "{{\"format\": \"gradmesh\", \"version\": 1, \"layers\": [{{\"name\": \"{name}\", \"points\": [], \"faces\": []}}]}}"
        );
        assert_eq!(
            read_document(&text).unwrap().layers[0].name.as_deref(),
            Some(name.as_str())
        );
    }

    #[test]
    fn empty_layers_are_written_compactly() {
        let doc = Document::new(vec![GradientMesh::default()]);
        let text = write_document(&doc);
        assert_eq!(
            text,
            "{\n  \"format\": \"gradmesh\",\n  \"version\": 1,\n  \"layers\": [\n    {\n      \"points\": [],\n      \"faces\": []\n    }\n  ]\n}\n"
        );
        assert_eq!(read_document(&text).unwrap(), doc);
    }

    #[test]
    fn refined_mesh_json() {
        let topology = Topology::from_faces(3, &[vec![0, 1, 2]]).unwrap();
        let data = [
            [0.0, 0.0, 50.0, 0.0, 0.0, 1.0],
            [1.0, 0.0, 60.0, 1.0, 2.0, 0.5],
            [0.0, 1.0, 70.0, -1.0, 0.0, 1.0],
        ]
        .map(VertexData::from_array);
        let text = write_refined(&[RefinedLayer {
            name: Some("a"),
            colour_space: ColourSpace::Lab,
            topology: &topology,
            data: &data,
        }]);
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["format"], "gradmesh-refined");
        assert_eq!(v["layers"][0]["points"][1]["opacity"], 0.5);
        assert_eq!(v["layers"][0]["faces"][0], serde_json::json!([0, 1, 2]));
    }

    #[test]
    fn paths_are_recovered_from_offsets() {
        let text = r#"{"a": [1, {"b": [2, 3]}], "c": "x,]"}"#;
        let at = |needle: &str| path_at(text, text.find(needle).unwrap() + needle.len());
        assert_eq!(
            at("[2, 3"),
            vec![
                Seg::Key("a".into()),
                Seg::Index(1),
                Seg::Key("b".into()),
                Seg::Index(1)
            ]
        );
        assert_eq!(at("\"x,]"), vec![Seg::Key("c".into())]);
        assert_eq!(line_of_path(text, &[Seg::Key("c".into())]), Some(1));
    }
}
