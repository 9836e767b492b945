//! The navigation computer's side of the mission upload (protocol 5, `auv_link::upload`,
//! docs/link.md#the-mission-upload): a waypoint mission goes to the disarmed board before `Arm` as a
//! `Begin` and its chunks; each telemetry frame says which chunks the board holds; the runner
//! resends what is missing until the board says the mission matches its CRC, in a bounded
//! number of rounds.

use std::time::{Duration, Instant};

use auv_link::{Command as LinkCommand, MissionUpload, Msg, Telemetry, UploadPart, MAX_FRAME};

use super::runner::BoardInTheLoop;

/// Rounds of sending (the first and each resend) before the upload is given up.
pub const MAX_UPLOAD_ROUNDS: u32 = 8;
/// Telemetry frames a round waits for the board to acknowledge its last frame (a lost last
/// frame is never acknowledged: the round ends on what the board says it holds).
const ACK_FRAMES: u32 = 5;

/// What an upload cost on the link.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct UploadStats {
    /// The mission's CRC (`StartMission` names it).
    pub crc: u32,
    /// Chunks of the mission.
    pub chunks: u32,
    /// Frames sent (the `Begin`, every chunk, every resend).
    pub frames: u32,
    /// Their bytes on the wire.
    pub bytes: u64,
    /// Rounds until the board verified it (1: nothing lost).
    pub rounds: u32,
    /// Chunks sent again.
    pub resent: u32,
    /// Wall-clock time from the `Begin` to the board's verification (s).
    pub seconds: f64,
}

impl BoardInTheLoop {
    /// Uploads `up` to the (disarmed) board; `lose` are chunks whose first sending is dropped
    /// on purpose (the scenario's `link_faults.lose_upload_chunks`), to show the resend.
    /// Returns the board's count of refused commands once it verified the upload.
    pub(super) fn upload(&mut self, up: &MissionUpload, lose: &[u8]) -> Result<u32, String> {
        let t0 = Instant::now();
        let mut stats = UploadStats {
            crc: up.crc(),
            chunks: u32::from(up.chunks()),
            ..UploadStats::default()
        };
        let mut begin = true;
        let mut chunks: Vec<u8> = (0..up.chunks()).collect();
        for round in 1..=MAX_UPLOAD_ROUNDS {
            if begin {
                self.send_part(UploadPart::Begin(up.header()), &mut stats)?;
            }
            for &i in &chunks {
                if round == 1 && lose.contains(&i) {
                    // Lost on the way: numbered and never sent.
                    self.seq = self.seq.wrapping_add(1);
                    continue;
                }
                if round > 1 {
                    stats.resent += 1;
                }
                self.send_part(UploadPart::Chunk(up.chunk(i)), &mut stats)?;
            }
            let t = self.acknowledged(self.seq.wrapping_sub(1))?;
            self.stats.board_last_refusal = t.last_refusal.map(|r| r.as_str().to_string());
            let held = t.upload;
            stats.rounds = round;
            if held.crc == up.crc() && held.chunks == up.chunks() {
                if held.verified {
                    stats.seconds = t0.elapsed().as_secs_f64();
                    self.stats.upload = Some(stats);
                    return Ok(t.refused_commands);
                }
                begin = false;
                chunks = held.missing().collect();
                if chunks.is_empty() {
                    // Every chunk held and not verified: the board dropped them on a CRC
                    // mismatch after this status was sent; all again.
                    chunks = (0..up.chunks()).collect();
                }
            } else {
                // The board holds another upload (the Begin was lost): everything again.
                begin = true;
                chunks = (0..up.chunks()).collect();
            }
        }
        Err(format!(
            "the board did not verify the mission upload (CRC {:#010x}, {} chunks) in {MAX_UPLOAD_ROUNDS} rounds{}",
            up.crc(),
            up.chunks(),
            self.stats
                .board_last_refusal
                .as_deref()
                .map_or(String::new(), |r| format!("; its last refusal: {r}"))
        ))
    }

    fn send_part(&mut self, part: UploadPart, stats: &mut UploadStats) -> Result<(), String> {
        let mut buf = [0u8; MAX_FRAME];
        let n = self.encode(Msg::Command(LinkCommand::Upload(part)), &mut buf)?;
        self.write(&buf[..n])?;
        stats.frames += 1;
        stats.bytes += n as u64;
        Ok(())
    }

    /// The board's telemetry once it has taken frame `last` (or after [`ACK_FRAMES`]
    /// telemetry frames, if `last` was lost).
    pub(super) fn acknowledged(&mut self, last: u16) -> Result<Telemetry, String> {
        let deadline = Instant::now() + Duration::from_secs(30);
        let mut frames = 0;
        loop {
            let t = self.next_telemetry()?;
            frames += 1;
            if t.last_rx_seq == last || frames >= ACK_FRAMES || Instant::now() > deadline {
                return Ok(t);
            }
        }
    }
}
