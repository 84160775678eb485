//! The JSON of the report: a value whose objects keep their keys in the order they were
//! written (and read back in document order), and a builder of flat records.

use crate::stats::Stat;
use serde::de::{Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::ser::{SerializeMap, SerializeSeq};
use serde::{Serialize, Serializer};

/// A JSON value whose objects keep their keys in insertion order.
#[derive(Clone)]
pub enum J {
    Null,
    Bool(bool),
    Int(i64),
    Num(f64),
    Str(String),
    Arr(Vec<J>),
    Obj(Vec<(String, J)>),
}

impl Serialize for J {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            J::Null => s.serialize_unit(),
            J::Bool(b) => s.serialize_bool(*b),
            J::Int(i) => s.serialize_i64(*i),
            J::Num(x) if x.is_finite() => s.serialize_f64(*x),
            J::Num(_) => s.serialize_unit(),
            J::Str(t) => s.serialize_str(t),
            J::Arr(v) => {
                let mut seq = s.serialize_seq(Some(v.len()))?;
                for x in v {
                    seq.serialize_element(x)?;
                }
                seq.end()
            }
            J::Obj(kv) => {
                let mut map = s.serialize_map(Some(kv.len()))?;
                for (k, v) in kv {
                    map.serialize_entry(k, v)?;
                }
                map.end()
            }
        }
    }
}

/// JSON read back in document order (the large section is merged into an earlier
/// results.json and carried over by a later run without reordering the file).
impl<'de> Deserialize<'de> for J {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<J, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = J;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a JSON value")
            }
            fn visit_unit<E>(self) -> Result<J, E> {
                Ok(J::Null)
            }
            fn visit_none<E>(self) -> Result<J, E> {
                Ok(J::Null)
            }
            fn visit_bool<E>(self, b: bool) -> Result<J, E> {
                Ok(J::Bool(b))
            }
            fn visit_i64<E>(self, i: i64) -> Result<J, E> {
                Ok(J::Int(i))
            }
            fn visit_u64<E>(self, u: u64) -> Result<J, E> {
                Ok(i64::try_from(u).map_or(J::Num(u as f64), J::Int))
            }
            fn visit_f64<E>(self, x: f64) -> Result<J, E> {
                Ok(J::Num(x))
            }
            fn visit_str<E>(self, t: &str) -> Result<J, E> {
                Ok(J::Str(t.to_string()))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut a: A) -> Result<J, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = a.next_element()? {
                    v.push(x);
                }
                Ok(J::Arr(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<J, A::Error> {
                let mut kv = Vec::new();
                while let Some(entry) = a.next_entry::<String, J>()? {
                    kv.push(entry);
                }
                Ok(J::Obj(kv))
            }
        }
        d.deserialize_any(V)
    }
}

impl J {
    /// The value of `key` in an object.
    pub fn get(&self, key: &str) -> Option<&J> {
        match self {
            J::Obj(kv) => kv.iter().find(|(k, _)| k == key).map(|(_, v)| v),
            _ => None,
        }
    }

    /// Sets `key` of an object (in place when present, else at the end).
    pub fn set(&mut self, key: &str, v: J) {
        if let J::Obj(kv) = self {
            match kv.iter_mut().find(|(k, _)| k == key) {
                Some(e) => e.1 = v,
                None => kv.push((key.to_string(), v)),
            }
        }
    }
}

impl From<f64> for J {
    fn from(x: f64) -> J {
        J::Num(x)
    }
}
impl From<usize> for J {
    fn from(x: usize) -> J {
        J::Int(x as i64)
    }
}
impl From<u64> for J {
    fn from(x: u64) -> J {
        J::Int(x as i64)
    }
}
impl From<bool> for J {
    fn from(x: bool) -> J {
        J::Bool(x)
    }
}
impl From<&str> for J {
    fn from(x: &str) -> J {
        J::Str(x.to_string())
    }
}
impl From<String> for J {
    fn from(x: String) -> J {
        J::Str(x)
    }
}
impl<T: Into<J>> From<Option<T>> for J {
    fn from(x: Option<T>) -> J {
        x.map_or(J::Null, Into::into)
    }
}

/// Builder of a flat JSON record.
#[derive(Default)]
pub struct Rec(Vec<(String, J)>);

impl Rec {
    pub fn put(mut self, key: &str, v: impl Into<J>) -> Self {
        self.0.push((key.to_string(), v.into()));
        self
    }

    /// `<prefix>_median`, `<prefix>_min`, `<prefix>_max`.
    pub fn stat(mut self, prefix: &str, s: &Stat) -> Self {
        self.0.push((format!("{prefix}_median"), J::Num(s.median)));
        self.0.push((format!("{prefix}_min"), J::Num(s.min)));
        self.0.push((format!("{prefix}_max"), J::Num(s.max)));
        self
    }

    /// Appends the fields of `other`.
    pub fn extend(mut self, other: Rec) -> Self {
        self.0.extend(other.0);
        self
    }

    pub fn json(self) -> J {
        J::Obj(self.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// results.json read back keeps its key order, and a key set into it goes last (or
    /// replaces the earlier one in place).
    #[test]
    fn json_round_trip_keeps_order() {
        let text = r#"{"schema":"x","z":[1,2.5,null,true],"a":{"k":"v","b":-3}}"#;
        let mut j: J = serde_json::from_str(text).unwrap();
        assert_eq!(serde_json::to_string(&j).unwrap(), text);
        j.set("large", J::Int(1));
        j.set("z", J::Null);
        assert_eq!(
            serde_json::to_string(&j).unwrap(),
            r#"{"schema":"x","z":null,"a":{"k":"v","b":-3},"large":1}"#
        );
        assert!(matches!(j.get("large"), Some(J::Int(1))));
    }

    /// A statistic is three keys; a number that is not finite is written as null, never
    /// as NaN.
    #[test]
    fn records_of_statistics() {
        let s = Stat::of(&[1.0, 2.0, 4.0]);
        let rec = Rec::default()
            .put("n", 3usize)
            .stat("t", &s)
            .put("none", None::<f64>)
            .put("nan", f64::NAN)
            .json();
        assert_eq!(
            serde_json::to_string(&rec).unwrap(),
            r#"{"n":3,"t_median":2.0,"t_min":1.0,"t_max":4.0,"none":null,"nan":null}"#
        );
    }
}
