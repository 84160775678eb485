//! Prescribed displacements that contradict one another: two `[[displacement]]` entries
//! whose node sets share a node and whose directions there are the same (or one lies in
//! the span of the node's earlier ones) take the earlier rows only (`constraints`: a row
//! in the span of earlier ones is dropped), so a later entry with other values would be
//! ignored without a word. Such a scene is refused; the same values given twice (an edge
//! node in two held faces) are accepted.

use super::*;

/// A later row in the span of earlier ones to this much of its length (unit directions:
/// the same test, in angle, as the constraint builder's rank test).
const IN_SPAN: f64 = 1e-9;
/// Values that agree to this fraction of the larger one (or absolutely below it) are the
/// same prescription.
const SAME_VALUE: f64 = 1e-12;

impl Builder {
    /// Refuses a node whose prescribed rows contradict each other (`origin[k]`: the
    /// `[[displacement]]` entry of row k).
    pub(super) fn consistent_displacements(
        &self,
        dirichlet: &[Dirichlet],
        origin: &[usize],
        node_sets: &[NodeSet],
    ) -> Result<(), SceneError> {
        if dirichlet.len() < 2 {
            return Ok(());
        }
        let mut rows: std::collections::BTreeMap<u32, Vec<usize>> = Default::default();
        for (k, d) in dirichlet.iter().enumerate() {
            for &n in &node_sets[d.node_set].nodes {
                rows.entry(n).or_default().push(k);
            }
        }
        for (node, ks) in rows.iter().filter(|(_, ks)| ks.len() > 1) {
            let mut kept: Vec<usize> = Vec::new();
            for &k in ks {
                let d = &dirichlet[k];
                let Some(c) = combination(dirichlet, &kept, &d.direction) else {
                    kept.push(k);
                    continue;
                };
                if let Some((t, v, w)) = differ(dirichlet, &kept, &c, &d.function) {
                    let earlier: Vec<String> = kept
                        .iter()
                        .zip(&c)
                        .filter(|(_, c)| c.abs() > IN_SPAN)
                        .map(|(&j, _)| format!("displacement[{}]", origin[j]))
                        .collect();
                    return Err(self.err(
                        format!("displacement[{}]", origin[k]),
                        format!(
                            "node {} is prescribed along ({}, {}, {}) by {} already, as {w} at t = {t}, and here as {v}: a node's direction may be prescribed once (again only with the same values)",
                            node + 1,
                            d.direction[0],
                            d.direction[1],
                            d.direction[2],
                            earlier.join(" and "),
                        ),
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The coefficients c with sum_j c_j dir(kept_j) = dir, when dir lies in the span of the
/// kept rows' (independent) directions.
fn combination(dirichlet: &[Dirichlet], kept: &[usize], dir: &Vec3) -> Option<Vec<f64>> {
    if kept.is_empty() {
        return None;
    }
    let m = kept.len();
    let a = nalgebra::DMatrix::from_fn(3, m, |i, j| dirichlet[kept[j]].direction[i]);
    let b = nalgebra::DVector::from_column_slice(dir);
    let c = (a.transpose() * &a).lu().solve(&(a.transpose() * &b))?;
    ((&a * &c - &b).norm() <= IN_SPAN).then(|| c.iter().copied().collect())
}

/// The first time (among every breakpoint of the functions involved) at which the row's
/// function `f` differs from the combination `c` of the kept rows' functions: (t, f(t),
/// the combination's value).
fn differ(
    dirichlet: &[Dirichlet],
    kept: &[usize],
    c: &[f64],
    f: &PiecewiseLinear,
) -> Option<(f64, f64, f64)> {
    let mut times: Vec<f64> = f.times().collect();
    for &j in kept {
        times.extend(dirichlet[j].function.times());
    }
    times.sort_by(f64::total_cmp);
    times.dedup();
    times.into_iter().find_map(|t| {
        let v = f.eval(t);
        let w: f64 = kept
            .iter()
            .zip(c)
            .map(|(&j, c)| c * dirichlet[j].function.eval(t))
            .sum();
        ((v - w).abs() > SAME_VALUE * v.abs().max(w.abs()).max(1.0)).then_some((t, v, w))
    })
}
