//! Sequences refused while they are decoded, as soon as they run past a bound, before their
//! elements are allocated: a message is hostile input, and a length prefix costs its sender four
//! bytes.

use serde::{Deserialize, Deserializer};

/// A sequence of at most `max` entries; past that, the error "a `what` of N entries; at most
/// `max` allowed". For `deserialize_with`, wrap it in a function that fixes `max` and `what`.
pub(super) fn bounded_vec<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D, max: usize, what: &'static str) -> Result<Vec<T>, D::Error> {
    struct Bounded<T> {
        max: usize,
        what: &'static str,
        entries: std::marker::PhantomData<T>,
    }
    impl<'de, T: Deserialize<'de>> serde::de::Visitor<'de> for Bounded<T> {
        type Value = Vec<T>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            write!(f, "a sequence of at most {} entries", self.max)
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
            let (max, what) = (self.max, self.what);
            let too_long = |n: &str| serde::de::Error::custom(format!("a {what} of {n} entries; at most {max} allowed"));
            if let Some(n) = seq.size_hint().filter(|n| *n > max) {
                return Err(too_long(&n.to_string()));
            }
            let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1024));
            while let Some(x) = seq.next_element()? {
                if out.len() == max {
                    return Err(too_long(&format!("more than {max}")));
                }
                out.push(x);
            }
            Ok(out)
        }
    }
    d.deserialize_seq(Bounded { max, what, entries: std::marker::PhantomData })
}
