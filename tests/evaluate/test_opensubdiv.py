"""Exact evaluation against OpenSubdiv 3.6.0 reference values (tests/data, inputs not outputs).

Tolerances relative to the bounding-box diagonal of the control mesh: positions 1e-12, first
derivatives 1e-10 on every sample outside an OpenSubdiv end cap (``endcap=false``) and on the
``deep`` values where the deeper evaluation is itself outside an end cap; vertex limits 1e-13.
"""

import functools
import json

import numpy as np
import pytest

from ccproof.evaluate import limit_surface
from ccproof.evaluate.backend import available_backends
from ccproof.mesh import read_obj

MESHES = ["cube", "sector_k3", "sector_k5", "sector_k6", "torus_8x6"]
#: the meshes with an extraordinary vertex (the torus has none, so no end-cap samples)
EV_MESHES = ["cube", "sector_k3", "sector_k5", "sector_k6"]


def _load(refdir, name):
    d = json.loads((refdir / f"osd_limit_{name}.json").read_text())
    assert d["boundary_interpolation"] == "VTX_BOUNDARY_EDGE_ONLY" and d["creases"] == "none"
    return d, read_obj(refdir / "meshes" / f"{name}.obj")


def _exact_samples(d):
    rows = []
    for s in d["samples"]:
        if not s["endcap"]:
            rows.append((s["face"], s["s"], s["t"], s["P"], s["Ps"], s["Pt"]))
        elif not s["deep"]["endcap"]:
            q = s["deep"]
            rows.append((s["face"], s["s"], s["t"], q["P"], q["Ps"], q["Pt"]))
    return rows


def _backends():
    return available_backends()


@functools.cache
def _surface(refdir, name):
    return limit_surface(read_obj(refdir / "meshes" / f"{name}.obj"))


@pytest.mark.parametrize("backend", _backends())
@pytest.mark.parametrize("name", MESHES)
def test_samples_match_opensubdiv(refdir, name, backend):
    d, mesh = _load(refdir, name)
    rows = _exact_samples(d)
    assert len(rows) >= 99
    S = _surface(refdir, name)
    f, u, v = (np.array([r[i] for r in rows]) for i in range(3))
    out = S.evaluate(f, u, v, derivatives=1, backend=backend)
    diag = mesh.bounding_box_diagonal
    P, Ps, Pt = (np.array([r[i] for r in rows]) for i in (3, 4, 5))
    assert np.abs(out["P"] - P).max() <= 1e-12 * diag
    assert np.abs(out["Pu"] - Ps).max() <= 1e-10 * diag
    assert np.abs(out["Pv"] - Pt).max() <= 1e-10 * diag


@pytest.mark.parametrize("name", EV_MESHES)
def test_exact_corner_samples(refdir, name):
    """At an exact extraordinary corner OpenSubdiv's end cap interpolates the vertex limit: so do we.
    (Other end-cap samples are approximations by OpenSubdiv's own account; positions near
    extraordinary vertices are checked against brute-force subdivision in test_bruteforce.py.)"""
    d, mesh = _load(refdir, name)
    rows = [s for s in d["samples"] if s["endcap"] and s["tag"].startswith("corner")]
    assert rows, f"{name}: no end-cap corner samples in the reference file"
    S = _surface(refdir, name)
    out = S.evaluate([s["face"] for s in rows], [s["s"] for s in rows], [s["t"] for s in rows], 0)
    P = np.array([s["P"] for s in rows])
    assert np.abs(out["P"] - P).max() <= 1e-15 * mesh.bounding_box_diagonal


@pytest.mark.parametrize("name", MESHES)
def test_vertex_limits(refdir, name):
    d, mesh = _load(refdir, name)
    S = _surface(refdir, name)
    assert np.abs(S.vertex_limits() - np.array(d["vertex_limit"])).max() <= 1e-13
    # the surface passes through the vertex limits at the face corners
    F = mesh.faces
    f = np.repeat(np.arange(mesh.n_faces), 4)
    uv = np.tile(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float), (mesh.n_faces, 1))
    P = S.evaluate(f, uv[:, 0], uv[:, 1], 0)["P"]
    assert np.abs(P - np.array(d["vertex_limit"])[F.reshape(-1)]).max() <= 1e-13
