//! Dormand–Prince 8(5,3) (DOP853) with step-size control and its 7th-order continuous extension.
//!
//! The method of Hairer, Nørsett & Wanner, *Solving Ordinary Differential Equations I* (2nd ed.,
//! Springer 1993), §II.10 (Dormand & Prince's 8th-order pair with the error estimator and dense
//! output of Hairer's code `dop853.f`). The coefficients are those of `dop853.f`, as transcribed in
//! SciPy's `scipy/integrate/_ivp/dop853_coefficients.py`; the code here is ours. The tableau is
//! checked against the order conditions in the tests below.
//!
//! A step takes 12 stages; the error test needs 11 new right-hand-side evaluations
//! ([`attempt`]), an accepted step one more at its end (first same as last) and three for the
//! dense output ([`Trial::finish`]): 15 per accepted step, 11 per rejected one. The state is a
//! fixed-size array `[f64; N]`, so nothing is allocated.

// The coefficients keep every digit `dop853.f` prints, so they can be checked against it.
#![allow(clippy::excessive_precision)]

/// Number of stages including the end point's derivative and the three dense-output stages.
const STAGES: usize = 16;

/// Nodes c_i (stage i at `t + c_i·h`), 0-based as in SciPy's table: stages 0–11 form the step,
/// 12 is the derivative at the end, 13–15 the dense-output stages.
const C: [f64; STAGES] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

/// A sparse row of the tableau: (stage index, coefficient).
type Row = &'static [(usize, f64)];

/// Nonzero a_ij of stages 1–11 (row i − 1 of this table is stage i).
const A: [Row; 11] = [
    &[(0, 5.26001519587677318785587544488e-2)],
    &[
        (0, 1.97250569845378994544595329183e-2),
        (1, 5.91751709536136983633785987549e-2),
    ],
    &[
        (0, 2.95875854768068491816892993775e-2),
        (2, 8.87627564304205475450678981324e-2),
    ],
    &[
        (0, 2.41365134159266685502369798665e-1),
        (2, -8.84549479328286085344864962717e-1),
        (3, 9.24834003261792003115737966543e-1),
    ],
    &[
        (0, 3.7037037037037037037037037037e-2),
        (3, 1.70828608729473871279604482173e-1),
        (4, 1.25467687566822425016691814123e-1),
    ],
    &[
        (0, 3.7109375e-2),
        (3, 1.70252211019544039314978060272e-1),
        (4, 6.02165389804559606850219397283e-2),
        (5, -1.7578125e-2),
    ],
    &[
        (0, 3.70920001185047927108779319836e-2),
        (3, 1.70383925712239993810214054705e-1),
        (4, 1.07262030446373284651809199168e-1),
        (5, -1.53194377486244017527936158236e-2),
        (6, 8.27378916381402288758473766002e-3),
    ],
    &[
        (0, 6.24110958716075717114429577812e-1),
        (3, -3.36089262944694129406857109825),
        (4, -8.68219346841726006818189891453e-1),
        (5, 2.75920996994467083049415600797e1),
        (6, 2.01540675504778934086186788979e1),
        (7, -4.34898841810699588477366255144e1),
    ],
    &[
        (0, 4.77662536438264365890433908527e-1),
        (3, -2.48811461997166764192642586468),
        (4, -5.90290826836842996371446475743e-1),
        (5, 2.12300514481811942347288949897e1),
        (6, 1.52792336328824235832596922938e1),
        (7, -3.32882109689848629194453265587e1),
        (8, -2.03312017085086261358222928593e-2),
    ],
    &[
        (0, -9.3714243008598732571704021658e-1),
        (3, 5.18637242884406370830023853209),
        (4, 1.09143734899672957818500254654),
        (5, -8.14978701074692612513997267357),
        (6, -1.85200656599969598641566180701e1),
        (7, 2.27394870993505042818970056734e1),
        (8, 2.49360555267965238987089396762),
        (9, -3.0467644718982195003823669022),
    ],
    &[
        (0, 2.27331014751653820792359768449),
        (3, -1.05344954667372501984066689879e1),
        (4, -2.00087205822486249909675718444),
        (5, -1.79589318631187989172765950534e1),
        (6, 2.79488845294199600508499808837e1),
        (7, -2.85899827713502369474065508674),
        (8, -8.87285693353062954433549289258),
        (9, 1.23605671757943030647266201528e1),
        (10, 6.43392746015763530355970484046e-1),
    ],
];

/// The 8th-order weights b_i (the step's update).
const B: Row = &[
    (0, 5.42937341165687622380535766363e-2),
    (5, 4.45031289275240888144113950566),
    (6, 1.89151789931450038304281599044),
    (7, -5.8012039600105847814672114227),
    (8, 3.1116436695781989440891606237e-1),
    (9, -1.52160949662516078556178806805e-1),
    (10, 2.01365400804030348374776537501e-1),
    (11, 4.47106157277725905176885569043e-2),
];

/// The 3rd-order error weights: b_i minus `dop853.f`'s BHH1–BHH3 (on stages 0, 8, 11).
const E3: Row = &[
    (
        0,
        5.42937341165687622380535766363e-2 - 0.244094488188976377952755905512,
    ),
    (5, 4.45031289275240888144113950566),
    (6, 1.89151789931450038304281599044),
    (7, -5.8012039600105847814672114227),
    (
        8,
        3.1116436695781989440891606237e-1 - 0.733846688281611857341361741547,
    ),
    (9, -1.52160949662516078556178806805e-1),
    (10, 2.01365400804030348374776537501e-1),
    (
        11,
        4.47106157277725905176885569043e-2 - 0.220588235294117647058823529412e-1,
    ),
];

/// The 5th-order error weights (`dop853.f`'s ER1–ER12).
const E5: Row = &[
    (0, 0.1312004499419488073250102996e-1),
    (5, -0.1225156446376204440720569753e1),
    (6, -0.4957589496572501915214079952),
    (7, 0.1664377182454986536961530415e1),
    (8, -0.3503288487499736816886487290),
    (9, 0.3341791187130174790297318841),
    (10, 0.8192320648511571246570742613e-1),
    (11, -0.2235530786388629525884427845e-1),
];

/// Nonzero a_ij of the dense-output stages 13–15.
const A_DENSE: [Row; 3] = [
    &[
        (0, 5.61675022830479523392909219681e-2),
        (6, 2.53500210216624811088794765333e-1),
        (7, -2.46239037470802489917441475441e-1),
        (8, -1.24191423263816360469010140626e-1),
        (9, 1.5329179827876569731206322685e-1),
        (10, 8.20105229563468988491666602057e-3),
        (11, 7.56789766054569976138603589584e-3),
        (12, -8.298e-3),
    ],
    &[
        (0, 3.18346481635021405060768473261e-2),
        (5, 2.83009096723667755288322961402e-2),
        (6, 5.35419883074385676223797384372e-2),
        (7, -5.49237485713909884646569340306e-2),
        (10, -1.08347328697249322858509316994e-4),
        (11, 3.82571090835658412954920192323e-4),
        (12, -3.40465008687404560802977114492e-4),
        (13, 1.41312443674632500278074618366e-1),
    ],
    &[
        (0, -4.28896301583791923408573538692e-1),
        (5, -4.69762141536116384314449447206),
        (6, 7.68342119606259904184240953878),
        (7, 4.06898981839711007970213554331),
        (8, 3.56727187455281109270669543021e-1),
        (12, -1.39902416515901462129418009734e-3),
        (13, 2.9475147891527723389556272149),
        (14, -9.15095847217987001081870187138),
    ],
];

/// The dense output's coefficients d_4 … d_7 (`dop853.f`'s D41–D716).
const D: [Row; 4] = [
    &[
        (0, -0.84289382761090128651353491142e1),
        (5, 0.56671495351937776962531783590),
        (6, -0.30689499459498916912797304727e1),
        (7, 0.23846676565120698287728149680e1),
        (8, 0.21170345824450282767155149946e1),
        (9, -0.87139158377797299206789907490),
        (10, 0.22404374302607882758541771650e1),
        (11, 0.63157877876946881815570249290),
        (12, -0.88990336451333310820698117400e-1),
        (13, 0.18148505520854727256656404962e2),
        (14, -0.91946323924783554000451984436e1),
        (15, -0.44360363875948939664310572000e1),
    ],
    &[
        (0, 0.10427508642579134603413151009e2),
        (5, 0.24228349177525818288430175319e3),
        (6, 0.16520045171727028198505394887e3),
        (7, -0.37454675472269020279518312152e3),
        (8, -0.22113666853125306036270938578e2),
        (9, 0.77334326684722638389603898808e1),
        (10, -0.30674084731089398182061213626e2),
        (11, -0.93321305264302278729567221706e1),
        (12, 0.15697238121770843886131091075e2),
        (13, -0.31139403219565177677282850411e2),
        (14, -0.93529243588444783865713862664e1),
        (15, 0.35816841486394083752465898540e2),
    ],
    &[
        (0, 0.19985053242002433820987653617e2),
        (5, -0.38703730874935176555105901742e3),
        (6, -0.18917813819516756882830838328e3),
        (7, 0.52780815920542364900561016686e3),
        (8, -0.11573902539959630126141871134e2),
        (9, 0.68812326946963000169666922661e1),
        (10, -0.10006050966910838403183860980e1),
        (11, 0.77771377980534432092869265740),
        (12, -0.27782057523535084065932004339e1),
        (13, -0.60196695231264120758267380846e2),
        (14, 0.84320405506677161018159903784e2),
        (15, 0.11992291136182789328035130030e2),
    ],
    &[
        (0, -0.25693933462703749003312586129e2),
        (5, -0.15418974869023643374053993627e3),
        (6, -0.23152937917604549567536039109e3),
        (7, 0.35763911791061412378285349910e3),
        (8, 0.93405324183624310003907691704e2),
        (9, -0.37458323136451633156875139351e2),
        (10, 0.10409964950896230045147246184e3),
        (11, 0.29840293426660503123344363579e2),
        (12, -0.43533456590011143754432175058e2),
        (13, 0.96324553959188282948394950600e2),
        (14, -0.39177261675615439165231486172e2),
        (15, -0.14972683625798562581422125276e3),
    ],
];

/// `Σ_j row_j · k_j[i]` for every component `i`.
#[inline(always)]
fn combine<const N: usize>(row: Row, k: &[[f64; N]; STAGES]) -> [f64; N] {
    let mut out = [0.0; N];
    for (i, o) in out.iter_mut().enumerate() {
        let mut s = 0.0;
        for &(j, a) in row {
            s += a * k[j][i];
        }
        *o = s;
    }
    out
}

/// `y + h·Σ_j row_j · k_j`.
#[inline(always)]
fn stage_state<const N: usize>(y: &[f64; N], h: f64, row: Row, k: &[[f64; N]; STAGES]) -> [f64; N] {
    let mut out = combine(row, k);
    for (o, yi) in out.iter_mut().zip(y) {
        *o = yi + h * *o;
    }
    out
}

/// The 7th-order continuous extension of one accepted step on `[t, t + h]` (Hairer's `CONTD8`).
#[derive(Debug, Clone, Copy)]
pub struct Dense<const N: usize> {
    pub t: f64,
    pub h: f64,
    r: [[f64; N]; 8],
}

impl<const N: usize> Dense<N> {
    /// State at `t_eval ∈ [t, t + h]` (7th-order accurate; exact at both ends).
    #[inline]
    pub fn eval(&self, t_eval: f64) -> [f64; N] {
        let s = (t_eval - self.t) / self.h;
        let s1 = 1.0 - s;
        let r = &self.r;
        let mut y = [0.0; N];
        for (i, yi) in y.iter_mut().enumerate() {
            let conv = r[4][i] + s * (r[5][i] + s1 * (r[6][i] + s * r[7][i]));
            *yi = r[0][i] + s * (r[1][i] + s1 * (r[2][i] + s * (r[3][i] + s1 * conv)));
        }
        y
    }

    /// End time of the step.
    pub fn t_end(&self) -> f64 {
        self.t + self.h
    }
}

/// An attempted step: its error norm and end state, and the stages to finish it with.
pub struct Trial<const N: usize> {
    t: f64,
    h: f64,
    y: [f64; N],
    pub y_new: [f64; N],
    /// Hairer's error norm of the 5th- and 3rd-order estimates (≤ 1 means accept).
    pub err: f64,
    k: [[f64; N]; STAGES],
}

/// An accepted, finished step.
pub struct Attempt<const N: usize> {
    pub y_new: [f64; N],
    /// Derivative at the new point (first same as last).
    pub f_new: [f64; N],
    pub err: f64,
    pub dense: Dense<N>,
}

/// Attempts one DOP853 step of size `h` from `(t, y)` with derivative `f0 = f(t, y)`: the 11 new
/// stages, the 8th-order update and the error norm. Finish an accepted trial with
/// [`Trial::finish`].
///
/// `rhs(t, y, dy)` returns `Err(e)` when the derivative cannot be evaluated there (the caller
/// shrinks the step).
pub fn attempt<const N: usize, E>(
    rhs: &mut impl FnMut(f64, &[f64; N], &mut [f64; N]) -> Result<(), E>,
    t: f64,
    y: &[f64; N],
    f0: &[f64; N],
    h: f64,
    rtol: f64,
    atol: f64,
) -> Result<Trial<N>, E> {
    let mut k = [[0.0; N]; STAGES];
    k[0] = *f0;
    for (i, row) in A.iter().enumerate() {
        let yi = stage_state(y, h, row, &k);
        rhs(t + C[i + 1] * h, &yi, &mut k[i + 1])?;
    }
    let y_new = stage_state(y, h, B, &k);
    let (e5, e3) = (combine(E5, &k), combine(E3, &k));
    let (mut err5, mut err3) = (0.0, 0.0);
    for i in 0..N {
        let sc = atol + rtol * y[i].abs().max(y_new[i].abs());
        err5 += (e5[i] / sc) * (e5[i] / sc);
        err3 += (e3[i] / sc) * (e3[i] / sc);
    }
    // dop853.f: err = |h|·err5 / sqrt(N·(err5 + 0.01·err3)) with the sums of squares.
    let deno = err5 + 0.01 * err3;
    let deno = if deno > 0.0 { deno } else { 1.0 };
    let err = h.abs() * err5 / (N as f64 * deno).sqrt();
    let finite = err.is_finite() && y_new.iter().all(|v| v.is_finite());
    Ok(Trial {
        t,
        h,
        y: *y,
        y_new,
        err: if finite { err } else { f64::INFINITY },
        k,
    })
}

impl<const N: usize> Trial<N> {
    /// Completes an accepted trial: the derivative at its end and the three stages of the
    /// 7th-order continuous extension (4 right-hand-side evaluations).
    pub fn finish<E>(
        mut self,
        rhs: &mut impl FnMut(f64, &[f64; N], &mut [f64; N]) -> Result<(), E>,
    ) -> Result<Attempt<N>, E> {
        let (t, h, y) = (self.t, self.h, self.y);
        let k = &mut self.k;
        let mut f_new = [0.0; N];
        rhs(t + h, &self.y_new, &mut f_new)?;
        k[12] = f_new;
        for (i, row) in A_DENSE.iter().enumerate() {
            let yi = stage_state(&y, h, row, k);
            rhs(t + C[13 + i] * h, &yi, &mut k[13 + i])?;
        }
        let mut r = [[0.0; N]; 8];
        for i in 0..N {
            let dy = self.y_new[i] - y[i];
            let bspl = h * k[0][i] - dy;
            r[0][i] = y[i];
            r[1][i] = dy;
            r[2][i] = bspl;
            r[3][i] = dy - h * f_new[i] - bspl;
        }
        for (m, row) in D.iter().enumerate() {
            let d = combine(row, k);
            for i in 0..N {
                r[4 + m][i] = h * d[i];
            }
        }
        Ok(Attempt {
            y_new: self.y_new,
            f_new,
            err: self.err,
            dense: Dense { t, h, r },
        })
    }
}

/// New step size from the error norm: Hairer's controller for order 8 (exponent 1/8, safety 0.9,
/// growth limits [0.333, 6] as in `dop853.f`, no Lund stabilisation).
#[inline]
pub fn next_step(h: f64, err: f64) -> f64 {
    let fac = if err == 0.0 {
        6.0
    } else {
        (0.9 * err.powf(-0.125)).clamp(0.333, 6.0)
    };
    h * fac
}

#[cfg(test)]
mod tests {
    use super::*;

    fn coefficient(row: Row, j: usize) -> f64 {
        row.iter().find(|&&(i, _)| i == j).map_or(0.0, |&(_, a)| a)
    }

    /// The tableau is consistent (each row of A sums to its node, Σb = 1) and the weights integrate
    /// polynomials of degree ≤ 7 exactly: Σ b_i c_i^q = 1/(q + 1) for q = 0…7 (bushy-tree order
    /// conditions, Hairer–Nørsett–Wanner §II.2). The dense-output stages' rows sum to their nodes.
    #[test]
    fn tableau_satisfies_row_sums_and_quadrature_conditions() {
        for (i, row) in A.iter().chain(A_DENSE.iter()).enumerate() {
            let node = if i < 11 { C[i + 1] } else { C[13 + i - 11] };
            let sum: f64 = row.iter().map(|&(_, a)| a).sum();
            assert!(
                (sum - node).abs() < 1e-14,
                "row {i}: {sum} against c = {node}"
            );
        }
        for q in 0..8 {
            let s: f64 = B.iter().map(|&(j, b)| b * C[j].powi(q)).sum();
            let exact = 1.0 / (q as f64 + 1.0);
            assert!((s - exact).abs() < 1e-13, "q = {q}: {s} against {exact}");
        }
        // The error weights sum to zero (they compare two consistent formulas).
        for row in [E3, E5] {
            let s: f64 = (0..12).map(|j| coefficient(row, j)).sum();
            assert!(s.abs() < 1e-13, "error weights sum to {s}");
        }
    }

    fn oscillator(_t: f64, y: &[f64; 2], dy: &mut [f64; 2]) -> Result<(), ()> {
        dy[0] = y[1];
        dy[1] = -y[0];
        Ok(())
    }

    /// One-period error of `n` fixed steps on y'' = −y (exact: back to (1, 0)).
    fn one_period_error(n: usize) -> f64 {
        let h = 2.0 * std::f64::consts::PI / n as f64;
        let (mut y, mut t) = ([1.0, 0.0], 0.0);
        let mut rhs = oscillator;
        for _ in 0..n {
            let mut f = [0.0; 2];
            oscillator(t, &y, &mut f).unwrap();
            y = attempt(&mut rhs, t, &y, &f, h, 1.0, 1.0).unwrap().y_new;
            t += h;
        }
        (y[0] - 1.0).abs().max(y[1].abs())
    }

    /// Order check against the closed form: halving a fixed step divides the one-period error by
    /// ≈ 2⁸ = 256 (errors ≈ 1e-8 … 1e-11, well above rounding).
    #[test]
    fn eighth_order_convergence() {
        let (e1, e2) = (one_period_error(12), one_period_error(24));
        let order = (e1 / e2).log2();
        eprintln!("one-period errors {e1:e}, {e2:e}: order {order:.3}");
        assert!(
            (order - 8.0).abs() < 0.3,
            "observed order {order} ({e1:e}, {e2:e})"
        );
    }

    /// The continuous extension between steps against the closed form (cos t, −sin t): on one
    /// fixed step of size h its error falls as h⁸ (a 7th-order interpolant's local error), and at
    /// rtol 1e-10 over ten periods it stays at the level of the global error.
    #[test]
    fn dense_output_is_seventh_order_and_accurate_between_steps() {
        let dense_error = |h: f64| {
            let y = [1.0, 0.0];
            let f = [0.0, -1.0];
            let mut rhs = oscillator;
            let a = attempt(&mut rhs, 0.0, &y, &f, h, 1.0, 1.0)
                .unwrap()
                .finish(&mut rhs)
                .unwrap();
            (1..8)
                .map(|j| {
                    let te = h * j as f64 / 8.0;
                    let yd = a.dense.eval(te);
                    (yd[0] - te.cos()).abs().max((yd[1] + te.sin()).abs())
                })
                .fold(0.0, f64::max)
        };
        let order = (dense_error(0.8) / dense_error(0.4)).log2();
        eprintln!("dense output: local order {order:.3}");
        assert!((order - 8.0).abs() < 0.5, "dense local order {order}");

        let (rtol, atol) = (1e-10, 1e-12);
        let mut rhs = oscillator;
        let (mut t, mut y, mut f, mut h) = (0.0, [1.0, 0.0], [0.0, -1.0], 1e-3);
        let (mut max_dense_err, mut steps): (f64, usize) = (0.0, 0);
        let t_end = 20.0 * std::f64::consts::PI;
        while t < t_end {
            h = f64::min(h, t_end - t);
            let trial = attempt(&mut rhs, t, &y, &f, h, rtol, atol).unwrap();
            let err = trial.err;
            if err <= 1.0 {
                let a = trial.finish(&mut rhs).unwrap();
                for j in 1..8 {
                    let te = t + h * j as f64 / 8.0;
                    let yd = a.dense.eval(te);
                    max_dense_err = max_dense_err.max((yd[0] - te.cos()).abs());
                }
                (t, y, f) = (t + h, a.y_new, a.f_new);
                steps += 1;
            }
            h = next_step(h, err);
        }
        assert!((y[0] - 1.0).abs() < 1e-8 && y[1].abs() < 1e-8, "{y:?}");
        assert!(max_dense_err < 1e-8, "dense error {max_dense_err:e}");
        // The same run with DOPRI5 (4th-order dense output) takes over twice the steps.
        let dopri5_steps = {
            let (mut t, mut y, mut f, mut h, mut n) = (0.0, [1.0, 0.0], [0.0, -1.0], 1e-3, 0);
            while t < t_end {
                h = f64::min(h, t_end - t);
                let a = super::super::rk::attempt(&mut rhs, t, &y, &f, h, rtol, atol).unwrap();
                if a.err <= 1.0 {
                    (t, y, f, n) = (t + h, a.y_new, a.f_new, n + 1);
                }
                h = super::super::rk::next_step(h, a.err);
            }
            n
        };
        eprintln!("ten periods at rtol 1e-10: DOP853 {steps} steps, DOPRI5 {dopri5_steps}");
        assert!(2 * steps < dopri5_steps, "{steps} against {dopri5_steps}");
    }
}
