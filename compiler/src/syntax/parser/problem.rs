//! Pest pairs → a `problem` item: its params and lets, mesh, regions, bindings, reference,
//! run and quadrature settings, coefs, initial values, Dirichlet conditions, obstacles, and
//! what it measures and plots.

use pest::iterators::Pair;

use super::Rule;
use super::build::{Builder, unquote};
use crate::diagnostic::Diagnostic;
use crate::source::Span;
use crate::syntax::ast::*;

impl Builder {
    pub(super) fn problem(
        &self,
        span: Span,
        name: Pair<Rule>,
        rest: pest::iterators::Pairs<Rule>,
    ) -> Result<Problem, Box<Diagnostic>> {
        let mut pb = Problem {
            name: self.ident(name),
            params: Vec::new(),
            mesh: Vec::new(),
            bodies: Vec::new(),
            regions: Vec::new(),
            binds: Vec::new(),
            sets: Vec::new(),
            coefs: Vec::new(),
            obstacles: Vec::new(),
            pairs: Vec::new(),
            initial: Vec::new(),
            dirichlet: Vec::new(),
            series: Vec::new(),
            summary: Vec::new(),
            expects: Vec::new(),
            plots: Vec::new(),
            run: Vec::new(),
            run_static: None,
            quadrature: Vec::new(),
            reference: None,
            reference_args: Vec::new(),
            lets: Vec::new(),
            fns: Vec::new(),
            neumann: Vec::new(),
            required: Vec::new(),
            span,
        };
        for p in rest {
            if p.as_rule() == Rule::region_decl {
                pb.regions.push(self.region(p, None)?);
                continue;
            }
            let span = self.span(&p);
            let rule = p.as_rule();
            let mut it = p.into_inner();
            let mut next = || it.next().expect("grammar guarantees the child");
            match rule {
                Rule::scheme_params => pb.params = self.params(it)?,
                Rule::mesh_decl => {
                    let q = next();
                    pb.mesh.push(match q.as_rule() {
                        Rule::string => MeshSource::File { path: unquote(q.as_str()), span: self.span(&q) },
                        _ => MeshSource::Generator(self.named_call(q)?),
                    });
                }
                Rule::body_decl => {
                    next(); // the word `body`
                    let name = self.ident(next());
                    let q = next();
                    let source = match q.as_rule() {
                        Rule::body_group => {
                            let g = q.into_inner().next().expect("group name");
                            BodySource::Group { name: unquote(g.as_str()), span: self.span(&g) }
                        }
                        _ => BodySource::Generator(self.named_call(q)?),
                    };
                    let mut body = Body { name, source, sets: Vec::new(), initial: Vec::new(), span };
                    for q in it {
                        let span = self.span(&q);
                        match q.as_rule() {
                            Rule::region_decl => pb.regions.push(self.region(q, Some(body.name.clone()))?),
                            Rule::set_decl => body.sets.extend(self.sets(q)?),
                            _ => {
                                let mut parts = q.into_inner();
                                body.initial.push(self.defined(span, parts.next().expect("field"), parts.next())?);
                            }
                        }
                    }
                    pb.bodies.push(body);
                }
                Rule::bind_decl => pb.binds.extend(it.map(|q| self.bound(q))),
                Rule::set_decl => {
                    for q in it {
                        pb.sets.push(self.set_arg(q)?);
                    }
                }
                Rule::run_decl => {
                    let q = next();
                    if q.as_rule() == Rule::run_static {
                        pb.run_static = Some(self.span(&q));
                    } else {
                        pb.run.extend(self.assignments(q)?);
                    }
                }
                Rule::quadrature_decl => pb.quadrature.extend(self.assignments(next())?),
                Rule::coef_def => pb.coefs.push(self.defined(span, next(), it.next())?),
                Rule::initial_field => pb.initial.push(self.defined(span, next(), it.next())?),
                Rule::series_decl | Rule::observe_decl => {
                    let d = self.defined(span, next(), it.next())?;
                    if it.next().is_some() {
                        pb.required.push(d.name.clone());
                    }
                    pb.series.push((d, rule == Rule::series_decl));
                }
                Rule::summary_decl => pb.summary.push(self.defined(span, next(), it.next())?),
                Rule::expect_decl => {
                    let key = self.ident(next());
                    let value = self.expr(next())?;
                    let within = self.expr(next())?;
                    let when = it.next().map(|q| self.condition(q)).transpose()?;
                    pb.expects.push(Expect { key, value, within, when, span });
                }
                Rule::let_decl => pb.lets.push(self.defined(span, next(), it.next())?),
                Rule::fn_decl => {
                    let name = self.ident(next());
                    let (mut params, mut body) = (Vec::new(), None);
                    for q in it {
                        match q.as_rule() {
                            Rule::ident_list => params = q.into_inner().map(|i| self.ident(i)).collect(),
                            _ => body = Some(self.expr(q)?),
                        }
                    }
                    pb.fns.push(ProblemFn { name, params, body: body.expect("fn has a body"), span });
                }
                Rule::contact_pair => {
                    next(); // the word `contact`
                    let own = self.ident(next());
                    next(); // the word `with`
                    let facing = self.ident(next());
                    let (mut reach, mut by, mut binds, mut sets) = (None, None, Vec::new(), Vec::new());
                    for q in it {
                        match q.as_rule() {
                            Rule::pair_by => by = q.into_inner().nth(1).map(|i| self.ident(i)),
                            Rule::bind_decl => binds.extend(q.into_inner().map(|b| self.bound(b))),
                            Rule::set_decl => sets.extend(self.sets(q)?),
                            _ => reach = Some(self.expr(q)?),
                        }
                    }
                    pb.pairs.push(ContactPair { own, facing, reach, by, binds, sets, span });
                }
                Rule::obstacle_decl => {
                    let shape = self.named_call(next())?;
                    let region = it.next().map(|q| self.ident(q));
                    pb.obstacles.push(Obstacle { shape, region, span });
                }
                Rule::dirichlet_decl => {
                    let target = next();
                    let on = if target.as_rule() == Rule::nearest_node {
                        let span = self.span(&target);
                        HeldAt::Nearest { point: self.expr(target.into_inner().next().expect("a point"))?, span }
                    } else {
                        HeldAt::Region(self.ident(target))
                    };
                    let field = self.ident(next());
                    let mut rest = next();
                    let mut component = None;
                    if rest.as_rule() == Rule::index {
                        component = Some(self.expr(rest.into_inner().next().expect("index expression"))?);
                        rest = next();
                    }
                    let value = self.expr(rest)?;
                    pb.dirichlet.push(Dirichlet { on, field, component, value, span });
                }
                Rule::neumann_decl => {
                    let region = self.ident(next());
                    let kind = self.ident(next());
                    let value = self.expr(next())?;
                    pb.neumann.push(Neumann { region, kind, value, span });
                }
                Rule::plot_decl => {
                    let title = unquote(next().as_str());
                    let columns = next().into_inner().map(|i| self.ident(i)).collect();
                    pb.plots.push(Plot { title, columns, span });
                }
                Rule::reference_decl => {
                    let target = next();
                    let (name, args) = if target.as_rule() == Rule::call_named {
                        let call = self.named_call(target)?;
                        (call.name, call.args)
                    } else {
                        (self.ident(target), Vec::new())
                    };
                    if let Some(prev) = &pb.reference {
                        let d = Diagnostic::error("E0102", "a problem names one reference", name.span, "second one")
                            .with_label(prev.span, "first one");
                        return Err(Box::new(d));
                    }
                    pb.reference = Some(name);
                    pb.reference_args = args;
                }
                r => unreachable!("not a problem item: {r:?}"),
            }
        }
        Ok(pb)
    }

    /// A `region` line, in a body or not.
    fn region(&self, p: Pair<Rule>, body: Option<Ident>) -> Result<RegionDecl, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut it = p.into_inner();
        let name = self.ident(it.next().expect("region name"));
        let sources = it.map(|q| self.region_source(q)).collect::<Result<Vec<_>, _>>()?;
        Ok(RegionDecl { name, sources, body, span })
    }

    /// A `set` line's assignments.
    fn sets(&self, p: Pair<Rule>) -> Result<Vec<Defined>, Box<Diagnostic>> {
        p.into_inner().map(|q| self.set_arg(q)).collect()
    }

    /// `ROLE = TARGET` of a `bind` line.
    fn bound(&self, q: Pair<Rule>) -> Bind {
        let span = self.span(&q);
        let mut parts = q.into_inner();
        let role = self.ident(parts.next().expect("role"));
        let target = parts.next().expect("target");
        let is_path = target.as_rule() == Rule::string;
        let target = if is_path { unquote(target.as_str()) } else { target.as_str().to_string() };
        Bind { role, target, is_path, span }
    }

    /// `NAME = VALUE` of a `set` line.
    fn set_arg(&self, q: Pair<Rule>) -> Result<Defined, Box<Diagnostic>> {
        let span = self.span(&q);
        let mut parts = q.into_inner();
        let name = self.ident(parts.next().expect("param path"));
        Ok(Defined { name, value: self.expr(parts.next().expect("value"))?, span })
    }

    /// A region's source: a union of parts (one part is itself).
    fn region_source(&self, p: Pair<Rule>) -> Result<RegionSource, Box<Diagnostic>> {
        let span = self.span(&p);
        let mut parts = p
            .into_inner()
            .map(|q| {
                let qspan = self.span(&q);
                Ok(match q.as_rule() {
                    Rule::group_source => {
                        let mut parts = q.into_inner();
                        let name = unquote(parts.next().expect("group name").as_str());
                        let condition = parts.next().map(|c| self.condition(c)).transpose()?;
                        RegionSource::Group { name, condition, span: qspan }
                    }
                    Rule::boundary_source => {
                        let condition = q.into_inner().next().map(|c| self.condition(c)).transpose()?;
                        RegionSource::Boundary { condition, span: qspan }
                    }
                    Rule::region_name => RegionSource::Region(self.ident(q.into_inner().next().expect("name"))),
                    _ => self.region_source(q)?,
                })
            })
            .collect::<Result<Vec<_>, Box<Diagnostic>>>()?;
        Ok(if parts.len() == 1 { parts.remove(0) } else { RegionSource::Union(parts, span) })
    }
}
