"""ccproof: Catmull-Clark subdivision surfaces as certified parametric surfaces.

One entry point per capability (``ccproof.__all__``; every name has a docstring with an example, but
``prove_interval``, whose shortest run takes a minute; every function is annotated, docs/api.md):

==================================  ======================================================================
capability                          names
==================================  ======================================================================
valences (one k, or every k >= k0)  :class:`Valence` (parsed and printed in one place), ``parse_valence``
the table of a valence              :func:`load_table` (float64 view), :func:`build_table` (write side)
certify                             :func:`prove_valence`, :func:`prove_interval`, :func:`prove_c1`
verify (the trusted base)           :func:`verify_file` -> :class:`VerifyResult` (parts and reasons)
meshes                              :class:`QuadMesh`, :class:`PolyMesh`, :func:`read_obj`, :func:`read_mesh`
the limit surface of a mesh         :func:`limit_surface` -> :class:`LimitSurface` (evaluate, normals),
                                    :class:`Parameterization` (values), :class:`PatchTable` (its arrays)
the characteristic map, Phi^-1      :func:`characteristic_map`, :func:`inverse_characteristic_map`
ARAP texture parameterization       :func:`parameterize` (hsh10), :func:`write_uv_mesh` (for other tools)
fit a surface to points             :func:`fit_points` (qmv98)
errors                              :class:`CCProofError` and subclasses; the verifier's own :class:`CertificateError`
==================================  ======================================================================

Every name loads on first use (PEP 562): verifying loads nothing of ccproof outside the trusted base
(docs/trusted_base.md), and ``import ccproof`` takes 2 ms, not ~1 s (numpy, scipy, numba). Layers:
docs/architecture.md.

>>> import ccproof
>>> ccproof.Valence.parse(">=40"), ccproof.load_table(5).N
(Valence('>=40'), 3)
"""

from importlib import import_module
from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the lazy names of _LAZY below, seen by type checkers (mypy in .ci/run) as what they are
    from ccproof.apps.arap.export import write_uv_mesh
    from ccproof.apps.arap.meshes import parameterize
    from ccproof.apps.dynamics.fit import fit_points
    from ccproof.certify.prover import prove_c1, prove_interval, prove_valence
    from ccproof.certify.verify import verify_file
    from ccproof.certify.verify.errors import CertificateError
    from ccproof.certify.verify.record import VerifyResult
    from ccproof.errors import CCProofError, MeshError, TableNotFoundError, ValenceError
    from ccproof.evaluate import LimitSurface, PatchTable
    from ccproof.inverse.algorithm import inverse_characteristic_map
    from ccproof.inverse.forward import characteristic_map
    from ccproof.mesh import PolyMesh, QuadMesh, read_mesh, read_obj
    from ccproof.reparam.surface import Parameterization, limit_surface
    from ccproof.tables.build import build_table
    from ccproof.tables.numeric import load_table
    from ccproof.valence import Valence, parse_valence

__version__ = "0.1.0"

#: lazily loaded public names -> defining module
_LAZY = {name: module for module, names in {
    "ccproof.errors": "CCProofError MeshError TableNotFoundError ValenceError",
    "ccproof.valence": "Valence parse_valence",
    "ccproof.tables.numeric": "load_table",
    "ccproof.tables.build": "build_table",
    "ccproof.certify.prover": "prove_valence prove_interval prove_c1",
    "ccproof.certify.verify": "verify_file",
    "ccproof.certify.verify.record": "VerifyResult",
    "ccproof.certify.verify.errors": "CertificateError",
    "ccproof.mesh": "QuadMesh PolyMesh read_obj read_mesh",
    "ccproof.reparam.surface": "limit_surface",
    "ccproof.evaluate": "LimitSurface PatchTable",
    "ccproof.reparam": "Parameterization",
    "ccproof.inverse.forward": "characteristic_map",
    "ccproof.inverse.algorithm": "inverse_characteristic_map",
    "ccproof.apps.arap.meshes": "parameterize",
    "ccproof.apps.arap.export": "write_uv_mesh",
    "ccproof.apps.dynamics.fit": "fit_points",
}.items() for name in names.split()}

__all__ = ["CCProofError", "CertificateError", "LimitSurface", "MeshError", "Parameterization", "PatchTable",
           "PolyMesh", "QuadMesh", "TableNotFoundError", "Valence", "ValenceError", "VerifyResult", "build_table",
           "characteristic_map", "fit_points", "inverse_characteristic_map", "limit_surface", "load_table",
           "parameterize", "parse_valence", "prove_c1", "prove_interval", "prove_valence", "read_mesh", "read_obj",
           "verify_file", "write_uv_mesh"]

assert set(__all__) == set(_LAZY)


def __getattr__(name: str) -> object:
    if name in _LAZY:
        value = getattr(import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'ccproof' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
