import random
from fractions import Fraction

import pytest

from ccproof.algebra.subdivision import (
    CENTER,
    stam_vertices,
    subdivision_matrix,
    two_ring_vertices,
)
from ccproof.errors import ValenceError

from ._bruteforce import cc_step, level1_value, ring_mesh


def _compare(k, ring):
    faces, vid = ring_mesh(k, 3)
    rng = random.Random(k)
    verts = set(v for f in faces for v in f)
    values = {v: Fraction(rng.randint(-1000, 1000), rng.randint(1, 50)) for v in verts}
    step = cc_step(faces, values, Fraction(0))
    ring_verts = two_ring_vertices(k) if ring == "two_ring" else stam_vertices(k)
    S = subdivision_matrix(k, ring)

    def key(v):
        return "c" if v == CENTER else v

    p0 = [values[key(v)] for v in ring_verts]
    for i, v in enumerate(ring_verts):
        got = sum((S[i][jj] * p0[jj] for jj in range(len(p0))), Fraction(0))
        if v == CENTER:
            want = step[2]["c"]
        else:
            want = level1_value(faces, vid, step, *v)
        assert got == want, (k, v)


@pytest.mark.parametrize("k", [3, 4, 5, 6, 7, 11])
def test_two_ring_matrix_equals_bruteforce_step(k):
    _compare(k, "two_ring")


@pytest.mark.parametrize("k", [3, 4, 5, 8])
def test_stam_matrix_equals_bruteforce_step(k):
    _compare(k, "stam")


def test_sizes_and_affine_invariance():
    for k in (3, 5, 9):
        S = subdivision_matrix(k)
        assert len(S) == 6 * k + 1
        assert all(sum(row) == 1 for row in S)
        assert len(subdivision_matrix(k, "stam")) == 2 * k + 8


@pytest.mark.parametrize("bad", [2, 0, -3, 3.5, float("nan"), "x", None, True])
def test_bad_valence(bad):
    with pytest.raises(ValenceError):
        subdivision_matrix(bad)


def test_unknown_ring():
    with pytest.raises(ValueError, match="unknown ring"):
        subdivision_matrix(5, "three_ring")
