"""Templates and their disk cache.

A *template* is everything the classification does with a job whose ring has a given tagged key (and
frame): the tree of virtual faces (split, regular, corner) with their domains in the ptex face, the
operators of its regular patches and corner rings as linear functions of the ring's control points
(:class:`Template`; built by :class:`ccproof.evaluate.factory.Builder`, laid out by
:func:`ccproof.evaluate.patch_table.assemble`). Templates are kept between runs in the disk cache of
:func:`ccproof.evaluate.local.corner_scheme` (:func:`cached_template`).
"""

from __future__ import annotations

import copy
import functools
from array import array

import numpy as np

from ccproof.errors import MeshError
from ccproof.evaluate import _diskcache
from ccproof.evaluate.frames import domain
from ccproof.evaluate.local import code_version

#: the sources that define a template besides :func:`ccproof.evaluate.local.code_version`'s (their hash names
#: the cache files)
TEMPLATE_SOURCES = ("frames.py", "halfedge_views.py", "factory.py", "template_cache.py")


class Template:
    """Virtual faces and leaf operators of one configuration of a job (see the module docstring)."""

    def __init__(self, n):
        self.n = n  # ring size N
        self.kind, self.dom, self.child, self.leaf, self.pts, self.cfg, self.corner = [], [], [], [], [], [], []
        self.reg = []  # (17, N) per regular patch
        self.cor = []  # (Nc, N) per corner face: ring relative to its vertex (rows 1..), then the limit point
        self.cor_vertex = []  # ring position of each corner face's vertex (-1: a new point)
        self.schemes = []  # per configuration used (``cfg``: index here): (corner key, orientation)
        self.n_pts = 0
        self.jobs = array("q")
        self.rings = array("i")

    def new_vface(self, kind, frame):
        self.kind.append(kind)
        self.dom.append(domain(frame))
        self.child.append([-1, -1, -1, -1])
        self.leaf.append(-1)
        self.pts.append(0)
        self.cfg.append(-1)
        self.corner.append((0, 0))
        return len(self.kind) - 1

    def finish(self):
        """Freeze the operators: ``R`` (n_reg * 17, N), ``Q`` (n_pts, N), ``O`` (n_corner, N)."""
        N = self.n
        self.R = np.concatenate(self.reg).reshape(-1, N) if self.reg else np.zeros((0, N))
        self.Q = np.concatenate([c[:-1] for c in self.cor]) if self.cor else np.zeros((0, N))
        self.O = np.array([c[-1] for c in self.cor]).reshape(-1, N)
        for a in (self.R, self.Q, self.O):
            if not np.isfinite(a).all():  # pragma: no cover - would be a bug in the local refinement
                raise MeshError("internal error: a patch uses a point outside the exact local refinement")
        self.reg = self.cor = None


def finished(t):
    t.finish()
    return t


@functools.lru_cache(maxsize=1)
def _template_version():
    """Hash of the sources that define a template (:func:`code_version` and :data:`TEMPLATE_SOURCES`)."""
    import hashlib
    from pathlib import Path

    here = Path(__file__).parent
    return hashlib.sha256((code_version() + "|").encode() + b"".join(
        (here / name).read_bytes() for name in TEMPLATE_SOURCES)).hexdigest()[:16]


_TPL_MAGIC = 20261202.0  # first value of a template file (the format below)


def _template_bytes(t):
    """A finished template as bytes: one little-endian float64 vector ``[magic, N, n_pts, V, n_reg,
    n_cor, len(json)]``, then per virtual face ``kind``, ``dom`` (3), ``child`` (4), ``leaf``,
    ``pts``, ``cfg``, ``corner`` (2), then ``cor_vertex`` (n_cor), ``R`` (17 n_reg, N), ``Q``
    (n_pts, N), ``O`` (n_cor, N) (integers are exact in float64), then the JSON of the corner keys
    and orientations of its configurations (the file seals these bytes, :mod:`._diskcache`)."""
    import json

    V, N = len(t.kind), t.n
    js = json.dumps(t.schemes).encode()
    ints = np.array([t.kind, t.leaf, t.pts, t.cfg], dtype=np.float64).reshape(4, V)
    return np.concatenate([
        [_TPL_MAGIC, N, t.n_pts, V, t.R.shape[0] // 17, t.O.shape[0], len(js)],
        np.array(t.dom, dtype=np.float64).reshape(-1), np.array(t.child, dtype=np.float64).reshape(-1),
        ints.reshape(-1), np.array(t.corner, dtype=np.float64).reshape(-1),
        np.array(t.cor_vertex, dtype=np.float64), t.R.reshape(-1), t.Q.reshape(-1), t.O.reshape(-1),
    ]).astype("<f8").tobytes() + js


def _tuples(x):
    return tuple(_tuples(y) for y in x) if isinstance(x, list) else x


def read_template(path, name):
    """The template stored at ``path`` for the cache name ``name`` (:func:`_template_bytes`, sealed by
    :func:`ccproof.evaluate._diskcache.seal`); ValueError unless the file holds exactly what was
    written for that name (digest of name and content, magic, sizes)."""
    try:
        return _parse_template(_diskcache.unseal(path.read_bytes(), name))
    except ValueError as e:
        raise ValueError(f"{path}: {e}") from None


def _parse_template(body):
    import json

    body = bytes(body)
    if len(body) < 56:
        raise ValueError("too short for a template file")
    head = np.frombuffer(body, dtype="<f8", count=7)
    if head[0] != _TPL_MAGIC or not all(0 <= x < 2**40 and x == int(x) for x in head[1:]):
        raise ValueError("not a template file")
    N, n_pts, V, n_reg, n_cor, n_js = (int(x) for x in head[1:])
    n = 7 + 13 * V + n_cor + (17 * n_reg + n_pts + n_cor) * N
    if len(body) != 8 * n + n_js:
        raise ValueError("sizes do not match its header")
    z = np.frombuffer(body, dtype="<f8", count=n)
    o = 7

    def take(k):
        nonlocal o
        o += k
        return z[o - k:o]

    t = Template(N)
    t.dom = [tuple(d) for d in take(3 * V).reshape(V, 3).tolist()]
    t.child = take(4 * V).astype(np.int64).reshape(V, 4).tolist()
    t.kind, t.leaf, t.pts, t.cfg = take(4 * V).astype(np.int64).reshape(4, V).tolist()
    t.corner = [tuple(c) for c in take(2 * V).astype(np.int64).reshape(V, 2).tolist()]
    t.cor_vertex = take(n_cor).astype(np.int64).tolist()
    t.R = take(17 * n_reg * N).reshape(-1, N)
    t.Q = take(n_pts * N).reshape(-1, N)
    t.O = take(n_cor * N).reshape(-1, N)
    t.n_pts = n_pts
    t.schemes = [(_tuples(k), _tuples(o_)) for k, o_ in json.loads(body[8 * n:].decode())]
    t.reg = t.cor = None
    return t


def cached_template(tkey, depth_semi, make):
    """``make()`` finished (a :class:`Template`), kept between runs in the disk cache of
    :func:`ccproof.evaluate.local.corner_scheme` (same folder, ``CCPROOF_CACHE``).

    One file per template, ``SHA-256(key, depth_semi, sources).tpl`` (:func:`_template_bytes`: the
    virtual faces, the leaf operators ``R``, ``Q``, ``O``, the corner keys of its configurations),
    sealed by the SHA-256 of its name and content (:mod:`ccproof.evaluate._diskcache`), checked on
    read with the header's sizes; a missing, unreadable or corrupt file is rebuilt (exact local
    refinement, from corner schemes that were themselves verified) and rewritten atomically, a
    corrupt one reported once. A cached template is the built one bit for bit; with every file
    present a setup does no exact local step.
    """
    d = _diskcache.cache_dir()
    if d is None:
        return finished(make())
    name = _template_name(tkey, depth_semi)
    path = d / f"{name}.tpl"
    data = _read_bytes(path)
    seen = _PARSED.get(name)
    if data is not None and seen is not None and seen[0] == data:
        return _fresh(seen[1])  # the very bytes verified and parsed before in this process
    t = _diskcache.read_entry(path, name, _parse_template, data)
    if t is not None:
        _remember(name, data, t)
        return _fresh(t)
    t = finished(make())
    _diskcache.store(d, name, ".tpl", _template_bytes(t))
    return t


#: per (template key, depth_semi, template version): the template's cache name, those of recent setups in this
#: process (at most :data:`_NAMES_MAX`; cleared when full)
_NAMES: dict = {}
_NAMES_MAX = 1 << 14


def _template_name(tkey, depth_semi):
    """The cache name of the template ``tkey`` built with ``depth_semi``: SHA-256 of the template version, of
    ``depth_semi`` and of ``repr(tkey)`` (computed once per key in this process: the key's hash is cheaper)."""
    import hashlib

    version = _template_version()
    k = (tkey, depth_semi, version)
    name = _NAMES.get(k)
    if name is None:
        if len(_NAMES) >= _NAMES_MAX:
            _NAMES.clear()
        name = _NAMES[k] = hashlib.sha256(f"template|{version}|{depth_semi}|{tkey!r}".encode()).hexdigest()
    return name


def _read_bytes(path):
    """The bytes of the file ``path``, or None where it cannot be read (one open, fstat and read: a setup
    reads each of its templates' files, most of them a few kB, where the buffered reader's overhead counts)."""
    import os

    try:
        fd = os.open(path, os.O_RDONLY)
    except OSError:
        return None
    try:
        size = os.fstat(fd).st_size
        parts = [os.read(fd, size + 1)]
        while parts[-1]:  # (a file that grew meanwhile: read to its end)
            parts.append(os.read(fd, 1 << 20))
        return b"".join(parts)
    except OSError:
        return None
    finally:
        os.close(fd)


#: per cache name: (the file's bytes, the template parsed from them), the templates of recent setups in this
#: process (a setup reads the file again and takes this one only where its bytes are these, byte for byte),
#: within :data:`PARSED_BUDGET` bytes (twice the files': their bytes and the parsed arrays; the oldest dropped
#: first): the small meshes' setups, where these fixed costs count, keep theirs
_PARSED: dict = {}
PARSED_BUDGET = 8 << 20


def _remember(name, data, t):
    held = sum(2 * len(d) for d, _ in _PARSED.values())
    while _PARSED and held + 2 * len(data) > PARSED_BUDGET:
        held -= 2 * len(_PARSED.pop(next(iter(_PARSED)))[0])
    if 2 * len(data) <= PARSED_BUDGET:
        _PARSED[name] = (data, _fresh(t))


def forget_parsed():
    """Drop the templates this process keeps parsed (:func:`cached_template` parses their files again)."""
    _PARSED.clear()


def _fresh(t):
    """A copy of a parsed template for one builder (the read-only operators shared; its jobs, rings and
    configuration indices its own)."""
    new = copy.copy(t)
    new.jobs, new.rings = array("q"), array("i")
    return new
