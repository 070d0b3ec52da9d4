//! Import of the paper authors' extended OFF ("version 3" of their tool).
//!
//! ```text
//! OFF
//! nV nF colour_mode
//! x y z c1 c2 c3 n j_1 .. j_n dx_1 dy_1 .. dx_n dy_n u_0 .. u_n     (nV vertex lines)
//! k i_1 .. i_k                                                      (nF face lines)
//! ```
//!
//! `colour_mode` 0 is CIE Lab (D65, L in 0..100), 1 is non-linear sRGB in 0..1; `z` is ignored;
//! `(dx_k, dy_k)` is the handle of the vertex towards its neighbour `j_k`; the `n + 1` trailing
//! values are unused (the authors' tool writes zeros) and may be left out. Blank lines are
//! skipped, as is text after `#`.

use std::collections::HashSet;

use kurbo::{Point, Vec2};

use crate::colour::ColourSpace;
use crate::error::{Error, ErrorKind};
use crate::mesh::{edge_key, ControlPoint, GradientMesh};
use crate::size_limits::Limits;

use super::{check_count, check_size, error_at, syntax_error};

/// Reservations made from declared counts are capped at this many elements; vectors grow past
/// it as the lines are actually read.
const RESERVE_CAP: usize = 1 << 16;

/// The non-blank lines of a text, numbered from 1, without `#` comments.
struct Lines<'a> {
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    last: usize,
}

impl<'a> Lines<'a> {
    fn new(text: &'a str) -> Self {
        Lines {
            inner: text.lines().enumerate(),
            last: 0,
        }
    }

    /// The next non-blank line: its number and its tokens.
    fn next_tokens(&mut self) -> Option<(usize, Vec<&'a str>)> {
        for (i, line) in self.inner.by_ref() {
            self.last = i + 1;
            let content = line.split('#').next().unwrap_or("");
            let tokens: Vec<&str> = content.split_whitespace().collect();
            if !tokens.is_empty() {
                return Some((i + 1, tokens));
            }
        }
        None
    }

    /// The error for a file that ends where `expected` should follow.
    fn eof(&self, expected: String) -> Error {
        syntax_error(
            self.last.max(1),
            format!("unexpected end of file: expected {expected}"),
        )
    }
}

// `what` names the field for an error message: built only when there is one (formatting it
// for every token was most of the time reading a file took).
fn parse_int(token: &str, what: impl Fn() -> String, line: usize) -> Result<u64, Error> {
    token.parse::<u64>().map_err(|_| {
        syntax_error(
            line,
            format!(
                "{}: expected a whole number >= 0, found \"{token}\"",
                what()
            ),
        )
    })
}

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

/// Reads the authors' extended OFF into one gradient mesh.
///
/// Every error names the line (1-based) and says what was expected and what was found: a
/// missing `OFF` line, counts that do not match the lines, words or non-finite values where
/// numbers belong, indices out of range, a truncated file, text after the last face. Declared
/// counts above the default [`Limits`] are refused before anything is allocated for them. A
/// handle towards a vertex that shares no face edge with its vertex is an error naming the
/// vertex's line.
pub fn read_off(text: &str) -> Result<GradientMesh, Error> {
    read_off_with_limits(text, &Limits::DEFAULT)
}

/// Reads the authors' extended OFF as [`read_off`] does, within `limits`: input bytes, declared
/// vertex and face counts (refused on the counts line), and corners summed over the faces.
pub fn read_off_with_limits(text: &str, limits: &Limits) -> Result<GradientMesh, Error> {
    check_size(text.len() as u64, limits.input_bytes)?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines = Lines::new(text);
    read_off_line(&mut lines)?;
    let (nv, nf, colour_space) = read_counts(&mut lines, limits)?;

    let mut mesh = GradientMesh::new(colour_space);
    mesh.points.reserve(nv.min(RESERVE_CAP));
    mesh.faces.reserve(nf.min(RESERVE_CAP));
    // Handles with the line they came from, checked against the faces at the end.
    let mut handle_lines: Vec<(u32, u32, usize)> = Vec::new();
    for v in 0..nv {
        let (line, t) = lines.next_tokens().ok_or_else(|| {
            lines.eof(format!(
                "the line of vertex {v} (the header declares {nv} vertices)"
            ))
        })?;
        read_vertex(&t, v, nv, line, &mut mesh, &mut handle_lines)?;
    }
    let edges = read_faces(&mut lines, nv, nf, limits, &mut mesh)?;

    if let Some((line, t)) = lines.next_tokens() {
        return Err(syntax_error(
            line,
            format!(
                "expected the end of the file after {nf} faces, found \"{}\"",
                t.join(" ")
            ),
        ));
    }
    for (v, j, line) in handle_lines {
        if !edges.contains(&edge_key(v, j)) {
            return Err(error_at(
                line,
                ErrorKind::NoSuchEdge {
                    what: format!("the handle of vertex {v} towards its neighbour {j}"),
                    a: v,
                    b: j,
                },
            ));
        }
    }
    Ok(mesh)
}

/// The first line: `OFF`.
fn read_off_line(lines: &mut Lines) -> Result<(), Error> {
    match lines.next_tokens() {
        Some((_, t)) if t == ["OFF"] => Ok(()),
        Some((line, t)) => Err(syntax_error(
            line,
            format!("expected \"OFF\", found \"{}\"", t.join(" ")),
        )),
        None => Err(lines.eof("\"OFF\"".into())),
    }
}

/// The counts line `nV nF colour_mode`: the numbers of vertices and faces, within `limits`,
/// and the colour space.
fn read_counts(lines: &mut Lines, limits: &Limits) -> Result<(usize, usize, ColourSpace), Error> {
    let (line, t) = lines
        .next_tokens()
        .ok_or_else(|| lines.eof("the counts \"nV nF colour_mode\"".into()))?;
    if t.len() != 3 {
        return Err(syntax_error(
            line,
            format!(
                "expected 3 numbers \"nV nF colour_mode\", found {} values \"{}\"",
                t.len(),
                t.join(" ")
            ),
        ));
    }
    let nv = parse_int(t[0], || "the number of vertices".into(), line)?;
    let nf = parse_int(t[1], || "the number of faces".into(), line)?;
    check_count("the number of vertices", nv, limits.points).map_err(|e| located(e, line))?;
    check_count("the number of faces", nf, limits.faces).map_err(|e| located(e, line))?;
    let colour_space = match t[2] {
        "0" => ColourSpace::Lab,
        "1" => ColourSpace::Srgb,
        other => {
            return Err(syntax_error(
                line,
                format!("colour_mode: expected 0 (CIE Lab) or 1 (sRGB), found \"{other}\""),
            ))
        }
    };
    Ok((nv as usize, nf as usize, colour_space))
}

/// The line of vertex `v` (of `nv`): `x y z c1 c2 c3 n j_1 .. j_n dx_1 dy_1 .. [u_0 .. u_n]`.
/// Pushes the point to `mesh`, its handles to `mesh` and `handle_lines`.
fn read_vertex(
    t: &[&str],
    v: usize,
    nv: usize,
    line: usize,
    mesh: &mut GradientMesh,
    handle_lines: &mut Vec<(u32, u32, usize)>,
) -> Result<(), Error> {
    let what = |field: &str| format!("vertex {v}: {field}");
    if t.len() < 7 {
        return Err(syntax_error(
            line,
            format!(
                "vertex {v}: expected at least 7 values \"x y z c1 c2 c3 n\", found {}",
                t.len()
            ),
        ));
    }
    let x = parse_num(t[0], || what("x"), line)?;
    let y = parse_num(t[1], || what("y"), line)?;
    parse_num(t[2], || what("z"), line)?;
    let mut colour = [0.0; 3];
    for (k, c) in colour.iter_mut().enumerate() {
        *c = parse_num(
            t[3 + k],
            || what(&format!("colour channel {}", k + 1)),
            line,
        )?;
    }
    let n = parse_int(t[6], || what("the number of neighbours n"), line)?;
    if n > t.len() as u64 {
        return Err(syntax_error(
            line,
            format!(
                "vertex {v}: the number of neighbours n = {n} is more than the {} values \
                 of the line",
                t.len()
            ),
        ));
    }
    // Saturating: a huge n must not wrap around to the length of the line.
    let (short, long) = (
        n.saturating_mul(3).saturating_add(7),
        n.saturating_mul(4).saturating_add(8),
    );
    if t.len() as u64 != short && t.len() as u64 != long {
        return Err(syntax_error(
            line,
            format!(
                "vertex {v}: with n = {n} neighbours expected {short} values (7 + 3n), or {long} \
                 with the n + 1 unused ones, found {}",
                t.len()
            ),
        ));
    }
    let n = n as usize;
    read_handles(t, v, nv, n, line, mesh, handle_lines)?;
    for (k, token) in t[7 + 3 * n..].iter().enumerate() {
        parse_num(token, || what(&format!("unused value {}", k + 1)), line)?;
    }
    mesh.points
        .push(ControlPoint::new(Point::new(x, y), colour));
    Ok(())
}

/// The `n` neighbours and handles of vertex `v` (of `nv`) on its line `t`.
fn read_handles(
    t: &[&str],
    v: usize,
    nv: usize,
    n: usize,
    line: usize,
    mesh: &mut GradientMesh,
    handle_lines: &mut Vec<(u32, u32, usize)>,
) -> Result<(), Error> {
    let what = |field: &str| format!("vertex {v}: {field}");
    let mut seen = HashSet::with_capacity(n);
    for k in 0..n {
        let j = parse_int(t[7 + k], || what(&format!("neighbour {}", k + 1)), line)?;
        if j >= nv as u64 {
            return Err(syntax_error(
                line,
                format!(
                    "vertex {v}: neighbour {} is {j}, but there are only {nv} vertices",
                    k + 1
                ),
            ));
        }
        if j == v as u64 {
            return Err(syntax_error(
                line,
                format!("vertex {v}: neighbour {} is the vertex itself", k + 1),
            ));
        }
        if !seen.insert(j) {
            return Err(syntax_error(
                line,
                format!("vertex {v}: neighbour {j} is listed twice"),
            ));
        }
        let dx = parse_num(
            t[7 + n + 2 * k],
            || what(&format!("handle {} dx", k + 1)),
            line,
        )?;
        let dy = parse_num(
            t[8 + n + 2 * k],
            || what(&format!("handle {} dy", k + 1)),
            line,
        )?;
        mesh.handles.insert((v as u32, j as u32), Vec2::new(dx, dy));
        handle_lines.push((v as u32, j as u32, line));
    }
    Ok(())
}

/// The `nf` face lines `k i_1 .. i_k` over `nv` vertices, pushed to `mesh`; returns the edges
/// of the faces.
fn read_faces(
    lines: &mut Lines,
    nv: usize,
    nf: usize,
    limits: &Limits,
    mesh: &mut GradientMesh,
) -> Result<HashSet<(u32, u32)>, Error> {
    let mut edges = HashSet::new();
    let mut corner_count = 0u64;
    for f in 0..nf {
        let (line, t) = lines.next_tokens().ok_or_else(|| {
            lines.eof(format!(
                "the line of face {f} (the header declares {nf} faces)"
            ))
        })?;
        let k = parse_int(t[0], || format!("face {f}: the number of corners"), line)?;
        if k < 3 {
            return Err(syntax_error(
                line,
                format!("face {f}: expected at least 3 corners, found {k}"),
            ));
        }
        corner_count = corner_count.saturating_add(k);
        check_count("the number of corners", corner_count, limits.corners)
            .map_err(|e| located(e, line))?;
        if t.len() as u64 != k + 1 {
            return Err(syntax_error(
                line,
                format!(
                    "face {f}: declares {k} corners, found {} indices",
                    t.len() - 1
                ),
            ));
        }
        let corners = face_corners(&t[1..], f, nv, line)?;
        for c in 0..corners.len() {
            edges.insert(edge_key(corners[c], corners[(c + 1) % corners.len()]));
        }
        mesh.faces.push(corners);
    }
    Ok(edges)
}

/// The corners of face `f` over `nv` vertices, from their tokens.
fn face_corners(tokens: &[&str], f: usize, nv: usize, line: usize) -> Result<Vec<u32>, Error> {
    let mut corners = Vec::with_capacity(tokens.len());
    // A set, not a search of the corners so far: faces may have millions of corners.
    let mut seen_corners = HashSet::with_capacity(tokens.len());
    for (c, token) in tokens.iter().enumerate() {
        let i = parse_int(token, || format!("face {f}: corner {c}"), line)?;
        if i >= nv as u64 {
            return Err(error_at(
                line,
                ErrorKind::IndexOutOfRange {
                    face: f,
                    corner: c,
                    index: i,
                    count: nv,
                },
            ));
        }
        if !seen_corners.insert(i) {
            return Err(error_at(
                line,
                ErrorKind::DegenerateFace {
                    face: f,
                    reason: format!("vertex {i} appears twice"),
                },
            ));
        }
        corners.push(i as u32);
    }
    Ok(corners)
}

fn located(mut e: Error, line: usize) -> Error {
    e.location.line = Some(line);
    e
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square split into two quads, with handles on vertex 0.
    const TWO_QUADS: &str = "OFF
6 2 0
0 0 1 50 0 0 2 1 3 0.3 0 0 0.3 0 0 0
1 0 1 60 0 0 0 0
2 0 1 70 0 0 0 0
0 1 1 50 10 0 0 0
1 1 1 60 10 0 0 0
2 1 1 70 10 0 0

4 0 3 4 1
4 1 4 5 2
";

    fn err(text: &str) -> String {
        read_off(text).unwrap_err().to_string()
    }

    #[test]
    fn reads_points_handles_and_faces() {
        let m = read_off(TWO_QUADS).unwrap();
        assert_eq!(m.colour_space, ColourSpace::Lab);
        assert_eq!(m.points.len(), 6);
        assert_eq!(m.points[4].position, Point::new(1.0, 1.0));
        assert_eq!(m.points[3].colour, [50.0, 10.0, 0.0]);
        assert_eq!(m.handles.len(), 2);
        assert_eq!(m.handles[&(0, 1)], Vec2::new(0.3, 0.0));
        assert_eq!(m.handles[&(0, 3)], Vec2::new(0.0, 0.3));
        assert_eq!(m.faces, vec![vec![0, 3, 4, 1], vec![1, 4, 5, 2]]);
        crate::validate::validate(&m).unwrap();
    }

    #[test]
    fn colour_mode_one_is_srgb() {
        let text = TWO_QUADS.replacen("6 2 0", "6 2 1", 1);
        assert_eq!(read_off(&text).unwrap().colour_space, ColourSpace::Srgb);
        assert_eq!(
            err(&TWO_QUADS.replacen("6 2 0", "6 2 7", 1)),
            "2: colour_mode: expected 0 (CIE Lab) or 1 (sRGB), found \"7\""
        );
    }

    #[test]
    fn syntax_errors_name_the_line() {
        assert_eq!(err("COFF\n"), "1: expected \"OFF\", found \"COFF\"");
        assert_eq!(err(""), "1: unexpected end of file: expected \"OFF\"");
        assert_eq!(
            err("OFF\n3 1\n"),
            "2: expected 3 numbers \"nV nF colour_mode\", found 2 values \"3 1\""
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("60 0 0 0 0", "60 zero 0 0 0", 1)),
            "4: vertex 1: colour channel 2: expected a number, found \"zero\""
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("70 0 0 0 0", "70 0 NaN 0 0", 1)),
            "5: vertex 2: colour channel 3 is not a finite number (NaN)"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("1 0 1 60", "inf 0 1 60", 1)),
            "4: vertex 1: x is not a finite number (inf)"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("0 0.3 0 0 0", "0 0.3 0 0", 1)),
            "3: vertex 0: with n = 2 neighbours expected 13 values (7 + 3n), or 16 with the n + 1 unused ones, found 15"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("2 1 3 0.3", "2 1 9 0.3", 1)),
            "3: vertex 0: neighbour 2 is 9, but there are only 6 vertices"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("4 1 4 5 2", "4 1 4 5 6", 1)),
            "11: face 1: corner 3 refers to point 6, but there are only 6 points"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("4 1 4 5 2", "4 1 4 5", 1)),
            "11: face 1: declares 4 corners, found 3 indices"
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("4 1 4 5 2", "4 1 4 5 -2", 1)),
            "11: face 1: corner 3: expected a whole number >= 0, found \"-2\""
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("4 1 4 5 2\n", "", 1)),
            "10: unexpected end of file: expected the line of face 1 (the header declares 2 faces)"
        );
        assert_eq!(
            err(&format!("{TWO_QUADS}3 0 1 2\n")),
            "12: expected the end of the file after 2 faces, found \"3 0 1 2\""
        );
        assert_eq!(
            err(&TWO_QUADS.replacen("6 2 0", "6 2.5 0", 1)),
            "2: the number of faces: expected a whole number >= 0, found \"2.5\""
        );
    }

    #[test]
    fn handle_towards_a_non_neighbour_is_refused() {
        // Vertex 0 and vertex 4 are opposite corners of a quad: no edge joins them.
        let text = TWO_QUADS.replacen("2 1 3 0.3 0 0 0.3", "2 1 4 0.3 0 0 0.3", 1);
        assert_eq!(
            err(&text),
            "3: the handle of vertex 0 towards its neighbour 4 names edge 0-4, which is not an edge of any face"
        );
    }

    #[test]
    fn enormous_counts_are_refused_before_allocation() {
        let e = read_off("OFF\n100000000000 1 0\n").unwrap_err();
        assert_eq!(e.location.line, Some(2));
        assert!(matches!(
            e.kind,
            ErrorKind::LimitExceeded {
                found: 100_000_000_000,
                ..
            }
        ));
        // Below the limit but far more than the file holds: a plain truncation error.
        let e = read_off("OFF\n16000000 16000000 0\n0 0 1 50 0 0 0 0\n").unwrap_err();
        assert!(
            e.to_string().contains("expected the line of vertex 1"),
            "{e}"
        );
    }

    #[test]
    fn trailing_unused_values_are_optional_and_comments_are_skipped() {
        let text = "OFF # authors' format\n3 1 1\n0 0 0 1 0 0 0\n1 0 0 0 1 0 0 0\n0 1 0 0 0 1 0\n3 0 1 2\n";
        let m = read_off(text).unwrap();
        assert_eq!(m.points.len(), 3);
        assert_eq!(m.faces, vec![vec![0, 1, 2]]);
    }
}
