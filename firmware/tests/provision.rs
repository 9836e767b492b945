//! The STM32 image's key provisioning (`src/provision.rs`, run by `build.rs`): signed by
//! default, a build without a key fails with a message that says how to set one or opt out.

#[path = "../src/provision.rs"]
mod provision;

use auv_link::sign::LinkKey;
use provision::{link_key, CI_TEST_KEY, KEY_VAR, UNSIGNED_VAR};

const HEX: &str = "00112233445566778899aabbccddeeff00112233445566778899AABBCCDDEEFF";

fn ci_key() -> LinkKey {
    let text = std::fs::read_to_string(format!("{}/../{CI_TEST_KEY}", env!("CARGO_MANIFEST_DIR")))
        .unwrap();
    LinkKey::from_key_file(&text).unwrap()
}

fn is_error(code: &str) -> bool {
    code.starts_with("compile_error!(")
}

#[test]
fn without_a_key_the_build_fails_and_says_how_to_set_one_or_opt_out() {
    let (code, warning) = link_key(None, None, Some(&ci_key()));
    assert!(is_error(&code), "{code}");
    assert!(code.contains(KEY_VAR) && code.contains(&format!("{UNSIGNED_VAR}=1")));
    assert!(code.contains("openssl rand -hex 32") && code.contains("firmware/README.md"));
    assert_eq!(warning, None);
}

#[test]
fn a_key_is_compiled_in_and_its_bytes_are_the_keys() {
    let (code, warning) = link_key(Some(HEX), None, Some(&ci_key()));
    assert!(!is_error(&code), "{code}");
    let bytes = LinkKey::from_hex(HEX).unwrap();
    assert!(
        code.contains(&format!("Some({:?})", bytes.bytes())),
        "{code}"
    );
    assert!(code.contains("LINK_KEY_IS_CI_TEST_KEY: bool = false"));
    assert!(!code.contains(HEX), "the hex text itself is not needed");
    assert_eq!(warning, None);
}

#[test]
fn the_ci_test_key_builds_with_a_warning_in_the_log_and_the_image() {
    let ci = ci_key();
    let hex: String = ci.bytes().iter().map(|b| format!("{b:02x}")).collect();
    let (code, warning) = link_key(Some(&hex), None, Some(&ci));
    assert!(code.contains("LINK_KEY_IS_CI_TEST_KEY: bool = true"));
    assert!(warning.unwrap().contains("PUBLIC CI test key"));
}

#[test]
fn opting_out_is_explicit_and_loud() {
    let (code, warning) = link_key(None, Some("1"), None);
    assert!(code.contains("LINK_KEY: Option<[u8; 32]> = None"), "{code}");
    assert!(warning.unwrap().contains("UNSIGNED"));
    // Anything but 1 is not an opt-out; both at once is a mistake.
    assert!(is_error(&link_key(None, Some("yes"), None).0));
    assert!(is_error(&link_key(Some(HEX), Some("1"), None).0));
}

#[test]
fn a_malformed_key_fails_with_the_reason_and_without_echoing_it() {
    let short = &HEX[..40];
    let (code, _) = link_key(Some(short), None, None);
    assert!(
        is_error(&code) && code.contains("got 40 characters"),
        "{code}"
    );
    assert!(!code.contains(short));
    let (code, _) = link_key(Some(&HEX.replace('a', "x")), None, None);
    assert!(is_error(&code) && code.contains("not"), "{code}");
}
