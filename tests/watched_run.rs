//! A run watched as it goes (the Python API's `on_step`): the watcher sees every row in order,
//! and one that says stop ends the run after that row's step, which keeps its rows. A test
//! binary of its own: a stop is the process's (SIGINT's flag), which the other tests' runs
//! must not see.

use signorini::error::CaseError;
use signorini::problem::run::{Options, Seen, run_watched};

#[test]
fn a_watcher_sees_every_row_and_stops_the_run_after_the_step_it_says_stop() {
    let mut opts = Options::new("bar");
    opts.t_end = Some(0.5);
    opts.keep_fields = true;
    let seen = std::cell::RefCell::new(Vec::new());
    let watcher = |s: &Seen| {
        assert_eq!(s.columns.len(), s.values.len());
        assert_eq!(s.t_end, 0.5);
        seen.borrow_mut().push(s.t);
        true
    };
    let whole = run_watched(&opts, Some(&watcher)).unwrap_or_else(|s| panic!("{}", s.error));
    let times: Vec<f64> = whole.rows.iter().map(|r| r.0).collect();
    assert_eq!(*seen.borrow(), times);
    // The last state is the last row's, on the problem's mesh.
    let fields = whole.fields.as_ref().expect("kept");
    let mesh = &fields.mesh;
    assert_eq!((fields.t, fields.u.len()), (*times.last().unwrap(), mesh.num_nodes() * mesh.dim()));

    seen.borrow_mut().clear();
    let stop = |s: &Seen| {
        seen.borrow_mut().push(s.t);
        s.t < 0.1
    };
    let stopped = match run_watched(&opts, Some(&stop)) {
        Ok(_) => panic!("the watcher said stop"),
        Err(s) => s,
    };
    signorini::interrupt::clear();
    assert!(matches!(stopped.error, CaseError::Interrupted { t } if (0.1..0.11).contains(&t)), "{}", stopped.error);
    let partial = stopped.run.expect("the rows up to the stop");
    let last = partial.rows.last().unwrap().0;
    // The row the watcher said stop at is the last one: its rows are a prefix of the whole run's.
    assert_eq!(last, *seen.borrow().last().unwrap());
    assert!(last >= 0.1 && partial.rows[partial.rows.len() - 2].0 < 0.1);
    for (a, b) in partial.rows.iter().zip(&whole.rows) {
        assert_eq!(a.0.to_bits(), b.0.to_bits());
        assert!(a.1.iter().zip(&b.1).all(|(x, y)| x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan())));
    }
    assert!(partial.fields.is_some());
}
