//! What a rank sends: point-to-point messages and their bytes, and the collective calls it
//! takes part in, the bytes it contributes to them and the bytes they bring it (counted by
//! the MPI `Comm`; a serial run sends nothing).

/// Counts of what one rank sent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Traffic {
    /// Point-to-point messages sent (the halo exchanges).
    pub messages: u64,
    /// Bytes of those messages.
    pub bytes: u64,
    /// Collective calls (reductions, gathers, broadcasts, all-to-all).
    pub collectives: u64,
    /// Bytes this rank contributed to them.
    pub collective_bytes: u64,
    /// Bytes they brought this rank: a gather every rank's parts (on the root), an
    /// all-gather the whole (its own part with it), a reduction its result, an all-to-all
    /// what the others sent it. A level of the multilevel hierarchy gathered whole on
    /// every rank is counted here, once per rank, whatever the rank count.
    pub collective_received: u64,
}

impl Traffic {
    /// What was sent between `earlier` and `self` (counts only grow).
    pub fn since(&self, earlier: &Traffic) -> Traffic {
        Traffic {
            messages: self.messages - earlier.messages,
            bytes: self.bytes - earlier.bytes,
            collectives: self.collectives - earlier.collectives,
            collective_bytes: self.collective_bytes - earlier.collective_bytes,
            collective_received: self.collective_received - earlier.collective_received,
        }
    }

    /// The five counts in a fixed order (for reductions over the ranks).
    pub fn as_array(&self) -> [u64; 5] {
        [
            self.messages,
            self.bytes,
            self.collectives,
            self.collective_bytes,
            self.collective_received,
        ]
    }

    pub fn from_array(a: [u64; 5]) -> Traffic {
        Traffic {
            messages: a[0],
            bytes: a[1],
            collectives: a[2],
            collective_bytes: a[3],
            collective_received: a[4],
        }
    }
}

impl std::ops::AddAssign for Traffic {
    fn add_assign(&mut self, o: Traffic) {
        self.messages += o.messages;
        self.bytes += o.bytes;
        self.collectives += o.collectives;
        self.collective_bytes += o.collective_bytes;
        self.collective_received += o.collective_received;
    }
}
