"""A fourth-order problem where C1 matters: the surface biharmonic ``Laplace_Gamma^2 u + u = f`` on a closed
limit surface.

The weak form ``int Laplace_Gamma u Laplace_Gamma v + u v = l(v)`` needs functions in H^2 of the surface:
the limit functions of the control vertices are (they are C1, C2 away from the extraordinary vertices, and
their second derivatives are square integrable near them), so the space is conforming. The Laplace-Beltrami
operator of a basis function comes from its second derivatives (``Duu``, ``Duv``, ``Dvv`` rows of
:meth:`ccproof.evaluate.surface.LimitSurface.basis`) and the metric:

``Laplace_Gamma phi = g^ab (phi_ab - Gamma^c_ab phi_c)``, ``Gamma^c_ab = g^cd (P_ab . P_d)``

(:func:`laplace_beltrami_rows`; on the coordinates it gives the mean curvature vector ``-kappa n``).

Manufactured solution. ``f = Laplace_Gamma^2 u + u`` would need the fourth derivatives of the surface; the
load is instead the functional ``l(v) = int Laplace_Gamma u Laplace_Gamma v + u v`` of the exact u (its
Laplace-Beltrami value is exact from the surface's second derivatives,
:meth:`~ccproof.apps.iga.assembly.AmbientFunction.laplace_beltrami`): the exact solution of the
variational problem with that load is u itself, and the Galerkin solution is its energy projection.

>>> from ccproof.mesh.examples import torus
>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.apps.iga.quadrature import surface_quadrature
>>> from ccproof.apps.iga.assembly import AmbientFunction
>>> S = natural_limit_surface(torus())
>>> r = solve_biharmonic(S, surface_quadrature(S, 4, "plain"), AmbientFunction())
>>> r["dofs"], round(r["L2"], 2), round(r["H2"], 2)       # level 0 of the torus study (docs/iga.md)
(48, 0.56, 3.37)
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

__all__ = ["laplace_beltrami_rows", "solve_biharmonic"]


def laplace_beltrami_rows(surface, fields, rule, parameterization="natural"):
    """CSR rows (n_points, n_vertices) of ``Laplace_Gamma phi_i`` at the points of ``rule``.

    ``fields`` is the :class:`~ccproof.apps.iga.assembly.SurfaceFields` of the same rule (its inverse metric);
    the second derivatives of the surface and the basis are evaluated here.
    """
    f, u, v, _ = rule
    W = surface.basis(f, u, v, 2, parameterization=parameterization)
    r = surface.evaluate(f, u, v, 2, parameterization=parameterization)
    G = fields.Ginv
    Pu, Pv = r["Pu"], r["Pv"]
    H = {"uu": r["Puu"], "uv": r["Puv"], "vv": r["Pvv"]}
    coef = {"uu": G[:, 0, 0], "uv": 2 * G[:, 0, 1], "vv": G[:, 1, 1]}
    # t_d = g^ab (P_ab . P_d); sum_ab g^ab Gamma^c_ab = g^cd t_d
    t = [sum(coef[k] * np.einsum("ij,ij->i", H[k], Pd) for k in H) for Pd in (Pu, Pv)]
    cu = G[:, 0, 0] * t[0] + G[:, 0, 1] * t[1]
    cv = G[:, 1, 0] * t[0] + G[:, 1, 1] * t[1]
    return fields.combine([(coef["uu"], W["Duu"]), (coef["uv"], W["Duv"]), (coef["vv"], W["Dvv"]),
                           (-cu, W["Du"]), (-cv, W["Dv"])])


def solve_biharmonic(surface, rule, exact, parameterization="natural", error_rule=None):
    """Galerkin solution of ``Laplace_Gamma^2 u + u = f`` on a closed surface for the manufactured solution
    ``exact`` (an :class:`~ccproof.apps.iga.assembly.AmbientFunction`; load: module docstring).

    Returns
    -------
    dict
        ``c`` (n_vertices,), errors ``L2``, ``H1`` (seminorm), ``H2`` (``|| Laplace_Gamma (u_h - u) ||``),
        ``dofs``.
    """
    from ccproof.apps.iga.assembly import SurfaceFields, solve_spd

    F = SurfaceFields(surface, rule, parameterization, curvature=True)
    L = laplace_beltrami_rows(surface, F, rule, parameterization)
    A = (L.T @ sp.diags(F.dA) @ L).tocsr() + F.mass()
    b = L.T @ (F.dA * exact.laplace_beltrami(F)) + F.load(exact.value(F.P))
    c = solve_spd(A, b)
    if error_rule is not None:
        rule = error_rule
        F = SurfaceFields(surface, rule, parameterization, curvature=True)
        L = laplace_beltrami_rows(surface, F, rule, parameterization)
    L2, H1 = F.errors(c, exact)
    e = L @ c - exact.laplace_beltrami(F)
    return {"c": c, "L2": L2, "H1": H1, "H2": float(np.sqrt(F.dA @ (e * e))), "dofs": int(c.size)}
