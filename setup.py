"""Build hooks: the wheel ships the published certificates as package data, and the C evaluation kernel.

The top-level ``certificates/`` folder (tables, injectivity and C1 certificates) is the source of
truth in the repository. A built wheel (``pip install .``, ``pip wheel .``, ``python -m build``)
carries a copy of it as ``ccproof/_certificates``, which ``ccproof.tables.format.certificates_dir``
uses when the package does not run from a checkout. An editable install reads the repository
folder directly and copies nothing.

The C evaluation kernel ``ccproof/evaluate/_clib.c`` is built as the optional extension
``ccproof.evaluate._clib`` (a plain shared library loaded with ctypes by ``ccproof/evaluate/_ckernel.py``):
``pip install .``, ``pip install -e .``, ``pip wheel .`` and ``python setup.py build_ext --inplace`` build it;
without a compiler the build skips it (``optional=True``) and evaluation falls back to the numba kernel.
It is compiled without floating-point contraction (``-ffp-contract=off``: no FMA) so that it computes the
same bits as the numba and numpy backends. Everything else is configured in ``pyproject.toml``.
"""

import shutil
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext
from setuptools.command.build_py import build_py

ROOT = Path(__file__).resolve().parent
PARTS = ("tables", "injectivity", "c1")


class BuildPyWithCertificates(build_py):
    """``build_py`` that also copies ``certificates/{tables,injectivity,c1}/**/*.json`` into the build."""

    def run(self):
        super().run()
        if getattr(self, "editable_mode", False):
            return
        src = ROOT / "certificates"
        missing = [p for p in PARTS if not (src / p).is_dir()]
        if missing:
            raise SystemExit(f"cannot build ccproof: {src} lacks {', '.join(missing)} (the published certificates)")
        dst = Path(self.build_lib) / "ccproof" / "_certificates"
        if dst.exists():
            shutil.rmtree(dst)
        for part in PARTS:
            (dst / part).mkdir(parents=True)
            for f in sorted((src / part).rglob("*.json")):  # c1/ has one folder per tagged family
                (dst / part / f.relative_to(src / part)).parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(f, dst / part / f.relative_to(src / part))


class BuildExtC(build_ext):
    """``build_ext`` with the C kernel's flags for the compiler at hand (gcc/clang: C99, -O3, no contraction)."""

    def build_extensions(self):
        unix = self.compiler.compiler_type in ("unix", "mingw32", "cygwin")
        for ext in self.extensions:
            if unix:
                ext.extra_compile_args = ["-std=c99", "-O3", "-ffp-contract=off", "-fno-math-errno", "-Wno-psabi"]
            else:  # MSVC: strict floating point keeps the order of the sums
                ext.extra_compile_args = ["/O2", "/fp:strict"]
                ext.define_macros = [*ext.define_macros, ("CCP_NO_CLONES", "1")]
        super().build_extensions()


setup(
    cmdclass={"build_py": BuildPyWithCertificates, "build_ext": BuildExtC},
    ext_modules=[Extension("ccproof.evaluate._clib", ["ccproof/evaluate/_clib.c"], optional=True,
                           define_macros=[("CCP_PYTHON_MODULE", "1")])],
)
