//! The scenario file's one type, `ScenarioFile`: the example that shows every knob names
//! exactly its keys; a configuration written through it reads back to itself; whatever a
//! writer puts in (quotes, newlines, 1e308) comes back as data.

mod common;

use std::collections::BTreeSet;
use std::path::Path;

use controller_core::trajectory::{Circle, FigureEight, Helix, LawnMower, SpeedList, WaypointList};
use controller_core::{Table1Case, TrajectoryKind};
use host_sim::scenario::file::{
    AttitudeName, BBoundName, BoundTable, ControllerTable, CurrentName, CurrentTable,
    EstimatorName, HeadingName, LawName, LinkFaultsTable, NoiseTable, ProfileName, StepTable,
    ThrustUnitName, TrajectoryTable, VariationTable,
};
use host_sim::scenario::navigation::{self, ErrorModel, NavigationModel, Preset, Source};
use host_sim::scenario::{
    load_config, load_scenario, paper, parse_scenario, KeyPath, ScenarioError, ScenarioFile,
    SimConfig,
};
use proptest::prelude::*;

use common::scenarios_dir;

/// Every key a TOML text names, commented out or not, as `table.key` (`key` at the top level):
/// a line `[table]`/`[[table]]` (after any `#`) opens a table, a line `key = …` (after any `#`,
/// `key` in lower case) names a key. A hand-made reading of the example, independent of the
/// `toml` crates.
fn keys_named(text: &str) -> BTreeSet<String> {
    let mut keys = BTreeSet::new();
    let mut table = String::new();
    for line in text.lines() {
        let line = line.trim_start_matches(|c: char| c == '#' || c.is_whitespace());
        if let Some(rest) = line.strip_prefix('[') {
            let name = rest.trim_start_matches('[');
            table = name[..name.find(']').unwrap_or(name.len())].to_string();
            continue;
        }
        let Some((key, _)) = line.split_once('=') else {
            continue;
        };
        let key = key.trim_end();
        let is_key = !key.is_empty()
            && key
                .chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_');
        if is_key {
            keys.insert(match table.as_str() {
                "" => key.to_string(),
                t => format!("{t}.{key}"),
            });
        }
    }
    keys
}

/// The keys of a written file as `table.key`: a table or an array of tables is not a key
/// itself, its keys are (`variation.steps.until`).
fn keys_written(table: &toml::Table, prefix: &str, out: &mut BTreeSet<String>) {
    for (key, value) in table {
        let path = match prefix {
            "" => key.clone(),
            p => format!("{p}.{key}"),
        };
        match value {
            toml::Value::Table(t) => keys_written(t, &path, out),
            toml::Value::Array(a) if a.iter().all(toml::Value::is_table) && !a.is_empty() => {
                for t in a.iter().filter_map(toml::Value::as_table) {
                    keys_written(t, &path, out);
                }
            }
            _ => {
                out.insert(path);
            }
        }
    }
}

/// One path of each kind, every optional key given and every defaulted key off its default (so
/// that the writer, which leaves defaults out, writes it). The match below does not compile
/// when a kind is added: add it here.
fn one_of_each_kind() -> Vec<TrajectoryKind> {
    let points = WaypointList::new(&[[0.0, 0.0, 5.0], [50.0, 0.0, 5.0], [50.0, 30.0, 5.0]]);
    let kinds = vec![
        TrajectoryKind::Circle(Circle {
            radius: 10.0,
            omega: 0.2,
            depth: 6.0,
        }),
        TrajectoryKind::FigureEight(FigureEight {
            amplitude: 15.0,
            omega: 0.2,
            depth: 6.0,
        }),
        TrajectoryKind::LawnMower(LawnMower {
            scale: 1.0,
            omega: 0.2,
            depth: 6.0,
        }),
        TrajectoryKind::Helix(Helix {
            radius: 10.0,
            omega: 0.2,
            depth: 6.0,
            depth_rate: 0.05,
        }),
        TrajectoryKind::Waypoints {
            points: points.unwrap(),
            speed: 0.5,
            turn_radius: Some(2.5),
            speeds: Some(SpeedList::new(&[0.5, 0.4, 0.5]).unwrap()),
            speed_change: Some(0.04),
        },
    ];
    for k in &kinds {
        match k {
            TrajectoryKind::Circle(_)
            | TrajectoryKind::FigureEight(_)
            | TrajectoryKind::LawnMower(_)
            | TrajectoryKind::Helix(_)
            | TrajectoryKind::Waypoints { .. } => {}
        }
    }
    kinds
}

/// A file with every key of the type given, one per path kind. Every struct is written out in
/// full (no `..`): a key added to the type does not compile here until it is given.
fn every_key(path: TrajectoryKind) -> ScenarioFile {
    let delta = [Some(1.0); 9];
    ScenarioFile {
        name: Some("n".into()),
        table1_case: Some("circular-10R".into()),
        duration: Some(1.0),
        plant_step: Some(1.0),
        plant_integrator: Some("midpoint".into()),
        noise_draws: Some("at-samples".into()),
        ideal_actuators: Some(true),
        initial_offset: Some([0.0; 6]),
        divergence_limit: Some(1.0),
        thruster_lag: Some(1.0),
        expect_faults: Some(true),
        initial_attitude: Some(AttitudeName::Trim),
        expect_missed: Some(true),
        trajectory: TrajectoryTable {
            path,
            heading: Some(HeadingName::Tangent),
            time_scale: Some(1.0),
            origin: Some([0.0; 3]),
            speed_limits: Some(vec![1.0]),
        },
        variation: Some(VariationTable {
            profile: ProfileName::Staircase,
            trimmed: Some(true),
            omega: Some(1.0),
            delta,
            steps: Some(vec![StepTable {
                until: Some(1.0),
                delta,
            }]),
        }),
        current: Some(CurrentTable {
            model: CurrentName::GaussMarkov,
            velocity: Some([0.0; 3]),
            mean: Some([0.0; 3]),
            sigma: Some([0.0; 3]),
            tau: Some(1.0),
            seed: Some(1),
        }),
        noise: Some(NoiseTable {
            eta_sigma: Some([0.0; 6]),
            nu_sigma: Some([0.0; 6]),
            seed: Some(1),
        }),
        navigation: Some({
            let mut m = NavigationModel::preset(Preset::Survey, 1).unwrap();
            m.dvl.seabed_depth = Some(30.0);
            m.fix = Some(m.depth.clone()).map(|d| Source {
                timing: d.timing,
                error: ErrorModel::EXACT,
            });
            navigation::table(&m)
        }),
        controller: Some(ControllerTable {
            robust: Some(true),
            law: Some(LawName::Discontinuous),
            k1: Some([1.0; 6]),
            k2: Some([1.0; 6]),
            q: Some([1.0; 2]),
            beta: Some(0.5),
            mu: Some(1.0),
            delta_max: Some(1.0),
            rate_hz: Some(100),
            pitch_limit_deg: Some(80.0),
            voltage_limit: Some(24.0),
            b_bound: Some(BBoundName::Literal),
            thrust_unit: Some(ThrustUnitName::Newton),
            axis_priority: Some(vec!["pitch".into()]),
            reversed_thrusters: Some(vec![]),
            estimator: Some(EstimatorName::Kalman),
            estimator_position_sigma: Some([1.0; 6]),
            estimator_velocity_sigma: Some([1.0; 6]),
            estimator_accel_sigma: Some([1.0; 6]),
        }),
        bound: Some(BoundTable {
            max_path: Some(1.0),
            saturated: Some(1.0),
            max_reversals_per_s: Some(3.0),
            max_command_tv: Some(50.0),
        }),
        link_faults: Some(LinkFaultsTable {
            drop: Some(vec![]),
            corrupt: Some(vec![]),
            delay: Some(vec![]),
            delay_ticks: Some(1),
            silent: Some(vec![]),
            lose_upload_chunks: Some(vec![]),
        }),
    }
}

/// The example that shows every knob, `scenarios/example-all-knobs.toml`, names exactly the
/// keys `ScenarioFile` writes (over every path kind): a key added to the type and not to the
/// example, or shown in the example and not read, fails here. And the example loads.
#[test]
fn the_all_knobs_example_names_exactly_the_types_keys() {
    let mut written = BTreeSet::new();
    for path in one_of_each_kind() {
        let text = every_key(path).to_toml().unwrap();
        keys_written(&toml::from_str(&text).unwrap(), "", &mut written);
    }
    let example = keys_named(
        &std::fs::read_to_string(scenarios_dir().join("example-all-knobs.toml")).unwrap(),
    );
    // The reader of the example works: it finds the keys the example uncomments and the
    // commented-out ones.
    assert!(
        example.contains("trajectory.kind") && example.contains("table1_case"),
        "{example:?}"
    );
    let only_type: Vec<_> = written.difference(&example).collect();
    let only_example: Vec<_> = example.difference(&written).collect();
    assert!(
        only_type.is_empty() && only_example.is_empty(),
        "keys the type writes and the example does not show: {only_type:?}; keys only in \
         example-all-knobs.toml: {only_example:?}"
    );
    load_scenario(&scenarios_dir().join("example-all-knobs.toml")).unwrap();
}

/// The paths a writer lays out itself (`KeyPath`) are where the type writes them.
#[test]
fn every_key_path_a_writer_lays_out_is_in_the_written_file() {
    let waypoints = one_of_each_kind().pop().unwrap();
    let mut doc = every_key(waypoints).to_document().unwrap();
    for at in KeyPath::ALL {
        let entry = doc.entry(at).unwrap_or_else(|e| panic!("{at}: {e}"));
        assert!(entry.starts_with(&format!("{} = ", at.key)), "{entry}");
    }
}

/// Every configuration a file can describe: the shipped scenarios, the campaigns' bases and
/// the paper's cases built in code (the Table-3 staircase, abs-sin, without Δu).
fn configurations() -> Vec<SimConfig> {
    let mut out = Vec::new();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for dir in ["scenarios", "scenarios/real", "campaigns"] {
        let mut files: Vec<_> = std::fs::read_dir(root.join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| {
                let name = p.file_name().unwrap().to_string_lossy().into_owned();
                name.ends_with(".toml") && !name.ends_with(".campaign.toml")
            })
            .collect();
        files.sort();
        out.extend(files.iter().map(|p| load_config(p).unwrap()));
    }
    // Choice 542: a study-grade configuration (its integrator is written, and read back).
    let mut study = out[0].clone();
    study.plant_integrator = host_sim::plant::Integrator::Midpoint;
    out.push(study.clone());
    // Choice 536: study-grade noise draws (written, and read back).
    study.noise_draws = host_sim::sim::nav_model::NoiseDraws::AtSamples;
    out.push(study);
    for case in Table1Case::ALL {
        out.push(paper::config(case, true));
        out.push(paper::config(case, false));
    }
    assert!(out.len() > 25, "{}", out.len());
    out
}

/// A configuration written through `ScenarioFile` (either layout) reads back to the same
/// configuration, field for field: what a writer gives `run` is what it flies.
#[test]
fn a_configuration_written_as_a_file_reads_back_to_itself() {
    for config in configurations() {
        let file =
            ScenarioFile::try_from(&config).unwrap_or_else(|e| panic!("{}: {e}", config.name));
        for text in [
            file.to_toml().unwrap(),
            file.to_document().unwrap().to_string(),
        ] {
            let read = parse_scenario(&text)
                .unwrap_or_else(|e| panic!("{}: {e}\n{text}", config.name))
                .into_config();
            assert_eq!(read, config, "{}:\n{text}", config.name);
        }
        // And the file read back is the file written.
        assert_eq!(
            ScenarioFile::from_toml(&file.to_toml().unwrap()).unwrap(),
            file
        );
    }
}

/// What a file cannot say is refused by name, not written as something else.
#[test]
fn a_configuration_a_file_cannot_describe_is_refused_by_field() {
    let base = paper::config(Table1Case::Circular10R, true);
    let mut c = base.clone();
    c.controller.params.mass += 1.0;
    assert_eq!(
        ScenarioFile::try_from(&c).unwrap_err().field,
        "controller.params"
    );
    let mut c = base.clone();
    c.controller.priority.weight[0] = 2.0;
    assert_eq!(
        ScenarioFile::try_from(&c).unwrap_err().field,
        "controller.priority"
    );
    let mut c = base;
    c.allow_long_run = true;
    assert_eq!(
        ScenarioFile::try_from(&c).unwrap_err().field,
        "allow_long_run"
    );
}

/// A key of the path left to its default (the paper's ω and depth) is not written, and the
/// path's f32 numbers are written as their decimals (10.3, not 10.300000190734863).
#[test]
fn a_path_is_written_with_its_f32_decimals_and_without_its_defaults() {
    let file = ScenarioFile::new(TrajectoryKind::Circle(Circle {
        radius: 10.3,
        omega: 0.1,
        depth: 5.0,
    }));
    for text in [
        file.to_toml().unwrap(),
        file.to_document().unwrap().to_string(),
    ] {
        let t: toml::Table = toml::from_str(&text).unwrap();
        let trajectory = t["trajectory"].as_table().unwrap();
        let keys: Vec<&str> = trajectory.keys().map(String::as_str).collect();
        assert_eq!(keys, ["kind", "radius"], "{text}");
        assert_eq!(trajectory["radius"].as_float(), Some(10.3), "{text}");
    }
}

fn named(name: &str) -> ScenarioFile {
    let mut file = ScenarioFile::new(Table1Case::Circular10R.kind());
    file.name = Some(name.to_string());
    file
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        ..ProptestConfig::default()
    })]

    /// Any string a writer puts in a file (a name with quotes, newlines, `[controller]`) and
    /// any number (1e308, 5e-324) reads back as that value: the serializer quotes and escapes,
    /// and a number is never 309 digits long.
    #[test]
    fn any_name_and_number_written_reads_back_as_itself(
        name in any::<String>(),
        x in any::<f64>().prop_filter("finite", |x| x.is_finite()),
    ) {
        let mut file = named(&name);
        file.duration = Some(x);
        file.initial_offset = Some([x, -x, 0.0, 1e308, 5e-324, -0.0]);
        for text in [file.to_toml().unwrap(), file.to_document().unwrap().to_string()] {
            prop_assert_eq!(&ScenarioFile::from_toml(&text).unwrap(), &file, "{}", text);
            let doc_text = file.to_document().unwrap().to_string();
            prop_assert!(doc_text.lines().all(|l| l.len() < 200), "{}", doc_text);
        }
    }
}

/// A header comment cannot end early: a newline in it (a plan file's name) is written
/// escaped, and the file reads back without the text after it.
#[test]
fn a_header_with_a_newline_stays_a_comment() {
    let mut doc = named("n").to_document().unwrap();
    doc.set_header(&["from w\nduration = 1 #.plan".to_string()]);
    let text = doc.to_string();
    assert!(
        text.starts_with("# from w\\nduration = 1 #.plan\n"),
        "{text}"
    );
    assert_eq!(ScenarioFile::from_toml(&text).unwrap().duration, None);
}

/// A writer's numbers at its own precision must be TOML numbers, one per number of the key.
#[test]
fn a_writers_own_numbers_are_checked() {
    let waypoints = one_of_each_kind().pop().unwrap();
    let mut doc = ScenarioFile::new(waypoints).to_document().unwrap();
    let e = doc
        .set_numbers(KeyPath::POINTS, &[1.0], |x| x.to_string())
        .unwrap_err();
    assert!(matches!(e, ScenarioError::Write(_)), "{e}");
    let nine = [0.0; 9];
    let e = doc
        .set_numbers(KeyPath::POINTS, &nine, |_| "NaN".to_string())
        .unwrap_err();
    assert!(e.to_string().contains("NaN"), "{e}");
    doc.set_numbers(KeyPath::POINTS, &nine, |x| format!("{x:.3}"))
        .unwrap();
    assert!(doc.to_string().contains("[0.000, 0.000, 0.000]"), "{doc}");
}
