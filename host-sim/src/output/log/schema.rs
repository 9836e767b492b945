//! The flight log's channels, declared once (**Choice 351**, docs/logs.md#channels): each
//! channel's topic, its fields (name, kind, unit), its rate, and how a control period's
//! [`Record`] fills it. The JSON Schema of a channel ([`json_schema`]) and its messages
//! ([`encode`]) are both made from the same [`Field`] list, so they cannot drift apart; the
//! `diff` command reads the fields back by the same names.
//!
//! JSON Schema with JSON messages: what Foxglove and PlotJuggler open without a plugin
//! (**Choice 350**). A number that is not finite is written `null` (JSON has no NaN).

use std::fmt::Write as _;

use serde_json::{json, Map, Value};

use super::inside::LawInside;
use crate::sim::Sample;

/// What a field holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A number (or `null` when it is not finite, or not known this period).
    Number,
    Integer,
    Boolean,
    Text,
}

impl Kind {
    fn json_type(self) -> Value {
        match self {
            Kind::Number => json!(["number", "null"]),
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
    /// When something happens (a status change, the run's end).
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
}

impl Topic {
    pub const ALL: [Topic; 7] = [
        Topic::Truth,
        Topic::Navigation,
        Topic::Reference,
        Topic::Tau,
        Topic::Thrusters,
        Topic::Law,
        Topic::Events,
    ];

    /// The channel's declaration.
    pub fn spec(self) -> &'static ChannelSpec {
        &CHANNELS[self as usize]
    }
}

/// The plant's truth is logged at most this often (Hz): it is f64 and changes smoothly, and
/// the log of a mission stays a few MB per minute (**Choice 352**, docs/logs.md#size).
pub const TRUTH_HZ: u32 = 20;

/// Every channel, indexed by [`Topic`].
pub const CHANNELS: [ChannelSpec; 7] = [
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
                "Eq 40's X = √(μδ / (2 λ_min(Q))); 0 for Eq 26, null without Δu",
            ),
            one(
                "status",
                Kind::Text,
                "ok, or why the thrusters are off (the CSV's status)",
            ),
        ],
        rate: Rate::Control,
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
    },
];

/// The JSON Schema (draft 2020-12) of a channel: every field required.
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
                json!({
                    "type": "object",
                    "description": f.about,
                    "properties": inner,
                    "required": members,
                })
            }
        };
        properties.insert(f.name.to_string(), schema);
    }
    let required: Vec<&str> = spec.fields.iter().map(|f| f.name).collect();
    json!({
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": spec.schema,
        "description": spec.about,
        "type": "object",
        "properties": properties,
        "required": required,
    })
}

/// What one control period gives the log: the sample and the law's inside computed from it.
pub struct Record<'a> {
    pub sample: &'a Sample,
    pub inside: &'a LawInside,
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

    /// The next field's name (a comma before all but the first).
    fn key(&mut self, kind: Kind, group: bool) -> Option<&'static Field> {
        let f = self.fields.next();
        debug_assert!(
            f.is_some_and(|f| f.kind == kind && f.members.is_some() == group),
            "{f:?} is not a {kind:?} (group {group})"
        );
        let f = f?;
        if self.out.len() > 1 {
            self.out.push(',');
        }
        let _ = write!(self.out, "\"{}\":", f.name);
        Some(f)
    }

    pub fn num(&mut self, x: impl JsonNumber) -> &mut Self {
        if self.key(Kind::Number, false).is_some() {
            x.put(self.out);
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

    /// A group of numbers, one per member (missing ones `null`).
    pub fn nums<T: JsonNumber>(&mut self, xs: impl IntoIterator<Item = T>) -> &mut Self {
        self.group(Kind::Number, xs, |out, x| x.put(out))
    }

    /// A group of booleans, one per member.
    pub fn bools(&mut self, xs: impl IntoIterator<Item = bool>) -> &mut Self {
        self.group(Kind::Boolean, xs, |out, b| {
            let _ = write!(out, "{b}");
        })
    }

    fn group<T>(
        &mut self,
        kind: Kind,
        xs: impl IntoIterator<Item = T>,
        put: impl Fn(&mut String, T),
    ) -> &mut Self {
        let Some(members) = self.key(kind, true).and_then(|f| f.members) else {
            return self;
        };
        self.out.push('{');
        let mut xs = xs.into_iter();
        for (i, m) in members.iter().enumerate() {
            if i > 0 {
                self.out.push(',');
            }
            let _ = write!(self.out, "\"{m}\":");
            match xs.next() {
                Some(x) => put(self.out, x),
                None => self.out.push_str("null"),
            }
        }
        self.out.push('}');
        self
    }

    fn end(self) {
        debug_assert!(self.fields.len() == 0, "fields left: {:?}", self.fields);
        self.out.push('}');
    }
}

/// A number as JSON: its type's shortest round-trip decimal (an f32 as the f32's digits,
/// `0.1`, not the widened `0.10000000149011612`: the value the law had, in fewer bytes), and
/// `null` when it is not finite.
pub trait JsonNumber: Copy {
    fn put(self, out: &mut String);
}

impl JsonNumber for f64 {
    fn put(self, out: &mut String) {
        if self.is_finite() {
            let _ = write!(out, "{self}");
        } else {
            out.push_str("null");
        }
    }
}

impl JsonNumber for f32 {
    fn put(self, out: &mut String) {
        if self.is_finite() {
            let _ = write!(out, "{self}");
        } else {
            out.push_str("null");
        }
    }
}

/// An f32 the sample widened to f64, narrowed back (exact: it was an f32).
fn narrow(xs: &[f64]) -> impl Iterator<Item = f32> + '_ {
    xs.iter().map(|&x| x as f32)
}

/// The message of `topic` for one control period, into `out` (cleared first). [`Topic::Events`]
/// is written by [`event`] instead.
pub fn encode(topic: Topic, r: &Record, out: &mut String) {
    let s = r.sample;
    let spec = topic.spec();
    let mut m = Message::new(spec, out);
    match topic {
        Topic::Truth => {
            m.nums(s.eta)
                .nums(s.signals.nu)
                .nums(s.error)
                .num(s.payload);
        }
        Topic::Navigation => {
            m.nums(s.signals.eta_told).nums(s.signals.nu_told);
        }
        Topic::Reference => {
            m.nums(narrow(&s.eta_d))
                .nums(s.signals.eta_d_dot)
                .nums(s.signals.eta_d_ddot);
        }
        Topic::Tau => {
            m.nums(narrow(&s.tau)).nums(s.tau_applied);
        }
        Topic::Thrusters => {
            m.nums(s.signals.thrust_demand)
                .nums(narrow(&s.voltage))
                .nums(s.thrust)
                .bools((0..THRUSTER_NAMES.len()).map(|i| s.saturated & (1 << i) != 0))
                .int(i64::from(s.saturated));
        }
        Topic::Law => {
            let i = r.inside;
            m.nums(i.e.into_iter().flatten())
                .nums(i.e_dot.into_iter().flatten())
                .num(i.e_norm.unwrap_or(f64::NAN))
                .num(s.w_norm as f32)
                .num(s.delta as f32)
                .boolean(s.delta_clamped)
                .num(i.lyapunov.unwrap_or(f64::NAN))
                .num(i.ball_radius.unwrap_or(f64::NAN))
                .text(&s.status.to_string());
        }
        Topic::Events => {
            m.text("").text("").text("");
        }
    }
    m.end();
}

/// An [`Topic::Events`] message into `out`.
pub fn event(kind: &str, status: &str, text: &str, out: &mut String) {
    let mut m = Message::new(Topic::Events.spec(), out);
    m.text(kind).text(status).text(text);
    m.end();
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every channel's fields are in its schema, required, and the topics and schema names are
    /// distinct: the table is a closed set indexed by [`Topic`].
    #[test]
    fn the_table_is_indexed_by_topic_and_each_schema_requires_its_fields() {
        for (i, t) in Topic::ALL.iter().enumerate() {
            assert_eq!(*t as usize, i);
            let spec = t.spec();
            let schema = json_schema(spec);
            for f in spec.fields {
                assert!(schema["properties"][f.name].is_object(), "{}", f.name);
            }
            assert_eq!(
                schema["required"].as_array().map(Vec::len),
                Some(spec.fields.len())
            );
        }
        let mut topics: Vec<_> = CHANNELS.iter().map(|c| c.topic).collect();
        topics.sort_unstable();
        topics.dedup();
        assert_eq!(topics.len(), CHANNELS.len());
    }
}
