//! What a θ_c prior does on a neck resting on its shoulder: the model-choice scene "soft neck
//! resting on a shoulder at 0.08 rad" (`tests/common/scenes.rs`, scene 8: a recording the model
//! made at rtol 1e-10 with 0.1 px of tracking noise and 1 % of the frames dropped) fitted with the
//! `blade2dof+shoulder` candidate alone and the main job's other settings (swarm, 5 restarts,
//! Laplace intervals), once without a prior and once with `theta_c = { normal = { mean, sd } }`
//! (a contact angle read from the blade's drawing). Prints, per fit, each parameter's value,
//! 68 % interval, truth and whether the interval covers it, as a Markdown table
//! (docs/validation.md, "A contact-angle prior on a resting shoulder").
//!
//! ```sh
//! cargo run --release --example prior_shoulder                       # prior 0.08 ± 0.005 rad
//! cargo run --release --example prior_shoulder -- --mean 0.085 --sd 0.005
//! cargo run --release --example prior_shoulder -- --truth-only       # the truth's costs (seconds)
//! ```

#[path = "../tests/common/fixtures.rs"]
mod fixtures;
#[path = "../tests/common/scenes.rs"]
#[allow(dead_code)]
mod scenes;

use clap::Parser;
#[allow(unused_imports)]
use fixtures::*;
use scenes::{SCENES, write_scene};
use wiperlab::fit::run_fit;
use wiperlab::job::LoadedJob;

#[derive(Parser)]
struct Args {
    /// The prior's mean for θ_c, rad.
    #[arg(long, default_value_t = 0.08)]
    mean: f64,
    /// The prior's standard deviation for θ_c, rad.
    #[arg(long, default_value_t = 0.005)]
    sd: f64,
    /// Print each job's cost at the truth and stop (a few simulations, no fit).
    #[arg(long)]
    truth_only: bool,
}

/// The resting-shoulder scene's index in [`SCENES`].
const RESTING: usize = 8;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args = Args::parse();
    let scene = &SCENES[RESTING];
    let dir = tempfile::tempdir()?;
    let (path, switches) = write_scene(dir.path(), RESTING, scene)?;
    println!("scene: {} ({switches} shoulder switches)", scene.name);
    let text = std::fs::read_to_string(&path)?.replace(
        "models = [\"head1dof\", \"blade2dof\", \"blade2dof+shoulder\"]",
        "models = [\"blade2dof+shoulder\"]",
    );
    let prior = format!(
        "[fit.priors]\ntheta_c = {{ normal = {{ mean = {}, sd = {} }} }}\n",
        args.mean, args.sd
    );
    for (label, job_text) in [
        ("no prior".to_string(), text.clone()),
        (
            format!("θ_c prior {} ± {} rad", args.mean, args.sd),
            format!("{text}{prior}"),
        ),
    ] {
        std::fs::write(&path, job_text)?;
        let job = LoadedJob::load(&path)?;
        let p = wiperlab::search::problem_for(&job, job.candidates()[0])?;
        let u: Vec<f64> = (p.free.iter())
            .map(|f| f.u_of(job.truth[&f.name]))
            .collect();
        println!("\n{label}: the truth's cost {:.2} nats", p.cost_at(&u));
        if args.truth_only {
            continue;
        }
        let r = run_fit(&job, false)?.result;
        println!(
            "{label}: cost {:.2} nats, {} evaluations, {:.0} s\n",
            r.cost, r.model_evaluations, r.wall_time_s
        );
        println!("| parameter | fitted | 68 % interval | truth | covers |\n|---|---|---|---|---|");
        for p in &r.parameters {
            let (lo, hi) = p
                .interval
                .as_ref()
                .map_or((f64::NAN, f64::NAN), |i| (i.lo, i.hi));
            let t = p.true_value.unwrap_or(f64::NAN);
            println!(
                "| {} | {:.4} | [{lo:.4}, {hi:.4}] | {t:.4} | {} |",
                p.name,
                p.value,
                if (lo..=hi).contains(&t) { "yes" } else { "no" }
            );
        }
        if let Some(pr) = &r.priors {
            println!("\nprior's nats at the fit: {:.3}", pr.nats_at_fit);
        }
    }
    Ok(())
}
