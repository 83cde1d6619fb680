"""Invert the characteristic map of valence K at the point (U, V) (bmz04 Algorithm 1).

Prints the preimage (r, s) = Phi^-1(U, V) in the face parameter, the layer n (the preimage lies in
2^-n times layer 0; n < 0 outside the face [0,1]^2, where Phi is extended by its scaling
relation), the polynomial piece P1, P2 or P3, whether the guaranteed fallback (Bezier-hull
subdivision) was needed, and the round-trip error |Phi(r, s) - (U, V)|. With --rigorous the
preimage is also certified in arb (Krawczyk interval Newton) and the enclosing box is printed.

Examples:
  ccproof invert 5 0.3 0.2
  ccproof invert 3 1 0 --rigorous
"""

from __future__ import annotations

#: --prec range: below 2 bits arb has no numbers; above 4096 a certification takes minutes for nothing
MIN_PREC, MAX_PREC = 2, 4096


def add_arguments(parser):
    parser.add_argument("K", help="valence (integer >= 3)")
    parser.add_argument("U", help="first coordinate of the point (>= 0)")
    parser.add_argument("V", help="second coordinate of the point (>= 0)")
    parser.add_argument("--domain", choices=("quadrant", "face"), default="quadrant",
                        help="'face': refuse points outside Phi([0,1]^2) (default: quadrant)")
    parser.add_argument("--rigorous", action="store_true", help="certify the preimage with arb")
    parser.add_argument("--prec", type=int, default=128,
                        help=f"arb precision in bits (--rigorous; default 128, {MIN_PREC}..{MAX_PREC})")


def _number(text, name):
    from ccproof.errors import CCProofError

    try:
        return float(text)
    except ValueError:
        raise CCProofError(f"{name} must be a real number, got {text!r}") from None


def run(args) -> int:
    from ccproof.errors import CCProofError, check_valence
    from ccproof.inverse import characteristic_map, inverse_characteristic_map
    from ccproof.inverse.algorithm import PATCH_NAMES

    k = check_valence(args.K)
    u, v = _number(args.U, "U"), _number(args.V, "V")
    if args.rigorous and not MIN_PREC <= args.prec <= MAX_PREC:
        raise CCProofError(f"--prec must be {MIN_PREC}..{MAX_PREC} bits, got {args.prec}")
    res = inverse_characteristic_map(k, u, v, domain=args.domain, full_output=True,
                                     rigorous=args.rigorous, prec=args.prec)
    r, s = float(res.r), float(res.s)
    x, y = characteristic_map(k, r, s)
    patch = int(res.patch)
    print(f"valence      {k}")
    print(f"point        ({u!r}, {v!r})")
    print(f"preimage     r = {r!r}")
    print(f"             s = {s!r}")
    if patch < 0:
        print("piece        the extraordinary vertex (origin)")
    else:
        print(f"piece        layer {int(res.layer)}, {PATCH_NAMES[patch]}")
    print(f"fallback     {'yes' if bool(res.fallback) else 'no'}")
    print(f"round trip   {max(abs(float(x) - u), abs(float(y) - v)):.3e}")
    if args.rigorous:
        box = res.boxes[0]
        print(f"certified    {'yes' if box.certified else 'NO'}")
        print(f"box r        {box.r.str(30, radius=True)}")
        print(f"box s        {box.s.str(30, radius=True)}")
        print(f"float error  <= {box.distance(r, s):.3e}")
        if not box.certified:
            return 1
    return 0 if bool(res.verified) else 1
