//! Board-independent part of the firmware: the controller instance, the pulse
//! path, and the PIL request handler. Its control path is `ivt-ctrl` only.

use core::sync::atomic::{AtomicBool, Ordering};

use ivt_ctrl::{Config, ControlOutput, Controller};
use ivt_wire::{frame::Decoder, msg, ErrorCode, Reply, Request, MAX_FRAME};

/// Samples per revolution of θ the firmware is built for (the encoder of the
/// rig has `PPR · config.decimation` edges per revolution).
pub const PPR: usize = 1200;
const _: () = assert!(
    ivt_ctrl::is_supported_ppr(PPR),
    "the firmware's PPR must be one of ivt_ctrl::SUPPORTED_PPR"
);

/// The controller type of this firmware.
pub type Ctrl = Controller<PPR>;

/// The pulse path: one encoder edge → one controller update.
///
/// Kept out of line under a fixed symbol so that (1) the instruction count per
/// pulse can be measured under QEMU from its entry to its return and (2) the
/// host-side test can prove from the ELF's call graph that nothing reachable
/// from here calls the panic handler.
#[no_mangle]
#[inline(never)]
pub fn ivt_fw_pulse(ctrl: &mut Ctrl, ticks: u32) -> ControlOutput {
    ctrl.on_pulse(ticks)
}

/// Takes the firmware's one controller: a static initialised to
/// `Controller::unconfigured()` at link time and configured in place with
/// `reset` — `Controller::new` would build the 4.8 KiB ring on the stack and
/// move it, a 10.7 KiB boot stack peak against an 8 KiB RAM budget. Returns
/// `None` on a second call.
#[inline(never)]
pub fn take_controller(config: Config) -> Option<&'static mut Ctrl> {
    static TAKEN: AtomicBool = AtomicBool::new(false);
    static mut CTRL: Ctrl = Ctrl::unconfigured();
    if TAKEN.swap(true, Ordering::AcqRel) {
        return None;
    }
    // SAFETY: TAKEN guarantees this runs once, so the &'static mut is unique.
    let ctrl = unsafe { &mut *core::ptr::addr_of_mut!(CTRL) };
    ctrl.reset(config);
    Some(ctrl)
}

/// Where bytes go (a UART transmitter).
pub trait ByteSink {
    /// Sends all bytes (blocking).
    fn write_all(&mut self, bytes: &[u8]);
}

/// A two-way byte pipe to the host.
pub trait Link: ByteSink {
    /// Blocks until a byte arrives.
    fn read_byte(&mut self) -> u8;
}

/// What the session loop should do after a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Session {
    /// Keep serving.
    Continue,
    /// The host asked to end the session.
    Exit,
}

/// Processor-in-the-loop server: decodes requests, runs the controller,
/// answers with one frame per request (protocol in `ivt_wire::msg`).
pub struct PilServer {
    dec: Decoder,
    tx: [u8; MAX_FRAME],
    /// Pulses served since the start (for telemetry and the exit report).
    pub pulses: u32,
}

impl Default for PilServer {
    fn default() -> Self {
        Self::new()
    }
}

impl PilServer {
    /// A server waiting for the first frame.
    pub const fn new() -> Self {
        Self {
            dec: Decoder::new(),
            tx: [0; MAX_FRAME],
            pulses: 0,
        }
    }

    /// Feeds one received byte; when it completes a request, runs it and
    /// sends the reply. `on_output` sees every pulse answer (for telemetry).
    pub fn feed(
        &mut self,
        byte: u8,
        ctrl: &mut Ctrl,
        link: &mut impl Link,
        mut on_output: impl FnMut(u32, &ControlOutput),
    ) -> Session {
        let Some(frame) = self.dec.push(byte) else {
            return Session::Continue;
        };
        let mut session = Session::Continue;
        let reply = match frame.and_then(|f| Request::decode(f.kind, f.payload)) {
            Ok(Request::Hello) => Reply::Hello {
                version: msg::VERSION,
                ppr: PPR as u32,
            },
            Ok(Request::Pulse { ticks }) => {
                let out = ivt_fw_pulse(ctrl, ticks);
                self.pulses = self.pulses.wrapping_add(1);
                on_output(ticks, &out);
                Reply::Output(out)
            }
            Ok(Request::Inputs { v_m, t_u }) => {
                ctrl.update_inputs(v_m, t_u);
                Reply::Ack
            }
            Ok(Request::Configure(config)) => {
                // In place (no stack temporary); an invalid config gives the
                // controller's own Fault::Config state.
                ctrl.reset(config);
                self.pulses = 0;
                Reply::Ack
            }
            Ok(Request::Exit) => {
                session = Session::Exit;
                Reply::Ack
            }
            Err(e) => Reply::Error(ErrorCode::from(e) as u8),
        };
        if let Ok(n) = reply.encode(&mut self.tx) {
            link.write_all(self.tx.get(..n).unwrap_or(&[]));
        }
        session
    }
}

/// Streams telemetry frames (`ivt_wire::Telemetry`) over a link.
pub struct TelemetryTx<L: ByteSink> {
    link: L,
    buf: [u8; 32],
    /// Frames sent so far.
    pub frames: u32,
}

impl<L: ByteSink> TelemetryTx<L> {
    /// A sender over `link`.
    pub fn new(link: L) -> Self {
        Self {
            link,
            buf: [0; 32],
            frames: 0,
        }
    }

    /// Sends one sample: the pulse's timestamp, ω, ω_a, r, the stepper
    /// position and the fault code.
    pub fn send(&mut self, time_ticks: u32, out: &ControlOutput, stepper_position: i32) {
        let t = ivt_wire::Telemetry {
            time_ticks,
            omega: out.omega,
            omega_a: out.omega_a,
            r: out.r,
            stepper_position,
            fault: out.fault.code(),
        };
        if let Ok(n) = t.encode(&mut self.buf) {
            self.link.write_all(self.buf.get(..n).unwrap_or(&[]));
            self.frames = self.frames.wrapping_add(1);
        }
    }
}
