#!/usr/bin/python3
"""The bouncing-disc benchmark with GetFEM's own bricks, for comparison with signorini.

Run with Debian's python (apt-get install python3-getfem, GetFEM 5.4):

    /usr/bin/python3 scripts/getfem/disc.py --theta 1 --out /tmp/gf/getfem-newmark-t1.csv
    (--scheme newmark|hht|midpoint|trbdf2, --alpha 0.05, --contact nitsche|nitsche-normal|penalty,
     --theta 1|0|-1)
    signorini run disc --scheme newmark --contact nitsche-traction --cell-size getfem \
        --param theta=1 --mesh disc_r10_h1_v22.msh --t-end 20 --out /tmp/gf/ours-newmark-t1
    signorini compare /tmp/gf/getfem-newmark-t1.csv /tmp/gf/ours-newmark-t1

The problem (docs/mathematics.md §6): disc of radius 10 centred at (0, 12), f = (0, -0.1), plane strain,
lambda = mu = 20, rho = 1, no Dirichlet condition, rigid ground {y = 0}; contact zone = the
boundary facets whose outward normal at the facet centre has n_y < 0.

GetFEM pieces (no hand-written weak form in the dynamics):
  - add_isotropic_linearized_elasticity_brick (2D: plane strain with the given Lame coefficients),
  - add_source_term_brick (body force), add_mass_brick on Dot2_u,
  - add_Nitsche_contact_with_rigid_obstacle_brick(mim, 'u', Neumann_term('u', GC), 'obs',
    'gamma0', GC, theta): obstacle level set obs = y (a P2 fem datum, exact on the isoparametric
    mesh), frictionless, gamma = gamma0/element_size;
  - add_Newmark_scheme('u', 1/4, 1/2) + set_time_step + solve + shift_variables_for_time_integration;
    HHT and the implicit midpoint rule are GetFEM's Newmark scheme used as an affine map (see
    "Time scheme" below), with add_explicit_rhs/set_private_rhs for HHT's explicit part;
  - --contact penalty: add_nonlinear_term with eps [u_N - g]_+ v_N, eps = gamma0/element_size
    (GetFEM's add_penalized_contact_with_rigid_obstacle_brick takes a constant r instead);
  - --contact nitsche-coulomb (Newmark only): forms/contact_nitsche_coulomb.wf as an
    add_nonlinear_term built on GetFEM's own Coulomb operator,
    -theta/gamma sigma(u)n.sigma(v)n + 1/gamma CFCP(sigma(u)n, n_c, alpha (u - Previous_u),
    g - u.n_c, F, gamma).(theta sigma(v)n - gamma v), where
    CFCP(lambda, n, Vs, g, f, r) = Coulomb_friction_coupled_projection
    = -(lambda.n + r g)_- n + P_B(n, f (lambda.n + r g)_-)(lambda - r Vs), GetFEM's (and its
    Nitsche brick's) projection, with its own derivative; Previous_u is the Newmark scheme's
    previous displacement, as signorini's prev(u). Its contact terms use IM_TRIANGLE(8), whose
    face rule has 5 Gauss points per edge, as the law's `degree = 8`. --vx gives the disc a
    horizontal velocity (the oblique impact, forms/problems/oblique_disc.wf), --omega a spin
    (v = (vx, 0) + omega e_z x (x - c), c = (0, 12), from u = 0: scripts/getfem/thrown_disc.wf).
  - contact on the deformed configuration (IM_TRIANGLE(8) on the contact zone; --contact-zone
    boundary for a spinning disc), against the plane g(x) = x_y, nc = -e_y read at X + u, with the
    run's material's nominal traction P(u)N (sigma(u)n for the linear material):
    --contact penalty-deformed: forms/contact_penalty_deformed.wf with F = 0, eps [-g(X+u)]_+ v.nc;
    --contact nitsche-deformed: forms/contact_nitsche_deformed.wf, P_N = P(u)N.nc,
    -theta/gamma P_N DP_N[v] + 1/gamma [P_N + gamma g(X+u)]_- (theta DP_N[v] - gamma v.nc), with
    DP_N[v] = Diff(P_N, u, Test_u);
    --contact nitsche-piola: GetFEM's Nitsche brick with P(u)N as its Neumann term (its theta term
    is the full traction's, -theta/gamma P(u)N.D(P(u)N)[v]: the same law as nitsche-deformed for
    theta = 0 only);
    --contact nitsche-raytracing: the rigid-obstacle term of GetFEM's large-sliding Nitsche brick,
    -Interpolate_filter(trans, CFCP(P(u)N, n_x, u, (Interpolate(X,trans) - X - u).n_x, 0, gamma).v, 2)
    with GetFEM's raytracing transformation and n_x = Transformed_unit_vector(Grad_u, Normal), written
    out because the brick fails in 5.4.2 (see the code); it has no theta term (theta = 0).
  - --contact nitsche-normal: signorini's normal form (forms/contact_nitsche.wf, compared with
    `signorini run disc --contact nitsche`) as an add_nonlinear_term in GWFL:
    -theta/gamma sigma_N(u) sigma_N(v) + 1/gamma [P_1,gamma(u)]_- (theta sigma_N(v) - gamma v.n_c),
    sigma_N(u) = (sigma(u) n).n_c with n the outward normal (GWFL's Normal) and n_c = -e_y the
    obstacle normal, P_1,gamma(u) = sigma_N(u) + gamma (g - u.n_c), gamma = gamma0/element_size.
  - --material neo_hookean: forms/neo_hookean.wf in place of the elasticity brick, an
    add_nonlinear_term P(u):Grad_Test_u with F = Id(2) + Grad_u, P = mu (F - F^-T) + lambda ln(det F) F^-T
    (plane strain); GetFEM derives the tangent. The small-strain contact laws keep the LINEAR Hooke stress
    sigma(u) = lambda div u I + 2 mu sym grad u in sigma(u)n, written out (a nonlinear term declares
    no Neumann term), as signorini's laws do (they import elasticity.wf). --polish 1 adds one
    Newton iteration after GetFEM's solve, whose criterion min(|R|_1/load estimate, |du|_1/|u|_1)
    <= max_res leaves |R|_2 up to ~4e-9 |F|_2 here (after it: ~1e-11, the round-off floor).
    --newton-rtol emulates signorini's Newton criterion, --check-residual reports the residual
    (scripts/getfem/README.md, "Neo-Hookean material").
GetFEM's own linear solver choice matters in Debian's 5.4.2 build: 'superlu' (and
linsolve_superlu) segfault, so the script uses 'mumps', and scipy for the mass solve. Newton's
max_res is 1e-9: GetFEM's relative criterion has a round-off floor near 1e-11 on this problem,
and at max_res 1e-12 Newton stalls for 50 iterations and then diverges.
The initial acceleration is not GetFEM's perform_init_time_derivative (an approximation: one
backward-Euler-like step of length ddt) but exactly M a0 = F - K u0 - C(u0): the rhs of the model
without its mass brick (md.assembly('build_rhs')), solved with the consistent mass matrix.

Quadrature: IM_TRIANGLE(6), the 12-point degree-6 rule (the same Dunavant rule as signorini),
whose face rule is IM_GAUSS1D(6), i.e. 4 Gauss points per edge (degree 7), as signorini's facets.

Measures (per step, t = 0 first), the columns of signorini's series.csv:
  energy      = 1/2 v.M v + 1/2 u.K u - F.u  (M, K, F assembled by GetFEM; neo_hookean: int W(u) in
                place of 1/2 u.K u, W = mu/2 (|F|^2 - 2) - mu ln J + lambda/2 (ln J)^2, J = det F)
  energy_aug  = energy - theta/(2 gamma) ||sigma(u)n||^2_GC + 1/(2 gamma) ||[P_1,gamma(u)]_-||^2_GC
                (nitsche-normal: sigma_N(u)^2 in place of |sigma(u)n|^2, the normal form's E_Theta)
  uy_mean     = e_y.M u / e_y.M e_y (centre of mass), uy_mean_nodal = plain mean of nodal u_y
  fy_contact  = the vertical resultant of the contact term = -int_GC [P_1,gamma(u)]_-
  (penalty: energy_aug = energy + 1/2 int_GC eps [u_N - g]_+^2, fy_contact = int_GC eps [u_N - g]_+;
  the deformed laws: the same with P(u)N, g(X + u); nitsche-raytracing: energy_aug takes
  1/(2 gamma) [P(u)N.n_x + gamma g]_-^2, (fx, fy)_contact = int_GC [P(u)N.n_x + gamma g]_- n_x)
  kinetic     = 1/2 v.M v, vx_mean, vy_mean = e.M v / e.M e (centre of mass),
  momentum    = (x + u)^perp.M v - m x_c x v_c, the angular momentum about the centre of mass
"""
import argparse
import sys

import numpy as np
import scipy.sparse
import scipy.sparse.linalg
import getfem as gf

GC = 10  # region number of the contact zone

p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
p.add_argument("--mesh", required=True, help="the benchmark mesh, disc_r10_h1_v22.msh (Gmsh 2.2)")
p.add_argument("--contact", choices=["nitsche", "nitsche-normal", "nitsche-coulomb", "penalty", "penalty-deformed",
                                     "nitsche-deformed", "nitsche-piola", "nitsche-raytracing"],
               default="nitsche",
               help="nitsche: GetFEM's Nitsche brick (full-traction theta term); nitsche-normal: signorini's "
                    "normal form (forms/contact_nitsche.wf) as a GWFL term; penalty: a GWFL term, "
                    "eps = gamma0/element_size (GetFEM's penalized contact brick takes a constant r, not gamma0/h). "
                    "On the deformed configuration, IM_TRIANGLE(8) on the contact zone: penalty-deformed: "
                    "forms/contact_penalty_deformed.wf with F = 0 (GWFL); nitsche-deformed: "
                    "forms/contact_nitsche_deformed.wf (GWFL, P_N = P(u)N.nc, test terms by Diff); nitsche-piola: "
                    "GetFEM's Nitsche brick with the Neumann term P(u)N; nitsche-raytracing: the rigid-obstacle term of "
                    "GetFEM's Nitsche large-sliding brick (raytracing, biased, frictionless), written out")
p.add_argument("--release-distance", type=float, default=1.0,
               help="nitsche-raytracing: the raytracing transformation's release distance")
p.add_argument("--contact-zone", choices=["lower", "boundary"], default="lower",
               help="lower: the boundary facets facing down (n_y < 0 at the facet centre); boundary: all of them "
                    "(a spinning disc lands on facets that started elsewhere)")
p.add_argument("--material", choices=["elasticity", "neo_hookean"], default="elasticity",
               help="elasticity: GetFEM's linearized elasticity brick; neo_hookean: forms/neo_hookean.wf as a "
                    "GWFL term (the small-strain contact laws keep the linear Hooke stress, as signorini's do; the "
                    "deformed ones take its P(u)N)")
p.add_argument("--theta", type=float, default=1.0)
p.add_argument("--friction", type=float, default=0.3, help="nitsche-coulomb: the friction coefficient F")
p.add_argument("--slip-scale", type=float, default=1.0, help="nitsche-coulomb: GetFEM's alpha")
p.add_argument("--vx", type=float, default=0.0, help="the initial horizontal velocity")
p.add_argument("--omega", type=float, default=0.0,
               help="the initial spin, counter-clockwise: v = (vx, 0) + omega e_z x (x - c), c = (0, 12), from u = 0")
p.add_argument("--gamma0", type=float, default=1000.0)
p.add_argument("--dt", type=float, default=0.02)
p.add_argument("--t-end", type=float, default=20.0)
p.add_argument("--scheme", choices=["newmark", "hht", "midpoint", "trbdf2"], default="newmark")
p.add_argument("--alpha", type=float, default=0.05, help="HHT, talk's convention alpha = -alpha_HHT")
p.add_argument("--beta", type=float, default=0.25)
p.add_argument("--gam", type=float, default=0.5)
p.add_argument("--integ", default="IM_TRIANGLE(6)")
p.add_argument("--max-res", type=float, default=1e-9)
p.add_argument("--lsearch", default="default", help="GetFEM's Newton line search")
p.add_argument("--polish", type=int, default=0,
               help="Newton iterations to add after GetFEM's solve, each with the model's own tangent and "
                    "residual and a scipy LU solve (GetFEM stops at min(|R|_1/load estimate, |du|_1/|u|_1) "
                    "<= max_res; one more step takes the neo-Hookean runs to the round-off floor)")
p.add_argument("--newton-rtol", type=float, default=None,
               help="instead of GetFEM's solve, a plain Newton (the model's tangent and residual, a scipy "
                    "LU solve) from the current u, stopped at |R|_inf <= rtol |R(u0)|_inf after at least one "
                    "iteration: signorini's relative criterion (its tol is 1e-10), from signorini's first "
                    "iterate u (newmark, hht, midpoint), for tolerance studies")
p.add_argument("--check-residual", action="store_true",
               help="after each solve, assemble the residual R(u) once more and report the largest "
                    "|R|_2/(|F|_2 + |f_int(u)|_2) over the run on stderr (F: the body load, f_int: the "
                    "material's internal force)")
p.add_argument("--noisy", action="store_true")
p.add_argument("--out", default="-")
args = p.parse_args()
coulomb = args.contact == "nitsche-coulomb"
if coulomb and args.scheme != "newmark":
    p.error("--contact nitsche-coulomb runs with --scheme newmark (the other schemes' Previous_u is not the previous step)")

lam, mu, rho, grav = 20.0, 20.0, 1.0, 0.1

# Mesh, fem, integration -------------------------------------------------------------------
m = gf.Mesh("import", "gmsh", args.mesh)
mf = gf.MeshFem(m, 2)
mf.set_classical_fem(2)  # FEM_PK(2,2), isoparametric on the GT_PK(2,2) cells
mfs = gf.MeshFem(m, 1)
mfs.set_classical_fem(2)
mim = gf.MeshIm(m, gf.Integ(args.integ))
# The frictional and deformed laws' facet rule: 5 Gauss points per edge (their `degree = 8`).
deformed = args.contact in ("penalty-deformed", "nitsche-deformed", "nitsche-piola", "nitsche-raytracing")
mim_c = gf.MeshIm(m, gf.Integ("IM_TRIANGLE(8)")) if coulomb or deformed else mim

faces = m.outer_faces()
normals = m.normal_of_faces(faces)  # at face centres: on a P2 edge, the chord normal
zone = faces if args.contact_zone == "boundary" else faces[:, normals[1, :] < 0]
m.set_region(GC, zone)
print(f"# {m.nbcvs()} cells, {mf.nbdof()} dofs, {faces.shape[1]} boundary facets, "
      f"{zone.shape[1]} in contact zone, min |n_y| on the boundary "
      f"{np.min(np.abs(normals[1, :])):.3e}", file=sys.stderr)

# Model --------------------------------------------------------------------------------------
md = gf.Model("real")
md.add_fem_variable("u", mf)
md.add_initialized_data("lambda", [lam])
md.add_initialized_data("mu", [mu])
md.add_initialized_data("rho", [rho])
md.add_initialized_data("f", [0.0, -grav])
md.add_initialized_data("gamma0", [args.gamma0])
md.add_initialized_data("F", [args.friction])
md.add_initialized_data("slip_scale", [args.slip_scale])
md.add_initialized_fem_data("obs", mfs, mfs.basic_dof_nodes()[1, :])  # gap to {y = 0}
# forms/neo_hookean.wf, plane strain: F = I + grad u, J = det F,
# P = mu (F - F^-T) + lambda ln J F^-T, W = mu/2 (|F|^2 - 2) - mu ln J + lambda/2 (ln J)^2.
defgrad = "(Id(2)+Grad_u)"
piola = f"(mu*({defgrad} - Inv({defgrad})') + lambda*log(Det({defgrad}))*Inv({defgrad})')"
strain_energy = (f"mu/2*(Norm_sqr({defgrad}) - 2) - mu*log(Det({defgrad}))"
                 f" + lambda/2*sqr(log(Det({defgrad})))")
if args.material == "elasticity":
    md.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda", "mu")
else:
    md.add_nonlinear_term(mim, f"{piola}:Grad_Test_u")
md.add_source_term_brick(mim, "u", "f")
if args.material == "elasticity":
    neumann = md.Neumann_term("u", GC)  # sigma(u) n, as the elasticity brick declares it
else:
    # A nonlinear term declares no Neumann term. The contact laws (they import elasticity.wf)
    # take the linear Hooke stress whatever the material: sigma(u) n written out.
    neumann = "((lambda*Div_u*Id(2) + 2*mu*Sym(Grad_u))*Normal)"
nc = "(-Normalized(Grad_obs))"
gamma = "(gamma0/element_size)"
theta = f"({args.theta!r})"
pen = f"pos_part(u.{nc} - obs)"  # [u_N - g]_+
# sigma_N = (sigma n).nc of u and of the test function (the brick's Neumann term with u -> Test_u).
sn_u = f"(({neumann}).{nc})"
sn_v = "(((lambda*Div_Test_u*Id(2) + 2*mu*Sym(Grad_Test_u))*Normal).{})".format(nc)
P1 = f"({sn_u} + {gamma}*(obs - u.{nc}))"  # P_1,gamma(u) + gamma g, the trial value
sigma_v_n = "((lambda*Div_Test_u*Id(2) + 2*mu*Sym(Grad_Test_u))*Normal)"
# The frictional contact stress lambda_N n_c + lambda_t (Previous_u: the step's start).
stress = (f"Coulomb_friction_coupled_projection({neumann}, {nc}, slip_scale*(u - Previous_u), "
          f"obs - u.{nc}, F, {gamma})")
# Contact on the deformed configuration, against the plane: its gap g(x) = x_y and normal
# nc = -grad g = -e_y read at the deformed point X + u (a plane's normal is constant), and the
# run's material's nominal traction P(u)N on the reference boundary (Hooke's sigma(u)n for the
# linear material), as forms/contact_{penalty,nitsche}_deformed.wf read them.
nc_d = "[0,-1]"
gap_d = "(X(2) + u(2))"
traction = f"({piola}*Normal)" if args.material == "neo_hookean" else f"({neumann})"
pn = f"(({traction}).{nc_d})"  # P_N(u)
dpn = f"Diff({pn}, u, Test_u)"  # DP_N(u)[v]
P1d = f"({pn} + {gamma}*{gap_d})"  # P_1,gamma(u)
P1p = f"(({traction}).{nc} + {gamma}*(obs - u.{nc}))"  # the same, as GetFEM's Nitsche brick writes it
# GetFEM's large-sliding Nitsche brick, rigid obstacle: n_x = F^-T N/|F^-T N| the deformed body's
# unit normal, g the distance from X + u to the obstacle along n_x (raytracing), and the contact
# stress [P(u)N.n_x + gamma g]_- along n_x (its Coulomb_friction_coupled_projection with F = 0).
nx = "Transformed_unit_vector(Grad_u, Normal)"
if coulomb:
    pass  # added with the time scheme, which declares Previous_u
elif args.contact == "penalty-deformed":
    # forms/contact_penalty_deformed.wf, F = 0: eps [-g(X + u)]_+ v.nc(X + u).
    md.add_nonlinear_term(mim_c, f"{gamma}*pos_part(-{gap_d})*(Test_u.{nc_d})", GC)
elif args.contact == "nitsche-deformed":
    # forms/contact_nitsche_deformed.wf: -theta/gamma P_N DP_N[v] + 1/gamma [P_1,gamma]_- (theta DP_N[v] + gamma Dg[v]),
    # Dg[v] = -nc.v; GWFL's neg_part(x) = -[x]_-.
    md.add_nonlinear_term(mim_c, f"-{theta}/{gamma}*{pn}*{dpn}"
                                 f" - 1/{gamma}*neg_part({P1d})*({theta}*{dpn} - {gamma}*(Test_u.{nc_d}))", GC)
elif args.contact == "nitsche-piola":
    # The brick takes the derivative of its Neumann term itself (extract_order1_term); its theta term
    # is the full traction's, -theta/gamma P(u)N.D(P(u)N)[v].
    md.add_Nitsche_contact_with_rigid_obstacle_brick(mim_c, "u", traction, "obs", "gamma0", GC, args.theta)
elif args.contact == "nitsche-raytracing":
    # add_Nitsche_large_sliding_contact_brick_raytracing's term for a rigid obstacle (biased: the
    # disc is the slave), written out with the brick's own pieces, because the brick cannot be
    # assembled in 5.4.2 once a point sees the obstacle: its rigid term
    #   -Interpolate_filter(trans, CFCP.Test_u, 2) + Interpolate_filter(trans, CFCP.Interpolate(Test_ug, trans), 2)
    # interpolates the master's test functions on the obstacle, which has no element ("No valid
    # element for the transformation"); the unbiased version has no rigid term at all. The second
    # term is zero for a rigid obstacle; the first is added here, with the brick's raytracing
    # transformation, its gap (Interpolate(X,trans) - X - u).n_x and CFCP with F = 0, alpha = 1.
    trans = "raytrace"
    md.add_raytracing_transformation(trans, args.release_distance)
    md.add_rigid_obstacle_to_raytracing_transformation(trans, "y", 2)
    md.add_slave_contact_boundary_to_raytracing_transformation(trans, m, "u", GC)
    gap_rt = f"((Interpolate(X,{trans}) - X - u).{nx})"
    cfcp_rt = f"Coulomb_friction_coupled_projection({traction}, {nx}, (u)*1, {gap_rt}, 0, {gamma})"
    md.add_nonlinear_term(mim_c, f"-Interpolate_filter({trans}, {cfcp_rt}.Test_u, 2)", GC)
    lam_rt = f"neg_part(({traction}).{nx} + {gamma}*{gap_rt})"  # -[P(u)N.n_x + gamma g]_-
elif args.contact == "nitsche":
    md.add_Nitsche_contact_with_rigid_obstacle_brick(mim, "u", neumann, "obs", "gamma0", GC, args.theta)
elif args.contact == "nitsche-normal":
    # forms/contact_nitsche.wf: C(u).v = -theta/gamma sn(u) sn(v) + 1/gamma [P_1(u) + gamma g]_- P_theta(v),
    # P_theta(v) = theta sn(v) - gamma v.nc; GWFL's neg_part(x) = max(-x, 0) = -[x]_-.
    md.add_nonlinear_term(mim, f"-{theta}/{gamma}*{sn_u}*{sn_v}"
                               f" - 1/{gamma}*neg_part({P1})*({theta}*{sn_v} - {gamma}*(Test_u.{nc}))", GC)
else:
    md.add_nonlinear_term(mim, f"{gamma}*{pen}*(Test_u.{nc})", GC)

# Matrices for the measures ----------------------------------------------------------------
n = mf.nbdof()
U0 = np.zeros(n)
V0 = np.zeros(n)
dof_x = mf.basic_dof_nodes()  # the dofs' nodes (exact on the isoparametric P2 mesh)
V0[0::2] = args.vx - args.omega * (dof_x[1, 0::2] - 12.0)
V0[1::2] = args.omega * dof_x[0, 1::2]
Mmat = gf.asm_generic(mim, 2, "rho*u.Test_u", -1, "rho", 0, [rho], "u", 1, mf, U0)
Kmat = gf.asm_generic(mim, 2, "(lambda*Div_u*Id(2)+2*mu*Sym(Grad_u)):Grad_Test_u", -1,
                      "lambda", 0, [lam], "mu", 0, [mu], "u", 1, mf, U0)


def strain_energy_of(U):
    """The stored energy: 1/2 u.K u, or the integral of the neo-Hookean W(u)."""
    if args.material == "elasticity":
        return 0.5 * U @ Kmat.mult(U)
    return gf.asm_generic(mim, 0, strain_energy, -1, "u", 0, mf, U, "lambda", 0, [lam], "mu", 0, [mu])


def internal_force(U):
    if args.material == "elasticity":
        return Kmat.mult(U)
    return gf.asm_generic(mim, 1, f"{piola}:Grad_Test_u", -1, "u", 1, mf, U, "lambda", 0, [lam], "mu", 0, [mu])


Fvec = gf.asm_generic(mim, 1, "f.Test_u", -1, "f", 0, [0.0, -grav], "u", 1, mf, U0)
ey = np.zeros(n)
ey[1::2] = 1.0
Mey = Mmat.mult(ey)
total_mass = ey @ Mey
ex = np.zeros(n)
ex[0::2] = 1.0
Mex = Mmat.mult(ex)


def boundary(expr, U, W=None):
    return gf.asm_generic(mim_c, 0, expr, GC, "u", 0, mf, U, "obs", 0, mfs, md.variable("obs"),
                          "Previous_u", 0, mf, U if W is None else W,
                          "lambda", 0, [lam], "mu", 0, [mu], "gamma0", 0, [args.gamma0],
                          "F", 0, [args.friction], "slip_scale", 0, [args.slip_scale])


def model_boundary(expr, U):
    """A contact functional at U assembled with the model (its raytracing transformation); the
    model's u is put back, so the next Newton starts where it would have."""
    keep = md.variable("u")
    md.set_variable("u", U)
    val = gf.asm_generic(mim_c, 0, expr, GC, md)
    md.set_variable("u", keep)
    return val


def measure(t, U, V, W):
    """The row at (U, V), W the step's start (U at the first row)."""
    energy = 0.5 * V @ Mmat.mult(V) + strain_energy_of(U) - Fvec @ U
    fx = 0.0
    if args.contact == "penalty-deformed":
        ce = boundary(f"{gamma}/2*sqr(pos_part(-{gap_d}))", U)
        fy = boundary(f"{gamma}*pos_part(-{gap_d})", U)
    elif args.contact == "nitsche-deformed":
        ce = boundary(f"-{theta}/(2*{gamma})*sqr({pn}) + 1/(2*{gamma})*sqr(neg_part({P1d}))", U)
        fy = boundary(f"neg_part({P1d})", U)
    elif args.contact == "nitsche-piola":
        ce = boundary(f"-{theta}/(2*{gamma})*Norm_sqr({traction}) + 1/(2*{gamma})*sqr(neg_part({P1p}))", U)
        fy = boundary(f"neg_part({P1p})", U)
    elif args.contact == "nitsche-raytracing":
        # The brick's term is lam_rt n_x.v (on the side of the internal forces): the obstacle pushes
        # the body by -lam_rt n_x, along the body's normal, not the plane's.
        ce = model_boundary(f"Interpolate_filter({trans}, 1/(2*{gamma})*sqr({lam_rt}), 2)", U)
        fx = -model_boundary(f"Interpolate_filter({trans}, {lam_rt}*({nx})(1), 2)", U)
        fy = -model_boundary(f"Interpolate_filter({trans}, {lam_rt}*({nx})(2), 2)", U)
    elif args.contact.startswith("nitsche"):
        theta_term = f"sqr({sn_u})" if args.contact == "nitsche-normal" else f"Norm_sqr({neumann})"
        ce = boundary(f"-{theta}/(2*{gamma})*{theta_term}"
                      f" + 1/(2*{gamma})*sqr(neg_part({P1}))", U)
        fy = boundary(f"neg_part({P1})", U)  # GWFL neg_part(x) = max(-x, 0) = -[x]_-
        if coulomb:  # the contact stress's resultant on the body
            fx = boundary(f"({stress})(1)", U, W)
    else:
        ce = boundary(f"{gamma}/2*sqr({pen})", U)
        fy = boundary(f"{gamma}*{pen}", U)
    ux, uy = (Mex @ U) / total_mass, (Mey @ U) / total_mass
    MV = Mmat.mult(V)
    vx, vy = (ex @ MV) / total_mass, (ey @ MV) / total_mass
    # The angular momentum about the current centre of mass: (x + u)^perp.M v - m x_c x v_c.
    perp = np.zeros(n)
    perp[0::2] = -(dof_x[1, 0::2] + U[1::2])
    perp[1::2] = dof_x[0, 1::2] + U[0::2]
    momentum = perp @ MV - total_mass * (ux * vy - (12.0 + uy) * vx)
    return (t, energy, energy + ce, ux, uy, np.mean(U[1::2]), fx, fy,
            0.5 * V @ MV, vx, vy, momentum)


# Initial acceleration: M a0 = F - K u0 - C(u0), the rhs of the model before the mass brick.
md.set_variable("u", U0)
if coulomb:
    # Its term reads Previous_u, which the time scheme (added below) declares; the disc starts
    # 2 above the ground, where C(u0) = 0.
    r0 = Fvec - internal_force(U0)
else:
    md.assembly("build_rhs")
    r0 = md.rhs()
jc, ir = Mmat.csc_ind()
A0 = scipy.sparse.linalg.spsolve(scipy.sparse.csc_matrix((Mmat.csc_val(), ir, jc), shape=(n, n)), r0)

# Time scheme --------------------------------------------------------------------------------
# newmark:  GetFEM's Newmark scheme as is (beta, gam), the mass brick on Dot2_u.
# hht:      (talk's convention alpha = -alpha_HHT) M a' + (1-alpha) B(u') + alpha B(u) = F with
#           Newmark kinematics, beta = (1+alpha)^2/4, gam = 1/2 + alpha: GetFEM's Newmark scheme, the
#           mass brick with density rho/(1-alpha), and an explicit rhs brick carrying
#           (F - alpha B(u^n))/(1-alpha) - F; B(u^n) = K u^n + C(u^n) follows from the previous step's
#           equation, B(u^n) = (F - M a^n - alpha B(u^{n-1}))/(1-alpha), B(u^0) = F - M a^0.
# midpoint: M (v'-v)/dt + B((u+u')/2) = F, (u'-u)/dt = (v+v')/2. The unknown is w = (u+u')/2:
#           (4/dt^2) M (w - u - dt/2 v) + B(w) = F, which is GetFEM's Newmark scheme with time step
#           dt/2, beta = 1 and Previous_Dot2_u = 0 (its Dot2_u is then exactly that affine map);
#           then u' = 2w - u, v' = 4(w - u)/dt - v.
# trbdf2:   gs = 2 - sqrt(2); trapezoidal stage to t + gs dt = GetFEM's Newmark (1/4, 1/2) with
#           time step gs dt; BDF2 stage: a' = (u' - P)/c^2 with c = (1-gs)/(2-gs) dt, k = gs(2-gs),
#           P = um/k - (1-gs)^2/k u + c (vm/k - (1-gs)^2/k v): the same Newmark scheme with time
#           step 2c and Previous_u = P, Previous_Dot_u = Previous_Dot2_u = 0; then
#           v' = vm/k - (1-gs)^2/k v + c a'.
alpha = args.alpha if args.scheme == "hht" else 0.0
if args.scheme in ("newmark", "trbdf2"):
    md.add_Newmark_scheme("u", args.beta, args.gam)
elif args.scheme == "hht":
    md.add_Newmark_scheme("u", (1 + alpha) ** 2 / 4, 0.5 + alpha)
    md.set_variable("rho", [rho / (1 - alpha)])
    ib_explicit = md.add_explicit_rhs("u", np.zeros(n))
else:
    md.add_Newmark_scheme("u", 1.0, 0.5)
md.add_mass_brick(mim, "Dot2_u", "rho")
if coulomb:
    md.add_nonlinear_term(mim_c, f"-{theta}/{gamma}*({neumann}).{sigma_v_n}"
                                 f" + 1/{gamma}*({stress}).({theta}*{sigma_v_n} - {gamma}*Test_u)", GC)
md.set_time_step(args.dt / 2 if args.scheme == "midpoint" else args.dt)



worst_residual = [0.0, 0.0]  # the largest |R(u)|_2/(|F|_2 + |f_int(u)|_2) after a solve, and its time


def tangent():
    """The model's tangent K at the current u, and its rhs -R(u) (GetFEM's Newton solves K du = rhs)."""
    md.assembly("build_all")
    jc, ir = md.tangent_matrix().csc_ind()
    return scipy.sparse.csc_matrix((md.tangent_matrix().csc_val(), ir, jc), shape=(n, n)), md.rhs()


def newton_step(K, rhs):
    md.set_variable("u", md.variable("u") + scipy.sparse.linalg.spsolve(K, rhs))


def solve(t):
    md.set_time(t)
    if args.newton_rtol is None:
        it = md.solve("max_res", args.max_res, "max_iter", 50, "lsolver", "mumps",
                      "lsearch", args.lsearch, *(["noisy"] if args.noisy else []))
        if not it[1]:
            print(f"# Newton did not converge at t = {t:g}: {it}", file=sys.stderr)
    else:
        # A solve that stops before its first iteration: GetFEM's standard_solve still advances
        # the time and updates the scheme's affine dependent variables (Dot_u, Dot2_u of u),
        # which the Python interface does not expose otherwise.
        md.solve("max_res", 1e300, "max_iter", 1, "lsolver", "mumps")
        K, rhs = tangent()
        r0 = np.max(np.abs(rhs))
        for k in range(51):
            if k >= 1 and np.max(np.abs(rhs)) <= args.newton_rtol * r0:
                break
            if k == 50:
                print(f"# Newton did not converge at t = {t:g}", file=sys.stderr)
                break
            newton_step(K, rhs)
            K, rhs = tangent()
    for _ in range(args.polish):
        newton_step(*tangent())
    if args.check_residual:
        md.assembly("build_rhs")
        rel = np.linalg.norm(md.rhs()) / (np.linalg.norm(Fvec) + np.linalg.norm(internal_force(md.variable("u"))))
        if rel > worst_residual[0]:
            worst_residual[:] = [rel, t]
    return md.variable("u")


def trbdf2_step(U, V, A, t):
    dt = args.dt
    gs = 2 - np.sqrt(2)
    c, kk = (1 - gs) / (2 - gs) * dt, gs * (2 - gs)
    md.set_time_step(gs * dt)
    md.set_variable("Previous_u", U)
    md.set_variable("Previous_Dot_u", V)
    md.set_variable("Previous_Dot2_u", A)
    Um = solve(t - dt + gs * dt)
    Am = 4 / (gs * dt) ** 2 * (Um - U - gs * dt * V) - A
    Vm = V + gs * dt / 2 * (A + Am)
    P = Um / kk - (1 - gs) ** 2 / kk * U + c * (Vm / kk - (1 - gs) ** 2 / kk * V)
    md.set_time_step(2 * c)
    md.set_variable("Previous_u", P)
    md.set_variable("Previous_Dot_u", np.zeros(n))
    md.set_variable("Previous_Dot2_u", np.zeros(n))
    U1 = solve(t)
    A1 = (U1 - P) / c ** 2
    V1 = Vm / kk - (1 - gs) ** 2 / kk * V + c * A1
    return U1, V1, A1


U, V, A = U0.copy(), V0.copy(), A0.copy()
B = Fvec - Mmat.mult(A0)  # B(u^0) = K u^0 + C(u^0)
rows = [measure(0.0, U, V, U)]
steps = int(round(args.t_end / args.dt))
for k in range(steps):
    t = (k + 1) * args.dt
    if args.scheme == "trbdf2":
        U, V, A = trbdf2_step(U, V, A, t)
        rows.append(measure(t, U, V, U))
        continue
    md.set_variable("Previous_u", U)
    md.set_variable("Previous_Dot_u", V)
    md.set_variable("Previous_Dot2_u", np.zeros(n) if args.scheme == "midpoint" else A)
    if args.scheme == "hht":
        md.set_private_rhs(ib_explicit, (Fvec - alpha * B) / (1 - alpha) - Fvec)
    if args.newton_rtol is not None:
        md.set_variable("u", U)  # signorini's first iterate: the step's start (midpoint: w = u)
    solve(t)
    start = U
    if args.scheme == "midpoint":
        W = md.variable("u")
        U, V = 2 * W - U, 4 * (W - U) / args.dt - V
    else:
        md.shift_variables_for_time_integration()
        U = md.variable("Previous_u")
        V = md.variable("Previous_Dot_u")
        A = md.variable("Previous_Dot2_u")
        B = (Fvec - Mmat.mult(A) - alpha * B) / (1 - alpha)
    rows.append(measure(t, U, V, start))

if args.check_residual:
    print(f"# largest |R(u)|_2/(|F|_2 + |f_int(u)|_2) after a solve: {worst_residual[0]:.3e} "
          f"(t = {worst_residual[1]:g})", file=sys.stderr)
out = sys.stdout if args.out == "-" else open(args.out, "w")
out.write("t,energy,energy_aug,ux_mean,uy_mean,uy_mean_nodal,fx_contact,fy_contact,kinetic,vx_mean,vy_mean,momentum\n")
for r in rows:
    out.write(",".join(repr(float(x)) for x in r) + "\n")
if out is not sys.stdout:
    out.close()
