//! Fault and status names, and the fault codes the board puts on the link. The names are the
//! simulator's CSV `status` column; the codes are protocol (never renumbered).

use controller_core::{Fault, Status};

#[test]
fn fault_codes_are_fixed_and_round_trip() {
    let want = [
        (Fault::NonFiniteInput, 1u8, "non-finite-input"),
        (Fault::InputOutOfRange, 2, "input-out-of-range"),
        (Fault::PitchLimit, 3, "pitch-limit"),
        (Fault::NonFiniteResult, 4, "non-finite-result"),
    ];
    assert_eq!(Fault::ALL.len(), want.len());
    for ((fault, code, name), listed) in want.into_iter().zip(Fault::ALL) {
        assert_eq!(listed, fault);
        assert_eq!(fault.code(), code);
        assert_eq!(Fault::from_code(code), Some(fault));
        assert_eq!(fault.as_str(), name);
        assert_eq!(fault.to_string(), name);
        let status = Status::Fault(fault);
        assert_eq!(status.as_str(), format!("fault:{name}"));
        assert_eq!(status.to_string(), status.as_str());
    }
    // 0 is "no fault" on the link; unknown codes are no fault the core knows.
    assert_eq!(Fault::from_code(0), None);
    assert_eq!(Fault::from_code(5), None);
    assert_eq!(Fault::from_code(u8::MAX), None);
    assert_eq!(Status::Ok.as_str(), "ok");
    assert_eq!(Status::Ok.to_string(), "ok");
}
