//! Channel samples as JSON objects and CSV rows, written straight into a
//! reused byte buffer, and serialized through serde (the Python bindings'
//! columns).
//!
//! The MCAP log of the default scene holds ≈ 24 000 JSON messages; through
//! serde_json's generic path (a fresh `Vec` per message, the `Serializer`
//! state machine) they cost more than a third of the whole run. Here each
//! sample type lists its fields once (the `record!` macro): that list gives the JSON
//! schema of the channel, the JSON object, the CSV row and the serde
//! `Serialize` impl; a field may sit in a member (`omega in out`: the
//! control sample logs the controller's `ControlOutput` as it is). Numbers are
//! formatted by the same crates serde_json uses (`zmij` for floats, `itoa` for
//! integers), so the bytes are identical to `serde_json::to_vec` of the
//! sample (test `json_is_byte_identical_to_serde_json`): non-finite floats
//! (ω_a before the first revolution) are `null` in JSON and empty CSV cells.

use crate::run::{ControlSample, PlantSample, SensorSample, StepperSample};
use ivt_ctrl::Fault;
use serde::ser::{Serialize, SerializeStruct, Serializer};

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

/// A sample of one logged channel.
pub trait Record: Copy {
    /// Channel name (`/NAME` topic, `ivt.NAME` schema).
    const CHANNEL: &'static str;
    /// Field names and JSON-schema types, in order.
    const FIELDS: &'static [(&'static str, &'static str)];
    /// Simulation time \[s\].
    fn time(&self) -> f64;
    /// Appends the sample as one JSON object.
    fn write_json(&self, out: &mut Vec<u8>);
    /// Appends the sample as one CSV row (fields in [`Record::FIELDS`] order, newline-terminated).
    fn write_csv(&self, out: &mut Vec<u8>);
}

/// Implements [`Record`] and `Serialize` from the field list `name: type, …`
/// (the struct's field order; `name in member: type` for a field of a
/// member; a type that does not match the field does not compile).
macro_rules! record {
    ($ty:ty, $channel:literal, $first:ident: $fty:ty $(, $f:ident $(in $m:ident)?: $t:ty)* $(,)?) => {
        impl Record for $ty {
            const CHANNEL: &'static str = $channel;
            const FIELDS: &'static [(&'static str, &'static str)] = &[
                (stringify!($first), <$fty as Value>::JSON_TYPE),
                $((stringify!($f), <$t as Value>::JSON_TYPE),)*
            ];
            fn time(&self) -> f64 {
                self.$first
            }
            fn write_json(&self, out: &mut Vec<u8>) {
                out.extend_from_slice(concat!("{\"", stringify!($first), "\":").as_bytes());
                <$fty as Value>::write(self.$first, out, b"null");
                $(
                    out.extend_from_slice(concat!(",\"", stringify!($f), "\":").as_bytes());
                    <$t as Value>::write(self$(.$m)?.$f, out, b"null");
                )*
                out.push(b'}');
            }
            fn write_csv(&self, out: &mut Vec<u8>) {
                <$fty as Value>::write(self.$first, out, b"");
                $(
                    out.push(b',');
                    <$t as Value>::write(self$(.$m)?.$f, out, b"");
                )*
                out.push(b'\n');
            }
        }

        impl Serialize for $ty {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let mut st = s.serialize_struct(stringify!($ty), Self::FIELDS.len())?;
                st.serialize_field(stringify!($first), &<$fty as Value>::serde(self.$first))?;
                $(
                    st.serialize_field(stringify!($f), &<$t as Value>::serde(self$(.$m)?.$f))?;
                )*
                st.end()
            }
        }
    };
}

record!(
    PlantSample,
    "plant",
    t: f64,
    theta: f64,
    omega: f64,
    omega_a: f64,
    r: f64,
    v_m: f64,
    t_u: f64,
    i_a: f64,
);
record!(
    ControlSample,
    "control",
    t: f64,
    ticks: u32,
    omega in out: f32,
    omega_a in out: f32,
    omega_t in out: f32,
    r_ol in out: f32,
    r_d in out: f32,
    r in out: f32,
    stepper_target in out: i32,
    saturated in out: bool,
    fault in out: Fault,
);
record!(
    StepperSample,
    "stepper",
    t: f64,
    target: i64,
    commanded: i64,
    position: i64,
    missed: u64,
);
record!(SensorSample, "sensors", t: f64, v_m: f64, t_u: f64);

/// One recorded sample of any channel, as the run loop hands it to a
/// streaming sink (the MCAP writer thread).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Sample {
    /// A `plant` sample.
    Plant(PlantSample),
    /// A `control` sample.
    Control(ControlSample),
    /// A `stepper` sample.
    Stepper(StepperSample),
    /// A `sensors` sample.
    Sensors(SensorSample),
}

/// The channels in log order (their MCAP channel ids follow this order).
pub const CHANNELS: [&str; 4] = [
    PlantSample::CHANNEL,
    ControlSample::CHANNEL,
    StepperSample::CHANNEL,
    SensorSample::CHANNEL,
];

impl Sample {
    /// Index of the sample's channel in [`CHANNELS`].
    pub fn channel(&self) -> usize {
        match self {
            Sample::Plant(_) => 0,
            Sample::Control(_) => 1,
            Sample::Stepper(_) => 2,
            Sample::Sensors(_) => 3,
        }
    }

    /// Simulation time \[s\].
    pub fn time(&self) -> f64 {
        match self {
            Sample::Plant(s) => s.time(),
            Sample::Control(s) => s.time(),
            Sample::Stepper(s) => s.time(),
            Sample::Sensors(s) => s.time(),
        }
    }

    /// Appends the sample as one JSON object.
    pub fn write_json(&self, out: &mut Vec<u8>) {
        match self {
            Sample::Plant(s) => s.write_json(out),
            Sample::Control(s) => s.write_json(out),
            Sample::Stepper(s) => s.write_json(out),
            Sample::Sensors(s) => s.write_json(out),
        }
    }
}

/// Field names and JSON-schema types of the channel `name`, in column order
/// (empty for an unknown name).
pub fn channel_fields(name: &str) -> &'static [(&'static str, &'static str)] {
    match name {
        PlantSample::CHANNEL => PlantSample::FIELDS,
        ControlSample::CHANNEL => ControlSample::FIELDS,
        StepperSample::CHANNEL => StepperSample::FIELDS,
        SensorSample::CHANNEL => SensorSample::FIELDS,
        _ => &[],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_ctrl::ControlOutput;

    fn same_as_serde<T: Record + Serialize>(s: T) {
        let mut ours = vec![];
        s.write_json(&mut ours);
        let theirs = serde_json::to_vec(&s).unwrap();
        assert_eq!(
            String::from_utf8_lossy(&ours),
            String::from_utf8_lossy(&theirs)
        );
        // the schema's field names are the serialized keys, in order
        let v: serde_json::Map<String, serde_json::Value> = serde_json::from_slice(&ours).unwrap();
        let keys: Vec<&str> = v.keys().map(String::as_str).collect();
        let mut names: Vec<&str> = T::FIELDS.iter().map(|(n, _)| *n).collect();
        names.sort_unstable(); // serde_json::Map is ordered by key
        assert_eq!(keys, names);
    }

    /// Values across magnitudes, signs, exponents, integers extremes and
    /// non-finite floats: the bytes equal serde_json's.
    #[test]
    fn json_is_byte_identical_to_serde_json() {
        let floats = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            0.1,
            1.0 / 3.0,
            std::f64::consts::PI * 1e-7,
            6.02e23,
            1e-300,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for (k, &x) in floats.iter().enumerate() {
            let y = floats[(k + 3) % floats.len()];
            same_as_serde(PlantSample {
                t: x.abs(),
                theta: x,
                omega: y,
                omega_a: x * 0.7,
                r: y * 1e-3,
                v_m: x,
                t_u: y,
                i_a: x,
            });
            same_as_serde(ControlSample {
                t: x,
                ticks: [0, 1, u32::MAX][k % 3],
                out: ControlOutput {
                    omega: x as f32,
                    omega_a: y as f32,
                    omega_t: (x * 1e-3) as f32,
                    r_ol: (y * 3.3) as f32,
                    r_d: f32::MIN_POSITIVE,
                    r: -1e-7,
                    stepper_target: [i32::MIN, -1, 0, i32::MAX][k % 4],
                    saturated: k % 2 == 0,
                    fault: [Fault::None, Fault::InputInvalid, Fault::Config][k % 3],
                    ..ControlOutput::IDLE
                },
            });
            same_as_serde(StepperSample {
                t: y,
                target: [i64::MIN, -3, i64::MAX][k % 3],
                commanded: k as i64,
                position: -(k as i64),
                missed: [0, u64::MAX][k % 2],
            });
            same_as_serde(SensorSample {
                t: x,
                v_m: y,
                t_u: x,
            });
        }
    }

    #[test]
    fn csv_rows_leave_non_finite_cells_empty() {
        let mut row = vec![];
        SensorSample {
            t: 0.5,
            v_m: f64::NAN,
            t_u: 2.0,
        }
        .write_csv(&mut row);
        assert_eq!(row, b"0.5,,2.0\n");
    }
}
