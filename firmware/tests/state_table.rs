//! The supervisor's state table, as firmware/README.md writes it ("State machine"), walked cell
//! by cell: the test parses the table from the README, so the documentation and the test
//! cannot drift apart. Every (state, event) pair must have exactly one cell.
//!
//! A cell is comma-separated: the next state first (`fail-safe (REASON)` when the event latches
//! the fail-safe for REASON), then what the event does besides: `on` / `off` (period events
//! only: the thrusters this period), `refused: REASON` (the command is refused, counted, and
//! REASON is `Refusal::as_str`), `dropped` (the frame is counted in `rx_stale`), `rx error`
//! (counted in `rx_errors`). Whatever a cell does not say must not happen: no refusal, nothing
//! counted, and the latched reason is kept exactly when the next state is latched.

use auv_link::{
    Command, ConfigPatch, FailSafeReason, MissionPlan, MissionSpec, Msg, Refusal, UploadPart,
};
use controller_core::effectiveness::THRUSTERS;
use firmware::board::{self, LinkBuffers};
use firmware::supervisor::{Mode, Supervisor};

mod common;
use common::{state, supervisor, Host, CIRCLE, NOW};

const README: &str = include_str!("../README.md");
/// The line after which the table starts.
const MARKER: &str = "<!-- state table: parsed by firmware/tests/state_table.rs -->";

// The harness's valid upload (a three-point waypoint mission, one chunk), shared with the
// supervisor fuzz target.
#[path = "common/supervisor_ops.rs"]
mod supervisor_ops;
use supervisor_ops::three_points;

/// The events, as the table's first column names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Event {
    Arm,
    Disarm,
    StartMission,
    StartMissionInvalid,
    StartMissionNotUploaded,
    StopMission,
    Upload,
    UploadInvalid,
    SetConfig,
    SetConfigInvalid,
    StateInOrder,
    StateRepeated,
    FrameCorrupt,
    PeriodFresh,
    PeriodStale,
    PeriodFault,
    PeriodOverrun,
}

impl Event {
    const ALL: [Event; 17] = [
        Event::Arm,
        Event::Disarm,
        Event::StartMission,
        Event::StartMissionInvalid,
        Event::StartMissionNotUploaded,
        Event::StopMission,
        Event::Upload,
        Event::UploadInvalid,
        Event::SetConfig,
        Event::SetConfigInvalid,
        Event::StateInOrder,
        Event::StateRepeated,
        Event::FrameCorrupt,
        Event::PeriodFresh,
        Event::PeriodStale,
        Event::PeriodFault,
        Event::PeriodOverrun,
    ];

    fn name(self) -> &'static str {
        match self {
            Event::Arm => "Arm",
            Event::Disarm => "Disarm",
            Event::StartMission => "StartMission",
            Event::StartMissionInvalid => "StartMission, invalid",
            Event::StartMissionNotUploaded => "StartMission, not uploaded",
            Event::StopMission => "StopMission",
            Event::Upload => "Upload",
            Event::UploadInvalid => "Upload, invalid",
            Event::SetConfig => "SetConfig",
            Event::SetConfigInvalid => "SetConfig, invalid",
            Event::StateInOrder => "state frame, in order",
            Event::StateRepeated => "state frame, repeated or old",
            Event::FrameCorrupt => "frame corrupt",
            Event::PeriodFresh => "period, state fresh",
            Event::PeriodStale => "period, state stale",
            Event::PeriodFault => "period, controller fault",
            Event::PeriodOverrun => "period, overrun",
        }
    }

    fn is_period(self) -> bool {
        matches!(
            self,
            Event::PeriodFresh | Event::PeriodStale | Event::PeriodFault | Event::PeriodOverrun
        )
    }
}

/// One cell, parsed.
#[derive(Debug)]
struct Cell {
    next: Mode,
    latches: Option<FailSafeReason>,
    thrusters_on: Option<bool>,
    refused: Option<Refusal>,
    dropped: bool,
    rx_error: bool,
}

fn mode(name: &str) -> Option<Mode> {
    Mode::ALL.into_iter().find(|m| m.as_str() == name)
}

fn reason(name: &str) -> Option<FailSafeReason> {
    FailSafeReason::ALL.into_iter().find(|r| r.as_str() == name)
}

fn parse_cell(text: &str) -> Cell {
    let mut items = text.split(',').map(str::trim);
    let first = items.next().unwrap_or("");
    let (next, latches) = match first.strip_prefix("fail-safe (") {
        Some(r) => {
            let r = r.strip_suffix(')').unwrap_or_else(|| panic!("`{first}`"));
            (
                Mode::FailSafe,
                Some(reason(r).unwrap_or_else(|| panic!("no fail-safe reason `{r}`"))),
            )
        }
        None => (
            mode(first).unwrap_or_else(|| panic!("no state `{first}` in `{text}`")),
            None,
        ),
    };
    let mut cell = Cell {
        next,
        latches,
        thrusters_on: None,
        refused: None,
        dropped: false,
        rx_error: false,
    };
    for item in items {
        match item {
            "on" => cell.thrusters_on = Some(true),
            "off" => cell.thrusters_on = Some(false),
            "dropped" => cell.dropped = true,
            "rx error" => cell.rx_error = true,
            _ => {
                let r = item
                    .strip_prefix("refused: ")
                    .unwrap_or_else(|| panic!("unknown item `{item}` in `{text}`"));
                cell.refused =
                    Some(Refusal::from_name(r).unwrap_or_else(|| panic!("no refusal `{r}`")));
            }
        }
    }
    cell
}

/// The table: (event, state, cell) for every cell.
fn table() -> Vec<(Event, Mode, Cell)> {
    let start = README
        .find(MARKER)
        .expect("firmware/README.md has the state table marker");
    let rows: Vec<Vec<&str>> = README[start + MARKER.len()..]
        .lines()
        .skip_while(|l| l.trim().is_empty())
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim()
                .trim_matches('|')
                .split('|')
                .map(|c| c.trim().trim_matches('`').trim())
                .collect()
        })
        .collect();
    let header = &rows[0];
    let columns: Vec<Mode> = header[1..]
        .iter()
        .map(|h| mode(h).unwrap_or_else(|| panic!("no state `{h}` in the header")))
        .collect();
    assert_eq!(
        columns,
        Mode::ALL,
        "one column per state, in Mode::ALL order"
    );
    let mut cells = Vec::new();
    for row in &rows[2..] {
        let event = Event::ALL
            .into_iter()
            .find(|e| e.name() == row[0])
            .unwrap_or_else(|| panic!("no event `{}`", row[0]));
        assert_eq!(row.len(), 1 + columns.len(), "row `{}`", row[0]);
        for (m, text) in columns.iter().zip(&row[1..]) {
            cells.push((event, *m, parse_cell(text)));
        }
    }
    cells
}

/// A supervisor in `mode`, and its host, with one frame already accepted (so that "repeated"
/// has a frame to repeat). A latched fail-safe is latched by an overrun.
struct Rig {
    sup: Supervisor,
    link: LinkBuffers,
    host: Host,
    last: Vec<u8>,
}

impl Rig {
    fn send(&mut self, msg: Msg) {
        self.last = self.host.wire(msg);
        board::receive(&mut self.sup, &mut self.link, &self.last);
    }

    fn command(&mut self, c: Command) {
        self.send(Msg::Command(c));
    }

    fn new(mode: Mode) -> Rig {
        let mut r = Rig {
            sup: supervisor(),
            link: LinkBuffers::new(),
            host: Host::new(),
            last: Vec::new(),
        };
        let fly = |r: &mut Rig| {
            r.command(Command::Arm);
            r.command(Command::StartMission(CIRCLE));
            r.send(Msg::State(state(0)));
            assert!(r.sup.step(false, NOW).voltages.iter().any(|v| *v != 0.0));
        };
        match mode {
            Mode::Disarmed => r.send(Msg::State(state(0))),
            Mode::Armed => r.command(Command::Arm),
            Mode::Running => fly(&mut r),
            Mode::FailSafe | Mode::DisarmedLatched => {
                fly(&mut r);
                r.sup.step(true, NOW);
                if mode == Mode::DisarmedLatched {
                    r.command(Command::Disarm);
                }
            }
        }
        assert_eq!(r.sup.mode(), mode, "set-up");
        r
    }

    /// Applies `event`; returns the period's voltages for period events.
    fn apply(&mut self, event: Event) -> Option<[f32; THRUSTERS]> {
        let invalid_mission = MissionSpec::Circle {
            radius: -1.0,
            omega: 0.1,
            depth: 5.0,
        };
        match event {
            Event::Arm => self.command(Command::Arm),
            Event::Disarm => self.command(Command::Disarm),
            Event::StartMission => self.command(Command::StartMission(CIRCLE)),
            Event::StartMissionInvalid => {
                self.command(Command::StartMission(invalid_mission.into()))
            }
            Event::StartMissionNotUploaded => self.command(Command::StartMission(MissionPlan {
                path: MissionSpec::Waypoints {
                    crc: three_points().crc(),
                },
                ..CIRCLE
            })),
            Event::StopMission => self.command(Command::StopMission),
            Event::Upload => {
                self.command(Command::Upload(UploadPart::Begin(three_points().header())))
            }
            Event::UploadInvalid => {
                self.command(Command::Upload(UploadPart::Chunk(three_points().chunk(0))))
            }
            Event::SetConfig => self.command(Command::SetConfig(ConfigPatch {
                stale_periods: Some(3),
                ..ConfigPatch::EMPTY
            })),
            Event::SetConfigInvalid => self.command(Command::SetConfig(ConfigPatch {
                voltage_limit: Some(100.0),
                ..ConfigPatch::EMPTY
            })),
            Event::StateInOrder => self.send(Msg::State(state(1))),
            Event::StateRepeated => {
                let again = self.last.clone();
                board::receive(&mut self.sup, &mut self.link, &again);
            }
            Event::FrameCorrupt => {
                let mut w = self.host.wire(Msg::Command(Command::Disarm));
                let mid = w.len() / 2;
                w[mid] ^= 0x20;
                board::receive(&mut self.sup, &mut self.link, &w);
            }
            Event::PeriodFresh => {
                self.send(Msg::State(state(1)));
                return Some(self.sup.step(false, NOW).voltages);
            }
            Event::PeriodStale => {
                // The periods the last frame still covers, then the one it does not.
                for _ in 0..self.sup.stale_periods() {
                    self.sup.step(false, NOW);
                }
                return Some(self.sup.step(false, NOW).voltages);
            }
            Event::PeriodFault => {
                let mut bad = state(1);
                bad.eta[2] = f32::NAN;
                self.send(Msg::State(bad));
                return Some(self.sup.step(false, NOW).voltages);
            }
            Event::PeriodOverrun => {
                self.send(Msg::State(state(1)));
                return Some(self.sup.step(true, NOW).voltages);
            }
        }
        None
    }
}

#[test]
fn every_cell_of_the_documented_state_table_holds() {
    let cells = table();
    // Exactly one cell per (event, state).
    assert_eq!(cells.len(), Event::ALL.len() * Mode::ALL.len());
    for e in Event::ALL {
        for m in Mode::ALL {
            let n = cells
                .iter()
                .filter(|(ce, cm, _)| *ce == e && *cm == m)
                .count();
            assert_eq!(n, 1, "{} × {}", e.name(), m.as_str());
        }
    }
    for (event, from, cell) in &cells {
        let at = format!("{} × {}", event.name(), from.as_str());
        assert_eq!(
            cell.thrusters_on.is_some(),
            event.is_period(),
            "{at}: `on`/`off` exactly on period events"
        );
        let mut r = Rig::new(*from);
        let latched_before = r.sup.latched();
        let (refused, stale, errors) = (
            r.sup.refused_commands(),
            r.sup.rx_stale(),
            r.sup.rx_errors(),
        );
        let voltages = r.apply(*event);

        assert_eq!(r.sup.mode(), cell.next, "{at}: next state");
        let want_latched = match (cell.latches, cell.next) {
            (Some(reason), _) => Some(reason),
            (None, Mode::FailSafe | Mode::DisarmedLatched) => latched_before,
            (None, _) => None,
        };
        assert_eq!(r.sup.latched(), want_latched, "{at}: latched reason");
        if let (Some(v), Some(on)) = (voltages, cell.thrusters_on) {
            assert_eq!(v.iter().any(|x| *x != 0.0), on, "{at}: thrusters {v:?}");
        }
        match cell.refused {
            Some(why) => {
                assert_eq!(r.sup.refused_commands(), refused + 1, "{at}: refused");
                assert_eq!(r.sup.last_refusal(), Some(why), "{at}: reason");
            }
            None => assert_eq!(r.sup.refused_commands(), refused, "{at}: not refused"),
        }
        assert_eq!(
            r.sup.rx_stale() - stale,
            u32::from(cell.dropped),
            "{at}: dropped"
        );
        assert_eq!(
            r.sup.rx_errors() - errors,
            u32::from(cell.rx_error),
            "{at}: rx error"
        );
    }
}

#[test]
fn the_table_parser_reads_what_it_is_given() {
    let c = parse_cell("fail-safe (stale state), off");
    assert_eq!(
        (c.next, c.latches, c.thrusters_on),
        (
            Mode::FailSafe,
            Some(FailSafeReason::StaleState),
            Some(false)
        )
    );
    let c = parse_cell("armed, refused: while armed");
    assert_eq!(
        (c.next, c.refused),
        (Mode::Armed, Some(Refusal::WhileArmed))
    );
    let c = parse_cell("disarmed (latched), dropped");
    assert!(c.next == Mode::DisarmedLatched && c.dropped && !c.rx_error);
}
