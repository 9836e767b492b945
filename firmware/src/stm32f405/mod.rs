//! Board: STM32F405 (Cortex-M4F at 168 MHz), e.g. STM32F405RGT6, with stm32f4xx-hal 0.23.
//!
//! Built only for `target_os = "none"` with `--features stm32f405`; the image is the
//! `firmware-stm32f405` binary. The same code, with what QEMU does not model substituted, is
//! the `firmware-stm32f405-emulator` image for QEMU's netduinoplus2 ([`emulator`], feature
//! `stm32f405-emulator`; not a flight image).
//!
//! # Clocks
//!
//! **Assumes an 8 MHz crystal on HSE** (OSC_IN/OSC_OUT). The PLL makes SYSCLK = HCLK =
//! 168 MHz, PCLK2 = 84 MHz (APB2 timers 168 MHz), PCLK1 = 42 MHz (APB1 timers 84 MHz). A
//! different crystal needs [`HSE_HZ`] changed; with no crystal fitted, `init` waits forever
//! for HSE to start (before the watchdog is running, with every thruster pin still floating:
//! see *Safe state* below).
//!
//! # Pin map
//!
//! | thruster            | `thrusters()` index | timer / channel | pin  |
//! |---------------------|---------------------|-----------------|------|
//! | main (surge)        | 0                   | TIM1 CH1        | PA8  |
//! | vertical fore       | 1                   | TIM1 CH2        | PA9  |
//! | vertical aft        | 2                   | TIM1 CH3        | PA10 |
//! | horizontal fore     | 3                   | TIM1 CH4        | PA11 |
//! | horizontal aft      | 4                   | TIM8 CH1        | PC6  |
//! | nav link TX         | –                   | USART2 TX (AF7) | PA2  |
//! | nav link RX         | –                   | USART2 RX (AF7) | PA3  |
//!
//! SWD (PA13/PA14) is left alone. PA9/PA11 are also USB OTG FS VBUS/DM, so USB FS is not
//! available with this map; PA9/PA10 are USART1's usual pins, USART1 is not used.
//!
//! - **PWM**: [`PWM_HZ`] = 20 kHz, edge-aligned PWM mode 1 on the two advanced timers (168 MHz
//!   timer clock, no prescaler: [`PWM_COUNTS`] = 8400 counts per period,
//!   [`Thruster::max_duty_cycle`] = 8400).
//!   Duty d gives a mean H-bridge voltage (2d − 1)·V_s (locked anti-phase, see
//!   [`crate::pwm`]); **neutral is 50 %**. `init` sets all five channels to neutral and
//!   lets the timers load it before it enables any output.
//! - **Navigation link**: USART2 at 460800 baud, 8 data bits, no parity, 1 stop bit (8N1), no
//!   flow control. [`Usart2Link`] is interrupt driven: the `USART2` interrupt moves bytes
//!   between the data register and two `heapless` queues ([`crate::serial`]:
//!   [`RX_CAPACITY`](crate::serial::RX_CAPACITY) / [`TX_CAPACITY`](crate::serial::TX_CAPACITY)
//!   bytes), so
//!   nothing is lost while the loop computes or waits for the period (the USART has a
//!   one-byte receive register: a polled receiver would drop almost every byte of a frame that
//!   arrives during `wait_period`), and telemetry goes out in the background instead of
//!   blocking the loop for a frame time (~87 µs per byte).
//! - **Period timer**: SysTick on the 168 MHz core clock (HCLK/8 = 21 MHz below 11 Hz, where
//!   the 24-bit reload would overflow). The period is 1/hz to within one count for hz ≥ 2;
//!   1 Hz is clamped to the longest SysTick period, 0.8 s. Between periods the core sleeps
//!   (WFI); SysTick's interrupt wakes it at the boundary, USART2's for each byte. (Under QEMU a
//!   core that polls SysTick keeps a host CPU busy and starves QEMU's I/O thread, which delivers
//!   the link's bytes; sleeping frees it.)
//! - **`now()`**: the DWT cycle counter CYCCNT, a free-running 32-bit up-counter in CPU cycles
//!   ([`SYSCLK_HZ`] per second; wraps every 25.6 s, `wrapping_sub` differences are fine). The
//!   real Cortex-M4 has it (`init` enables DCB trace and the counter); QEMU does not model
//!   the DWT cycle counter (the QEMU board times with SysTick).
//! - **Supply**: [`SUPPLY_VOLTAGE`] = 24 V, a constant (the board does not measure it).
//! - **Watchdog**: the independent watchdog (IWDG, on the ~32 kHz LSI) is started at the end of
//!   `init` with a 50 ms timeout — five periods at 100 Hz — and fed by `feed_watchdog()` once
//!   per period. [`Board::set_rate`] lengthens it to four periods for rates below 80 Hz (up to
//!   4.1 s), so a slow rate does not reset a healthy board. The LSI is only specified to
//!   17–47 kHz: the real timeout is 0.68–1.9 × nominal (≥ 2.7 periods).
//!
//! # Safe state
//!
//! A hang (a stuck loop, or a fault or panic handler that neither resets nor returns) stops the
//! feeding, and the IWDG resets the MCU. Reset returns every GPIO to a floating input, so the five PWM pins stop driving
//! and the **H-bridge inputs must be pulled low on the board** (pull-downs on the PWM/enable
//! lines, or the driver's own): low = H-bridge disabled, which is the safe state. The same
//! holds from power-on until `init` drives the channels to neutral, and while a debugger halts
//! the core: `init` sets the DBGMCU freeze bits, so TIM1/TIM8 stop with their outputs disabled
//! (RM0090, advanced timers in debug mode: as if MOE were cleared; with OSSI = 0 the timer no
//! longer drives the pins) and the IWDG pauses.
//!
//! # Timing notes
//!
//! Each received or sent byte costs one short interrupt (a few dozen cycles, ~11.5 k/s each
//! way at full line rate); it can land inside a timed `Controller::update` and lengthen the
//! measured ticks by that much.

use core::convert::Infallible;

use controller_core::effectiveness::THRUSTERS;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{DWT, SYST};
use embedded_hal::pwm::{ErrorType as PwmErrorType, SetDutyCycle};
use stm32f4xx_hal::gpio::{PA10, PA11, PA2, PA3, PA8, PA9, PC6};
use stm32f4xx_hal::pac;
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::rcc::{Config as ClockConfig, Rcc};
use stm32f4xx_hal::serial::config::StopBits;
use stm32f4xx_hal::serial::{Config as SerialConfig, Serial};
use stm32f4xx_hal::timer::{ErasedChannel, PwmHzManager};

use crate::board::Board;
use crate::pwm;
use crate::serial::LINK_BAUD;

mod usart2;
pub use usart2::{on_usart2_interrupt, Usart2Link};

#[cfg(feature = "stm32f405-emulator")]
pub mod emulator;

/// HSE crystal frequency (Hz). **Assumption: an 8 MHz crystal.**
pub const HSE_HZ: u32 = 8_000_000;
/// Core clock SYSCLK = HCLK (Hz); also the unit of [`Board::now`] (CPU cycles). The flight
/// clock the budgets are checked against (`crate::watchdog`).
pub const SYSCLK_HZ: u32 = crate::watchdog::FLIGHT_CLOCK_HZ;
/// APB1 clock (USART2; APB1 timers run at twice this).
pub const PCLK1_HZ: u32 = 42_000_000;
/// APB2 clock (TIM1, TIM8 run at twice this: 168 MHz).
pub const PCLK2_HZ: u32 = 84_000_000;
/// Thruster PWM frequency (Hz).
pub const PWM_HZ: u32 = 20_000;
/// Counts of one PWM period, the channels' full duty: the advanced timers' clock (2 × PCLK2 =
/// 168 MHz) over [`PWM_HZ`], no prescaler.
pub const PWM_COUNTS: u16 = (2 * PCLK2_HZ / PWM_HZ) as u16;
/// H-bridge supply voltage V_s (V): nominal, not measured. The duty for a commanded voltage
/// is computed against it ([`crate::pwm::duty_fraction`]).
pub const SUPPLY_VOLTAGE: f32 = controller_core::DEFAULT_V_LIMIT;
/// Control rate set up by [`Stm32Board::init`] (Hz), the controller's default; call
/// [`Board::set_rate`] for another.
pub const DEFAULT_RATE_HZ: u32 = 100;
pub use crate::watchdog::WATCHDOG_MIN_MS;
use crate::watchdog::{timeout_ms as watchdog_timeout_ms, LSI_HZ};

/// IWDG prescaler /32: one watchdog count per ms at the nominal LSI.
const IWDG_DIV: u32 = 32;

/// Ends the program (the image's panic and fault handlers): a system reset — the exit code has
/// nowhere to go. Reset returns every pin to a floating input, so the H-bridge pull-downs
/// disable the thrusters (see *Safe state*).
pub fn halt(_code: i32) -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}

// ---------------------------------------------------------------------------------------------
// Thrusters
// ---------------------------------------------------------------------------------------------

/// One thruster PWM channel: a TIM1 or TIM8 output channel behind one type, so the five can
/// live in one array. Implements `embedded_hal::pwm::SetDutyCycle` (the HAL's channels do;
/// this only dispatches).
pub enum Thruster {
    Tim1(ErasedChannel<pac::TIM1>),
    Tim8(ErasedChannel<pac::TIM8>),
}

/// The board's five thruster outputs, as [`Stm32Board`] drives them: the real timers
/// ([`AdvancedTimers`]) or, in the emulator build, RAM channels (`emulator::EmulatedTimers`).
pub trait ThrusterOutputs {
    /// One channel.
    type Channel: SetDutyCycle;
    /// The five channels, order [main, vert fore, vert aft, horz fore, horz aft].
    fn channels(&mut self) -> &mut [Self::Channel; THRUSTERS];
}

/// The thruster outputs of the real board: TIM1 CH1–CH4 and TIM8 CH1 (pin map above), the
/// timers held so nothing else can reconfigure them.
pub struct AdvancedTimers {
    channels: [Thruster; THRUSTERS],
    _tim1: PwmHzManager<pac::TIM1>,
    _tim8: PwmHzManager<pac::TIM8>,
}

impl AdvancedTimers {
    /// Starts both timers at [`PWM_HZ`], sets every channel to neutral, waits until the timers
    /// have loaded it, and only then enables the outputs.
    fn init(
        tim1: pac::TIM1,
        tim8: pac::TIM8,
        (pa8, pa9, pa10, pa11, pc6): (PA8, PA9, PA10, PA11, PC6),
        rcc: &mut Rcc,
    ) -> Self {
        // The timers run from here on, every channel output still disabled.
        let (tim1, (t1c1, t1c2, t1c3, t1c4)) = tim1.pwm_hz(PWM_HZ.Hz(), rcc);
        let (tim8, (t8c1, ..)) = tim8.pwm_hz(PWM_HZ.Hz(), rcc);
        let mut channels = [
            Thruster::Tim1(t1c1.with(pa8).erase()),
            Thruster::Tim1(t1c2.with(pa9).erase()),
            Thruster::Tim1(t1c3.with(pa10).erase()),
            Thruster::Tim1(t1c4.with(pa11).erase()),
            Thruster::Tim8(t8c1.with(pc6).erase()),
        ];
        for t in channels.iter_mut() {
            let Ok(()) = pwm::set_neutral(t);
        }
        // The compare registers are preloaded: the neutral duty takes effect at the next update
        // event. Two PWM periods make sure it has before any output is enabled.
        cortex_m::asm::delay(2 * SYSCLK_HZ / PWM_HZ);
        for t in channels.iter_mut() {
            t.enable();
        }
        AdvancedTimers {
            channels,
            _tim1: tim1,
            _tim8: tim8,
        }
    }
}

impl ThrusterOutputs for AdvancedTimers {
    type Channel = Thruster;
    fn channels(&mut self) -> &mut [Thruster; THRUSTERS] {
        &mut self.channels
    }
}

impl Thruster {
    fn enable(&mut self) {
        match self {
            Thruster::Tim1(c) => c.enable(),
            Thruster::Tim8(c) => c.enable(),
        }
    }
}

impl PwmErrorType for Thruster {
    type Error = Infallible;
}

impl SetDutyCycle for Thruster {
    fn max_duty_cycle(&self) -> u16 {
        match self {
            Thruster::Tim1(c) => c.max_duty_cycle(),
            Thruster::Tim8(c) => c.max_duty_cycle(),
        }
    }

    fn set_duty_cycle(&mut self, duty: u16) -> Result<(), Infallible> {
        match self {
            Thruster::Tim1(c) => c.set_duty_cycle(duty),
            Thruster::Tim8(c) => c.set_duty_cycle(duty),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// The board
// ---------------------------------------------------------------------------------------------

/// The STM32F405 thruster board, with its thruster outputs `T` (the real timers; the emulator
/// build's RAM channels). See the module docs for clocks, pins and the safe state.
pub struct Stm32Board<T: ThrusterOutputs = AdvancedTimers> {
    thrusters: T,
    link: Usart2Link,
    syst: SYST,
    iwdg: pac::IWDG,
    rate_hz: u32,
    _dwt: DWT,
}

impl Stm32Board<AdvancedTimers> {
    /// Brings the board up: clocks, thruster PWM at neutral, the link, the period timer at
    /// [`DEFAULT_RATE_HZ`], the cycle counter and, last, the watchdog — from then on the caller
    /// must call [`Board::feed_watchdog`] (the control loop does, once per period) at least
    /// every 50 ms.
    ///
    /// `cp` is the core peripherals (`cortex_m::Peripherals::take()`, done by the caller); the
    /// board uses SYST, DWT, DCB and NVIC from it and drops the rest.
    ///
    /// # Panics
    ///
    /// Takes the device peripherals (`stm32f4xx_hal::pac::Peripherals::take()`): **call it
    /// once**. A second call, or a call after anything else took them, panics.
    pub fn init(cp: cortex_m::Peripherals) -> Self {
        let dp = pac::Peripherals::take().expect("device peripherals already taken");
        stop_in_debug(&dp.DBGMCU);
        let mut rcc = dp.RCC.freeze(
            ClockConfig::hse(HSE_HZ.Hz())
                .sysclk(SYSCLK_HZ.Hz())
                .hclk(SYSCLK_HZ.Hz())
                .pclk1(PCLK1_HZ.Hz())
                .pclk2(PCLK2_HZ.Hz()),
        );
        defmt::info!(
            "stm32f405: sysclk {} Hz, pclk1 {} Hz, pclk2 {} Hz",
            rcc.clocks.sysclk().raw(),
            rcc.clocks.pclk1().raw(),
            rcc.clocks.pclk2().raw()
        );
        let gpioa = dp.GPIOA.split(&mut rcc);
        let gpioc = dp.GPIOC.split(&mut rcc);
        let pwm_pins = (gpioa.pa8, gpioa.pa9, gpioa.pa10, gpioa.pa11, gpioc.pc6);
        let thrusters = AdvancedTimers::init(dp.TIM1, dp.TIM8, pwm_pins, &mut rcc);
        let link_pins = (gpioa.pa2, gpioa.pa3);
        Stm32Board::assemble(cp, dp.USART2, link_pins, dp.IWDG, &mut rcc, thrusters)
    }
}

/// Binds the STM32 board's handlers — `USART2` ([`on_usart2_interrupt`]) and `SysTick`
/// ([`on_systick_interrupt`]) — in an image's binary. Each STM32 image invokes it once, at its
/// top level (it brings the PAC's `interrupt` attribute into scope there).
#[macro_export]
macro_rules! stm32f405_handlers {
    () => {
        use stm32f4xx_hal::pac::interrupt;

        #[interrupt]
        fn USART2() {
            $crate::stm32f405::on_usart2_interrupt();
        }

        #[cortex_m_rt::exception]
        fn SysTick() {
            $crate::stm32f405::on_systick_interrupt();
        }
    };
}

/// The body of the `SysTick` exception handler ([`stm32f405_handlers!`](crate::stm32f405_handlers)
/// binds it): nothing. The interrupt is there to wake [`Board::wait_period`]'s WFI; the
/// period is still told by COUNTFLAG, which the exception does not clear.
#[inline(always)]
pub fn on_systick_interrupt() {}

/// Halting the core in a debugger disables the thruster outputs and pauses the IWDG (module
/// docs, *Safe state*). DBG_SLEEP (a probe's connection while the core sleeps) is left to the
/// probe software, so that a board flying without a probe never runs with it set.
fn stop_in_debug(dbgmcu: &pac::DBGMCU) {
    dbgmcu.apb2_fz().modify(|_, w| {
        w.dbg_tim1_stop().set_bit();
        w.dbg_tim8_stop().set_bit()
    });
    dbgmcu.apb1_fz().modify(|_, w| w.dbg_iwdg_stop().set_bit());
}

impl<T: ThrusterOutputs> Stm32Board<T> {
    /// What every build of the board does once its clocks and thrusters are up: the link on
    /// USART2 (PA2/PA3, AF7) with its interrupt, the cycle counter for `now()`, and last the
    /// period timer and the watchdog.
    fn assemble(
        cp: cortex_m::Peripherals,
        usart2: pac::USART2,
        pins: (PA2, PA3),
        iwdg: pac::IWDG,
        rcc: &mut Rcc,
        thrusters: T,
    ) -> Self {
        let mut cp = cp;
        let serial: Serial<pac::USART2, u8> = Serial::new(
            usart2,
            pins,
            SerialConfig::default()
                .baudrate(LINK_BAUD.bps())
                .wordlength_8()
                .parity_none()
                .stopbits(StopBits::STOP1),
            rcc,
        )
        .expect("USART2 460800 8N1 from PCLK1");
        let link = Usart2Link::new(serial);

        // Cycle counter for `now()`.
        cp.DCB.enable_trace();
        cp.DWT.enable_cycle_counter();

        let mut board = Stm32Board {
            thrusters,
            link,
            syst: cp.SYST,
            iwdg,
            rate_hz: DEFAULT_RATE_HZ,
            _dwt: cp.DWT,
        };

        // Watchdog last: once started it cannot be stopped. Starting also starts the LSI.
        board.iwdg.kr().write(|w| w.key().start());
        board.set_rate(DEFAULT_RATE_HZ);
        defmt::info!(
            "stm32f405: PWM {} Hz ({} counts), link {} baud, rate {} Hz, watchdog {} ms",
            PWM_HZ,
            board.thrusters.channels()[0].max_duty_cycle(),
            LINK_BAUD,
            board.rate_hz,
            watchdog_timeout_ms(board.rate_hz)
        );
        board
    }

    /// Sets the IWDG timeout (the counter must be running) and restarts the count with it.
    fn set_watchdog_ms(&mut self, ms: u32) {
        let reload = (ms * LSI_HZ / IWDG_DIV / 1000).clamp(1, 0x1000) - 1;
        // PR/RLR can be written only when no earlier update is in flight (a few LSI cycles).
        while self.iwdg.sr().read().bits() != 0 {}
        self.iwdg.kr().write(|w| w.key().unlock());
        self.iwdg.pr().write(|w| w.pr().divide_by32());
        self.iwdg.rlr().write(|w| w.rl().set(reload as u16));
        // Wait until the new values reached the LSI domain, so that the reload below uses them.
        while self.iwdg.sr().read().bits() != 0 {}
        self.iwdg.kr().write(|w| w.key().feed());
    }
}

impl<T: ThrusterOutputs> Board for Stm32Board<T> {
    type Thruster = T::Channel;
    type Link = Usart2Link;

    fn supply_voltage(&self) -> f32 {
        SUPPLY_VOLTAGE
    }

    fn thrusters(&mut self) -> &mut [T::Channel; THRUSTERS] {
        self.thrusters.channels()
    }

    fn link(&mut self) -> &mut Usart2Link {
        &mut self.link
    }

    /// SysTick period 1/`hz` (`hz` = 0 is taken as 1). Also sets the watchdog to four periods
    /// (at least 50 ms) and restarts the period count: the next `wait_period` waits a full
    /// period and reports no overrun.
    fn set_rate(&mut self, hz: u32) {
        let hz = hz.max(1);
        // SysTick's reload is 24 bits: at 168 MHz that is ≥ 10.02 Hz; below, use HCLK/8.
        let (source, clock) = if SYSCLK_HZ / hz <= 1 << 24 {
            (SystClkSource::Core, SYSCLK_HZ)
        } else {
            (SystClkSource::External, SYSCLK_HZ / 8)
        };
        let reload = (clock / hz).clamp(2, 1 << 24) - 1;
        self.syst.disable_counter();
        self.syst.set_clock_source(source);
        self.syst.set_reload(reload);
        // Writing the current value clears it and COUNTFLAG.
        self.syst.clear_current();
        // The interrupt only wakes `wait_period`'s WFI; the image binds an empty handler.
        self.syst.enable_interrupt();
        self.syst.enable_counter();
        self.rate_hz = hz;
        self.set_watchdog_ms(watchdog_timeout_ms(hz));
    }

    fn period_elapsed(&mut self) -> bool {
        // COUNTFLAG is set at each wrap and cleared by reading it.
        self.syst.has_wrapped()
    }

    /// Sleeps (WFI) between interrupts until the boundary: SysTick's interrupt (an empty
    /// handler, [`on_systick_interrupt`]) wakes the core at the boundary, a USART2 byte in
    /// between. The flag is tested with interrupts masked and WFI entered still masked (a
    /// pending interrupt ends WFI either way), so a boundary that comes between the test and
    /// the WFI cannot be slept through. Interrupts are unmasked after each wake only if they
    /// were unmasked on entry (a caller's critical section stays one: the flag still ends the
    /// wait). A NOP follows the WFI: with a probe attached that sets DBGMCU's DBG_SLEEP, some
    /// STM32 parts are reported to mis-fetch the instruction after a WFI executed with
    /// interrupts masked (firmware/README.md, "Verified only on hardware").
    fn wait_period(&mut self) -> bool {
        let overrun = self.period_elapsed();
        if !overrun {
            let unmasked = cortex_m::register::primask::read().is_active();
            loop {
                cortex_m::interrupt::disable();
                let boundary = self.period_elapsed();
                if !boundary {
                    cortex_m::asm::wfi();
                    cortex_m::asm::nop();
                }
                if unmasked {
                    // SAFETY: restores the unmasked state this call found; the pending
                    // interrupt that woke the core runs here.
                    unsafe { cortex_m::interrupt::enable() };
                }
                if boundary {
                    break;
                }
            }
        }
        overrun
    }

    /// CPU cycles (DWT CYCCNT, [`SYSCLK_HZ`] per second, wrapping).
    fn now(&self) -> u32 {
        DWT::cycle_count()
    }

    fn feed_watchdog(&mut self) {
        self.iwdg.kr().write(|w| w.key().feed());
    }
}
