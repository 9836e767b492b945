//! Builds the controller with the paper's defaults, prints the configuration-time numbers, and
//! runs one `update` on each Table-1 mission with the vehicle on its reference at t = 0 s and at
//! t = 35 s. `cargo run --release -p controller-core --example track`.

use controller_core::kinematics::{self, Attitude};
use controller_core::{Controller, ControllerConfig, Status, Table1Case, Trajectory};

fn main() {
    let ctl = match Controller::new(ControllerConfig::default()) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("configuration rejected: {e}");
            std::process::exit(1);
        }
    };
    let b = ctl.bounds();
    let p = ctl.lyapunov()[0];
    println!(
        "controller-core, math backend {}",
        controller_core::math::BACKEND
    );
    println!(
        "P per axis: p11 = {}, p12 = {}, p22 = {}",
        p.p11, p.p12, p.p22
    );
    println!(
        "bounds over the Table-3 box: ΔM = {:.2}, Δg = {:.1} N, c_b = {:.3e}, ‖M⁻¹‖ = {:.3e}, β̂ = {:.4}",
        b.delta_m, b.delta_g, b.b_controlled, b.b_full, b.beta_hat
    );
    println!(
        "Theorem 2 as printed: {:.2} < {:.2} ({})",
        b.theorem2.lhs,
        b.theorem2.rhs,
        if b.theorem2.holds() { "holds" } else { "fails" }
    );
    println!();
    println!(
        "{:<20} {:>6} {:>7} {:>9} {:>9} {:>9} {:>11}",
        "mission", "t (s)", "K_d", "delta", "|tau| (N)", "peak |V|", "saturated"
    );
    for case in Table1Case::ALL {
        let tr = Trajectory::table1(case);
        for ticks in [0u64, 3500] {
            let d = tr.sample(ticks, ctl.config().rate_hz);
            let nu = kinematics::jacobian_inv(&Attitude::from_eta_f32(&d.eta)) * d.eta_dot;
            let out = ctl.update(ticks, &d.eta.into(), &nu.into(), &tr);
            if out.status != Status::Ok {
                println!("{:<20} fault: {:?}", case.name(), out.status);
                continue;
            }
            let tau = out.tau.iter().map(|x| x * x).sum::<f32>().sqrt();
            let peak = out.voltage.iter().fold(0.0f32, |m, v| m.max(v.abs()));
            println!(
                "{:<20} {:>6.1} {:>7.4} {:>9.3} {:>9.1} {:>9.2} {:>11}",
                case.name(),
                ticks as f32 / 100.0,
                tr.accel_bound(),
                out.delta,
                tau,
                peak,
                format!("{:05b}", out.saturated)
            );
        }
    }
}
