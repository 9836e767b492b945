//! The STM32 image's link key, from the build's environment: what `build.rs` writes into
//! `link_key.rs` (which only that image includes). Not a module of the library: `build.rs`
//! and `tests/provision.rs` include this file (`#[path]`), so the messages are tested on the
//! host.

use auv_link::sign::LinkKey;

pub use firmware_images::{LINK_KEY_VAR as KEY_VAR, LINK_UNSIGNED_VAR as UNSIGNED_VAR};
/// The public test key CI builds with (workspace-relative).
pub const CI_TEST_KEY: &str = "firmware/ci-test-link-key.hex";

/// `link_key.rs`, which only the STM32 image includes: `LINK_KEY` and `LINK_KEY_IS_CI_TEST_KEY`,
/// or a `compile_error!` that says how to provision a key or opt out. Also a warning for the
/// build log when the image is unsigned or carries the public test key.
pub fn link_key(
    key: Option<&str>,
    unsigned: Option<&str>,
    ci_key: Option<&LinkKey>,
) -> (String, Option<String>) {
    let how = format!(
        "set {KEY_VAR} to the team's key, 64 hexadecimal digits (make one with `openssl rand -hex 32`; \
         firmware/README.md, \"Link key\"), e.g. {KEY_VAR}=$(grep -v '^#' ~/.config/auv150/link.key), \
         or build an unsigned image explicitly with {UNSIGNED_VAR}=1"
    );
    let error = |msg: String| (format!("compile_error!({msg:?});\n"), None);
    match (key, unsigned) {
        (Some(_), Some(_)) => error(format!(
            "firmware-stm32f405: both {KEY_VAR} and {UNSIGNED_VAR} are set; set one"
        )),
        (None, Some("1")) => (
            "/// Built with AUV150_LINK_UNSIGNED=1: signing off.\n\
             pub const LINK_KEY: Option<[u8; 32]> = None;\n\
             pub const LINK_KEY_IS_CI_TEST_KEY: bool = false;\n"
                .into(),
            Some(format!(
                "firmware-stm32f405 is built UNSIGNED ({UNSIGNED_VAR}=1): any peer that computes the CRC can command it"
            )),
        ),
        (None, Some(other)) => error(format!(
            "firmware-stm32f405: {UNSIGNED_VAR} must be 1 to opt out of signing, got {other:?}; or {how}"
        )),
        (None, None) => error(format!(
            "firmware-stm32f405 signs its link and no key was given: {how}"
        )),
        (Some(hex), None) => match LinkKey::from_hex(hex) {
            Err(e) => error(format!("firmware-stm32f405: {KEY_VAR}: {e}; {how}")),
            Ok(k) => {
                let test = ci_key == Some(&k);
                let code = format!(
                    "/// From AUV150_LINK_KEY at build time (fingerprint {:08x}).\n\
                     pub const LINK_KEY: Option<[u8; 32]> = Some({:?});\n\
                     pub const LINK_KEY_IS_CI_TEST_KEY: bool = {test};\n",
                    k.fingerprint(),
                    k.bytes()
                );
                let warning = test.then(|| {
                    format!(
                        "firmware-stm32f405 carries the PUBLIC CI test key ({CI_TEST_KEY}): do not fly this ELF"
                    )
                });
                (code, warning)
            }
        },
    }
}
