//! The flight log's channels, declared once (**Choice 351**, docs/logs.md#channels): each
//! channel's topic, its fields (name, kind, unit), its rate, and how a control period's
//! [`Record`] fills it. The JSON Schema of a channel ([`json_schema`]) and its messages
//! ([`encode`]) are both made from the same [`Field`] list, so they cannot drift apart; the
//! `diff` command reads the fields back by the same names.
//!
//! JSON Schema with JSON messages: what Foxglove and PlotJuggler open without a plugin
//! (**Choice 350**). A number that is not finite is left out of its message (JSON has no NaN),
//! and a number's schema is the one type `number`, not optional in the schema's `required`
//! (**Choice 480**: Foxglove reads only a single `type` and refuses `["number", "null"]`).

use std::fmt::Write as _;

use serde_json::{json, Map, Value};

use super::inside::LawInside;
use crate::sim::Sample;

/// What a field holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A number (left out of the message when it is not finite, or not known this period).
    Number,
    Integer,
    Boolean,
    Text,
}

impl Kind {
    fn json_type(self) -> Value {
        match self {
            Kind::Number => json!("number"),
            Kind::Integer => json!("integer"),
            Kind::Boolean => json!("boolean"),
            Kind::Text => json!("string"),
        }
    }
}

/// A field of a channel's message: one value, or an object of named values of one kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    /// `Some`: an object with these members, each of [`Field::kind`].
    pub members: Option<&'static [&'static str]>,
    pub kind: Kind,
    /// Unit and meaning, the schema's `description`.
    pub about: &'static str,
}

const fn one(name: &'static str, kind: Kind, about: &'static str) -> Field {
    Field {
        name,
        members: None,
        kind,
        about,
    }
}

const fn group(name: &'static str, members: &'static [&'static str], about: &'static str) -> Field {
    Field {
        name,
        members: Some(members),
        kind: Kind::Number,
        about,
    }
}

/// η's components (m, rad), the CSV's names.
pub const POSE: &[&str] = &["x", "y", "z", "roll", "pitch", "yaw"];
/// ν's components (m/s, rad/s).
pub const VELOCITY: &[&str] = &["u", "v", "w", "p", "q", "r"];
/// The attitude's components (rad), η's last three.
pub const ATTITUDE: &[&str] = &["roll", "pitch", "yaw"];
/// The body rates (rad/s), ν's last three.
pub const RATES: &[&str] = &["p", "q", "r"];
/// The linear body velocities (m/s), ν's first three.
pub const LINEAR: &[&str] = &["u", "v", "w"];
/// τ's components (N, N m).
pub const WRENCH: &[&str] = &["X", "Y", "Z", "K", "M", "N"];
/// The thrusters, in the order of [`Sample::thrust`] (the CSV's suffixes).
pub const THRUSTER_NAMES: &[&str] = &["main", "vert_fore", "vert_aft", "horz_fore", "horz_aft"];

/// How often a channel has a message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rate {
    /// Every control period.
    Control,
    /// At most this many per second: every ⌈rate/hz⌉-th control period, from the first.
    AtMost(u32),
    /// When a navigation source's measurement arrives: the source's own rate, after its
    /// latency, none in its outages (**Choice 381**).
    Arrival,
    /// When something happens (a status change, a refusal, an upload's round, the run's end).
    Events,
}

/// One channel of the log.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChannelSpec {
    pub topic: &'static str,
    /// The schema's name (`auv150.Truth`).
    pub schema: &'static str,
    pub about: &'static str,
    pub fields: &'static [Field],
    pub rate: Rate,
    /// Only a board in the loop has it (the supervisor, the link, the upload): a SIL log
    /// declares it and writes no message on it, and `diff` does not hold its absence from
    /// one of two flights against them (**Choice 382**).
    pub board_only: bool,
}

/// The channels a log has, in the order they are declared in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Topic {
    Truth,
    Navigation,
    Reference,
    Tau,
    Thrusters,
    Law,
    Events,
    Ins,
    Dvl,
    Depth,
    Fix,
    Supervisor,
    Refusals,
    Link,
    Upload,
}

impl Topic {
    pub const ALL: [Topic; 15] = [
        Topic::Truth,
        Topic::Navigation,
        Topic::Reference,
        Topic::Tau,
        Topic::Thrusters,
        Topic::Law,
        Topic::Events,
        Topic::Ins,
        Topic::Dvl,
        Topic::Depth,
        Topic::Fix,
        Topic::Supervisor,
        Topic::Refusals,
        Topic::Link,
        Topic::Upload,
    ];

    /// The channel's declaration.
    pub fn spec(self) -> &'static ChannelSpec {
        &CHANNELS[self as usize]
    }
}

/// Whether the channel `topic` is one only a board in the loop has ([`ChannelSpec::board_only`]).
pub fn board_only(topic: &str) -> bool {
    CHANNELS.iter().any(|c| c.topic == topic && c.board_only)
}

/// The plant's truth is logged at most this often (Hz): it is f64 and changes smoothly, and
/// the log of a mission stays a few MB per minute (**Choice 352**, docs/logs.md#size).
pub const TRUTH_HZ: u32 = 20;

/// Every channel, indexed by [`Topic`].
pub const CHANNELS: [ChannelSpec; 15] = [
    ChannelSpec {
        topic: "/plant/truth",
        schema: "auv150.Truth",
        about: "the plant's true state (f64), and e = η − η_d from it (the CSV's e_*)",
        fields: &[
            group("eta", POSE, "true pose η (m, rad)"),
            group("nu", VELOCITY, "true body velocities ν (m/s, rad/s)"),
            group(
                "error",
                POSE,
                "e = η − η_d from the true pose, yaw wrapped (m, rad)",
            ),
            one("payload", Kind::Number, "payload mass variation Δm (kg)"),
        ],
        rate: Rate::AtMost(TRUTH_HZ),
        board_only: false,
    },
    ChannelSpec {
        topic: "/navigation/told",
        schema: "auv150.Told",
        about: "the state the law was told this period (f32, as it crossed to the controller)",
        fields: &[
            group("eta", POSE, "η told (m, rad)"),
            group("nu", VELOCITY, "ν told (m/s, rad/s)"),
        ],
        rate: Rate::Control,
        board_only: false,
    },
    ChannelSpec {
        topic: "/reference",
        schema: "auv150.Reference",
        about: "the reference the law tracked this period",
        fields: &[
            group("eta_d", POSE, "η_d (m, rad)"),
            group("eta_d_dot", POSE, "η̇_d (m/s, rad/s)"),
            group("eta_d_ddot", POSE, "η̈_d (m/s², rad/s²)"),
        ],
        rate: Rate::Control,
        board_only: false,
    },
    ChannelSpec {
        topic: "/control/tau",
        schema: "auv150.Tau",
        about: "body force demanded by the law and applied to the plant by the thrusters",
        fields: &[
            group("demanded", WRENCH, "τ commanded (N, N m)"),
            group(
                "applied",
                WRENCH,
                "τ the thrusters applied, B·thrust (N, N m)",
            ),
        ],
        rate: Rate::Control,
        board_only: false,
    },
    ChannelSpec {
        topic: "/thrusters",
        schema: "auv150.Thrusters",
        about:
            "each thruster: the thrust it was driven towards, its voltage, its thrust, saturation",
        fields: &[
            group("demand", THRUSTER_NAMES, "thrust driven towards (N)"),
            group("voltage", THRUSTER_NAMES, "voltage from the controller (V)"),
            group("thrust", THRUSTER_NAMES, "thrust applied to the plant (N)"),
            Field {
                name: "saturated",
                members: Some(THRUSTER_NAMES),
                kind: Kind::Boolean,
                about: "the thruster's saturation bit",
            },
            one(
                "saturated_bits",
                Kind::Integer,
                "the saturation bits (the CSV's saturated)",
            ),
        ],
        rate: Rate::Control,
        board_only: false,
    },
    ChannelSpec {
        topic: "/law",
        schema: "auv150.Law",
        about: "the law's inside: e as the law saw it, w = BᵀPe, δ, V = eᵀPe and the Eq 40 ball",
        fields: &[
            group(
                "e",
                POSE,
                "e₁ = η − η_d from the state told, Eq 12 (m, rad)",
            ),
            group("e_dot", POSE, "e₂ = η̇ − η̇_d, Eq 13 (m/s, rad/s)"),
            one(
                "e_norm",
                Kind::Number,
                "‖e‖ = ‖[e₁; e₂]‖ over the controlled axes",
            ),
            one(
                "w_norm",
                Kind::Number,
                "‖w‖ = ‖BᵀPe‖ as the law computed it",
            ),
            one("delta", Kind::Number, "δ(e,t) after the clamp, Eq 29"),
            one("delta_clamped", Kind::Boolean, "the δ clamp limited Δu"),
            one("lyapunov", Kind::Number, "V = eᵀPe (Theorems 3-4)"),
            one(
                "ball_radius",
                Kind::Number,
                "Eq 40's X = √(μδ / (2 λ_min(Q))); 0 for Eq 26, left out without Δu",
            ),
            one(
                "status",
                Kind::Text,
                "ok, or why the thrusters are off (the CSV's status)",
            ),
        ],
        rate: Rate::Control,
        board_only: false,
    },
    ChannelSpec {
        topic: "/events",
        schema: "auv150.Event",
        about: "what happened: the control status changing, the run's outcome",
        fields: &[
            one("kind", Kind::Text, "status or outcome"),
            one(
                "status",
                Kind::Text,
                "the status from this period on (kind status)",
            ),
            one("text", Kind::Text, "what happened, in words"),
        ],
        rate: Rate::Events,
        board_only: false,
    },
    ChannelSpec {
        topic: "/navigation/ins",
        schema: "auv150.InsSample",
        about: "each INS sample as it reached the navigation computer ([navigation].ins)",
        fields: &[
            one(
                "t_sampled",
                Kind::Number,
                "when it was sampled (s; it arrives its latency later)",
            ),
            group("attitude", ATTITUDE, "attitude measured (rad)"),
            group("rates", RATES, "body rates measured (rad/s)"),
        ],
        rate: Rate::Arrival,
        board_only: false,
    },
    ChannelSpec {
        topic: "/navigation/dvl",
        schema: "auv150.DvlPing",
        about: "each DVL ping as it reached the navigation computer ([navigation].dvl)",
        fields: &[
            one("t_sampled", Kind::Number, "when it was sampled (s)"),
            one(
                "bottom_lock",
                Kind::Boolean,
                "the DVL had bottom lock: its velocity reset the solution's",
            ),
            group(
                "velocity",
                LINEAR,
                "velocity over the bottom measured (m/s); left out without bottom lock",
            ),
        ],
        rate: Rate::Arrival,
        board_only: false,
    },
    ChannelSpec {
        topic: "/navigation/depth",
        schema: "auv150.Depth",
        about: "each pressure depth as it reached the navigation computer ([navigation].depth)",
        fields: &[
            one("t_sampled", Kind::Number, "when it was sampled (s)"),
            one("z", Kind::Number, "depth measured (m)"),
        ],
        rate: Rate::Arrival,
        board_only: false,
    },
    ChannelSpec {
        topic: "/navigation/fix",
        schema: "auv150.Fix",
        about: "each position fix as it reached the navigation computer ([navigation].fix)",
        fields: &[
            one("t_sampled", Kind::Number, "when it was sampled (s)"),
            one("x", Kind::Number, "north measured (m)"),
            one("y", Kind::Number, "east measured (m)"),
        ],
        rate: Rate::Arrival,
        board_only: false,
    },
    ChannelSpec {
        topic: "/board/supervisor",
        schema: "auv150.Supervisor",
        about: "the board supervisor's state, from its first answer on and at each change",
        fields: &[
            one(
                "state",
                Kind::Text,
                "disarmed, armed, running, or fail-safe and its reason (the board's words)",
            ),
            one(
                "previous",
                Kind::Text,
                "the state before (empty at the first answer)",
            ),
            one("board_tick", Kind::Integer, "the board's own tick of the answer"),
        ],
        rate: Rate::Events,
        board_only: true,
    },
    ChannelSpec {
        topic: "/board/refusals",
        schema: "auv150.Refusal",
        about: "the commands the board refused, when its count of them grows",
        fields: &[
            one(
                "refused",
                Kind::Integer,
                "commands refused since the board's previous answer",
            ),
            one(
                "refused_commands",
                Kind::Integer,
                "the board's count of refused commands",
            ),
            one("reason", Kind::Text, "the board's last refusal"),
        ],
        rate: Rate::Events,
        board_only: true,
    },
    ChannelSpec {
        topic: "/board/link",
        schema: "auv150.LinkCounters",
        about: "the link's counters at each answer: this end's and the board's, as its telemetry reports them",
        fields: &[
            one(
                "state_frames_sent",
                Kind::Integer,
                "state frames this end sent",
            ),
            one(
                "telemetry_frames",
                Kind::Integer,
                "telemetry frames this end took",
            ),
            one(
                "telemetry_refused",
                Kind::Integer,
                "telemetry frames this end refused (undecodable, badly signed, out of sequence)",
            ),
            one("rearms", Kind::Integer, "re-arms after a fail-safe"),
            one("rx_frames", Kind::Integer, "frames the board took"),
            one(
                "rx_errors",
                Kind::Integer,
                "frames the board could not decode",
            ),
            one(
                "rx_stale",
                Kind::Integer,
                "frames the board dropped as repeated, old or off its mission clock",
            ),
            one(
                "rx_auth_errors",
                Kind::Integer,
                "frames the board refused for their authentication",
            ),
            one(
                "rx_ahead",
                Kind::Integer,
                "of those, authentic frames stamped too far ahead",
            ),
            one(
                "refused_commands",
                Kind::Integer,
                "commands the board refused",
            ),
            one(
                "loop_overruns",
                Kind::Integer,
                "control periods the board overran",
            ),
            one(
                "worst_update_ticks",
                Kind::Integer,
                "the board's longest update, in its timer's unit",
            ),
        ],
        rate: Rate::Control,
        board_only: true,
    },
    ChannelSpec {
        topic: "/board/upload",
        schema: "auv150.UploadRound",
        about: "each round of a waypoint mission's upload, before the flight (time 0)",
        fields: &[
            one("round", Kind::Integer, "the round (1: the first sending)"),
            one(
                "chunks_sent",
                Kind::Integer,
                "chunks sent in this round (a chunk lost on purpose is not)",
            ),
            one(
                "missing",
                Kind::Integer,
                "chunks the board lacked after it",
            ),
            one(
                "verified",
                Kind::Boolean,
                "the board verified the mission against its CRC",
            ),
            one(
                "frames",
                Kind::Integer,
                "upload frames sent so far (the Begin, the chunks, the resends)",
            ),
            one("bytes", Kind::Integer, "their bytes on the wire"),
            one(
                "seconds",
                Kind::Number,
                "wall-clock time since the Begin (s)",
            ),
        ],
        rate: Rate::Events,
        board_only: true,
    },
];

/// Whether a field of this kind is in every message (its schema's `required`): all but a
/// number, which is left out when it is not finite (Choice 480).
fn always_there(kind: Kind) -> bool {
    kind != Kind::Number
}

/// The JSON Schema (draft 2020-12) of a channel: every field required but a number (Choice
/// 480); a group (an object of numbers) is always there, its members are numbers.
pub fn json_schema(spec: &ChannelSpec) -> Value {
    let mut properties = Map::new();
    for f in spec.fields {
        let schema = match f.members {
            None => json!({"type": f.kind.json_type(), "description": f.about}),
            Some(members) => {
                let inner: Map<String, Value> = members
                    .iter()
                    .map(|m| (m.to_string(), json!({"type": f.kind.json_type()})))
                    .collect();
                let required: &[&str] = if always_there(f.kind) { members } else { &[] };
                json!({
                    "type": "object",
                    "description": f.about,
                    "properties": inner,
                    "required": required,
                })
            }
        };
        properties.insert(f.name.to_string(), schema);
    }
    let required: Vec<&str> = spec
        .fields
        .iter()
        .filter(|f| f.members.is_some() || always_there(f.kind))
        .map(|f| f.name)
        .collect();
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": spec.schema,
        "description": spec.about,
        "type": "object",
        "properties": properties,
        "required": required,
    })
}

/// What one control period gives the log: the sample, the law's inside computed from it, and
/// the control period (s: a source's sample tick as a time).
pub struct Record<'a> {
    pub sample: &'a Sample,
    pub inside: &'a LawInside,
    pub period: f64,
}

/// A message's JSON, written field by field in the order of the channel's declaration.
pub struct Message<'o> {
    out: &'o mut String,
    fields: std::slice::Iter<'static, Field>,
}

impl<'o> Message<'o> {
    fn new(spec: &'static ChannelSpec, out: &'o mut String) -> Self {
        out.clear();
        out.push('{');
        Message {
            out,
            fields: spec.fields.iter(),
        }
    }

    /// The next field of the declaration, which must be of `kind`.
    fn next_field(&mut self, kind: Kind, group: bool) -> Option<&'static Field> {
        let f = self.fields.next();
        debug_assert!(
            f.is_some_and(|f| f.kind == kind && f.members.is_some() == group),
            "{f:?} is not a {kind:?} (group {group})"
        );
        f
    }

    /// A name into the message (a comma before all but the first).
    fn write_key(&mut self, name: &str) {
        if self.out.len() > 1 {
            self.out.push(',');
        }
        let _ = write!(self.out, "\"{name}\":");
    }

    /// The next field, its name written.
    fn key(&mut self, kind: Kind, group: bool) -> Option<&'static Field> {
        let f = self.next_field(kind, group)?;
        self.write_key(f.name);
        Some(f)
    }

    /// A number; left out, name and all, when it is not finite (Choice 480).
    pub fn num(&mut self, x: impl JsonNumber) -> &mut Self {
        if let Some(f) = self.next_field(Kind::Number, false) {
            if x.finite() {
                self.write_key(f.name);
                x.put(self.out);
            }
        }
        self
    }

    pub fn int(&mut self, x: i64) -> &mut Self {
        if self.key(Kind::Integer, false).is_some() {
            let _ = write!(self.out, "{x}");
        }
        self
    }

    pub fn boolean(&mut self, x: bool) -> &mut Self {
        if self.key(Kind::Boolean, false).is_some() {
            let _ = write!(self.out, "{x}");
        }
        self
    }

    pub fn text(&mut self, x: &str) -> &mut Self {
        if self.key(Kind::Text, false).is_some() {
            let _ = write!(self.out, "{}", Value::from(x));
        }
        self
    }

    /// A group of numbers, one per member (a missing or non-finite one left out, Choice 480).
    pub fn nums<T: JsonNumber>(&mut self, xs: impl IntoIterator<Item = T>) -> &mut Self {
        self.group(Kind::Number, xs, |out, x| {
            if x.finite() {
                x.put(out);
            }
            x.finite()
        })
    }

    /// A group of booleans, one per member.
    pub fn bools(&mut self, xs: impl IntoIterator<Item = bool>) -> &mut Self {
        self.group(Kind::Boolean, xs, |out, b| {
            let _ = write!(out, "{b}");
            true
        })
    }

    /// An object of the field's members; `put` writes one value and says whether it did (a
    /// member without a value, or whose value `put` leaves out, is left out, name and all).
    fn group<T>(
        &mut self,
        kind: Kind,
        xs: impl IntoIterator<Item = T>,
        put: impl Fn(&mut String, T) -> bool,
    ) -> &mut Self {
        let Some(members) = self.key(kind, true).and_then(|f| f.members) else {
            return self;
        };
        self.out.push('{');
        let mut xs = xs.into_iter();
        let mut first = true;
        for m in members {
            let Some(x) = xs.next() else { break };
            let mark = self.out.len();
            if !first {
                self.out.push(',');
            }
            let _ = write!(self.out, "\"{m}\":");
            if put(self.out, x) {
                first = false;
            } else {
                self.out.truncate(mark);
            }
        }
        self.out.push('}');
        self
    }

    fn end(&mut self) {
        debug_assert!(self.fields.len() == 0, "fields left: {:?}", self.fields);
        self.out.push('}');
    }
}

/// A number as JSON: its type's shortest round-trip decimal (an f32 as the f32's digits,
/// `0.1`, not the widened `0.10000000149011612`: the value the law had, in fewer bytes). A
/// number that is not finite has no JSON: the message leaves it out (Choice 480).
pub trait JsonNumber: Copy {
    fn finite(self) -> bool;
    /// Writes a finite number.
    fn put(self, out: &mut String);
}

impl JsonNumber for f64 {
    fn finite(self) -> bool {
        self.is_finite()
    }
    fn put(self, out: &mut String) {
        debug_assert!(self.is_finite());
        let _ = write!(out, "{self}");
    }
}

impl JsonNumber for f32 {
    fn finite(self) -> bool {
        self.is_finite()
    }
    fn put(self, out: &mut String) {
        debug_assert!(self.is_finite());
        let _ = write!(out, "{self}");
    }
}

/// An f32 the sample widened to f64, narrowed back (exact: it was an f32).
fn narrow(xs: &[f64]) -> impl Iterator<Item = f32> + '_ {
    xs.iter().map(|&x| x as f32)
}

/// The message of `topic` for one control period into `out` (cleared first), if the channel
/// has one this period: a navigation source only when its measurement arrived, a board's
/// channel only with a board in the loop. The event channels ([`Rate::Events`]) are written
/// by [`event`], [`supervisor`], [`refusals`] and [`upload_round`] instead.
pub fn encode(topic: Topic, r: &Record, out: &mut String) -> bool {
    match topic {
        Topic::Truth
        | Topic::Navigation
        | Topic::Reference
        | Topic::Tau
        | Topic::Thrusters
        | Topic::Law => {
            loop_message(topic, r, out);
            true
        }
        Topic::Ins | Topic::Dvl | Topic::Depth | Topic::Fix => source_message(topic, r, out),
        Topic::Link => link_message(r, out),
        Topic::Events | Topic::Supervisor | Topic::Refusals | Topic::Upload => false,
    }
}

/// A control-rate channel's message of the loop's own signals.
fn loop_message(topic: Topic, r: &Record, out: &mut String) {
    let s = r.sample;
    let spec = topic.spec();
    match topic {
        Topic::Truth => {
            Message::new(spec, out)
                .nums(s.eta)
                .nums(s.signals.nu)
                .nums(s.error)
                .num(s.payload)
                .end();
        }
        Topic::Navigation => {
            Message::new(spec, out)
                .nums(s.signals.eta_told)
                .nums(s.signals.nu_told)
                .end();
        }
        Topic::Reference => {
            Message::new(spec, out)
                .nums(narrow(&s.eta_d))
                .nums(s.signals.eta_d_dot)
                .nums(s.signals.eta_d_ddot)
                .end();
        }
        Topic::Tau => {
            Message::new(spec, out)
                .nums(narrow(&s.tau))
                .nums(s.tau_applied)
                .end();
        }
        Topic::Thrusters => {
            Message::new(spec, out)
                .nums(s.signals.thrust_demand)
                .nums(narrow(&s.voltage))
                .nums(s.thrust)
                .bools((0..THRUSTER_NAMES.len()).map(|i| s.saturated & (1 << i) != 0))
                .int(i64::from(s.saturated))
                .end();
        }
        Topic::Law => {
            let i = r.inside;
            Message::new(spec, out)
                .nums(i.e.into_iter().flatten())
                .nums(i.e_dot.into_iter().flatten())
                .num(i.e_norm.unwrap_or(f64::NAN))
                .num(s.w_norm as f32)
                .num(s.delta as f32)
                .boolean(s.delta_clamped)
                .num(i.lyapunov.unwrap_or(f64::NAN))
                .num(i.ball_radius.unwrap_or(f64::NAN))
                .text(&s.status.to_string())
                .end();
        }
        _ => debug_assert!(false, "{topic:?} is not a loop channel"),
    }
}

/// A navigation source's message, if its measurement arrived this period.
fn source_message(topic: Topic, r: &Record, out: &mut String) -> bool {
    let arrived = &r.sample.signals.navigation;
    let at = |tick: u64| tick as f64 * r.period;
    let spec = topic.spec();
    match topic {
        Topic::Ins => {
            let Some(m) = arrived.ins else { return false };
            Message::new(spec, out)
                .num(at(m.sampled_at))
                .nums(m.value[..3].iter().copied())
                .nums(m.value[3..].iter().copied())
                .end();
        }
        Topic::Dvl => {
            let Some(p) = arrived.dvl else { return false };
            Message::new(spec, out)
                .num(at(p.sampled_at))
                .boolean(p.velocity.is_some())
                .nums(p.velocity.into_iter().flatten())
                .end();
        }
        Topic::Depth => {
            let Some(m) = arrived.depth else {
                return false;
            };
            Message::new(spec, out)
                .num(at(m.sampled_at))
                .num(m.value[0])
                .end();
        }
        Topic::Fix => {
            let Some(m) = arrived.fix else { return false };
            Message::new(spec, out)
                .num(at(m.sampled_at))
                .num(m.value[0])
                .num(m.value[1])
                .end();
        }
        _ => return false,
    }
    true
}

/// The link's counters, with a board in the loop.
fn link_message(r: &Record, out: &mut String) -> bool {
    let Some(b) = &r.sample.signals.board else {
        return false;
    };
    let c = &b.counters;
    let int = |x: u64| i64::try_from(x).unwrap_or(i64::MAX);
    Message::new(Topic::Link.spec(), out)
        .int(int(c.state_frames_sent))
        .int(int(c.telemetry_frames))
        .int(int(c.telemetry_refused))
        .int(i64::from(c.rearms))
        .int(i64::from(c.rx_frames))
        .int(i64::from(c.rx_errors))
        .int(i64::from(c.rx_stale))
        .int(i64::from(c.rx_auth_errors))
        .int(i64::from(c.rx_ahead))
        .int(i64::from(c.refused_commands))
        .int(i64::from(c.loop_overruns))
        .int(i64::from(c.worst_update_ticks))
        .end();
    true
}

/// A [`Topic::Supervisor`] message into `out`: the board's `state` (its own words), the one
/// before (empty at the first answer), its tick.
pub fn supervisor(state: &str, previous: &str, board_tick: u64, out: &mut String) {
    Message::new(Topic::Supervisor.spec(), out)
        .text(state)
        .text(previous)
        .int(i64::try_from(board_tick).unwrap_or(i64::MAX))
        .end();
}

/// A [`Topic::Refusals`] message into `out`: `refused` more commands refused, the board's
/// count, its last reason.
pub fn refusals(refused: u32, count: u32, reason: &str, out: &mut String) {
    Message::new(Topic::Refusals.spec(), out)
        .int(i64::from(refused))
        .int(i64::from(count))
        .text(reason)
        .end();
}

/// A [`Topic::Upload`] message into `out`: one round of a mission's upload.
pub fn upload_round(r: &crate::sim::UploadRound, out: &mut String) {
    Message::new(Topic::Upload.spec(), out)
        .int(i64::from(r.round))
        .int(i64::from(r.chunks_sent))
        .int(i64::from(r.missing))
        .boolean(r.verified)
        .int(i64::from(r.frames))
        .int(i64::try_from(r.bytes).unwrap_or(i64::MAX))
        .num(r.seconds)
        .end();
}

/// An [`Topic::Events`] message into `out`.
pub fn event(kind: &str, status: &str, text: &str, out: &mut String) {
    Message::new(Topic::Events.spec(), out)
        .text(kind)
        .text(status)
        .text(text)
        .end();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every channel's fields are in its schema, required but for a lone number (Choice 480),
    /// and the topics and schema names are distinct: the table is a closed set indexed by
    /// [`Topic`].
    #[test]
    fn the_table_is_indexed_by_topic_and_each_schema_requires_its_fields() {
        for (i, t) in Topic::ALL.iter().enumerate() {
            assert_eq!(*t as usize, i);
            let spec = t.spec();
            let schema = json_schema(spec);
            let required: Vec<&str> = schema["required"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(Value::as_str)
                .collect();
            for f in spec.fields {
                assert!(schema["properties"][f.name].is_object(), "{}", f.name);
                let lone_number = f.members.is_none() && f.kind == Kind::Number;
                assert_eq!(required.contains(&f.name), !lone_number, "{}", f.name);
            }
        }
        let mut topics: Vec<_> = CHANNELS.iter().map(|c| c.topic).collect();
        topics.sort_unstable();
        topics.dedup();
        assert_eq!(topics.len(), CHANNELS.len());
    }

    /// Every `type` in every channel's schema, at any depth, is one string of the six Foxglove
    /// Studio's JSON Schema reader takes (`boolean`, `string`, `number`, `integer`, `object`,
    /// `array`: its `parseJsonSchema` switches on a single `type` and refuses anything else,
    /// `["number", "null"]` included, so the channel's messages cannot be plotted). Choice 480.
    #[test]
    fn every_type_in_the_schemas_is_one_foxglove_reads() {
        fn walk(v: &Value, at: &str, bad: &mut Vec<String>) {
            match v {
                Value::Object(m) => {
                    if let Some(t) = m.get("type") {
                        let ok = ["boolean", "string", "number", "integer", "object", "array"];
                        if !t.as_str().is_some_and(|t| ok.contains(&t)) {
                            bad.push(format!("{at}: {t}"));
                        }
                    }
                    for (k, sub) in m {
                        walk(sub, &format!("{at}.{k}"), bad);
                    }
                }
                Value::Array(xs) => xs.iter().for_each(|x| walk(x, at, bad)),
                _ => {}
            }
        }
        let mut bad = Vec::new();
        for spec in &CHANNELS {
            walk(&json_schema(spec), spec.topic, &mut bad);
        }
        assert!(bad.is_empty(), "types Foxglove refuses: {bad:?}");
    }

    /// A number that is not finite is left out of its message, name and all, in a lone field
    /// and in a group; what is left is JSON the schema takes (its required keys all there).
    #[test]
    fn a_number_that_is_not_finite_is_left_out_of_its_message() {
        let mut out = String::new();
        Message::new(Topic::Depth.spec(), &mut out)
            .num(f64::NAN)
            .num(2.5)
            .end();
        assert_eq!(out, r#"{"z":2.5}"#);
        Message::new(Topic::Depth.spec(), &mut out)
            .num(1.0)
            .num(f64::INFINITY)
            .end();
        assert_eq!(out, r#"{"t_sampled":1}"#);
        let spec = Topic::Truth.spec();
        let mut m = Message::new(spec, &mut out);
        for f in spec.fields {
            let n = f.members.map_or(1, <[_]>::len);
            let mut xs = vec![0.5f64; n];
            xs[n / 2] = f64::NAN;
            match f.members {
                Some(_) => m.nums(xs),
                None => m.num(xs[0]),
            };
        }
        m.end();
        let v: Value = serde_json::from_str(&out).expect("JSON");
        let schema = json_schema(spec);
        for f in spec.fields {
            if let Some(members) = f.members {
                let got = v[f.name].as_object().expect("a group is there");
                assert_eq!(got.len(), members.len() - 1, "{}: {got:?}", f.name);
                assert!(!got.contains_key(members[members.len() / 2]));
            }
        }
        for key in schema["required"].as_array().expect("required") {
            assert!(v.get(key.as_str().expect("a name")).is_some(), "{key}");
        }
    }
}
