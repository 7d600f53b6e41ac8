use std::io::Read;
use wiperlab::model::{BladeParams, FrictionLaw, StickForm};
use wiperlab::simulate::SolverOptions;
use wiperlab::simulate::blade::{default_window, simulate_blade};

fn main() {
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string("data/reversal/truth.json").unwrap())
            .unwrap();
    let p = &truth["params"];
    let g = |k: &str| p[k].as_f64().unwrap();
    let params = BladeParams {
        l1_m: g("l1"),
        l2_m: g("l2"),
        head_mass_kg: g("M"),
        neck_mass_kg: g("m1"),
        lip_mass_kg: g("m2"),
        neck_com_m: g("d1"),
        lip_com_m: g("d2"),
        neck_inertia_kg_m2: g("J1"),
        lip_inertia_kg_m2: g("J2"),
        k0_n_per_m: g("k0"),
        k1_nm_per_rad: g("k1"),
        k2_nm_per_rad: g("k2"),
        c0_ns_per_m: g("c0"),
        c1_nms_per_rad: g("c1"),
        c2_nms_per_rad: g("c2"),
        hd_m: g("hd"),
        friction: FrictionLaw::Exponential {
            a: g("A"),
            b_s_per_m: g("B"),
            c: g("C"),
        },
        drive_a_m: g("a"),
        drive_omega_rad_per_s: g("omega"),
    };
    println!(
        "head {} Hz neck {} Hz",
        params.head_freq_hz(),
        params.neck_freq_hz()
    );
    let mut s = String::new();
    flate2::read::GzDecoder::new(std::fs::File::open("data/reversal/clean_10kfps.csv.gz").unwrap())
        .read_to_string(&mut s)
        .unwrap();
    let mut ts = vec![];
    let mut v3 = vec![];
    let mut u = vec![];
    let mut th = vec![];
    let mut st = vec![];
    for line in s.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        ts.push(f[1].parse::<f64>().unwrap());
        u.push(f[4].parse::<f64>().unwrap());
        v3.push(f[5].parse::<f64>().unwrap());
        th.push(f[6].parse::<f64>().unwrap());
        st.push(f[8].parse::<i32>().unwrap());
    }
    let win = default_window(&params);
    println!("window {:?}, clean t0 {} n {}", win, ts[0], ts.len());
    let t0 = truth["camera"]["t0_s"].as_f64().unwrap();
    let times: Vec<f64> = (0..ts.len()).map(|k| t0 + k as f64 / 1e4).collect();
    for (form, rtol) in [
        (StickForm::Reduced, 1e-8),
        (StickForm::Reduced, 1e-10),
        (StickForm::Reduced, 1e-12),
        (StickForm::Baumgarte { omega_b_per_s: 1e4 }, 1e-12),
    ] {
        let opts = SolverOptions {
            rtol,
            atol: rtol * 1e-2,
            ..Default::default()
        };
        let t = std::time::Instant::now();
        let sim = simulate_blade(
            &params,
            (times[0], times[times.len() - 1] + 1e-9),
            &times,
            &opts,
            form,
        );
        let el = t.elapsed().as_secs_f64();
        match sim {
            Err(e) => println!("{form:?}: error {e}"),
            Ok(sim) => {
                let tr_ref = truth["simulation"]["transitions"].as_array().unwrap();
                println!(
                    "{form:?} rtol {rtol}: {el:.3} s, {} transitions (ref {}), stats {:?}",
                    sim.transitions.len(),
                    tr_ref.len(),
                    sim.stats
                );
                let mut maxdt: f64 = 0.0;
                for (a, b) in sim.transitions.iter().zip(tr_ref) {
                    let d = (a.t_s - b["t"].as_f64().unwrap()).abs();
                    maxdt = maxdt.max(d);
                }
                println!(
                    "  first transitions: {:?}",
                    &sim.transitions[..4.min(sim.transitions.len())]
                );
                println!("  max |dt| over paired transitions {maxdt:e}");
                let mut maxv3: f64 = 0.0;
                let mut maxu: f64 = 0.0;
                let mut maxth: f64 = 0.0;
                let mut phase_mismatch = 0;
                println!("  n sim {} n ref {}", sim.t_s.len(), ts.len());
                for i in 0..ts.len().min(sim.t_s.len()) {
                    maxv3 = maxv3.max((sim.v3_m[i] - v3[i]).abs());
                    maxu = maxu.max((sim.u_m[i] - u[i]).abs());
                    maxth = maxth.max((sim.theta_rad[i] - th[i]).abs());
                    if sim.phase[i].code() as i32 != st[i] {
                        phase_mismatch += 1;
                    }
                }
                println!(
                    "  max |v3 diff| {maxv3:e} m, |u diff| {maxu:e} m, |theta| {maxth:e}, phase mismatches {phase_mismatch}"
                );
                println!("  first sample theta {} vs {}", sim.theta_rad[0], th[0]);
                for i in [8800usize] {
                    println!(
                        "   i {i} t {:.5} th {:.8e} ref {:.8e}  v3-v {:.6e} ref {:.6e} u {:.6e} ref {:.6e} st {} ref {}",
                        sim.t_s[i],
                        sim.theta_rad[i],
                        th[i],
                        sim.v3_m[i] - sim.v_m[i],
                        v3[i] - (sim.v_m[i]),
                        sim.u_m[i],
                        u[i],
                        sim.phase[i].code(),
                        st[i]
                    );
                }
            }
        }
    }
}
