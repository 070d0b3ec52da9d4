//! Pixar's creasing rules for Catmull-Clark subdivision, as OpenSubdiv's `Sdc` applies them.
//!
//! Only rules: which vertex rule applies, how sharpness decays, and how a vertex whose rule
//! changes between levels blends the two masks. No mesh type appears here.

use crate::scheme::{CreasingMethod, SHARPNESS_INFINITE};

/// The rule that computes a vertex point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum VertexRule {
    /// No sharp incident edge.
    Smooth,
    /// Exactly one sharp incident edge: smooth mask.
    Dart,
    /// Exactly two sharp incident edges: the cubic B-spline curve rule along them.
    Crease,
    /// A sharp vertex, or three or more sharp incident edges: the vertex stays put.
    Corner,
}

/// Whether a sharpness counts as sharp.
pub fn is_sharp(s: f64) -> bool {
    s > 0.0
}

/// Whether a sharpness is infinite.
pub fn is_infinite(s: f64) -> bool {
    s >= SHARPNESS_INFINITE
}

/// The vertex rule from the vertex's own sharpness and the number of sharp incident edges.
pub fn vertex_rule(vertex_sharpness: f64, sharp_edge_count: usize) -> VertexRule {
    if is_sharp(vertex_sharpness) {
        return VertexRule::Corner;
    }
    match sharp_edge_count {
        0 => VertexRule::Smooth,
        1 => VertexRule::Dart,
        2 => VertexRule::Crease,
        _ => VertexRule::Corner,
    }
}

/// Sharpness after one level, for sharpness that does not depend on neighbours.
pub fn decrement_sharpness(s: f64) -> f64 {
    if is_infinite(s) {
        SHARPNESS_INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

/// Sharpness of the child edge at vertex end `v` of a parent edge of sharpness `s`, given the
/// sharpness of all edges incident to `v` (OpenSubdiv's `SubdivideEdgeSharpnessAtVertex`).
pub fn child_edge_sharpness(method: CreasingMethod, s: f64, incident: &[f64]) -> f64 {
    if method == CreasingMethod::Uniform || incident.len() < 2 {
        return decrement_sharpness(s);
    }
    if !is_sharp(s) {
        return 0.0;
    }
    if is_infinite(s) {
        return SHARPNESS_INFINITE;
    }
    let semi: Vec<f64> = incident
        .iter()
        .copied()
        .filter(|&x| is_sharp(x) && !is_infinite(x))
        .collect();
    let mut s = s;
    if semi.len() > 1 {
        // Chaikin: three quarters of its own sharpness, a quarter of the others' average.
        let others = (semi.iter().sum::<f64>() - s) / (semi.len() - 1) as f64;
        s = 0.75 * s + 0.25 * others;
    }
    s -= 1.0;
    if is_sharp(s) {
        s
    } else {
        0.0
    }
}

/// The weight of the parent rule's mask when a vertex's rule relaxes from one level to the next
/// (OpenSubdiv's `ComputeFractionalWeightAtVertex`): the average parent sharpness of the features
/// that become smooth, at most 1.
pub fn fractional_weight(
    parent_vertex: f64,
    child_vertex: f64,
    parent_edges: &[f64],
    child_edges: &[f64],
) -> f64 {
    let mut count = 0usize;
    let mut sum = 0.0;
    if is_sharp(parent_vertex) && !is_sharp(child_vertex) {
        count += 1;
        sum += parent_vertex;
    }
    for (&p, &c) in parent_edges.iter().zip(child_edges) {
        if is_sharp(p) && !is_sharp(c) {
            count += 1;
            sum += p;
        }
    }
    if count == 0 {
        0.0
    } else {
        (sum / count as f64).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_by_sharp_edge_count() {
        assert_eq!(vertex_rule(0.0, 0), VertexRule::Smooth);
        assert_eq!(vertex_rule(0.0, 1), VertexRule::Dart);
        assert_eq!(vertex_rule(0.0, 2), VertexRule::Crease);
        assert_eq!(vertex_rule(0.0, 3), VertexRule::Corner);
        assert_eq!(vertex_rule(0.5, 0), VertexRule::Corner);
    }

    #[test]
    fn sharpness_decays() {
        assert_eq!(decrement_sharpness(2.5), 1.5);
        assert_eq!(decrement_sharpness(0.5), 0.0);
        assert_eq!(decrement_sharpness(SHARPNESS_INFINITE), SHARPNESS_INFINITE);
        // Chaikin: 0.75 * 2 + 0.25 * 4 - 1 = 1.5.
        let s = child_edge_sharpness(CreasingMethod::Chaikin, 2.0, &[2.0, 4.0, 0.0]);
        assert!((s - 1.5).abs() < 1e-12);
        assert_eq!(
            child_edge_sharpness(CreasingMethod::Uniform, 2.0, &[2.0, 4.0]),
            1.0
        );
    }

    #[test]
    fn fractional_weight_averages_transitions() {
        assert_eq!(fractional_weight(0.0, 0.0, &[0.5, 0.3], &[0.0, 0.0]), 0.4);
        assert_eq!(fractional_weight(0.0, 0.0, &[3.0, 3.0], &[2.0, 2.0]), 0.0);
        assert_eq!(fractional_weight(0.0, 0.0, &[1.5, 0.0], &[0.0, 0.0]), 1.0);
    }
}
