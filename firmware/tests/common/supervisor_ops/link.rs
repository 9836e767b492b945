//! The navigation computer's end of the link and its checks: frames built and signed (as
//! expected, the other way, forged, reflected, or by a restarted key holder), replays and
//! raw bytes, and what may pass the board's link to the supervisor.

use super::*;

/// How a frame the harness built was authenticated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Auth {
    /// No signature.
    Unsigned,
    /// Signed with the key, for the board, with this timestamp.
    Good(u64),
    /// Signed, but not in a way the board may accept (wrong key or direction).
    Forged,
}

/// A frame the harness built: its envelope and how it was signed.
pub(super) type Known = Option<(Envelope, Auth)>;

impl Harness {
    pub(super) fn counters(&self) -> (u32, u32, u32, u32, u32, u32) {
        (
            self.sup.rx_frames(),
            self.sup.rx_stale(),
            self.sup.rx_errors(),
            self.sup.refused_commands(),
            self.sup.rx_auth_errors(),
            self.sup.rx_ahead(),
        )
    }

    /// A key holder's timestamp from 8 input bytes: the low 2 bits pick anywhere in 48 bits,
    /// around the lead past the harness's last stamp, around the ceiling, or at or below it.
    pub(super) fn restarted_stamp(&self, raw: u64) -> u64 {
        let last = self.signer.timestamp();
        let r = raw >> 16;
        match raw & 3 {
            0 => r,
            1 => last + MAX_LEAD - (1 << 20) + r % (1 << 21),
            2 => CEILING - 8 + r % 16,
            _ => r % (last + 1),
        }
    }

    /// Builds the frame for `(seq, msg)`, signed as `how` says, sends it and checks what the
    /// supervisor did with it.
    pub(super) fn send(&mut self, seq: u16, msg: Msg, how: u8, input: &mut Bytes) {
        let env = Envelope::new(seq, msg);
        let mut out = [0u8; MAX_FRAME];
        let signed = match how % 5 {
            SIGN_AS_EXPECTED => self.signing,
            SIGN_OTHER_WAY => !self.signing,
            _ => true,
        };
        let (n, auth) = if !signed {
            (encode(&env, &mut out), Auth::Unsigned)
        } else {
            match how % 5 {
                SIGN_WRONG_KEY => (
                    encode_signed(&env, &mut self.forger, &mut out),
                    Auth::Forged,
                ),
                SIGN_WRONG_DIRECTION => (
                    encode_signed(&env, &mut self.reflector, &mut out),
                    Auth::Forged,
                ),
                SIGN_RESTARTED => {
                    let mut restarted = Signer::new(&KEY, Direction::ToBoard);
                    restarted.advance_to(self.restarted_stamp(input.u64()));
                    let n = encode_signed(&env, &mut restarted, &mut out);
                    (n, Auth::Good(restarted.timestamp()))
                }
                _ => {
                    let n = encode_signed(&env, &mut self.signer, &mut out);
                    (n, Auth::Good(self.signer.timestamp()))
                }
            }
        };
        // Only a restarted signer at the last timestamp can fail to sign.
        let Ok(n) = n else { return };
        let frame = out[..n].to_vec();
        self.deliver(&frame, Some((env, auth)));
        if let (true, SIGN_RESTARTED, Auth::Good(t)) = (signed, how % 5, auth) {
            if self.signing && self.model.last_timestamp == Some(t) {
                self.stats.restarted_taken += 1;
            }
        }
        self.remember(frame, Some((env, auth)));
    }

    pub(super) fn remember(&mut self, frame: Vec<u8>, known: Known) {
        if self.history.len() == 8 {
            self.history.remove(0);
        }
        self.history.push((frame, known));
    }

    /// Bytes the harness did not build as a frame (a corruption, raw bytes), split at the
    /// delimiters. A chunk equal to a frame sent earlier is that frame; otherwise it is what
    /// `decode_frame` says it is (signing off) or, signing on, a key holder's frame if it
    /// verifies with the key: libFuzzer learns a MAC from the comparison that checks it, so the
    /// fuzzer holds the key too (it wrote the signed `Arm` of timestamp 1 from raw bytes).
    pub(super) fn raw(&mut self, bytes: &[u8]) {
        for chunk in bytes.split_inclusive(|&b| b == 0) {
            let mut body = chunk.strip_suffix(&[0]).unwrap_or(chunk).to_vec();
            let earlier = self
                .history
                .iter()
                .find(|(f, _)| f.as_slice() == chunk)
                .and_then(|(_, k)| *k);
            let known = earlier.or_else(|| {
                if self.signing {
                    let mut v = Verifier::new(&KEY, Direction::ToBoard);
                    let env = decode_frame_signed(&mut body, &mut v).ok()?;
                    Some((env, Auth::Good(v.last_timestamp()?)))
                } else {
                    decode_frame(&mut body).ok().map(|e| (e, Auth::Unsigned))
                }
            });
            self.deliver(chunk, known);
        }
    }

    /// Feeds `frame` to the board's end of the link and checks the supervisor's reaction
    /// against the model. `known`: the envelope and how it was signed, if it is a frame.
    pub(super) fn deliver(&mut self, frame: &[u8], known: Known) {
        let before = self.counters();
        let settings_before = settings(&self.sup);
        board::receive(&mut self.sup, &mut self.link, frame);
        let after = self.counters();
        let d = |a: u32, b: u32| a.checked_sub(b).expect("counters never go down");
        let (accepted, stale, errors, refused, auth_errors, ahead) = (
            d(after.0, before.0),
            d(after.1, before.1),
            d(after.2, before.2),
            d(after.3, before.3),
            d(after.4, before.4),
            d(after.5, before.5),
        );
        let Some((env, auth)) = known else {
            assert_eq!(
                (accepted, stale, ahead),
                (0, 0, 0),
                "only a frame reaches the supervisor; only an authentic one is ahead"
            );
            assert_eq!(refused, 0);
            return;
        };
        self.stats.frames_sent += 1;
        assert_eq!(
            accepted + stale + errors,
            1,
            "a frame is counted once: {env:?}"
        );
        // A frame the harness built fails at the link only on authentication (or, signing off,
        // on a signature); an error without one is the supervisor's (telemetry to the board).
        let passed_link = accepted + stale == 1 || (errors == 1 && auth_errors == 0);
        // An authentic frame on a signed link: the timestamp rule decides, from the docs.
        let stamp = match (self.signing, auth) {
            (true, Auth::Good(t)) => {
                let m = &self.model;
                let replay = m.last_timestamp.is_some_and(|l| t <= l);
                let too_far = !replay
                    && (t > CEILING
                        || m.last_timestamp
                            .is_some_and(|l| t - l > MAX_LEAD + m.counted));
                assert_eq!(
                    ahead,
                    u32::from(too_far),
                    "stamp {t}, last {:?}, counted {}",
                    m.last_timestamp,
                    m.counted
                );
                assert_eq!(
                    passed_link,
                    !replay && !too_far,
                    "stamp {t}, last {:?}, counted {}",
                    m.last_timestamp,
                    m.counted
                );
                Some(t)
            }
            _ => {
                assert_eq!(ahead, 0, "only an authentic frame is ahead: {auth:?}");
                None
            }
        };
        self.model.ahead += ahead;
        self.stats.ahead += ahead;
        if passed_link {
            // It passed the link's checks: authentic as the board's mode requires.
            match (self.signing, stamp) {
                (false, _) => assert_eq!(auth, Auth::Unsigned, "signing off: {env:?}"),
                (true, Some(t)) => {
                    self.model.last_timestamp = Some(t);
                    self.model.counted = 0;
                    // As a navigation computer would: its next stamp goes above it.
                    self.signer.advance_to(t);
                }
                (true, None) => {
                    panic!("signing on, {auth:?} frame reached the supervisor: {env:?}")
                }
            }
        }
        if matches!(env.msg, Msg::Telemetry(_)) {
            assert_eq!(accepted + stale, 0, "telemetry to the board is an error");
        }
        if accepted == 0 {
            assert_eq!(refused, 0, "a dropped frame is not a command");
            assert_eq!(
                settings(&self.sup),
                settings_before,
                "a dropped frame changes nothing"
            );
            return;
        }
        self.stats.frames_accepted += 1;
        if let Some(last) = self.model.last_seq {
            let dist = env.seq.wrapping_sub(last);
            assert!(
                (1..=SEQ_WINDOW).contains(&dist),
                "seq {} accepted after {last}",
                env.seq
            );
        }
        self.model.last_seq = Some(env.seq);
        match env.msg {
            Msg::State(s) => {
                assert_eq!(refused, 0);
                if self.model.lockstep && self.model.mission {
                    if let Some((t, periods)) = self.model.clock {
                        assert!(
                            s.t_ticks > t && s.t_ticks - t <= periods,
                            "tick {} accepted after {t}, {periods} periods on",
                            s.t_ticks
                        );
                    }
                    self.model.clock = Some((s.t_ticks, 0));
                }
                self.model.periods_since_state = Some(0);
            }
            Msg::Command(c) => {
                let refused = refused == 1;
                if refused {
                    self.stats.refusals += 1;
                    assert!(self.sup.last_refusal().is_some());
                }
                self.command(&c, refused);
                if !refused && *self.sup.controller().config() != settings_before.0 {
                    self.model.rebuilt = true;
                }
                if refused || !matches!(c, Command::SetConfig(_)) {
                    assert_eq!(
                        settings(&self.sup),
                        settings_before,
                        "{c:?} changed settings"
                    );
                }
            }
            Msg::Telemetry(_) => unreachable!("checked above"),
        }
    }
}
