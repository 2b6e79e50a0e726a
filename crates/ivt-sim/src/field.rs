//! The machinery of a logged channel: a field's value written as JSON and CSV
//! text ([`Value`]), a field's name, unit and JSON-schema type ([`Field`]),
//! and a channel's sample ([`Record`], implemented by the `record!` macro).
//! The channels themselves are declared in [`crate::record`].
//!
//! Numbers are formatted by the same crates serde_json uses (`zmij` for
//! floats, `itoa` for integers), so the bytes are identical to
//! `serde_json::to_vec` of the sample: non-finite floats (ω_a before the
//! first revolution) are `null` in JSON and empty CSV cells.

use ivt_ctrl::Fault;
use serde::Serialize;

/// A field value: its JSON-schema type and its text.
pub trait Value: Copy {
    /// JSON-schema `type` of the field.
    const JSON_TYPE: &'static str;
    /// What serde serializes for the value.
    type Serde: Serialize;
    /// The value as serde serializes it.
    fn serde(self) -> Self::Serde;
    /// Appends the value's JSON text to `out`, or `null` when it has none
    /// (a non-finite float).
    fn write(self, out: &mut Vec<u8>, null: &[u8]);
}

/// Implements [`Value`] for types serde serializes as they are, from the
/// JSON-schema type and the text written for a value `x` (`null`: the text
/// of a value that has none).
macro_rules! value {
    ($json:literal, |$x:ident, $out:ident, $null:ident| $write:expr, $($t:ty),*) => {$(
        impl Value for $t {
            const JSON_TYPE: &'static str = $json;
            type Serde = Self;
            fn serde(self) -> Self {
                self
            }
            #[inline]
            fn write(self, $out: &mut Vec<u8>, $null: &[u8]) {
                let $x = self;
                $write
            }
        }
    )*};
}
value!(
    "number",
    |x, out, null| if x.is_finite() {
        out.extend_from_slice(zmij::Buffer::new().format_finite(x).as_bytes());
    } else {
        out.extend_from_slice(null);
    },
    f32,
    f64
);
value!(
    "integer",
    |x, out, _null| out.extend_from_slice(itoa::Buffer::new().format(x).as_bytes()),
    u8,
    u32,
    i32,
    i64,
    u64
);
value!(
    "boolean",
    |x, out, _null| out.extend_from_slice(if x { b"true" } else { b"false" }),
    bool
);

/// A fault is logged as its numeric code.
impl Value for Fault {
    const JSON_TYPE: &'static str = "integer";
    type Serde = u8;
    fn serde(self) -> u8 {
        self.code()
    }
    #[inline]
    fn write(self, out: &mut Vec<u8>, null: &[u8]) {
        self.code().write(out, null);
    }
}

/// One field of a channel: its name (JSON key, CSV column), its unit and its
/// JSON-schema type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    /// JSON key and CSV column.
    pub name: &'static str,
    /// SI unit (`""` for a flag or a code).
    pub unit: &'static str,
    /// JSON-schema `type`: `"number"`, `"integer"` or `"boolean"`.
    pub json_type: &'static str,
}

/// A sample of one logged channel.
pub trait Record: Copy {
    /// Channel name (`/NAME` topic, `ivt.NAME` schema, `_NAME.csv` file).
    const CHANNEL: &'static str;
    /// The fields, in order.
    const FIELDS: &'static [Field];
    /// Simulation time \[s\].
    fn time(&self) -> f64;
    /// Appends the sample as one JSON object.
    fn write_json(&self, out: &mut Vec<u8>);
    /// Appends the sample as one CSV row (fields in [`Record::FIELDS`] order, newline-terminated).
    fn write_csv(&self, out: &mut Vec<u8>);
}

/// Implements [`Record`] and `Serialize` from the field list
/// `name: type = "unit", …` (the struct's field order; `name in member: type
/// = "unit"` for a field of a member; a type that does not match the field
/// does not compile).
macro_rules! record {
    ($ty:ty, $channel:literal,
     $first:ident: $fty:ty = $funit:literal
     $(, $f:ident $(in $m:ident)?: $t:ty = $unit:literal)* $(,)?) => {
        impl $crate::field::Record for $ty {
            const CHANNEL: &'static str = $channel;
            const FIELDS: &'static [$crate::field::Field] = &[
                $crate::field::Field {
                    name: stringify!($first),
                    unit: $funit,
                    json_type: <$fty as $crate::field::Value>::JSON_TYPE,
                },
                $($crate::field::Field {
                    name: stringify!($f),
                    unit: $unit,
                    json_type: <$t as $crate::field::Value>::JSON_TYPE,
                },)*
            ];
            fn time(&self) -> f64 {
                self.$first
            }
            fn write_json(&self, out: &mut Vec<u8>) {
                out.extend_from_slice(concat!("{\"", stringify!($first), "\":").as_bytes());
                <$fty as $crate::field::Value>::write(self.$first, out, b"null");
                $(
                    out.extend_from_slice(concat!(",\"", stringify!($f), "\":").as_bytes());
                    <$t as $crate::field::Value>::write(self$(.$m)?.$f, out, b"null");
                )*
                out.push(b'}');
            }
            fn write_csv(&self, out: &mut Vec<u8>) {
                <$fty as $crate::field::Value>::write(self.$first, out, b"");
                $(
                    out.push(b',');
                    <$t as $crate::field::Value>::write(self$(.$m)?.$f, out, b"");
                )*
                out.push(b'\n');
            }
        }

        impl serde::Serialize for $ty {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                use serde::ser::SerializeStruct as _;
                use $crate::field::Record as _;
                let mut st = s.serialize_struct(stringify!($ty), Self::FIELDS.len())?;
                st.serialize_field(
                    stringify!($first),
                    &<$fty as $crate::field::Value>::serde(self.$first),
                )?;
                $(
                    st.serialize_field(
                        stringify!($f),
                        &<$t as $crate::field::Value>::serde(self$(.$m)?.$f),
                    )?;
                )*
                st.end()
            }
        }
    };
}
pub(crate) use record;
