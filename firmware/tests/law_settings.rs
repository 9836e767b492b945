//! Protocol 8 on the board (Choice 508): `SetConfig` carries the law's settings (K₁, K₂, Q, β,
//! μ, the robust law, the ‖b‖ bound, the pitch limit). The board validates them with the
//! core's own checks in its disarmed rebuild and flies what the host's core flies on the same
//! settings, bit for bit; whatever the core refuses (Assumption 2's β̂ ≤ β, the loop-rate rule,
//! a gain that is not finite and > 0) the board refuses too, whole, and changes nothing.

mod common;

use auv_link::{Command, ConfigPatch, LawSettings, Msg, Refusal, StateFrame};
use common::{state, supervisor, Host, CIRCLE, NOW};
use controller_core::effectiveness::THRUSTERS;
use controller_core::{ConfigError, Controller, ControllerConfig, Mission, Trajectory};
use firmware::board::LinkBuffers;
use firmware::supervisor::Supervisor;

/// The law a team tuned: μ = 0.15 (the real-circle campaign's better layer, Choice 507's
/// figures) and changed gains on surge (K₁) and yaw (K₂).
fn tuned() -> ControllerConfig {
    let mut c = ControllerConfig {
        mu: 0.15,
        ..ControllerConfig::default()
    };
    c.k1[0] = 5.0;
    c.k2[5] = 3.0;
    c
}

/// A state frame a few millimetres and milliradians off the circle at tick `k`: inside the
/// boundary layer (‖w‖ < μ), where μ and the gains decide Δu.
fn off_path(k: u64) -> StateFrame {
    let mut s = state(k);
    for i in 0..6 {
        let phase = 0.31 * k as f32 * (i as f32 + 1.0) + i as f32;
        let scale = if i < 3 { 0.004 } else { 0.001 };
        s.eta[i] += scale * libm::sinf(phase);
        s.nu[i] += 0.5 * scale * libm::cosf(phase);
    }
    s
}

/// What the board commands over 30 periods of the circle on [`off_path`] after `patch` (sent
/// through its end of the link, as a navigation computer sends it), and the refusals it made.
fn fly(patch: Option<ConfigPatch>) -> (Vec<[u32; THRUSTERS]>, Option<Refusal>) {
    let mut s = supervisor();
    let mut link = LinkBuffers::new();
    let mut h = Host::new();
    if let Some(p) = patch {
        h.send(&mut s, &mut link, Msg::Command(Command::SetConfig(p)));
        // The rebuild is its period's long job (Choice 226).
        s.step(false, NOW);
    }
    let refusal = s.last_refusal();
    h.send(&mut s, &mut link, Msg::Command(Command::Arm));
    h.send(
        &mut s,
        &mut link,
        Msg::Command(Command::StartMission(CIRCLE)),
    );
    let volts = (0..30u64)
        .map(|k| {
            h.send(&mut s, &mut link, Msg::State(off_path(k)));
            s.step(false, NOW).telemetry.voltages.map(f32::to_bits)
        })
        .collect();
    (volts, refusal)
}

/// The host's core on the same frames: what SIL's law commands.
fn host(cfg: ControllerConfig) -> Vec<[u32; THRUSTERS]> {
    let c = Controller::new(cfg).expect("a configuration the core takes");
    let tr = Trajectory::new(Mission::try_from(CIRCLE).expect("a closed form")).unwrap();
    (0..30u64)
        .map(|k| {
            let f = off_path(k);
            c.update(k, &f.eta, &f.nu, &tr).voltage.map(f32::to_bits)
        })
        .collect()
}

/// The board flies the law it is sent, bit for bit as the host's core: before protocol 8 the
/// patch had no law and the board flew its built-in μ = 0.1 and paper gains (`host(tuned())`
/// differs from the defaults' commands, so that board could not match).
#[test]
fn the_board_flies_the_law_it_is_sent_as_the_host_does() {
    let cfg = tuned();
    let whole = ConfigPatch::whole(&cfg, 2, false);
    let (got, refusal) = fly(Some(whole));
    assert_eq!(refusal, None);
    assert_eq!(got, host(cfg));
    // The law matters on these frames: the defaults command other voltages.
    let (defaults, _) = fly(None);
    assert_eq!(defaults, host(ControllerConfig::default()));
    assert_ne!(got, defaults);
    // Only the law's part of the patch does the same.
    let law_only = ConfigPatch {
        law: Some(LawSettings::of(&cfg)),
        ..ConfigPatch::EMPTY
    };
    assert_eq!(fly(Some(law_only)).0, got);
}

/// The board's configuration and digest after a law patch are those of the settings sent.
#[test]
fn the_board_reports_the_law_it_took_in_its_digest() {
    let mut s = supervisor();
    let mut h = Host::new();
    let whole = ConfigPatch::whole(&tuned(), 2, false);
    h.command(&mut s, Command::SetConfig(whole));
    assert_eq!(s.last_refusal(), None);
    assert_eq!(LawSettings::of(s.controller().config()), whole.law.unwrap());
    assert_eq!(s.config_digest(), whole.digest().unwrap());
    assert_ne!(
        s.config_digest(),
        ConfigPatch::whole(&ControllerConfig::default(), 2, false)
            .digest()
            .unwrap()
    );
}

/// Law settings the core refuses, each with the check that refuses it on the host.
fn refused_laws() -> Vec<(&'static str, ControllerConfig)> {
    let d = ControllerConfig::default();
    let mut roll = d;
    roll.k1[3] = 1.0;
    let mut nan_gain = d;
    nan_gain.k2[2] = f32::NAN;
    vec![
        // Assumption 2 (Eq 20): β̂ of Table 3's box (0.0667) is above β.
        ("beta below beta_hat", ControllerConfig { beta: 0.05, ..d }),
        // The loop-rate rule at 100 Hz: δ_max/μ = 25 000 per unit of w.
        ("loop rate", ControllerConfig { mu: 0.001, ..d }),
        ("beta outside (0, 1)", ControllerConfig { beta: 1.5, ..d }),
        ("mu not positive", ControllerConfig { mu: 0.0, ..d }),
        (
            "pitch limit at 90°",
            ControllerConfig {
                pitch_limit: core::f32::consts::FRAC_PI_2,
                ..d
            },
        ),
        ("roll gain", roll),
        ("gain not finite", nan_gain),
        (
            "q not positive",
            ControllerConfig {
                q: [1.0, -1.0],
                ..d
            },
        ),
    ]
}

/// A law the host would refuse, sent over the link, is refused whole with `controller config
/// invalid` and changes nothing: the board flies on as before, digest and all.
#[test]
fn a_law_the_core_refuses_is_refused_over_the_link_and_changes_nothing() {
    for (what, cfg) in refused_laws() {
        let err = Controller::new(cfg).err();
        assert!(err.is_some(), "{what}: the host takes it");
        if what == "beta below beta_hat" {
            assert!(
                matches!(err, Some(ConfigError::Assumption2 { .. })),
                "{err:?}"
            );
        }
        if what == "loop rate" {
            assert!(matches!(err, Some(ConfigError::LoopRate { .. })), "{err:?}");
        }
        let mut s: Supervisor = supervisor();
        let mut link = LinkBuffers::new();
        let mut h = Host::new();
        let before = (*s.controller().config(), s.config_digest());
        // Whole (with a rate change the board would otherwise take), and the law alone.
        for patch in [
            ConfigPatch {
                rate_hz: Some(50),
                ..ConfigPatch::whole(&cfg, 2, false)
            },
            ConfigPatch {
                law: Some(LawSettings::of(&cfg)),
                ..ConfigPatch::EMPTY
            },
        ] {
            let refused = s.refused_commands();
            h.send(&mut s, &mut link, Msg::Command(Command::SetConfig(patch)));
            assert_eq!(s.refused_commands(), refused + 1, "{what}");
            assert_eq!(s.last_refusal(), Some(Refusal::ControllerConfig), "{what}");
            // Nothing changed (compared by Debug: a NaN setting would fail `==` on its own).
            assert_eq!(
                format!("{:?}", s.controller().config()),
                format!("{:?}", before.0)
            );
            assert_eq!(s.config_digest(), before.1, "{what}");
        }
    }
}

/// The board takes a law exactly when the host's core does: a sweep of μ and β across their
/// checks (the loop-rate rule's edge at 100 Hz and Assumption 2's β̂ = 0.0667 of Table 3's
/// box), each sent alone.
#[test]
fn the_board_takes_a_law_exactly_when_the_host_does() {
    let mut taken = 0;
    let mut refused = 0;
    // μ's edge at 100 Hz: T·(k₂ + p₂₂ δ_max/μ) < 2 with p₂₂ = 5/32, δ_max = 25: μ > 0.01993.
    for mu in [
        0.0005f32, 0.0199, 0.01993, 0.01994, 0.02, 0.1, 0.15, 1.0, 10.0,
    ] {
        for beta in [0.01f32, 0.05, 0.066, 0.067, 0.07, 0.605, 0.99] {
            let cfg = ControllerConfig {
                mu,
                beta,
                ..ControllerConfig::default()
            };
            let host_takes = Controller::new(cfg).is_ok();
            let mut s = supervisor();
            let mut h = Host::new();
            h.command(
                &mut s,
                Command::SetConfig(ConfigPatch {
                    law: Some(LawSettings::of(&cfg)),
                    ..ConfigPatch::EMPTY
                }),
            );
            let board_takes = s.last_refusal().is_none();
            assert_eq!(board_takes, host_takes, "μ {mu}, β {beta}");
            if host_takes {
                taken += 1;
            } else {
                refused += 1;
            }
        }
    }
    // Both sides of both checks are in the sweep.
    assert!(taken > 0 && refused > 0, "{taken} taken, {refused} refused");
}

/// Like the rest of the configuration, the law is refused while armed (`while armed`).
#[test]
fn the_law_is_refused_while_armed() {
    let mut s = supervisor();
    let mut h = Host::new();
    h.command(&mut s, Command::Arm);
    let before = s.config_digest();
    h.command(
        &mut s,
        Command::SetConfig(ConfigPatch {
            law: Some(LawSettings::of(&tuned())),
            ..ConfigPatch::EMPTY
        }),
    );
    assert_eq!(s.last_refusal(), Some(Refusal::WhileArmed));
    assert_eq!(s.config_digest(), before);
    assert_eq!(s.controller().config().mu, ControllerConfig::default().mu);
}
