//! Monte Carlo campaigns beyond one machine (docs/campaigns.md): a campaign file
//! ([`file`]) says what is drawn around which base scenarios, how many runs, the seed, the
//! metrics and the bound; a **shard** runs the indices i ≡ I (mod N) of it
//! (**Choice 131**), on any engine (Slurm array, Kubernetes Indexed Job, a laptop), and writes one
//! [`record::Record`] per run; the **merge** ([`merge`]) checks that the shards belong to the
//! same campaign and cover every index once, and summarises.
//!
//! **Run i depends only on (seed, i)** (**Choice 130**): its draw comes from ChaCha8 seeded with
//! the campaign's seed on stream i ([`Campaign::draw`]), its base is ⌊i·B/runs⌋, and it is
//! flown alone with the law built from its own scenario. Neither the shard count nor the thread
//! scheduling enters, so the records of any sharding, sorted by index, are the same bytes as
//! the one-machine run's, and so is the report made from them.

use controller_core::effectiveness::ThrusterGeometry;
use controller_core::model::{ParamVariation, VARIED_PARAMETERS};
use controller_core::uncertainty::ParamBox;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use sha2::{Digest, Sha256};

use crate::plant::{CurrentModel, VariationProfile};
use crate::scenario::file::{
    BoundTable, CurrentName, CurrentTable, ProfileName, ScenarioFile, VariationTable,
};
use crate::scenario::navigation::NavigationTable;
use crate::scenario::{Scenario, ScenarioError};
use crate::sim::{self, LocalController, Metrics, Recording};

pub mod file;
pub mod merge;
pub mod record;
pub mod shard;

pub use file::{Base, CampaignError, CampaignSpec, ParameterDraw, PlantStep, STUDY_PATH_TOLERANCE};
pub use record::{Outcome, Record};
pub use shard::{Done, Shard};

/// The metrics a campaign can report, in the order of the records' columns (the one name
/// table, [`Metrics::NAMES`]).
pub const METRIC_NAMES: [&str; 13] = Metrics::NAMES;

/// What run i drew. Everything is drawn for every run, in a fixed order (new keys draw after
/// the old ones), whether the campaign
/// uses it or not, so that what one key draws never shifts another's numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct Draw {
    /// Δp (the base's when parameters are not drawn: zeros).
    pub variation: [f64; VARIED_PARAMETERS],
    /// The constant current (north, east, down), m/s; zeros when not drawn.
    pub current: [f64; 3],
    /// The seed of the run's sensor noise (the base's `[noise]` seed when not drawn). Drawn,
    /// it seeds both `[noise]` and the navigation model (**Choice 460**).
    pub noise_seed: u64,
    /// The start offset, the base's plus the drawn one.
    pub initial_offset: [f64; 6],
    /// The mission's time scale (the base's when not drawn).
    pub time_scale: f32,
    /// The reversed-thruster mask of the mounting ([`ThrusterGeometry::auv150`]); the base's
    /// when not drawn ([`NOT_AUV150_LAYOUT`] if its geometry is not the AUV-150 layout).
    pub mounting: u8,
}

/// [`Draw::mounting`] of a base whose geometry is not the AUV-150 layout with some thrusters
/// reversed.
pub const NOT_AUV150_LAYOUT: u8 = u8::MAX;

/// A campaign, loaded and checked: its spec, its bases, and its hash.
#[derive(Clone, Debug)]
pub struct Campaign {
    pub spec: CampaignSpec,
    pub bases: Vec<Base>,
    /// The campaign file's text, as read.
    pub text: String,
    /// sha256 (hex) of the canonical campaign, the bases' texts and the program version.
    pub hash: String,
    /// The masks of `draw.mountings`, checked.
    masks: Option<Vec<u8>>,
}

/// The program version in the campaign's hash (a shard of another build does not merge).
pub const PROGRAM_VERSION: &str = concat!("host-sim ", env!("CARGO_PKG_VERSION"));

impl Campaign {
    /// A campaign from its file's text, its spec and its bases.
    pub fn new(text: String, spec: CampaignSpec, bases: Vec<Base>) -> Self {
        let hash = hash(&spec, &bases);
        // Checked when the file was parsed.
        let masks = spec
            .draw
            .mountings
            .as_deref()
            .and_then(|m| file::mounting_masks(m).ok());
        Campaign {
            spec,
            bases,
            text,
            hash,
            masks,
        }
    }

    /// Reads a campaign file and its bases.
    pub fn load(path: &std::path::Path) -> Result<Self, CampaignError> {
        let (text, spec, bases) = file::load(path)?;
        Ok(Campaign::new(text, spec, bases))
    }

    /// The campaign a shard's manifest keeps (its texts), checked and hashed again.
    pub fn from_manifest(m: &merge::Manifest) -> Result<Self, CampaignError> {
        let (spec, bases) = file::from_texts(&m.campaign_text, &m.name, &m.bases)?;
        Ok(Campaign::new(m.campaign_text.clone(), spec, bases))
    }

    pub fn runs(&self) -> u64 {
        self.spec.runs
    }

    /// The base run `i` flies: ⌊i·B/runs⌋, equal blocks of indices.
    pub fn base_of(&self, i: u64) -> usize {
        (u128::from(i) * self.bases.len() as u128 / u128::from(self.spec.runs)) as usize
    }

    /// Run `i`'s draw: ChaCha8 seeded from the campaign's seed, on stream `i`.
    pub fn draw(&self, i: u64) -> Draw {
        let mut rng = ChaCha8Rng::seed_from_u64(self.spec.seed);
        rng.set_stream(i);
        let d = &self.spec.draw;
        let base = self.bases[self.base_of(i)].scenario.config();
        let f: [f64; VARIED_PARAMETERS] = std::array::from_fn(|_| rng.random::<f64>());
        let corner: [bool; VARIED_PARAMETERS] = std::array::from_fn(|_| rng.random::<bool>());
        let (speed, dir) = (rng.random::<f64>(), rng.random::<f64>());
        // A TOML integer is an i64: the seed stays within it (the worst case's file).
        let noise_seed = rng.random::<u64>() >> 1;
        let offset: [f64; 6] = std::array::from_fn(|_| rng.random::<f64>());
        let k = rng.random::<f64>();
        let m = rng.random::<u64>();
        let variation = match d.parameters {
            ParameterDraw::None => [0.0; VARIED_PARAMETERS],
            ParameterDraw::Uniform => ParamBox::table3().lerp(&f).to_array(),
            ParameterDraw::Corners => ParamBox::table3()
                .lerp(&corner.map(|c| f64::from(u8::from(c))))
                .to_array(),
        };
        let current = match d.current {
            Some(vmax) => {
                let (s, a) = (vmax * speed, std::f64::consts::TAU * dir);
                [s * a.cos(), s * a.sin(), 0.0]
            }
            None => [0.0; 3],
        };
        let mut initial_offset = base.initial_offset;
        if let Some(w) = d.initial_offset {
            for j in 0..6 {
                initial_offset[j] += w[j] * (2.0 * offset[j] - 1.0);
            }
        }
        Draw {
            variation,
            current,
            noise_seed: match (&base.noise, d.noise_seed) {
                (_, true) => noise_seed,
                (Some(n), false) => n.seed,
                (None, false) => 0,
            },
            initial_offset,
            time_scale: match d.time_scale {
                Some([lo, hi]) => (lo + (hi - lo) * k).clamp(lo, hi) as f32,
                None => base.time_scale,
            },
            mounting: match &self.masks {
                Some(masks) => masks[(m % masks.len() as u64) as usize],
                None => base
                    .controller
                    .geometry
                    .auv150_reversed()
                    .unwrap_or(NOT_AUV150_LAYOUT),
            },
        }
    }

    /// The name of run `i`'s scenario: `{campaign}-{i}`.
    pub fn run_name(&self, i: u64) -> String {
        format!("{}-{i}", self.spec.name())
    }

    /// Run `i`'s scenario: its base with the draw applied (and the campaign's bound).
    pub fn scenario(&self, i: u64, d: &Draw) -> Result<Scenario, ScenarioError> {
        let spec = &self.spec;
        self.bases[self.base_of(i)].scenario.with(|c| {
            c.name = self.run_name(i);
            if let Some(step) = spec.plant_step {
                // Choice 400: study-grade flight.
                step.apply(c);
            }
            if let Some(draws) = spec.noise_draws {
                c.noise_draws = draws;
            }
            if spec.draw.parameters != ParameterDraw::None {
                c.variation = VariationProfile::Constant(ParamVariation::from_array(d.variation));
            }
            if spec.draw.current.is_some() {
                c.current = CurrentModel::Constant(d.current);
            }
            if spec.draw.noise_seed {
                // Choice 460: the drawn seed seeds every noise the run's navigation makes, the
                // navigation model's as much as `[noise]`'s (each source of the model draws
                // from its own generator, seeded apart from `[noise]`'s: navigation.rs).
                if let Some(n) = c.noise.as_mut() {
                    n.seed = d.noise_seed;
                }
                if let Some(m) = c.navigation.as_mut() {
                    m.seed = d.noise_seed;
                }
            }
            c.initial_offset = d.initial_offset;
            c.time_scale = d.time_scale;
            if spec.draw.mountings.is_some() {
                c.controller.geometry = ThrusterGeometry::auv150(d.mounting);
            }
            if let Some(b) = spec.bound() {
                c.bound_setting = Some(b);
            }
        })
    }

    /// Flies run `i` (metrics only) and records it; `None` if it was interrupted (it is not
    /// recorded, and a rerun of the shard does it again). A draw that makes an invalid
    /// scenario (a drawn offset beyond the divergence limit, say) is recorded as such.
    pub fn fly(&self, i: u64) -> Option<Record> {
        let d = self.draw(i);
        let base = self.base_of(i);
        let scenario = match self.scenario(i, &d) {
            Ok(s) => s,
            Err(e) => return Some(Record::invalid(i, base, d, e.to_string())),
        };
        let r = sim::fly(
            &scenario,
            &mut LocalController::new(&scenario),
            &mut (),
            Recording::MetricsOnly,
        );
        if r.interrupted() {
            return None;
        }
        Some(Record::of(i, base, d, &r))
    }
}

/// The campaign's hash: sha256 over a version tag, [`PROGRAM_VERSION`], the spec in its
/// canonical form (JSON of the parsed file: comments, spacing and key order do not count) and
/// every base's text (the bytes the runs parse).
fn hash(spec: &CampaignSpec, bases: &[Base]) -> String {
    let mut h = Sha256::new();
    h.update(b"auv150 campaign v1\n");
    h.update(PROGRAM_VERSION.as_bytes());
    h.update(b"\n");
    // A spec always serialises (plain data).
    h.update(serde_json::to_string(spec).unwrap_or_default().as_bytes());
    for b in bases {
        h.update(b"\n--base ");
        h.update(b.path.as_bytes());
        h.update(format!(" {}\n", b.text.len()).as_bytes());
        h.update(b.text.as_bytes());
    }
    hex(h)
}

/// A sha256's digest in lower-case hex.
pub(crate) fn hex(h: Sha256) -> String {
    h.finalize()
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<String>()
}

impl Campaign {
    /// Run `i`'s scenario as a TOML file that `host-sim run` flies bit for bit as the campaign
    /// did (**Choice 134**): its base's file as written ([`ScenarioFile`]) with the draw written
    /// in (`[variation]` constant, `[current]` constant, the noise seed, `initial_offset`,
    /// `trajectory.time_scale`, the campaign's `[bound]`) and the run's name, serialized
    /// ([`ScenarioFile::to_toml`]). Numbers are written in their shortest exact form, so the
    /// file reads back to the same f64.
    pub fn scenario_text(&self, i: u64, d: &Draw) -> Result<String, String> {
        let base = &self.bases[self.base_of(i)];
        let mut file =
            ScenarioFile::from_toml(&base.text).map_err(|e| format!("base {}: {e}", base.path))?;
        file.name = Some(self.run_name(i));
        if let Some(step) = self.spec.plant_step {
            // Choice 460: a study-grade run (Choice 400) replays at its own step.
            let mut c = base.scenario.config().clone();
            step.apply(&mut c);
            file.plant_step = Some(c.plant_step);
            file.plant_integrator = Some(c.plant_integrator.name().into());
        }
        if let Some(draws) = self.spec.noise_draws {
            // Choice 536: a run of study-grade noise replays with its draws.
            file.noise_draws = Some(draws.name().into());
        }
        if self.spec.draw.parameters != ParameterDraw::None {
            file.variation = Some(VariationTable {
                profile: ProfileName::Constant,
                trimmed: file.variation.and_then(|v| v.trimmed),
                omega: None,
                delta: d.variation.map(Some),
                steps: None,
            });
        }
        if self.spec.draw.current.is_some() {
            file.current = Some(CurrentTable {
                velocity: Some(d.current),
                ..CurrentTable::new(CurrentName::Constant)
            });
        }
        if self.spec.draw.noise_seed {
            if let Some(n) = file.noise.as_mut() {
                n.seed = Some(d.noise_seed);
            }
            // Choice 460: the navigation model's seed, written in; a base without the table
            // flies the real chain's default preset, which the table names.
            if let Some(m) = &base.scenario.config().navigation {
                file.navigation
                    .get_or_insert_with(|| NavigationTable {
                        preset: Some(m.preset),
                        ..NavigationTable::default()
                    })
                    .seed = Some(d.noise_seed);
            }
        }
        file.initial_offset = Some(d.initial_offset);
        if self.spec.draw.mountings.is_some() {
            let names = file::mounting_names(d.mounting);
            file.controller.get_or_insert_default().reversed_thrusters =
                Some(names.iter().map(|n| n.to_string()).collect());
        }
        file.trajectory.time_scale = Some(f64::from(d.time_scale));
        if let Some(b) = self.spec.bound() {
            file.bound = Some(BoundTable::from(b));
        }
        let header = format!(
            "# Run {i} of campaign {} (hash {}), written by `host-sim campaign merge`:\n\
             # its base {} with the run's draw. `host-sim run --scenario` on this file flies\n\
             # the campaign's run bit for bit.\n",
            self.spec.name(),
            self.hash,
            base.path
        );
        file.to_toml()
            .map(|body| header + &body)
            .map_err(|e| e.to_string())
    }

    /// Runs the runs of `shard` not in `done` in parallel (rayon), handing each record to
    /// `sink` as it is made (in completion order; the merge sorts). The indices are iterated,
    /// not listed (Choice 244). Runs not started when a stop is requested are not run.
    pub fn run_shard(&self, shard: Shard, done: &Done, sink: impl Fn(Record) + Sync) {
        use rayon::prelude::*;
        // An error stops rayon from starting more: an interrupted shard of 10⁹ runs does not
        // walk the rest of its indices.
        let _ = (0..shard.len())
            .into_par_iter()
            .map(|k| shard.run(k))
            .filter(|i| !done.contains(*i))
            .try_for_each(|i| {
                if crate::interrupt::requested() {
                    return Err(());
                }
                if let Some(r) = self.fly(i) {
                    sink(r);
                }
                Ok(())
            });
    }

    /// The shard `index`/`count` of this campaign.
    pub fn shard(&self, index: u64, count: u64) -> Shard {
        Shard {
            runs: self.runs(),
            index,
            count,
        }
    }

    /// The bound run `i` is held to: the campaign's, else its base's ([`Campaign::scenario`]
    /// sets the campaign's on the base).
    pub fn bound_of(&self, i: u64) -> Option<crate::scenario::Bound> {
        self.spec
            .bound()
            .or_else(|| self.bases[self.base_of(i)].scenario.config().bound())
    }

    /// Seconds of CPU per run, from one calibration run of each base
    /// ([`crate::studies::montecarlo::CALIBRATION_SECONDS`] of simulated time), scaled by plant
    /// steps to the bases' durations and averaged over the bases as the runs use them.
    pub fn calibrate(&self) -> Result<f64, ScenarioError> {
        let mut total = 0.0;
        for b in &self.bases {
            total += crate::studies::montecarlo::Calibration::of(&b.scenario)?.seconds_per_run;
        }
        Ok(total / self.bases.len() as f64)
    }
}
