//! A second build of host-sim does nothing (issue 18): `cargo build --release -p host-sim`
//! twice in a row, and the second must find every unit fresh — no compile, no build script
//! run, no link. Every README command and every script that flies missions starts with that
//! build (`cargo run --release -p host-sim …`); with fat LTO a stale unit anywhere below
//! host-sim costs a whole-program link (1 m 35 s on two cores when firmware/build.rs watched a
//! file that does not exist).
//!
//! Between the two builds the link key's environment ([`KEY_VAR`]) changes: host-sim does not
//! depend on the firmware package and its key-provisioning build script, so a developer who
//! sources `scripts/ci-link-key.sh` in one shell and not in another does not rebuild it.
//!
//! The second build runs with `--message-format=json` (a `compiler-artifact` message with
//! `"fresh": false` is a unit that was rebuilt) and cargo's fingerprint log, whose `dirty:` and
//! `stale:` lines say why.

use std::process::Stdio;
use std::time::Instant;

use xtask::ci::Ci;

// The variable the firmware's build script reads (`cargo:rerun-if-env-changed`).
#[allow(dead_code)]
use firmware::LINK_KEY_VAR as KEY_VAR;

/// The cargo profile the README's commands build host-sim with.
pub const README_PROFILE: &str = "release";

/// A link key for the second build only (64 hexadecimal digits; never flown).
const OTHER_KEY: &str = "0f1e2d3c4b5a69788796a5b4c3d2e1f00f1e2d3c4b5a69788796a5b4c3d2e1f0";

/// Builds host-sim with `profile` twice; fails if the second build rebuilt anything.
pub fn run(ci: &mut Ci, profile: &str) {
    ci.step(&format!(
        "a second `cargo build --profile {profile} -p host-sim` is a no-op"
    ));
    let args = ["build", "--profile", profile, "-p", "host-sim"];
    let start = Instant::now();
    match ci.cargo().args(args).status() {
        Ok(s) if s.success() => {}
        Ok(s) => return ci.fail(format!("cargo {} exited {s}", args.join(" "))),
        Err(e) => return ci.fail(format!("running cargo {}: {e}", args.join(" "))),
    }
    println!("first build: {:.1} s", start.elapsed().as_secs_f64());

    let start = Instant::now();
    let out = ci
        .cargo()
        .args(args)
        .arg("--message-format=json")
        .env("CARGO_LOG", "cargo::core::compiler::fingerprint=info")
        .env(KEY_VAR, OTHER_KEY)
        .stdin(Stdio::null())
        .output();
    let out = match out {
        Ok(o) => o,
        Err(e) => return ci.fail(format!("running cargo {}: {e}", args.join(" "))),
    };
    let seconds = start.elapsed().as_secs_f64();
    if !out.status.success() {
        return ci.fail(format!(
            "the second cargo {} exited {}",
            args.join(" "),
            out.status
        ));
    }
    let rebuilt = rebuilt_units(&String::from_utf8_lossy(&out.stdout));
    let log = String::from_utf8_lossy(&out.stderr);
    let reasons = dirty_reasons(&log);
    if rebuilt.is_empty() && reasons.is_empty() {
        println!("second build: {seconds:.1} s, every unit fresh");
        return;
    }
    ci.fail(format!(
        "the second `cargo {}` ({KEY_VAR} changed) was not a no-op ({seconds:.1} s): rebuilt {}; \
         cargo's fingerprint log says:\n{}\n(a `rerun-if-changed` path that does not exist keeps a \
         build script stale forever; host-sim must not depend on the firmware package's build script)",
        args.join(" "),
        if rebuilt.is_empty() { "nothing, but".into() } else { rebuilt.join(", ") },
        reasons.join("\n")
    ));
}

/// The units a `--message-format=json` build compiled rather than found fresh, as
/// `package target` (one `compiler-artifact` message each).
pub fn rebuilt_units(json_lines: &str) -> Vec<String> {
    json_lines
        .lines()
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|m| m["reason"] == "compiler-artifact" && m["fresh"] == false)
        .map(|m| {
            format!(
                "{} {}",
                m["package_id"].as_str().unwrap_or("?"),
                m["target"]["name"].as_str().unwrap_or("?")
            )
        })
        .collect()
}

/// The lines of cargo's fingerprint log (`CARGO_LOG=cargo::core::compiler::fingerprint=info`)
/// that say a unit is dirty or stale, and why.
pub fn dirty_reasons(log: &str) -> Vec<String> {
    log.lines()
        .filter(|l| l.contains("dirty:") || l.contains("stale:"))
        .map(|l| {
            // Keep the message, not the span's timestamps and fields.
            l.find("fingerprint: ")
                .map_or(l, |i| &l[i + "fingerprint: ".len()..])
                .trim()
                .to_string()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fresh_artifact_is_not_a_rebuild_and_a_stale_one_is() {
        let json = r#"{"reason":"compiler-artifact","package_id":"path+file:///w/host-sim#0.1.0","target":{"name":"host_sim"},"fresh":true}
{"reason":"build-script-executed","package_id":"path+file:///w/firmware#0.1.0"}
{"reason":"compiler-artifact","package_id":"path+file:///w/firmware#0.1.0","target":{"name":"firmware"},"fresh":false}
   Compiling firmware v0.1.0
{"reason":"build-finished","success":true}"#;
        assert_eq!(
            rebuilt_units(json),
            ["path+file:///w/firmware#0.1.0 firmware"]
        );
    }

    #[test]
    fn the_fingerprint_log_names_why() {
        // Two lines of cargo 1.9x's log for the defect this check was written for.
        let log = r#"   0.2s  INFO prepare_target{force=false package_id=firmware v0.1.0 (/w/firmware) target="build-script-build"}: cargo::core::compiler::fingerprint: fingerprint dirty for firmware v0.1.0
   0.2s  INFO prepare_target{force=false package_id=firmware v0.1.0 (/w/firmware) target="build-script-build"}: cargo::core::compiler::fingerprint:     dirty: FsStatusOutdated(StaleItem(MissingFile { path: "/w/firmware/firmware/ci-test-link-key.hex" }))
   0.3s  INFO cargo::core::compiler::fingerprint: fresh unit"#;
        assert_eq!(
            dirty_reasons(log),
            [
                r#"dirty: FsStatusOutdated(StaleItem(MissingFile { path: "/w/firmware/firmware/ci-test-link-key.hex" }))"#
            ]
        );
    }
}
