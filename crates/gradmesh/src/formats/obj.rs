//! Import of Wavefront OBJ polygon meshes (with vertex colours and OpenSubdiv's crease and
//! corner tags), and export of refined meshes as OBJ.
//!
//! Read: `v x y z [r g b]` (z ignored; colours non-linear sRGB in 0..1), `f` with any number of
//! corners in the forms `v`, `v/vt`, `v//vn`, `v/vt/vn` (only `v` is used; negative indices count
//! back from the last vertex read), and OpenSubdiv's tags `t name ints/floats/strings args..`:
//! `crease` (pairs of 0-based vertex indices, one sharpness or one per pair), `corner` (0-based
//! vertices, one sharpness or one per vertex), `interpolateboundary` (1 edge-and-corner,
//! 2 edge-only) and `creasemethod` (`normal` or `chaikin`). Texture coordinates, normals,
//! objects, groups, smoothing groups, materials, lines and points are ignored; `#` starts a
//! comment. When no vertex has a colour, every point is a neutral grey (sRGB 0.5, 0.5, 0.5).

use kurbo::Point;

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind};
use crate::mesh::{BoundaryInterpolation, ControlPoint, CreasingMethod, EdgeKind, GradientMesh};
use crate::size_limits::Limits;
use crate::topology::Topology;
use crate::validate::VertexData;

use super::{check_count, check_size, error_at, syntax_error};

/// The colour given to every point of a file without vertex colours (sRGB).
pub const NEUTRAL_GREY: [f64; 3] = [0.5, 0.5, 0.5];

/// Statements that carry nothing for a 2D gradient mesh.
const IGNORED: [&str; 10] = [
    "vt", "vn", "vp", "o", "g", "s", "usemtl", "mtllib", "l", "p",
];

/// Tags of OpenSubdiv that only concern face-varying data, which a gradient mesh has none of.
const IGNORED_TAGS: [&str; 2] = [
    "facevaryinginterpolateboundary",
    "facevaryingpropagatecorners",
];

// `what` names the field for an error message, built only when there is one.
fn parse_num(token: &str, what: impl Fn() -> String, line: usize) -> Result<f64, Error> {
    let v = token.parse::<f64>().map_err(|_| {
        syntax_error(
            line,
            format!("{}: expected a number, found \"{token}\"", what()),
        )
    })?;
    if !v.is_finite() {
        return Err(error_at(
            line,
            ErrorKind::NotFinite {
                what: what(),
                value: token.to_string(),
            },
        ));
    }
    Ok(v)
}

/// A vertex index of a tag (0-based, as OpenSubdiv writes them).
fn parse_tag_index(token: &str, what: &str, line: usize) -> Result<u32, Error> {
    token.parse::<u32>().map_err(|_| {
        syntax_error(
            line,
            format!("{what}: expected a vertex index (0-based), found \"{token}\""),
        )
    })
}

/// An OpenSubdiv tag: `t name ints/floats/strings args..`.
struct Tag<'a> {
    name: &'a str,
    ints: Vec<u32>,
    floats: Vec<f64>,
    strings: Vec<&'a str>,
}

fn parse_tag<'a>(t: &[&'a str], line: usize) -> Result<Tag<'a>, Error> {
    let usage = "expected \"t name ints/floats/strings\" followed by the arguments";
    let (name, counts) = match t {
        [_, name, counts, ..] => (*name, *counts),
        _ => return Err(syntax_error(line, format!("tag: {usage}"))),
    };
    let parsed: Option<Vec<usize>> = counts.split('/').map(|c| c.parse().ok()).collect();
    let [ni, nf, ns] = parsed.as_deref().unwrap_or_default() else {
        return Err(syntax_error(
            line,
            format!("tag {name}: {usage}; found \"{counts}\" for the counts"),
        ));
    };
    let (ni, nf, ns) = (*ni, *nf, *ns);
    let args = &t[3..];
    // Counts near usize::MAX must not wrap around to the number of arguments.
    let announced = ni.checked_add(nf).and_then(|n| n.checked_add(ns));
    if announced != Some(args.len()) {
        let announced = announced.map_or_else(|| "more".to_string(), |n| n.to_string());
        return Err(syntax_error(
            line,
            format!(
                "tag {name}: the counts {counts} announce {announced} arguments, found {}",
                args.len()
            ),
        ));
    }
    let ints = args[..ni]
        .iter()
        .enumerate()
        .map(|(k, a)| parse_tag_index(a, &format!("tag {name}: integer {}", k + 1), line))
        .collect::<Result<_, _>>()?;
    let floats = args[ni..ni + nf]
        .iter()
        .enumerate()
        .map(|(k, a)| parse_num(a, || format!("tag {name}: number {}", k + 1), line))
        .collect::<Result<_, _>>()?;
    Ok(Tag {
        name,
        ints,
        floats,
        strings: args[ni + nf..].to_vec(),
    })
}

/// The sharpness of item `k` of a tag: a single value for all items, or one per item.
fn tag_sharpness(tag: &Tag, items: usize, k: usize, line: usize) -> Result<f64, Error> {
    let s = match tag.floats.len() {
        1 => tag.floats[0],
        n if n == items => tag.floats[k],
        n => {
            return Err(syntax_error(
                line,
                format!(
                    "tag {}: expected 1 sharpness or {items} (one per item), found {n}",
                    tag.name
                ),
            ))
        }
    };
    if s < 0.0 {
        return Err(syntax_error(
            line,
            format!("tag {}: expected a sharpness >= 0, found {s}", tag.name),
        ));
    }
    Ok(s)
}

/// Reads an OBJ polygon mesh into one gradient mesh in the sRGB colour space.
///
/// Every error names the line and says what was expected and what was found. Statements this
/// reader does not know, and tags it cannot honour (`hole`, smooth triangles), are errors rather
/// than silently dropped.
pub fn read_obj(text: &str) -> Result<GradientMesh, Error> {
    read_obj_with_limits(text, &Limits::DEFAULT)
}

/// Reads an OBJ polygon mesh as [`read_obj`] does, within `limits`: input bytes, vertices, faces
/// and corners, each refused at the line that goes beyond it.
pub fn read_obj_with_limits(text: &str, limits: &Limits) -> Result<GradientMesh, Error> {
    check_size(text.len() as u64, limits.input_bytes)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut reader = ObjReader::new(limits);
    for (i, raw) in text.lines().enumerate() {
        reader.read_line(i + 1, raw)?;
    }
    reader.finish()
}

/// What has been read of an OBJ file so far.
struct ObjReader<'l> {
    limits: &'l Limits,
    mesh: GradientMesh,
    /// Whether vertices carry colours, with the line of the first vertex.
    coloured: Option<(bool, usize)>,
    /// The line of each face: corners with positive indices are checked once every vertex is
    /// known.
    face_lines: Vec<usize>,
    /// Crease tags `(a, b, sharpness, line)`, applied at the end.
    creases: Vec<(u32, u32, f64, usize)>,
    /// Corner tags `(vertex, sharpness, line)`, applied at the end.
    corners: Vec<(u32, f64, usize)>,
    corner_count: u64,
}

impl<'l> ObjReader<'l> {
    fn new(limits: &'l Limits) -> Self {
        ObjReader {
            limits,
            mesh: GradientMesh::new(ColourSpace::Srgb),
            coloured: None,
            face_lines: Vec::new(),
            creases: Vec::new(),
            corners: Vec::new(),
            corner_count: 0,
        }
    }

    /// Reads line number `line`, whose text is `raw`.
    fn read_line(&mut self, line: usize, raw: &str) -> Result<(), Error> {
        let content = raw.split('#').next().unwrap_or("");
        if content.trim_end().ends_with('\\') {
            return Err(syntax_error(
                line,
                "line continuations (a line ending in \\) are not supported",
            ));
        }
        let t: Vec<&str> = content.split_whitespace().collect();
        let Some(&keyword) = t.first() else {
            return Ok(());
        };
        match keyword {
            "v" => self.read_vertex(&t, line),
            "f" => self.read_face(&t, line),
            "t" => self.read_tag(&t, line),
            k if IGNORED.contains(&k) => Ok(()),
            other => Err(syntax_error(
                line,
                format!("unknown statement \"{other}\" (expected v, f or t)"),
            )),
        }
    }

    /// `v x y z [r g b]`.
    fn read_vertex(&mut self, t: &[&str], line: usize) -> Result<(), Error> {
        let v = self.mesh.points.len();
        check_count("the number of vertices", v as u64 + 1, self.limits.points)
            .map_err(|e| located(e, line))?;
        let values: Vec<f64> = t[1..]
            .iter()
            .enumerate()
            .map(|(k, s)| parse_num(s, || format!("vertex {} value {}", v + 1, k + 1), line))
            .collect::<Result<_, _>>()?;
        let has_colour = match values.len() {
            3 => false,
            6 => true,
            n => {
                return Err(syntax_error(
                    line,
                    format!(
                        "vertex {}: expected \"x y z\" or \"x y z r g b\", found {n} numbers",
                        v + 1
                    ),
                ))
            }
        };
        match self.coloured {
            None => self.coloured = Some((has_colour, line)),
            Some((c, first)) if c != has_colour => {
                let (this, that) = if has_colour {
                    ("has a colour", "has none")
                } else {
                    ("has no colour", "has one")
                };
                return Err(syntax_error(
                    line,
                    format!(
                        "vertex {} {this}, but the first vertex (line {first}) {that}: \
                         give every vertex a colour or none",
                        v + 1
                    ),
                ));
            }
            Some(_) => {}
        }
        let colour = if has_colour {
            [values[3], values[4], values[5]]
        } else {
            NEUTRAL_GREY
        };
        self.mesh
            .points
            .push(ControlPoint::new(Point::new(values[0], values[1]), colour));
        Ok(())
    }

    /// `f v1 v2 v3 ..`, each corner in one of the forms `v`, `v/vt`, `v//vn`, `v/vt/vn`.
    fn read_face(&mut self, t: &[&str], line: usize) -> Result<(), Error> {
        let f = self.mesh.faces.len();
        check_count("the number of faces", f as u64 + 1, self.limits.faces)
            .map_err(|e| located(e, line))?;
        self.corner_count += t.len() as u64 - 1;
        check_count(
            "the number of corners",
            self.corner_count,
            self.limits.corners,
        )
        .map_err(|e| located(e, line))?;
        if t.len() < 4 {
            return Err(syntax_error(
                line,
                format!(
                    "face {}: expected at least 3 corners, found {}",
                    f + 1,
                    t.len() - 1
                ),
            ));
        }
        let mut face = Vec::with_capacity(t.len() - 1);
        // A set, not a search of the corners so far: faces may have millions of corners.
        let mut seen = std::collections::HashSet::with_capacity(t.len() - 1);
        let count = self.mesh.points.len() as i64;
        for (c, token) in t[1..].iter().enumerate() {
            let resolved = face_corner(token, f, c, count, line)?;
            if !seen.insert(resolved) {
                return Err(syntax_error(
                    line,
                    format!(
                        "face {}: vertex {} appears twice",
                        f + 1,
                        u64::from(resolved) + 1
                    ),
                ));
            }
            face.push(resolved);
        }
        self.mesh.faces.push(face);
        self.face_lines.push(line);
        Ok(())
    }

    /// `t name ints/floats/strings args..`: OpenSubdiv's tags.
    fn read_tag(&mut self, t: &[&str], line: usize) -> Result<(), Error> {
        let tag = parse_tag(t, line)?;
        match tag.name {
            "crease" => {
                if tag.ints.len() < 2 || tag.ints.len() % 2 != 0 {
                    return Err(syntax_error(
                        line,
                        format!(
                            "tag crease: expected pairs of vertex indices, found {} integers",
                            tag.ints.len()
                        ),
                    ));
                }
                let pairs = tag.ints.len() / 2;
                for k in 0..pairs {
                    let s = tag_sharpness(&tag, pairs, k, line)?;
                    self.creases
                        .push((tag.ints[2 * k], tag.ints[2 * k + 1], s, line));
                }
            }
            "corner" => {
                if tag.ints.is_empty() {
                    return Err(syntax_error(
                        line,
                        "tag corner: expected at least one vertex index",
                    ));
                }
                for (k, &v) in tag.ints.iter().enumerate() {
                    let s = tag_sharpness(&tag, tag.ints.len(), k, line)?;
                    self.corners.push((v, s, line));
                }
            }
            "interpolateboundary" => {
                self.mesh.boundary = match tag.ints.as_slice() {
                    [1] => BoundaryInterpolation::EdgeAndCorner,
                    [2] => BoundaryInterpolation::EdgeOnly,
                    other => {
                        return Err(syntax_error(
                            line,
                            format!(
                                "tag interpolateboundary: expected 1 (edge and corner) or 2 \
                                 (edge only), found {other:?}"
                            ),
                        ))
                    }
                }
            }
            "creasemethod" => {
                self.mesh.creasing = match tag.strings.as_slice() {
                    ["normal"] | ["uniform"] => CreasingMethod::Uniform,
                    ["chaikin"] => CreasingMethod::Chaikin,
                    other => {
                        return Err(syntax_error(
                            line,
                            format!(
                            "tag creasemethod: expected \"normal\" or \"chaikin\", found {other:?}"
                        ),
                        ))
                    }
                }
            }
            "smoothtriangles" if tag.strings == ["catmark"] => {}
            name if IGNORED_TAGS.contains(&name) => {}
            name => {
                return Err(syntax_error(
                    line,
                    format!(
                        "tag {name}: not supported (supported: crease, corner, \
                         interpolateboundary, creasemethod)"
                    ),
                ))
            }
        }
        Ok(())
    }

    /// Checks the faces' corners and the tags' vertices against the vertices read, and
    /// applies the tags.
    fn finish(self) -> Result<GradientMesh, Error> {
        let ObjReader {
            mut mesh,
            face_lines,
            creases,
            corners,
            ..
        } = self;
        let n = mesh.points.len();
        for (f, face) in mesh.faces.iter().enumerate() {
            for (c, &v) in face.iter().enumerate() {
                if v as usize >= n {
                    return Err(syntax_error(
                        face_lines[f],
                        format!(
                            "face {}: corner {} refers to vertex {}, but there are only {n} vertices",
                            f + 1,
                            c + 1,
                            u64::from(v) + 1
                        ),
                    ));
                }
            }
        }
        let check_tag_vertex = |v: u32, tag: &str, line: usize| {
            if v as usize >= n {
                Err(syntax_error(
                    line,
                    format!(
                        "tag {tag}: vertex {v} (0-based) does not exist (there are {n} vertices)"
                    ),
                ))
            } else {
                Ok(())
            }
        };
        for (a, b, s, line) in creases {
            check_tag_vertex(a, "crease", line)?;
            check_tag_vertex(b, "crease", line)?;
            if a == b {
                return Err(syntax_error(
                    line,
                    format!("tag crease: the edge {a}-{b} joins a vertex to itself"),
                ));
            }
            // As in OpenSubdiv, a later tag on the same edge wins, and sharpness 0 is smooth.
            let kind = if s > 0.0 {
                EdgeKind::Crease
            } else {
                EdgeKind::Smooth
            };
            mesh.set_edge(a, b, kind, Some(s));
        }
        for (v, s, line) in corners {
            check_tag_vertex(v, "corner", line)?;
            mesh.points[v as usize].corner = s > 0.0;
        }
        Ok(mesh)
    }
}

/// The 0-based vertex of corner `c` of face `f` (both 0-based) from its token, with `count`
/// vertices read so far: 1-based, or negative to count back from the last vertex read.
fn face_corner(token: &str, f: usize, c: usize, count: i64, line: usize) -> Result<u32, Error> {
    let first = token.split('/').next().unwrap_or("");
    let index: i64 = first.parse().map_err(|_| {
        syntax_error(
            line,
            format!(
                "face {}: corner {}: expected a vertex index, found \"{token}\"",
                f + 1,
                c + 1
            ),
        )
    })?;
    let resolved = match index {
        0 => {
            return Err(syntax_error(
                line,
                format!(
                    "face {}: corner {}: expected an index from 1 (or negative), found 0",
                    f + 1,
                    c + 1
                ),
            ))
        }
        i if i < 0 && i + count < 0 => {
            return Err(syntax_error(
                line,
                format!(
                    "face {}: corner {}: relative index {i} reaches before the first vertex \
                     ({count} vertices read so far)",
                    f + 1,
                    c + 1
                ),
            ))
        }
        i if i < 0 => i + count,
        i => i - 1,
    };
    u32::try_from(resolved).map_err(|_| {
        syntax_error(
            line,
            format!(
                "face {}: corner {}: index {index} is too large",
                f + 1,
                c + 1
            ),
        )
    })
}

fn located(mut e: Error, line: usize) -> Error {
    e.location.line = Some(line);
    e
}

/// One layer for [`write_refined_obj`]: its name, the faces, and the data of each vertex.
pub type ObjLayer<'a> = (Option<&'a str>, &'a Topology, &'a [VertexData]);

/// Writes refined meshes as OBJ: per layer an `o name` line (when named), `v x y 0 c0 c1 c2` per
/// vertex and `f` lines with 1-based indices continuing across layers. Colours are in each
/// mesh's working colour space (Lab unless the mesh says otherwise), not necessarily sRGB;
/// opacity is not written. Numbers are printed in their shortest exact form.
pub fn write_refined_obj(layers: &[ObjLayer]) -> String {
    let mut out = Vec::new();
    write_refined_obj_to(&mut out, layers).expect("writing to memory does not fail");
    String::from_utf8(out).expect("the output is UTF-8")
}

/// As [`write_refined_obj`], streamed into `w` (blocks of lines are formatted in parallel and
/// written in order).
pub fn write_refined_obj_to(
    w: &mut dyn std::io::Write,
    layers: &[ObjLayer],
) -> std::io::Result<()> {
    use rayon::prelude::*;
    // Refined meshes reach millions of lines: format blocks of lines in parallel, with ryu for
    // the numbers (shortest round-trip form, like `{}` but several times faster).
    const BLOCK: usize = 1 << 14;
    const GROUP: usize = 4 * BLOCK;
    w.write_all(
        b"# gradmesh refined mesh: v x y 0 c0 c1 c2 (colours in the mesh's working space)\n",
    )?;
    let mut base = 0usize;
    for &(name, topology, data) in layers {
        if let Some(name) = name {
            let clean: String = name
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect();
            w.write_all(format!("o {clean}\n").as_bytes())?;
        }
        // A bounded number of blocks at a time keeps memory small (a group of text is about
        // 4 MB: a few blocks per core).
        for group in data.chunks(GROUP) {
            let vertices: Vec<String> = group
                .par_chunks(BLOCK)
                .map(|block| {
                    let mut s = String::with_capacity(block.len() * 64);
                    let mut num = ryu::Buffer::new();
                    for d in block {
                        s.push('v');
                        let ([x, y], [c0, c1, c2]) = (d.position, d.colour);
                        for (k, &x) in [x, y, 0.0, c0, c1, c2].iter().enumerate() {
                            s.push(' ');
                            if k == 2 {
                                s.push('0');
                            } else {
                                s.push_str(shortest(&mut num, x));
                            }
                        }
                        s.push('\n');
                    }
                    s
                })
                .collect();
            for s in &vertices {
                w.write_all(s.as_bytes())?;
            }
        }
        let face_count = topology.face_count();
        for group in (0..face_count).step_by(GROUP) {
            let group_end = (group + GROUP).min(face_count);
            let faces: Vec<String> = (group..group_end)
                .step_by(BLOCK)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|first| {
                    let block = first..(first + BLOCK).min(group_end);
                    let mut s = String::with_capacity(block.len() * 32);
                    let mut num = itoa::Buffer::new();
                    for f in block {
                        s.push('f');
                        for &v in topology.face_vertices(f) {
                            s.push(' ');
                            s.push_str(num.format(base + v as usize + 1));
                        }
                        s.push('\n');
                    }
                    s
                })
                .collect();
            for s in &faces {
                w.write_all(s.as_bytes())?;
            }
        }
        base += data.len();
    }
    Ok(())
}

/// A finite number in its shortest round-trip form, without a trailing `.0` (so integers read
/// as in other OBJ files); non-finite values as Rust prints them.
fn shortest(buffer: &mut ryu::Buffer, x: f64) -> &str {
    if !x.is_finite() {
        return if x.is_nan() {
            "NaN"
        } else if x > 0.0 {
            "inf"
        } else {
            "-inf"
        };
    }
    let s = buffer.format_finite(x);
    s.strip_suffix(".0").unwrap_or(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SQUARE: &str = "# a square of two quads
o square
v 0 0 0 1 0 0
v 1 0 0 0 1 0
v 2 0 0 0 0 1
v 0 1 0 1 1 0
v 1 1 0 0 1 1
v 2 1 0 1 0 1
vt 0 0
vn 0 0 1
s off
f 1/1/1 4/1/1 5/1/1 2/1/1
f -5//1 -2//1 -1//1 -4//1
t crease 2/1/0 1 4 2.5
t corner 1/1/0 0 10
t interpolateboundary 1/0/0 2
";

    fn err(text: &str) -> String {
        read_obj(text).unwrap_err().to_string()
    }

    #[test]
    fn reads_vertices_faces_and_tags() {
        let m = read_obj(SQUARE).unwrap();
        assert_eq!(m.colour_space, ColourSpace::Srgb);
        assert_eq!(m.points.len(), 6);
        assert_eq!(m.points[1].colour, [0.0, 1.0, 0.0]);
        assert_eq!(m.faces, vec![vec![0, 3, 4, 1], vec![1, 4, 5, 2]]);
        let tag = m.edge_tag(4, 1);
        assert_eq!((tag.kind, tag.sharpness), (EdgeKind::Crease, Some(2.5)));
        assert!(m.points[0].corner && !m.points[1].corner);
        assert_eq!(m.boundary, BoundaryInterpolation::EdgeOnly);
        crate::validate::validate(&m).unwrap();
    }

    #[test]
    fn vertices_without_colour_are_grey() {
        let m = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
        assert!(m.points.iter().all(|p| p.colour == NEUTRAL_GREY));
    }

    #[test]
    fn errors_name_the_line() {
        assert_eq!(
            err("v 0 0 0\nv 1 0\n"),
            "2: vertex 2: expected \"x y z\" or \"x y z r g b\", found 2 numbers"
        );
        assert_eq!(
            err("v 0 0 0\nv 1 0 x\n"),
            "2: vertex 2 value 3: expected a number, found \"x\""
        );
        assert_eq!(
            err("v 0 0 nan\n"),
            "1: vertex 1 value 3 is not a finite number (nan)"
        );
        assert_eq!(
            err("v 0 0 0 1 1 1\nv 1 0 0\n"),
            "2: vertex 2 has no colour, but the first vertex (line 1) has one: give every vertex a colour or none"
        );
        assert_eq!(
            err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
            "4: face 1: corner 3 refers to vertex 4, but there are only 3 vertices"
        );
        assert_eq!(
            err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n"),
            "4: face 1: corner 3: expected an index from 1 (or negative), found 0"
        );
        assert_eq!(
            err("v 0 0 0\nf -1 -2 -3\n"),
            "2: face 1: corner 2: relative index -2 reaches before the first vertex (1 vertices read so far)"
        );
        assert_eq!(
            err("v 0 0 0\nv 1 0 0\nf 1 2\n"),
            "3: face 1: expected at least 3 corners, found 2"
        );
        assert_eq!(
            err("v 0 0 0\nf 1 a 3\n"),
            "2: face 1: corner 2: expected a vertex index, found \"a\""
        );
        assert_eq!(
            err("curv 0 1 2\n"),
            "1: unknown statement \"curv\" (expected v, f or t)"
        );
        assert_eq!(
            err("t crease 2/1/0 0 1\n"),
            "1: tag crease: the counts 2/1/0 announce 3 arguments, found 2"
        );
        assert_eq!(
            err("t hole 1/0/0 0\n"),
            "1: tag hole: not supported (supported: crease, corner, interpolateboundary, creasemethod)"
        );
        assert_eq!(
            err("v 0 0 0\nt corner 1/1/0 3 1\n"),
            "2: tag corner: vertex 3 (0-based) does not exist (there are 1 vertices)"
        );
        assert_eq!(
            err("t crease 2/1/0 0 1 -1\n"),
            "1: tag crease: expected a sharpness >= 0, found -1"
        );
    }

    #[test]
    fn refined_obj_output() {
        let topology = Topology::from_faces(3, &[vec![0, 1, 2]]).unwrap();
        let data = [
            [0.0, 0.0, 50.0, 0.0, 0.0, 1.0],
            [1.5, 0.0, 60.0, 0.1, 2.0, 0.5],
            [0.0, 1e-7, 70.0, -1.0, 0.0, 1.0],
        ]
        .map(VertexData::from_array);
        let text = write_refined_obj(&[(Some("a"), &topology, &data), (None, &topology, &data)]);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[1], "o a");
        assert_eq!(lines[3], "v 1.5 0 0 60 0.1 2");
        assert_eq!(lines[5], "f 1 2 3");
        assert_eq!(*lines.last().unwrap(), "f 4 5 6");
        // Numbers read back exactly.
        let y: f64 = lines[4].split(' ').nth(2).unwrap().parse().unwrap();
        assert_eq!(y, 1e-7);
    }
}
