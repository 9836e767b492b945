//! The chunked mission upload (protocol 5, docs/link.md#the-mission-upload, Choices 163–167): a waypoint
//! path is up to [`MAX_WAYPOINTS`] points and [`MAX_PARTS`] speeds, far more than one frame,
//! so it travels as data before the mission starts.
//!
//! **The transfer.** While the board is disarmed the navigation computer sends
//! [`UploadPart::Begin`] with the [`UploadHeader`] (the counts, the path's scalars and the
//! whole mission's CRC-32), then every [`UploadChunk`] ([`CHUNK_WORDS`] words each: the
//! points' coordinates, then the speeds, in order; the last chunk padded with zeros). Each
//! telemetry frame acknowledges what the board holds ([`UploadStatus`]: the CRC it was told,
//! the chunk count, a bit per chunk received, and whether the assembled mission matched the
//! CRC): the sender resends the chunks whose bits are clear until the board says `verified`.
//! A new `Begin` drops whatever was uploaded before. Chunks may arrive in any order and more
//! than once (the last copy wins; each copy is whole, the frame's CRC or MAC saw to that).
//! Every part of an upload is refused while armed (a mission is never changed under a running
//! loop, Choice 164), and one with counts the board cannot hold is refused whole.
//!
//! **The mission.** The upload is the whole mission: the path, its heading and its time scale
//! (the board builds its trajectory as soon as the upload is verified, while disarmed, so that
//! `StartMission` costs no more than a closed form's; Choice 169). `StartMission` then names it
//! as [`MissionSpec::Waypoints`] with the CRC, its heading and time scale the upload's: the
//! board flies its upload only if it is verified and is that mission
//! ([`UploadBuffer::mission`]); otherwise it refuses with [`Refusal::NoUpload`]. The upload
//! survives disarming and a fail-safe, so a re-armed board restarts the same mission.
//!
//! **The CRC** (CRC-32/ISO-HDLC, [`mission_crc`]) covers the header's fields and every word,
//! in this order: point count, speed count (0xFF: none), `speed`, `turn_radius` and
//! `speed_change` (0xFF for none, else 0x01 and the value), the heading (0 paper, 1 tangent),
//! the time scale, then the words, each `f32` as its four little-endian bytes. It is the whole mission's check, beside each frame's CRC-16 (or MAC):
//! a mission assembled from chunks of two uploads, or a header from a third, does not match.
//!
//! [`MissionSpec::Waypoints`]: crate::MissionSpec::Waypoints
//! [`Refusal::NoUpload`]: crate::Refusal::NoUpload

use controller_core::trajectory::{SpeedList, WaypointList, MAX_PARTS, MAX_WAYPOINTS};
use controller_core::{Mission, TrajectoryKind};
use serde::{Deserialize, Serialize};

use crate::heading::Heading;
use crate::refusal::Refusal;

/// Words (`f32`) per chunk: a chunk is 131 postcard bytes, under the largest telemetry frame,
/// so that a chunk never makes the link's largest frame larger (Choice 163).
pub const CHUNK_WORDS: usize = 32;
/// Words of the largest mission: three coordinates per point, then one speed per part.
pub const MAX_WORDS: usize = 3 * MAX_WAYPOINTS + MAX_PARTS;
/// Chunks of the largest mission.
pub const MAX_CHUNKS: usize = MAX_WORDS.div_ceil(CHUNK_WORDS);
const _: () = assert!(MAX_CHUNKS <= 32, "one bit per chunk in a u32");
/// The speed count of a header without a speed list.
const NO_SPEEDS: u8 = u8::MAX;

/// CRC-32/ISO-HDLC (the zip/Ethernet CRC; check value 0xCBF43926).
pub(crate) const CRC32: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC);

/// What a mission upload is: its counts, the path's scalars and the whole mission's CRC.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UploadHeader {
    /// Waypoints (2 to [`MAX_WAYPOINTS`]).
    pub points: u8,
    /// Speeds of the time law (`None`: `speed` everywhere; at most [`MAX_PARTS`]).
    pub speeds: Option<u8>,
    /// σ̇ on the legs (m/s), `TrajectoryKind::Waypoints::speed`.
    pub speed: f32,
    /// The smallest turn radius (m), or the default.
    pub turn_radius: Option<f32>,
    /// The largest |σ̈| of a speed change (m/s²), or the default.
    pub speed_change: Option<f32>,
    /// The mission's heading (Choice 169: the board builds the whole mission when the upload
    /// is verified, so `StartMission` costs it nothing).
    pub heading: Heading,
    /// The mission's time scale k.
    pub time_scale: f32,
    /// [`mission_crc`] of the header's other fields and every word.
    pub crc: u32,
}

impl UploadHeader {
    /// Worst-case postcard size (bytes).
    pub const MAX_SIZE: usize = 1 + 2 + 4 + 5 + 5 + 1 + 4 + 5;

    /// Words the chunks carry: 3 per point, then the speeds.
    pub fn words(&self) -> usize {
        3 * self.points as usize + self.speeds.map_or(0, usize::from)
    }

    /// Chunks of this upload.
    pub fn chunks(&self) -> u8 {
        self.words().div_ceil(CHUNK_WORDS) as u8
    }

    /// The counts fit the board: 2 to [`MAX_WAYPOINTS`] points, at most [`MAX_PARTS`] speeds.
    fn fits(&self) -> bool {
        (2..=MAX_WAYPOINTS).contains(&(self.points as usize))
            && self.speeds.is_none_or(|n| n as usize <= MAX_PARTS)
    }
}

/// One chunk: words `index·CHUNK_WORDS ..` of the mission.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UploadChunk {
    /// Which chunk (0-based).
    pub index: u8,
    /// Its words; past the mission's end, zeros.
    pub words: [f32; CHUNK_WORDS],
}

impl UploadChunk {
    /// Worst-case postcard size (bytes).
    pub const MAX_SIZE: usize = 1 + 4 * CHUNK_WORDS;
}

/// A part of a mission upload ([`crate::Command::Upload`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum UploadPart {
    /// Starts an upload (drops the one before).
    Begin(UploadHeader),
    /// One chunk of the upload begun.
    Chunk(UploadChunk),
}

impl UploadPart {
    /// Worst-case postcard size (bytes).
    pub const MAX_SIZE: usize = 1 + if UploadHeader::MAX_SIZE > UploadChunk::MAX_SIZE {
        UploadHeader::MAX_SIZE
    } else {
        UploadChunk::MAX_SIZE
    };
}

/// What the board holds of an upload, in every telemetry frame: the acknowledgement.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct UploadStatus {
    /// The header's CRC (0 with no upload).
    pub crc: u32,
    /// Chunks of the upload (0 with no upload).
    pub chunks: u8,
    /// Bit i set: chunk i is held.
    pub received: u32,
    /// Every chunk is held and the assembled mission matches the CRC.
    pub verified: bool,
}

impl UploadStatus {
    /// Worst-case postcard size (bytes).
    pub const MAX_SIZE: usize = 5 + 1 + 5 + 1;
    /// No upload.
    pub const NONE: UploadStatus = UploadStatus {
        crc: 0,
        chunks: 0,
        received: 0,
        verified: false,
    };

    /// The chunks still missing, in order.
    pub fn missing(&self) -> impl Iterator<Item = u8> + '_ {
        (0..self.chunks).filter(move |i| self.received & (1 << i) == 0)
    }
}

/// CRC-32 of a mission: the header's fields (its `crc` aside) and `words`, as the module doc
/// lays them out. The one definition both ends use.
pub fn mission_crc(header: &UploadHeader, words: &[f32]) -> u32 {
    let mut d = CRC32.digest();
    d.update(&[header.points, header.speeds.unwrap_or(NO_SPEEDS)]);
    d.update(&header.speed.to_le_bytes());
    for v in [header.turn_radius, header.speed_change] {
        match v {
            None => d.update(&[NO_SPEEDS]),
            Some(x) => {
                d.update(&[1]);
                d.update(&x.to_le_bytes());
            }
        }
    }
    d.update(&[header.heading as u8]);
    d.update(&header.time_scale.to_le_bytes());
    for w in words {
        d.update(&w.to_le_bytes());
    }
    d.finalize()
}

/// A waypoint mission as an upload (the sender's side; no heap): its header and its chunks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MissionUpload {
    header: UploadHeader,
    words: [f32; MAX_WORDS],
}

impl MissionUpload {
    /// The upload of `mission`, or `None` if its path is not a waypoint path (a closed-form
    /// path fits one `StartMission`).
    pub fn of(mission: &Mission) -> Option<MissionUpload> {
        let Mission {
            path,
            heading,
            time_scale,
        } = mission;
        let TrajectoryKind::Waypoints {
            points,
            speed,
            turn_radius,
            speeds,
            speed_change,
        } = path
        else {
            return None;
        };
        let mut words = [0.0; MAX_WORDS];
        let mut n = 0;
        for p in points.as_slice() {
            words[n..n + 3].copy_from_slice(p);
            n += 3;
        }
        if let Some(s) = speeds {
            words[n..n + s.as_slice().len()].copy_from_slice(s.as_slice());
        }
        let mut header = UploadHeader {
            points: points.as_slice().len() as u8,
            speeds: speeds.map(|s| s.as_slice().len() as u8),
            speed: *speed,
            turn_radius: *turn_radius,
            speed_change: *speed_change,
            heading: (*heading).into(),
            time_scale: *time_scale,
            crc: 0,
        };
        header.crc = mission_crc(&header, &words[..header.words()]);
        Some(MissionUpload { header, words })
    }

    /// The `Begin` part's header.
    pub fn header(&self) -> UploadHeader {
        self.header
    }

    /// The whole mission's CRC (what `StartMission` names).
    pub fn crc(&self) -> u32 {
        self.header.crc
    }

    /// Chunks of the upload.
    pub fn chunks(&self) -> u8 {
        self.header.chunks()
    }

    /// Chunk `index` (zeros past the mission's end; an index past the last is all zeros).
    pub fn chunk(&self, index: u8) -> UploadChunk {
        let mut words = [0.0; CHUNK_WORDS];
        let start = (index as usize * CHUNK_WORDS).min(MAX_WORDS);
        let end = (start + CHUNK_WORDS).min(self.header.words().max(start));
        words[..end - start].copy_from_slice(&self.words[start..end]);
        UploadChunk { index, words }
    }
}

/// The board's upload buffer: one mission's words in a fixed array (no heap), its header and
/// what has arrived. Never panics on any part.
#[derive(Clone, Debug, PartialEq)]
pub struct UploadBuffer {
    header: Option<UploadHeader>,
    words: [f32; MAX_WORDS],
    received: u32,
    verified: bool,
    /// Moves whenever the header or a word changes ([`UploadBuffer::revision`]).
    revision: u32,
}

impl Default for UploadBuffer {
    fn default() -> Self {
        Self::EMPTY
    }
}

impl UploadBuffer {
    /// No upload.
    pub const EMPTY: UploadBuffer = UploadBuffer {
        header: None,
        words: [0.0; MAX_WORDS],
        received: 0,
        verified: false,
        revision: 0,
    };

    /// Takes one part: a `Begin` drops the upload before and starts this one (refused whole,
    /// [`Refusal::InvalidUpload`], if its counts do not fit); a chunk is stored (refused,
    /// [`Refusal::InvalidUpload`], with no upload begun or an index past its last). When the
    /// last missing chunk arrives the mission is checked against the header's CRC; on a
    /// mismatch every chunk is dropped (to be sent again) and the chunk is refused
    /// ([`Refusal::UploadCrc`]).
    pub fn take(&mut self, part: &UploadPart) -> Result<(), Refusal> {
        match part {
            UploadPart::Begin(h) => {
                if !h.fits() {
                    return Err(Refusal::InvalidUpload);
                }
                let revision = self.revision.wrapping_add(1);
                *self = Self::EMPTY;
                self.header = Some(*h);
                self.revision = revision;
                Ok(())
            }
            UploadPart::Chunk(c) => self.chunk(c),
        }
    }

    fn chunk(&mut self, c: &UploadChunk) -> Result<(), Refusal> {
        let Some(h) = self.header else {
            return Err(Refusal::InvalidUpload);
        };
        if c.index >= h.chunks() {
            return Err(Refusal::InvalidUpload);
        }
        let start = c.index as usize * CHUNK_WORDS;
        let end = (start + CHUNK_WORDS).min(h.words());
        let new = &c.words[..end - start];
        let same = self.words[start..end]
            .iter()
            .zip(new)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        if !same {
            self.revision = self.revision.wrapping_add(1);
        }
        self.words[start..end].copy_from_slice(new);
        self.received |= 1 << c.index;
        self.verified = false;
        if self.received == all(h.chunks()) {
            if mission_crc(&h, &self.words[..h.words()]) != h.crc {
                self.received = 0;
                return Err(Refusal::UploadCrc);
            }
            self.verified = true;
        }
        Ok(())
    }

    /// The acknowledgement telemetry carries.
    pub fn status(&self) -> UploadStatus {
        match self.header {
            None => UploadStatus::NONE,
            Some(h) => UploadStatus {
                crc: h.crc,
                chunks: h.chunks(),
                received: self.received,
                verified: self.verified,
            },
        }
    }

    /// The uploaded mission, if the upload is verified and its CRC is `crc`; else
    /// [`Refusal::NoUpload`]. Not validated: build it with `controller_core::Trajectory`.
    pub fn mission(&self, crc: u32) -> Result<Mission, Refusal> {
        let h = match self.header {
            Some(h) if self.verified && h.crc == crc => h,
            _ => return Err(Refusal::NoUpload),
        };
        let n = h.points as usize;
        let mut points = [[0.0f32; 3]; MAX_WAYPOINTS];
        for (i, p) in points.iter_mut().enumerate().take(n) {
            p.copy_from_slice(&self.words[3 * i..3 * i + 3]);
        }
        let points = WaypointList::new(&points[..n]).map_err(|_| Refusal::NoUpload)?;
        let speeds = match h.speeds {
            None => None,
            Some(m) => Some(
                SpeedList::new(&self.words[3 * n..3 * n + m as usize])
                    .map_err(|_| Refusal::NoUpload)?,
            ),
        };
        Ok(Mission {
            path: TrajectoryKind::Waypoints {
                points,
                speed: h.speed,
                turn_radius: h.turn_radius,
                speeds,
                speed_change: h.speed_change,
            },
            heading: h.heading.into(),
            time_scale: h.time_scale,
        })
    }

    /// The CRC of the verified upload, if there is one.
    pub fn verified(&self) -> Option<u32> {
        self.header.filter(|_| self.verified).map(|h| h.crc)
    }

    /// A number that moves whenever the upload's data changes: at every accepted `Begin`
    /// (even of the same header: its chunks are dropped) and at every chunk whose words differ,
    /// bit for bit, from those held; not at a chunk resent unchanged. What a cache of the
    /// mission built from this buffer is keyed by, beside the CRC, so that it never stands for
    /// data it did not check (two missions may share a CRC-32: Choice 229). It wraps after
    /// 2³² changes: compare it across one [`take`](Self::take), not across a long history.
    pub fn revision(&self) -> u32 {
        self.revision
    }
}

/// Bits 0..n set.
fn all(n: u8) -> u32 {
    if n >= 32 {
        u32::MAX
    } else {
        (1u32 << n) - 1
    }
}
