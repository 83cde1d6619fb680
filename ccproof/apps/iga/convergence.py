"""Manufactured-solution convergence study of ``-Laplace_Gamma u + u = f`` on closed limit surfaces.

Meshes (:func:`study_mesh`): ``torus`` (no extraordinary vertex), ``cube`` (valence 3), ``icosahedron``
(one Catmull-Clark step of the icosahedron: valence 5 and 3) and ``prism6`` (one step of the hexagonal
prism: valence 6 and 3). Level L is the mesh subdivided L times (uniform refinement, h halves); the
errors are measured with a finer rule than the one assembled with (adaptive, 6 x 6 points per cell,
14 rings), so that they are the solution's. The rate between levels is ``log2(e_(L-1) / e_L)``
(per sqrt(dofs)); with ``graded``, the space of :mod:`ccproof.apps.iga.graded` refined toward the
extraordinary vertices at each level, whose rates are per sqrt(dofs) (:func:`rates`). docs/iga.md lists
the measured tables.

>>> rows = list(convergence_study("torus", levels=2))
>>> [r["dofs"] for r in rows], rows[-1]["L2"] < rows[0]["L2"]
([48, 192], True)
"""

from __future__ import annotations

import math

import numpy as np

from ccproof.apps.iga.assembly import AmbientFunction, solve_screened_poisson
from ccproof.apps.iga.quadrature import surface_quadrature
from ccproof.errors import CCProofError

__all__ = ["STUDY_MESHES", "OPEN_MESHES", "PROBLEMS", "study_mesh", "open_study_mesh", "half_fan",
           "FlatBoundaryFunction", "fan_contraction", "convergence_study", "rates", "fit_rate"]

STUDY_MESHES = ("torus", "cube", "icosahedron", "prism6")

#: flat open meshes (plane z = 0): ``grid`` (4 x 4 unit-square grid scaled to side 1; four corners with one
#: face), ``annulus`` (12 x 2 quads between radii 0.5 and 1.5; every vertex regular), ``ogrid`` (a square in
#: a ring of four trapezoids: four interior vertices of valence 3, a regular boundary), ``disk5`` (the planar
#: 5-regular complex of 5 sectors of 2 x 2 quads scaled by 1/2: one interior vertex of valence 5, five
#: boundary corners with one face), ``fan3`` and ``fan5`` (:func:`half_fan`, two rings: a boundary vertex with 3
#: or 5 faces on a straight boundary, the boundary extraordinary vertices ``crease:3`` and ``crease:5``)
OPEN_MESHES = ("grid", "annulus", "ogrid", "disk5", "fan3", "fan5")

PROBLEMS = ("screened", "biharmonic", "plate")


def _icosahedron():
    p = (1 + 5**0.5) / 2
    V = [[-1, p, 0], [1, p, 0], [-1, -p, 0], [1, -p, 0], [0, -1, p], [0, 1, p], [0, -1, -p], [0, 1, -p],
         [p, 0, -1], [p, 0, 1], [-p, 0, -1], [-p, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6],
         [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10],
         [8, 6, 7], [9, 8, 1]]
    return np.array(V, dtype=np.float64) / math.sqrt(1 + p * p), F


def _prism6():
    a = np.arange(6) * np.pi / 3
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(6)], 1)
    V = np.concatenate([ring - [0, 0, 1], ring + [0, 0, 1]])
    F = [[5, 4, 3, 2, 1, 0], [6, 7, 8, 9, 10, 11]] + [[i, (i + 1) % 6, (i + 1) % 6 + 6, i + 6] for i in range(6)]
    return V, F


def _annulus(n, radii):
    a = 2 * np.pi * np.arange(n) / n
    r = np.asarray(radii, dtype=np.float64)
    V = np.stack([np.outer(r, np.cos(a)).ravel(), np.outer(r, np.sin(a)).ravel(), np.zeros(r.size * n)], 1)
    F = [[i * n + j, (i + 1) * n + j, (i + 1) * n + (j + 1) % n, i * n + (j + 1) % n]
         for i in range(r.size - 1) for j in range(n)]
    return V, F


def _ogrid(sizes):
    """Nested squares of half-sides ``sizes`` joined by rings of four trapezoids, the first one a face."""
    sq = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]], dtype=np.float64)
    V = np.concatenate([np.c_[s * sq, np.zeros(4)] for s in sizes])
    F = [[0, 1, 2, 3]] + [[4 * (i + 1) + c, 4 * (i + 1) + (c + 1) % 4, 4 * i + (c + 1) % 4, 4 * i + c]
                          for i in range(len(sizes) - 1) for c in range(4)]
    return V, F


class FlatBoundaryFunction(AmbientFunction):
    """``u = y^3 cos(a x)`` (flat meshes): its Hessian vanishes on the line ``y = 0``, so on a straight
    EDGE_ONLY boundary there it meets the space's end condition (a zero second derivative across the
    boundary, docs/iga.md), and what is left of the error at the boundary is its vertices'.

    >>> u = FlatBoundaryFunction()
    >>> x = np.array([[0.3, 0.0, 0.0]])
    >>> float(np.abs(u.hessian(x)).max()), float(np.abs(u.gradient(x)).max())
    (0.0, 0.0)
    """

    def __init__(self, a=math.pi):
        super().__init__(a, 0.0, 0.0)

    def value(self, X):
        return X[:, 1] ** 3 * np.cos(self.a * X[:, 0])

    def gradient(self, X):
        a, x, y = self.a, X[:, 0], X[:, 1]
        return np.stack([-a * y**3 * np.sin(a * x), 3 * y**2 * np.cos(a * x), 0 * x], axis=1)

    def hessian(self, X):
        a, x, y = self.a, X[:, 0], X[:, 1]
        H = np.zeros((X.shape[0], 3, 3))
        H[:, 0, 0] = -a * a * y**3 * np.cos(a * x)
        H[:, 0, 1] = H[:, 1, 0] = -3 * a * y**2 * np.sin(a * x)
        H[:, 1, 1] = 6 * y * np.cos(a * x)
        return H


def half_fan(k, rings=2):
    """A planar open fan of ``k`` parallelogram sectors of ``rings x rings`` quads over the upper half-disk:
    sector j is spanned by ``e_j = (cos(pi j / k), sin(pi j / k))`` and ``e_(j+1)``, its vertex (a, b) at
    ``(a e_j + b e_(j+1)) / rings``; the centre (vertex 0, at the origin) is a boundary vertex with k faces
    on the straight boundary along rays 0 and k (the x-axis).

    >>> m = half_fan(3)
    >>> m.n_faces, int(np.bincount(np.asarray(m.faces).ravel())[0]), bool(m.is_boundary_vertex[0])
    (12, 3, True)
    """
    from ccproof.mesh import QuadMesh

    if int(k) != k or k < 2 or rings < 1:
        raise CCProofError(f"half_fan needs k >= 2 sectors and rings >= 1, got k={k}, rings={rings}")
    k, R = int(k), int(rings)
    last = 1 + k * R * (R + 1)  # the vertices (a, 0) of ray k, a = 1 .. R

    def vid(j, a, b):
        if a == 0 and b == 0:
            return 0
        if a == 0:
            return vid(j + 1, b, 0) if j + 1 < k else last + b - 1
        return 1 + (j * R + a - 1) * (R + 1) + b

    e = np.stack([np.cos(np.pi * np.arange(k + 1) / k), np.sin(np.pi * np.arange(k + 1) / k)], 1)
    V = np.zeros((last + R, 3))
    for j in range(k):
        for a in range(R + 1):
            for b in range(R + 1):
                V[vid(j, a, b), :2] = (a * e[j] + b * e[j + 1]) / R
    F = [[vid(j, a, b), vid(j, a + 1, b), vid(j, a + 1, b + 1), vid(j, a, b + 1)]
         for j in range(k) for a in range(R) for b in range(R)]
    return QuadMesh(V, F)


def open_study_mesh(name, ghost=False):
    """The level-0 QuadMesh of a flat open study mesh (:data:`OPEN_MESHES`) and its region (bool per face).

    With ``ghost``, one more ring of faces outside, its vertices at ``2 B - I`` (B a boundary vertex, I its
    neighbour inside): the region (the original faces) is then surrounded by free ghost vertices, and its
    limit is a regular bicubic surface up to its boundary (on ``grid``: exactly the unit square). On
    ``fan3`` and ``fan5`` the ring is added on the curved side only (a third ring of the sectors): the
    straight boundary and its extraordinary vertex stay a boundary of the mesh (EDGE_ONLY).

    >>> m, region = open_study_mesh("grid", ghost=True)
    >>> m.n_vertices, int(region.sum()), float(m.vertices[:, :2].min()), float(m.vertices[:, :2].max())
    (49, 16, -0.25, 1.25)
    """
    from ccproof.mesh import QuadMesh
    from ccproof.mesh.examples import grid, k_regular_disk

    if name not in OPEN_MESHES:
        raise CCProofError(f"unknown open study mesh {name!r}; use one of {', '.join(OPEN_MESHES)}")
    g = int(bool(ghost))
    if name.startswith("fan"):
        m, R = half_fan(int(name[3:]), rings=2 + g), 2 + g  # sector j, face (j R + a) R + b
        a, b = np.divmod(np.arange(m.n_faces) % (R * R), R)
        return QuadMesh(m.vertices * R / 2, m.faces), (a < 2) & (b < 2)
    if name == "grid":
        m = grid(4 + 2 * g, 4 + 2 * g)
        V = (m.vertices - [g, g, 0.0]) / 4
        i = np.arange(4 + 2 * g)
        region = ((i[None, :] >= g) & (i[None, :] < 4 + g) & (i[:, None] >= g) & (i[:, None] < 4 + g)).ravel()
        return QuadMesh(V, m.faces), region
    if name == "annulus":
        V, F = _annulus(12, np.linspace(0.5 - 0.5 * g, 1.5 + 0.5 * g, 3 + 2 * g))
        region = np.zeros(len(F), dtype=bool)
        region[12 * g:12 * (2 + g)] = True
        return QuadMesh(V, F), region
    if name == "disk5":  # sector j, face (j R + a) R + b; the sectors extend linearly (2 B - I)
        m, R = k_regular_disk(5, rings=2 + g), 2 + g
        a, b = np.divmod(np.arange(m.n_faces) % (R * R), R)
        return QuadMesh(m.vertices / 2, m.faces), (a < 2) & (b < 2)
    V, F = _ogrid([0.4, 1.0, 1.6][:2 + g])
    return QuadMesh(V, F), np.arange(len(F)) < 5


def study_mesh(name):
    """The level-0 QuadMesh of a study mesh (see the module docstring).

    >>> m = study_mesh("prism6")
    >>> m.n_faces, sorted(set(m.valence.tolist()))
    (36, [3, 4, 6])
    """
    from ccproof.mesh.examples import cube, torus
    from ccproof.mesh.polymesh import PolyMesh

    if name == "torus":
        return torus()
    if name == "cube":
        return cube()
    if name in ("icosahedron", "prism6"):
        V, F = _icosahedron() if name == "icosahedron" else _prism6()
        return PolyMesh(V, F).refine(operator=False)[0].to_quad_mesh()
    raise CCProofError(f"unknown study mesh {name!r}; use one of {', '.join(STUDY_MESHES)}")


def convergence_study(mesh, levels=4, kind="adaptive", parameterization="natural", exact=None, start=0,
                      graded=None, problem="screened", options=None):
    """Yield per level ``{"level", "faces", "dofs", "L2", "H1"}`` (and ``"H2"`` for the biharmonic problem, the
    errors per level of the refinement ``"leaves"`` for a graded space) of the Galerkin solution.

    Parameters
    ----------
    mesh : str or QuadMesh
        A :data:`STUDY_MESHES` or :data:`OPEN_MESHES` name, or a closed QuadMesh (level 0).
    levels : int
        Levels ``start .. start + levels - 1``.
    kind : str
        The assembly's quadrature (:func:`ccproof.apps.iga.quadrature.surface_quadrature`).
    parameterization : {"natural", "characteristic"}
    exact : AmbientFunction, optional
        The manufactured solution (default ``AmbientFunction()``; on the open meshes
        ``sin(pi x) cos(pi y)``).
    start : int
        The first level.
    graded : (extra, rings) or (extra, rings, width), optional
        Instead of the uniform space: the hierarchical space graded toward the EVs
        (:mod:`ccproof.apps.iga.graded`; natural parameterization, adaptive rule), ``extra`` levels deep at
        every level (an int), or at level L ``graded_levels(valence, L, margin)`` levels around each EV
        (``extra = "auto"``, margin 1, or ``"auto:M"``), over ``rings`` face rings per level, or with a
        ``width`` > 0 over ``graded_rings(valence, L, j, rings, width)`` rings at level ``L + j``: the
        grading that keeps the regular rates.
    problem : {"screened", "biharmonic", "plate"}
        ``-Laplace_Gamma u + u = f``, or ``Laplace_Gamma^2 u + u = f`` on a closed mesh
        (:mod:`ccproof.apps.iga.biharmonic`; uniform space), or the plate on ``grid`` (the unit square,
        level L at mesh size ``1 / (4 2^L)``, :mod:`ccproof.apps.iga.plate`).
    options : dict, optional
        ``order`` (4) and ``depth`` (12) of the assembly's rule; on the open meshes ``bc``
        (``"dirichlet"`` or ``"neumann"``, :func:`ccproof.apps.iga.boundary.solve_open_screened_poisson`)
        and ``ghost`` (False: the space with a ring of ghost vertices, :func:`open_study_mesh`); for the
        plate ``support`` (``"clamped"`` or ``"simple"``).
    """
    opt = {"order": 4, "depth": 12, "bc": "dirichlet", "ghost": False, "support": "clamped", **(options or {})}
    unknown = sorted(set(opt) - {"order", "depth", "bc", "ghost", "support"})
    if unknown:
        raise CCProofError(f"unknown convergence_study options {unknown}; use order, depth, bc, ghost, support")
    order, depth = int(opt["order"]), int(opt["depth"])
    if problem not in PROBLEMS:
        raise CCProofError(f"unknown problem {problem!r}; use one of {', '.join(PROBLEMS)}")
    if problem == "plate":
        if mesh != "grid":
            raise CCProofError(f"the plate problem is posed on the mesh 'grid' (the unit square), not {mesh!r}")
        from ccproof.apps.iga.plate import solve_plate

        for L in range(start, start + levels):
            r = solve_plate(4 * 2**L, opt["support"])
            yield {"level": L, "faces": 16 * 4**L, **{k: r[k] for k in ("dofs", "L2", "H1", "H2")}}
        return
    if isinstance(mesh, str) and mesh in OPEN_MESHES:
        if problem == "screened" and graded is not None and mesh.startswith("fan") and opt["ghost"] \
                and opt["bc"] == "neumann":
            yield from _fan_graded_study(mesh, levels, graded, exact, start)
            return
        if problem != "screened" or graded is not None:
            raise CCProofError(f"the open mesh {mesh!r} takes the screened Poisson problem on a uniform space "
                               "(a graded space: fan3 or fan5 with ghost=True and bc='neumann')")
        yield from _open_study(mesh, levels, (kind, order, depth), exact, start, opt["bc"], opt["ghost"])
        return
    from ccproof.mesh import subdivide

    M = study_mesh(mesh) if isinstance(mesh, str) else mesh
    if M.is_boundary_vertex.any():
        raise CCProofError("the convergence study needs a closed mesh or an open study mesh name "
                           f"({', '.join(OPEN_MESHES)})")
    exact = AmbientFunction() if exact is None else exact
    for _ in range(start):
        M = subdivide(M)
    for L in range(start, start + levels):
        if graded is not None:
            from ccproof.apps.iga.graded import solve_graded

            extra, rings = _graded_space(M, graded, L)
            r = solve_graded(M, extra, exact, rings=rings)
        else:
            r = _solve_uniform(M, (kind, order, depth), parameterization, exact, problem)
        yield {"level": L, "faces": M.n_faces, **{k: r[k] for k in ("dofs", "L2", "H1", "H2", "leaves") if k in r}}
        if L + 1 < start + levels:
            M = subdivide(M)


def _solve_uniform(mesh, rule, parameterization, exact, problem):
    """One level of :func:`convergence_study` on a closed mesh, uniform space (``rule`` = kind, order, depth
    of the assembly's quadrature; errors with the finer rule of the module docstring)."""
    from ccproof.reparam import limit_surface

    S = limit_surface(mesh)
    kind, order, depth = rule
    rule = surface_quadrature(S, order, kind, depth)
    fine = surface_quadrature(S, 6, "adaptive" if parameterization == "natural" else "split", 14)
    if problem == "biharmonic":
        from ccproof.apps.iga.biharmonic import solve_biharmonic

        return solve_biharmonic(S, rule, exact, parameterization, error_rule=fine)
    return solve_screened_poisson(S, rule, exact, parameterization, error_rule=fine)


def _graded_space(mesh, graded, level):
    """``(extra, rings)`` of :class:`ccproof.apps.iga.graded.HierarchicalSpace` at ``level`` from ``graded``
    of :func:`convergence_study`: an int as it is, ``"auto[:margin]"`` per valence of the mesh's EVs; the
    rings as they are, or with a width (third entry > 0) per valence and level (``graded_rings``)."""
    from ccproof.apps.iga.graded import graded_levels, graded_rings

    extra, rings = graded[0], int(graded[1])
    width = float(graded[2]) if len(graded) > 2 else 0.0
    val = np.unique(np.asarray(mesh.valence)[~np.asarray(mesh.is_boundary_vertex)]).tolist()
    if isinstance(extra, str):
        name, _, margin = extra.partition(":")
        if name != "auto":
            raise CCProofError(f"graded extra levels must be an int or 'auto[:margin]', got {extra!r}")
        extra = {n: graded_levels(n, level, int(margin or 1)) for n in val}
    if width <= 0:
        return extra, rings
    depth = extra if isinstance(extra, dict) else dict.fromkeys(val, int(extra))
    return extra, {n: [graded_rings(n, level, j, rings, width) for j in range(1, depth[n] + 1)] for n in val}


def _open_study(name, levels, rule, exact, start, bc, ghost):
    """:func:`convergence_study` on an open study mesh (natural parameterization; ``rule`` = kind, order,
    depth of the assembly's quadrature)."""
    from ccproof.apps.iga.boundary import solve_open_screened_poisson
    from ccproof.evaluate import natural_limit_surface
    from ccproof.mesh import subdivide

    M, region = open_study_mesh(name, ghost)
    if exact is None:
        exact = FlatBoundaryFunction() if name.startswith("fan") else AmbientFunction(math.pi, math.pi, 0.0)
    for L in range(start + levels):
        if L >= start:
            S = natural_limit_surface(M)
            r = solve_open_screened_poisson(S, surface_quadrature(S, rule[1], rule[0], rule[2]), exact, bc,
                                            error_rule=surface_quadrature(S, 6, "adaptive", 14),
                                            region=region if ghost else None)
            yield {"level": L, "faces": int(region.sum()), "dofs": r["dofs"], "L2": r["L2"], "H1": r["H1"]}
        if L + 1 < start + levels:
            M, region = subdivide(M), np.repeat(region, 4)


def fan_contraction(k, steps=7):
    """The cross-boundary contraction ``mu`` of the boundary vertex with ``k`` faces (the centre of
    :func:`half_fan`): the ratio of its one-ring's height above the boundary line between the last two of
    ``steps`` uniform subdivisions (the mesh is symmetric under x -> -x: the 1/2 of the boundary curve's
    tangent is along x; the height contracts at the largest eigenvalue of the other eigenvectors).

    >>> round(fan_contraction(2), 12)
    0.5
    """
    from ccproof.mesh import subdivide

    m, heights = half_fan(k), []
    for i in range(steps + 1):
        F = np.asarray(m.faces)
        ring = np.unique(F[(F == 0).any(axis=1)])
        heights.append(float(np.abs(m.vertices[ring, 1]).max()))
        if i < steps:
            m = subdivide(m)
    return heights[-1] / heights[-2]


def _fan_graded_study(name, levels, graded, exact, start):
    """:func:`convergence_study` on ``fan3`` / ``fan5`` with the curved side's ghost ring, Neumann, in the
    space graded toward the boundary EV: at level L ``graded_levels(.., lam=mu, orders=(4, 3))`` extra
    levels (``mu`` = :func:`fan_contraction`; the solution has no quadratic part at the vertex: its errors
    there are ``mu^(4L)``, ``mu^(3L)``) over ``graded_rings(.., lam=mu)`` rings (``graded`` as in
    :func:`convergence_study`: ``("auto[:margin]", rings, width)``)."""
    from ccproof.apps.iga.graded import graded_levels, graded_rings, solve_graded
    from ccproof.mesh import subdivide

    extra, rings = str(graded[0]), int(graded[1])
    width = float(graded[2]) if len(graded) > 2 else 0.0
    name_, _, margin = extra.partition(":")
    if name_ != "auto":
        raise CCProofError(f"a graded fan study takes extra 'auto[:margin]', got {graded[0]!r}")
    M, region = open_study_mesh(name, ghost=True)
    mu, n = fan_contraction(int(name[3:])), int(M.valence[0])
    exact = FlatBoundaryFunction() if exact is None else exact
    for L in range(start + levels):
        if L >= start:
            s = graded_levels(n, L, int(margin or 1), lam=mu, orders=(4, 3))
            R = [graded_rings(n, L, j, rings, width, lam=mu) if width > 0 else rings for j in range(1, s + 1)]
            r = solve_graded(M, s, exact, rings={n: R}, vertices=[0], region=region)
            yield {"level": L, "faces": int(region.sum()), **{k: r[k] for k in ("dofs", "L2", "H1", "leaves")}}
        if L + 1 < start + levels:
            M, region = subdivide(M), np.repeat(region, 4)


def fit_rate(rows, key, per="level"):
    """Least-squares slope of ``-log2 e`` against the level (h halves per level), scikit-fem style, or
    (``per="dofs"``) of ``-log e`` against ``log sqrt(dofs)``.

    >>> fit_rate([{"L2": 1.0}, {"L2": 1 / 16}, {"L2": 1 / 256}], "L2")
    4.0
    >>> fit_rate([{"L2": 1.0, "dofs": 10}, {"L2": 1 / 16, "dofs": 40}], "L2", per="dofs")
    4.0
    """
    e = np.log2([r[key] for r in rows])
    x = np.arange(e.size) if per == "level" else 0.5 * np.log2([r["dofs"] for r in rows])
    return float(round(-np.polyfit(x, e, 1)[0], 12))


def rates(rows, key, per="level"):
    """Rates between consecutive rows (NaN for the first): ``log2(e_(L-1) / e_L)`` per level, or per
    sqrt(dofs) (``per="dofs"``: ``2 log(e_(L-1) / e_L) / log(N_L / N_(L-1))``; the same for uniform
    refinement, where N grows fourfold)."""
    e = [r[key] for r in rows]
    if per == "level":
        return [math.nan] + [math.log2(a / b) for a, b in zip(e[:-1], e[1:])]
    n = [r["dofs"] for r in rows]
    return [math.nan] + [2 * math.log(a / b) / math.log(m / k) for a, b, k, m in zip(e[:-1], e[1:], n[:-1], n[1:])]
