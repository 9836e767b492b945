//! Fixed-length number arrays read exactly: `k1 = [4, 4, 4, 0, 4, 4]` has six entries, not
//! "at least six". Serde's own `[f64; N]` stops after N elements and the `toml` crate ignores
//! the rest, so `k1` with seven entries or `q = [1, 1, "x"]` used to load; here any other length
//! is an error that the `toml` crate reports with the key and its line.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserializer, IgnoredAny, SeqAccess, Visitor};

/// `#[serde(default, deserialize_with = "fixed_arrays::option")]` on an `Option<[f64; N]>` field.
pub(super) fn option<'de, D: Deserializer<'de>, const N: usize>(
    deserializer: D,
) -> Result<Option<[f64; N]>, D::Error> {
    deserializer
        .deserialize_seq(Exact::<N>(PhantomData))
        .map(Some)
}

struct Exact<const N: usize>(PhantomData<[f64; N]>);

impl<'de, const N: usize> Visitor<'de> for Exact<N> {
    type Value = [f64; N];

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array of exactly {N} numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[f64; N], A::Error> {
        let mut out = [0.0; N];
        for (i, x) in out.iter_mut().enumerate() {
            *x = seq
                .next_element()?
                .ok_or_else(|| de::Error::invalid_length(i, &self))?;
        }
        // Count what is left, whatever its type, so that the message gives the real length.
        let mut len = N;
        while seq.next_element::<IgnoredAny>()?.is_some() {
            len += 1;
        }
        if len != N {
            return Err(de::Error::invalid_length(len, &self));
        }
        Ok(out)
    }
}
