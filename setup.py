"""Build hook: the wheel ships the published certificates as package data.

The top-level ``certificates/`` folder (tables, injectivity and C1 certificates) is the source of
truth in the repository. A built wheel (``pip install .``, ``pip wheel .``, ``python -m build``)
carries a copy of it as ``ccproof/_certificates``, which ``ccproof.tables.format.certificates_dir``
uses when the package does not run from a checkout. An editable install reads the repository
folder directly and copies nothing. Everything else is configured in ``pyproject.toml``.
"""

import shutil
from pathlib import Path

from setuptools import setup
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


setup(cmdclass={"build_py": BuildPyWithCertificates})
