"""The ``ccproof invert`` subcommand."""

import pytest

from ccproof.cli import main
from ccproof.inverse import characteristic_map


def _field(out, name):
    for line in out.splitlines():
        if line.strip().startswith(name):
            return line.strip()[len(name):].strip()
    raise AssertionError(f"{name!r} not in output:\n{out}")


def test_invert_point(capsys):
    x, y = characteristic_map(5, 0.7, 0.3)
    assert main(["invert", "5", repr(float(x)), repr(float(y))]) == 0
    out = capsys.readouterr().out
    assert float(_field(out, "preimage     r =")) == pytest.approx(0.7, abs=1e-15)
    assert float(_field(out, "s =")) == pytest.approx(0.3, abs=1e-15)
    assert _field(out, "piece") == "layer 0, P1"
    assert _field(out, "fallback") == "no"


def test_invert_rigorous_and_outside(capsys):
    assert main(["invert", "3", "2", "5", "--rigorous"]) == 0
    out = capsys.readouterr().out
    assert _field(out, "certified") == "yes"
    assert _field(out, "piece").startswith("layer -")
    assert main(["invert", "5", "0.95", "0.95", "--domain", "face"]) == 2
    assert "outside the image" in capsys.readouterr().err


@pytest.mark.parametrize("args", [["2", "0.1", "0.1"], ["5", "nan", "0.1"], ["5", "-1", "0.1"], ["5", "x", "0"]])
def test_invert_bad_input(args, capsys):
    assert main(["invert", *args]) == 2
    assert "error" in capsys.readouterr().err
