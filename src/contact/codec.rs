//! The contact state as words: one active constraint as a typed message (sent between
//! ranks when the state is made whole, and stored in the restart file), and the whole state
//! for a restart, read back checked against the problem.

use super::mortar::Tie;
use super::state::{Active, ContactState, Mode};
use crate::comm::message::{self, Message, Reader, Writer};
use crate::problem::Discretization;
use crate::problem::Problem;

/// Words of one active constraint (the restart file's layout): pair, slave, face, s (2),
/// normal (3), mode (tag, direction (3), magnitude), normal force, tangential force (3),
/// slip stiffness, secant (flag, force (3), slip (3)), start (flag, face, s (2)),
/// reversals.
const ACTIVE_WORDS: usize = 30;

impl Message for Active {
    fn write(&self, w: &mut Writer<'_>) {
        w.index(self.pair);
        w.id(self.slave);
        w.id(self.face);
        w.reals(&self.s);
        w.reals(&self.normal);
        match self.mode {
            Mode::Free => {
                w.id(0);
                w.pad(4);
            }
            Mode::Stick => {
                w.id(1);
                w.pad(4);
            }
            Mode::Slip { dir, magnitude } => {
                w.id(2);
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
            Some((face, s)) => {
                w.id(face);
                w.reals(&s);
            }
            None => w.pad(3),
        }
        w.id(self.reversals);
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
        let mode = match tag {
            0 => Mode::Free,
            1 => Mode::Stick,
            2 => Mode::Slip { dir, magnitude },
            _ => return None,
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
        Some(Active {
            pair,
            slave,
            face,
            s,
            normal,
            mode,
            normal_force,
            tangential_force,
            slip_stiffness,
            secant,
            start,
            reversals,
        })
    }
}

impl ContactState {
    /// The whole state as words (active constraints, released (slave, pair) entries,
    /// mortar ties), for a restart.
    pub fn encode(&self) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let active = message::encode(&self.active);
        debug_assert_eq!(active.len(), ACTIVE_WORDS * self.active.len());
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
                && a.start.is_none_or(|(f, _)| face_ok(a.pair, f))
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
            ties,
            tangent: false,
            onset: false,
            onset_springs: Default::default(),
            steady: false,
            held_masters: None,
            spring_turns: Default::default(),
            newton_turns: Default::default(),
            newton_off: Default::default(),
        })
    }
}

fn finite(a: &Active) -> bool {
    let mut words = Vec::with_capacity(ACTIVE_WORDS);
    message::push(&mut words, a);
    words.iter().all(|x| x.is_finite())
}
