//! Mesh gradient elements: the `href` chain, the attributes, and the grid of patches their
//! stops describe, in the gradient's own coordinates.

use std::collections::HashMap;

use kurbo::{Affine, CubicBez, Point, Vec2};
use roxmltree::{Node, NodeId};

use super::attr::{self, error_at, is_svg_element, limit_at, warning_at};
use super::scene::{Corner, MeshGrid, MeshType};
use crate::error::{Error, Warning, WarningKind};

/// Element names of a mesh gradient: SVG 2 draft, Inkscape 0.91, Inkscape 0.92 pre-releases.
pub(super) const MESH_GRADIENT: [&str; 3] = ["meshgradient", "meshGradient", "mesh"];
const MESH_ROW: [&str; 2] = ["meshrow", "meshRow"];
const MESH_PATCH: [&str; 2] = ["meshpatch", "meshPatch"];

/// What `x`, `y` and the stop paths are measured in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Units {
    /// The user space of the shape that is filled.
    UserSpaceOnUse,
    /// Fractions of the shape's bounding box (the initial value).
    ObjectBoundingBox,
}

/// A mesh gradient with its `href` chain resolved: each attribute comes from the nearest
/// element of the chain that sets it, the rows from the nearest one that has rows.
pub(super) struct MeshGradient<'a, 'input> {
    /// The element the shape names.
    pub node: Node<'a, 'input>,
    /// The element whose rows make the mesh.
    pub rows_from: Node<'a, 'input>,
    /// `x` and the element it is on.
    pub x: Option<(Node<'a, 'input>, &'a str)>,
    /// `y` and the element it is on.
    pub y: Option<(Node<'a, 'input>, &'a str)>,
    /// `gradientUnits`.
    pub units: Units,
    /// `gradientTransform` (Inkscape's name; the draft's `transform` is read too).
    pub transform: Affine,
    /// `type`.
    pub kind: MeshType,
}

/// Whether `node` is a mesh gradient element.
pub(super) fn is_mesh_gradient(node: Node) -> bool {
    is_svg_element(node, &MESH_GRADIENT)
}

/// Follows the `href` chain of the mesh gradient `node`. A reference to another kind of
/// element ends the chain: Inkscape 0.91 points its meshes at the linear gradient that holds
/// the colours it started from.
pub(super) fn resolve<'a, 'input>(
    node: Node<'a, 'input>,
    ids: &HashMap<&'a str, Node<'a, 'input>>,
    warnings: &mut Vec<Warning>,
) -> Result<MeshGradient<'a, 'input>, Error> {
    let mut chain = vec![node];
    let mut seen: Vec<NodeId> = vec![node.id()];
    let mut current = node;
    while let Some(text) = attr::href(current) {
        let id = attr::local_reference(current, "href", text)?;
        let target = *ids
            .get(id)
            .ok_or_else(|| error_at(current, format!("href names #{id}, which no element has")))?;
        if !is_mesh_gradient(target) {
            break;
        }
        if seen.contains(&target.id()) {
            return Err(error_at(
                node,
                format!("its href chain loops back to #{id}"),
            ));
        }
        seen.push(target.id());
        chain.push(target);
        current = target;
    }
    let find = |name: &str| {
        chain
            .iter()
            .find_map(|n| n.attribute(name).map(|v| (*n, v)))
    };
    let rows_from = chain
        .iter()
        .copied()
        .find(|n| n.children().any(|c| is_svg_element(c, &MESH_ROW)))
        .ok_or_else(|| error_at(node, "the mesh gradient has no meshrow"))?;
    let units = match find("gradientUnits") {
        None => Units::ObjectBoundingBox,
        Some((_, "objectBoundingBox")) => Units::ObjectBoundingBox,
        Some((_, "userSpaceOnUse")) => Units::UserSpaceOnUse,
        Some((n, other)) => {
            return Err(error_at(
                n,
                format!("gradientUnits {other:?} is neither userSpaceOnUse nor objectBoundingBox"),
            ))
        }
    };
    let transform = match find("gradientTransform").or_else(|| find("transform")) {
        Some((n, _)) if n.has_attribute("gradientTransform") => {
            attr::transform_attribute(n, "gradientTransform")?
        }
        Some((n, _)) => attr::transform_attribute(n, "transform")?,
        None => Affine::IDENTITY,
    };
    let kind = match find("type") {
        None | Some((_, "bilinear")) => MeshType::Bilinear,
        Some((_, "coons")) => MeshType::Coons,
        Some((_, "bicubic")) => MeshType::Bicubic,
        Some((n, other)) => {
            warnings.push(warning_at(
                n,
                WarningKind::SvgReadDifferently,
                format!("type {other:?} is not bilinear, coons or bicubic: read as bilinear"),
            ));
            MeshType::Bilinear
        }
    };
    Ok(MeshGradient {
        node,
        rows_from,
        x: find("x"),
        y: find("y"),
        units,
        transform,
        kind,
    })
}

/// The patch counts of the gradient's rows, checked to form a grid within `max_patches`
/// before anything is allocated for it.
fn grid_size(rows_from: Node, max_patches: u64) -> Result<(usize, usize), Error> {
    let mut rows = 0usize;
    let mut columns = 0usize;
    for row in rows_from
        .children()
        .filter(|c| is_svg_element(*c, &MESH_ROW))
    {
        let count = patches(row).count();
        if rows == 0 {
            columns = count;
        } else if count != columns {
            return Err(error_at(
                row,
                format!("the row has {count} patches, but the first row has {columns}; every row must have the same number"),
            ));
        }
        rows += 1;
        let total = (rows as u64).saturating_mul(columns as u64);
        if total > max_patches {
            return Err(limit_at(
                rows_from,
                "the number of mesh patches".into(),
                total,
                max_patches,
            ));
        }
    }
    if columns == 0 {
        return Err(error_at(rows_from, "the first meshrow has no meshpatch"));
    }
    Ok((rows, columns))
}

fn patches<'a, 'input>(row: Node<'a, 'input>) -> impl Iterator<Item = Node<'a, 'input>> {
    row.children().filter(|c| is_svg_element(*c, &MESH_PATCH))
}

/// A corner of the grid: (row, column).
type CornerAt = (usize, usize);

/// One side of a patch, in the order its stops give them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Top,
    Right,
    Bottom,
    Left,
}

/// The sides the stops of patch `(r, c)` describe, with the corners each runs between: sides
/// shared with the patch above or to the left are left out of the file.
fn sides_of(r: usize, c: usize) -> Vec<(Side, CornerAt, CornerAt)> {
    let mut sides = Vec::with_capacity(4);
    if r == 0 {
        sides.push((Side::Top, (r, c), (r, c + 1)));
    }
    sides.push((Side::Right, (r, c + 1), (r + 1, c + 1)));
    sides.push((Side::Bottom, (r + 1, c + 1), (r + 1, c)));
    if c == 0 {
        sides.push((Side::Left, (r + 1, c), (r, c)));
    }
    sides
}

/// The grid of the gradient in its own coordinates (before units and transforms), with `x`
/// and `y` already read into `origin`.
pub(super) fn read_grid(
    gradient: &MeshGradient,
    origin: Point,
    max_patches: u64,
    warnings: &mut Vec<Warning>,
) -> Result<MeshGrid, Error> {
    let (rows, columns) = grid_size(gradient.rows_from, max_patches)?;
    let mut builder = GridBuilder::new(rows, columns, origin);
    let row_nodes = gradient
        .rows_from
        .children()
        .filter(|c| is_svg_element(*c, &MESH_ROW));
    for (r, row) in row_nodes.enumerate() {
        for (c, patch) in patches(row).enumerate() {
            builder.read_patch(patch, r, c, warnings)?;
        }
    }
    builder.finish(gradient.node, gradient.kind)
}

/// The grid as it fills up, patch by patch.
struct GridBuilder {
    rows: usize,
    columns: usize,
    positions: Vec<Option<Point>>,
    colours: Vec<Option<([f64; 3], f64)>>,
    row_sides: Vec<Option<CubicBez>>,
    column_sides: Vec<Option<CubicBez>>,
}

impl GridBuilder {
    fn new(rows: usize, columns: usize, origin: Point) -> Self {
        let corners = (rows + 1) * (columns + 1);
        let mut positions = vec![None; corners];
        positions[0] = Some(origin);
        GridBuilder {
            rows,
            columns,
            positions,
            colours: vec![None; corners],
            row_sides: vec![None; (rows + 1) * columns],
            column_sides: vec![None; rows * (columns + 1)],
        }
    }

    fn corner_index(&self, (i, j): (usize, usize)) -> usize {
        i * (self.columns + 1) + j
    }

    /// Reads the stops of patch `(r, c)`: the sides it adds, and the colours of the corners
    /// its stops start from that no earlier stop gave.
    fn read_patch(
        &mut self,
        patch: Node,
        r: usize,
        c: usize,
        warnings: &mut Vec<Warning>,
    ) -> Result<(), Error> {
        let sides = sides_of(r, c);
        let mut stops = patch.children().filter(|n| is_svg_element(*n, &["stop"]));
        for (k, &(side, start, end)) in sides.iter().enumerate() {
            let stop = stops.next().ok_or_else(|| {
                error_at(
                    patch,
                    format!(
                        "the patch in row {r}, column {c} has {k} stops; it needs {} (one per side not shared with an earlier patch)",
                        sides.len()
                    ),
                )
            })?;
            let (s, e) = (self.corner_index(start), self.corner_index(end));
            let from = self.positions[s].ok_or_else(|| {
                error_at(stop, "the side starts at a corner no earlier side reached")
            })?;
            let curve = read_side(stop, from, self.positions[e])?;
            self.positions[e].get_or_insert(curve.p3);
            if self.colours[s].is_none() {
                self.colours[s] = Some(stop_colour(stop)?);
            }
            let reversed = CubicBez::new(curve.p3, curve.p2, curve.p1, curve.p0);
            match side {
                Side::Top => self.row_sides[r * self.columns + c] = Some(curve),
                Side::Right => self.column_sides[r * (self.columns + 1) + c + 1] = Some(curve),
                Side::Bottom => self.row_sides[(r + 1) * self.columns + c] = Some(reversed),
                Side::Left => self.column_sides[r * (self.columns + 1) + c] = Some(reversed),
            }
        }
        if let Some(extra) = stops.next() {
            warnings.push(warning_at(
                extra,
                WarningKind::SvgReadDifferently,
                format!(
                    "the patch in row {r}, column {c} needs {} stops: the rest are ignored",
                    sides.len()
                ),
            ));
        }
        Ok(())
    }

    fn finish(self, node: Node, kind: MeshType) -> Result<MeshGrid, Error> {
        let incomplete = || error_at(node, "the mesh is incomplete");
        let corners = self
            .positions
            .iter()
            .zip(&self.colours)
            .map(|(p, c)| {
                let (colour, opacity) = c.ok_or_else(incomplete)?;
                Ok(Corner {
                    position: p.ok_or_else(incomplete)?,
                    colour,
                    opacity,
                })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        let all = |sides: Vec<Option<CubicBez>>| sides.into_iter().collect::<Option<Vec<_>>>();
        Ok(MeshGrid {
            kind,
            rows: self.rows,
            columns: self.columns,
            corners,
            row_sides: all(self.row_sides).ok_or_else(incomplete)?,
            column_sides: all(self.column_sides).ok_or_else(incomplete)?,
        })
    }
}

/// The colour and opacity of a stop: `stop-color` (black when absent) and `stop-opacity`
/// times the colour's own alpha.
fn stop_colour(stop: Node) -> Result<([f64; 3], f64), Error> {
    let (rgb, alpha) = match attr::own_property(stop, "stop-color") {
        Some(text) if text != "inherit" => attr::colour(stop, "stop-color", text)?,
        _ => ([0.0; 3], 1.0),
    };
    Ok((rgb, alpha * attr::own_opacity(stop, "stop-opacity")?))
}

/// The side a stop's `path` draws from `from`: one `l`, `L`, `c` or `C` command. When the end
/// corner is already known (`to`), the side closes its patch: the path may leave out its end
/// point, and an end point it gives is ignored, as Inkscape does.
fn read_side(stop: Node, from: Point, to: Option<Point>) -> Result<CubicBez, Error> {
    let text = stop
        .attribute("path")
        .ok_or_else(|| error_at(stop, "the stop has no path"))?
        .trim();
    let mut chars = text.chars();
    let command = chars.next().unwrap_or(' ');
    let not_one_command = || {
        error_at(
            stop,
            format!("path {text:?} is not one l, L, c or C command"),
        )
    };
    if !matches!(command, 'l' | 'L' | 'c' | 'C') {
        return Err(not_one_command());
    }
    let mut numbers = Vec::with_capacity(6);
    for n in svgtypes::NumberListParser::from(chars.as_str()).take(7) {
        let n = n.map_err(|_| not_one_command())?;
        numbers.push(attr::finite(stop, "a path coordinate", n)?);
    }
    let absolute = command.is_ascii_uppercase();
    let point = |k: usize| {
        let v = Vec2::new(numbers[k], numbers[k + 1]);
        if absolute {
            v.to_point()
        } else {
            from + v
        }
    };
    let third = |a: Point, b: Point, t: f64| a.lerp(b, t);
    match (command.to_ascii_lowercase(), numbers.len(), to) {
        ('l', 2, None) => {
            let end = point(0);
            Ok(CubicBez::new(
                from,
                third(from, end, 1.0 / 3.0),
                third(from, end, 2.0 / 3.0),
                end,
            ))
        }
        ('l', 0 | 2, Some(end)) => Ok(CubicBez::new(
            from,
            third(from, end, 1.0 / 3.0),
            third(from, end, 2.0 / 3.0),
            end,
        )),
        ('c', 6, None) => Ok(CubicBez::new(from, point(0), point(2), point(4))),
        ('c', 4 | 6, Some(end)) => Ok(CubicBez::new(from, point(0), point(2), end)),
        (_, found, to) => {
            let expected = match (command.to_ascii_lowercase(), to) {
                ('l', None) => "2 numbers",
                ('l', Some(_)) => "2 numbers, or none on a side that closes its patch",
                (_, None) => "6 numbers",
                (_, Some(_)) => "6 numbers, or 4 on a side that closes its patch",
            };
            Err(error_at(
                stop,
                format!("path {text:?}: {command} takes {expected}, found {found}"),
            ))
        }
    }
}
