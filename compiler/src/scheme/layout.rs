//! A compiled scheme laid out for a stepper: every scalar it needs numbered in one coefficient
//! array (in first-use order), and its description for the runtime (`SchemeDesc`: stages,
//! terms and updates referring to those numbers). Generated Rust prints the description; a
//! scheme interpreted at run time runs with it as built. One numbering, one description.

use std::collections::HashMap;

use signorini_descriptors::{Combination, InitialDesc, List, SchemeDesc, SlotUse, StageDesc, TermDesc};

use super::{Affine, Quantity, SchemeIr, Term};
use crate::ir::graph::{Graph, NodeId};
use crate::source::SourceMap;

/// A compiled scheme's description, and what it does not say: the graph node of each of its
/// coefficients, and what each is for.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    pub desc: SchemeDesc,
    /// `desc.coefficients` nodes, in the coefficient array's order.
    pub coefficients: Vec<NodeId>,
    /// Per coefficient, what it is for in the scheme's own names: a line per part of the
    /// scheme using it (the initial problem, a stage), e.g. "stage `bdf2`: coefficient of `u`
    /// in `v'` and `a'`; weight of `mass(a')`". Generated code shows them above `out[k]`.
    pub uses: Vec<Vec<String>>,
}

/// One use of a coefficient in part `part` (0 the initial problem, s + 1 stage s): its `role`
/// for `object` (the stage, a term, a quantity or a term's argument, as written).
struct Use {
    part: usize,
    role: Role,
    object: String,
}

#[derive(Clone, PartialEq)]
enum Role {
    Time,
    Weight,
    /// Of this level.
    Coefficient(String),
}

#[derive(Default)]
struct Numbering {
    index: HashMap<NodeId, usize>,
    order: Vec<NodeId>,
    uses: Vec<Vec<Use>>,
}

/// How a part of the scheme (its number, as in `Use`) names its levels.
struct Names<'a> {
    part: usize,
    unknown: &'a str,
    /// A combination's name when it is one quantity (a term's argument written `a'`).
    named: &'a dyn Fn(&Affine) -> Option<String>,
    /// A known level's name.
    level: &'a dyn Fn(Quantity) -> String,
}

impl Numbering {
    fn of(&mut self, n: NodeId) -> usize {
        *self.index.entry(n).or_insert_with(|| {
            self.order.push(n);
            self.uses.push(Vec::new());
            self.order.len() - 1
        })
    }

    /// `of`, noting the use.
    fn used(&mut self, n: NodeId, part: usize, role: Role, object: String) -> usize {
        let k = self.of(n);
        self.uses[k].push(Use { part, role, object });
        k
    }

    /// A combination's numbers, its coefficients noted as being in `object` (or not noted: the
    /// unknown in itself, a term's argument that is a quantity, noted as that quantity).
    fn combination(&mut self, g: &Graph, a: &Affine, names: &Names, object: Option<&str>) -> Combination {
        let one = |n: &mut Self, c: NodeId, level: &str| match object {
            Some(o) => n.used(c, names.part, Role::Coefficient(level.into()), o.into()),
            None => n.of(c),
        };
        let unknown = (!g.is_zero(a.unknown)).then(|| one(self, a.unknown, names.unknown));
        let known = a.known.iter().map(|(q, k)| ((*q).into(), one(self, *k, &(names.level)(*q)))).collect();
        Combination { unknown, known }
    }

    /// A part's terms. The time most of them share is noted once, "every term" (but the few
    /// others), for the lines to stay short.
    fn terms(&mut self, g: &Graph, ts: &[Term], names: &Names) -> List<TermDesc> {
        let labels = labels(g, ts, names.named);
        let common = ts.iter().map(|t| t.time).max_by_key(|&x| ts.iter().filter(|t| t.time == x).count());
        let others: Vec<String> =
            ts.iter().zip(&labels).filter(|(t, _)| Some(t.time) != common).map(|(_, l)| format!("`{l}`")).collect();
        let shared = ts.len() >= 2 && others.len() * 2 < ts.len();
        let descs = ts
            .iter()
            .zip(&labels)
            .map(|(t, label)| {
                let coef = self.used(t.coef, names.part, Role::Weight, format!("`{label}`"));
                let args = t
                    .args
                    .iter()
                    .enumerate()
                    .map(|(i, a)| {
                        let object = match t.args.len() {
                            1 => format!("{ARGUMENT}`{label}`"),
                            _ => format!("argument {} of `{label}`", i + 1),
                        };
                        let object = (names.named)(a).is_none().then_some(object);
                        self.combination(g, a, names, object.as_deref())
                    })
                    .collect();
                let time = match shared && Some(t.time) == common {
                    true => self.of(t.time),
                    false => self.used(t.time, names.part, Role::Time, format!("`{label}`")),
                };
                TermDesc { coef, form: t.form.clone().into(), args, time }
            })
            .collect();
        if let (true, Some(c)) = (shared, common) {
            let object = match others.is_empty() {
                true => "every term".to_string(),
                false => format!("every term but {}", and(&others)),
            };
            self.used(c, names.part, Role::Time, object);
        }
        descs
    }
}

/// What the one argument of a term is called ("the arguments of `f(…)` and `g(…)`" together).
const ARGUMENT: &str = "the argument of ";

/// Terms as written: `load(t + dt)`, `mass(a')`, `stiffness(…)` (an argument that is no one
/// quantity); a label two terms share gets its rank among them (`#2`).
fn labels(g: &Graph, ts: &[Term], named: &dyn Fn(&Affine) -> Option<String>) -> Vec<String> {
    let written: Vec<String> = ts
        .iter()
        .map(|t| {
            let args: Vec<String> = match t.args.is_empty() {
                true => vec![super::print::scalar(g, t.time)],
                false => t.args.iter().map(|a| named(a).unwrap_or_else(|| "…".into())).collect(),
            };
            format!("{}({})", t.form, args.join(", "))
        })
        .collect();
    written
        .iter()
        .enumerate()
        .map(|(i, w)| match written.iter().filter(|x| *x == w).count() {
            1 => w.clone(),
            _ => format!("{w} #{}", written[..=i].iter().filter(|x| *x == w).count()),
        })
        .collect()
}

/// Whether `a` is `level` alone, with coefficient one.
fn is_level(g: &Graph, a: &Affine) -> Option<Option<Quantity>> {
    match (g.is_zero(a.unknown), a.known.as_slice()) {
        (false, []) if g.as_const(a.unknown) == Some(1.0) => Some(None),
        (true, [(q, c)]) if g.as_const(*c) == Some(1.0) => Some(Some(*q)),
        _ => None,
    }
}

/// The layout of a compiled scheme (`sources`: where its `uses` line is).
pub fn layout(s: &SchemeIr, sources: &SourceMap) -> Layout {
    let g = &s.graph;
    let mut n = Numbering::default();
    let level = |q: Quantity| match q {
        Quantity::State(i) => s.states[i].clone(),
        Quantity::Stage { stage, index } => s.stages[stage].quantities[index].clone(),
    };
    let mut parts = vec![String::new()];
    let initial = s.initial.as_ref().map(|i| {
        let unknown = &s.states[i.state];
        parts[0] = format!("initial `{unknown}`");
        let named = |a: &Affine| is_level(g, a).map(|q| q.map_or_else(|| unknown.clone(), level));
        let names = Names { part: 0, unknown, named: &named, level: &level };
        InitialDesc { state: i.state, terms: n.terms(g, &i.terms, &names) }
    });
    let stages = s
        .stages
        .iter()
        .enumerate()
        .map(|(si, st)| {
            parts.push(format!("stage `{}`", st.name));
            let named = |a: &Affine| match st.values.iter().position(|v| v == a) {
                Some(i) => Some(st.quantities[i].clone()),
                None => is_level(g, a).and_then(|q| q.map(level)),
            };
            let names = Names { part: si + 1, unknown: &st.quantities[0], named: &named, level: &level };
            let time = n.used(st.time, si + 1, Role::Time, "the stage".into());
            // The unknown's own value (itself) says nothing.
            let values = (st.quantities.iter().zip(&st.values).enumerate())
                .map(|(i, (q, v))| n.combination(g, v, &names, (i > 0).then(|| format!("`{q}`")).as_deref()))
                .collect();
            StageDesc {
                name: st.name.clone().into(),
                time,
                quantities: st.quantities.iter().map(|q| q.clone().into()).collect(),
                values,
                terms: n.terms(g, &st.terms, &names),
            }
        })
        .collect();
    let estimate = s.estimate.as_ref().map(|e| {
        parts.push("the estimate".into());
        let named = |_: &Affine| None;
        let names = Names { part: parts.len() - 1, unknown: "", named: &named, level: &level };
        n.combination(g, e, &names, Some("the estimate"))
    });
    let uses = s
        .slots
        .iter()
        .map(|u| SlotUse {
            name: u.name.clone().into(),
            fields: u.fields,
            declared: crate::docs::location_col(sources, u.span).into(),
        })
        .collect();
    let desc = SchemeDesc {
        name: s.name.clone().into(),
        uses,
        states: s.states.iter().map(|x| x.clone().into()).collect(),
        initial,
        stages,
        updates: s.updates.iter().map(|&q| q.into()).collect(),
        estimate,
        coefficients: n.order.len(),
    };
    let uses = n.uses.iter().map(|u| described(u, &parts)).collect();
    Layout { desc, coefficients: n.order, uses }
}

/// A coefficient's uses as lines, a part per line: "stage `s`: weight of `f(a)` and `g(b)`;
/// coefficient of `u` and `v` in `w`"; the coefficients of several levels in the same objects
/// are one clause, where the first of them is.
fn described(uses: &[Use], parts: &[String]) -> Vec<String> {
    enum Clause {
        Said(String),
        Coefficient { levels: Vec<String>, objects: Vec<String> },
    }
    let mut lines = Vec::new();
    for (p, name) in parts.iter().enumerate() {
        let mine: Vec<&Use> = uses.iter().filter(|u| u.part == p).collect();
        let mut roles: Vec<&Role> = Vec::new();
        for u in &mine {
            if !roles.contains(&&u.role) {
                roles.push(&u.role);
            }
        }
        let mut clauses: Vec<Clause> = Vec::new();
        for r in roles {
            let mut objects: Vec<String> = Vec::new();
            for u in mine.iter().filter(|u| u.role == *r) {
                if !objects.contains(&u.object) {
                    objects.push(u.object.clone());
                }
            }
            let same = |c: &&mut Clause| matches!(c, Clause::Coefficient { objects: o, .. } if *o == objects);
            match r {
                Role::Time => clauses.push(Clause::Said(format!("time of {}", and(&objects)))),
                Role::Weight => clauses.push(Clause::Said(format!("weight of {}", and(&objects)))),
                Role::Coefficient(level) => match clauses.iter_mut().find(same) {
                    Some(Clause::Coefficient { levels, .. }) => levels.push(format!("`{level}`")),
                    _ => clauses.push(Clause::Coefficient { levels: vec![format!("`{level}`")], objects }),
                },
            }
        }
        let said: Vec<String> = clauses
            .into_iter()
            .map(|c| match c {
                Clause::Said(s) => s,
                Clause::Coefficient { levels, objects } => {
                    let args: Option<Vec<String>> =
                        objects.iter().map(|o| o.strip_prefix(ARGUMENT).map(String::from)).collect();
                    let objects = match args {
                        Some(terms) if terms.len() > 1 => format!("the arguments of {}", and(&terms)),
                        _ => and(&objects),
                    };
                    format!("coefficient of {} in {objects}", and(&levels))
                }
            })
            .collect();
        if !said.is_empty() {
            lines.push(format!("{name}: {}", said.join("; ")));
        }
    }
    lines
}

/// `a`, `a and b`, `a, b and c`.
fn and(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::source::MemLoader;

    fn laid_out(name: &str, text: &str) -> Layout {
        let path = std::path::Path::new(name);
        let prog = crate::check_text(path, text, &MemLoader::default()).unwrap_or_else(|(d, _)| panic!("{d:?}"));
        layout(&prog.schemes[0], &prog.sources)
    }

    fn library(name: &str) -> Layout {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../forms/schemes/{name}.wf"));
        laid_out(&format!("{name}.wf"), &std::fs::read_to_string(path).expect("a library scheme"))
    }

    #[test]
    fn every_coefficient_says_what_it_is_for() {
        for name in
            ["central", "genalpha", "hht", "hht_imex", "hht_unweighted", "hybrid", "midpoint", "newmark", "trbdf2"]
        {
            let l = library(name);
            assert_eq!(l.uses.len(), l.desc.coefficients, "{name}");
            assert!(l.uses.iter().all(|u| !u.is_empty()), "{name}: {:#?}", l.uses);
        }
    }

    /// The lines name what the description's indices point at: `v' = ... + c·u`, the weights
    /// of HHT's two loads, midpoint's `(u + u')/2`.
    #[test]
    fn uses_are_the_description_s() {
        let l = library("newmark");
        let v = &l.desc.stages[0].values[1];
        assert_eq!(l.uses[v.known[0].1], ["stage `stage1`: coefficient of `u` in `v'`"]);
        assert_eq!(l.uses[l.desc.stages[0].time], ["stage `stage1`: time of the stage and every term"]);
        let l = library("hht");
        let weights: Vec<&Vec<String>> = l.desc.stages[0].terms.iter().map(|t| &l.uses[t.coef]).collect();
        assert!(weights.contains(&&vec!["stage `stage1`: weight of `load(t)`".to_string()]), "{weights:#?}");
        assert!(weights.contains(&&vec!["stage `stage1`: weight of `load(t + dt)`".to_string()]), "{weights:#?}");
        let l = library("midpoint");
        let stiffness = l.desc.stages[0].terms.iter().find(|t| t.form == "stiffness").expect("a stiffness term");
        assert_eq!(
            l.uses[stiffness.args[0].unknown.expect("u'")],
            ["stage `stage1`: coefficient of `u'` and `u` in the arguments of `stiffness(…)` and `contact(…)`"]
        );
    }

    #[test]
    fn terms_written_alike_are_told_apart() {
        let l = laid_out(
            "twice.wf",
            "scheme twice {\n  uses mass, stiffness, load\n  state u, v\n  unknown u'\n  new abar\n  \
             relate u' = u + dt*v + dt^2/2*abar\n  relate v' = v + dt*abar\n  \
             residual mass(abar) + stiffness((u + u')/2) + 2*stiffness((u + 3*u')/4) == load(t + dt)\n}\n",
        );
        let weights: Vec<&str> = l.desc.stages[0].terms.iter().map(|t| l.uses[t.coef][0].as_str()).collect();
        assert!(weights.iter().any(|w| w.contains("`stiffness(…) #2`")), "{weights:#?}");
    }
}
