"""Static checks of the rigorous layer's source: no float, no global precision change."""

import io
import pathlib
import tokenize

import pytest

import ccproof.rigorous

SOURCES = sorted(pathlib.Path(ccproof.rigorous.__file__).parent.glob("*.py"))


def _is_float_literal(text):
    t = text.lower().replace("_", "")
    if t.startswith(("0x", "0o", "0b")):
        return False
    return "." in t or "e" in t or t.endswith("j")


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_no_float_literals_or_calls(path):
    src = path.read_text()
    toks = list(tokenize.generate_tokens(io.StringIO(src).readline))
    for tok in toks:
        if tok.type == tokenize.NUMBER:
            assert not _is_float_literal(tok.string), (
                f"{path.name}:{tok.start[0]} float literal {tok.string}"
            )
        if tok.type == tokenize.NAME:
            assert tok.string not in {"float", "numpy", "np", "mpmath"}, (
                f"{path.name}:{tok.start[0]} {tok.string}"
            )
    code = "".join(t.string for t in toks if t.type not in (tokenize.COMMENT, tokenize.STRING))
    assert "ctx.prec=" not in code.replace(" ", ""), f"{path.name} sets the global flint precision"
    assert "ctx.dps=" not in code.replace(" ", ""), f"{path.name} sets the global flint precision"


def test_scan_sees_the_files():
    names = {p.name for p in SOURCES}
    assert {"__init__.py", "bernstein.py", "tensor.py"} <= names
    assert _is_float_literal("1.5") and _is_float_literal("1e3") and not _is_float_literal("0xE")
