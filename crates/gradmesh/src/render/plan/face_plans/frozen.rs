//! A draft's plans: the counts and orders of an earlier preparation's balanced plans, kept
//! while a gesture moves points, with the faces the edit reached evaluated again and nothing
//! measured or balanced (see [`RenderOptions::draft`](crate::render::RenderOptions::draft)).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use super::{each_face, CachedPlan, FacePlanner, FacePlans, FaceSurface, Order, Plan};
use crate::limit_surface::patches::{regular_patch_with, LocalPatch};

/// One local refinement of the earlier preparation and the faces on it, by root.
type FrozenGroup = Vec<(usize, usize, Arc<Plan>)>;

impl FacePlanner<'_> {
    /// Every face's plan at the count and order of `frozen`, the balanced plans of an earlier
    /// preparation of the same faces: those marked in `again` evaluated on this planner's data
    /// (their figures are the earlier ones), the others taken as they are. Their counts are
    /// balanced already, so they need no [`balance`](FacePlanner::balance). `None` where a
    /// neighbourhood no longer forms a valid mesh: the caller then plans the faces.
    pub fn regrid_all(&self, frozen: &[CachedPlan], again: &[bool]) -> Option<FacePlans> {
        let nf = self.t.face_count();
        let regular: Vec<Option<Arc<Plan>>> = each_face(nf, |f| match &frozen[f] {
            CachedPlan::Regular(plan) if again[f] => {
                let cp = regular_patch_with(self.level, self.data, f, |v| self.regular[v])?;
                let plan = regridded(plan, &mut FaceSurface::Regular(cp))?;
                Some(Some(Arc::new(plan)))
            }
            CachedPlan::Regular(plan) => Some(Some(Arc::clone(plan))),
            CachedPlan::Local(..) => Some(None),
        })?;
        let mut reused: Vec<bool> = again.iter().map(|&a| !a).collect();
        let mut plans = regular;
        let mut local = vec![None; nf];
        let groups: Vec<FrozenGroup> = frozen_groups(frozen).into_values().collect();
        let regridded: Vec<_> = groups
            .par_iter()
            .map(|group| self.regrid_group(group, frozen, again))
            .collect::<Option<_>>()?;
        for group in regridded {
            for (f, plan, patch, root, kept) in group {
                plans[f] = Some(plan);
                local[f] = Some((patch, root));
                reused[f] = kept;
            }
        }
        let plans = plans.into_iter().collect::<Option<Vec<_>>>()?;
        Some(FacePlans {
            plans,
            local,
            reused,
        })
    }

    /// The faces of one earlier local refinement: as they were if the edit reached none of
    /// them, else on a local refinement of the same faces and this planner's data.
    #[allow(clippy::type_complexity)]
    fn regrid_group(
        &self,
        group: &FrozenGroup,
        frozen: &[CachedPlan],
        again: &[bool],
    ) -> Option<Vec<(usize, Arc<Plan>, Arc<Mutex<LocalPatch>>, usize, bool)>> {
        if !group.iter().any(|&(_, f, _)| again[f]) {
            return group
                .iter()
                .map(|&(root, f, ref plan)| match &frozen[f] {
                    CachedPlan::Local(_, patch, _) => {
                        Some((f, Arc::clone(plan), Arc::clone(patch), root, true))
                    }
                    CachedPlan::Regular(_) => None,
                })
                .collect();
        }
        let faces: Vec<usize> = group.iter().map(|&(_, f, _)| f).collect();
        let patch = LocalPatch::new(self.level, self.data, &faces, self.shapes)?;
        let mut surface = FaceSurface::Local { patch, root: 0 };
        let mut out = Vec::with_capacity(group.len());
        for &(root, f, ref plan) in group {
            if let FaceSurface::Local { root: r, .. } = &mut surface {
                *r = root;
            }
            out.push((f, Arc::new(regridded(plan, &mut surface)?), root));
        }
        let patch = surface.into_shared_patch()?;
        Some(
            out.into_iter()
                .map(|(f, plan, root)| (f, plan, Arc::clone(&patch), root, false))
                .collect(),
        )
    }
}

/// The irregular faces of `frozen` by the local refinement they were planned on, each group
/// in the order of its roots (the order its refinement was cut out in).
fn frozen_groups(frozen: &[CachedPlan]) -> BTreeMap<usize, FrozenGroup> {
    let mut groups: BTreeMap<usize, FrozenGroup> = BTreeMap::new();
    for (f, cached) in frozen.iter().enumerate() {
        if let CachedPlan::Local(plan, patch, root) = cached {
            let key = Arc::as_ptr(patch) as usize;
            groups
                .entry(key)
                .or_default()
                .push((*root, f, Arc::clone(plan)));
        }
    }
    for group in groups.values_mut() {
        group.sort_unstable_by_key(|&(root, f, _)| (root, f));
    }
    groups
}

/// `old`'s count, order and figures on `surface`: its grids evaluated again, as balancing
/// evaluates a face it refines (a regular quadratic face's grid is the even points of its
/// finer one).
fn regridded(old: &Plan, surface: &mut FaceSurface) -> Option<Plan> {
    let n = old.n;
    let quadratic = old.order == Order::Quadratic;
    let regular = matches!(surface, FaceSurface::Regular(_));
    let finer = if quadratic {
        Some(surface.grid(2 * n)?)
    } else {
        None
    };
    let grid = if quadratic && regular {
        Vec::new()
    } else {
        surface.grid(n)?
    };
    Some(Plan {
        n,
        grid,
        measured: old.measured,
        capped: old.capped,
        estimated: old.estimated,
        centre: None,
        order: old.order,
        finer,
        linear_colour: old.linear_colour,
    })
}
