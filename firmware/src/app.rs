//! Board-independent part of the firmware: the controller instance, the pulse
//! path, and the PIL request handler. Its control path is `ivt-ctrl` only.

use core::sync::atomic::{AtomicBool, Ordering};

use ivt_ctrl::commission::{SequenceStep, Sequencer, Stage};
use ivt_ctrl::{Config, ControlOutput, Controller};
use ivt_wire::telemetry::{PulseBatch, StageStart, TelemetryFrame, TelemetrySample};
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

/// The pulse path while a commissioning sequence runs
/// (`ivt_ctrl::commission`): the stage logic, then [`Controller::on_pulse`].
/// Out of line under a fixed symbol for the panic-reachability proof.
#[no_mangle]
#[inline(never)]
pub fn ivt_fw_sequenced_pulse(seq: &mut Sequencer, ctrl: &mut Ctrl, ticks: u32) -> SequenceStep {
    seq.on_pulse(ctrl, ticks)
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
    /// The running commissioning sequence (after `Commission`, until `Configure`).
    seq: Option<Sequencer>,
    /// Timer rate of the last configuration (the sequencer's clock).
    f_timer_hz: f32,
    /// The last inputs received.
    inputs: [f32; 2],
}

/// What one served pulse produced, for telemetry.
#[derive(Clone, Copy, Debug)]
pub struct PulseEvent {
    /// The pulse's timestamp.
    pub ticks: u32,
    /// The controller's output.
    pub out: ControlOutput,
    /// The inputs the controller holds (V_m, T_U).
    pub inputs: [f32; 2],
    /// The commissioning stage that started at this pulse.
    pub started: Option<Stage>,
    /// The pulse falls in a pulse-log stage.
    pub pulse_log: bool,
}

impl Default for PilServer {
    fn default() -> Self {
        Self::new()
    }
}

impl PilServer {
    /// A server waiting for the first frame (the controller as `boot` made
    /// it: `Config::default()`).
    pub fn new() -> Self {
        let c = Config::default();
        Self {
            dec: Decoder::new(),
            tx: [0; MAX_FRAME],
            pulses: 0,
            seq: None,
            f_timer_hz: c.f_timer_hz,
            inputs: c.initial_inputs,
        }
    }

    /// Feeds one received byte; when it completes a request, runs it and
    /// sends the reply. `on_output` sees every pulse answer (for telemetry).
    pub fn feed(
        &mut self,
        byte: u8,
        ctrl: &mut Ctrl,
        link: &mut impl Link,
        mut on_output: impl FnMut(&PulseEvent),
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
                self.pulses = self.pulses.wrapping_add(1);
                let mut ev = PulseEvent {
                    ticks,
                    out: ControlOutput::IDLE,
                    inputs: self.inputs,
                    started: None,
                    pulse_log: false,
                };
                let reply = match self.seq.as_mut() {
                    Some(seq) => {
                        let st = ivt_fw_sequenced_pulse(seq, ctrl, ticks);
                        ev.out = st.out;
                        ev.started = st.started;
                        ev.pulse_log = st.pulse_log;
                        Reply::Sequenced {
                            out: st.out,
                            stage: st.stage,
                            started: st.started.is_some(),
                            pulse_log: st.pulse_log,
                            done: st.done,
                        }
                    }
                    None => {
                        ev.out = ivt_fw_pulse(ctrl, ticks);
                        Reply::Output(ev.out)
                    }
                };
                on_output(&ev);
                reply
            }
            Ok(Request::Inputs { v_m, t_u }) => {
                ctrl.update_inputs(v_m, t_u);
                self.inputs = [v_m, t_u];
                Reply::Ack
            }
            Ok(Request::Configure(config)) => {
                // In place (no stack temporary); an invalid config gives the
                // controller's own Fault::Config state. Ends a sequence.
                ctrl.reset(config);
                self.pulses = 0;
                self.seq = None;
                self.f_timer_hz = config.f_timer_hz;
                self.inputs = config.initial_inputs;
                Reply::Ack
            }
            Ok(Request::Commission { selection, plan }) => {
                self.seq = Some(Sequencer::new(plan, selection, self.f_timer_hz));
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

/// Streams telemetry frames (`ivt_wire::telemetry`, v2) over a link:
/// samples, stage starts and batches of logged encoder edges.
pub struct TelemetryTx<L: ByteSink> {
    link: L,
    buf: [u8; MAX_FRAME],
    batch: PulseBatch,
    /// Sample frames sent so far.
    pub frames: u32,
}

impl<L: ByteSink> TelemetryTx<L> {
    /// A sender over `link`.
    pub const fn new(link: L) -> Self {
        Self {
            link,
            buf: [0; MAX_FRAME],
            batch: PulseBatch::new(0),
            frames: 0,
        }
    }

    fn send(&mut self, f: &TelemetryFrame) -> bool {
        match f.encode(&mut self.buf) {
            Ok(n) => {
                self.link.write_all(self.buf.get(..n).unwrap_or(&[]));
                true
            }
            Err(_) => false,
        }
    }

    /// Sends one sample: the timestamp, ω, ω_a, r, the inputs read, the
    /// stepper position and the fault code.
    pub fn sample(
        &mut self,
        time_ticks: u32,
        out: &ControlOutput,
        inputs: [f32; 2],
        position: i32,
    ) {
        let s = TelemetrySample {
            time_ticks,
            omega: out.omega,
            omega_a: out.omega_a,
            r: out.r,
            inputs: Some(inputs),
            stepper_position: position,
            fault: out.fault.code(),
        };
        if self.send(&TelemetryFrame::Sample(s)) {
            self.frames = self.frames.wrapping_add(1);
        }
    }

    /// Announces a stage start (flushing the edges of the stage before).
    pub fn stage(&mut self, stage: &Stage, time_ticks: u32) {
        self.flush_pulses();
        self.send(&TelemetryFrame::Stage(StageStart::of(stage, time_ticks)));
    }

    /// Logs one encoder edge; a full batch is sent.
    pub fn log_pulse(&mut self, ticks: u32) {
        if !self.batch.push(ticks) {
            self.flush_pulses();
            self.batch.push(ticks);
        }
    }

    /// Sends the logged edges not sent yet.
    pub fn flush_pulses(&mut self) {
        if self.batch.len > 0 {
            self.send(&TelemetryFrame::Pulses(self.batch));
        }
        let next = self.batch.first.wrapping_add(u32::from(self.batch.len));
        self.batch = PulseBatch::new(next);
    }
}
