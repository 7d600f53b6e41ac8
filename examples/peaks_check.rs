use wiperlab::model::{BladeParams, FrictionLaw, StickForm};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::simulate_blade;
use wiperlab::spectrum::{WelchConfig, find_peak, welch_gappy};

fn main() {
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("data/reversal/truth.json").unwrap()).unwrap();
    let p = &truth["params"];
    let g = |k: &str| p[k].as_f64().unwrap();
    let params = BladeParams {
        l1_m: g("l1"), l2_m: g("l2"), head_mass_kg: g("M"), neck_mass_kg: g("m1"), lip_mass_kg: g("m2"),
        neck_com_m: g("d1"), lip_com_m: g("d2"), neck_inertia_kg_m2: g("J1"), lip_inertia_kg_m2: g("J2"),
        k0_n_per_m: g("k0"), k1_nm_per_rad: g("k1"), k2_nm_per_rad: g("k2"), c0_ns_per_m: g("c0"),
        c1_nms_per_rad: g("c1"), c2_nms_per_rad: g("c2"), hd_m: g("hd"),
        friction: FrictionLaw::Exponential { a: g("A"), b_s_per_m: g("B"), c: g("C") },
        drive_a_m: g("a"), drive_omega_rad_per_s: g("omega"),
    };
    let s = std::fs::read_to_string("data/reversal/wiper_reversal_sample_xypts.csv").unwrap();
    let mut rel = vec![];
    for line in s.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse::<f64>().unwrap_or(f64::NAN)).collect();
        rel.push((f[2] - f[0]) * 1.5e-5);
    }
    let t0 = truth["camera"]["t0_s"].as_f64().unwrap();
    let times: Vec<f64> = (0..rel.len()).map(|k| t0 + k as f64 / 1e4).collect();
    let args: Vec<String> = std::env::args().collect();
    let nps: Vec<usize> = args[1..].iter().map(|a| a.parse().unwrap()).collect();
    let show = |name: &str, x: &[f64]| {
        for &np in &nps {
            let cfg = WelchConfig::new(np);
            let (psd, _) = welch_gappy(x, 1e4, &cfg, 5).unwrap();
            let lo = find_peak(&psd.freq_hz, &psd.density, (30.0, 300.0)).unwrap_or(wiperlab::spectrum::Peak{freq_hz: f64::NAN, level: f64::NAN, bin: 0, prominence: f64::NAN});
            let hi = find_peak(&psd.freq_hz, &psd.density, (500.0, 5000.0)).unwrap();
            println!("{name:>14} nperseg {np:>6}: low {:8.3} Hz (lvl {:.3e})  high {:8.3} Hz (lvl {:.3e})", lo.freq_hz, lo.level, hi.freq_hz, hi.level);
        }
    };
    show("recording", &rel);
    for rtol in [1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12] {
        let opts = SolverOptions { rtol, atol: rtol * 1e-2, ..Default::default() };
        let t = std::time::Instant::now();
        let sim = simulate_blade(&params, (times[0], *times.last().unwrap()), &times, &opts, StickForm::Reduced).unwrap();
        let el = t.elapsed().as_secs_f64();
        let x: Vec<f64> = sim.v3_m.iter().zip(&sim.v_m).map(|(a, b)| a - b).collect();
        println!("rtol {rtol:e}: {el:.3} s, {} transitions", sim.transitions.len());
        show(&format!("model {rtol:e}"), &x);
    }
}
