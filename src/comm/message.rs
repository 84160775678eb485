//! Typed messages between ranks. The transport carries f64 words; a message type writes its
//! fields to a `Writer` and reads them back from a `Reader` in one place, in order, so no
//! call site picks a value out of a buffer by its position. Integers ride exactly (every
//! u32, and every index below 2^53, is an exact f64) and are read back checked: a word that
//! is not a whole number in range, a flag that is neither 0 nor 1, or a buffer that ends
//! inside a message or runs on past the last one makes `decode` answer None. The same
//! encoding serves the restart file, which stores these words.

use super::communicator::Comm;

/// A value that travels between ranks as words.
pub trait Message: Sized {
    fn write(&self, w: &mut Writer<'_>);
    /// None when the words do not describe a value of this type.
    fn read(r: &mut Reader) -> Option<Self>;
}

/// Appends the fields of messages to a buffer of words, or counts them (`count`).
pub struct Writer<'a> {
    words: &'a mut Vec<f64>,
    /// Words counted instead of written: `Some` while counting.
    counted: Option<usize>,
}

impl<'a> Writer<'a> {
    pub fn new(words: &'a mut Vec<f64>) -> Self {
        Writer {
            words,
            counted: None,
        }
    }

    fn word(&mut self, x: f64) {
        match &mut self.counted {
            Some(n) => *n += 1,
            None => self.words.push(x),
        }
    }

    pub fn real(&mut self, x: f64) {
        self.word(x);
    }

    pub fn id(&mut self, x: u32) {
        self.word(x as f64);
    }

    pub fn index(&mut self, x: usize) {
        debug_assert!(x < 1 << 53, "an index beyond 2^53 is not exact as a word");
        self.word(x as f64);
    }

    pub fn flag(&mut self, x: bool) {
        self.word(if x { 1.0 } else { 0.0 });
    }

    pub fn reals(&mut self, x: &[f64]) {
        match &mut self.counted {
            Some(n) => *n += x.len(),
            None => self.words.extend_from_slice(x),
        }
    }

    /// Zero words where an absent optional part of a fixed-size message would stand.
    pub fn pad(&mut self, n: usize) {
        match &mut self.counted {
            Some(k) => *k += n,
            None => self.words.resize(self.words.len() + n, 0.0),
        }
    }

    pub fn put<T: Message>(&mut self, x: &T) {
        x.write(self);
    }
}

/// The words of `x`, in a buffer of exactly their number (counted first: a large message
/// written into a growing buffer would hold up to twice its words).
pub fn words_of<T: Message>(x: &T) -> Vec<f64> {
    let mut none = Vec::new();
    let mut counter = Writer {
        words: &mut none,
        counted: Some(0),
    };
    x.write(&mut counter);
    let n = counter.counted.unwrap_or(0);
    let mut words = Vec::with_capacity(n);
    x.write(&mut Writer::new(&mut words));
    debug_assert_eq!(words.len(), n);
    words
}

/// Reads the fields of messages from a buffer of words, in the order they were written.
pub struct Reader<'a> {
    words: &'a [f64],
    at: usize,
}

impl<'a> Reader<'a> {
    pub fn new(words: &'a [f64]) -> Self {
        Reader { words, at: 0 }
    }

    pub fn is_done(&self) -> bool {
        self.at == self.words.len()
    }

    /// The words not read yet.
    pub fn words_left(&self) -> usize {
        self.words.len() - self.at
    }

    pub fn real(&mut self) -> Option<f64> {
        let x = *self.words.get(self.at)?;
        self.at += 1;
        Some(x)
    }

    /// A whole number in [0, max].
    fn whole(&mut self, max: f64) -> Option<f64> {
        let x = self.real()?;
        (x >= 0.0 && x <= max && x.fract() == 0.0).then_some(x)
    }

    pub fn id(&mut self) -> Option<u32> {
        self.whole(u32::MAX as f64).map(|x| x as u32)
    }

    pub fn index(&mut self) -> Option<usize> {
        self.whole(((1u64 << 53) - 1) as f64).map(|x| x as usize)
    }

    pub fn flag(&mut self) -> Option<bool> {
        let x = self.real()?;
        if x == 0.0 {
            Some(false)
        } else if x == 1.0 {
            Some(true)
        } else {
            None
        }
    }

    pub fn reals<const N: usize>(&mut self) -> Option<[f64; N]> {
        let s = self.words.get(self.at..self.at + N)?;
        self.at += N;
        Some(std::array::from_fn(|i| s[i]))
    }

    /// Passes over `n` words (the padding of an absent optional part).
    pub fn skip(&mut self, n: usize) -> Option<()> {
        self.words.get(self.at..self.at + n)?;
        self.at += n;
        Some(())
    }

    pub fn get<T: Message>(&mut self) -> Option<T> {
        T::read(self)
    }
}

impl Message for f64 {
    fn write(&self, w: &mut Writer<'_>) {
        w.real(*self);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        r.real()
    }
}

impl Message for u32 {
    fn write(&self, w: &mut Writer<'_>) {
        w.id(*self);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        r.id()
    }
}

impl Message for bool {
    fn write(&self, w: &mut Writer<'_>) {
        w.flag(*self);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        r.flag()
    }
}

/// A text (a log line, a refusal) as its length and one word per byte.
impl Message for String {
    fn write(&self, w: &mut Writer<'_>) {
        w.index(self.len());
        for &b in self.as_bytes() {
            w.id(u32::from(b));
        }
    }
    fn read(r: &mut Reader) -> Option<Self> {
        let n = r.index()?;
        let bytes = (0..n)
            .map(|_| r.id().and_then(|b| u8::try_from(b).ok()))
            .collect::<Option<Vec<u8>>>()?;
        String::from_utf8(bytes).ok()
    }
}

impl<T: Message> Message for Option<T> {
    fn write(&self, w: &mut Writer<'_>) {
        w.flag(self.is_some());
        if let Some(x) = self {
            x.write(w);
        }
    }
    fn read(r: &mut Reader) -> Option<Self> {
        Some(if r.flag()? { Some(T::read(r)?) } else { None })
    }
}

impl<T: Message, E: Message> Message for Result<T, E> {
    fn write(&self, w: &mut Writer<'_>) {
        w.flag(self.is_ok());
        match self {
            Ok(x) => x.write(w),
            Err(e) => e.write(w),
        }
    }
    fn read(r: &mut Reader) -> Option<Self> {
        Some(if r.flag()? {
            Ok(T::read(r)?)
        } else {
            Err(E::read(r)?)
        })
    }
}

impl Message for usize {
    fn write(&self, w: &mut Writer<'_>) {
        w.index(*self);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        r.index()
    }
}

impl<const N: usize> Message for [f64; N] {
    fn write(&self, w: &mut Writer<'_>) {
        w.reals(self);
    }
    fn read(r: &mut Reader) -> Option<Self> {
        r.reals()
    }
}

/// A list of any length: its length, then its items.
impl<T: Message> Message for Vec<T> {
    fn write(&self, w: &mut Writer<'_>) {
        w.index(self.len());
        for x in self {
            w.put(x);
        }
    }
    fn read(r: &mut Reader) -> Option<Self> {
        let n = r.index()?;
        // Reserved at the list's length (held at its size: a list read by pushing would keep
        // up to twice its items' room), but never beyond the words left, since each item
        // takes at least one: a corrupt length must not allocate.
        let mut out = Vec::with_capacity(n.min(r.words_left()));
        for _ in 0..n {
            out.push(r.get()?);
        }
        Some(out)
    }
}

macro_rules! tuple_message {
    ($($t:ident $v:ident),+) => {
        impl<$($t: Message),+> Message for ($($t,)+) {
            fn write(&self, w: &mut Writer<'_>) {
                let ($($v,)+) = self;
                $(w.put($v);)+
            }
            fn read(r: &mut Reader) -> Option<Self> {
                Some(($(r.get::<$t>()?,)+))
            }
        }
    };
}

tuple_message!(A a, B b);
tuple_message!(A a, B b, C c);
tuple_message!(A a, B b, C c, D d);

/// Appends one message to a buffer of words.
pub fn push<T: Message>(words: &mut Vec<f64>, x: &T) {
    x.write(&mut Writer::new(words));
}

/// The words of a list of messages.
pub fn encode<T: Message>(items: &[T]) -> Vec<f64> {
    let mut words = Vec::new();
    let mut w = Writer::new(&mut words);
    for x in items {
        x.write(&mut w);
    }
    words
}

/// The list of messages `encode` wrote; None when the words are not such a list.
pub fn decode<T: Message>(words: &[f64]) -> Option<Vec<T>> {
    let mut r = Reader::new(words);
    let mut out = Vec::new();
    while !r.is_done() {
        out.push(T::read(&mut r)?);
    }
    Some(out)
}

/// Decodes a message another rank of this run wrote: malformed words there are a defect.
fn decode_sent<T: Message>(words: &[f64]) -> Vec<T> {
    decode(words).expect("a message written by another rank decodes")
}

/// The messages in words that ranks of this run wrote, one by one, without a list.
pub fn items<T: Message>(words: &[f64]) -> impl Iterator<Item = T> + '_ {
    let mut r = Reader::new(words);
    std::iter::from_fn(move || {
        (!r.is_done()).then(|| T::read(&mut r).expect("a message written by a rank decodes"))
    })
}

/// Rank 0 receives every rank's `items`, in rank order; the others an empty list.
/// Collective.
pub fn gather<T: Message, C: Comm + ?Sized>(comm: &C, items: &[T]) -> Vec<T> {
    joined(&comm.gather_f64(&encode(items)))
}

/// Every rank receives every rank's `items`, in rank order. Collective.
pub fn all_gather<T: Message, C: Comm + ?Sized>(comm: &C, items: &[T]) -> Vec<T> {
    joined(&comm.all_gather_f64(&encode(items)))
}

/// Every rank's items decoded, in rank order, into a list of exactly their number,
/// counted first (a list collected through `flat_map` or `decode` grows by doubling, up to
/// twice the items, and lists decoded rank by rank and then joined were held twice: the
/// contact set every rank holds is such a list, 0.6 MB at n = 40).
fn joined<T: Message>(parts: &[Vec<f64>]) -> Vec<T> {
    let count = parts.iter().map(|part| items::<T>(part).count()).sum();
    let mut all = Vec::with_capacity(count);
    for part in parts {
        all.extend(items::<T>(part));
    }
    all
}

/// Rank 0's `x` on every rank (`x` is read on rank 0 only, where it must be given).
/// Collective.
pub fn broadcast<T: Message, C: Comm + ?Sized>(comm: &C, x: Option<&T>) -> T {
    let mut bytes = Vec::new();
    if comm.is_root() {
        let words = words_of(x.expect("rank 0 gives the value it broadcasts"));
        bytes = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    }
    comm.broadcast_bytes(0, &mut bytes);
    let words: Vec<f64> = bytes
        .as_chunks::<8>()
        .0
        .iter()
        .map(|b| f64::from_le_bytes(*b))
        .collect();
    drop(bytes);
    one_sent(&words)
}

/// Rank 0's `x` on every rank, for a value of many types (serde's, sent as `postcard`'s
/// bytes: little-endian, so every f64 arrives bitwise): the problem rank 0 loaded. Rank 0
/// gets its own back, the others a copy (`x` is read on rank 0 only). Collective.
pub fn broadcast_value<T, C>(comm: &C, x: Option<T>) -> T
where
    T: serde::Serialize + serde::de::DeserializeOwned,
    C: Comm + ?Sized,
{
    if comm.is_root() {
        let x = x.expect("rank 0 gives the value it broadcasts");
        if comm.size() > 1 {
            let mut bytes = postcard::to_stdvec(&x).expect("a value of plain data serializes");
            comm.broadcast_bytes(0, &mut bytes);
        }
        return x;
    }
    let mut bytes = Vec::new();
    comm.broadcast_bytes(0, &mut bytes);
    postcard::from_bytes(&bytes).expect("rank 0's value deserializes")
}

/// Rank 0 makes every rank's message in turn (`make(r)`, called on rank 0 only) and sends
/// it before making the next (`Comm::scatter_f64`); every rank returns its own. Collective.
pub fn scatter<T: Message, C: Comm + ?Sized>(comm: &C, mut make: impl FnMut(usize) -> T) -> T {
    let words = comm.scatter_f64(&mut |r| words_of(&make(r)));
    one_sent(&words)
}

/// The one message in words another rank of this run wrote.
fn one_sent<T: Message>(words: &[f64]) -> T {
    let mut r = Reader::new(words);
    let x = T::read(&mut r).filter(|_| r.is_done());
    x.expect("a message written by another rank decodes")
}

/// Every rank sends `send[r]` (possibly empty) to rank r and receives every rank's list for
/// it, in rank order. Collective.
pub fn all_to_all<T: Message, C: Comm + ?Sized>(comm: &C, send: &[Vec<T>]) -> Vec<Vec<T>> {
    let words: Vec<Vec<f64>> = send.iter().map(|items| encode(items)).collect();
    comm.all_to_all_f64(&words)
        .iter()
        .map(|part| decode_sent(part))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tuples_round_trip() {
        let items = vec![(3u32, 7usize, [1.5, -2.0, 0.25]), (0, 1 << 40, [0.0; 3])];
        let words = encode(&items);
        assert_eq!(words.len(), 10);
        assert_eq!(decode::<(u32, usize, [f64; 3])>(&words), Some(items));
        let lists = vec![(7u32, vec![[1.0, 2.0], [3.0, 4.0]]), (9, vec![])];
        let words = encode(&lists);
        assert_eq!(words, [7.0, 2.0, 1.0, 2.0, 3.0, 4.0, 9.0, 0.0]);
        assert_eq!(decode::<(u32, Vec<[f64; 2]>)>(&words), Some(lists));
    }

    #[test]
    fn malformed_words_are_refused() {
        // A fraction, a negative number and a value past u32::MAX are not ids.
        for bad in [0.5, -1.0, 4294967296.0, f64::NAN] {
            assert_eq!(decode::<(u32, f64)>(&[bad, 1.0]), None, "{bad}");
        }
        // A list that ends inside a message.
        assert_eq!(decode::<(u32, f64)>(&[1.0, 2.0, 3.0]), None);
        let mut r = Reader::new(&[2.0]);
        assert_eq!(r.flag(), None);
    }

    #[test]
    fn texts_options_and_results_round_trip_in_counted_words() {
        let x: (String, Option<u32>, Result<Vec<bool>, String>, Option<f64>) = (
            "t\u{ea}te".to_string(),
            Some(7),
            Err("no".to_string()),
            None,
        );
        let words = words_of(&x);
        // "tête" is 5 bytes: length + 5; Some(7): 2; Err("no"): 1 + 3; None: 1.
        assert_eq!(words.len(), 6 + 2 + 4 + 1);
        assert_eq!(words.capacity(), words.len());
        let mut r = Reader::new(&words);
        assert_eq!(r.get(), Some(x));
        assert!(r.is_done());
        let ok: Result<Vec<bool>, String> = Ok(vec![true, false]);
        assert_eq!(one_sent::<Result<Vec<bool>, String>>(&words_of(&ok)), ok);
        // A byte beyond 255 is not text.
        assert_eq!(decode::<String>(&[1.0, 256.0]), None);
    }

    #[test]
    fn a_list_is_read_at_its_size_and_a_corrupt_length_allocates_nothing() {
        let list: Vec<u32> = (0..1000).collect();
        let read: Vec<u32> = one_sent(&words_of(&list));
        assert_eq!((read.len(), read.capacity()), (1000, 1000));
        // A length of 2^40 over two words: refused, having reserved two items' room.
        assert_eq!(decode::<Vec<u32>>(&[(1u64 << 40) as f64, 1.0, 2.0]), None);
    }
}
