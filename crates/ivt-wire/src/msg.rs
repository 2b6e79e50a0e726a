//! Typed messages carried in frames. All integers and floats little-endian;
//! floats travel as their IEEE-754 bits, so a round trip is bit-exact.
//!
//! | kind | direction | name      | payload                                                         |
//! |------|-----------|-----------|-----------------------------------------------------------------|
//! | 0x01 | host → fw | `Hello`   | —                                                               |
//! | 0x02 | host → fw | `Pulse`   | `ticks: u32`                                                    |
//! | 0x03 | host → fw | `Inputs`  | `v_m: f32, t_u: f32`                                            |
//! | 0x04 | host → fw | `Exit`    | —                                                               |
//! | 0x81 | fw → host | `Hello`   | `version: u16, ppr: u32`                                        |
//! | 0x82 | fw → host | `Output`  | `omega, omega_a, omega_t, r_ol, r_d, r: f32, stepper_target: i32, saturated: u8, fault: u8` |
//! | 0x83 | fw → host | `Ack`     | —                                                               |
//! | 0x8F | fw → host | `Error`   | `code: u8` (see [`ErrorCode`])                                  |
//! | 0x90 | fw → host | telemetry | `time_ticks: u32, omega, omega_a, r: f32, stepper_position: i32, fault: u8` |

use crate::frame::{encode, WireError};

/// Protocol version reported by `Hello`; bump on any incompatible change.
pub const VERSION: u16 = 1;

const K_HELLO: u8 = 0x01;
const K_PULSE: u8 = 0x02;
const K_INPUTS: u8 = 0x03;
const K_EXIT: u8 = 0x04;
const K_R_HELLO: u8 = 0x81;
const K_R_OUTPUT: u8 = 0x82;
const K_R_ACK: u8 = 0x83;
const K_R_ERROR: u8 = 0x8F;
/// Frame kind of a [`Telemetry`] frame.
pub const K_TELEMETRY: u8 = 0x90;

/// Host → firmware.
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
}

/// The controller's answer to one pulse (the fields of `ivt_ctrl::ControlOutput`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Output {
    /// ω [rad/s] over the last pulse interval.
    pub omega: f32,
    /// ω_a [rad/s], mean over the last revolution.
    pub omega_a: f32,
    /// ω_T [rad/s], ω one revolution earlier.
    pub omega_t: f32,
    /// Open-loop eccentricity u_ol [m].
    pub r_ol: f32,
    /// Feedback part r_d [m].
    pub r_d: f32,
    /// Commanded eccentricity r [m] after saturation.
    pub r: f32,
    /// Stepper target [steps].
    pub stepper_target: i32,
    /// Whether r was saturated.
    pub saturated: bool,
    /// Fault code (`ivt_ctrl::Fault as u8`).
    pub fault: u8,
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
    /// Answer to a pulse.
    Output(Output),
    /// `Inputs` or `Exit` accepted.
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

const OUTPUT_LEN: usize = 6 * 4 + 4 + 2;
const TELEMETRY_LEN: usize = 4 * 4 + 4 + 1;

impl Request {
    /// Encodes the request as a frame into `out`; returns the frame length.
    ///
    /// # Errors
    /// [`WireError::BufferTooSmall`].
    pub fn encode(&self, out: &mut [u8]) -> Result<usize, WireError> {
        let mut p = Put::<8>::new();
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
                for v in [o.omega, o.omega_a, o.omega_t, o.r_ol, o.r_d, o.r] {
                    p.f32(v);
                }
                p.bytes(&o.stepper_target.to_le_bytes());
                p.bytes(&[o.saturated as u8, o.fault]);
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
                Reply::Output(Output {
                    omega: g.f32(),
                    omega_a: g.f32(),
                    omega_t: g.f32(),
                    r_ol: g.f32(),
                    r_d: g.f32(),
                    r: g.f32(),
                    stepper_target: g.i32(),
                    saturated: g.u8() != 0,
                    fault: g.u8(),
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

    fn one_frame(bytes: &[u8]) -> (u8, [u8; 64], usize) {
        let mut dec = Decoder::new();
        for &b in bytes {
            if let Some(r) = dec.push(b) {
                let f = r.unwrap();
                let mut p = [0u8; 64];
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
        let out = Output {
            omega: 10.471_975,
            omega_a: 10.5,
            omega_t: f32::INFINITY,
            r_ol: 0.0067,
            r_d: -1e-6,
            r: 0.012,
            stepper_target: -123_456,
            saturated: true,
            fault: 3,
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
        assert_eq!(Reply::Output(out).encode(&mut buf).unwrap(), 30 + 5);
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
        assert!(Reply::decode(K_R_OUTPUT, &[0; 29]).is_err());
        assert!(Telemetry::decode(K_R_ACK, &[0; 21]).is_err());
    }
}
