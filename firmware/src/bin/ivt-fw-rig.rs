//! STM32F411 rig image. Interrupts (lower number = more urgent):
//! - TIM2 (priority 0): encoder edge captured on CH1 → `ivt_fw_pulse`.
//! - TIM3 (priority 1): step generator tick → step/dir pins.
//! - thread mode: ADC → `update_inputs` every ms, telemetry on USART1, fault LED,
//!   and requests from the host on USART1 RX: `Commission` starts the
//!   commissioning sequences (`ivt_ctrl::commission`), run from here on by
//!   the TIM2 ISR; stage starts and the logged edges go out as telemetry.
//!
//! The controller is shared in a `Mutex<RefCell<..>>`; TIM3 and the thread
//! mode take it inside `interrupt::free`, which delays (never loses) the
//! pulse ISR: the edge time is latched by the capture hardware.
#![no_std]
#![no_main]

use core::cell::RefCell;

use cortex_m::interrupt::{free, Mutex};
use cortex_m_rt::entry;
use defmt_rtt as _;
use ivt_ctrl::commission::{Sequencer, Stage};
use ivt_ctrl::{ControlOutput, Fault};
use ivt_firmware::app::{
    ivt_fw_pulse, ivt_fw_sequenced_pulse, take_controller, ByteSink, Ctrl, TelemetryTx,
};
use ivt_firmware::board::rig::{self, F_TIMER_HZ, STEP_TICK_HZ, T_U_SCALE, V_M_SCALE};
use ivt_wire::frame::Decoder;
use ivt_wire::telemetry::PulseBatch;
use ivt_wire::Request;
use stm32f4xx_hal::{
    adc::{config::AdcConfig, config::SampleTime, Adc},
    gpio::{Output, PushPull, PB0, PB1},
    pac::{self, interrupt, Interrupt},
    prelude::*,
    rcc,
    timer::{CapturePolarity, Event, Timer},
};

struct Shared {
    ctrl: &'static mut Ctrl,
    last: Option<ControlOutput>,
    position: i32,
    overcaptures: u32,
    step: PB0<Output<PushPull>>,
    dir: PB1<Output<PushPull>>,
    step_high: bool,
    /// The running commissioning sequence.
    seq: Option<Sequencer>,
    /// A stage that started (with its pulse's timestamp), not announced yet.
    started: Option<(Stage, u32)>,
    /// Edges logged by the TIM2 ISR in a pulse-log stage, not sent yet.
    log: PulseBatch,
    /// Edges that did not fit in `log` before thread mode sent it.
    log_lost: u32,
}

static SHARED: Mutex<RefCell<Option<Shared>>> = Mutex::new(RefCell::new(None));

/// USART1 transmit through the PAC (the HAL configured pins and baud rate).
struct Usart1;

/// The byte USART1 received, if one is waiting (PAC; RE enabled at start).
fn usart1_read() -> Option<u8> {
    // SAFETY: USART1 is owned by this image; this reads its RX side only.
    let u = unsafe { &*pac::USART1::ptr() };
    let sr = u.sr().read();
    if sr.ore().bit_is_set() || sr.rxne().bit_is_set() {
        // Reading DR clears RXNE (and, after SR, an overrun).
        Some(u.dr().read().bits() as u8)
    } else {
        None
    }
}

impl ByteSink for Usart1 {
    fn write_all(&mut self, bytes: &[u8]) {
        // SAFETY: USART1 is owned by this image; only its TX side is used here.
        let u = unsafe { &*pac::USART1::ptr() };
        for &b in bytes {
            while u.sr().read().txe().bit_is_clear() {}
            u.dr().write(|w| unsafe { w.bits(b as u16) });
        }
    }
}

#[entry]
fn main() -> ! {
    let (Some(dp), Some(mut cp)) = (pac::Peripherals::take(), cortex_m::Peripherals::take()) else {
        halt()
    };
    let mut rcc = dp
        .RCC
        .freeze(rcc::Config::hse(25.MHz()).sysclk(rig::SYSCLK_HZ.Hz()));
    let gpioa = dp.GPIOA.split(&mut rcc);
    let gpiob = dp.GPIOB.split(&mut rcc);
    let gpioc = dp.GPIOC.split(&mut rcc);

    // Encoder: TIM2 CH1 on PA0, rising edges, counting at F_TIMER_HZ.
    let (mut tim2, (ch1, ..)) = Timer::new(dp.TIM2, &mut rcc).capture_hz(F_TIMER_HZ.Hz());
    let mut ch1 = ch1.with(gpioa.pa0);
    ch1.set_polarity(CapturePolarity::ActiveHigh);
    ch1.enable();
    tim2.listen(Event::C1);

    // Step generator tick.
    let mut tim3 = dp.TIM3.counter_hz(&mut rcc);
    if tim3.start(STEP_TICK_HZ.Hz()).is_err() {
        halt()
    }
    tim3.listen(Event::Update);

    // Inputs, telemetry, LED.
    let v_m_pin = gpioa.pa1.into_analog();
    let t_u_pin = gpioa.pa4.into_analog();
    let mut adc = Adc::new(dp.ADC1, true, AdcConfig::default(), &mut rcc);
    let Ok(_tx): Result<stm32f4xx_hal::serial::Tx<pac::USART1, u8>, _> =
        dp.USART1.tx(gpioa.pa9, rig::TELEMETRY_BAUD.bps(), &mut rcc)
    else {
        halt()
    };
    let _rx_pin = gpioa.pa10.into_alternate::<7>();
    // SAFETY: turns on the receiver of the USART1 the HAL just configured.
    unsafe { (*pac::USART1::ptr()).cr1().modify(|_, w| w.re().set_bit()) };
    let mut requests = Decoder::new();
    let mut telemetry = TelemetryTx::new(Usart1);
    let mut led = gpioc.pc13.into_push_pull_output(); // active low on the Black Pill
    led.set_high();
    let mut delay = cp.SYST.delay(&rcc.clocks);

    let Some(ctrl) = take_controller(rig::config()) else {
        halt()
    };
    free(|cs| {
        SHARED.borrow(cs).replace(Some(Shared {
            ctrl,
            last: None,
            position: 0,
            overcaptures: 0,
            step: gpiob.pb0.into_push_pull_output(),
            dir: gpiob.pb1.into_push_pull_output(),
            step_high: false,
            seq: None,
            started: None,
            log: PulseBatch::new(0),
            log_lost: 0,
        }));
    });
    // SAFETY: priorities are set before the interrupts are unmasked.
    unsafe {
        cp.NVIC.set_priority(Interrupt::TIM2, 0x00);
        cp.NVIC.set_priority(Interrupt::TIM3, 0x10);
        cortex_m::peripheral::NVIC::unmask(Interrupt::TIM2);
        cortex_m::peripheral::NVIC::unmask(Interrupt::TIM3);
    }
    defmt::info!(
        "ivt-fw-rig: PPR {}, f_timer {} Hz",
        ivt_firmware::app::PPR,
        F_TIMER_HZ
    );

    let mut n: u32 = 0;
    loop {
        let mut commission = None;
        while let Some(b) = usart1_read() {
            if let Some(Ok(f)) = requests.push(b) {
                if let Ok(Request::Commission { selection, plan }) =
                    Request::decode(f.kind, f.payload)
                {
                    commission = Some(Sequencer::new(plan, selection, F_TIMER_HZ as f32));
                }
            }
        }
        let v_m = V_M_SCALE.apply(adc.convert(&v_m_pin, SampleTime::Cycles_480));
        let t_u = T_U_SCALE.apply(adc.convert(&t_u_pin, SampleTime::Cycles_480));
        let snapshot = free(|cs| {
            let mut guard = SHARED.borrow(cs).try_borrow_mut().ok()?;
            let s = guard.as_mut()?;
            s.ctrl.update_inputs(v_m, t_u);
            if commission.is_some() {
                s.seq = commission;
            }
            let log = s.log;
            let next = log
                .first
                .wrapping_add(u32::from(log.len))
                .wrapping_add(s.log_lost);
            s.log = PulseBatch::new(next);
            s.log_lost = 0;
            Some((s.last, s.position, s.overcaptures, s.started.take(), log))
        });
        if let Some((last, position, overcaptures, started, log)) = snapshot {
            for &edge in log.edges() {
                telemetry.log_pulse(edge);
            }
            if let Some((stage, at)) = started {
                telemetry.stage(&stage, at);
            }
            let out = last.unwrap_or(ControlOutput::IDLE);
            if out.fault == Fault::None && overcaptures == 0 {
                led.set_high();
            } else {
                led.set_low();
            }
            n = n.wrapping_add(1);
            if n % rig::TELEMETRY_EVERY == 0 {
                // SAFETY: read-only access to the free-running TIM2 counter.
                let now = unsafe { (*pac::TIM2::ptr()).cnt().read().bits() };
                telemetry.flush_pulses();
                telemetry.sample(now, &out, [v_m, t_u], position);
                if out.fault != Fault::None {
                    defmt::warn!("fault {}", out.fault as u8);
                }
            }
        }
        delay.delay_ms(rig::INPUT_PERIOD_MS);
    }
}

#[interrupt]
fn TIM2() {
    // SAFETY: TIM2 belongs to the encoder capture; this ISR only reads the
    // capture register (which clears CC1IF) and clears CC1OF.
    let tim = unsafe { &*pac::TIM2::ptr() };
    let sr = tim.sr().read();
    if sr.cc1if().bit_is_clear() {
        return;
    }
    let ticks = tim.ccr1().read().bits();
    let overcapture = sr.cc1of().bit_is_set();
    if overcapture {
        // rc_w0: write 0 to CC1OF (bit 9), 1 elsewhere leaves other flags alone.
        tim.sr().write(|w| unsafe { w.bits(!(1 << 9)) });
    }
    free(|cs| {
        if let Ok(mut guard) = SHARED.borrow(cs).try_borrow_mut() {
            if let Some(s) = guard.as_mut() {
                let out = match s.seq.as_mut() {
                    Some(seq) => {
                        let st = ivt_fw_sequenced_pulse(seq, s.ctrl, ticks);
                        if let Some(stage) = st.started {
                            s.started = Some((stage, ticks));
                        }
                        if st.pulse_log && !s.log.push(ticks) {
                            s.log_lost = s.log_lost.wrapping_add(1);
                        }
                        st.out
                    }
                    None => ivt_fw_pulse(s.ctrl, ticks),
                };
                s.last = Some(out);
                s.overcaptures = s.overcaptures.wrapping_add(overcapture as u32);
            }
        }
    });
}

#[interrupt]
fn TIM3() {
    // SAFETY: TIM3 is the step tick; clear its update flag (rc_w0, bit 0).
    let tim3 = unsafe { &*pac::TIM3::ptr() };
    tim3.sr().write(|w| unsafe { w.bits(!1) });
    // SAFETY: read-only access to the free-running TIM2 counter.
    let now = unsafe { (*pac::TIM2::ptr()).cnt().read().bits() };
    free(|cs| {
        if let Ok(mut guard) = SHARED.borrow(cs).try_borrow_mut() {
            if let Some(s) = guard.as_mut() {
                if s.step_high {
                    s.step.set_low();
                    s.step_high = false;
                    return;
                }
                let st = s.ctrl.step_tick(now);
                s.position = st.position;
                if st.step {
                    if st.forward {
                        s.dir.set_high();
                    } else {
                        s.dir.set_low();
                    }
                    s.step.set_high();
                    s.step_high = true;
                }
            }
        }
    });
}

/// Stops everything: interrupts off, step pin idle. A watchdog (not enabled
/// here) would reset; the stepper holds its position.
fn halt() -> ! {
    cortex_m::interrupt::disable();
    loop {
        cortex_m::asm::wfi();
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    halt()
}
