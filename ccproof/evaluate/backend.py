"""The one place that chooses an evaluation backend: the C kernel, numba, or numpy.

Three backends compute the same sums in the same order (the same bits), one file each:

* ``"c"``: :mod:`ccproof.evaluate._ckernel` (the extension built from ``_clib.c`` at install);
* ``"numba"``: :mod:`ccproof.evaluate._numba_kernel` (compiled on first use, cached on disk);
* ``"numpy"``: :mod:`ccproof.evaluate._numpy_kernel` (the reference the tests compare with).

Each serves the same three jobs: evaluate points (:func:`evaluation_kernel`, :func:`evaluation_blocks`), walk rings
(:func:`compiled_ring_walk`; numpy's is the Python walk of :class:`ccproof.evaluate.factory.Builder`) and the closest
points' Newton descent (:func:`newton_kernel`; the C backend uses numba's). The choice: the ``backend``
argument, else the environment variable ``CCPROOF_BACKEND``, else the first of :func:`available_backends`.

>>> backend_name("numpy"), evaluation_kernel("numpy")
('numpy', ('numpy', None))
"""

from __future__ import annotations

import os
import sys

from ccproof.errors import CCProofError

__all__ = ["available_backends", "backend_name", "compiled_ring_walk", "evaluation_blocks", "evaluation_kernel",
           "newton_kernel"]

#: the names ``backend=`` takes (``"auto"``: the first available)
BACKENDS = ("auto", "c", "numba", "numpy")
#: the outputs of an evaluation, in the order the kernels take them
OUTPUTS = ("P", "Pu", "Pv", "Puu", "Puv", "Pvv")
#: jobs from which the numba ring walk pays for loading numba and its cached kernel (~1 to 1.5 s in a
#: fresh process, against ~0.15 ms per job for the Python walk); below, the Python walk, unless the
#: numba kernels are loaded already. The C kernel's walk (loaded in milliseconds) is taken at any size.
COMPILED_WALK_MIN = 8192


def available_backends():
    """The evaluation backends this install can run, in the order the automatic choice takes them.

    ``"c"`` where the install built the C kernel (``ccproof/evaluate/_clib.c``), ``"numba"`` where numba
    is installed (not imported here), and always ``"numpy"`` (the reference the tests compare with).

    Returns
    -------
    list of str

    Examples
    --------
    >>> available_backends()[-1]
    'numpy'
    """
    import importlib.util

    from ccproof.evaluate._ckernel import load

    return (["c"] if load() is not None else []) + \
        (["numba"] if importlib.util.find_spec("numba") is not None else []) + ["numpy"]


def backend_name(backend):
    """``backend`` (None: ``CCPROOF_BACKEND``, else ``"auto"``) checked against :data:`BACKENDS`."""
    if backend is None:
        backend = os.environ.get("CCPROOF_BACKEND", "auto")
    if backend not in BACKENDS:
        raise CCProofError(f"unknown backend {backend!r} (use 'c', 'numba' or 'numpy')")
    return backend


def evaluation_kernel(backend):
    """``(name, kernel)`` for ``backend`` (None: automatic): ``("c", library)`` (the C kernel, where it was
    built: :mod:`ccproof.evaluate._ckernel`), ``("numba", evaluate_points)``, or ``("numpy", None)``.
    The automatic choice takes them in that order; imports numba only when the C kernel is missing."""
    backend = backend_name(backend)
    if backend == "numpy":
        return "numpy", None
    if backend in ("auto", "c"):
        from ccproof.evaluate._ckernel import load

        lib = load()
        if lib is not None:
            return "c", lib
        if backend == "c":
            raise CCProofError("backend 'c' requested but the C kernel was not built (reinstall with a C compiler, "
                               "or run `python setup.py build_ext --inplace` in a checkout)")
    kernel = _numba("numba" if backend == "numba" else "auto", "evaluate_points")
    return ("numba", kernel) if kernel is not None else ("numpy", None)


def newton_kernel(backend):
    """The compiled Newton descent of the closest points (numba's ``newton_points``, with any backend but
    numpy: the C kernel has none), or None: the numpy descent."""
    return _numba(backend_name(backend), "newton_points")


def _numba(backend, name):
    """The numba kernel ``name`` of :mod:`ccproof.evaluate._numba_kernel` for ``backend`` (checked), or None
    for the numpy path (also when numba is not installed and the backend is automatic)."""
    if backend == "numpy":
        return None
    from ccproof.evaluate import _numba_kernel

    kernel = getattr(_numba_kernel, name)
    if kernel is None and backend == "numba":
        raise CCProofError("backend 'numba' requested but numba is not installed")
    return kernel


def evaluation_blocks(name, kernel, tables, f, u, v, derivatives, out, order=None):
    """``(block, back)``: ``block(lo, hi)`` evaluates the points lo:hi into ``out`` (a dict of (n, 3) arrays by
    :data:`OUTPUTS` name) by the compiled kernel ``(name, kernel)`` of :func:`evaluation_kernel` and returns -1
    or the first point it refuses; ``back``: ``[(name, temporary)]`` to copy into ``out`` after the blocks (the
    outputs a kernel cannot write in place). ``tables(name)``: the patch table as that backend reads it.
    ``order`` (the C kernel only): a permutation of the points; ``block(lo, hi)`` then evaluates the points
    ``order[lo:hi]``, in that order, each into its own row."""
    if name == "c":
        from ccproof.evaluate._ckernel import point_blocks as blocks
    else:
        if order is not None:
            raise CCProofError(f"internal error: the {name} kernel takes the points in their own order")
        from ccproof.evaluate._numba_kernel import point_blocks as blocks
    if order is not None:
        block, back = blocks(kernel, tables(name), f, u, v, derivatives, [out.get(k) for k in OUTPUTS], order)
        return block, [(OUTPUTS[i], a) for i, a in back]
    block, back = blocks(kernel, tables(name), f, u, v, derivatives, [out.get(k) for k in OUTPUTS])
    return block, [(OUTPUTS[i], a) for i, a in back]


def compiled_ring_walk(n_jobs):
    """The compiled ring walk for ``n_jobs`` rings: the C kernel's where the install built it (no numba
    import), else numba's, or None: the Python walk (neither installed, or fewer than
    :data:`COMPILED_WALK_MIN` jobs in a process that has not loaded the numba kernels)."""
    from ccproof.evaluate import _ckernel

    if _ckernel.load() is not None:
        return _ckernel.ring_walks
    if n_jobs < COMPILED_WALK_MIN and "ccproof.evaluate._numba_kernel" not in sys.modules:
        return None
    from ccproof.evaluate._numba_kernel import ring_walks as walks

    return walks
