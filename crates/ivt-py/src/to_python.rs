//! The results of `ivt_jobs` as Python objects, by serde: a struct or map
//! becomes a dict (its field names are the JSON keys of the CLI), a sequence
//! a list, a unit enum variant its snake_case name, `None` None, and an
//! [`ivt_jobs::Array`] a numpy array. Floats stay floats (NaN included,
//! which JSON would turn into null).

use crate::flat_floats::flat_floats;
use ivt_jobs::ARRAY_NAME;
use numpy::IntoPyArray;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};
use pyo3::IntoPyObjectExt;
use serde::ser::{self, Serialize};
use std::fmt;

/// A job result as a dict.
///
/// # Errors
/// `TypeError` when `value` does not serialize to a mapping; a Python error
/// raised on the way (numpy missing, memory).
pub fn to_dict<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyDict>> {
    let obj = value.serialize(Ser { py }).map_err(|e| e.0)?;
    obj.cast_into::<PyDict>()
        .map_err(|_| PyTypeError::new_err("a job result must serialize to a dict"))
}

/// The error of the serializer: the Python exception it met.
#[derive(Debug)]
pub struct Error(PyErr);

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for Error {}

impl ser::Error for Error {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self(PyTypeError::new_err(msg.to_string()))
    }
}

impl From<PyErr> for Error {
    fn from(e: PyErr) -> Self {
        Self(e)
    }
}

type Res<'py> = Result<Bound<'py, PyAny>, Error>;

/// Serializes into Python objects.
#[derive(Clone, Copy)]
struct Ser<'py> {
    py: Python<'py>,
}

impl<'py> Ser<'py> {
    fn any<T: IntoPyObject<'py>>(self, v: T) -> Res<'py> {
        Ok(v.into_bound_py_any(self.py)?)
    }

    /// `{variant: value}` (externally tagged, as serde_json).
    fn tagged(self, variant: &str, value: Bound<'py, PyAny>) -> Res<'py> {
        let d = PyDict::new(self.py);
        d.set_item(variant, value)?;
        Ok(d.into_any())
    }
}

/// Items of a list (sequences, tuples); `variant` tags a tuple variant.
struct SeqSer<'py> {
    ser: Ser<'py>,
    items: Vec<Bound<'py, PyAny>>,
    variant: Option<&'static str>,
}

impl<'py> SeqSer<'py> {
    fn push<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Error> {
        self.items.push(v.serialize(self.ser)?);
        Ok(())
    }
    fn finish(self) -> Res<'py> {
        let list = PyList::new(self.ser.py, self.items)?.into_any();
        match self.variant {
            Some(v) => self.ser.tagged(v, list),
            None => Ok(list),
        }
    }
}

/// Entries of a dict (maps, structs); `variant` tags a struct variant.
struct MapSer<'py> {
    ser: Ser<'py>,
    dict: Bound<'py, PyDict>,
    key: Option<Bound<'py, PyAny>>,
    variant: Option<&'static str>,
}

impl<'py> MapSer<'py> {
    fn finish(self) -> Res<'py> {
        let dict = self.dict.into_any();
        match self.variant {
            Some(v) => self.ser.tagged(v, dict),
            None => Ok(dict),
        }
    }
    fn field<T: Serialize + ?Sized>(&mut self, key: &str, v: &T) -> Result<(), Error> {
        let value = v.serialize(self.ser)?;
        self.dict.set_item(key, value)?;
        Ok(())
    }
}

/// The `Serializer` methods of the scalars Python takes as they are (`int`,
/// `float`, `bool`, a one-character `str`, `bytes`).
macro_rules! scalar_methods {
    ($($method:ident: $t:ty),+ $(,)?) => {$(
        fn $method(self, v: $t) -> Res<'py> {
            self.any(v)
        }
    )+};
}

impl<'py> ser::Serializer for Ser<'py> {
    type Ok = Bound<'py, PyAny>;
    type Error = Error;
    type SerializeSeq = SeqSer<'py>;
    type SerializeTuple = SeqSer<'py>;
    type SerializeTupleStruct = SeqSer<'py>;
    type SerializeTupleVariant = SeqSer<'py>;
    type SerializeMap = MapSer<'py>;
    type SerializeStruct = MapSer<'py>;
    type SerializeStructVariant = MapSer<'py>;

    scalar_methods!(
        serialize_bool: bool, serialize_char: char, serialize_f64: f64, serialize_bytes: &[u8],
        serialize_i8: i8, serialize_i16: i16, serialize_i32: i32, serialize_i64: i64,
        serialize_u8: u8, serialize_u16: u16, serialize_u32: u32, serialize_u64: u64,
    );
    fn serialize_f32(self, v: f32) -> Res<'py> {
        self.any(f64::from(v))
    }
    fn serialize_str(self, v: &str) -> Res<'py> {
        Ok(PyString::new(self.py, v).into_any())
    }
    fn serialize_none(self) -> Res<'py> {
        Ok(self.py.None().into_bound(self.py))
    }
    fn serialize_some<T: Serialize + ?Sized>(self, v: &T) -> Res<'py> {
        v.serialize(self)
    }
    fn serialize_unit(self) -> Res<'py> {
        self.serialize_none()
    }
    fn serialize_unit_struct(self, _name: &'static str) -> Res<'py> {
        self.serialize_none()
    }
    fn serialize_unit_variant(
        self,
        _name: &'static str,
        _i: u32,
        variant: &'static str,
    ) -> Res<'py> {
        self.serialize_str(variant)
    }
    /// An [`ivt_jobs::Array`] becomes a numpy array (of `f64` straight
    /// from its numbers, [`crate::flat_floats`]; otherwise
    /// `numpy.asarray(list)`); any other newtype is its content.
    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        name: &'static str,
        v: &T,
    ) -> Res<'py> {
        if name == ARRAY_NAME {
            if let Some(floats) = flat_floats(v) {
                return Ok(floats.into_pyarray(self.py).into_any());
            }
        }
        let inner = v.serialize(self)?;
        if name == ARRAY_NAME {
            let np = self.py.import("numpy")?;
            return Ok(np.call_method1("asarray", (inner,))?);
        }
        Ok(inner)
    }
    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _name: &'static str,
        _i: u32,
        variant: &'static str,
        v: &T,
    ) -> Res<'py> {
        let value = v.serialize(self)?;
        self.tagged(variant, value)
    }
    fn serialize_seq(self, len: Option<usize>) -> Result<SeqSer<'py>, Error> {
        Ok(SeqSer {
            ser: self,
            items: Vec::with_capacity(len.unwrap_or(0)),
            variant: None,
        })
    }
    fn serialize_tuple(self, len: usize) -> Result<SeqSer<'py>, Error> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_struct(self, _name: &'static str, len: usize) -> Result<SeqSer<'py>, Error> {
        self.serialize_seq(Some(len))
    }
    fn serialize_tuple_variant(
        self,
        _name: &'static str,
        _i: u32,
        variant: &'static str,
        len: usize,
    ) -> Result<SeqSer<'py>, Error> {
        let mut s = self.serialize_seq(Some(len))?;
        s.variant = Some(variant);
        Ok(s)
    }
    fn serialize_map(self, _len: Option<usize>) -> Result<MapSer<'py>, Error> {
        Ok(MapSer {
            ser: self,
            dict: PyDict::new(self.py),
            key: None,
            variant: None,
        })
    }
    fn serialize_struct(self, _name: &'static str, _len: usize) -> Result<MapSer<'py>, Error> {
        self.serialize_map(None)
    }
    fn serialize_struct_variant(
        self,
        _name: &'static str,
        _i: u32,
        variant: &'static str,
        _len: usize,
    ) -> Result<MapSer<'py>, Error> {
        let mut m = self.serialize_map(None)?;
        m.variant = Some(variant);
        Ok(m)
    }
}

/// The four sequence traits of serde (`Seq`, `Tuple`, `TupleStruct`,
/// `TupleVariant`) all push an element onto the one list and end with it;
/// `$push` is the trait's name for "add an element".
macro_rules! seq_impl {
    ($($trait:ident :: $push:ident),+ $(,)?) => {$(
        impl<'py> ser::$trait for SeqSer<'py> {
            type Ok = Bound<'py, PyAny>;
            type Error = Error;
            fn $push<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Error> {
                self.push(v)
            }
            fn end(self) -> Res<'py> {
                self.finish()
            }
        }
    )+};
}

seq_impl!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field,
    SerializeTupleVariant::serialize_field,
);

impl<'py> ser::SerializeMap for MapSer<'py> {
    type Ok = Bound<'py, PyAny>;
    type Error = Error;
    fn serialize_key<T: Serialize + ?Sized>(&mut self, k: &T) -> Result<(), Error> {
        self.key = Some(k.serialize(self.ser)?);
        Ok(())
    }
    fn serialize_value<T: Serialize + ?Sized>(&mut self, v: &T) -> Result<(), Error> {
        let key = self
            .key
            .take()
            .ok_or_else(|| <Error as ser::Error>::custom("a map value without its key"))?;
        let value = v.serialize(self.ser)?;
        self.dict.set_item(key, value)?;
        Ok(())
    }
    fn end(self) -> Res<'py> {
        self.finish()
    }
}

/// A struct and a struct variant both set a named field of the one dict.
macro_rules! struct_impl {
    ($($trait:ident),+ $(,)?) => {$(
        impl<'py> ser::$trait for MapSer<'py> {
            type Ok = Bound<'py, PyAny>;
            type Error = Error;
            fn serialize_field<T: Serialize + ?Sized>(
                &mut self,
                key: &'static str,
                v: &T,
            ) -> Result<(), Error> {
                self.field(key, v)
            }
            fn end(self) -> Res<'py> {
                self.finish()
            }
        }
    )+};
}

struct_impl!(SerializeStruct, SerializeStructVariant);
