//! What the images that run under QEMU take from semihosting (target only, for the `qemu`
//! board and the STM32F405 `stm32f405-emulator` build): how they end (QEMU exits with the
//! image's code) and their boot configuration (the semihosting command line, QEMU's
//! `-append "…"`; the flying images take their link key from it).

/// Ends the program: QEMU exits with `code` (0 = success) through semihosting. Without a
/// semihosting host (a real board), the core resets instead.
pub fn halt(code: i32) -> ! {
    let status = if code == 0 {
        cortex_m_semihosting::debug::EXIT_SUCCESS
    } else {
        cortex_m_semihosting::debug::EXIT_FAILURE
    };
    cortex_m_semihosting::debug::exit(status);
    cortex_m::peripheral::SCB::sys_reset()
}

/// Room for the semihosting command line: QEMU passes the ELF's path, then `-append`'s text.
pub const CMDLINE_LEN: usize = 512;

/// The semihosting command line (`qemu-run.sh ELF -append "…"`), into `buf`; `None` if QEMU
/// refused it (it does when the line does not fit).
pub fn command_line(buf: &mut [u8; CMDLINE_LEN]) -> Option<&[u8]> {
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: SYS_GET_CMDLINE writes at most `block[1]` bytes into `buf` and the length back
    // into `block[1]`.
    let r = unsafe {
        cortex_m_semihosting::syscall1(
            cortex_m_semihosting::nr::GET_CMDLINE,
            block.as_mut_ptr() as usize,
        )
    };
    if r != 0 {
        return None;
    }
    let n = block[1].min(buf.len());
    Some(&buf[..n])
}

/// The word of the command line that provisions the link key: `link-key=` and 64 hex digits.
pub const LINK_KEY_ARG: &str = "link-key=";

/// Why the command line's key was not taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum KeyArgError {
    /// The command line could not be read (longer than [`CMDLINE_LEN`]?).
    Unreadable,
    /// `link-key=` is followed by something that is not a key.
    Malformed(auv_link::sign::KeyError),
}

/// The QEMU image's link key: `link-key=<64 hex digits>` on the semihosting command line
/// (`host-sim pil --link-key-file` passes it), the QEMU analogue of a key in the board's flash
/// configuration; it never crosses the link. `Ok(None)`: no key given, signing off.
pub fn link_key() -> Result<Option<auv_link::sign::LinkKey>, KeyArgError> {
    let mut buf = [0u8; CMDLINE_LEN];
    let cmd = command_line(&mut buf).ok_or(KeyArgError::Unreadable)?;
    let Some(word) = cmd
        .split(|&b| b == b' ')
        .find_map(|w| w.strip_prefix(LINK_KEY_ARG.as_bytes()))
    else {
        return Ok(None);
    };
    let text = core::str::from_utf8(word)
        .map_err(|_| KeyArgError::Malformed(auv_link::sign::KeyError::NotHex { at: 0 }))?;
    auv_link::sign::LinkKey::from_hex(text)
        .map(Some)
        .map_err(KeyArgError::Malformed)
}

/// The flying image's link key from the command line ([`link_key`]), or — if the command line
/// cannot be read or its key is malformed — a log line that says so and [`halt`]`(1)`: a board
/// that was meant to sign never flies unsigned.
pub fn link_key_or_halt() -> Option<auv_link::sign::LinkKey> {
    match link_key() {
        Ok(key) => key,
        Err(KeyArgError::Unreadable) => {
            defmt::error!("semihosting command line unreadable: no link key, not flying");
            halt(1)
        }
        Err(KeyArgError::Malformed(_)) => {
            defmt::error!(
                "{=str} is not followed by 64 hexadecimal digits: not flying",
                LINK_KEY_ARG
            );
            halt(1)
        }
    }
}
