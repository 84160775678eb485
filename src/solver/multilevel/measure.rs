//! The first coarse operator Kc = Q^T A Q, assembled sparse from one application of the
//! (constrained, matrix-free) operator per colour and mode: the probe of colour c and mode
//! m sums mode m of every aggregate of colour c, and Q^T A probe gives, at every aggregate
//! k, column (j, m) of Kc for the one aggregate j of colour c that k sees.

use super::colouring::Colouring;
use super::prolongator::MODES;
use super::sparse::Csr;
use super::transfer::Transfer;
use crate::comm::Comm;
use crate::constraints::Constraints;
use crate::math::Vec3;

/// Buffers of the fine level used while measuring.
pub struct Probe<'b> {
    pub v: &'b mut [Vec3],
    pub av: &'b mut [Vec3],
    pub coeff: &'b mut [f64],
}

/// Measures Kc; `apply(v, av)` sets av = T^T A T v on the owned nodes (v may be changed).
/// The result is symmetrised: (Kc + Kc^T) / 2. Collective.
#[allow(clippy::too_many_arguments)]
pub fn measure<C: Comm + ?Sized, E>(
    comm: &C,
    tr: &mut Transfer,
    col: &Colouring,
    cons: &Constraints,
    owned: usize,
    buf: Probe,
    mut apply: impl FnMut(&mut [Vec3], &mut [Vec3]) -> Result<(), E>,
) -> Result<Csr, E> {
    let mut trip: Vec<(u32, u32, f64)> = Vec::new();
    for c in 0..col.num_colours {
        for m in 0..MODES {
            tr.aggregates.probe(cons, &col.colour, c, m, owned, buf.v);
            apply(buf.v, buf.av)?;
            tr.aggregates.restrict(comm, buf.av, buf.coeff);
            for &(k, j) in col.pairs(c) {
                let (k, j) = (k as usize, j as usize);
                for l in 0..MODES {
                    let v = buf.coeff[MODES * k + l];
                    if v != 0.0 {
                        trip.push(((MODES * k + l) as u32, (MODES * j + m) as u32, v));
                    }
                }
            }
        }
    }
    let n = tr.dim();
    Ok(Csr::from_triplets(n, n, trip).symmetric_part())
}
