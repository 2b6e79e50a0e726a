//! The numbers of a flat sequence of floats, collected by serde without
//! Python objects: the fast path of [`crate::to_python`] for an
//! [`ivt_jobs::Array`] of `f64` (one numpy array from a `Vec`, instead of a
//! Python list of floats handed to `numpy.asarray`). Anything else (nested
//! sequences, bools, strings) is refused with [`NotFlat`], and the caller
//! takes the general path.

use serde::ser::{self, Impossible, Serialize};
use std::fmt;

/// The content was not a flat sequence of floats.
#[derive(Debug)]
pub struct NotFlat;

impl fmt::Display for NotFlat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("not a flat sequence of floats")
    }
}

impl std::error::Error for NotFlat {}

impl ser::Error for NotFlat {
    fn custom<T: fmt::Display>(_msg: T) -> Self {
        Self
    }
}

/// The floats of `v` if it serializes as one sequence of `f64`.
pub fn flat_floats<T: Serialize + ?Sized>(v: &T) -> Option<Vec<f64>> {
    v.serialize(Sequence).ok()
}

/// Accepts one sequence (its elements by [`Float`]).
struct Sequence;

/// Accepts one `f64`.
struct Float;

/// The elements collected so far.
struct Elements(Vec<f64>);

impl ser::SerializeSeq for Elements {
    type Ok = Vec<f64>;
    type Error = NotFlat;
    fn serialize_element<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), NotFlat> {
        self.0.push(v.serialize(Float)?);
        Ok(())
    }
    fn end(self) -> Result<Vec<f64>, NotFlat> {
        Ok(self.0)
    }
}

/// The `Serializer` methods that refuse: every kind of value but the one the
/// serializer takes.
macro_rules! refuse {
    ($($method:ident($($arg:ty),*) -> $ret:ty;)+) => {$(
        fn $method(self, $(_: $arg),*) -> Result<$ret, NotFlat> {
            Err(NotFlat)
        }
    )+};
}

/// The methods both serializers refuse (all but `f64` and sequences).
macro_rules! refuse_common {
    ($ok:ty) => {
        refuse! {
            serialize_bool(bool) -> $ok;
            serialize_i8(i8) -> $ok;
            serialize_i16(i16) -> $ok;
            serialize_i32(i32) -> $ok;
            serialize_i64(i64) -> $ok;
            serialize_u8(u8) -> $ok;
            serialize_u16(u16) -> $ok;
            serialize_u32(u32) -> $ok;
            serialize_u64(u64) -> $ok;
            serialize_f32(f32) -> $ok;
            serialize_char(char) -> $ok;
            serialize_str(&str) -> $ok;
            serialize_bytes(&[u8]) -> $ok;
            serialize_none() -> $ok;
            serialize_unit() -> $ok;
            serialize_unit_struct(&'static str) -> $ok;
            serialize_unit_variant(&'static str, u32, &'static str) -> $ok;
            serialize_tuple(usize) -> Impossible<$ok, NotFlat>;
            serialize_tuple_struct(&'static str, usize) -> Impossible<$ok, NotFlat>;
            serialize_tuple_variant(&'static str, u32, &'static str, usize) -> Impossible<$ok, NotFlat>;
            serialize_map(Option<usize>) -> Impossible<$ok, NotFlat>;
            serialize_struct(&'static str, usize) -> Impossible<$ok, NotFlat>;
            serialize_struct_variant(&'static str, u32, &'static str, usize) -> Impossible<$ok, NotFlat>;
        }
        fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<$ok, NotFlat> {
            Err(NotFlat)
        }
        fn serialize_newtype_struct<T: Serialize + ?Sized>(
            self,
            _: &'static str,
            _: &T,
        ) -> Result<$ok, NotFlat> {
            Err(NotFlat)
        }
        fn serialize_newtype_variant<T: Serialize + ?Sized>(
            self,
            _: &'static str,
            _: u32,
            _: &'static str,
            _: &T,
        ) -> Result<$ok, NotFlat> {
            Err(NotFlat)
        }
    };
}

impl ser::Serializer for Sequence {
    type Ok = Vec<f64>;
    type Error = NotFlat;
    type SerializeSeq = Elements;
    type SerializeTuple = Impossible<Vec<f64>, NotFlat>;
    type SerializeTupleStruct = Impossible<Vec<f64>, NotFlat>;
    type SerializeTupleVariant = Impossible<Vec<f64>, NotFlat>;
    type SerializeMap = Impossible<Vec<f64>, NotFlat>;
    type SerializeStruct = Impossible<Vec<f64>, NotFlat>;
    type SerializeStructVariant = Impossible<Vec<f64>, NotFlat>;

    refuse_common!(Vec<f64>);
    refuse! { serialize_f64(f64) -> Vec<f64>; }
    fn serialize_seq(self, len: Option<usize>) -> Result<Elements, NotFlat> {
        Ok(Elements(Vec::with_capacity(len.unwrap_or(0))))
    }
}

impl ser::Serializer for Float {
    type Ok = f64;
    type Error = NotFlat;
    type SerializeSeq = Impossible<f64, NotFlat>;
    type SerializeTuple = Impossible<f64, NotFlat>;
    type SerializeTupleStruct = Impossible<f64, NotFlat>;
    type SerializeTupleVariant = Impossible<f64, NotFlat>;
    type SerializeMap = Impossible<f64, NotFlat>;
    type SerializeStruct = Impossible<f64, NotFlat>;
    type SerializeStructVariant = Impossible<f64, NotFlat>;

    refuse_common!(f64);
    refuse! { serialize_seq(Option<usize>) -> Impossible<f64, NotFlat>; }
    fn serialize_f64(self, v: f64) -> Result<f64, NotFlat> {
        Ok(v)
    }
}
