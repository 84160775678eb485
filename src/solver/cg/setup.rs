//! When and how the preconditioner's coarse parts are (re)built: the two-level coarse
//! operator Q^T A Q, measured by probes and factored, and the multilevel hierarchy.

use super::failure::SolveFailure;
use super::full_tangent::{FullTangent, MODEL_START};
use super::kept::BuildRows;
use super::model::{agree, agree_alloc, max_abs, CgSettings, ModelProblem};
use super::state::Cg;
use crate::comm::{self, Comm};
use crate::constraints::Constraints;
use crate::math::Vec3;
use crate::memory::try_filled;
use crate::solver::assembly::{Elastic, Tangents};

impl Cg {
    /// Measures and factors the coarse operator Q^T A Q when it is out of date: one
    /// operator application per colour and mode (exact for linear bodies, a
    /// finite-difference probe at u otherwise).
    pub(super) fn setup_coarse<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let Some(mut cs) = self.coarse.take() else {
            return Ok(());
        };
        let rows = pb.cons.num_rows() as f64;
        let rows = comm::global_sum(pb.comm, {
            let mut acc = comm::ExactSum::new();
            acc.add(rows);
            acc
        });
        let similar = (rows - self.coarse_rows as f64).abs() <= 0.1 * self.coarse_rows as f64;
        let mut fp = None;
        if cs.is_set_up() && self.coarse_stale && linear && self.coarse_fp.is_some() {
            // A new increment with the operator the coarse space was measured on.
            fp = Some(operator_fingerprint(pb));
            self.coarse_stale = self.coarse_fp != fp;
        }
        if cs.is_set_up() && similar && !self.coarse_stale {
            self.coarse = Some(cs);
            return Ok(());
        }
        self.coarse_stale = false;
        self.built_rate = None;
        self.trace.coarse_builds += 1;
        self.coarse_rows = rows as usize;
        self.coarse_fp = linear.then(|| fp.unwrap_or_else(|| operator_fingerprint(pb)));
        let comm = pb.comm;
        let owned = pb.owned();
        let dim = cs.dim();
        let mut kc = match agree_alloc(comm, try_filled(0.0, dim * dim, "the coarse operator")) {
            Ok(kc) => kc,
            Err(e) => {
                self.coarse = Some(cs);
                return Err(e);
            }
        };
        let mut restricted = Vec::new();
        let mut result = Ok(());
        'probes: for c in 0..cs.num_colors() {
            for m in 0..6 {
                cs.probe(pb.cons, (c, m), (owned, &pb.asm.mesh.coords), &mut self.pu);
                pb.cons.expand(comm, &mut self.pu);
                pb.asm.mesh.exchange(comm, &mut self.pu);
                if linear {
                    // A probe is non-zero on one colour's aggregates only.
                    let r = pb
                        .asm
                        .internal_force_sparse(&self.pu, &mut self.q, &mut self.nonzero);
                    if let Err(e) = agree(comm, r) {
                        result = Err(e);
                        break 'probes;
                    }
                } else {
                    let pmax = max_abs(comm, &self.pu, owned).max(f64::MIN_POSITIVE);
                    let eps = 1e-7 * s.length_scale / pmax;
                    for a in 0..u.len() {
                        for i in 0..3 {
                            self.trial[a][i] = u[a][i] + eps * self.pu[a][i];
                        }
                    }
                    if let Err(e) = pb.forces(&self.trial, &mut self.fi_trial, &mut self.fe_trial) {
                        result = Err(e);
                        break 'probes;
                    }
                    for a in 0..u.len() {
                        for i in 0..3 {
                            self.q[a][i] = ((self.fi_trial[a][i] - self.fe_trial[a][i])
                                - (self.fi[a][i] - self.fe[a][i]))
                                / eps;
                        }
                    }
                }
                pb.cons.reduce(comm, &mut self.q, None);
                cs.restrict(comm, &pb.asm.mesh.coords, &self.q, &mut restricted);
                cs.record(c, m, &restricted, &mut kc);
            }
        }
        if result.is_ok() {
            result = agree_alloc(comm, cs.factor(kc)).map(|_| ());
        }
        self.coarse = Some(cs);
        result
    }

    /// Builds the multilevel hierarchy when it is out of date, by the rule of the coarse
    /// space (`invalidate_coarse`): first use, a new load increment (unless the bodies are
    /// linear and the constrained operator is the one it was built on), or the number of
    /// constraint rows changed by more than a tenth.
    pub(super) fn setup_multilevel<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        if self.ml_standby || self.multilevel.is_none() {
            return Ok(());
        }
        // Contact rows counted apart: a body held only by contact has its rigid modes in
        // the coarse levels only through them.
        let [rows, contact] = row_counts(pb);
        if linear && self.resume_kept(pb, u, [rows, contact], s)? {
            return Ok(());
        }
        let Some(ml) = self.multilevel.as_mut() else {
            return Ok(());
        };
        let (old, old_contact) = (self.coarse_rows, self.ml_contact_rows);
        let similar = near(rows, old) && near(contact, old_contact);
        let mut fp = None;
        if ml.is_set_up() && self.coarse_stale && linear && self.coarse_fp.is_some() {
            // A new increment with the operator the hierarchy was built on: building it
            // again would give the same bits. The smoother's bound must then be the one
            // measured on this operator too (not one measured, or widened, on another
            // constraint set within the last increment).
            fp = Some(operator_fingerprint(pb));
            if fp == self.coarse_fp {
                self.coarse_stale = false;
                if ml.smooths_fine() && self.ml_smoother_fp != fp {
                    self.ml_smoother_rows = [rows, contact];
                    self.ml_smoother_fp = fp;
                    let mut op = fine_op!(self, pb, u, linear, s);
                    ml.estimate_smoother(pb.comm, &self.minv, &mut op, &mut self.q)?;
                }
                return Ok(());
            }
        }
        if let Some(built) = self
            .ml_built
            .as_ref()
            .filter(|_| ml.is_set_up() && self.coarse_stale && linear && similar)
        {
            if keeps(pb, built, [rows, contact], [old, old_contact]) {
                // A new increment on a constraint set close to the one the hierarchy was
                // built on: kept (a valid preconditioner of the operator as it is now,
                // as within an increment), its fine smoother measured on this operator.
                self.coarse_stale = false;
                self.ml_smoother_rows = [rows, contact];
                self.ml_smoother_fp = Some(fp.unwrap_or_else(|| operator_fingerprint(pb)));
                if ml.smooths_fine() {
                    let mut op = fine_op!(self, pb, u, linear, s);
                    ml.estimate_smoother(pb.comm, &self.minv, &mut op, &mut self.q)?;
                }
                self.trace.ml_kept += 1;
                return Ok(());
            }
        }
        if ml.is_set_up() && similar && !self.coarse_stale {
            // The hierarchy still serves, but the fine smoother is positive definite only
            // while its bound covers the spectrum of D^-1 A, which a new constraint set
            // moves (the paper's stick/slip bar: a slip front four nodes further on made
            // the cycle indefinite).
            if ml.smooths_fine() && self.ml_smoother_rows != [rows, contact] {
                self.ml_smoother_rows = [rows, contact];
                self.ml_smoother_fp = linear.then(|| operator_fingerprint(pb));
                let mut op = fine_op!(self, pb, u, linear, s);
                ml.estimate_smoother(pb.comm, &self.minv, &mut op, &mut self.q)?;
            }
            return Ok(());
        }
        let why = if !ml.is_set_up() {
            "first use".to_string()
        } else if !similar {
            format!("constraint rows {old} -> {rows}, of them contact {old_contact} -> {contact}")
        } else {
            "new load increment".to_string()
        };
        self.ml_contact_rows = contact;
        self.ml_smoother_rows = [rows, contact];
        self.coarse_stale = false;
        self.built_rate = None;
        self.coarse_rows = rows;
        let fp = linear.then(|| fp.unwrap_or_else(|| operator_fingerprint(pb)));
        self.coarse_fp = fp;
        self.ml_smoother_fp = fp;
        let mut op = fine_op!(self, pb, u, linear, s);
        let start = std::time::Instant::now();
        self.trace.ml_builds += 1;
        // z and pu are written before they are read in every iteration (the preconditioned
        // residual, the expanded direction): freed while the hierarchy is built, its peak
        // (25 MiB per rank at n = 80 on 2 ranks); q, the cycle's scratch, the build frees
        // and gives back itself.
        let nl = self.z.len();
        self.z = Vec::new();
        self.pu = Vec::new();
        self.ml_built = None;
        let q = &mut self.q;
        let built = ml.setup(
            pb.comm,
            pb.cons,
            pb.asm.mesh,
            &self.minv,
            &mut op,
            linear,
            q,
        );
        self.z = vec![[0.0; 3]; nl];
        self.pu = vec![[0.0; 3]; nl];
        built?;
        self.ml_built = linear.then(|| BuildRows::record(pb));
        self.rebuild_note = Some(format!(
            "{} (build {}: {why}; {:.3} s)",
            ml.summary,
            ml.builds,
            start.elapsed().as_secs_f64()
        ));
        Ok(())
    }
}

impl Cg {
    /// A continued run's first use of the hierarchy (`resume_hierarchy`): when the
    /// uninterrupted run would have kept the hierarchy it was using here, builds that one
    /// from the rows the restart file keeps (`rebuild_kept`) and says so. `now`: the
    /// model problem's rows and contact rows. Collective.
    fn resume_kept<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        now: [usize; 2],
        s: &CgSettings,
    ) -> Result<bool, SolveFailure> {
        if self.multilevel.as_ref().is_none_or(|m| m.is_set_up()) {
            return Ok(false);
        }
        let Some(words) = self.ml_resume.take() else {
            return Ok(false);
        };
        let Some(built) = BuildRows::of_words(&words, pb.asm.mesh) else {
            return Ok(false);
        };
        let mut was = built.counts();
        pb.comm.sum_i64(&mut was);
        let was = [was[0] as usize, was[1] as usize];
        if !keeps(pb, &built, now, was) {
            return Ok(false);
        }
        let specs = built.specs(pb.asm.mesh);
        let Ok(cons) = Constraints::new(pb.comm, pb.asm.mesh, specs) else {
            return Ok(false);
        };
        self.rebuild_kept(pb, u, (built, cons), [was, now], s)?;
        Ok(true)
    }

    /// Builds the multilevel hierarchy from the rows and springs an earlier run built it
    /// from (a continued run, `resume_hierarchy`; `cons` their constraint set), then
    /// measures the fine smoother on the operator as it is now: the state the
    /// uninterrupted run had at this point, bit for bit. `counts`: the rows and contact
    /// rows then and now.
    fn rebuild_kept<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        (built, cons): (BuildRows, Constraints),
        [was, now]: [[usize; 2]; 2],
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        let springs = built.springs(pb.asm.mesh);
        let then = ModelProblem {
            cons: &cons,
            springs: &springs,
            ..*pb
        };
        let then_fp = operator_fingerprint(&then);
        let now_fp = operator_fingerprint(pb);
        let Some(ml) = self.multilevel.as_mut() else {
            return Ok(());
        };
        let start = std::time::Instant::now();
        let nl = self.z.len();
        self.z = Vec::new();
        self.pu = Vec::new();
        let mut op = fine_op!(self, &then, u, true, s);
        let made = ml.setup(
            pb.comm,
            &cons,
            pb.asm.mesh,
            &self.minv,
            &mut op,
            true,
            &mut self.q,
        );
        self.z = vec![[0.0; 3]; nl];
        self.pu = vec![[0.0; 3]; nl];
        made?;
        self.trace.ml_builds += 1;
        self.trace.ml_kept += 1;
        [self.coarse_rows, self.ml_contact_rows] = was;
        self.coarse_stale = false;
        self.built_rate = None;
        self.coarse_fp = Some(then_fp);
        self.ml_built = Some(built);
        self.ml_smoother_rows = now;
        self.ml_smoother_fp = Some(now_fp);
        if ml.smooths_fine() {
            let mut op = fine_op!(self, pb, u, true, s);
            ml.estimate_smoother(pb.comm, &self.minv, &mut op, &mut self.q)?;
        }
        self.rebuild_note = Some(format!(
            "{} (build {}: a continued run, from the rows the earlier run built its hierarchy on; {:.3} s)",
            ml.summary,
            ml.builds,
            start.elapsed().as_secs_f64()
        ));
        Ok(())
    }
}

/// The model problem's constraint rows and, of them, contact rows (collective).
fn row_counts<C: Comm + ?Sized>(pb: &ModelProblem<C>) -> [usize; 2] {
    let mut counts = [0i64; 2];
    for l in 0..pb.owned() {
        for (_, row) in pb.cons.rows(l) {
            let contact = matches!(row.kind, crate::constraints::RowKind::Contact { .. });
            counts[0] += 1;
            counts[1] += i64::from(contact);
        }
    }
    pb.comm.sum_i64(&mut counts);
    [counts[0] as usize, counts[1] as usize]
}

/// Whether two row counts are within a tenth of the second.
fn near(a: usize, b: usize) -> bool {
    a.abs_diff(b) as f64 <= 0.1 * b as f64
}

/// Whether a hierarchy built on `built` (whose counts of rows and contact rows were `was`)
/// still serves the model problem (whose counts are `now`) from one increment to the next:
/// the counts within a tenth, as within an increment, and at most a tenth of the contact
/// rows tied to other master nodes than at the build (a sliding contact moves its ties
/// face by face: the coarse levels' coupling of the bodies moves with them). Collective.
fn keeps<C: Comm + ?Sized>(
    pb: &ModelProblem<C>,
    built: &BuildRows,
    now: [usize; 2],
    was: [usize; 2],
) -> bool {
    if !(near(now[0], was[0]) && near(now[1], was[1])) {
        return false;
    }
    let mut moved = [built.moved_ties(pb)];
    pb.comm.sum_i64(&mut moved);
    moved[0] as f64 <= 0.1 * now[1] as f64
}

/// A fingerprint of the constrained operator of linear bodies (collective, the same on
/// any number of ranks): every owned node's constraint rows (direction, master nodes and
/// weights) and slip springs, hashed with the node's global id, summed over the nodes.
/// With linear bodies these are all the operator and the block-Jacobi diagonal depend on,
/// so a coarse space or hierarchy measured on an operator of the same fingerprint is the
/// one measuring again would give. (Two different operators share a fingerprint with a
/// probability of about 2^-64; the preconditioner kept would still be a valid one.)
fn operator_fingerprint<C: Comm + ?Sized>(pb: &ModelProblem<C>) -> u64 {
    let ids = &pb.asm.mesh.node_global;
    let mut sum = 0u64;
    for l in 0..pb.owned() {
        let mut h = None;
        for (_, row) in pb.cons.rows(l) {
            let mut x = h.unwrap_or_else(|| mix(0x6e6f_6465, ids[l] as u64));
            for d in row.dir {
                x = mix(x, d.to_bits());
            }
            for &(m, w) in &row.masters {
                x = mix(mix(x, m as u64), w.to_bits());
            }
            h = Some(mix(x, 0x0072_6f77));
        }
        if let Some(h) = h {
            sum = sum.wrapping_add(h);
        }
    }
    for sp in pb.springs {
        let mut x = mix(0x7370_7269_6e67, ids[sp.node] as u64);
        for v in sp.k.iter().flatten() {
            x = mix(x, v.to_bits());
        }
        sum = sum.wrapping_add(x);
    }
    // The wrapping sum over all ranks, exactly: its two 32-bit halves summed apart.
    let mut halves = [(sum & 0xffff_ffff) as i64, (sum >> 32) as i64];
    pb.comm.sum_i64(&mut halves);
    (halves[0] as u64).wrapping_add((halves[1] as u64) << 32)
}

/// One step of a 64-bit hash (SplitMix64's finaliser over the state and the next word).
fn mix(h: u64, x: u64) -> u64 {
    let mut z = (h ^ x.rotate_left(25))
        .wrapping_add(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(h.rotate_left(7));
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

impl Cg {
    /// Leaves the full tangent for the rest of the model problem (block Jacobi, built at its
    /// start, takes over); logs why.
    pub(super) fn drop_full_tangent(&mut self, why: &str) {
        self.tangent = None;
        let note = format!("full tangent dropped for this model problem ({why}): block Jacobi");
        self.add_note(note);
    }

    /// Builds the full tangent at `u` when the run uses it (collective); logs the build.
    pub(super) fn setup_full_tangent<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        linear: bool,
        s: &CgSettings,
        why: &str,
    ) -> Result<(), SolveFailure> {
        if !self.use_tangent {
            return Ok(());
        }
        if why == MODEL_START && !self.tangent_increment && self.tangent_fits(pb) {
            // A later model problem of the increment on the same unknowns: the factor is
            // kept, and the rate rule rebuilds it when it goes stale.
            self.tangent_builds_here = 0;
            return Ok(());
        }
        self.tangent_increment = false;
        let start = std::time::Instant::now();
        self.tangent = None;
        crate::memory::guard::give_back_freed();
        let marked = if linear {
            0
        } else {
            pb.asm
                .mark_elastic(u, &mut self.elastic, &mut self.tangent_marks)
        };
        let elastic = Elastic {
            matrices: &self.elastic,
            marks: &self.tangent_marks,
        };
        let mut tangents = Tangents::default();
        let assembled = if linear {
            0
        } else {
            pb.asm.consistent_tangents(u, Some(elastic), &mut tangents)
        };
        let mut op = fine_op!(self, pb, u, linear, s);
        op.central = true;
        op.elastic = Some(elastic);
        op.tangents = Some(&tangents);
        let t = match FullTangent::build(
            pb,
            &mut op,
            &mut self.tangent_order,
            &mut self.tangent_colours,
        )? {
            Ok(t) => t,
            Err(limit) => {
                self.use_tangent = false;
                self.drop_full_tangent(&format!(
                    "its factor would hold more than {limit} entries; for the rest of the run"
                ));
                return Ok(());
            }
        };
        self.tangent_builds += 1;
        self.tangent_builds_here = if why == MODEL_START {
            1
        } else {
            self.tangent_builds_here + 1
        };
        let note = format!(
            "full tangent: {} unknowns, factor {} entries (build {}: {why}; {:.3} s: colour {:.3}, probe {:.3} ({marked} local elements elastic, {assembled} assembled), order {:.3}, factor {:.3})",
            t.unknowns,
            t.nnz,
            self.tangent_builds,
            start.elapsed().as_secs_f64(),
            t.seconds[0],
            t.seconds[1],
            t.seconds[2],
            t.seconds[3]
        );
        self.add_note(note);
        self.tangent = Some(t);
        Ok(())
    }

    /// The full tangent of a coupled solve (cg/coupled.rs) of nonlinear bodies: built at
    /// the increment's first model problem (so a restart, which begins at an increment,
    /// builds what the run it continues built) and again when the free directions of a
    /// node changed (its unknowns are another set: stick and slip change a node's rows),
    /// or when it was dropped; kept otherwise (collective).
    pub(super) fn refresh_full_tangent<C: Comm + ?Sized>(
        &mut self,
        pb: &ModelProblem<C>,
        u: &[Vec3],
        s: &CgSettings,
    ) -> Result<(), SolveFailure> {
        if !self.use_tangent {
            return Ok(());
        }
        if !self.tangent_increment && self.tangent_fits(pb) {
            return Ok(());
        }
        let why = if self.tangent_increment {
            "coupled solve, new increment"
        } else {
            "coupled solve on another constraint set"
        };
        self.setup_full_tangent(pb, u, false, s, why)
    }

    /// Whether the full tangent is built on the unknowns of `pb` on every rank
    /// (collective).
    fn tangent_fits<C: Comm + ?Sized>(&self, pb: &ModelProblem<C>) -> bool {
        let fits = self.tangent.as_ref().is_some_and(|t| t.fits(pb));
        !comm::any(pb.comm, !fits)
    }
}
