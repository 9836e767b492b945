//! How arbitrary bytes become inputs to `Controller::update`, and the properties every output
//! must have. Shared, as source, by the stable proptests (`controller-core/tests/update_bytes.rs`)
//! and the cargo-fuzz target (`fuzz/fuzz_targets/controller_update.rs`, through `#[path]`), so
//! the two check exactly the same thing. The layout of the bytes is documented in
//! `update_bytes.rs`.

use std::sync::OnceLock;

use controller_core::controller::{MAX_ANGLE, MAX_ANGULAR_RATE, MAX_LINEAR_SPEED, MAX_POSITION};
use controller_core::kinematics::{self, Attitude};
use controller_core::{
    Controller, ControllerConfig, Fault, Output, Status, Table1Case, Trajectory, TrajectoryKind,
};

/// `[robust off, robust on]`, built once.
fn controllers() -> &'static [Controller; 2] {
    static C: OnceLock<[Controller; 2]> = OnceLock::new();
    C.get_or_init(|| {
        let build = |robust| {
            Controller::new(ControllerConfig {
                robust,
                ..ControllerConfig::default()
            })
            .expect("default configuration is valid")
        };
        [build(false), build(true)]
    })
}

#[derive(Debug)]
struct Input {
    ticks: u64,
    eta: [f32; 6],
    nu: [f32; 6],
    case: Table1Case,
    robust: bool,
    relative: bool,
    custom: Option<TrajectoryKind>,
}

/// The closed-form kinds of `TrajectoryKind::EXAMPLES`, in declaration order.
fn closed_forms() -> Vec<TrajectoryKind> {
    TrajectoryKind::EXAMPLES
        .into_iter()
        .filter(|k| !matches!(k, TrajectoryKind::Waypoints { .. }))
        .collect()
}

/// The most parameters any of `kinds` has: the words the input holds for them.
fn max_parameters(kinds: &[TrajectoryKind]) -> usize {
    let count = |mut k: TrajectoryKind| {
        let mut n = 0;
        k.parameters(&mut |_, _| n += 1);
        n
    };
    kinds.iter().map(|k| count(*k)).max().unwrap_or(0)
}

/// Reads the input front to back; past the end every byte is zero.
struct Reader<'a> {
    data: &'a [u8],
    pos: usize,
}

impl Reader<'_> {
    fn bytes<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        for b in out.iter_mut() {
            *b = self.data.get(self.pos).copied().unwrap_or(0);
            self.pos += 1;
        }
        out
    }
    fn u8(&mut self) -> u8 {
        self.bytes::<1>()[0]
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.bytes())
    }
    fn u64(&mut self) -> u64 {
        u64::from_le_bytes(self.bytes())
    }
}

fn to_f32(bits: u32, scaled: bool, limit: f32) -> f32 {
    if scaled {
        (bits as i32) as f32 / i32::MAX as f32 * limit
    } else {
        f32::from_bits(bits)
    }
}

fn parse(data: &[u8]) -> Input {
    let mut r = Reader { data, pos: 0 };
    let mut ticks = r.u64();
    let raw: [u32; 12] = core::array::from_fn(|_| r.u32());
    let case = Table1Case::ALL[usize::from(r.u8()) % Table1Case::ALL.len()];
    let flags = r.u8();
    let robust = flags & 1 != 0;
    let custom_on = flags & 2 != 0;
    if flags & 4 != 0 {
        ticks %= 1 << 20;
    }
    let scaled = flags & 8 != 0;
    let relative = flags & 16 != 0;
    let (position, angle, speed, rate) = if relative {
        (0.5, 0.2, 0.5, 0.2)
    } else {
        (
            1.05 * MAX_POSITION,
            1.05 * MAX_ANGLE,
            1.05 * MAX_LINEAR_SPEED,
            1.05 * MAX_ANGULAR_RATE,
        )
    };
    let limits = [
        position, position, position, angle, angle, angle, speed, speed, speed, rate, rate, rate,
    ];
    let x: [f32; 12] = core::array::from_fn(|i| to_f32(raw[i], scaled, limits[i]));
    let eta = core::array::from_fn(|i| x[i]);
    let nu = core::array::from_fn(|i| x[6 + i]);

    // A closed form of `TrajectoryKind::EXAMPLES` (declaration order), its parameters in field
    // order from the next words, each scaled to 1.05 × its own limit.
    let closed = closed_forms();
    let mut custom = closed[usize::from(r.u8()) % closed.len()];
    let words: Vec<u32> = (0..max_parameters(&closed)).map(|_| r.u32()).collect();
    let mut next = words.iter();
    custom.parameters(&mut |param, value| {
        *value = to_f32(*next.next().unwrap_or(&0), scaled, 1.05 * param.max());
    });
    let custom = custom_on.then_some(custom);
    Input {
        ticks,
        eta,
        nu,
        case,
        robust,
        relative,
        custom,
    }
}

/// Checks one `update`; returns its status and δ-clamp flag.
fn check(c: &Controller, input: &Input, tr: &Trajectory) -> (Status, bool) {
    let cfg = c.config();
    let (eta, nu): ([f32; 6], [f32; 6]) = if input.relative {
        let d = tr.sample(input.ticks, cfg.rate_hz);
        let nu_d = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
        (
            core::array::from_fn(|i| d.eta[i] + input.eta[i]),
            core::array::from_fn(|i| nu_d[i] + input.nu[i]),
        )
    } else {
        (input.eta, input.nu)
    };
    let out = c.update(input.ticks, &eta, &nu, tr);
    let ctx = || {
        format!(
            "{input:?} (η = {eta:?}, ν = {nu:?}) on {:?}: {out:?}",
            tr.kind()
        )
    };

    let fields = out
        .tau
        .iter()
        .chain(&out.tau_achieved)
        .chain(&out.thrust)
        .chain(&out.voltage)
        .chain(&out.eta_d)
        .chain(&out.e1)
        .chain([&out.delta, &out.w_norm]);
    for x in fields {
        assert!(x.is_finite(), "non-finite output {x}: {}", ctx());
    }
    for v in out.voltage {
        assert!(
            v.abs() <= cfg.voltage_limit,
            "|voltage| {v} > limit: {}",
            ctx()
        );
    }
    assert!(
        out.delta <= cfg.delta_max,
        "delta above delta_max: {}",
        ctx()
    );
    assert!(out.delta >= 0.0, "negative delta: {}", ctx());
    assert!(out.w_norm >= 0.0, "negative |w|: {}", ctx());
    assert!(out.saturated < 1 << 5, "saturation bits: {}", ctx());
    if out.delta_clamped {
        assert!(cfg.robust, "clamp reported with robust off: {}", ctx());
        assert_eq!(out.delta, cfg.delta_max, "clamped delta: {}", ctx());
    }
    if let Status::Fault(fault) = out.status {
        assert_eq!(out, Output::fail_safe(fault), "fault output: {}", ctx());
    }

    if !eta.iter().chain(&nu).all(|x| x.is_finite()) {
        assert_eq!(
            out.status,
            Status::Fault(Fault::NonFiniteInput),
            "{}",
            ctx()
        );
    } else {
        let plausible = eta[..3].iter().all(|x| x.abs() <= MAX_POSITION)
            && eta[3..].iter().all(|x| x.abs() <= MAX_ANGLE)
            && nu[..3].iter().all(|x| x.abs() <= MAX_LINEAR_SPEED)
            && nu[3..].iter().all(|x| x.abs() <= MAX_ANGULAR_RATE);
        if !plausible {
            assert_eq!(
                out.status,
                Status::Fault(Fault::InputOutOfRange),
                "{}",
                ctx()
            );
        }
    }

    let again = c.update(input.ticks, &eta, &nu, tr);
    assert_eq!(bits(&out), bits(&again), "not deterministic: {}", ctx());
    (out.status, out.delta_clamped)
}

/// Every float of an output as bits, plus the non-float fields.
fn bits(o: &Output) -> (Vec<u32>, Status, u8, bool) {
    let floats = o
        .tau
        .iter()
        .chain(&o.tau_achieved)
        .chain(&o.thrust)
        .chain(&o.voltage)
        .chain(&o.eta_d)
        .chain(&o.e1)
        .chain([&o.delta, &o.w_norm])
        .map(|x| x.to_bits())
        .collect();
    (floats, o.status, o.saturated, o.delta_clamped)
}

/// The fuzz target's body; returns the outputs' statuses and δ-clamp flags.
pub fn run(data: &[u8]) -> Vec<(Status, bool)> {
    let input = parse(data);
    let c = &controllers()[usize::from(input.robust)];
    let mut seen = vec![check(c, &input, &Trajectory::table1(input.case))];
    if let Some(kind) = input.custom {
        if let Ok(tr) = Trajectory::new(kind) {
            seen.push(check(c, &input, &tr));
        }
    }
    seen
}
