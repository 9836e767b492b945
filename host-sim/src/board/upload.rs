//! The navigation computer's side of the mission upload (protocol 5, `auv_link::upload`,
//! docs/link.md#the-mission-upload): a waypoint mission goes to the disarmed board before `Arm` as a
//! `Begin` and its chunks; each telemetry frame says which chunks the board holds; the runner
//! resends what is missing until the board says the mission matches its CRC, in a bounded
//! number of rounds.

use std::time::Instant;

use auv_link::{Command as LinkCommand, MissionUpload, Msg, Telemetry, UploadPart};

use super::error::Error;
use super::link::Link;
use super::stats::UploadStats;
use crate::sim::UploadRound;

/// Rounds of sending (the first and each resend) before the upload is given up.
pub const MAX_UPLOAD_ROUNDS: u32 = 8;

/// Uploads `up` to the (disarmed) board over `link`; `lose` are chunks whose first sending is
/// dropped on purpose (the scenario's `link_faults.lose_upload_chunks`), to show the resend.
/// Returns what it cost and the board's telemetry that verified it.
pub(super) fn upload(
    link: &mut Link,
    up: &MissionUpload,
    lose: &[u8],
) -> Result<(UploadStats, Telemetry), Error> {
    let t0 = Instant::now();
    let mut stats = UploadStats {
        crc: up.crc(),
        chunks: u32::from(up.chunks()),
        ..UploadStats::default()
    };
    let mut begin = true;
    let mut chunks: Vec<u8> = (0..up.chunks()).collect();
    let mut last_refusal = None;
    for round in 1..=MAX_UPLOAD_ROUNDS {
        let frames_before = stats.frames;
        if begin {
            send_part(link, UploadPart::Begin(up.header()), &mut stats)?;
        }
        for &i in &chunks {
            if round == 1 && lose.contains(&i) {
                // Lost on the way: numbered and never sent.
                link.skip();
                continue;
            }
            if round > 1 {
                stats.resent += 1;
            }
            send_part(link, UploadPart::Chunk(up.chunk(i)), &mut stats)?;
        }
        let t = link.acknowledged(link.last_seq())?;
        last_refusal = t.last_refusal;
        let held = t.upload;
        stats.rounds = round;
        let ours = held.crc == up.crc() && held.chunks == up.chunks();
        stats.round_log.push(UploadRound {
            round,
            chunks_sent: stats.frames - frames_before - u32::from(begin),
            missing: if ours {
                held.missing().count() as u32
            } else {
                u32::from(up.chunks())
            },
            verified: ours && held.verified,
            frames: stats.frames,
            bytes: stats.bytes,
            seconds: t0.elapsed().as_secs_f64(),
        });
        if ours {
            if held.verified {
                stats.seconds = t0.elapsed().as_secs_f64();
                return Ok((stats, t));
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
    Err(Error::UploadNotVerified {
        crc: up.crc(),
        chunks: up.chunks(),
        rounds: MAX_UPLOAD_ROUNDS,
        last_refusal,
    })
}

fn send_part(link: &mut Link, part: UploadPart, stats: &mut UploadStats) -> Result<(), Error> {
    let mut frame = Vec::new();
    let n = link.append(Msg::Command(LinkCommand::Upload(part)), &mut frame)?;
    link.write(&frame)?;
    stats.frames += 1;
    stats.bytes += n as u64;
    Ok(())
}
