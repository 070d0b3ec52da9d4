//! Masks made of mesh gradients over mesh fills. gradmesh's SVG export writes a translucent
//! layer as opaque meshes in a group whose luminance mask holds the same meshes in grey (each
//! corner's opacity as its grey), so that a viewer paints no seams where meshes overlap. Such
//! a mask is read back into the opacity of the masked meshes' corners.

use kurbo::Point;

use super::scene::{MeshFill, MeshGrid};

/// The luminance of an sRGB colour as a luminance mask takes it (CSS Masking: the
/// coefficients on the colour's values, in sRGB as `color-interpolation` is by default).
fn luminance([r, g, b]: [f64; 3]) -> f64 {
    (0.2125 * r + 0.7154 * g + 0.0721 * b).clamp(0.0, 1.0)
}

/// Whether two corners, read from the same text through the same transforms, are at the same
/// place.
fn same_place(a: Point, b: Point) -> bool {
    (a - b).hypot() <= 1e-9 * (1.0 + a.to_vec2().hypot())
}

/// Whether `masks` match `fills` one for one: as many, each with the rows, columns and corner
/// positions of its fill's mesh.
fn matches(fills: &[MeshFill], masks: &[MeshGrid]) -> bool {
    fills.len() == masks.len()
        && fills.iter().zip(masks).all(|(fill, mask)| {
            let mesh = &fill.mesh;
            (mesh.rows, mesh.columns) == (mask.rows, mask.columns)
                && mesh
                    .corners
                    .iter()
                    .zip(&mask.corners)
                    .all(|(a, b)| same_place(a.position, b.position))
        })
}

/// Multiplies the opacity of each corner of `fills` by the luminance times the opacity of the
/// corner at the same place of `masks[k]` (for `fills[k]`), when the two match one for one.
/// Returns whether they did (otherwise nothing changes).
pub(super) fn apply_luminance_mask(fills: &mut [MeshFill], masks: &[MeshGrid]) -> bool {
    if !matches(fills, masks) {
        return false;
    }
    for (fill, mask) in fills.iter_mut().zip(masks) {
        for (corner, by) in fill.mesh.corners.iter_mut().zip(&mask.corners) {
            corner.opacity *= luminance(by.colour) * by.opacity;
        }
    }
    true
}
