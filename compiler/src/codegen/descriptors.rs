//! Descriptor values (`signorini_descriptors`) as Rust constant expressions: their text and
//! lists `Borrowed` by the constant. Each printer names every field of what it prints, so a
//! field added to a descriptor is a compile error here until it is printed.

use signorini_descriptors::{
    CoefInfo, Combination, InitialDesc, Level, ParamInfo, SchemeDesc, SlotInfo, SlotUse, StageDesc, TermDesc,
};

fn text(s: &str) -> String {
    format!("Borrowed({s:?})")
}

fn list<T>(items: &[T], item: impl Fn(&T) -> String) -> String {
    let items: Vec<String> = items.iter().map(item).collect();
    format!("Borrowed(&[{}])", items.join(", "))
}

/// `ParamInfo { ... }`, its range the expression `range` (an entry of the struct's `RANGES`,
/// whose bounds are written as in the source).
pub fn param(p: &ParamInfo, range: &str) -> String {
    let ParamInfo { name, default, range: _, doc, declared, written, owner } = p;
    format!(
        "ParamInfo {{ name: {}, default: {default:?}, range: {range}, doc: {}, declared: {}, written: {}, owner: {} }}",
        text(name),
        text(doc),
        text(declared),
        text(written),
        text(owner)
    )
}

/// `CoefInfo { ... }`.
pub fn coef(c: &CoefInfo) -> String {
    let CoefInfo { name, rank, doc, declared } = c;
    format!("CoefInfo {{ name: {}, rank: {rank}, doc: {}, declared: {} }}", text(name), text(doc), text(declared))
}

/// `SlotInfo { ... }`.
pub fn slot(s: &SlotInfo) -> String {
    let SlotInfo { name, fields, functional, doc, declared } = s;
    format!(
        "SlotInfo {{ name: {}, fields: {fields}, functional: {functional}, doc: {}, declared: {} }}",
        text(name),
        text(doc),
        text(declared)
    )
}

fn level(l: &Level) -> String {
    match l {
        Level::State(i) => format!("Level::State({i})"),
        Level::Stage(stage, index) => format!("Level::Stage({stage}, {index})"),
    }
}

fn combination(c: &Combination) -> String {
    let Combination { unknown, known } = c;
    let unknown = unknown.map_or("None".to_string(), |k| format!("Some({k})"));
    let known = list(known, |(l, k)| format!("({}, {k})", level(l)));
    format!("Combination {{ unknown: {unknown}, known: {known} }}")
}

fn term(t: &TermDesc) -> String {
    let TermDesc { coef, form, args, time } = t;
    format!("TermDesc {{ coef: {coef}, form: {}, args: {}, time: {time} }}", text(form), list(args, combination))
}

fn stage(s: &StageDesc) -> String {
    let StageDesc { name, time, quantities, values, terms } = s;
    format!(
        "StageDesc {{ name: {}, time: {time}, quantities: {}, values: {}, terms: {} }}",
        text(name),
        list(quantities, |q| text(q)),
        list(values, combination),
        list(terms, term)
    )
}

fn slot_use(u: &SlotUse) -> String {
    let SlotUse { name, fields, declared } = u;
    format!("SlotUse {{ name: {}, fields: {fields}, declared: {} }}", text(name), text(declared))
}

/// `SchemeDesc { ... }`.
pub fn scheme(d: &SchemeDesc) -> String {
    let SchemeDesc { name, uses, states, initial, stages, updates, estimate, coefficients } = d;
    let initial = match initial {
        Some(InitialDesc { state, terms }) => {
            format!("Some(InitialDesc {{ state: {state}, terms: {} }})", list(terms, term))
        }
        None => "None".into(),
    };
    let estimate = estimate.as_ref().map_or("None".to_string(), |c| format!("Some({})", combination(c)));
    format!(
        "SchemeDesc {{ name: {}, uses: {}, states: {}, initial: {initial}, stages: {}, updates: {}, estimate: {estimate}, coefficients: {coefficients} }}",
        text(name),
        list(uses, slot_use),
        list(states, |s| text(s)),
        list(stages, stage),
        list(updates, level)
    )
}
