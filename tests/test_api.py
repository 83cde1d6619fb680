"""The public namespace ``ccproof``: every name resolves and is documented with an example, and one
name means one thing across the whole package."""

import collections
import importlib
import inspect
import pkgutil
import subprocess
import sys

import pytest

import ccproof

#: names of ccproof.__all__ whose docstrings have no example (no call is fast enough to run as a doctest);
#: the test fails as soon as one gains an example (then drop it here) or another one lacks it
PENDING_EXAMPLES: dict[str, str] = {}

#: public functions of ccproof.__all__ whose signatures are not annotated yet, in modules owned elsewhere
#: (mypy checks the rest of the public API in .ci/run: [tool.mypy] in pyproject.toml)
PENDING_ANNOTATIONS: dict[str, str] = {}

#: public names defined more than once on purpose (or pending a module being rewritten elsewhere)
ALLOWED_DUPLICATES = {
    # the trusted verifier re-implements what it checks, importing nothing of the package (docs/trusted_base.md)
    "bspline_to_bezier": "the verifier's own copy (ccproof.certify.verify.statement)",
    "canonical": "the verifier's own copy (ccproof.certify.verify.rules)",
    # the command protocol of the cli modules: every command module has add_arguments / run
    "add_arguments": "one per command module",
    "run": "one per command module",
    # the evaluation backends' interface: one per compiled backend module (ccproof.evaluate._ckernel, _numba_kernel)
    "point_blocks": "one per compiled backend module",
    # pending: modules other engineers are rewriting
}


def test_all_is_sorted_unique_and_resolves():
    assert ccproof.__all__ == sorted(set(ccproof.__all__))
    for name in ccproof.__all__:
        obj = getattr(ccproof, name)
        assert obj is not None, name
        assert name in dir(ccproof)
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        ccproof.nope  # noqa: B018


def test_every_public_name_has_a_docstring_with_an_example():
    missing = set()
    for name in ccproof.__all__:
        doc = inspect.getdoc(getattr(ccproof, name)) or ""
        assert doc.strip(), f"ccproof.{name} has no docstring"
        if ">>>" not in doc:
            missing.add(name)
    assert missing == set(PENDING_EXAMPLES), (
        f"lacking an example and not listed: {sorted(missing - set(PENDING_EXAMPLES))}; "
        f"listed but documented now (drop them from PENDING_EXAMPLES): {sorted(set(PENDING_EXAMPLES) - missing)}")


def test_every_public_function_is_annotated():
    """Every parameter and the return of every function of ``ccproof.__all__`` carry a type annotation
    (what mypy then checks: the annotations of an unannotated function would be silently Any)."""
    missing = {}
    for name in ccproof.__all__:
        obj = getattr(ccproof, name)
        if not inspect.isfunction(obj):
            continue
        sig = inspect.signature(obj)
        bare = [p for p, par in sig.parameters.items() if par.annotation is inspect.Parameter.empty]
        if sig.return_annotation is inspect.Signature.empty:
            bare.append("return")
        if bare:
            missing[name] = bare
    pending = set(PENDING_ANNOTATIONS)
    assert set(missing) == pending, (
        f"not annotated and not listed: {sorted(set(missing) - pending)}; "
        f"listed but annotated now (drop them from PENDING_ANNOTATIONS): {sorted(pending - set(missing))}")


def test_headline_entry_points_are_the_package_objects():
    from ccproof.certify.prover import prove_valence
    from ccproof.certify.verify import verify_file
    from ccproof.inverse import inverse_characteristic_map
    from ccproof.reparam import limit_surface

    assert ccproof.prove_valence is prove_valence and ccproof.verify_file is verify_file
    assert ccproof.limit_surface is limit_surface
    assert ccproof.inverse_characteristic_map is inverse_characteristic_map


def _public_definitions():
    """{name: {qualified name: module}} over every module of the package: functions and classes listed in the
    module's ``__all__`` (or not starting with ``_``), defined in ccproof, under their own name
    (``obj.__name__ == name``; a kept former name such as ``evaluate.limit_surface`` is an alias)."""
    defs = collections.defaultdict(dict)
    for info in pkgutil.walk_packages(ccproof.__path__, "ccproof."):
        mod = importlib.import_module(info.name)
        names = getattr(mod, "__all__", None) or [n for n in vars(mod) if not n.startswith("_")]
        for n in names:
            obj = getattr(mod, n, None)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)):
                continue
            if not getattr(obj, "__module__", "").startswith("ccproof") or obj.__name__ != n:
                continue
            defs[n][f"{obj.__module__}.{obj.__qualname__}"] = obj.__module__  # a re-import is the same definition
    return defs


def test_one_name_one_object():
    defs = _public_definitions()
    assert {"limit_surface", "inverse_characteristic_map", "ring_subdivision_matrix"} <= set(defs)
    clashes = {n: sorted(d.values()) for n, d in defs.items() if len(d) > 1 and n not in ALLOWED_DUPLICATES}
    assert clashes == {}
    stale = {n for n in ALLOWED_DUPLICATES if len(defs.get(n, {})) < 2}
    assert stale == set(), f"no longer duplicated: drop from ALLOWED_DUPLICATES: {sorted(stale)}"


def test_former_names_are_aliases_of_the_one_concept():
    from ccproof.algebra import subdivision
    from ccproof.evaluate import limit_surface, natural_limit_surface

    assert limit_surface is natural_limit_surface
    assert subdivision.subdivision_matrix is subdivision.ring_subdivision_matrix
    import ccproof.errors

    assert not hasattr(ccproof.errors, "CertificateError")  # the verifier's is the only one


def test_import_is_cheap():
    code = "import sys, ccproof; print(sorted(m for m in ('numpy', 'sympy', 'scipy', 'flint') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "[]"
