//! The board's status and fail-safe names, and the reason bytes on the wire. The names are what
//! the firmware logs (its defmt snapshots hold them) and what host-sim's reports and JSON say.

use auv_link::{BoardStatus, FailSafeReason, Refusal, Telemetry, ThrustUnit};
use controller_core::effectiveness::THRUSTERS;
use controller_core::Fault;

#[test]
fn status_names_are_the_logged_ones() {
    let want = [
        (BoardStatus::Disarmed, "disarmed"),
        (BoardStatus::Armed, "armed"),
        (BoardStatus::Running, "running"),
        (
            BoardStatus::FailSafe(FailSafeReason::StaleState),
            "fail-safe: stale state",
        ),
        (
            BoardStatus::FailSafe(FailSafeReason::ControllerFault),
            "fail-safe: controller fault",
        ),
        (
            BoardStatus::FailSafe(FailSafeReason::Overrun),
            "fail-safe: overrun",
        ),
    ];
    for (status, name) in want {
        assert_eq!(status.as_str(), name);
        assert_eq!(status.to_string(), name);
    }
    // Every reason is named, and its status name is "fail-safe: " + the reason's.
    for r in FailSafeReason::ALL {
        assert!(!r.as_str().is_empty());
        assert_eq!(r.to_string(), r.as_str());
        assert_eq!(
            BoardStatus::FailSafe(r).as_str(),
            format!("fail-safe: {}", r.as_str())
        );
    }
    assert_eq!(FailSafeReason::StaleState.as_str(), "stale state");
}

#[test]
fn a_reasons_discriminant_is_its_byte_on_the_wire() {
    for (i, r) in FailSafeReason::ALL.into_iter().enumerate() {
        let mut buf = [0u8; FailSafeReason::MAX_SIZE];
        let bytes = postcard::to_slice(&r, &mut buf).unwrap();
        assert_eq!(bytes, &[r as u8]);
        // ALL is in wire order, without gaps.
        assert_eq!(r as u8 as usize, i);
    }
}

#[test]
fn telemetry_fault_code_is_the_cores() {
    let mut t = Telemetry {
        tick: 0,
        status: BoardStatus::FailSafe(FailSafeReason::ControllerFault),
        voltages: [0.0; THRUSTERS],
        thrusts: [0.0; THRUSTERS],
        tau: [0.0; 6],
        saturated: 0,
        delta: 0.0,
        delta_clamped: false,
        w_norm: 0.0,
        controller_fault: 0,
        loop_overruns: 0,
        worst_update_ticks: 0,
        rx_frames: 0,
        rx_errors: 0,
        last_state_seq: 0,
        latched: Some(FailSafeReason::ControllerFault),
        refused_commands: 0,
        last_refusal: None,
        rx_stale: 0,
        rx_auth_errors: 0,
        last_rx_seq: 0,
        signing: false,
        thrust_unit: ThrustUnit::Kgf,
        reversed_thrusters: 0,
        rx_ahead: 0,
        upload: auv_link::UploadStatus::NONE,
        config_digest: 0,
    };
    assert_eq!(t.fault(), None);
    for f in Fault::ALL {
        t.controller_fault = f.code();
        assert_eq!(t.fault(), Some(f));
    }
    t.controller_fault = 200;
    assert_eq!(t.fault(), None);
}

#[test]
fn refusal_names_are_unique_comma_free_and_their_bytes_are_the_wire() {
    for (i, r) in Refusal::ALL.into_iter().enumerate() {
        let mut buf = [0u8; Refusal::MAX_SIZE];
        assert_eq!(postcard::to_slice(&r, &mut buf).unwrap(), &[r as u8]);
        assert_eq!(r as u8 as usize, i, "ALL is in wire order");
        assert_eq!(r.to_string(), r.as_str());
        assert!(!r.as_str().is_empty() && !r.as_str().contains(','));
        assert_eq!(Refusal::from_name(r.as_str()), Some(r));
        for other in Refusal::ALL {
            assert!(other == r || other.as_str() != r.as_str());
        }
    }
    assert_eq!(Refusal::from_name("no such reason"), None);
    assert_eq!(Refusal::Latched.as_str(), "fail-safe latched");
}
