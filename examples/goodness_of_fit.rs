//! The goodness of fit of a job's candidate at given parameters: the recording's spectral excess
//! NLL against noise replicates of the model (`wiperlab::search::evidence`, `goodness_of_fit`).
//!
//! `cargo run --release --example goodness_of_fit -- JOB CANDIDATE NAME=VALUE...`, e.g.
//! `fits/reversal.toml blade2dof A=0.88 B=69.747 C=0.56 k1=0.029748` (freed parameters not
//! named sit at the middle of their normalised range).
use wiperlab::job::Candidate;
use wiperlab::job::LoadedJob;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: goodness_of_fit JOB CANDIDATE NAME=VALUE...".into());
    }
    let job = LoadedJob::load(std::path::Path::new(&args[1]))?;
    let candidate: Candidate = args[2].parse()?;
    let problem = wiperlab::search::problem_for(&job, candidate)?;
    let mut u = vec![0.5; problem.free.len()];
    for kv in &args[3..] {
        let (name, value) = kv
            .split_once('=')
            .ok_or_else(|| format!("expected NAME=VALUE, got '{kv}'"))?;
        let value: f64 = value.parse()?;
        let id: wiperlab::model::ParamId = name.parse()?;
        let i = problem
            .free
            .iter()
            .position(|f| f.name == id)
            .ok_or_else(|| format!("'{name}' is not freed by {candidate}"))?;
        u[i] = problem.free[i].u_of(value);
    }
    let sim = problem.simulate(&problem.params_at(&u))?;
    let lik = problem.likelihood.as_ref().map_err(|e| e.clone())?;
    let g = lik.goodness_of_fit(&problem, &sim)?;
    println!(
        "excess NLL {:.2} nats; {} noise replicates {:.2} ± {:.2}; z {:.1}; p {:.3}",
        g.excess_nll_nats,
        g.replicates,
        g.replicate_mean_nats,
        g.replicate_sd_nats,
        g.z(),
        g.p_value
    );
    Ok(())
}
