//! Host side of the processor-in-the-loop link: starts the QEMU firmware
//! (`firmware/`, image `ivt-fw-qemu`), connects to its UART0 over a Unix
//! socket and exchanges one request/reply pair per call.
//!
//! QEMU is started as
//! `qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -display none -monitor none
//!  -semihosting-config enable=on,target=native -chardev socket,id=pil,path=SOCK
//!  -serial chardev:pil -serial TELEMETRY -kernel ELF`
//! with the host listening on `SOCK` (QEMU connects as client, so there is no
//! race on start-up). UART1 (telemetry) goes to `null` unless asked otherwise.

use std::io::{BufRead, BufReader, Read, Write};
use std::os::unix::net::{UnixListener, UnixStream};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use ivt_ctrl::{Config, ControlOutput, Plan, Selection};

use crate::frame::{Decoder, WireError, MAX_FRAME};
use crate::msg::{Reply, Request, VERSION};

/// Errors of the PIL link. Each says what failed and, where it helps, what the
/// firmware printed.
#[derive(Debug, thiserror::Error)]
pub enum PilError {
    /// The firmware image is not there: a path the user gave (`$IVT_FW_ELF`)
    /// is shown, the default image of the source tree is named relative to
    /// the tree (never by the build machine's absolute path).
    #[error("{}", missing_image(.0))]
    MissingImage(PathBuf),
    /// QEMU could not be started.
    #[error("cannot start {program}: {source}")]
    Spawn {
        /// The program that failed to start.
        program: String,
        /// The OS error.
        source: std::io::Error,
    },
    /// Socket I/O failed.
    #[error("PIL link I/O: {0}")]
    Io(#[from] std::io::Error),
    /// No answer in time.
    #[error("PIL link: no answer within {0:?} ({1})")]
    Timeout(Duration, &'static str),
    /// A malformed frame arrived.
    #[error("PIL link: {0}")]
    Wire(WireError),
    /// The firmware answered something unexpected.
    #[error("PIL protocol: expected {expected}, got {got:?}")]
    Protocol {
        /// What the request called for.
        expected: &'static str,
        /// What came back.
        got: Reply,
    },
    /// The firmware was built for another PPR or protocol version.
    #[error("firmware speaks protocol v{version} with PPR {ppr}; host needs v{VERSION} with PPR {want_ppr}")]
    Incompatible {
        /// Firmware protocol version.
        version: u16,
        /// Firmware PPR.
        ppr: u32,
        /// PPR the host asked for.
        want_ppr: u32,
    },
    /// QEMU ended abnormally.
    #[error("QEMU exited with {status}; its output: {output}")]
    Exited {
        /// Exit status.
        status: std::process::ExitStatus,
        /// What QEMU/semihosting printed.
        output: String,
    },
}

/// How to start the QEMU firmware.
#[derive(Clone, Debug)]
pub struct QemuOptions {
    /// Path to the `ivt-fw-qemu` ELF.
    pub elf: PathBuf,
    /// The QEMU binary.
    pub qemu: String,
    /// QEMU `-serial` spec for UART1 (telemetry), e.g. `null`, `pty`, `file:PATH`.
    /// With `pty`, [`QemuPil::telemetry_pty`] gives the device QEMU allocated.
    pub telemetry_serial: String,
    /// Time allowed for QEMU to start and for each answer.
    pub timeout: Duration,
}

impl QemuOptions {
    /// Defaults: the image built by `firmware/run-qemu.sh build` in this
    /// repository (or `$IVT_FW_ELF`), `qemu-system-arm`, telemetry to `null`,
    /// 20 s per answer (generous: CI machines are loaded).
    pub fn from_env() -> Self {
        let elf = std::env::var_os("IVT_FW_ELF")
            .map(PathBuf::from)
            .unwrap_or_else(default_elf);
        Self {
            elf,
            qemu: "qemu-system-arm".into(),
            telemetry_serial: "null".into(),
            timeout: Duration::from_secs(20),
        }
    }
}

/// The default firmware image, relative to the source tree.
const DEFAULT_ELF: &str = "firmware/target/thumbv7em-none-eabihf/release/ivt-fw-qemu";

/// `firmware/target/thumbv7em-none-eabihf/release/ivt-fw-qemu` of this repository.
pub fn default_elf() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(DEFAULT_ELF)
}

/// The message of [`PilError::MissingImage`] for the image `elf`.
fn missing_image(elf: &Path) -> String {
    if elf == default_elf() {
        format!(
            "the QEMU firmware image is not built ({DEFAULT_ELF} of the source tree): \
             run firmware/run-qemu.sh build there, or set $IVT_FW_ELF to an image"
        )
    } else {
        format!(
            "firmware image {} not found: set $IVT_FW_ELF to an image, or build the \
             source tree's with firmware/run-qemu.sh build",
            elf.display()
        )
    }
}

/// What the firmware reported when the session ended (semihosting
/// `key=value` lines).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FirmwareReport {
    /// Pulses served.
    pub pulses: u64,
    /// Telemetry frames sent on UART1.
    pub telemetry_frames: u64,
    /// Measured stack high-water mark \[bytes\].
    pub stack_high_water_bytes: u64,
    /// RAM used by statics \[bytes\].
    pub static_ram_bytes: u64,
}

/// A running QEMU firmware with its PIL link.
pub struct QemuPil {
    child: Child,
    stdout: Option<BufReader<ChildStdout>>,
    telemetry_pty: Option<PathBuf>,
    stream: UnixStream,
    socket: PathBuf,
    dec: Decoder,
    rx: [u8; 256],
    rx_len: usize,
    rx_pos: usize,
    tx: [u8; MAX_FRAME],
    timeout: Duration,
}

static SESSION: AtomicU32 = AtomicU32::new(0);

impl QemuPil {
    /// Starts QEMU and waits for its connection; then checks the firmware's
    /// protocol version and that it was built for `ppr`.
    ///
    /// # Errors
    /// Missing image, spawn failure, time-out, or an incompatible firmware.
    pub fn start(opts: &QemuOptions, ppr: u32) -> Result<Self, PilError> {
        if !opts.elf.is_file() {
            return Err(PilError::MissingImage(opts.elf.clone()));
        }
        let socket = std::env::temp_dir().join(format!(
            "ivt-pil-{}-{}.sock",
            std::process::id(),
            SESSION.fetch_add(1, Ordering::Relaxed)
        ));
        let _ = std::fs::remove_file(&socket);
        let listener = UnixListener::bind(&socket)?;
        listener.set_nonblocking(true)?;
        let mut child = Command::new(&opts.qemu)
            .args(["-cpu", "cortex-m4", "-machine", "mps2-an386"])
            .args(["-display", "none", "-monitor", "none"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-chardev")
            .arg(format!("socket,id=pil,path={}", socket.display()))
            .args(["-serial", "chardev:pil", "-serial", &opts.telemetry_serial])
            .arg("-kernel")
            .arg(&opts.elf)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|source| PilError::Spawn {
                program: opts.qemu.clone(),
                source,
            })?;
        let mut stdout = child.stdout.take().map(BufReader::new);
        let telemetry_pty = if opts.telemetry_serial == "pty" {
            // QEMU announces "char device redirected to /dev/pts/N (label serial1)"
            // on stdout while it creates the chardevs, before the guest runs.
            let mut found = None;
            let mut line = String::new();
            while let Some(out) = stdout.as_mut() {
                line.clear();
                if out.read_line(&mut line)? == 0 {
                    break;
                }
                if let Some(rest) = line.split("redirected to ").nth(1) {
                    if line.contains("(label serial1)") {
                        found = rest.split_whitespace().next().map(PathBuf::from);
                        break;
                    }
                }
            }
            if found.is_none() {
                let _ = child.kill();
                let status = child.wait()?;
                let _ = std::fs::remove_file(&socket);
                return Err(PilError::Exited {
                    status,
                    output: format!("no pty announced for UART1; last line: {line}"),
                });
            }
            found
        } else {
            None
        };
        let t0 = Instant::now();
        let stream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    if let Some(status) = child.try_wait()? {
                        let _ = std::fs::remove_file(&socket);
                        return Err(PilError::Exited {
                            status,
                            output: drain_output(&mut child, &mut stdout),
                        });
                    }
                    if t0.elapsed() > opts.timeout {
                        let _ = child.kill();
                        let _ = child.wait();
                        let _ = std::fs::remove_file(&socket);
                        return Err(PilError::Timeout(opts.timeout, "QEMU did not connect"));
                    }
                    std::thread::sleep(Duration::from_millis(5));
                }
                Err(e) => return Err(e.into()),
            }
        };
        stream.set_nonblocking(false)?;
        stream.set_read_timeout(Some(opts.timeout))?;
        let mut pil = Self {
            child,
            stdout,
            telemetry_pty,
            stream,
            socket,
            dec: Decoder::new(),
            rx: [0; 256],
            rx_len: 0,
            rx_pos: 0,
            tx: [0; MAX_FRAME],
            timeout: opts.timeout,
        };
        match pil.call(&Request::Hello)? {
            Reply::Hello {
                version,
                ppr: fw_ppr,
            } if version == VERSION && fw_ppr == ppr => Ok(pil),
            Reply::Hello {
                version,
                ppr: fw_ppr,
            } => Err(PilError::Incompatible {
                version,
                ppr: fw_ppr,
                want_ppr: ppr,
            }),
            got => Err(PilError::Protocol {
                expected: "Hello",
                got,
            }),
        }
    }

    /// The pty QEMU allocated for UART1 (telemetry) when started with
    /// `telemetry_serial = "pty"`.
    pub fn telemetry_pty(&self) -> Option<&Path> {
        self.telemetry_pty.as_deref()
    }

    /// Sends one request and waits for its reply.
    ///
    /// # Errors
    /// I/O, time-out or a malformed frame.
    pub fn call(&mut self, req: &Request) -> Result<Reply, PilError> {
        let n = req.encode(&mut self.tx).map_err(PilError::Wire)?;
        let frame = self
            .tx
            .get(..n)
            .ok_or(PilError::Wire(WireError::BufferTooSmall))?;
        self.stream.write_all(frame)?;
        loop {
            if self.rx_pos == self.rx_len {
                self.rx_len = match self.stream.read(&mut self.rx) {
                    Ok(0) => {
                        return Err(PilError::Exited {
                            status: self.child.wait()?,
                            output: drain_output(&mut self.child, &mut self.stdout),
                        })
                    }
                    Ok(n) => n,
                    Err(e)
                        if matches!(
                            e.kind(),
                            std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                        ) =>
                    {
                        return Err(PilError::Timeout(self.timeout, "no reply"))
                    }
                    Err(e) => return Err(e.into()),
                };
                self.rx_pos = 0;
            }
            let Some(&b) = self.rx.get(self.rx_pos) else {
                // Past the buffer (cannot follow a read): read afresh.
                self.rx_pos = self.rx_len;
                continue;
            };
            self.rx_pos += 1;
            if let Some(frame) = self.dec.push(b) {
                let f = frame.map_err(PilError::Wire)?;
                return Reply::decode(f.kind, f.payload).map_err(PilError::Wire);
            }
        }
    }

    /// Replaces the firmware's controller by `Controller::new(config)`.
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a reply other than `Ack`.
    pub fn configure(&mut self, config: &Config) -> Result<(), PilError> {
        self.expect_ack(&Request::Configure(*config), "Ack to Configure")
    }

    /// Sends V_m and T_U.
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a reply other than `Ack`.
    pub fn update_inputs(&mut self, v_m: f32, t_u: f32) -> Result<(), PilError> {
        self.expect_ack(&Request::Inputs { v_m, t_u }, "Ack to Inputs")
    }

    /// One encoder pulse; returns the firmware controller's output.
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a reply other than `Output`.
    pub fn on_pulse(&mut self, ticks: u32) -> Result<ControlOutput, PilError> {
        match self.call(&Request::Pulse { ticks })? {
            Reply::Output(o) => Ok(o),
            got => Err(PilError::Protocol {
                expected: "Output",
                got,
            }),
        }
    }

    /// Starts the commissioning sequences `selection` of `plan` on the next
    /// pulse; pulses are then answered by [`QemuPil::sequenced_pulse`].
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a reply other than `Ack`.
    pub fn commission(&mut self, selection: Selection, plan: &Plan) -> Result<(), PilError> {
        let req = Request::Commission {
            selection,
            plan: *plan,
        };
        self.expect_ack(&req, "Ack to Commission")
    }

    /// One encoder pulse while a sequence runs: the `Sequenced` reply.
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a reply other than `Sequenced`.
    pub fn sequenced_pulse(&mut self, ticks: u32) -> Result<Reply, PilError> {
        match self.call(&Request::Pulse { ticks })? {
            r @ Reply::Sequenced { .. } => Ok(r),
            got => Err(PilError::Protocol {
                expected: "Sequenced",
                got,
            }),
        }
    }

    fn expect_ack(&mut self, req: &Request, expected: &'static str) -> Result<(), PilError> {
        match self.call(req)? {
            Reply::Ack => Ok(()),
            got => Err(PilError::Protocol { expected, got }),
        }
    }

    /// Ends the session: the firmware exits QEMU with status 0 and reports
    /// its counters and stack high-water mark.
    ///
    /// # Errors
    /// As [`QemuPil::call`], or a non-zero QEMU exit.
    pub fn finish(mut self) -> Result<FirmwareReport, PilError> {
        self.expect_ack(&Request::Exit, "Ack to Exit")?;
        let status = self.child.wait()?;
        let output = drain_output(&mut self.child, &mut self.stdout);
        if !status.success() {
            return Err(PilError::Exited { status, output });
        }
        let mut rep = FirmwareReport::default();
        for line in output.lines() {
            let Some((k, v)) = line.trim().split_once('=') else {
                continue;
            };
            let Ok(v) = v.parse::<u64>() else { continue };
            match k {
                "pulses" => rep.pulses = v,
                "telemetry_frames" => rep.telemetry_frames = v,
                "stack_high_water_bytes" => rep.stack_high_water_bytes = v,
                "static_ram_bytes" => rep.static_ram_bytes = v,
                _ => {}
            }
        }
        Ok(rep)
    }
}

impl Drop for QemuPil {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
        let _ = std::fs::remove_file(&self.socket);
    }
}

fn drain_output(child: &mut Child, stdout: &mut Option<BufReader<ChildStdout>>) -> String {
    let mut s = String::new();
    if let Some(out) = stdout.as_mut() {
        let _ = out.read_to_string(&mut s);
    }
    if let Some(err) = child.stderr.as_mut() {
        let _ = err.read_to_string(&mut s);
    }
    s
}
