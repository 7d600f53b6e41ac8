//! The right-hand sides allocate nothing (issue 5, "Speed"): counted with a global allocator that
//! tallies allocations made by the current thread.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use wiperlab::model::belt::Belt;
use wiperlab::model::benchmarks::leine_belt;
use wiperlab::model::{Blade, BladeParams, StickForm};
use wiperlab::simulate::blade::default_window;
use wiperlab::simulate::hybrid::{Mode, Phase, SolverOptions, StickSlipModel, integrate};
use wiperlab::simulate::method::{Method, Outcome};
use wiperlab::simulate::rk;
use wiperlab::simulate::timestep::NonsmoothModel;

struct Counting;

thread_local! {
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

fn allocations_in(f: impl FnOnce()) -> usize {
    let before = ALLOCS.with(|c| c.get());
    f();
    ALLOCS.with(|c| c.get()) - before
}

fn params() -> BladeParams {
    common::true_blade()
}

#[test]
fn right_hand_sides_allocate_nothing() {
    // The counter sees allocations (so the zero below means something).
    assert!(allocations_in(|| drop(std::hint::black_box(vec![1u8; 8]))) >= 1);
    let p = params();
    let reduced = Blade::new(p, StickForm::Reduced);
    let baum = Blade::new(p, StickForm::Baumgarte { omega_b_per_s: 1e4 });
    let (t0, _) = default_window(&p);
    let y = reduced.slip_equilibrium(t0).unwrap();
    let anchor = reduced.tip_position(t0, &y);
    let belt = Belt {
        c_ns_per_m: 0.1,
        ..leine_belt()
    };
    let modes = [
        Mode {
            phase: Phase::SlipPos,
            anchor: 0.0,
            region: 0,
        },
        Mode {
            phase: Phase::SlipNeg,
            anchor: 0.0,
            region: 0,
        },
        Mode {
            phase: Phase::Stick,
            anchor,
            region: 0,
        },
    ];
    let mut sink = 0.0;
    let n = allocations_in(|| {
        for mode in &modes {
            // (At this slip+ equilibrium slip− is Painlevé-inconsistent; its error would allocate.)
            for blade in [&reduced, &baum]
                .into_iter()
                .filter(|_| mode.phase != Phase::SlipNeg)
            {
                let mut dy = [0.0; 4];
                let mut yc = y;
                blade.complete(mode, t0, &mut yc).unwrap();
                let c = blade.rhs(mode, t0, &yc, &mut dy).unwrap();
                sink += c.normal + dy[2] + blade.slip_velocity(t0, &yc);
            }
            let mut dy = [0.0; 2];
            let c = belt.rhs(mode, 0.0, &[0.3, 0.1], &mut dy).unwrap();
            sink += c.friction + dy[1];
        }
        // One DOPRI5 step (6 stages) on the blade's slip right-hand side.
        let mode = modes[0];
        let mut rhs =
            |t: f64, yy: &[f64; 4], dy: &mut [f64; 4]| reduced.rhs(&mode, t, yy, dy).map(|_| ());
        let mut f0 = [0.0; 4];
        rhs(t0, &y, &mut f0).unwrap();
        let a = rk::attempt(&mut rhs, t0, &y, &f0, 1e-5, 1e-8, 1e-10).unwrap();
        sink += a.dense.eval(t0 + 5e-6)[0];
        // One DOP853 step (12 stages and the 3 of its dense output), through the method layer.
        match Method::Dop853
            .attempt(&mut rhs, t0, &y, &f0, 1e-5, 1e-8, 1e-10)
            .unwrap()
        {
            Outcome::Accepted(step) => sink += step.dense.eval(t0 + 5e-6)[0],
            Outcome::Rejected { err } => panic!("the DOP853 step was rejected (err {err})"),
        }
        // The comparison methods' right-hand sides.
        let mut yy = y;
        reduced.moreau_step(t0, 1e-6, &mut yy).unwrap();
        let mut dy = [0.0; 4];
        reduced.smoothed_rhs(1e-3, t0, &y, &mut dy).unwrap();
        sink += yy[0] + dy[2];
    });
    assert!(sink.is_finite());
    assert_eq!(n, 0, "{n} allocations in the right-hand sides");
}

/// A whole event-driven run allocates only for its output (transition list growth), not per step:
/// over the 1.887 s reversal window (> 10,000 steps) fewer than 100 allocations.
#[test]
fn integration_allocates_per_output_not_per_step() {
    let p = params();
    let blade = Blade::new(p, StickForm::Reduced);
    let (t0, t1) = default_window(&p);
    let y0 = blade.slip_equilibrium(t0).unwrap();
    let mode = Mode {
        phase: Phase::SlipPos,
        anchor: 0.0,
        region: 0,
    };
    let opts = SolverOptions {
        rtol: 1e-8,
        atol: 1e-10,
        ..Default::default()
    };
    let mut steps = 0;
    let n = allocations_in(|| {
        let run = integrate(&blade, t0, y0, mode, t1, &[], &opts).unwrap();
        steps = run.stats.steps;
    });
    eprintln!("{n} allocations over {steps} steps");
    assert!(steps > 10_000);
    assert!(n < 100, "{n} allocations");
}
