//! Typed messages carried in frames. All integers and floats little-endian;
//! floats travel as their IEEE-754 bits, so a round trip is bit-exact.
//!
//! | kind | direction | name      | payload                                                         |
//! |------|-----------|-----------|-----------------------------------------------------------------|
//! | 0x01 | host → fw | `Hello`   | —                                                               |
//! | 0x02 | host → fw | `Pulse`   | `ticks: u32`                                                    |
//! | 0x03 | host → fw | `Inputs`  | `v_m: f32, t_u: f32`                                            |
//! | 0x04 | host → fw | `Exit`    | —                                                               |
//! | 0x05 | host → fw | `Configure` | `ivt_ctrl::Config` in declaration order, [`CONFIG_LEN`] bytes (see [`Request::Configure`]) |
//! | 0x81 | fw → host | `Hello`   | `version: u16, ppr: u32`                                        |
//! | 0x82 | fw → host | `Output`  | `omega, omega_a, omega_t, r_ol, r_d, r: f32, stepper_target: i32, flags: u8 (bit0 saturated, bit1 ready, bit2 inputs_clamped), fault: u8, ol_region: u8` |
//! | 0x83 | fw → host | `Ack`     | —                                                               |
//! | 0x8F | fw → host | `Error`   | `code: u8` (see [`ErrorCode`])                                  |
//! | 0x90 | fw → host | telemetry | `time_ticks: u32, omega, omega_a, r: f32, stepper_position: i32, fault: u8` |

use crate::frame::{encode, WireError};
use ivt_ctrl::{
    ActuatorMap, Config, ControlOutput, Fault, Gains, LawKind, OlRegion, OpenLoopCoeffs,
    StepperLimits,
};

/// Protocol version reported by `Hello`; bump on any incompatible change.
pub const VERSION: u16 = 1;

const K_HELLO: u8 = 0x01;
const K_PULSE: u8 = 0x02;
const K_INPUTS: u8 = 0x03;
const K_EXIT: u8 = 0x04;
const K_CONFIGURE: u8 = 0x05;
const K_R_HELLO: u8 = 0x81;
const K_R_OUTPUT: u8 = 0x82;
const K_R_ACK: u8 = 0x83;
const K_R_ERROR: u8 = 0x8F;
/// Frame kind of a [`Telemetry`] frame.
pub const K_TELEMETRY: u8 = 0x90;

/// Host → firmware.
// `Configure` is ~200 bytes; boxing it is not an option without a heap, and a
// request lives only between decoding and handling.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Request {
    /// Asks for the protocol version and the controller's PPR.
    Hello,
    /// One encoder pulse with its timer timestamp.
    Pulse {
        /// Timer ticks of the pulse edge.
        ticks: u32,
    },
    /// Slow readings: motor voltage [V] and load torque [N·m].
    Inputs {
        /// Motor voltage V_m [V].
        v_m: f32,
        /// Load torque T_U [N·m].
        t_u: f32,
    },
    /// Ends the session (the QEMU image exits with status 0).
    Exit,
    /// Replaces the controller by `Controller::new(config)` (a fresh state).
    /// Every field travels, in declaration order; enums as `u8`, bools as 0/1.
    Configure(Config),
}

/// Why the firmware rejected a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum ErrorCode {
    /// The request frame failed its CRC.
    BadCrc = 1,
    /// Unknown request kind.
    UnknownKind = 2,
    /// Known kind, wrong payload length.
    BadLength = 3,
    /// A field that is not a valid enum value.
    BadValue = 4,
}

impl From<WireError> for ErrorCode {
    fn from(e: WireError) -> Self {
        match e {
            WireError::BadCrc => ErrorCode::BadCrc,
            WireError::UnknownKind(_) => ErrorCode::UnknownKind,
            WireError::BadValue => ErrorCode::BadValue,
            _ => ErrorCode::BadLength,
        }
    }
}

/// Firmware → host.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Reply {
    /// Protocol version and the PPR the firmware was built with.
    Hello {
        /// [`VERSION`] of the firmware.
        version: u16,
        /// Pulses per revolution of θ (the controller's const generic).
        ppr: u32,
    },
    /// Answer to a pulse: the whole `ControlOutput`, bit-exact.
    Output(ControlOutput),
    /// `Inputs`, `Configure` or `Exit` accepted.
    Ack,
    /// A request was rejected (the raw error code, see [`ErrorCode`]).
    Error(u8),
}

/// One telemetry sample streamed by the firmware.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Telemetry {
    /// Timer ticks of the pulse that produced the sample.
    pub time_ticks: u32,
    /// ω [rad/s].
    pub omega: f32,
    /// ω_a [rad/s].
    pub omega_a: f32,
    /// Commanded eccentricity r [m].
    pub r: f32,
    /// Stepper position [steps].
    pub stepper_position: i32,
    /// Fault code.
    pub fault: u8,
}

/// Little-endian field writer over a fixed buffer.
struct Put<const N: usize> {
    buf: [u8; N],
    at: usize,
}

impl<const N: usize> Put<N> {
    fn new() -> Self {
        Self { buf: [0; N], at: 0 }
    }
    fn bytes(&mut self, b: &[u8]) {
        if let Some(dst) = self.buf.get_mut(self.at..self.at + b.len()) {
            dst.copy_from_slice(b);
        }
        self.at += b.len();
    }
    fn f32(&mut self, v: f32) {
        self.bytes(&v.to_bits().to_le_bytes());
    }
    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    fn f32s(&mut self, v: &[f32]) {
        for &x in v {
            self.f32(x);
        }
    }
    fn done(&self) -> &[u8] {
        &self.buf[..self.at.min(N)]
    }
}

/// Little-endian field reader; the caller checks the total length first.
struct Get<'a> {
    p: &'a [u8],
}

impl Get<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let (Some(head), Some(rest)) = (self.p.get(..N), self.p.get(N..)) {
            out.copy_from_slice(head);
            self.p = rest;
        }
        out
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take())
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take())
    }
    fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    fn u8(&mut self) -> u8 {
        self.take::<1>()[0]
    }
    fn f32s<const N: usize>(&mut self) -> [f32; N] {
        core::array::from_fn(|_| self.f32())
    }
}

fn law_code(law: LawKind) -> u8 {
    match law {
        LawKind::Delay => 0,
        LawKind::NoDelay => 1,
        LawKind::Prop => 2,
        LawKind::Open => 3,
    }
}

fn law_from(code: u8) -> Result<LawKind, WireError> {
    Ok(match code {
        0 => LawKind::Delay,
        1 => LawKind::NoDelay,
        2 => LawKind::Prop,
        3 => LawKind::Open,
        _ => return Err(WireError::BadValue),
    })
}

/// Payload length of `Configure` (see `put_config`): 27 four-byte scalars,
/// the u16 decimation, two u8 (law, feedforward) and the open-loop polynomial.
pub const CONFIG_LEN: usize =
    4 * 27 + 2 + 2 + 4 * ivt_ctrl::open_loop::POLY_V_TERMS * ivt_ctrl::open_loop::POLY_T_TERMS;

fn put_config(p: &mut Put<CONFIG_LEN>, c: &Config) {
    // Exhaustive destructuring: a field added to Config fails to compile here
    // until the wire format carries it.
    let Config {
        f_timer_hz,
        omega0,
        decimation,
        law,
        gains:
            Gains {
                k,
                k2,
                k_prop,
                prop_period_s,
            },
        open_loop:
            OpenLoopCoeffs {
                poly,
                boundary,
                r_max,
                v_m_range,
                t_u_range,
            },
        feedforward,
        actuator: ActuatorMap {
            steps_per_metre,
            offset_steps,
        },
        stepper: StepperLimits { max_speed, accel },
        stall_timeout_s,
        omega_max,
        safe_r,
        v_m_valid,
        t_u_valid,
        initial_inputs,
    } = *c;
    p.f32s(&[f_timer_hz, omega0]);
    p.bytes(&decimation.to_le_bytes());
    p.bytes(&[law_code(law)]);
    p.f32s(&[k, k2, k_prop, prop_period_s]);
    for row in &poly {
        p.f32s(row);
    }
    p.f32s(&boundary);
    p.f32(r_max);
    p.f32s(&v_m_range);
    p.f32s(&t_u_range);
    p.bytes(&[feedforward as u8]);
    p.f32(steps_per_metre);
    p.bytes(&offset_steps.to_le_bytes());
    p.f32s(&[max_speed, accel, stall_timeout_s, omega_max, safe_r]);
    p.f32s(&v_m_valid);
    p.f32s(&t_u_valid);
    p.f32s(&initial_inputs);
}

fn get_config(g: &mut Get<'_>) -> Result<Config, WireError> {
    let f_timer_hz = g.f32();
    let omega0 = g.f32();
    let decimation = u16::from_le_bytes(g.take());
    let law = law_from(g.u8())?;
    let gains = Gains {
        k: g.f32(),
        k2: g.f32(),
        k_prop: g.f32(),
        prop_period_s: g.f32(),
    };
    let poly = core::array::from_fn(|_| g.f32s());
    let open_loop = OpenLoopCoeffs {
        poly,
        boundary: g.f32s(),
        r_max: g.f32(),
        v_m_range: g.f32s(),
        t_u_range: g.f32s(),
    };
    let feedforward = match g.u8() {
        0 => false,
        1 => true,
        _ => return Err(WireError::BadValue),
    };
    let actuator = ActuatorMap {
        steps_per_metre: g.f32(),
        offset_steps: g.i32(),
    };
    Ok(Config {
        f_timer_hz,
        omega0,
        decimation,
        law,
        gains,
        open_loop,
        feedforward,
        actuator,
        stepper: StepperLimits {
            max_speed: g.f32(),
            accel: g.f32(),
        },
        stall_timeout_s: g.f32(),
        omega_max: g.f32(),
        safe_r: g.f32(),
        v_m_valid: g.f32s(),
        t_u_valid: g.f32s(),
        initial_inputs: g.f32s(),
    })
}

fn expect_len(kind: u8, payload: &[u8], len: usize) -> Result<Get<'_>, WireError> {
    if payload.len() == len {
        Ok(Get { p: payload })
    } else {
        Err(WireError::BadLength {
            kind,
            len: payload.len() as u8,
        })
    }
}

const OUTPUT_LEN: usize = 6 * 4 + 4 + 3;
const TELEMETRY_LEN: usize = 4 * 4 + 4 + 1;

impl Request {
    /// Encodes the request as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<CONFIG_LEN>::new();
        let kind = match *self {
            Request::Hello => K_HELLO,
            Request::Pulse { ticks } => {
                p.u32(ticks);
                K_PULSE
            }
            Request::Inputs { v_m, t_u } => {
                p.f32(v_m);
                p.f32(t_u);
                K_INPUTS
            }
            Request::Exit => K_EXIT,
            Request::Configure(ref c) => {
                put_config(&mut p, c);
                K_CONFIGURE
            }
        };
        encode(kind, p.done(), out)
    }

    /// Decodes a request from a frame's kind and payload.
    ///
    /// # Errors
    /// [`WireError::UnknownKind`] or [`WireError::BadLength`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        Ok(match kind {
            K_HELLO => {
                expect_len(kind, payload, 0)?;
                Request::Hello
            }
            K_PULSE => Request::Pulse {
                ticks: expect_len(kind, payload, 4)?.u32(),
            },
            K_INPUTS => {
                let mut g = expect_len(kind, payload, 8)?;
                Request::Inputs {
                    v_m: g.f32(),
                    t_u: g.f32(),
                }
            }
            K_EXIT => {
                expect_len(kind, payload, 0)?;
                Request::Exit
            }
            K_CONFIGURE => {
                Request::Configure(get_config(&mut expect_len(kind, payload, CONFIG_LEN)?)?)
            }
            other => return Err(WireError::UnknownKind(other)),
        })
    }
}

impl Reply {
    /// Encodes the reply as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<OUTPUT_LEN>::new();
        let kind = match *self {
            Reply::Hello { version, ppr } => {
                p.bytes(&version.to_le_bytes());
                p.u32(ppr);
                K_R_HELLO
            }
            Reply::Output(o) => {
                // Every field is written: `decode` builds the struct with all
                // of them named, so a new field fails to compile there.
                p.f32s(&[o.omega, o.omega_a, o.omega_t, o.r_ol, o.r_d, o.r]);
                p.bytes(&o.stepper_target.to_le_bytes());
                let flags =
                    o.saturated as u8 | (o.ready as u8) << 1 | (o.inputs_clamped as u8) << 2;
                p.bytes(&[flags, o.fault.code(), o.ol_region.code()]);
                K_R_OUTPUT
            }
            Reply::Ack => K_R_ACK,
            Reply::Error(code) => {
                p.bytes(&[code]);
                K_R_ERROR
            }
        };
        encode(kind, p.done(), out)
    }

    /// Decodes a reply from a frame's kind and payload.
    ///
    /// # Errors
    /// [`WireError::UnknownKind`] or [`WireError::BadLength`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        Ok(match kind {
            K_R_HELLO => {
                let mut g = expect_len(kind, payload, 6)?;
                Reply::Hello {
                    version: u16::from_le_bytes(g.take()),
                    ppr: g.u32(),
                }
            }
            K_R_OUTPUT => {
                let mut g = expect_len(kind, payload, OUTPUT_LEN)?;
                let [omega, omega_a, omega_t, r_ol, r_d, r] = g.f32s();
                let stepper_target = g.i32();
                let flags = g.u8();
                Reply::Output(ControlOutput {
                    omega,
                    omega_a,
                    omega_t,
                    r_ol,
                    r_d,
                    r,
                    stepper_target,
                    saturated: flags & 1 != 0,
                    ready: flags & 2 != 0,
                    inputs_clamped: flags & 4 != 0,
                    fault: Fault::from_code(g.u8()).ok_or(WireError::BadValue)?,
                    ol_region: OlRegion::from_code(g.u8()).ok_or(WireError::BadValue)?,
                })
            }
            K_R_ACK => {
                expect_len(kind, payload, 0)?;
                Reply::Ack
            }
            K_R_ERROR => Reply::Error(expect_len(kind, payload, 1)?.u8()),
            other => return Err(WireError::UnknownKind(other)),
        })
    }
}

impl Telemetry {
    /// Encodes the sample as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<TELEMETRY_LEN>::new();
        p.u32(self.time_ticks);
        p.f32(self.omega);
        p.f32(self.omega_a);
        p.f32(self.r);
        p.bytes(&self.stepper_position.to_le_bytes());
        p.bytes(&[self.fault]);
        encode(K_TELEMETRY, p.done(), out)
    }

    /// Decodes a telemetry payload (frame kind [`K_TELEMETRY`]).
    ///
    /// # Errors
    /// [`WireError::UnknownKind`] or [`WireError::BadLength`].
    pub fn decode(kind: u8, payload: &[u8]) -> Result<Self, WireError> {
        if kind != K_TELEMETRY {
            return Err(WireError::UnknownKind(kind));
        }
        let mut g = expect_len(kind, payload, TELEMETRY_LEN)?;
        Ok(Telemetry {
            time_ticks: g.u32(),
            omega: g.f32(),
            omega_a: g.f32(),
            r: g.f32(),
            stepper_position: g.i32(),
            fault: g.u8(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Decoder, MAX_FRAME};

    fn one_frame(bytes: &[u8]) -> (u8, [u8; MAX_FRAME], usize) {
        let mut dec = Decoder::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                let f = r.unwrap();
                let mut p = [0u8; MAX_FRAME];
                p[..f.payload.len()].copy_from_slice(f.payload);
                return (f.kind, p, f.payload.len());
            }
        }
        panic!("no frame");
    }

    #[test]
    fn requests_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        for req in [
            Request::Hello,
            Request::Pulse { ticks: 0xFFFF_FFF0 },
            // A NaN with payload bits must survive unchanged (bits, not value).
            Request::Inputs {
                v_m: f32::from_bits(0x7FC0_1234),
                t_u: -0.0,
            },
            Request::Exit,
        ] {
            let n = req.encode(&mut buf).unwrap();
            let (k, p, len) = one_frame(&buf[..n]);
            let back = Request::decode(k, &p[..len]).unwrap();
            match (req, back) {
                (Request::Inputs { v_m, t_u }, Request::Inputs { v_m: v2, t_u: t2 }) => {
                    assert_eq!(v_m.to_bits(), v2.to_bits());
                    assert_eq!(t_u.to_bits(), t2.to_bits());
                }
                _ => assert_eq!(req, back),
            }
        }
    }

    #[test]
    fn replies_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        let out = ControlOutput {
            omega: 10.471_975,
            omega_a: 10.5,
            omega_t: f32::INFINITY,
            r_ol: 0.0067,
            r_d: -1e-6,
            r: 0.012,
            stepper_target: -123_456,
            saturated: true,
            fault: Fault::InputInvalid,
            ready: false,
            inputs_clamped: true,
            ol_region: OlRegion::UnderDrive,
        };
        for rep in [
            Reply::Hello {
                version: VERSION,
                ppr: 1200,
            },
            Reply::Output(out),
            Reply::Ack,
            Reply::Error(ErrorCode::BadLength as u8),
        ] {
            let n = rep.encode(&mut buf).unwrap();
            let (k, p, len) = one_frame(&buf[..n]);
            assert_eq!(Reply::decode(k, &p[..len]).unwrap(), rep);
        }
        assert_eq!(Reply::Output(out).encode(&mut buf).unwrap(), 31 + 5);
    }

    #[test]
    fn config_round_trip_is_exact() {
        // Every field distinct so a swapped pair shows up.
        let mut c = Config::default();
        let mut x = 1.0f32;
        let mut next = || {
            x += 0.125;
            x
        };
        c.f_timer_hz = next();
        c.omega0 = next();
        c.decimation = 7;
        c.law = LawKind::Prop;
        c.gains = Gains {
            k: next(),
            k2: next(),
            k_prop: next(),
            prop_period_s: next(),
        };
        for row in c.open_loop.poly.iter_mut() {
            for v in row.iter_mut() {
                *v = next();
            }
        }
        c.open_loop.boundary = [next(), next(), next()];
        c.open_loop.r_max = next();
        c.open_loop.v_m_range = [next(), next()];
        c.open_loop.t_u_range = [next(), next()];
        c.feedforward = false;
        c.actuator = ActuatorMap {
            steps_per_metre: next(),
            offset_steps: -9,
        };
        c.stepper = StepperLimits {
            max_speed: next(),
            accel: next(),
        };
        c.stall_timeout_s = next();
        c.omega_max = next();
        c.safe_r = next();
        c.v_m_valid = [next(), next()];
        c.t_u_valid = [next(), next()];
        c.initial_inputs = [next(), next()];
        let mut buf = [0u8; MAX_FRAME];
        let n = Request::Configure(c).encode(&mut buf).unwrap();
        assert_eq!(n, CONFIG_LEN + 5);
        let (k, p, len) = one_frame(&buf[..n]);
        assert_eq!(
            Request::decode(k, &p[..len]).unwrap(),
            Request::Configure(c)
        );
    }

    #[test]
    fn telemetry_round_trip() {
        let mut buf = [0u8; MAX_FRAME];
        let t = Telemetry {
            time_ticks: 7,
            omega: 1.0,
            omega_a: 2.0,
            r: 0.003,
            stepper_position: 42,
            fault: 0,
        };
        let n = t.encode(&mut buf).unwrap();
        assert_eq!(n, 21 + 5);
        let (k, p, len) = one_frame(&buf[..n]);
        assert_eq!(Telemetry::decode(k, &p[..len]).unwrap(), t);
    }

    #[test]
    fn wrong_lengths_and_kinds_are_errors() {
        assert_eq!(
            Request::decode(K_PULSE, &[1, 2, 3]),
            Err(WireError::BadLength {
                kind: K_PULSE,
                len: 3
            })
        );
        assert_eq!(
            Request::decode(0x55, &[]),
            Err(WireError::UnknownKind(0x55))
        );
        assert!(Reply::decode(K_R_OUTPUT, &[0; 30]).is_err());
        // A fault code the controller does not define.
        let mut bad = [0u8; OUTPUT_LEN];
        bad[OUTPUT_LEN - 2] = 99;
        assert_eq!(Reply::decode(K_R_OUTPUT, &bad), Err(WireError::BadValue));
        assert!(Telemetry::decode(K_R_ACK, &[0; 21]).is_err());
    }
}
