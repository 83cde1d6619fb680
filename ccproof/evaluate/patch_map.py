"""Locating points of ptex faces in a patch table (OpenSubdiv ``Far::PatchMap``; bmz04 section 3, Fig. 3).

The patch table (:class:`ccproof.evaluate.patch_table.PatchTable`) stores per ptex face the job of each of its
four quadrants and, per job, a template of virtual faces; :class:`PatchMap` finds, for points (f, u, v),
the virtual face holding each point and, in a corner face (one irregular corner), the layer and the
patch of that layer (the evaluation then applies the configuration's layer operator to the face's ring):

::

    ptex face f, (u, v) in [0, 1]^2           a corner face (irregular corner at the origin here)
    +-----------+-----------+ (1,1)           +-----------------------+
    |           |           |                 |           |           |
    |  q = 2    |  q = 3    |                 |  code 2   |  code 1   |   layer 0: max(du, dv) in [1/2, 1)
    |           |           |                 |           |           |
    +-----------+-----------+                 +-----+-----+-----------+
    |           |           |                 |  2  |  1  |           |
    |  q = 0    |  q = 1    |                 +--+--+-----+  code 0   |   layer n: max(du, dv) in
    |           |           |                 |..|0 |  0  |           |     [2^-(n+1), 2^-n)
    +-----------+-----------+                 +--+--+-----+-----------+
  (0,0)                   (1,0)              (0,0)

    q = (u >= 1/2) + 2 (v >= 1/2): top[f, q]  du, dv: distances from the irregular corner in units
    is the quadrant's job; split virtual       of the face's side (exact: dyadic); n = -e for
    faces are descended by the same rule       max(du, dv) in [2^(e-1), 2^e), clipped to the
                                               configuration's last layer

Every step is exact in floating point (dyadic rescalings, Sterbenz subtractions): the compiled kernels
(``_clib.c``, ``_numba_kernel.py``) locate by the same rules, and the lookup tests compare them bit for bit.

>>> import numpy as np
>>> from ccproof.evaluate import natural_limit_surface
>>> from ccproof.mesh.examples import k_regular_disk
>>> S = natural_limit_surface(k_regular_disk(5, 3))

Face 0 has the extraordinary vertex at its corner (0, 0): a corner face; a point lies in layer
floor(-log2 max(u, v)), here 1 and 8, and in patch 2 of layer 8 (v the larger after rescaling):

>>> loc = S.patch_map.locate(np.array([0, 0]), np.array([0.3, 1e-3]), np.array([0.2, 2e-3]))
>>> loc.kind.tolist(), loc.layer.tolist(), loc.code.tolist()
([1, 1], [1, 8], [0, 2])
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ccproof.evaluate.patch_table import KIND_CORNER, KIND_SPLIT

__all__ = ["PatchMap", "Location"]


class Location(NamedTuple):
    """Where points (f, u, v) lie in a patch table (:meth:`PatchMap.locate`); arrays of shape (n,).

    Attributes
    ----------
    patch : ndarray of int64
        A stored regular patch (``< n_patches``), or ``n_patches + 3 (max_layers c + n) + code`` for
        patch ``code`` of layer ``n`` of corner face ``c`` (not stored).
    s, t : ndarray of float64
        Parameter in the patch, in [0, 1] (exact: dyadic rescaling).
    scale : ndarray of float64
        ``1 / h``: d/du = scale * d/ds for a patch of side h (a power of 2).
    job, vface, kind : ndarray of int64, int64, int8
        The point's job, the template virtual face holding it and that face's kind (0 regular patch,
        1 corner face).
    corner : ndarray of int64
        The indices of the points in corner faces (``kind == 1``).
    layer, code, corner_face : ndarray of int64, shape (len(corner),)
        For those points: the layer, the patch of the layer and the corner face's index (rows of
        ``origin``).
    """

    patch: np.ndarray
    s: np.ndarray
    t: np.ndarray
    scale: np.ndarray
    job: np.ndarray
    vface: np.ndarray
    kind: np.ndarray
    corner: np.ndarray
    layer: np.ndarray
    code: np.ndarray
    corner_face: np.ndarray


class PatchMap:
    """Locates points (ptex face, u, v) in a :class:`~ccproof.evaluate.patch_table.PatchTable` (module docstring).

    Parameters
    ----------
    table : PatchTable
        Only its topology arrays are read (``top``, ``job_root``, ``job_net``, ``job_corner``, ``kind``,
        ``child``, ``u0``, ``v0``, ``h``, ``leaf``, ``cfg``, ``cu``, ``cv``, ``n_layers``, ``unit``,
        ``split_depth``), so one map serves every surface that shares them
        (:meth:`ccproof.evaluate.surface.LimitSurface.with_vertices`).

    Attributes
    ----------
    n_patches : int
        Regular patches (their ids: ``job_net[job] + leaf``).
    max_layers : int
        The most layers of any configuration (the stride of corner patch ids).
    """

    def __init__(self, table):
        self.table = table
        self.n_patches = int(table.n_regular)
        self.max_layers = int(table.n_layers.max()) if table.n_layers.size else 0

    def faces(self, f, u, v):
        """The job of every point, the template virtual face holding it after descending the splits,
        and that face's kind.

        Parameters
        ----------
        f : ndarray of int64, shape (n,)
        u, v : ndarray of float64, shape (n,)

        Returns
        -------
        job, vface : ndarray of int64, shape (n,)
        kind : ndarray of int8, shape (n,)
        """
        T = self.table
        q = (u >= 0.5).astype(np.int64) + 2 * (v >= 0.5)
        job = T.top[f, q]
        vf = T.job_root[job]
        kind = T.kind[vf]
        for _ in range(T.split_depth):
            idx = np.flatnonzero(kind == KIND_SPLIT)
            if idx.size == 0:
                break
            w = vf[idx]
            half = T.h[w] * 0.5
            q = (u[idx] >= T.u0[w] + half).astype(np.int64) + 2 * (v[idx] >= T.v0[w] + half)
            vf[idx] = T.child[w, q]
            kind[idx] = T.kind[vf[idx]]
        return job, vf, kind

    def corner_layer(self, vf, u, v):
        """Layer ``n`` and patch ``code`` of points (u, v) in corner faces ``vf``, and the patch domains
        ``(u0, v0, h)`` (exact: dyadic; bmz04 Fig. 3).

        Returns
        -------
        n, code : ndarray of int64, shape (n,)
        u0, v0, h : ndarray of float64, shape (n,)
        """
        T = self.table
        U0, V0, H = T.u0[vf], T.v0[vf], T.h[vf]
        du = np.where(T.cu[vf], (U0 + H) - u, u - U0) / H  # exact: dyadic, Sterbenz
        dv = np.where(T.cv[vf], (V0 + H) - v, v - V0) / H
        mx = np.maximum(du, dv)
        _, e = np.frexp(mx)  # mx in [2^(e-1), 2^e): layer n = -e
        cfg = T.cfg[vf]
        nmax = T.n_layers[cfg] - 1
        n = np.where(mx > 0, np.clip(-e, 0, nmax), nmax)
        du, dv = np.ldexp(du, n), np.ldexp(dv, n)
        a, b = du >= 0.5, dv >= 0.5
        code = np.where(a & ~b, 0, np.where(a & b, 1, np.where(b, 2, 1)))
        unit = T.unit[cfg, code]
        sc = np.ldexp(H, -n)
        pu0 = unit[:, 0] * sc + np.where(T.cu[vf], U0 + H, U0)
        pv0 = unit[:, 1] * sc + np.where(T.cv[vf], V0 + H, V0)
        return n, code, pu0, pv0, unit[:, 2] * sc

    def locate(self, f, u, v):
        """The patch of every point and the point's parameter in it.

        Parameters
        ----------
        f : ndarray of int64, shape (n,)
            Ptex faces (checked by the caller).
        u, v : ndarray of float64, shape (n,)
            In [0, 1].

        Returns
        -------
        Location
        """
        T = self.table
        job, vf, kind = self.faces(f, u, v)
        patch = T.job_net[job] + T.leaf[vf]
        pu0, pv0, h = T.u0[vf], T.v0[vf], T.h[vf]
        idx = np.flatnonzero(kind == KIND_CORNER)
        n = code = ci = np.zeros(0, dtype=np.int64)
        if idx.size:
            w = vf[idx]
            n, code, pu0[idx], pv0[idx], h[idx] = self.corner_layer(w, u[idx], v[idx])
            ci = T.job_corner[job[idx]] + T.leaf[w]
            patch[idx] = self.n_patches + 3 * (self.max_layers * ci + n) + code
        s = np.clip((u - pu0) / h, 0.0, 1.0)
        t = np.clip((v - pv0) / h, 0.0, 1.0)
        return Location(patch, s, t, 1.0 / h, job, vf, kind, idx, n, code, ci)
