//! The closest achievable pair of an exploration and the constraint that keeps it from the targets:
//! when no plausible parameter set reaches the targets, the map shows the closest achievable pair
//! and the report names the constraint that prevents it.
//!
//! - **Distance** of a sample from the targets: per band with a target, the line's relative miss
//!   (0 inside a range, (f − hi)/hi above it, (f − lo)/lo below) over the band's tolerance
//!   ([`band_tolerance`]: 1 % for the first band, 2 % for the others, as for the seed paper's pairs), and
//!   the largest of these. A sample with distance ≤ 1 whose lines are all their own and prominent
//!   is one that [`super::Exploration::reaches`] counts.
//! - **Closest achievable pair**: the sample of smallest distance among those whose every band's
//!   line is its own (not a harmonic of a stronger line) and at least
//!   [`MIN_PROMINENCE`] times its local floor, from a run that did not fail.
//! - **Constraint**: at that sample, the band farthest from its target (the binding band), the freed
//!   parameters within [`BOUND_MARGIN`] of a bound (in the box's normalised coordinates), and for
//!   each freed parameter what the one-at-a-time elasticity around the sample says: the
//!   first-order value that would put the binding band's line on its target,
//!   θ·(f_target/f)^(1/e), and whether it lies beyond a bound. Past each such bound, what the
//!   outer [`EDGE_SHARE`] of the box on that side gave (failures by cause).

use super::{Exploration, FailureCause, Outcome, Sample, Sensitivity};
use crate::names::named_enum;
use crate::spectrum::harmonics::MIN_PROMINENCE;
use serde::Serialize;

/// A parameter closer to a bound than this share of its box (normalised coordinates) sits on it.
pub const BOUND_MARGIN: f64 = 0.03;

/// The outer share of the box beside a bound whose samples show what lies beyond it.
pub const EDGE_SHARE: f64 = 0.1;

/// A parameter whose first-order value for the target is more than this factor from the sample's
/// moves the line too little to count as a lever (the linear estimate means nothing that far).
pub const MAX_LEVER_FACTOR: f64 = 10.0;

/// The relative tolerance of band `b`: 1 % for the first band, 2 % for the others (the criterion
/// for the seed paper's pairs, 78.4 Hz ± 1 % and 900 Hz ± 2 %).
pub fn band_tolerance(b: usize) -> f64 {
    if b == 0 { 0.01 } else { 0.02 }
}

/// The signed relative miss of a line at `f_hz` from the range `[lo, hi]`: 0 inside,
/// (f − hi)/hi above, (f − lo)/lo below.
pub fn relative_miss(f_hz: f64, [lo, hi]: [f64; 2]) -> f64 {
    if f_hz > hi {
        (f_hz - hi) / hi
    } else if f_hz < lo {
        (f_hz - lo) / lo
    } else {
        0.0
    }
}

/// The target's edge nearest to a line at `f_hz` (the line itself when inside).
fn nearest_edge(f_hz: f64, [lo, hi]: [f64; 2]) -> f64 {
    f_hz.clamp(lo, hi)
}

named_enum! {
    /// Why a band's line does not count as the band's own, prominent line.
    pub enum LineFlaw: "line flaw" {
        /// A harmonic of a stronger line.
        Harmonic => "harmonic",
        /// Below [`MIN_PROMINENCE`] times its local floor.
        Weak => "weak",
        /// Its floor is not measurable at the band's bins (prominence NaN).
        Unmeasurable => "unmeasurable",
    }
}

impl LineFlaw {
    fn of(l: &super::BandLine) -> Option<LineFlaw> {
        if l.harmonic_of_hz.is_some() {
            Some(LineFlaw::Harmonic)
        } else if !l.prominence.is_finite() {
            Some(LineFlaw::Unmeasurable)
        } else if l.prominence < MIN_PROMINENCE {
            Some(LineFlaw::Weak)
        } else {
            None
        }
    }

    /// The flaw in words.
    pub fn text(self) -> String {
        match self {
            LineFlaw::Harmonic => "a harmonic of a stronger line".into(),
            LineFlaw::Weak => format!("under {MIN_PROMINENCE}x its local floor"),
            LineFlaw::Unmeasurable => "its floor not measurable at the band's bins".into(),
        }
    }
}

/// A sample's distance from the targets ([module docs](self)): the largest tolerance-scaled
/// relative miss over the bands with a target; `None` for a failed run.
pub fn distance(s: &Sample, targets: &[Option<[f64; 2]>]) -> Option<f64> {
    let lines = s.outcome.lines()?;
    Some(
        lines
            .iter()
            .zip(targets)
            .enumerate()
            .filter_map(|(b, (l, t))| {
                t.map(|t| relative_miss(l.freq_hz, t).abs() / band_tolerance(b))
            })
            .fold(0.0, f64::max),
    )
}

/// The first flaw of a sample's lines, in band order (`None` when all are own and prominent).
fn first_flaw(s: &Sample) -> Option<(usize, LineFlaw)> {
    s.outcome
        .lines()?
        .iter()
        .enumerate()
        .find_map(|(b, l)| LineFlaw::of(l).map(|f| (b, f)))
}

/// The closest achievable pair: a sample index and its distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Closest {
    pub sample: usize,
    pub distance: f64,
}

/// The sample of smallest [`distance`] among those whose lines are all own and prominent (the
/// lowest index on a tie); `None` when no sample has such lines.
pub fn closest_pair(samples: &[Sample], targets: &[Option<[f64; 2]>]) -> Option<Closest> {
    samples
        .iter()
        .enumerate()
        .filter(|(_, s)| first_flaw(s).is_none())
        .filter_map(|(i, s)| distance(s, targets).map(|d| (i, d)))
        .min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)))
        .map(|(sample, distance)| Closest { sample, distance })
}

named_enum! {
    /// Which side of its box a parameter is on.
    pub enum Side: "side" {
        Lower => "lower",
        Upper => "upper",
    }
}

impl Side {
    pub fn text(self) -> &'static str {
        match self {
            Side::Lower => "below its lower bound",
            Side::Upper => "above its upper bound",
        }
    }
}

/// Freed parameter `param` of the closest sample within [`BOUND_MARGIN`] of its bound on `side`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct BoundHit {
    pub param: usize,
    pub side: Side,
    /// The sample's normalised coordinate (0 at the lower bound, 1 at the upper).
    pub u: f64,
}

/// The freed parameters of `s` within [`BOUND_MARGIN`] of a bound, in job order.
pub fn bound_hits(e: &Exploration, s: &Sample) -> Vec<BoundHit> {
    e.free
        .iter()
        .zip(&s.values)
        .enumerate()
        .filter_map(|(param, (f, v))| {
            let u = f.u_of(*v);
            let side = if u <= BOUND_MARGIN {
                Side::Lower
            } else if u >= 1.0 - BOUND_MARGIN {
                Side::Upper
            } else {
                return None;
            };
            Some(BoundHit { param, side, u })
        })
        .collect()
}

/// Whether the line of band `b` is the band's own, prominent line in `o` (a run with lines).
fn own_line(o: &Outcome, b: usize) -> bool {
    o.lines()
        .and_then(|l| l.get(b))
        .is_some_and(|l| LineFlaw::of(l).is_none())
}

/// What moving one freed parameter alone does for the binding band, to first order.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Push {
    pub param: usize,
    /// d ln f / d ln θ of the binding band's line around the closest sample.
    pub elasticity: f64,
    /// θ·(f_target/f)^(1/e): the value that would put the line on its target's nearest edge.
    pub needed: f64,
    /// The bound `needed` lies beyond, if any.
    pub beyond: Option<Side>,
    /// Whether the sample already sits on that bound ([`BoundHit`]).
    pub on_bound: bool,
}

impl Push {
    /// Whether the first-order value lies within [`MAX_LEVER_FACTOR`] of the sample's.
    pub fn is_lever(&self, value: f64) -> bool {
        let r = self.needed / value;
        r.is_finite() && (1.0 / MAX_LEVER_FACTOR..=MAX_LEVER_FACTOR).contains(&r)
    }
}

/// One freed parameter of the closest sample set to its first-order value ([`Push::needed`]) and
/// simulated: what the linear estimate is worth (computed by [`super::explore`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LeverCheck {
    pub param: usize,
    pub value: f64,
    pub outcome: Outcome,
}

/// What the outer [`EDGE_SHARE`] of the box beside one bound gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Edge {
    pub param: usize,
    pub side: Side,
    pub samples: usize,
    pub with_lines: usize,
    /// Failures by cause, most frequent first.
    pub failures: Vec<(FailureCause, usize)>,
}

/// Samples nearer to the targets than the closest achievable pair whose lines did not count.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Nearer {
    /// How many, per the flaw of their first flawed band.
    pub by_flaw: Vec<(LineFlaw, usize)>,
    /// Of these, the ones within every tolerance (distance ≤ 1), per flaw.
    pub within: Vec<(LineFlaw, usize)>,
    /// The nearest of them: sample index, distance, its first flawed band and flaw.
    pub best: Option<(usize, f64, usize, LineFlaw)>,
}

/// The closest achievable pair and what keeps it from the targets.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Constraint {
    pub closest: Option<Closest>,
    /// The band farthest from its target at the closest sample and its signed relative miss.
    pub binding: Option<(usize, f64)>,
    pub hits: Vec<BoundHit>,
    /// Per freed parameter with an elasticity for the binding band, in job order.
    pub pushes: Vec<Push>,
    /// The freed parameters whose ±step lost the binding band's own line ([`line_jumps`]).
    pub jumps: Vec<usize>,
    /// Beside every bound a push lies beyond.
    pub edges: Vec<Edge>,
    pub nearer: Nearer,
}

/// The binding band of the closest sample: the one of largest tolerance-scaled miss (the first on
/// a tie) and its signed relative miss; `None` inside every tolerance.
fn binding_band(e: &Exploration, s: &Sample) -> Option<(usize, f64)> {
    let lines = s.outcome.lines()?;
    let mut best: Option<(usize, f64, f64)> = None;
    for (b, (l, t)) in lines.iter().zip(&e.targets).enumerate() {
        let Some(t) = t else { continue };
        let miss = relative_miss(l.freq_hz, *t);
        let scaled = miss.abs() / band_tolerance(b);
        if scaled > 1.0 && best.is_none_or(|x| scaled > x.2) {
            best = Some((b, miss, scaled));
        }
    }
    best.map(|(b, m, _)| (b, m))
}

/// Each freed parameter's first-order push of the binding band `band` to its target, from the
/// sensitivity `around` the closest sample `s`: only where both ±steps kept the band's line its
/// own and prominent (else the step jumped to another line, see [`line_jumps`]).
fn pushes(e: &Exploration, s: &Sample, band: usize, around: &[Sensitivity]) -> Vec<Push> {
    let (Some(lines), Some(target)) = (s.outcome.lines(), e.targets[band]) else {
        return Vec::new();
    };
    let f = lines[band].freq_hz;
    let goal = nearest_edge(f, target);
    let hits = bound_hits(e, s);
    around
        .iter()
        .enumerate()
        .filter(|(_, r)| own_line(&r.outcomes[0], band) && own_line(&r.outcomes[2], band))
        .filter_map(|(param, r)| {
            let el = r.elasticity.get(band).copied().flatten()?;
            let v = s.values[param];
            if el == 0.0 || !el.is_finite() || v <= 0.0 {
                return None;
            }
            let needed = v * (goal / f).powf(1.0 / el);
            let fp = &e.free[param];
            let beyond = if needed < fp.lower {
                Some(Side::Lower)
            } else if needed > fp.upper {
                Some(Side::Upper)
            } else {
                None
            };
            let on_bound = hits
                .iter()
                .any(|h| h.param == param && Some(h.side) == beyond);
            Some(Push {
                param,
                elasticity: el,
                needed,
                beyond,
                on_bound,
            })
        })
        .collect()
}

/// The freed parameters whose ±step around the closest sample left band `band` without an own,
/// prominent line (a failed run, or the band's largest maximum became another, flawed line).
fn line_jumps(band: usize, around: &[Sensitivity]) -> Vec<usize> {
    around
        .iter()
        .enumerate()
        .filter(|(_, r)| !(own_line(&r.outcomes[0], band) && own_line(&r.outcomes[2], band)))
        .map(|(i, _)| i)
        .collect()
}

/// What the outer [`EDGE_SHARE`] of the box beside bound `side` of parameter `param` gave.
pub fn edge(e: &Exploration, param: usize, side: Side) -> Edge {
    let fp = &e.free[param];
    let near = |s: &&Sample| {
        let u = fp.u_of(s.values[param]);
        match side {
            Side::Lower => u <= EDGE_SHARE,
            Side::Upper => u >= 1.0 - EDGE_SHARE,
        }
    };
    let inside: Vec<&Sample> = e.samples.iter().filter(near).collect();
    let mut failures: Vec<(FailureCause, usize)> = FailureCause::ALL
        .iter()
        .map(|c| {
            let n = inside
                .iter()
                .filter(|s| matches!(&s.outcome, Outcome::Failed { cause, .. } if cause == c))
                .count();
            (*c, n)
        })
        .filter(|(_, n)| *n > 0)
        .collect();
    failures.sort_by_key(|x| std::cmp::Reverse(x.1));
    Edge {
        param,
        side,
        samples: inside.len(),
        with_lines: inside
            .iter()
            .filter(|s| s.outcome.lines().is_some())
            .count(),
        failures,
    }
}

/// The samples nearer than `limit` (all samples with lines when `None`) whose lines do not count.
fn nearer(e: &Exploration, limit: Option<f64>) -> Nearer {
    let mut by_flaw: Vec<(LineFlaw, usize)> = Vec::new();
    let mut within: Vec<(LineFlaw, usize)> = Vec::new();
    let count = |v: &mut Vec<(LineFlaw, usize)>, flaw| match v.iter_mut().find(|(f, _)| *f == flaw)
    {
        Some((_, n)) => *n += 1,
        None => v.push((flaw, 1)),
    };
    let mut best: Option<(usize, f64, usize, LineFlaw)> = None;
    for (i, s) in e.samples.iter().enumerate() {
        let (Some((band, flaw)), Some(d)) = (first_flaw(s), distance(s, &e.targets)) else {
            continue;
        };
        if limit.is_some_and(|l| d >= l) {
            continue;
        }
        count(&mut by_flaw, flaw);
        if d <= 1.0 {
            count(&mut within, flaw);
        }
        if best.is_none_or(|b| d < b.1) {
            best = Some((i, d, band, flaw));
        }
    }
    by_flaw.sort_by_key(|x| std::cmp::Reverse(x.1));
    within.sort_by_key(|x| std::cmp::Reverse(x.1));
    Nearer {
        by_flaw,
        within,
        best,
    }
}

/// The closest achievable pair of `e` and what keeps it from the targets, from the exploration's
/// samples and its sensitivity around that pair ([`Exploration::around_closest`]).
pub fn constraint(e: &Exploration) -> Constraint {
    let closest = e
        .closest_pair
        .and_then(|k| distance(&e.samples[k], &e.targets).map(|d| (k, d)))
        .map(|(sample, distance)| Closest { sample, distance });
    let Some(c) = closest else {
        return Constraint {
            closest: None,
            binding: None,
            hits: Vec::new(),
            pushes: Vec::new(),
            jumps: Vec::new(),
            edges: Vec::new(),
            nearer: nearer(e, None),
        };
    };
    let s = &e.samples[c.sample];
    let binding = binding_band(e, s);
    let pushes = binding.map_or_else(Vec::new, |(b, _)| pushes(e, s, b, &e.around_closest));
    let jumps = binding.map_or_else(Vec::new, |(b, _)| line_jumps(b, &e.around_closest));
    let edges = pushes
        .iter()
        .filter(|p| p.is_lever(s.values[p.param]))
        .filter_map(|p| p.beyond.map(|side| edge(e, p.param, side)))
        .collect();
    Constraint {
        closest,
        binding,
        hits: bound_hits(e, s),
        pushes,
        jumps,
        edges,
        nearer: nearer(e, Some(c.distance)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::explore::BandLine;
    use crate::job::FreeParam;
    use crate::model::ParamId;

    fn line(freq_hz: f64, prominence: f64, harmonic_of_hz: Option<f64>) -> BandLine {
        BandLine {
            freq_hz,
            prominence,
            harmonic_of_hz,
            below_dominant: 1.0,
        }
    }

    fn lines(v: &[f64], l: [BandLine; 2]) -> Sample {
        Sample {
            values: v.to_vec(),
            outcome: Outcome::Lines {
                lines: l.to_vec(),
                cost: 0.0,
            },
        }
    }

    fn failed(v: &[f64], cause: FailureCause) -> Sample {
        Sample {
            values: v.to_vec(),
            outcome: Outcome::Failed {
                cause,
                message: String::new(),
            },
        }
    }

    /// A synthetic exploration of two freed parameters: head mass on [0.01, 0.15] kg (log box:
    /// 15×) and A on [0.2, 1.5] (linear), targets 78.4 Hz and 900 Hz.
    fn exploration(samples: Vec<Sample>) -> Exploration {
        let free = vec![
            FreeParam::new(ParamId::HeadMass, 0.01, 0.15),
            FreeParam::new(ParamId::A, 0.2, 1.5),
        ];
        assert!(free[0].log && !free[1].log);
        let start = samples[0].clone();
        Exploration {
            job: "synthetic".into(),
            model: "blade2dof".into(),
            free,
            bands: vec![
                ("low".into(), [30.0, 300.0]),
                ("high".into(), [500.0, 5000.0]),
            ],
            targets: vec![Some([78.4, 78.4]), Some([900.0, 900.0])],
            signal: Default::default(),
            seed: 1,
            samples,
            start,
            sensitivity: Vec::new(),
            closest_pair: None,
            around_closest: Vec::new(),
            lever_checks: Vec::new(),
            wall_time_s: 0.0,
            threads: 1,
        }
    }

    /// The known answer: sample 2 is nearest (61 Hz: −22.2 %, 22.2 tolerances; 905 Hz: 0.28),
    /// sample 1 is nearer (79 Hz, 0.77; 890 Hz, 0.56) but its high line is a harmonic, sample 3 is
    /// nearer still but weak (×3), sample 4 failed, sample 0 is farther (50 Hz: 36.2 tolerances).
    fn known() -> Vec<Sample> {
        vec![
            lines(
                &[0.05, 0.8],
                [line(50.0, 100.0, None), line(900.0, 50.0, None)],
            ),
            lines(
                &[0.02, 0.5],
                [line(79.0, 300.0, None), line(890.0, 50.0, Some(445.0))],
            ),
            lines(
                &[0.0101, 1.49],
                [line(61.0, 900.0, None), line(905.0, 40.0, None)],
            ),
            lines(
                &[0.03, 0.7],
                [line(78.4, 3.0, None), line(900.0, 60.0, None)],
            ),
            failed(&[0.011, 0.4], FailureCause::ContactLoss),
        ]
    }

    #[test]
    fn distance_is_the_largest_tolerance_scaled_miss() {
        let s = known();
        let t = exploration(s.clone()).targets;
        // 61 Hz against 78.4 Hz: (61 − 78.4)/78.4 = −0.22194 over 1 %; 905 against 900: 0.2778.
        let d = distance(&s[2], &t).unwrap();
        assert!((d - 17.4 / 78.4 / 0.01).abs() < 1e-9, "{d}");
        assert_eq!(distance(&s[4], &t), None);
        // A range: zero inside, measured from the nearer edge outside.
        assert_eq!(relative_miss(500.0, [359.0, 692.0]), 0.0);
        assert!((relative_miss(300.0, [359.0, 692.0]) + 59.0 / 359.0).abs() < 1e-15);
        assert!((relative_miss(700.0, [359.0, 692.0]) - 8.0 / 692.0).abs() < 1e-15);
    }

    #[test]
    fn closest_pair_takes_only_own_prominent_lines() {
        let s = known();
        let e = exploration(s.clone());
        let c = closest_pair(&s, &e.targets).unwrap();
        assert_eq!(c.sample, 2);
        // Nothing counts: no closest pair.
        let flawed = vec![s[1].clone(), s[3].clone(), s[4].clone()];
        assert_eq!(closest_pair(&flawed, &e.targets), None);
    }

    #[test]
    fn bounds_and_the_direction_to_the_target_are_named() {
        let mut e = exploration(known());
        e.closest_pair = Some(2);
        // Around sample 2 the low line falls with a heavier head (elasticity −0.5) and does not
        // move with A; the high line rises with A.
        let sens = |parameter, el: [Option<f64>; 2]| Sensitivity {
            parameter,
            values: [0.0; 3],
            outcomes: [
                e.samples[0].outcome.clone(),
                e.samples[0].outcome.clone(),
                e.samples[0].outcome.clone(),
            ],
            elasticity: el.to_vec(),
        };
        e.around_closest = vec![
            sens(ParamId::HeadMass, [Some(-0.5), Some(0.1)]),
            sens(ParamId::A, [Some(5.0), Some(0.3)]),
        ];
        // A's lower step gave a weak low line (sample 3's): its elasticity of 5 is a jump to
        // another line, not a lever.
        e.around_closest[1].outcomes[0] = e.samples[3].outcome.clone();
        let c = constraint(&e);
        assert_eq!(c.closest.map(|c| c.sample), Some(2));
        // Head mass 0.0101 kg: u = ln(1.01)/ln(15) = 0.0037, on its lower bound; A 1.49:
        // u = 1.29/1.3 = 0.992, on its upper.
        let sides: Vec<(usize, Side)> = c.hits.iter().map(|h| (h.param, h.side)).collect();
        assert_eq!(sides, [(0, Side::Lower), (1, Side::Upper)]);
        let (band, miss) = c.binding.unwrap();
        assert_eq!(band, 0);
        assert!((miss + 17.4 / 78.4).abs() < 1e-12);
        // 78.4 Hz needs head mass 0.0101·(78.4/61)^(−2) = 0.006114 kg: below the 10 g bound it sits on.
        assert_eq!(c.pushes.len(), 1);
        let p = c.pushes[0];
        assert_eq!(
            (p.param, p.beyond, p.on_bound),
            (0, Some(Side::Lower), true)
        );
        assert!(
            (p.needed - 0.0101 * (61.0f64 / 78.4).powi(2)).abs() < 1e-12,
            "{}",
            p.needed
        );
        assert!(p.is_lever(0.0101));
        assert_eq!(c.jumps, [1]);
        // The lowest tenth of the head-mass box (u ≤ 0.1: M ≤ 0.01·15^0.1 = 0.01311 kg) holds
        // samples 2 and 4: one with lines, one contact loss.
        assert_eq!(c.edges.len(), 1);
        let edge = &c.edges[0];
        assert_eq!((edge.samples, edge.with_lines), (2, 1));
        assert_eq!(edge.failures, [(FailureCause::ContactLoss, 1)]);
        // Nearer than sample 2 (22.2): sample 1 (harmonic, 1.1) and sample 3 (weak, 0).
        let mut flaws = c.nearer.by_flaw.clone();
        flaws.sort();
        assert_eq!(flaws, [(LineFlaw::Harmonic, 1), (LineFlaw::Weak, 1)]);
        let mut within = c.nearer.within.clone();
        within.sort();
        assert_eq!(within, [(LineFlaw::Harmonic, 1), (LineFlaw::Weak, 1)]);
        let best = c.nearer.best.unwrap();
        assert_eq!((best.0, best.2, best.3), (3, 0, LineFlaw::Weak));
    }
}
