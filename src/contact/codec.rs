//! The contact state as words: one active constraint as a typed message (sent between
//! ranks when the state is made whole, and stored in the restart file), and the whole state
//! for a restart, read back checked against the problem.

use super::active::{Active, ContactState, Fold, Mode};
use super::mortar::Tie;
use crate::comm::message::{self, Message, Reader, Writer};
use crate::problem::Discretization;
use crate::problem::Problem;

/// Words of one active constraint (the restart file's layout): pair, slave, face, s (2),
/// normal (3), mode (tag, direction (3), magnitude), normal force, tangential force (3),
/// slip stiffness, secant (flag, force (3), slip (3)), start (flag, face, s (2)),
/// reversals; then, for a node beyond its face's edge now or at the step's start, its
/// offset (3) and the start's (3), marked by the mode's tag plus EXTENDED. A node without
/// offsets keeps the layout written before offsets were kept, so those files read as
/// before and their words are unchanged. A node held at a fold, or that left a face in
/// the step, takes FOLD_WORDS more after those: the fold (flag, face, s (2), normal (3),
/// edge (3), forces (2)) and the face left (flag, face), marked by FOLDED added to the tag.
const ACTIVE_WORDS: usize = 30;
const OFFSET_WORDS: usize = 6;
const FOLD_WORDS: usize = 14;
const EXTENDED: u32 = 3;
const FOLDED: u32 = 6;

impl Message for Active {
    fn write(&self, w: &mut Writer<'_>) {
        w.index(self.pair);
        w.id(self.slave);
        w.id(self.face);
        w.reals(&self.s);
        w.reals(&self.normal);
        let start_offset = self.start.map_or([0.0; 3], |(_, _, o)| o);
        let extended = self.offset != [0.0; 3] || start_offset != [0.0; 3];
        let folded = self.fold.is_some() || self.left.is_some();
        let mark = if extended { EXTENDED } else { 0 } + if folded { FOLDED } else { 0 };
        match self.mode {
            Mode::Free => {
                w.id(mark);
                w.pad(4);
            }
            Mode::Stick => {
                w.id(1 + mark);
                w.pad(4);
            }
            Mode::Slip { dir, magnitude } => {
                w.id(2 + mark);
                w.reals(&dir);
                w.real(magnitude);
            }
        }
        w.real(self.normal_force);
        w.reals(&self.tangential_force);
        w.real(self.slip_stiffness);
        w.flag(self.secant.is_some());
        match self.secant {
            Some((force, slip)) => {
                w.reals(&force);
                w.reals(&slip);
            }
            None => w.pad(6),
        }
        w.flag(self.start.is_some());
        match self.start {
            Some((face, s, _)) => {
                w.id(face);
                w.reals(&s);
            }
            None => w.pad(3),
        }
        w.id(self.reversals);
        if extended {
            w.reals(&self.offset);
            w.reals(&start_offset);
        }
        if folded {
            w.flag(self.fold.is_some());
            match self.fold {
                Some(f) => {
                    w.id(f.face);
                    w.reals(&f.s);
                    w.reals(&f.normal);
                    w.reals(&f.edge);
                    w.reals(&f.forces);
                }
                None => w.pad(11),
            }
            w.flag(self.left.is_some());
            w.id(self.left.unwrap_or(0));
        }
    }

    fn read(r: &mut Reader) -> Option<Self> {
        let pair = r.index()?;
        let slave = r.id()?;
        let face = r.id()?;
        let s = r.reals()?;
        let normal = r.reals()?;
        let tag = r.id()?;
        let dir = r.reals()?;
        let magnitude = r.real()?;
        if tag >= 2 * FOLDED {
            return None;
        }
        let folded = tag >= FOLDED;
        let tag = tag % FOLDED;
        let extended = tag >= EXTENDED;
        let mode = match tag % EXTENDED {
            0 => Mode::Free,
            1 => Mode::Stick,
            _ => Mode::Slip { dir, magnitude },
        };
        let normal_force = r.real()?;
        let tangential_force = r.reals()?;
        let slip_stiffness = r.real()?;
        let secant = match r.flag()? {
            true => Some((r.reals()?, r.reals()?)),
            false => r.skip(6).map(|_| None)?,
        };
        let start = match r.flag()? {
            true => Some((r.id()?, r.reals()?)),
            false => r.skip(3).map(|_| None)?,
        };
        let reversals = r.id()?;
        let (offset, start_offset) = match extended {
            true => (r.reals()?, r.reals()?),
            false => ([0.0; 3], [0.0; 3]),
        };
        let (fold, left) = match folded {
            true => {
                let fold = match r.flag()? {
                    true => Some(Fold {
                        face: r.id()?,
                        s: r.reals()?,
                        normal: r.reals()?,
                        edge: r.reals()?,
                        forces: r.reals()?,
                    }),
                    false => r.skip(11).map(|_| None)?,
                };
                let has_left = r.flag()?;
                let left = r.id()?;
                (fold, has_left.then_some(left))
            }
            false => (None, None),
        };
        Some(Active {
            pair,
            slave,
            face,
            s,
            normal,
            offset,
            mode,
            normal_force,
            tangential_force,
            slip_stiffness,
            secant,
            start: start.map(|(f, s)| (f, s, start_offset)),
            reversals,
            fold,
            left,
        })
    }
}

impl ContactState {
    /// The whole state as words (active constraints, released (slave, pair) entries,
    /// mortar ties), for a restart.
    pub fn encode(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let active = message::encode(&self.active);
        debug_assert!(active.len() >= ACTIVE_WORDS * self.active.len());
        debug_assert!(
            active.len() <= (ACTIVE_WORDS + OFFSET_WORDS + FOLD_WORDS) * self.active.len()
        );
        (
            active,
            message::encode(&self.released),
            message::encode(&self.ties),
        )
    }

    /// The state `encode` wrote; None when the words do not describe constraints of this
    /// problem (a malformed entry, a pair, node or face that does not exist, a value that
    /// is not finite).
    pub fn decode(
        problem: &Problem,
        active: &[f64],
        released: &[f64],
        ties: &[f64],
    ) -> Option<Self> {
        let nodes = problem.mesh.num_nodes();
        let pairs = &problem.contacts;
        let face_ok = |p: usize, f: u32| (f as usize) < pairs[p].master_faces.len();
        let active: Vec<Active> = message::decode(active)?;
        let released: Vec<(u32, usize)> = message::decode(released)?;
        let ok = |a: &Active| {
            a.pair < pairs.len()
                && (a.slave as usize) < nodes
                && face_ok(a.pair, a.face)
                && a.start.is_none_or(|(f, _, _)| face_ok(a.pair, f))
                && a.fold.is_none_or(|f| face_ok(a.pair, f.face))
                && a.left.is_none_or(|f| face_ok(a.pair, f))
                && finite(a)
        };
        let released_ok = |&(s, p): &(u32, usize)| (s as usize) < nodes && p < pairs.len();
        let ties: Vec<(usize, Tie)> = message::decode(ties)?;
        // Every active constraint of a mortar pair has its tie, and every tie a constraint.
        let mortar = |p: usize| pairs[p].discretization == Discretization::Mortar;
        let tie_ok = |(p, t): &(usize, Tie)| {
            *p < pairs.len()
                && mortar(*p)
                && active.iter().any(|a| a.pair == *p && a.slave == t.slave)
                && t.masters
                    .iter()
                    .all(|&(m, w)| (m as usize) < nodes && w.is_finite())
        };
        let tied = |a: &Active| {
            !mortar(a.pair) || ties.iter().any(|(p, t)| *p == a.pair && t.slave == a.slave)
        };
        (active.iter().all(ok)
            && released.iter().all(released_ok)
            && ties.iter().all(tie_ok)
            && active.iter().all(tied))
        .then_some(ContactState {
            active,
            released,
            let_go: Vec::new(),
            ties,
            tangent: false,
            onset: false,
            onset_springs: Default::default(),
            steady: false,
            held_masters: None,
            held_directions: None,
            spring_turns: Default::default(),
            newton_turns: Default::default(),
            newton_off: Default::default(),
        })
    }
}

fn finite(a: &Active) -> bool {
    let mut words = Vec::with_capacity(ACTIVE_WORDS + OFFSET_WORDS + FOLD_WORDS);
    message::push(&mut words, a);
    words.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::comm::message;

    fn active(offset: [f64; 3], start_offset: [f64; 3]) -> Active {
        Active {
            pair: 0,
            slave: 12,
            face: 3,
            s: [-1.0, 0.25],
            normal: [0.0, 1.0, 0.0],
            offset,
            mode: Mode::Slip {
                dir: [1.0, 0.0, 0.0],
                magnitude: 2.5,
            },
            normal_force: 8.0,
            tangential_force: [0.5, 0.0, 0.0],
            slip_stiffness: 40.0,
            secant: Some(([1.0, 0.0, 0.0], [0.01, 0.0, 0.0])),
            start: Some((2, [1.0, 0.5], start_offset)),
            reversals: 1,
            fold: None,
            left: None,
        }
    }

    /// A node without offsets keeps the 30-word layout written before offsets were kept
    /// (so restart files of earlier runs read as before); one beyond an edge, now or at
    /// the step's start, takes 6 words more; both read back exactly, in one list.
    #[test]
    fn offsets_beyond_an_edge_round_trip_and_plain_nodes_keep_the_old_layout() {
        let plain = active([0.0; 3], [0.0; 3]);
        let beyond = active([-0.02, 0.0, 0.0], [0.0; 3]);
        let started = active([0.0; 3], [0.0, 0.0, 0.03]);
        assert_eq!(message::encode(&[plain]).len(), ACTIVE_WORDS);
        assert_eq!(
            message::encode(&[beyond]).len(),
            ACTIVE_WORDS + OFFSET_WORDS
        );
        let list = [plain, beyond, started, plain];
        let back: Vec<Active> = message::decode(&message::encode(&list)).expect("decodes");
        assert_eq!(back, list);
        // A mode tag (word 8) beyond the extended and folded ones is not a constraint.
        let mut words = message::encode(&[plain]);
        words[8] = (2 * FOLDED) as f64;
        assert!(message::decode::<Active>(&words).is_none());
    }

    /// A node held at a fold, or that left a face in the step, takes FOLD_WORDS more,
    /// with or without offsets, and reads back exactly beside plain nodes.
    #[test]
    fn folds_and_faces_left_round_trip() {
        let plain = active([0.0; 3], [0.0; 3]);
        let mut folded = active([0.0; 3], [0.0; 3]);
        folded.fold = Some(Fold {
            face: 4,
            s: [1.0, -0.5],
            normal: [0.1, 0.99, 0.0],
            edge: [0.0, 0.0, 1.0],
            forces: [2.5, 1.25],
        });
        folded.left = Some(4);
        let mut left = active([-0.02, 0.0, 0.0], [0.0; 3]);
        left.left = Some(2);
        assert_eq!(message::encode(&[folded]).len(), ACTIVE_WORDS + FOLD_WORDS);
        assert_eq!(
            message::encode(&[left]).len(),
            ACTIVE_WORDS + OFFSET_WORDS + FOLD_WORDS
        );
        let list = [plain, folded, left, plain];
        let back: Vec<Active> = message::decode(&message::encode(&list)).expect("decodes");
        assert_eq!(back, list);
    }
}
