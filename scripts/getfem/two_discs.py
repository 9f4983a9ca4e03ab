#!/usr/bin/python3
"""Two discs colliding, with GetFEM 5.4, for comparison with signorini's pair law `pair_penalty`.

Run with Debian's python (apt-get install python3-getfem, GetFEM 5.4):

    /usr/bin/python3 scripts/getfem/two_discs.py --mesh assets/meshes/two_discs_p1.msh --out /tmp/gf2/getfem.csv
    signorini run scripts/getfem/two_discs.wf --cell-size getfem --out /tmp/gf2/ours --force
    signorini compare /tmp/gf2/getfem.csv /tmp/gf2/ours

The problem (scripts/getfem/two_discs.wf, after tests/problems/two_discs_collide.wf): two discs of
radius 10 centred at (-11, 0) and (11, 0) in one Gmsh mesh (assets/meshes/two_discs.geo, P1 or
isoparametric P2), thrown at each other at +-v, no gravity, no Dirichlet condition, plane strain,
lambda = mu = 20, rho = 1, Newmark beta = 1/4, gamma = 1/2, dt = 0.05.

Contact (docs/mathematics.md section 9, forms/pairs/pair_penalty.wf, master-slave): integrated over
the own surface OWN = the left disc's boundary facets with n_x > 0.3 (outward normal at the facet
centre), facing FACING = the right disc's with n_x < -0.3. At a quadrature point x of OWN, y is
the closest point of FACING, both on the deformed configuration; n' = F^-T N/|F^-T N| the facing
surface's deformed unit normal at y (cof(F) N up to det F > 0), g = (x + u(x) - y - u(y)).n',
and the term is

    eps [g]_- (v(x) - v(y)).n',  eps = gamma0/element_size (the own cell's),

written as one add_nonlinear_term on OWN with GetFEM's projection transformation
(add_projection_transformation, FACING its master boundary, OWN its slave boundary):
    -eps neg_part(g) ((Test_u - Interpolate(Test_u, proj)).n'),
    g  = (X + u - Interpolate(X, proj) - Interpolate(u, proj)).n',
    n' = Transformed_unit_vector(Interpolate(Grad_u, proj), Interpolate(Normal, proj)),
inside Interpolate_filter(proj, ..., 1) (points with no facing facet within the release distance
face nothing). GWFL's neg_part(x) = max(-x, 0) = -[x]_-.

GetFEM's projection transformation is not signorini's closest point everywhere (see the README,
"Two discs colliding", and --check-projection): of the facing facets whose box the line through
x + u along the own deformed normal crosses, it keeps those whose unconstrained projection falls
inside the facet and, among them, the SMALLEST SIGNED distance, which for a penetrating point is
the deepest, not the closest, facet.

--projection exact replaces GetFEM's transformation by the exact closest point onto the deformed
facing polyline, computed here (P1 only), at each Gauss point of each own facet. It reaches the
assembly as discontinuous P5 fields on the own cells (Yf = y, Nf = N, Onf = 1 where the point
faces), each the degree-5 polynomial through the 6 Gauss points' values along the facet, and an
expression transformation add_interpolate_transformation_from_expression(m, m, "Yf") (an im_data
cannot be read in a transformation's expression in 5.4.2). y is held fixed in Newton; each step
is a fixed point: Newton, new y from the new u, until y changes by <= 1e-14. Then the discrete
problem is signorini's.

The tangent: GetFEM's projection transformation's derivative is not in the tangent ("CAUTION",
its doc), and the expression transformation treats Yf as data. After GetFEM's solve (max_res,
mumps), --polish iterates the model's tangent and residual with a scipy LU solve until
|R|_inf <= --polish-tol * max|M v0|/dt (or the residual stops contracting).

Initial acceleration: zero (no load, u0 = 0, the discs 2 apart), exact.

Measures (t = 0 first), the columns of the signorini run's series.csv:
  ux_left, ux_right   = e_x.M u / e_x.M e_x over each body (centre of mass)
  vx_left, vx_right   = the same for v
  force               = contact_pressure(u) = int_OWN eps [g]_-  (<= 0)
  energy              = 1/2 v.M v + 1/2 u.K u
  energy_aug          = energy + int_OWN eps/2 [g]_-^2
  kinetic             = 1/2 v.M v
"""
import argparse
import sys
import time

import numpy as np
import scipy.sparse
import scipy.sparse.linalg
import getfem as gf

gf.util_trace_level(0)

OWN, FACING = 20, 21

p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
p.add_argument("--mesh", required=True, help="assets/meshes/two_discs_p1.msh (Gmsh 2.2; _p2 for P2)")
p.add_argument("--v", type=float, default=1.0, help="each disc's speed towards the other")
p.add_argument("--gamma0", type=float, default=1000.0)
p.add_argument("--dt", type=float, default=0.025)
p.add_argument("--t-end", type=float, default=6.0)
p.add_argument("--beta", type=float, default=0.25)
p.add_argument("--gam", type=float, default=0.5)
p.add_argument("--integ", default="IM_TRIANGLE(6)", help="the cells' rule")
p.add_argument("--integ-contact", default="IM_TRIANGLE(10)",
               help="the rule whose face rule integrates OWN: IM_TRIANGLE(10)'s is IM_GAUSS1D(10), 6 points per "
                    "edge, as the law's degree = 10")
p.add_argument("--projection", choices=["getfem", "exact"], default="getfem",
               help="getfem: GetFEM's projection transformation; exact: the closest point computed here (P1)")
p.add_argument("--release-distance", type=float, default=1.0)
p.add_argument("--max-res", type=float, default=1e-9)
p.add_argument("--polish", type=int, default=30,
               help="at most this many Newton iterations after GetFEM's solve (model tangent, scipy LU)")
p.add_argument("--polish-tol", type=float, default=1e-13,
               help="stop polishing at |R|_inf <= tol * |R(start of step)|_inf")
p.add_argument("--check-projection", action="store_true",
               help="at each step, compare GetFEM's facing point with the exact closest point (P1) on stderr")
p.add_argument("--evaluate-vtu", default=None,
               help="only evaluate the contact functionals (force, contact energy) and the residual's contact "
                    "part at the displacement of a signorini VTU snapshot, and exit (a diagnostic)")
p.add_argument("--noisy", action="store_true")
p.add_argument("--out", default="-")
args = p.parse_args()

lam, mu, rho = 20.0, 20.0, 1.0

# Mesh, fem, integration -------------------------------------------------------------------
m = gf.Mesh("import", "gmsh", args.mesh)
order = 2 if "GT_PK(2,2)" in str(m.geotrans(m.cvid()[0])) or "(2,2)" in str(m.geotrans(m.cvid()[0])) else 1
mf = gf.MeshFem(m, 2)
mf.set_classical_fem(order)
mim = gf.MeshIm(m, gf.Integ(args.integ))
mim_c = gf.MeshIm(m, gf.Integ(args.integ_contact))
if args.projection == "exact" and order != 1:
    p.error("--projection exact is written for straight P1 facets")

faces = m.outer_faces()
normals = m.normal_of_faces(faces)  # at face centres
pts = m.pts()


def face_vertices(cv, f):
    """The two vertices (point ids) of face f of cell cv, in GetFEM's face order."""
    return m.pid_in_faces(np.array([[cv], [f]]))


centres = np.array([pts[:, m.pid_in_faces(faces[:, [k]])[:2]].mean(axis=1) for k in range(faces.shape[1])]).T
own = faces[:, (centres[0] < 0) & (normals[0] > 0.3)]
facing = faces[:, (centres[0] > 0) & (normals[0] < -0.3)]
m.set_region(OWN, own)
m.set_region(FACING, facing)
cell_x = np.array([pts[0, m.pid_from_cvid(cv)[0]].mean() for cv in range(m.nbcvs())])
print(f"# {m.nbcvs()} cells (order {order}), {mf.nbdof()} dofs, {faces.shape[1]} boundary facets, "
      f"{own.shape[1]} own (facing_right), {facing.shape[1]} facing (facing_left)", file=sys.stderr)

# Model --------------------------------------------------------------------------------------
md = gf.Model("real")
md.add_fem_variable("u", mf)
md.add_initialized_data("lambda", [lam])
md.add_initialized_data("mu", [mu])
md.add_initialized_data("rho", [rho])
md.add_initialized_data("gamma0", [args.gamma0])
md.add_isotropic_linearized_elasticity_brick(mim, "u", "lambda", "mu")

trans = "proj"
if args.projection == "getfem":
    md.add_projection_transformation(trans, args.release_distance)
    md.add_master_contact_boundary_to_projection_transformation(trans, m, "u", FACING)
    md.add_slave_contact_boundary_to_projection_transformation(trans, m, "u", OWN)
    filt = lambda e: f"Interpolate_filter({trans}, {e}, 1)"
else:
    # The facing point y and its facet's outward reference normal N at each quadrature point of OWN
    # are data: discontinuous P5 fields on OWN's cells whose restriction to each own facet is the
    # degree-5 polynomial through their values at the facet's 6 Gauss points (IM_GAUSS1D(10), the
    # face rule of IM_TRIANGLE(10)), so the assembly reads them at those points to round-off; an
    # expression transformation (an im_data cannot be read there in 5.4.2: "Im data have to be
    # used only on their original integration method") maps each point to y. Onf is 1 where the
    # point faces a facet.
    own_cells = np.unique(own[0])
    if len(own_cells) != own.shape[1]:
        p.error("cells with two own facets")
    mfY = gf.MeshFem(m, 2)
    mfY.set_fem(gf.Fem("FEM_PK_DISCONTINUOUS(2,5)"), own_cells)
    mfO = gf.MeshFem(m, 1)
    mfO.set_fem(gf.Fem("FEM_PK_DISCONTINUOUS(2,5)"), own_cells)
    md.add_initialized_fem_data("Yf", mfY, np.zeros(mfY.nbdof()))
    md.add_initialized_fem_data("Nf", mfY, np.zeros(mfY.nbdof()))
    md.add_initialized_fem_data("Onf", mfO, np.zeros(mfO.nbdof()))
    md.add_interpolate_transformation_from_expression(trans, m, m, "Yf")
    filt = lambda e: f"(Onf*({e}))"

if args.projection == "getfem":
    # GetFEM 5.4 cannot derive Interpolate(Normal, trans) ("Sorry, cannot derive the interpolated
    # Normal"), so the facing facets' reference outward normal is a datum: a discontinuous P1 field
    # whose value on each facing facet is rot(dx/ds), the facet's tangent turned outward (not unit:
    # Transformed_unit_vector normalizes). dx/ds is linear along a P2 facet and constant on a P1
    # one, so the P1 field is the facet's normal direction exactly; the projection returns the
    # facing cell, which has one facing facet (checked).
    mfN = gf.MeshFem(m, 2)
    mfN.set_fem(gf.Fem("FEM_PK_DISCONTINUOUS(2,1)"))
    Nfac = np.zeros(mfN.nbdof())
    cells, counts = np.unique(facing[0], return_counts=True)
    if np.any(counts > 1):
        p.error(f"cells with two facing facets: {cells[counts > 1]}")
    for cv, f in facing.T:
        ids = m.pid_in_faces(np.array([[cv], [f]]))
        if order == 2:  # the two ends, then the midpoint node: the one nearest the other two
            P = m.pts(ids)
            mid = int(np.argmin([sum(np.linalg.norm(P[:, i] - P[:, j]) for j in range(3)) for i in range(3)]))
            ids = [ids[i] for i in range(3) if i != mid] + [ids[mid]]
        P = m.pts(ids)
        if order == 1:
            d0 = d1 = P[:, 1] - P[:, 0]
        else:
            a, b, c = P[:, 0], P[:, 1], P[:, 2]  # x(s) = a (1-s)(1-2s) + 4 c s(1-s) + b s(2s-1)
            d0, d1 = -3 * a + 4 * c - b, a - 4 * c + 3 * b  # x'(0), x'(1)
        nout = m.normal_of_face(int(cv), int(f))
        dofs = mfN.basic_dof_from_cv(int(cv))
        nodes = mfN.basic_dof_nodes(dofs)
        for vid, d in ((ids[0], d0), (ids[1], d1)):
            rot = np.array([d[1], -d[0]])
            rot *= np.sign(rot @ nout)
            at = [k for k in range(len(dofs)) if np.allclose(nodes[:, k], m.pts([vid])[:, 0], atol=1e-12)]
            Nfac[dofs[at[0]]], Nfac[dofs[at[1]]] = rot[0], rot[1]
    md.add_initialized_fem_data("Nfac", mfN, Nfac)
    nref = f"Interpolate(Nfac, {trans})"
else:
    nref = "Nf"
nprime = f"Transformed_unit_vector(Interpolate(Grad_u, {trans}), {nref})"
gap = f"((X + u - Interpolate(X, {trans}) - Interpolate(u, {trans})).{nprime})"
eps = "(gamma0/element_size)"
md.add_nonlinear_term(mim_c, filt(f"-{eps}*neg_part({gap})*((Test_u - Interpolate(Test_u, {trans})).{nprime})"), OWN)

# Matrices for the measures ----------------------------------------------------------------
n = mf.nbdof()
U0 = np.zeros(n)
dof_x = mf.basic_dof_nodes()
left = dof_x[0] < 0
V0 = np.where(left, args.v, -args.v) * (np.arange(n) % 2 == 0)
Mmat = gf.asm_generic(mim, 2, "rho*u.Test_u", -1, "rho", 0, [rho], "u", 1, mf, U0)
Kmat = gf.asm_generic(mim, 2, "(lambda*Div_u*Id(2)+2*mu*Sym(Grad_u)):Grad_Test_u", -1,
                      "lambda", 0, [lam], "mu", 0, [mu], "u", 1, mf, U0)
ex_l = ((np.arange(n) % 2 == 0) & left).astype(float)
ex_r = ((np.arange(n) % 2 == 0) & ~left).astype(float)
Mex_l, Mex_r = Mmat.mult(ex_l), Mmat.mult(ex_r)
mass_l, mass_r = ex_l @ Mex_l, ex_r @ Mex_r


def model_boundary(expr, U):
    """A functional of OWN at U, assembled with the model (its transformation and data); the
    model's u is put back."""
    keep = md.variable("u")
    md.set_variable("u", U)
    if args.projection == "exact":
        update_projection()
    val = gf.asm_generic(mim_c, 0, filt(expr), OWN, md)
    md.set_variable("u", keep)
    if args.projection == "exact":
        update_projection()
    return val


# The exact closest-point projection (P1) ------------------------------------------------------
def face_points(cv, f):
    """The two vertices (point ids) of a straight facet."""
    return [int(i) for i in m.pid_in_faces(np.array([[cv], [f]]))[:2]]


facing_v = np.array([face_points(cv, f) for cv, f in facing.T])  # (nf, 2)
own_v = np.array([face_points(cv, f) for cv, f in own.T])
if args.projection == "exact" or args.check_projection:
    if order != 1:
        p.error("--projection exact and --check-projection are written for straight P1 facets")
    # The P1 vector dofs are node-major: dofs 2k, 2k+1 at the node basic_dof_nodes()[:, 2k].
    dn = mf.basic_dof_nodes()
    vert_node = np.zeros(m.nbpts(), int)
    for i in range(0, n, 2):
        vert_node[int(np.argmin(np.sum((pts - dn[:, [i]]) ** 2, axis=0)))] = i // 2
    facing_N = np.array([m.normal_of_face(int(cv), int(f)) for cv, f in facing.T])
    facing_N /= np.linalg.norm(facing_N, axis=1)[:, None]
    # The facing surface's two end vertices: those of one facet only.
    ids, counts = np.unique(facing_v, return_counts=True)
    ends = set(int(i) for i in ids[counts == 1])
    g1 = gf.Integ("IM_GAUSS1D(10)")
    gauss_s = np.sort(g1.pts()[0, :g1.nbpts()[0]])  # its 6 points in [0, 1] (a symmetric set)
    imd_q = gf.MeshImData(mim_c, OWN, [2])
    imd_q1 = gf.MeshImData(mim_c, OWN, [1])


def closest_point(ps, Ad, E, L2):
    """The closest point of the deformed facing polyline to ps: (facet k, its parameter s in [0, 1],
    the signed distance along the deformed facet's outward normal, and whether it faces the surface:
    not when the closest point is an end of the surface and not straight along the normal there)."""
    s = np.einsum("ij,ij->i", ps - Ad, E) / L2
    sc = np.clip(s, 0.0, 1.0)
    d = np.linalg.norm(ps - (Ad + sc[:, None] * E), axis=1)
    k = int(np.argmin(d))
    on = True
    if (sc[k] == 0.0 and int(facing_v[k, 0]) in ends) or (sc[k] == 1.0 and int(facing_v[k, 1]) in ends):
        on = s[k] == sc[k]
    if d[k] > args.release_distance:
        on = False
    nd = np.array([E[k, 1], -E[k, 0]]) / np.sqrt(L2[k])
    nd *= np.sign(nd @ facing_N[k])
    return k, sc[k], (ps - (Ad[k] + sc[k] * E[k])) @ nd, on


def facing_polyline(U):
    Ud = U.reshape(-1, 2)
    A, B = pts[:, facing_v[:, 0]].T, pts[:, facing_v[:, 1]].T
    Ad, Bd = A + Ud[vert_node[facing_v[:, 0]]], B + Ud[vert_node[facing_v[:, 1]]]
    E = Bd - Ad
    return A, B, Ad, E, np.einsum("ij,ij->i", E, E)


def update_projection():
    """Sets Yf, Nf, Onf from the closest points at the current u; returns the largest change of Yf."""
    U = md.variable("u")
    Ud = U.reshape(-1, 2)
    A, B, Ad, E, L2 = facing_polyline(U)
    Yf, Nf, Onf = np.zeros(mfY.nbdof()), np.zeros(mfY.nbdof()), np.zeros(mfO.nbdof())
    for j, (cv, f) in enumerate(own.T):
        a, b = pts[:, own_v[j, 0]], pts[:, own_v[j, 1]]
        ua, ub = Ud[vert_node[own_v[j, 0]]], Ud[vert_node[own_v[j, 1]]]
        vals = np.zeros((len(gauss_s), 5))  # y (2), N (2), on
        for i, sg in enumerate(gauss_s):
            ps = (1 - sg) * (a + ua) + sg * (b + ub)
            k, sk, _, on = closest_point(ps, Ad, E, L2)
            vals[i, :2] = A[k] + sk * (B[k] - A[k])
            vals[i, 2:4] = facing_N[k]
            vals[i, 4] = 1.0 if on else 0.0
        coef = np.linalg.solve(np.vander(gauss_s, 6), vals)  # the degree-5 polynomials in s
        for mfx, field, comps in ((mfY, Yf, (0, 1)), (mfY, Nf, (2, 3)), (mfO, Onf, (4,))):
            dofs = mfx.basic_dof_from_cv(int(cv))
            nodes = mfx.basic_dof_nodes(dofs)
            q = len(comps)
            for r in range(0, len(dofs), q):
                x = nodes[:, r]
                sn = (x - a) @ (b - a) / ((b - a) @ (b - a))
                if abs((x - a) @ np.array([b[1] - a[1], a[0] - b[0]])) > 1e-9 * ((b - a) @ (b - a)):
                    continue  # not on the own facet
                val = np.vander([sn], 6) @ coef
                for c in range(q):
                    field[dofs[r + c]] = val[0, comps[c]]
    change = np.max(np.abs(Yf - md.variable("Yf")))
    md.set_variable("Yf", Yf)
    md.set_variable("Nf", Nf)
    md.set_variable("Onf", Onf)
    return change


def exact_at_points(U):
    """The closest point (reference y), the signed distance and the flag at the quadrature points
    of OWN, in the order of imd_q (for --check-projection)."""
    keep = md.variable("u")
    md.set_variable("u", U)
    xs = md.interpolation("X + u", imd_q, OWN).reshape(-1, 2)
    md.set_variable("u", keep)
    A, B, Ad, E, L2 = facing_polyline(U)
    Y, dist, on = np.zeros_like(xs), np.zeros(len(xs)), np.zeros(len(xs))
    for q, ps in enumerate(xs):
        k, sk, dist[q], on[q] = closest_point(ps, Ad, E, L2)
        Y[q] = A[k] + sk * (B[k] - A[k])
    return Y, dist, on


def measure(t, U, V):
    MV = Mmat.mult(V)
    kinetic = 0.5 * V @ MV
    energy = kinetic + 0.5 * U @ Kmat.mult(U)
    ce = model_boundary(f"{eps}/2*sqr(neg_part({gap}))", U)
    force = -model_boundary(f"{eps}*neg_part({gap})", U)
    return (t, (Mex_l @ U) / mass_l, (Mex_r @ U) / mass_r, (Mex_l @ V) / mass_l, (Mex_r @ V) / mass_r,
            force, energy, energy + ce, kinetic)


def tangent():
    md.assembly("build_all")
    jc, ir = md.tangent_matrix().csc_ind()
    return scipy.sparse.csc_matrix((md.tangent_matrix().csc_val(), ir, jc), shape=(n, n)), md.rhs()


stats = {"newton": 0, "polish": 0, "outer": 0, "worst": 0.0}


def newton_solve(t):
    it = md.solve("max_res", args.max_res, "max_iter", 100, "lsolver", "mumps",
                  *(["noisy"] if args.noisy else []))
    stats["newton"] += it[0]
    if not it[1]:
        print(f"# GetFEM's Newton did not converge at t = {t:g}: {it}", file=sys.stderr)
    K, rhs = tangent()
    for k in range(args.polish):
        r = np.max(np.abs(rhs))
        if r <= args.polish_tol * ref_scale:
            break
        md.set_variable("u", md.variable("u") + scipy.sparse.linalg.spsolve(K, rhs))
        stats["polish"] += 1
        K, rhs = tangent()
        if np.max(np.abs(rhs)) >= 0.5 * r:  # no longer contracting: the round-off floor
            break
    res = np.max(np.abs(rhs)) / ref_scale
    stats["worst"] = max(stats["worst"], res)
    return res


def solve(t):
    md.set_time(t)
    if args.projection == "getfem":
        return newton_solve(t)
    # A fixed point on the facing points: Newton with y (and N, the flags) fixed, then y at the new
    # u, until y no longer changes.
    update_projection()
    for outer in range(50):
        res = newton_solve(t)
        stats["outer"] += 1
        change = update_projection()
        if change <= 1e-14:
            if change > 0:  # y moved by round-off: one more Newton with it
                res = newton_solve(t)
            return res
    print(f"# the facing points did not settle at t = {t:g}: change {change:.3e}", file=sys.stderr)
    return res


def check_projection(t, U):
    """GetFEM's facing point against the exact closest point, at the penetrating points."""
    keep = md.variable("u")
    md.set_variable("u", U)
    ys = md.interpolation(filt(f"Interpolate(X, {trans})"), imd_q, OWN).reshape(-1, 2)
    found = md.interpolation(filt("1"), imd_q1, OWN)
    md.set_variable("u", keep)
    Y, dist, on = exact_at_points(U)
    pen = (dist < 0) & (on > 0)
    dy = np.linalg.norm(ys - Y, axis=1)
    far = pen & (found > 0.5) & (dy > 1e-6)
    if np.any(pen):
        print(f"# t = {t:g}: {np.sum(pen)} penetrating points; GetFEM's facing point: largest |dy| "
              f"{np.max(np.where(pen & (dy <= 1e-6), dy, 0)):.1e} where within 1e-6, {np.sum(far)} farther "
              f"(largest {np.max(np.where(far, dy, 0)):.2e}), {np.sum(pen & (found < 0.5))} with none",
              file=sys.stderr)


def read_vtu_displacement(path):
    """The displacement of a signorini VTU snapshot (ascii), as a vector of mf's dofs (P1: by node position)."""
    import xml.etree.ElementTree as ET
    arrays = {d.get("Name"): np.array(d.text.split(), float) for d in ET.parse(path).iter("DataArray")}
    pieces = list(ET.parse(path).iter("Points"))[0]
    X = np.array(list(pieces.iter("DataArray"))[0].text.split(), float).reshape(-1, 3)[:, :2]
    D = arrays["displacement"].reshape(-1, 3)[:, :2]
    U = np.zeros(n)
    for i in range(0, n, 2):
        j = int(np.argmin(np.sum((X - dof_x[:, i]) ** 2, axis=1)))
        U[i:i + 2] = D[j]
    return U


if args.evaluate_vtu:
    U = read_vtu_displacement(args.evaluate_vtu)
    md.set_variable("u", U)
    if args.projection == "exact":
        update_projection()
    print(f"force {-model_boundary(f'{eps}*neg_part({gap})', U):.16e}  contact energy "
          f"{model_boundary(f'{eps}/2*sqr(neg_part({gap}))', U):.16e}")
    sys.exit(0)


# Time stepping ------------------------------------------------------------------------------
md.add_Newmark_scheme("u", args.beta, args.gam)
md.add_mass_brick(mim, "Dot2_u", "rho")
md.set_time_step(args.dt)
ref_scale = np.max(np.abs(Mmat.mult(V0))) / args.dt  # a force scale: the momentum over a step

U, V, A = U0.copy(), V0.copy(), np.zeros(n)
md.set_variable("u", U)
if args.projection == "exact":
    update_projection()
rows = [measure(0.0, U, V)]
steps = int(round(args.t_end / args.dt))
t0 = time.time()
for k in range(steps):
    t = (k + 1) * args.dt
    md.set_variable("Previous_u", U)
    md.set_variable("Previous_Dot_u", V)
    md.set_variable("Previous_Dot2_u", A)
    solve(t)
    md.shift_variables_for_time_integration()
    U = md.variable("Previous_u")
    V = md.variable("Previous_Dot_u")
    A = md.variable("Previous_Dot2_u")
    if args.check_projection:
        check_projection(t, U)
    rows.append(measure(t, U, V))

print(f"# {steps} steps in {time.time() - t0:.1f} s: GetFEM Newton iterations {stats['newton']}, polish "
      f"iterations {stats['polish']}, projection updates {stats['outer']}, largest final |R|_inf/scale "
      f"{stats['worst']:.2e}", file=sys.stderr)
out = sys.stdout if args.out == "-" else open(args.out, "w")
out.write("t,ux_left,ux_right,vx_left,vx_right,force,energy,energy_aug,kinetic\n")
for r in rows:
    out.write(",".join(repr(float(x)) for x in r) + "\n")
if out is not sys.stdout:
    out.close()
