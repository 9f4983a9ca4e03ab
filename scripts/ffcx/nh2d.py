import basix.ufl, ufl
from ufl import (Coefficient, Constant, FunctionSpace, Identity, Mesh, TestFunction, TrialFunction,
                 derivative, det, dx, grad, ln, tr, variable, diff, inner)
import os
cellname = os.environ.get("CELL", "triangle")
gdim = 2 if cellname == "triangle" else 3
qd = os.environ.get("QDEG")
domain = Mesh(basix.ufl.element("Lagrange", cellname, 1, shape=(gdim,)))
V = FunctionSpace(domain, basix.ufl.element("Lagrange", cellname, 2, shape=(gdim,)))
v = TestFunction(V); du = TrialFunction(V); u = Coefficient(V)
mu = Constant(domain); lmbda = Constant(domain)
I = Identity(gdim)
F = variable(I + grad(u))
C = F.T * F
Ic = tr(C); J = det(F)
psi = (mu / 2) * (Ic - gdim) - mu * ln(J) + (lmbda / 2) * (ln(J))**2
P = diff(psi, F)
md = {} if qd is None else {"quadrature_degree": int(qd)}
R = inner(P, grad(v)) * dx(metadata=md)
a = derivative(R, u, du)
forms = [a]
