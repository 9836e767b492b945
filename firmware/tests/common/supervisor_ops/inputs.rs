//! How the fuzz input's bytes become the harness's events: the reader, sequence numbers,
//! state frames, missions, patches, commands and upload parts (the layout is the parent's docs).

use super::*;

/// Reads the input; missing bytes are 0.
pub(super) struct Bytes<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> Bytes<'a> {
    /// The input from its first byte.
    pub(super) fn new(data: &'a [u8]) -> Self {
        Bytes { data, at: 0 }
    }

    pub(super) fn more(&self) -> bool {
        self.at < self.data.len()
    }
    pub(super) fn u8(&mut self) -> u8 {
        let b = self.peek_u8();
        self.at += 1;
        b
    }
    /// The next byte, without taking it.
    pub(super) fn peek_u8(&self) -> u8 {
        self.data.get(self.at).copied().unwrap_or(0)
    }
    pub(super) fn u16(&mut self) -> u16 {
        u16::from_le_bytes([self.u8(), self.u8()])
    }
    pub(super) fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    pub(super) fn u64(&mut self) -> u64 {
        u64::from(self.u32()) | u64::from(self.u32()) << 32
    }
    pub(super) fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    pub(super) fn take(&mut self, n: usize) -> &[u8] {
        let start = self.at.min(self.data.len());
        let end = (start + n).min(self.data.len());
        self.at = start + n;
        &self.data[start..end]
    }
}

/// The reference on the paper's 10 m circle at tick `k` (the vehicle exactly on it).
fn on_circle(k: u64) -> StateFrame {
    let d = Trajectory::table1(Table1Case::Circular10R).sample(k, 100);
    let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
    StateFrame {
        t_ticks: k,
        eta: d.eta.into(),
        nu: nu.into(),
    }
}

/// The next sequence number: usually +1; sometimes a repeat, a step back or a jump.
pub(super) fn next_seq(h: &mut Harness, input: &mut Bytes) -> u16 {
    let s = input.u8();
    let step = match s {
        0..=200 => 1,
        255 => input.u16(),
        _ => u16::from(s).wrapping_sub(228), // −27 ..= +26
    };
    h.seq = h.seq.wrapping_add(step);
    h.seq
}

/// A state frame: on the reference at the next tick of the mission clock (or the next after
/// `value`), at an arbitrary tick, and sometimes with one component replaced by arbitrary bits.
pub(super) fn state_frame(h: &Harness, input: &mut Bytes) -> StateFrame {
    let mode = input.u8();
    let next = h.model.clock.map_or(0, |(t, _)| t + 1);
    let t = match mode % 4 {
        0 => next,
        1 => next.wrapping_add(u64::from(input.u8())),
        2 => next.wrapping_sub(u64::from(input.u8())),
        _ => input.u64(),
    };
    // The reference only depends on t mod its period; keep the sample finite for huge ticks.
    let mut s = on_circle(t % 1_000_000);
    s.t_ticks = t;
    if mode & 0x80 != 0 {
        let i = usize::from(input.u8() % 12);
        let v = input.f32();
        if i < 6 {
            s.eta[i] = v;
        } else {
            s.nu[i - 6] = v;
        }
    }
    s
}

/// A mission: [`path`]'s, with the tangent heading if bit 6 of its first byte is set and, if
/// bit 5 is, a time scale from the input (else 1) — so byte 0 is the paper's circle as before.
pub(super) fn mission(input: &mut Bytes) -> MissionPlan {
    let kind = input.peek_u8();
    let path = path(input);
    MissionPlan {
        path,
        heading: if kind & 0x40 != 0 {
            Heading::Tangent
        } else {
            Heading::Paper
        },
        time_scale: if kind & 0x20 != 0 { input.f32() } else { 1.0 },
    }
}

/// A path: the paper's circle ([`MissionPlan::EXAMPLE`]) unless bit 7 of its byte is set, the
/// uploaded mission by its CRC when bits 7 and 4 are 0 and 1, else a closed form of
/// `TrajectoryKind::EXAMPLES` (byte % their count) with every parameter from the input.
pub(super) fn path(input: &mut Bytes) -> MissionSpec {
    let kind = input.u8();
    if kind & 0x90 == 0x10 {
        // The uploaded mission, by its CRC (the board flies it only if it holds it verified).
        return MissionSpec::Waypoints {
            crc: three_points().crc(),
        };
    }
    if kind & 0x80 == 0 {
        return MissionPlan::EXAMPLE.path;
    }
    let closed: Vec<TrajectoryKind> = TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .collect();
    let mut path = closed[usize::from(kind) % closed.len()];
    path.parameters(&mut |_, value| *value = input.f32());
    path.into()
}

/// A config patch: each field present or not, with values from a few meaningful ones
/// (valid, at and beyond the limits) or arbitrary bits.
pub(super) fn patch(input: &mut Bytes) -> ConfigPatch {
    let present = input.u8();
    let pick = |input: &mut Bytes, values: &[f32]| {
        let i = usize::from(input.u8()) % (values.len() + 1);
        values.get(i).copied().unwrap_or_else(|| input.f32())
    };
    ConfigPatch {
        rate_hz: (present & 1 != 0).then(|| {
            let values = [100, 50, 200, 201, 0, u32::MAX, 10];
            let i = usize::from(input.u8()) % (values.len() + 1);
            values.get(i).copied().unwrap_or_else(|| input.u32())
        }),
        robust: (present & 2 != 0).then(|| input.u8() & 1 == 1),
        delta_max: (present & 4 != 0).then(|| pick(input, &[1.0, 0.5, 0.0, -1.0, f32::NAN])),
        voltage_limit: (present & 8 != 0)
            .then(|| pick(input, &[SUPPLY, 12.0, SUPPLY + 0.5, 0.0, f32::INFINITY])),
        stale_periods: (present & 16 != 0).then(|| input.u8()),
        lockstep: (present & 32 != 0).then(|| input.u8() & 1 == 1),
        // Protocol 3's chain: any unit, any mask byte (a sixth thruster is refused); the
        // priority stays unset (no bit left in `present`; tests/thruster_chain.rs covers it).
        thrust_unit: (present & 64 != 0).then(|| {
            if input.u8() & 1 == 0 {
                ThrustUnit::Kgf
            } else {
                ThrustUnit::Newton
            }
        }),
        reversed_thrusters: (present & 128 != 0).then(|| input.u8()),
        priority: None,
        // Protocol 7's estimator stays unset too (tests/estimator.rs flies it), and protocol
        // 8's law (tests/law_settings.rs: the board takes a law exactly when the core does).
        estimator: None,
        law: None,
    }
}

/// A command: `Command::EXAMPLES[byte % their count]`, its arguments from the input.
pub(super) fn command(input: &mut Bytes) -> Command {
    let example = Command::EXAMPLES[usize::from(input.u8()) % Command::EXAMPLES.len()];
    match example {
        Command::StartMission(_) => Command::StartMission(mission(input)),
        Command::SetConfig(_) => Command::SetConfig(patch(input)),
        Command::Upload(_) => Command::Upload(upload(input)),
        Command::Arm | Command::Disarm | Command::StopMission => example,
    }
}

/// The valid upload the harness sends most: the waypoint path of `TrajectoryKind::EXAMPLES`
/// (three points, one chunk), the paper's heading.
pub fn three_points() -> MissionUpload {
    let path = TrajectoryKind::EXAMPLES
        .into_iter()
        .find(|k| matches!(k, TrajectoryKind::Waypoints { .. }))
        .expect("a waypoint example");
    MissionUpload::of(&controller_core::Mission::paper(path)).expect("a waypoint path")
}

/// An upload part: the valid mission's `Begin` or chunk, or a header or chunk of fuzz bytes.
pub(super) fn upload(input: &mut Bytes) -> UploadPart {
    let up = three_points();
    match input.u8() % 4 {
        0 => UploadPart::Begin(up.header()),
        1 => UploadPart::Chunk(up.chunk(input.u8() % 2)),
        2 => UploadPart::Begin(UploadHeader {
            points: input.u8(),
            speeds: (input.u8() & 1 == 1).then(|| input.u8()),
            speed: input.f32(),
            turn_radius: (input.u8() & 1 == 1).then(|| input.f32()),
            speed_change: (input.u8() & 1 == 1).then(|| input.f32()),
            heading: if input.u8() & 1 == 1 {
                Heading::Tangent
            } else {
                Heading::Paper
            },
            time_scale: input.f32(),
            crc: input.u32(),
        }),
        _ => {
            let index = input.u8();
            let mut words = [0.0; auv_link::upload::CHUNK_WORDS];
            for w in words.iter_mut().take(4) {
                *w = input.f32();
            }
            UploadPart::Chunk(UploadChunk { index, words })
        }
    }
}
