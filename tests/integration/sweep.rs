//! The talk's conclusions on the bar (the report's Δt sweep, docs/mathematics.md §7), as checks:
//! mass redistribution removes the spurious oscillation of the contact stress; HHT and TR-BDF2
//! dissipate; every implicit scheme converges up to Δt = 0.2 with either mass; IMEX-HHT's explicit
//! contact gains energy with the consistent mass.

use signorini::report::sweep::{self, Point};

/// A scheme that claims a stability limit (an explicit one).
fn explicit(scheme: &str) -> bool {
    let methods = signorini::driver::Methods { scheme: scheme.into(), ..Default::default() };
    signorini::verify::claimed_cfl(&methods).unwrap().is_some()
}

fn point<'a>(s: &'a sweep::Sweeps, scheme: &str, mass: &str, dt: f64) -> &'a Point {
    s.series("bar", scheme, mass).into_iter().find(|p| p.dt == dt).unwrap_or_else(|| panic!("{scheme} {mass} {dt}"))
}

#[test]
fn the_bar_sweep_shows_the_talks_conclusions() {
    let s = sweep::run(&mut |_| {}, &sweep::cases()[..1]);
    for scheme in signorini::driver::all_schemes() {
        if scheme == "hht_imex" {
            // Explicit contact with the consistent mass: unstable, the energy grows and the
            // guard stops the run (the sweep's guard allows half the energy scale).
            match &point(&s, scheme, "consistent", 0.01).outcome {
                Ok(m) => assert!(m.energy_change > 0.5, "{scheme}: {m:?}"),
                Err(e) => assert!(e.contains("exceeds E_aug(0)"), "{scheme}: {e}"),
            }
            assert_eq!(s.largest_converging("bar", scheme, "consistent"), None);
            continue;
        }
        if explicit(scheme) {
            // Central differences: refused with the redistributed mass, and above its critical
            // step (0.0257 on this bar), converging below it.
            assert_eq!(s.largest_converging("bar", scheme, "redistributed"), None);
            assert_eq!(s.largest_converging("bar", scheme, "consistent"), Some(0.02));
            let refused = point(&s, scheme, "consistent", 0.05).outcome.as_ref().unwrap_err();
            assert!(refused.contains("beyond the stable step"), "{refused}");
            continue;
        }
        for mass in ["consistent", "redistributed"] {
            let largest = s.largest_converging("bar", scheme, mass);
            assert!(largest.is_some_and(|dt| dt >= 0.2), "{scheme} {mass}: converges up to {largest:?}");
        }
        // The stress where the scheme imposes contact: at t^{n+1/2} for midpoint, hybrid and
        // energy–momentum (the midpoint rule for a linear material).
        let half = matches!(scheme, "midpoint" | "hybrid" | "energy_momentum");
        let osc = |mass| {
            let m = point(&s, scheme, mass, 0.01).outcome.as_ref().unwrap();
            if half { m.oscillation_half } else { m.oscillation }
        };
        let (consistent, redistributed) = (osc("consistent"), osc("redistributed"));
        assert!(redistributed < consistent / 4.0, "{scheme}: oscillation {consistent} → {redistributed}");
        if matches!(scheme, "hht" | "trbdf2") {
            for p in s.series("bar", scheme, "consistent") {
                let m = p.outcome.as_ref().unwrap();
                assert!(m.energy_change < 0.0, "{scheme} Δt = {}: {m:?}", p.dt);
            }
        }
    }
}

/// The disc at large steps: every implicit scheme converges at Δt = 0.2 with either mass; at
/// Δt = 1 the hybrid scheme still loses less than 10 % of the impact energy, while midpoint
/// with the consistent mass gains energy at contact (its jumps are ≥ 0 on entering contact).
#[test]
fn the_disc_at_large_steps() {
    let case = sweep::Case { steps: &[0.2, 1.0], ..sweep::cases()[1] };
    let s = sweep::run(&mut |_| {}, &[case]);
    let get = |scheme: &str, mass: &str, dt: f64| {
        s.series("disc", scheme, mass).into_iter().find(|p| p.dt == dt).unwrap().outcome.clone()
    };
    for scheme in signorini::driver::all_schemes() {
        for mass in ["consistent", "redistributed"] {
            let p = s.series("disc", scheme, mass)[0];
            let implicit = scheme != "hht_imex" && !explicit(scheme);
            assert_eq!(p.converged(), implicit, "{scheme} {mass} at Δt = 0.2: {:?}", p.outcome);
        }
    }
    for mass in ["consistent", "redistributed"] {
        let hybrid = get("hybrid", mass, 1.0).unwrap();
        assert!(hybrid.energy_change < 0.0 && hybrid.energy_change > -0.1, "hybrid {mass}: {hybrid:?}");
    }
    let midpoint = get("midpoint", "consistent", 1.0).unwrap();
    assert!(midpoint.energy_change > 0.1, "midpoint: {midpoint:?}");
}
