"""The O(N) derivation for crease and corner sectors (ccproof.certify.verify.tagged_modes): its spectrum
against numpy on the library's independent Sdc stencils and against the exact characteristic polynomial,
its closed-form eigenvectors against the exact route's bordered solve, and forgeries of each new claim."""

import copy
import json

import numpy as np
import pytest
from flint import arb, arb_mat, ctx, fmpq

from ccproof.certify.verify import tagged_modes as tm
from ccproof.certify.verify import verify_certificate
from ccproof.certify.verify.errors import CertificateError
from ccproof.certify.verify.tagged import crease_points, eigenvalues, sector_matrix
from ccproof.tables.format import certificates_dir

from .test_tagged import library_matrix

QUIET = {"log": lambda line: None}


def _floats(ev):
    return np.sort_complex(np.array([complex(float(t[0].real.mid()), float(t[0].imag.mid())) for t in ev]).round(6))


@pytest.mark.parametrize("fam,n", [("crease", 5), ("crease", 8), ("corner", 6), ("corner", 45), ("crease", 61)])
def test_mode_spectrum_equals_numpy_on_the_library_matrix(fam, n):
    """Independent: numpy's eigenvalues of the sector matrix read from the library's Sdc stencils."""
    with ctx.workprec(128):
        ours = _floats(tm.mode_spectrum(fam, n))
    num = np.sort_complex(np.linalg.eigvals(library_matrix(fam, n)).round(6))
    assert len(ours) == len(num) == 6 * n + 3
    # defective 1/2, 1/8 (Jordan blocks) move by ~sqrt(eps) in floats; every distinct pair is 1e-5 apart
    assert np.max(np.abs(ours - num)) < 1e-5


@pytest.mark.parametrize("fam,n", [("crease", 7), ("corner", 12)])
def test_mode_spectrum_equals_the_exact_characteristic_polynomial(fam, n):
    with ctx.workprec(128):
        ours = _floats(tm.mode_spectrum(fam, n))
        exact = _floats(eigenvalues(fam, n, 128))
    assert np.array_equal(ours, exact)


@pytest.mark.parametrize("fam,n,j", [("crease", 7, 1), ("corner", 9, 2), ("crease", 12, 3)])
def test_mode_vector_equals_the_bordered_solve_of_the_whole_matrix(fam, n, j):
    """The closed form f = v - v o R against the eigenvector the exact route solves on all 6N - 2 points."""
    with ctx.workprec(128):
        lam = max(t[0].real for t in tm.mode_spectrum(fam, n) if t[3] == j)
        f = tm.mode_vector(fam, n, j, lam)
        S, cp = sector_matrix(fam, n), crease_points(fam, n)
        free = [i for i in range(S.nrows()) if i not in cp]
        for pv in sorted(free, key=lambda i: -float(abs(f[i]).mid())):
            try:
                sol = tm.bordered_solve([[arb(S[i, j]) for j in free] for i in free], lam, free.index(pv), arb_mat)
                break
            except ZeroDivisionError:
                continue
        for k, i in enumerate(free):
            g = f[i] / f[pv]
            assert g.imag.contains(0) and float(abs(g.imag).upper()) < 1e-30
            assert abs(float((g.real - sol[k]).mid())) < 1e-30


def test_structure_check_fails_on_a_changed_rule(monkeypatch):
    """A sector whose rows are not the folded ring rule (one weight moved) is refused, as is a stencil
    that does not commute with the reflection."""
    rows = list(tm.sector_rows("crease", 9))
    i = 30  # a quadrant point
    row = dict(rows[i])
    a, b = [k for k in sorted(row) if k not in crease_points("crease", 9)][:2]
    row[a], row[b] = row[a] + fmpq(1, 64), row[b] - fmpq(1, 64)
    rows[i] = row
    monkeypatch.setattr(tm, "sector_rows", lambda fam, n: tuple(rows))
    tm.check_structure.cache_clear()
    with pytest.raises(CertificateError, match="not the folded ring rule"):
        tm.check_structure("crease", 9)
    monkeypatch.undo()
    tm.check_structure.cache_clear()
    stencil = [dict(r) for r in tm.ring_stencil()]
    key = next(iter(stencil[3]))
    stencil[3][key] += fmpq(1, 32)
    monkeypatch.setattr(tm, "ring_stencil", lambda: tuple(stencil))
    tm.check_ring.cache_clear()
    with pytest.raises(CertificateError, match="reflection|characteristic polynomial"):
        tm.check_ring()
    monkeypatch.undo()
    tm.check_ring.cache_clear()
    assert tm.check_ring() and tm.check_structure("crease", 9)


def _cert(name):
    fam, n = name.split(":")
    return json.loads((certificates_dir() / "c1" / fam / f"n{int(n):03d}.json").read_text())


def _fails(cert, why):
    res = verify_certificate(cert, **QUIET)
    assert not res
    text = (res.error or "") + " ".join(p.name + ": " + p.message for p in res.failures())
    assert why in text, text


def test_published_certificates_up_to_100_verify():
    for name in ("crease:41", "crease:77", "crease:100", "corner:41", "corner:100"):
        assert verify_certificate(_cert(name), **QUIET), name
    for k in (41, 100):
        assert verify_certificate(_dart(k), **QUIET), k


def test_forgery_relabelled_configuration():
    """Relabelled to a C1 configuration (old route, exact spectrum) or to a far N. (A neighbouring N may
    accept the same witness: its intervals and pivots can fit there too, and then it proves that N.)"""
    _fails(dict(_cert("crease:100"), configuration="crease:3"), "does not isolate")
    _fails(dict(_cert("corner:100"), configuration="corner:1"), "does not isolate")
    _fails(dict(_cert("crease:41"), configuration="crease:90"), "does not isolate")
    _fails(dict(_cert("corner:90"), configuration="corner:41"), "does not isolate")


def test_forgery_x_and_y_swapped_or_the_same():
    cert = copy.deepcopy(_cert("crease:60"))
    w = cert["witness"]
    w["x"], w["y"] = w["y"], w["x"]
    _fails(cert, "alpha >= beta is not certain")
    cert = copy.deepcopy(_cert("crease:60"))
    cert["witness"]["y"] = cert["witness"]["x"]
    _fails(cert, "the same eigenvector")


def test_forgery_lower_mode_root_as_beta():
    """y the eigenvector of lam(cos(3 pi/N)) (a true simple eigenvalue, closed form fine): the net is
    degenerate (lam2's coefficient 0), part G refuses it."""
    cert = copy.deepcopy(_cert("crease:50"))
    with ctx.workprec(128):
        ev = tm.mode_spectrum("crease", 50)
        third = next(t[0].real for t in ev if t[3] == 3 and t[0].real > fmpq(1, 2))
    lo, hi = (third - fmpq(1, 10**6)).mid(), (third + fmpq(1, 10**6)).mid()
    cert["witness"]["y"]["eigenvalue"] = [lo.str(30, radius=False), hi.str(30, radius=False)]
    _fails(cert, "not certainly below beta")


def test_forgery_rational_or_small_root_as_x():
    """An interval around 1/8 (a constant of every mode, not a single mode's root) or around the small
    root 1/(16 lam) is refused: the first is no simple mode root, the second is not lam1."""
    cert = copy.deepcopy(_cert("corner:50"))
    cert["witness"]["x"]["eigenvalue"] = ["0.12", "0.13"]
    _fails(cert, "does not isolate")
    with ctx.workprec(128):
        ev = tm.mode_spectrum("corner", 50)
        small = [t[0].real for t in ev if t[3] == 1 and t[0].real < fmpq(1, 2)][0]
    cert["witness"]["x"]["eigenvalue"] = [(small - fmpq(1, 10**9)).mid().str(30, radius=False),
                                          (small + fmpq(1, 10**9)).mid().str(30, radius=False)]
    _fails(cert, "G generic")


def test_forgery_pivot_on_a_zero_of_the_eigenvector():
    """Mode 2 of crease:40 vanishes on ray 20 (sin(2 pi 20/40) = 0): normalizing there proves nothing."""
    cert = copy.deepcopy(_cert("crease:40"))
    from ccproof.certify.verify.tagged import labels

    cert["witness"]["y"]["pivot"] = labels("crease", 40).index(("r", 20, 1, 0))
    _fails(cert, "not certainly non-zero at the pivot")
    cert["witness"]["y"]["pivot"] = 0
    _fails(cert, "pivot must index a non-crease point")


def test_forgery_z_not_the_crease_tangent():
    cert = copy.deepcopy(_cert("crease:70"))
    cert["witness"]["z"] = {"eigenvalue": "0.25", "crease": ["-1", "2", "11", "2", "11"]}  # C's 1/4 vector
    _fails(cert, "gamma is not the crease block's largest")
    cert["witness"]["z"] = {"eigenvalue": "0.125", "crease": ["0", "0", "1", "0", "0"]}  # C's 1/8 vector
    _fails(cert, "1/8 is possibly a multiple eigenvalue of I")  # its generalized z need not exist
    cert["witness"]["z"] = {"eigenvalue": "0.5", "crease": ["0", "-0.5", "-1", "0.5", "0.5"]}
    _fails(cert, "no eigenvector for 1/2")
    cert["witness"]["z"] = {"eigenvalue": "0.5", "crease": ["0", "0", "0", "0", "0"]}
    _fails(cert, "no eigenvector for 1/2")


# ----------------------------------------------------------------------- darts: odd half by modes, even half exact
def _dart_against(k, reference):
    """The enclosed entries of a dart's mode spectrum are eigenvalues of ``reference`` (greedy matching,
    1e-5), and every eigenvalue left over lies in the bound the outer block's entries claim."""
    with ctx.workprec(128):
        ev = tm.mode_spectrum("dart", k)
    bound = tm.check_dart(k)[5]
    known = [complex(float(t[0].real.mid()), float(t[0].imag.mid())) for t in ev if t[0].real.rad() < 1e-20]
    left = list(reference)
    assert len(ev) == len(left) == 6 * k + 1
    for z in known:
        i = int(np.argmin([abs(z - w) for w in left]))
        assert abs(z - left[i]) < 1e-5, (z, left[i])
        left.pop(i)
    assert len(left) == len(ev) - len(known) and all(abs(w) <= float(bound) + 1e-9 for w in left)


@pytest.mark.parametrize("k", [5, 8, 45])
def test_dart_mode_spectrum_equals_numpy_on_the_library_matrix(k):
    _dart_against(k, np.linalg.eigvals(library_matrix("dart", k)))


@pytest.mark.parametrize("k", [6, 9])
def test_dart_mode_spectrum_equals_the_exact_characteristic_polynomial(k):
    with ctx.workprec(128):
        exact = [complex(float(t[0].real.mid()), float(t[0].imag.mid())) for t in eigenvalues("dart", k, 128)]
    _dart_against(k, exact)


@pytest.mark.parametrize("k", [7, 12])
def test_dart_vectors_equal_the_exact_route(k):
    """x (odd, closed form) and y (even, from S_E) against the whole matrix's bordered solve."""
    from ccproof.certify.verify.tagged import labels

    with ctx.workprec(128):
        ev = tm.mode_spectrum("dart", k)
        rest = sorted((i for i, t in enumerate(ev) if abs(t[0]) < 1), key=lambda i: -float(abs(ev[i][0]).mid()))
        S = sector_matrix("dart", k)
        free = list(range(S.nrows()))
        for i in rest[:2]:
            lam = ev[i][0].real
            pv = labels("dart", k).index(("q", 1, 1, 1))
            if ev[i][3] is not None:
                f = tm.mode_vector("dart", k, ev[i][3], lam)
                ours = [v / f[pv] if not isinstance(v, fmpq) else v for v in f]
                ours = [v.real if not isinstance(v, fmpq) else v for v in ours]
            else:
                ours = tm.even_vector(k, lam, pv)
            ref = tm.bordered_solve([[arb(S[i, j]) for j in free] for i in free], lam, pv, arb_mat)
            assert max(abs(float((ref[j] - ours[j]).mid())) for j in free) < 1e-30


def test_dart_structure_check_fails_on_a_changed_rule(monkeypatch):
    """A rule that breaks the reflection symmetry (one weight moved on one side) is refused."""
    rows = list(tm.sector_rows("dart", 7))
    i = 30
    row = dict(rows[i])
    a, b = sorted(row)[:2]
    row[a], row[b] = row[a] + fmpq(1, 64), row[b] - fmpq(1, 64)
    rows[i] = row
    monkeypatch.setattr(tm, "sector_rows", lambda fam, n: tuple(rows))
    tm.check_dart.cache_clear()
    with pytest.raises(CertificateError, match="reflection"):
        tm.check_dart(7)
    monkeypatch.undo()
    tm.check_dart.cache_clear()
    assert tm.check_dart(7)


def _dart(k):
    return json.loads((certificates_dir() / "c1" / "dart" / f"k{k:03d}.json").read_text())


def test_dart_forgeries():
    cert = _dart(40)
    assert verify_certificate(cert, **QUIET)
    _fails(dict(cert, configuration="dart:20"), "does not isolate lam")
    forged = copy.deepcopy(cert)
    forged["map"]["x"], forged["map"]["y"] = forged["map"]["y"], forged["map"]["x"]
    _fails(forged, "not the eigenvalue of lam1 / lam2")
    forged = copy.deepcopy(cert)
    forged["map"]["x"]["pivot"] = 0  # the centre: the odd vector vanishes there
    _fails(forged, "not certainly non-zero at the pivot")
    forged = copy.deepcopy(cert)
    forged["map"]["orientation"] = -forged["map"]["orientation"]
    _fails(forged, "regularity")
    forged = copy.deepcopy(cert)
    forged["map"]["y"]["crease"] = ["0"]
    _fails(forged, "crease []")
