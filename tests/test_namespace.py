"""``import ccproof`` exposes the same names as before its lazy table was written compactly: each public name
resolves to the object of its defining module, loaded on first use only."""

import importlib
import subprocess
import sys

import ccproof

#: the public names and their defining modules, written out here independently of ccproof/__init__.py
EXPECTED = {
    "CCProofError": "ccproof.errors", "MeshError": "ccproof.errors", "TableNotFoundError": "ccproof.errors",
    "ValenceError": "ccproof.errors", "Valence": "ccproof.valence", "parse_valence": "ccproof.valence",
    "load_table": "ccproof.tables.numeric", "build_table": "ccproof.tables.build",
    "prove_valence": "ccproof.certify.prover", "prove_interval": "ccproof.certify.prover",
    "prove_c1": "ccproof.certify.prover", "verify_file": "ccproof.certify.verify",
    "VerifyResult": "ccproof.certify.verify.record", "CertificateError": "ccproof.certify.verify.errors",
    "QuadMesh": "ccproof.mesh", "PolyMesh": "ccproof.mesh", "read_obj": "ccproof.mesh", "read_mesh": "ccproof.mesh",
    "limit_surface": "ccproof.reparam.surface", "LimitSurface": "ccproof.evaluate", "Parameterization":
    "ccproof.reparam", "PatchTable": "ccproof.evaluate", "characteristic_map": "ccproof.inverse.forward",
    "inverse_characteristic_map": "ccproof.inverse.algorithm", "parameterize": "ccproof.apps.arap.meshes",
    "write_uv_mesh": "ccproof.apps.arap.export", "fit_points": "ccproof.apps.dynamics.fit",
}


def test_the_public_names_are_those_of_their_modules():
    assert ccproof.__all__ == sorted(EXPECTED)
    for name, module in EXPECTED.items():
        assert getattr(ccproof, name) is getattr(importlib.import_module(module), name), name
    assert ccproof.__version__ == "0.1.0"


def test_importing_ccproof_loads_no_submodule():
    code = ("import sys, ccproof; print(sorted(m for m in sys.modules if m.startswith('ccproof')));"
            "print(sorted(n for n in dir(ccproof) if not n.startswith('_')))")
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout.split("\n")
    assert out[0] == "['ccproof']"
    assert out[1] == str(sorted({*EXPECTED, "TYPE_CHECKING", "import_module"}))
