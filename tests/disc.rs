//! The bouncing disc (spec §6.2): before the first contact every scheme reproduces free fall
//! exactly, u_y = −½ 0.1 t², and the first contact happens in the step containing t* = √40.

use signorini::cases::bar::SchemeChoice;
use signorini::cases::disc::{self, GRAVITY, Options};

#[test]
fn free_fall_is_exact_and_contact_starts_in_the_right_step() {
    let t_star = (2.0 * 2.0 / GRAVITY).sqrt();
    for scheme in SchemeChoice::ALL {
        let opts = Options { scheme, h: 2.0, t_end: 6.5, ..Options::default() };
        let r = disc::run(&opts).unwrap_or_else(|e| panic!("{scheme:?}: {e}"));
        for row in r.series.iter().filter(|row| row.t < t_star - 0.05) {
            let exact = -0.5 * GRAVITY * row.t * row.t;
            assert!((row.uy_mean - exact).abs() < 1e-10, "{scheme:?} t = {}: mean {} vs {exact}", row.t, row.uy_mean);
            assert!(
                (row.uy_lowest - exact).abs() < 1e-10,
                "{scheme:?} t = {}: lowest {} vs {exact}",
                row.t,
                row.uy_lowest
            );
            assert_eq!(row.active_points, 0);
        }
        let first = r.summary.first_contact.expect("the disc reaches the ground");
        assert!(first - opts.dt < t_star && t_star <= first, "{scheme:?}: first contact at {first}, t* = {t_star}");
    }
}
