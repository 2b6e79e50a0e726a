//! The simulator's channels, declared once. Each channel is a sample struct
//! with its field list (name, unit; the `record!` macro of [`crate::field`]
//! gives the JSON schema, the JSON object, the CSV row and the serde
//! `Serialize` impl) and one line of the `channels!` table, which gives the
//! [`Channel`] enum (names, log order, lookup by name), the [`Sample`] enum
//! the run loop streams, and the recorded [`Channels`]. The MCAP schemas
//! ([`crate::output::json_schema`]), the CSV headers, the scene's
//! `[[outputs.channels]]` names and the reproduction read this table; the plot
//! panels ([`Panel`]) are fields of the `plant` channel.
//!
//! Adding a channel is one edit here: its sample struct, its `record!` field
//! list and its `channels!` line (plus the place in [`crate::run`] that
//! records it); `tests/channels.rs` checks, for every channel of the table,
//! that the scene names it and that it reaches the MCAP schema and topic, the
//! CSV header and the lookup by name, and that every plot panel is a `plant`
//! field.
//!
//! The MCAP log of the default scene holds ≈ 24 000 JSON messages; through
//! serde_json's generic path (a fresh `Vec` per message, the `Serializer`
//! state machine) they cost more than a third of the whole run, so each
//! sample writes its own bytes, identical to `serde_json::to_vec` of the
//! sample (test `json_is_byte_identical_to_serde_json`).

use crate::field::record;
pub use crate::field::{Field, Record};
use ivt_ctrl::ControlOutput;
use serde::{Deserialize, Deserializer};

/// One `plant` channel sample (at a pulse).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlantSample {
    /// Time \[s\].
    pub t: f64,
    /// θ \[rad\].
    pub theta: f64,
    /// ω \[rad/s\].
    pub omega: f64,
    /// ω_a from the exact pulse times (NaN for the first revolution) \[rad/s\].
    pub omega_a: f64,
    /// Real eccentricity r \[m\].
    pub r: f64,
    /// True V_m \[V\].
    pub v_m: f64,
    /// True T_U \[N·m\].
    pub t_u: f64,
    /// Armature current: the state with L_a > 0 (Eq. 137), the algebraic
    /// (V_m − k_e f ω)/R_a with L_a = 0 (Eq. 138) \[A\].
    pub i_a: f64,
}

/// One `control` channel sample: the backend's [`ControlOutput`] for the
/// pulse at `t` with timer capture `ticks`, as the controller returned it
/// (the channel logs the fields listed below).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ControlSample {
    /// Time \[s\].
    pub t: f64,
    /// Timer capture \[ticks\].
    pub ticks: u32,
    /// The controller's answer to the pulse.
    pub out: ControlOutput,
}

/// One `stepper` channel sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepperSample {
    /// Time \[s\].
    pub t: f64,
    /// Target from the controller \[steps\].
    pub target: i64,
    /// Steps issued \[steps\].
    pub commanded: i64,
    /// Real position \[steps\].
    pub position: i64,
    /// Steps lost so far.
    pub missed: u64,
}

/// One `sensors` channel sample (what the controller was given).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorSample {
    /// Time \[s\].
    pub t: f64,
    /// V_m reading \[V\].
    pub v_m: f64,
    /// T_U reading \[N·m\].
    pub t_u: f64,
}

record!(
    PlantSample,
    "plant",
    t: f64 = "s",
    theta: f64 = "rad",
    omega: f64 = "rad/s",
    omega_a: f64 = "rad/s",
    r: f64 = "m",
    v_m: f64 = "V",
    t_u: f64 = "N·m",
    i_a: f64 = "A",
);
record!(
    ControlSample,
    "control",
    t: f64 = "s",
    ticks: u32 = "ticks",
    omega in out: f32 = "rad/s",
    omega_a in out: f32 = "rad/s",
    omega_t in out: f32 = "rad/s",
    r_ol in out: f32 = "m",
    r_d in out: f32 = "m",
    r in out: f32 = "m",
    stepper_target in out: i32 = "steps",
    saturated in out: bool = "",
    fault in out: ivt_ctrl::Fault = "",
);
record!(
    StepperSample,
    "stepper",
    t: f64 = "s",
    target: i64 = "steps",
    commanded: i64 = "steps",
    position: i64 = "steps",
    missed: u64 = "steps",
);
record!(
    SensorSample,
    "sensors",
    t: f64 = "s",
    v_m: f64 = "V",
    t_u: f64 = "N·m",
);

/// The [`Channel`] enum, the [`Sample`] enum and the recorded [`Channels`]
/// from the list `Variant(SampleType) field, …` (log order: the MCAP
/// channel ids follow it).
macro_rules! channels {
    ($($variant:ident($ty:ty) $field:ident),* $(,)?) => {
        /// A logged channel (scene `[[outputs.channels]] name`, MCAP topic
        /// `/name`, CSV file `<scene>_name.csv`).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum Channel {
            $(
                #[doc = concat!("`", stringify!($field), "` samples.")]
                $variant,
            )*
        }

        impl Channel {
            /// Every channel, in log order.
            pub const ALL: &'static [Channel] = &[$(Channel::$variant),*];

            /// The channel's name.
            #[must_use]
            pub fn name(self) -> &'static str {
                match self {
                    $(Channel::$variant => <$ty as Record>::CHANNEL,)*
                }
            }

            /// The channel's fields, in column order.
            #[must_use]
            pub fn fields(self) -> &'static [Field] {
                match self {
                    $(Channel::$variant => <$ty as Record>::FIELDS,)*
                }
            }
        }

        /// One recorded sample of any channel, as the run loop hands it to a
        /// streaming sink (the MCAP writer thread).
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub enum Sample {
            $(
                #[doc = concat!("A `", stringify!($field), "` sample.")]
                $variant($ty),
            )*
        }

        impl Sample {
            /// The sample's channel.
            #[must_use]
            pub fn channel(&self) -> Channel {
                match self {
                    $(Sample::$variant(_) => Channel::$variant,)*
                }
            }

            /// Simulation time \[s\].
            #[must_use]
            pub fn time(&self) -> f64 {
                match self {
                    $(Sample::$variant(s) => s.time(),)*
                }
            }

            /// Appends the sample as one JSON object.
            pub fn write_json(&self, out: &mut Vec<u8>) {
                match self {
                    $(Sample::$variant(s) => s.write_json(out),)*
                }
            }
        }

        /// The channels that were asked for (None = not recorded at all).
        #[derive(Clone, Debug, Default)]
        pub struct Channels {
            $(
                #[doc = concat!("`", stringify!($field), "` samples.")]
                pub $field: Option<Vec<$ty>>,
            )*
            /// Plant samples for the plots (only when plots are asked for;
            /// about 4000 over the run, whatever `plant`'s decimation).
            pub plot: Option<Vec<PlantSample>>,
        }

        impl Channels {
            /// Empty buffers for the channels `wanted` and, if `plots`, for
            /// the plot samples.
            #[must_use]
            pub fn recording(wanted: impl Fn(Channel) -> bool, plots: bool) -> Self {
                Self {
                    $($field: wanted(Channel::$variant).then(Vec::new),)*
                    plot: plots.then(Vec::new),
                }
            }

            /// Whether `channel` was recorded.
            #[must_use]
            pub fn recorded(&self, channel: Channel) -> bool {
                match channel {
                    $(Channel::$variant => self.$field.is_some(),)*
                }
            }

            /// The recorded samples of `channel` (None: not recorded).
            #[must_use]
            pub fn samples(&self, channel: Channel) -> Option<Vec<Sample>> {
                match channel {
                    $(Channel::$variant => self
                        .$field
                        .as_ref()
                        .map(|v| v.iter().map(|&s| Sample::$variant(s)).collect()),)*
                }
            }

            /// The samples of `channel` as JSON objects, through serde (the
            /// Python bindings' columns; None: not recorded).
            ///
            /// # Errors
            /// A sample serde_json cannot represent.
            pub fn json_rows(
                &self,
                channel: Channel,
            ) -> Option<Result<Vec<serde_json::Value>, serde_json::Error>> {
                match channel {
                    $(Channel::$variant => self
                        .$field
                        .as_ref()
                        .map(|v| v.iter().map(serde_json::to_value).collect()),)*
                }
            }

            /// The CSV text of `channel`: the header of its field names, one
            /// row per sample (None: not recorded).
            #[must_use]
            pub fn csv(&self, channel: Channel) -> Option<Vec<u8>> {
                match channel {
                    $(Channel::$variant => self.$field.as_deref().map(csv_text),)*
                }
            }
        }
    };
}

channels!(
    Plant(PlantSample) plant,
    Control(ControlSample) control,
    Stepper(StepperSample) stepper,
    Sensors(SensorSample) sensors,
);

impl Channel {
    /// The channel called `name` (None for an unknown name).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.iter().copied().find(|c| c.name() == name)
    }

    /// Every channel's name, in log order.
    #[must_use]
    pub fn names() -> Vec<&'static str> {
        Self::ALL.iter().map(|c| c.name()).collect()
    }
}

/// A scene names a channel by its name.
impl<'de> Deserialize<'de> for Channel {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Self::from_name(&name).ok_or_else(|| {
            serde::de::Error::custom(format!("\"{name}\" is not one of {:?}", Self::names()))
        })
    }
}

/// CSV text of samples: the header, then one row per sample.
fn csv_text<T: Record>(samples: &[T]) -> Vec<u8> {
    let header: Vec<&str> = T::FIELDS.iter().map(|f| f.name).collect();
    let mut text = header.join(",").into_bytes();
    text.push(b'\n');
    for s in samples {
        s.write_csv(&mut text);
    }
    text
}

/// A plot panel: one field of the `plant` channel against t, in the unit
/// people read (rpm, mm).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Panel {
    /// ω \[rpm\].
    Omega,
    /// ω_a \[rpm\].
    OmegaA,
    /// r \[mm\].
    R,
    /// V_m \[V\].
    VM,
    /// T_U \[N·m\].
    TU,
}

/// rad/s → rpm.
const RPM_PER_RAD_S: f64 = 60.0 / std::f64::consts::TAU;

impl Panel {
    /// Every panel a scene may ask for.
    pub const ALL: [Panel; 5] = [Panel::Omega, Panel::OmegaA, Panel::R, Panel::VM, Panel::TU];

    /// The panel's name: the `plant` field it shows.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Panel::Omega => "omega",
            Panel::OmegaA => "omega_a",
            Panel::R => "r",
            Panel::VM => "v_m",
            Panel::TU => "t_u",
        }
    }

    /// The field's value in a plant sample (SI unit of [`Channel::fields`]).
    #[must_use]
    pub fn of(self, s: &PlantSample) -> f64 {
        match self {
            Panel::Omega => s.omega,
            Panel::OmegaA => s.omega_a,
            Panel::R => s.r,
            Panel::VM => s.v_m,
            Panel::TU => s.t_u,
        }
    }

    /// Title of the panel and the factor from the field's SI unit to it.
    #[must_use]
    pub fn label(self) -> (&'static str, f64) {
        match self {
            Panel::Omega => ("ω [rpm]", RPM_PER_RAD_S),
            Panel::OmegaA => ("ω_a [rpm]", RPM_PER_RAD_S),
            Panel::R => ("r [mm]", 1e3),
            Panel::VM => ("V_m [V]", 1.0),
            Panel::TU => ("T_U [N·m]", 1.0),
        }
    }

    /// A speed panel (drawn with the target ω0).
    #[must_use]
    pub fn is_speed(self) -> bool {
        matches!(self, Panel::Omega | Panel::OmegaA)
    }

    /// The panel called `name` (None for an unknown name).
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// A scene names a panel by its name.
impl<'de> Deserialize<'de> for Panel {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = String::deserialize(d)?;
        Self::from_name(&name).ok_or_else(|| {
            let names: Vec<&str> = Self::ALL.iter().map(|p| p.name()).collect();
            serde::de::Error::custom(format!("entry \"{name}\" is not one of {names:?}"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ivt_ctrl::Fault;
    use serde::Serialize;

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
        let mut names: Vec<&str> = T::FIELDS.iter().map(|f| f.name).collect();
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
